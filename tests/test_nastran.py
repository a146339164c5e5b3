"""Nastran decks through pyNastran: what goes in reads back, a beam read back vibrates as the
panel it came from, and a deck the panel cannot come from is refused by name."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

import thermojitter as tj
from conftest import ENTRY, GEO, PAPER, panels, pynastran_imports
from thermojitter import nastran

needs_pynastran = pytest.mark.skipif(
    not pynastran_imports(), reason="pyNastran (thermojitter[nastran]) does not import here"
)


def _read(path: Path, *, xref: bool = True):  # type: ignore[no-untyped-def]
    from pyNastran.bdf.bdf import read_bdf

    return read_bdf(str(path), xref=xref, debug=None)


def _new_model():  # type: ignore[no-untyped-def]
    from pyNastran.bdf.bdf import BDF

    return BDF(debug=None)


def _eclipse_run(panel: tj.Panel = PAPER) -> tj.Solution:
    return tj.simulate(panel, GEO, (ENTRY - 120.0, ENTRY + 240.0), dt_out=1.5)


def _free_free_frequency(panel: tj.Panel) -> float:
    """(β₁L)² sqrt(EI/(m L⁴))/2π with β₁L the first root of cos x cosh x = 1, solved here."""
    beta_l = brentq(lambda x: math.cos(x) * math.cosh(x) - 1.0, 4.0, 5.0, xtol=1e-15)
    rigidity = panel.youngs_modulus * panel.bending_inertia
    return (
        beta_l**2 * math.sqrt(rigidity / (panel.mass_per_length * panel.length**4)) / (2 * math.pi)
    )


# --- the load deck ---------------------------------------------------------------------------


@needs_pynastran
def test_hinge_run_reads_back_as_written(tmp_path: Path) -> None:
    sol = _eclipse_run()
    path = tj.to_nastran(tmp_path / "eclipse.bdf", PAPER, sol)
    model = _read(path)  # cross-referenced: every id the deck uses is defined in it
    assert model.sol == 112
    (tid,) = model.tables_d
    table = model.tables_d[tid]
    span = sol.t[-1] - sol.t[0]
    np.testing.assert_allclose(table.x, sol.t - sol.t[0], rtol=1e-12, atol=1e-12 * span)
    np.testing.assert_allclose(table.y, sol.thermal_moment, rtol=1e-12, atol=0.0)
    assert np.ptp(sol.thermal_moment) > 10.0  # the window holds the collapse of the moment
    # One couple: +M about +Y at node 1, -M at node 101 (the paper's 101 nodes).
    (darea,) = model.dareas.values()
    assert (darea.nodes, darea.components, darea.scales) == ([1, 101], [5, 5], [1.0, -1.0])
    (tload,) = [entry for entries in model.dload_entries.values() for entry in entries]
    assert (tload.excite_id, tload.tid) == (darea.sid, tid)
    (dload,) = [d for ds in model.dloads.values() for d in ds]
    assert dload.load_ids == [tload.sid] and dload.scale_factors == [1.0]
    (tstep,) = model.tsteps.values()
    assert tstep.N[0] * tstep.DT[0] >= span * (1 - 1e-12)
    assert tstep.DT[0] == pytest.approx(1.5, rel=1e-12)
    subcase = model.case_control_deck.subcases[0]
    assert subcase.get_parameter("DLOAD")[0] == dload.sid
    assert subcase.get_parameter("TSTEP")[0] == tstep.sid
    assert model.params["INREL"].values == [-1]
    assert model.suport[0].nodes == [51] and model.suport[0].Cs == ["135"]
    assert len(model.nodes) == 101 and len(model.elements) == 100


@needs_pynastran
def test_hinge_moment_scale_is_not_in_the_beam_load(tmp_path: Path) -> None:
    """The beam carries a E I ΔT/d: the hinge's χ multiplies the run's moment, not the deck's."""
    chi = 1.3
    sol = _eclipse_run(PAPER.replace(moment_scale=chi))
    path = tj.to_nastran(tmp_path / "scaled.bdf", PAPER.replace(moment_scale=chi), sol)
    (table,) = _read(path).tables_d.values()
    np.testing.assert_allclose(table.y, sol.thermal_moment / chi, rtol=1e-12, atol=0.0)


@needs_pynastran
@pytest.mark.parametrize("support", ["free-free", "cantilever"])
def test_distributed_run_loads_every_element(tmp_path: Path, support: str) -> None:
    sol = tj.simulate_distributed(
        PAPER, GEO, (ENTRY - 60.0, ENTRY + 120.0), support=support, elements=8, dt_out=2.0
    )
    path = tj.to_nastran(tmp_path / "distributed.bdf", PAPER, sol)
    model = _read(path)
    assert len(model.elements) == 8
    np.testing.assert_allclose(
        [model.nodes[n].xyz[0] for n in sorted(model.nodes)], sol.x_node, rtol=1e-12
    )
    by_table = {e.tid: e for entries in model.dload_entries.values() for e in entries}
    assert sorted(by_table) == list(range(1, 9))
    for element in range(8):
        table = model.tables_d[element + 1]
        np.testing.assert_allclose(table.y, sol.thermal_moment[:, element], rtol=1e-12, atol=0.0)
        darea = model.dareas[by_table[element + 1].excite_id]
        assert darea.nodes == [element + 1, element + 2]
        assert darea.scales == [1.0, -1.0]
    if support == "cantilever":
        (spc,) = model.spcs.values()
        assert spc[0].nodes == [1] and spc[0].components == "123456"
        assert not model.suport and "INREL" not in model.params
        subcase = model.case_control_deck.subcases[0]
        assert subcase.get_parameter("SPC")[0] == spc[0].conid
    else:
        assert model.suport[0].nodes == [5]
    damping = next(iter(model.tables_sdamping.values()))
    assert damping.Type == "CRIT"
    np.testing.assert_allclose(damping.y, sol.damping_ratio, rtol=1e-4)  # a small-field card


@needs_pynastran
def test_the_couple_bends_the_tips_as_the_engine_does(tmp_path: Path) -> None:
    """The deck's loads, on a Hermite beam assembled here in Nastran's degrees of freedom (w along
    Z, θ_y = −w'), give the tip rise over the centre the engine's beam has under the same end
    moments: the sign and the size of the couple."""
    moment = 250.0
    sol = tj.simulate(PAPER, GEO, (0.0, 10.0), t_eval=[0.0, 10.0])
    path = tj.to_nastran(tmp_path / "couple.bdf", PAPER, sol, elements=20)
    model = _read(path)
    x = np.array([model.nodes[n].xyz[0] for n in sorted(model.nodes)])
    prop = model.properties[1]
    rigidity = model.materials[prop.mid].e * prop.i1
    n = x.size
    stiffness = np.zeros((2 * n, 2 * n))
    for e in range(n - 1):
        h = x[e + 1] - x[e]
        k = (
            rigidity
            / h**3
            * np.array(
                [
                    [12, 6 * h, -12, 6 * h],
                    [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                    [-12, -6 * h, 12, -6 * h],
                    [6 * h, 2 * h * h, -6 * h, 4 * h * h],
                ]
            )
        )  # in (w, w') per node
        flip = np.diag([1.0, -1.0, 1.0, -1.0])  # (w, w') -> (w, θ_y)
        dofs = [2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3]
        stiffness[np.ix_(dofs, dofs)] += flip @ k @ flip
    load = np.zeros(2 * n)
    (darea,) = model.dareas.values()
    for node, component, scale in zip(darea.nodes, darea.components, darea.scales, strict=True):
        assert component == 5
        load[2 * (node - 1) + 1] += scale * moment
    w = np.linalg.lstsq(stiffness, load, rcond=None)[0][0::2]
    eta = w[-1] - w[n // 2]
    expected = tj.FreeFreeBeam(PAPER, 20).static_tip_deflection(moment)
    assert expected > 0
    assert eta == pytest.approx(expected, rel=1e-9)
    assert eta == pytest.approx(moment * PAPER.length**2 / (8 * rigidity), rel=1e-9)


# --- the beam model, written and read -------------------------------------------------------


@needs_pynastran
def test_beam_deck_holds_the_panel(tmp_path: Path) -> None:
    path = tj.to_nastran(tmp_path / "beam.bdf", PAPER)
    model = _read(path)
    assert model.sol == 103 and not model.tables_d
    assert len(model.nodes) == 101
    xs = np.array([model.nodes[n].xyz for n in sorted(model.nodes)])
    np.testing.assert_allclose(xs[:, 0], np.linspace(0.0, PAPER.length, 101), rtol=1e-14)
    assert np.all(xs[:, 1:] == 0.0)
    (prop,) = model.properties.values()
    mat = model.materials[prop.mid]
    assert (mat.e, prop.i1, prop.nsm, mat.rho) == (
        PAPER.youngs_modulus,
        PAPER.bending_inertia,
        PAPER.mass_per_length,
        0.0,
    )
    assert mat.a == PAPER.expansion_coeff
    assert model.params["COUPMASS"].values == [1]
    assert model.params["INREL"].values == [-1] and model.suport[0].nodes == [51]
    clamped = _read(tj.to_nastran(tmp_path / "clamped.bdf", PAPER, support="cantilever"))
    assert [s.nodes for spcs in clamped.spcs.values() for s in spcs] == [[1]]
    assert not clamped.suport and "INREL" not in clamped.params


@needs_pynastran
def test_paper_beam_round_trip_keeps_its_frequency(tmp_path: Path) -> None:
    path = tj.to_nastran(tmp_path / "beam.bdf", PAPER)
    beam = tj.from_nastran(path)
    assert beam.n_elements == 100 and beam.tip_masses == ()
    assert beam.panel == PAPER
    assert tj.beam_frequency(beam.panel) == pytest.approx(_free_free_frequency(PAPER), rel=1e-12)
    np.testing.assert_allclose(
        tj.FreeFreeBeam(beam.panel, 100).natural_frequencies(3),
        tj.FreeFreeBeam(PAPER, 100).natural_frequencies(3),
        rtol=1e-12,
    )


@needs_pynastran
@settings(max_examples=15, deadline=None)
@given(panel=panels(), elements=st.integers(1, 60).map(lambda k: 2 * k))
def test_any_panel_round_trips(panel: tj.Panel, elements: int) -> None:
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = tj.to_nastran(Path(folder) / "beam.bdf", panel, elements=elements)
        beam = tj.from_nastran(path, base=panel)
    assert beam.n_elements == elements
    for name in ("length", "youngs_modulus", "bending_inertia", "mass_per_length"):
        assert getattr(beam.panel, name) == pytest.approx(getattr(panel, name), rel=1e-13)
    assert tj.beam_frequency(beam.panel) == pytest.approx(_free_free_frequency(panel), rel=1e-12)


@needs_pynastran
def test_cbeam_deck_from_elsewhere(tmp_path: Path) -> None:
    """A deck written without thermojitter: CBEAM/PBEAM, unordered ids, uneven spacing along a
    tilted line, mass as RHO A + NSM, CONM2 at a tip."""
    model = _new_model()
    direction = np.array([3.0, 4.0, 0.0]) / 5.0
    origin = np.array([1.0, -2.0, 0.5])
    stations = [0.0, 1.0, 2.5, 4.0, 6.0, 10.0]
    ids = [70, 30, 50, 10, 20, 90]
    for nid, s in zip(ids, stations, strict=True):
        model.add_grid(nid, list(origin + s * direction))
    for k in range(5):
        model.add_cbeam(200 - k, 7, [ids[k + 1], ids[k]], [0.0, 0.0, 1.0], None)
    area, rho, nsm = 0.02, 2700.0, 1.25
    model.add_pbeam(7, 3, [0.0], ["C"], [area], [2e-6], [5e-4], [0.0], [1e-6], nsm=[nsm])
    model.add_mat1(3, 68e9, None, 0.33, rho=rho, a=2.3e-5)
    model.add_conm2(900, 90, 4.5)
    path = tmp_path / "boom.bdf"
    model.write_bdf(str(path), enddata=True)  # bulk data only: no executive or case control
    beam = tj.from_nastran(path)
    assert beam.nodes == (70, 30, 50, 10, 20, 90)
    assert beam.elements == (200, 199, 198, 197, 196)
    np.testing.assert_allclose(beam.x, stations, rtol=1e-12, atol=1e-12)
    assert beam.panel.length == pytest.approx(10.0, rel=1e-12)
    assert beam.panel.youngs_modulus == 68e9 and beam.panel.bending_inertia == 2e-6
    assert beam.panel.mass_per_length == pytest.approx(rho * area + nsm, rel=1e-15)
    assert beam.panel.expansion_coeff == 2.3e-5
    assert beam.panel.emissivity_front == PAPER.emissivity_front  # from the base panel
    assert beam.tip_masses == (nastran.TipMass(node=90, x=pytest.approx(10.0), mass=4.5),)
    assert tj.from_nastran(path, inertia="I2").panel.bending_inertia == 5e-4


# --- refusals --------------------------------------------------------------------------------


def _bar_deck(tmp_path: Path, edit) -> Path:  # type: ignore[no-untyped-def]
    """A three-bar deck, changed by ``edit(model)`` before it is written."""
    model = _new_model()
    for i in range(4):
        model.add_grid(i + 1, [float(i), 0.0, 0.0])
    for e in range(3):
        model.add_cbar(e + 1, 1, [e + 1, e + 2], [0.0, 0.0, 1.0], None)
    model.add_pbar(1, 1, A=0.01, i1=1e-6, i2=1e-6, j=1e-6, nsm=2.0)
    model.add_mat1(1, 70e9, None, 0.3)
    edit(model)
    path = tmp_path / "bad.bdf"
    model.write_bdf(str(path), enddata=True)
    return path


def _second_section(model) -> None:  # type: ignore[no-untyped-def]
    model.add_pbar(2, 1, A=0.01, i1=2e-6, i2=1e-6, j=1e-6, nsm=2.0)
    model.elements[3].pid = 2


def _shear_only(model) -> None:  # type: ignore[no-untyped-def]
    model.materials.clear()
    model.add_mat1(1, None, 26e9, None)


def _drop_elements(model) -> None:  # type: ignore[no-untyped-def]
    model.elements.clear()


def _shell(model) -> None:  # type: ignore[no-untyped-def]
    model.add_cquad4(50, 9, [1, 2, 3, 4])
    model.add_pshell(9, 1, 0.01)


def _branch(model) -> None:  # type: ignore[no-untyped-def]
    model.add_grid(5, [1.0, 1.0, 0.0])
    model.add_cbar(4, 1, [2, 5], [0.0, 0.0, 1.0], None)


def _bend(model) -> None:  # type: ignore[no-untyped-def]
    model.nodes[4].xyz[1] = 0.5


def _taper(model) -> None:  # type: ignore[no-untyped-def]
    model.add_pbeam(2, 1, [0.0, 1.0], ["YES", "YES"], [0.01, 0.01], [1e-6, 2e-6], [1e-6, 1e-6],
                    [0.0, 0.0], [1e-6, 1e-6])  # fmt: skip
    for e in (1, 2, 3):
        el = model.elements.pop(e)
        model.add_cbeam(e, 2, el.nodes, [0.0, 0.0, 1.0], None)


@needs_pynastran
@pytest.mark.parametrize(
    ("edit", "parameter", "words"),
    [
        (lambda m: m.materials.clear(), "MAT1", "material 1 of PBAR 1 is missing"),
        (_shear_only, "MAT1", "no Young's modulus"),
        (_second_section, "section", "bending_inertia"),
        (_drop_elements, "elements", "no CBAR or CBEAM"),
        (_shell, "elements", "CQUAD4"),
        (_branch, "CBAR", "node 2 joins 3 elements"),
        (_bend, "GRID", "straight"),
        (_taper, "PBEAM", "tapered"),
        (lambda m: m.add_conm2(9, 77, 1.0), "CONM2", "not on the beam"),
    ],
    ids=[
        "no-mat1",
        "no-modulus",
        "non-uniform",
        "no-elements",
        "shell",
        "branched",
        "bent",
        "tapered",
        "mass",
    ],
)
def test_bad_deck_is_refused_by_name(tmp_path: Path, edit, parameter: str, words: str) -> None:  # type: ignore[no-untyped-def]
    path = _bar_deck(tmp_path, edit)
    with pytest.raises(tj.ParameterError, match=words) as info:
        tj.from_nastran(path)
    assert info.value.parameter == parameter


@needs_pynastran
def test_good_three_bar_deck_reads(tmp_path: Path) -> None:
    """The deck the refusals above start from is itself accepted."""
    beam = tj.from_nastran(_bar_deck(tmp_path, lambda m: None))
    assert beam.panel.length == 3.0 and beam.panel.mass_per_length == 2.0


@needs_pynastran
def test_bad_arguments_are_refused(tmp_path: Path) -> None:
    sol = _eclipse_run()
    with pytest.raises(tj.ParameterError) as info:
        tj.to_nastran(tmp_path / "odd.bdf", PAPER, sol, elements=7)
    assert info.value.parameter == "elements"
    with pytest.raises(tj.ParameterError) as info:
        tj.to_nastran(tmp_path / "x.bdf", PAPER, sol, inertia_relief="yes")  # type: ignore[arg-type]
    assert info.value.parameter == "inertia_relief"
    with pytest.raises(tj.ParameterTypeError) as info:
        tj.to_nastran(tmp_path / "x.bdf", PAPER, "a run")  # type: ignore[arg-type]
    assert info.value.parameter == "solution"
    with pytest.raises(tj.ParameterError) as info:
        tj.to_nastran(tmp_path / "x.bdf", PAPER, sol, support="cantilever")
    assert info.value.parameter == "support"
    with pytest.raises(tj.ParameterError) as info:
        tj.to_nastran(tmp_path / "x.bdf", PAPER, support="cantilever", inertia_relief="auto")
    assert info.value.parameter == "inertia_relief"
    with pytest.raises(tj.ParameterError) as info:
        tj.from_nastran(tmp_path / "absent.bdf")
    assert info.value.parameter == "path"


def test_missing_pynastran_says_how_to_install(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for name in ("pyNastran", "pyNastran.bdf", "pyNastran.bdf.bdf"):
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(ImportError, match=r"thermojitter\[nastran\]"):
        tj.to_nastran(tmp_path / "beam.bdf", PAPER)
    with pytest.raises(ImportError, match=r"thermojitter\[nastran\]"):
        tj.from_nastran(tmp_path / "beam.bdf")
    assert not (tmp_path / "beam.bdf").exists()
