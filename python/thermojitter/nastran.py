"""Nastran bulk data in and out, through pyNastran (the optional extra ``thermojitter[nastran]``).

- :func:`to_nastran` writes the panel as a beam model (GRID/CBAR/PBAR/MAT1, the paper's 101 nodes
  by default) and, given a run, its thermal moment as a transient load (TABLED1 time tables,
  DAREA/TLOAD1/DLOAD, TSTEP) ready for a modal transient run (SOL 112) with inertia relief, as the
  paper took its moment into Nastran (Sec. 4.3). Without a run the deck is a normal-modes run
  (SOL 103) of the same beam.
- :func:`from_nastran` reads a straight, uniform beam (CBAR/CBEAM, PBAR/PBEAM, MAT1, CONM2
  masses) back into a :class:`~thermojitter.Panel`.

    deck = tj.to_nastran("eclipse.bdf", panel, sol)   # sol from tj.simulate(...)
    beam = tj.from_nastran("eclipse.bdf")
    beam.panel, beam.tip_masses

The deck, in SI units (m, kg, s, N, Pa): x runs along the panel from node 1 (x = 0); +Z is the
direction of positive deflection, away from the Sun (towards the back face: the front face looks
to −Z); the panel bends in the XZ plane, plane 1 of its CBARs (v = +Z, so PBAR I1 is the panel's
bending inertia I). Every GRID holds the in-plane and torsion degrees of freedom (PS = 246): the
engine's beam is planar, so I2 (= I1) and J (0) are inert. The mass per length is the PBAR's
non-structural mass (MAT1 RHO = 0), the mass matrix the consistent one (PARAM,COUPMASS,1), and
every bar is Euler–Bernoulli (no shear flexibility: K1, K2 blank).

A thermal moment M_e on element e loads it, as in the engine, with the couple of its consistent
nodal loads: +M_e about +Y (component 5) at its first node and −M_e at its second; a uniform
moment is the pair of end moments ±M_T of :class:`~thermojitter.FreeFreeBeam`. Nastran starts
its transient at t = 0 from rest: the tables hold t − t0 of the run, and a moment that is not
zero at t0 is applied as a step there (the engine's beam starts in its static shape instead).

This module converts and presents; the mesh, the physical moment and the damping come from the
engine (``_core``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.distributed import DistributedSolution
from thermojitter.panel import Panel
from thermojitter.results import Solution
from thermojitter.simulate import check_inputs

Array = NDArray[np.float64]
InertiaRelief = Literal["suport", "auto", "none"]
Support = Literal["free-free", "cantilever"]

PAPER_ELEMENTS = 100
"""Bar elements of the paper's Nastran model (101 nodes, Sec. 4.3)."""

DEFAULT_MODES = 20
"""Eigenvectors asked of Nastran (EIGRL ND) for the modal run."""

INSTALL_HINT = "pip install 'thermojitter[nastran]'"

# Card ids (each card type has its own ids; the dynamic load sets share one range).
_MAT, _PROP, _EIGRL, _DAMPING, _TSTEP, _DLOAD, _SPC = 1, 1, 1, 2, 3, 4, 5
_DAREA0, _TLOAD0 = 10_000, 20_000
_BENDING = 5  # rotation about +Y: the panel bends in the XZ plane
_HELD = "246"  # in-plane translation and the two rotations that are not bending
_RIGID = "135"  # the planar beam's rigid modes: x, z and the rotation about y
_UNIFORM = 1e-9  # relative spread accepted for one section, one straight line
_AXES = """thermojitter panel in SI units (m, kg, s, N, Pa).
X along the panel from node 1; +Z the positive deflection, away from the Sun.
It bends in the XZ plane (CBAR plane 1, PBAR I1); PS=246 holds the rest."""


def _pynastran() -> Any:
    """The pyNastran module that reads and writes bulk data, or an ImportError that says how to
    install it."""
    try:
        from pyNastran.bdf import bdf
    except ImportError as exc:
        raise ImportError(
            f"Nastran decks need pyNastran, the optional extra: {INSTALL_HINT}"
        ) from exc
    except Exception as exc:  # an installed pyNastran that does not import
        raise ImportError(
            f"pyNastran is installed but does not import ({type(exc).__name__}: {exc}); "
            f"pyNastran 1.4 needs numpy < 2 (here numpy {np.__version__}): {INSTALL_HINT} "
            "installs a matching set"
        ) from exc
    return bdf


@dataclass(frozen=True)
class TipMass:
    """A CONM2 on the beam: ``x`` its node's distance from the first node (m), ``mass`` (kg)."""

    node: int
    x: float
    mass: float


@dataclass(frozen=True)
class NastranBeam:
    """A beam read from bulk data by :func:`from_nastran`.

    ``panel``: the base panel with the beam's length, E, I, mass per length (and expansion
    coefficient, where the MAT1 gives one); ``x``: the nodes' distances from the first node (m);
    ``nodes``/``elements``: their ids in chain order; ``tip_masses``: the CONM2 masses on the
    beam's nodes (a Panel carries none: add them to the model that takes them).
    """

    panel: Panel
    x: Array
    nodes: tuple[int, ...]
    elements: tuple[int, ...]
    tip_masses: tuple[TipMass, ...] = ()

    @property
    def n_elements(self) -> int:
        return len(self.elements)


# --- writing -------------------------------------------------------------------------------


def _moment_history(panel: Panel, solution: Solution) -> Array:
    """The physical thermal moment of a hinge run (N m): the beam carries a E I ΔT/d, without
    the hinge's calibration χ (as :func:`thermojitter.compare_with_beam` loads its beam)."""
    if panel.moment_scale == 1.0:
        return np.asarray(solution.thermal_moment, dtype=float)
    if solution.T_nodes is not None:
        raise checks.ParameterError(
            "panel",
            panel,
            message=f"panel.moment_scale = {panel.moment_scale:g}: the physical moment of a "
            "layered run cannot be recovered here; pass the run of a panel with moment_scale=1",
        )
    physical = panel.replace(moment_scale=1.0)
    return np.asarray(
        _core.moment(
            physical.as_dict(),
            np.ascontiguousarray(solution.T_front, dtype=float),
            np.ascontiguousarray(solution.T_back, dtype=float),
        )
    )


def _time_step(t: Array, dt: float | None) -> tuple[float, int]:
    """TSTEP's DT and N covering the run: DT the mean sample spacing unless given."""
    span = float(t[-1] - t[0])
    step = span / (t.size - 1) if dt is None else checks.positive("dt", dt)
    n = max(1, math.ceil(span / step * (1.0 - 1e-12)))
    if n > _core.MAX_SAMPLES:
        raise checks.ParameterError(
            "dt", step, f"would write more than {_core.MAX_SAMPLES} time steps of the run"
        )
    return step, n


def _loads(
    panel: Panel, solution: Solution | DistributedSolution | None, n_elements: int
) -> tuple[Array, list[tuple[int, int, Array]]]:
    """The run's times and its moment couples: (first node, second node, M(t)) each."""
    if solution is None:
        return np.empty(0), []
    t = np.asarray(solution.t, dtype=float)
    if t.size < 2 or not t[-1] > t[0]:
        raise checks.ParameterError("solution", solution, "holds fewer than two times")
    if isinstance(solution, DistributedSolution):
        moments = np.asarray(solution.thermal_moment, dtype=float)
        return t, [(e + 1, e + 2, moments[:, e]) for e in range(moments.shape[1])]
    return t, [(1, n_elements + 1, _moment_history(panel, solution))]


def _mesh(
    panel: Panel, solution: Solution | DistributedSolution | None, elements: int | None
) -> tuple[Array, str]:
    """The node positions (m, from the engine's mesh) and the support."""
    if isinstance(solution, DistributedSolution):
        x = np.asarray(solution.x_node, dtype=float)
        if elements is not None and elements != x.size - 1:
            raise checks.ParameterError(
                "elements", elements, f"the distributed run has {x.size - 1} elements"
            )
        if not math.isclose(float(x[-1]), panel.length, rel_tol=1e-12):
            raise checks.ParameterError(
                "panel",
                panel,
                message=f"panel.length = {panel.length:g} m but the run's panel is "
                f"{float(x[-1]):g} m long",
            )
        return x, solution.support
    n = PAPER_ELEMENTS if elements is None else elements
    n = checks.integer("elements", n, 2, _core.BEAM_MAX_ELEMENTS)
    if n % 2:
        raise checks.ParameterError("elements", n, "must be even (the centre is a node)")
    return np.asarray(_core.beam_modes(panel.as_dict(), n, 1)["x"], dtype=float), "free-free"


def _beam_cards(model: Any, panel: Panel, x: Array) -> None:
    """GRID/CBAR/PBAR/MAT1 of the panel, nodes 1..n+1 at ``x`` along X."""
    values = panel.as_dict()
    for i, xi in enumerate(x):
        model.add_grid(i + 1, [float(xi), 0.0, 0.0], ps=_HELD, comment=_AXES if i == 0 else "")
    for e in range(x.size - 1):
        model.add_cbar(e + 1, _PROP, [e + 1, e + 2], [0.0, 0.0, 1.0], None)
    inertia = values["bending_inertia"]
    model.add_pbar(
        _PROP,
        _MAT,
        A=values["width"] * values["thickness"],
        i1=inertia,
        i2=inertia,
        j=0.0,
        nsm=values["mass_per_length"],
        k1=None,
        k2=None,
        comment="A = width x thickness; NSM = the panel's mass per length (kg/m)",
    )
    model.add_mat1(_MAT, values["youngs_modulus"], None, None, rho=0.0, a=values["expansion_coeff"])
    model.add_param("COUPMASS", [1])


def _load_cards(
    model: Any,
    t: Array,
    couples: list[tuple[int, int, Array]],
    dt: float,
    n_steps: int,
) -> None:
    """One TABLED1/DAREA/TLOAD1 per moment couple, their DLOAD, and the TSTEP."""
    times = t - t[0]
    for k, (first, second, moment) in enumerate(couples, start=1):
        comment = (
            f"thermal moment, N m, against t - t0 (s), t0 = {float(t[0])!r} s of the run"
            if k == 1
            else ""
        )
        model.add_tabled1(k, times, np.asarray(moment, dtype=float), comment=comment)
        model.add_darea(_DAREA0 + k, [first, second], [_BENDING, _BENDING], [1.0, -1.0])
        model.add_tload1(_TLOAD0 + k, _DAREA0 + k, k)
    model.add_dload(
        _DLOAD, 1.0, [1.0] * len(couples), [_TLOAD0 + k for k in range(1, len(couples) + 1)]
    )
    model.add_tstep(_TSTEP, n_steps, dt, 1)


def to_nastran(
    path: str | Path,
    panel: Panel,
    solution: Solution | DistributedSolution | None = None,
    *,
    elements: int | None = None,
    dt: float | None = None,
    support: Support | None = None,
    inertia_relief: InertiaRelief | None = None,
    modes: int = DEFAULT_MODES,
    damping_ratio: float | None = None,
    title: str | None = None,
) -> Path:
    """Writes a Nastran deck of the panel as a beam, loaded by a run's thermal moment; returns
    the path written.

    - ``solution``: a :class:`~thermojitter.Solution` (the hinge model: its thermal moment,
      without the hinge's χ, as end moments ±M_T) or a
      :class:`~thermojitter.DistributedSolution` (each element's own moment, on its own support
      and mesh); ``None`` writes the beam alone in a normal-modes run (SOL 103).
    - ``elements``: bars of the beam (even; default the paper's 100, 101 nodes); a distributed
      run brings its own.
    - ``dt``: TSTEP's step, s (default the run's mean sample spacing); the steps cover the run.
    - ``support``: ``"free-free"`` or ``"cantilever"`` for the beam alone; a run brings its own
      (the hinge model's panel is free).
    - ``inertia_relief``: ``"suport"`` (PARAM,INREL,-1 with a SUPORT at the centre node, as the
      paper did), ``"auto"`` (PARAM,INREL,-2) or ``"none"``; default ``"suport"`` for a free
      panel and ``"none"`` for a cantilever (clamped at node 1 by an SPC1).
    - ``modes``: eigenvectors asked (EIGRL ND). ``damping_ratio``: modal damping of every mode
      (TABDMP1, CRIT), default the engine's beam damping of the panel (a distributed run's own).

    Needs pyNastran (``pip install 'thermojitter[nastran]'``).
    """
    target = checks.path("path", path)
    check_inputs(panel)
    if solution is not None:
        checks.instance(
            "solution",
            solution,
            (Solution, DistributedSolution),
            "a thermojitter.Solution or DistributedSolution",
        )
    modes = checks.integer("modes", modes, 1)
    x, held = _mesh(panel, solution, elements)
    if support is not None:
        asked = checks.choice("support", support, ("free-free", "cantilever"))
        if solution is not None and asked != held:
            raise checks.ParameterError(
                "support", support, f"the run's panel is {held}: leave support out"
            )
        held = asked
    relief = "none" if held == "cantilever" else "suport"
    if inertia_relief is not None:
        relief = checks.choice("inertia_relief", inertia_relief, ("suport", "auto", "none"))
        if held == "cantilever" and relief != "none":
            raise checks.ParameterError(
                "inertia_relief", inertia_relief, "a clamped panel takes no inertia relief"
            )
    if damping_ratio is not None:
        zeta = checks.in_range("damping_ratio", damping_ratio, 0.0, 10.0)
    elif isinstance(solution, DistributedSolution):
        zeta = float(solution.damping_ratio)
    else:
        zeta = float(_core.hinge_equivalent_damping_ratio(panel.as_dict()))
    if title is not None and (not isinstance(title, str) or "\n" in title):
        raise checks.wrong_type("title", title, "a one-line string")
    t, couples = _loads(panel, solution, x.size - 1)
    step, n_steps = _time_step(t, dt) if couples else (0.0, 0)

    bdf = _pynastran()
    model = bdf.BDF(debug=None)
    transient = bool(couples)
    model.sol = 112 if transient else 103
    model.executive_control_lines = [f"SOL {model.sol}", "CEND"]
    case = [
        f"TITLE = {title or 'thermojitter panel'}",
        "ECHO = NONE",
        f"METHOD = {_EIGRL}",
        "DISPLACEMENT = ALL",
    ]
    if transient:
        case += [f"SDAMPING = {_DAMPING}", f"DLOAD = {_DLOAD}", f"TSTEP = {_TSTEP}"]
    if held == "cantilever":
        case.append(f"SPC = {_SPC}")
    model.case_control_deck = bdf.CaseControlDeck([*case, "BEGIN BULK"])
    _beam_cards(model, panel, x)
    model.add_eigrl(_EIGRL, nd=modes)
    if held == "cantilever":
        model.add_spc1(_SPC, "123456", [1], comment="clamped at x = 0")
    elif relief == "suport":
        model.add_param("INREL", [-1])
        model.add_suport([x.size // 2 + 1], [_RIGID], comment="inertia relief at the centre")
    elif relief == "auto":
        model.add_param("INREL", [-2])
    if transient:
        model.add_tabdmp1(_DAMPING, [0.0, 1000.0], [zeta, zeta], Type="CRIT")
        _load_cards(model, t, couples, step, n_steps)
    target.parent.mkdir(parents=True, exist_ok=True)
    # Large fields: 16 characters keep a table's values to about 1e-14.
    model.write_bdf(str(target), size=16, enddata=True)
    return target


# --- reading -------------------------------------------------------------------------------


def _bad(card: str, value: Any, message: str) -> checks.ParameterError:
    return checks.ParameterError(card, value, message=message)


def _section(model: Any, element: Any, inertia: str) -> tuple[float, float, float, float]:
    """(E, I, mass per length, expansion coefficient) of a CBAR/CBEAM, from its PBAR/PBEAM and
    MAT1 (mass per length = RHO A + NSM)."""
    prop = model.properties.get(element.pid)
    if prop is None:
        raise _bad(
            "PBAR",
            element.pid,
            f"property {element.pid} of {element.type} {element.eid} is missing from the deck",
        )
    if prop.type == "PBAR":
        area, i1, i2, nsm = prop.A, prop.i1, prop.i2, prop.nsm
    elif prop.type == "PBEAM":
        stations = {
            (a, b, c, d) for a, b, c, d in zip(prop.A, prop.i1, prop.i2, prop.nsm, strict=True)
        }
        if len(stations) > 1:
            raise _bad(
                "PBEAM",
                prop.pid,
                f"PBEAM {prop.pid} is tapered (its stations differ): a panel has one section",
            )
        area, i1, i2, nsm = stations.pop()
    else:
        raise _bad(
            prop.type,
            prop.pid,
            f"{prop.type} {prop.pid} is not supported: give the section as PBAR or PBEAM",
        )
    mat = model.materials.get(prop.mid)
    if mat is None or mat.type != "MAT1":
        found = "missing from the deck" if mat is None else f"a {mat.type}"
        raise _bad(
            "MAT1",
            prop.mid,
            f"material {prop.mid} of {prop.type} {prop.pid} is {found}: a MAT1 is needed",
        )
    if not mat.e:
        raise _bad("MAT1", prop.mid, f"MAT1 {prop.mid} gives no Young's modulus E")
    inertia_value = i1 if inertia == "I1" else i2
    return (
        float(mat.e),
        float(inertia_value),
        float(mat.rho) * float(area) + float(nsm),
        float(mat.a),
    )


def _chain(ends: dict[int, tuple[int, int]]) -> tuple[list[int], list[int]]:
    """The nodes and elements in order along a single open chain, from its end of lower id."""
    touching: dict[int, list[int]] = {}
    for eid, (a, b) in ends.items():
        if a == b:
            raise _bad("CBAR", eid, f"element {eid} joins node {a} to itself")
        touching.setdefault(a, []).append(eid)
        touching.setdefault(b, []).append(eid)
    tips = sorted(n for n, es in touching.items() if len(es) == 1)
    branched = sorted(n for n, es in touching.items() if len(es) > 2)
    if branched or len(tips) != 2:
        where = (
            f"node {branched[0]} joins {len(touching[branched[0]])} elements"
            if branched
            else "the elements close a loop or fall in pieces"
        )
        raise _bad("CBAR", sorted(ends)[0], f"the elements are not one open chain: {where}")
    nodes: list[int] = [tips[0]]
    order: list[int] = []
    while len(order) < len(ends):
        here = nodes[-1]
        nxt = [e for e in touching[here] if not order or e != order[-1]]
        if not nxt:
            break
        eid = nxt[0]
        a, b = ends[eid]
        order.append(eid)
        nodes.append(b if a == here else a)
    if len(order) != len(ends):
        raise _bad(
            "CBAR", sorted(set(ends) - set(order))[0], "the elements are not one connected chain"
        )
    return nodes, order


def _read_model(path: Path) -> Any:
    bdf = _pynastran()
    try:
        text = path.read_text(errors="replace")
    except OSError as exc:
        raise checks.ParameterError(
            "path", str(path), message=f"cannot read {path}: {exc}"
        ) from exc
    bulk_only = re.search(r"^\s*BEGIN\s+BULK", text, re.IGNORECASE | re.MULTILINE) is None
    model = bdf.BDF(debug=None)
    try:
        model.read_bdf(str(path), xref=False, punch=bulk_only)
    except Exception as exc:
        raise checks.ParameterError(
            "path", str(path), message=f"pyNastran cannot read {path}: {exc}"
        ) from exc
    return model


def from_nastran(
    path: str | Path, base: Panel | None = None, *, inertia: Literal["I1", "I2"] = "I1"
) -> NastranBeam:
    """Reads a straight, uniform beam from Nastran bulk data (a whole deck or its bulk data).

    The beam is one open chain of CBAR/CBEAM elements of one section (PBAR/PBEAM, MAT1); its
    length, Young's modulus, bending inertia (``inertia``: the PBAR/PBEAM ``"I1"``, bending in
    the bar's plane 1, or ``"I2"``) and mass per length (RHO A + NSM) replace those of ``base``
    (default the paper's panel, which gives what bulk data cannot: the optical and thermal
    properties, the thickness and the hinge), as does the MAT1's expansion coefficient where it is
    not zero. CONM2 masses on its nodes come back as :attr:`NastranBeam.tip_masses`.

    A deck without elements, with other elements, a missing or non-MAT1 material, a section that
    varies along the beam, a branched or bent chain raises :class:`~thermojitter.ParameterError`
    naming the card. Needs pyNastran (``pip install 'thermojitter[nastran]'``).
    """
    source = checks.path("path", path)
    panel = Panel.paper() if base is None else base
    check_inputs(panel)
    inertia = checks.choice("inertia", inertia, ("I1", "I2"))  # type: ignore[assignment]
    model = _read_model(source)
    beams = {eid: el for eid, el in model.elements.items() if el.type in ("CBAR", "CBEAM")}
    others = sorted({el.type for el in model.elements.values()} - {"CBAR", "CBEAM"})
    others += sorted({el.type for el in model.rigid_elements.values()})
    if others:
        raise _bad(
            "elements",
            others,
            f"the deck holds {', '.join(others)}: only CBAR and CBEAM make a panel",
        )
    if not beams:
        raise _bad("elements", 0, f"{source} holds no CBAR or CBEAM element")
    for eid, el in beams.items():
        if el.pa or el.pb:
            raise _bad(el.type, eid, f"{el.type} {eid} has pin flags: a panel is continuous")
    nodes, order = _chain({eid: (el.nodes[0], el.nodes[1]) for eid, el in beams.items()})
    missing = [n for n in nodes if n not in model.nodes]
    if missing:
        raise _bad("GRID", missing[0], f"node {missing[0]} is missing from the deck")
    for n in nodes:
        if model.nodes[n].cp != 0:
            raise _bad(
                "GRID",
                n,
                f"GRID {n} is in coordinate system {model.nodes[n].cp}: "
                "give the beam's nodes in the basic system",
            )
    xyz = np.array([model.nodes[n].xyz for n in nodes], dtype=float)
    axis = xyz[-1] - xyz[0]
    length = float(np.linalg.norm(axis))
    x = (xyz - xyz[0]) @ axis / length if length > 0 else np.zeros(len(nodes))
    off = np.linalg.norm((xyz - xyz[0]) - np.outer(x, axis / max(length, 1e-300)), axis=1)
    if length == 0 or np.any(np.diff(x) <= 0) or np.max(off) > _UNIFORM * length:
        raise _bad(
            "GRID",
            nodes[int(np.argmax(off))],
            "the beam's nodes are not in order on a straight line: a panel is straight",
        )
    sections = np.array([_section(model, beams[eid], inertia) for eid in order])
    names = ("youngs_modulus", "bending_inertia", "mass_per_length", "expansion_coeff")
    for j, name in enumerate(names):
        col = sections[:, j]
        spread = float(np.max(col) - np.min(col))
        if spread > _UNIFORM * float(np.max(np.abs(col))):
            k = int(np.argmax(np.abs(col - col[0]) > 0))
            raise _bad(
                "section",
                name,
                f"non-uniform section: {name} is {col[0]:g} on element "
                f"{order[0]} but {col[k]:g} on element {order[k]}; a panel has one "
                "section",
            )
    e_mod, i_bend, mass, alpha = (float(v) for v in sections[0])
    changes = {
        "length": length,
        "youngs_modulus": e_mod,
        "bending_inertia": i_bend,
        "mass_per_length": mass,
    }
    if alpha != 0.0:
        changes["expansion_coeff"] = alpha
    imported = panel.replace(**changes)
    position = dict(zip(nodes, x, strict=True))
    tips = []
    for eid, mass_el in sorted(model.masses.items()):
        if mass_el.type != "CONM2":
            raise _bad(
                mass_el.type, eid, f"{mass_el.type} {eid} is not supported: give masses as CONM2"
            )
        if mass_el.nid not in position:
            raise _bad("CONM2", eid, f"CONM2 {eid} sits on node {mass_el.nid}, not on the beam")
        tips.append(TipMass(int(mass_el.nid), float(position[mass_el.nid]), float(mass_el.mass)))
    return NastranBeam(
        panel=imported,
        x=np.asarray(x, dtype=float),
        nodes=tuple(int(n) for n in nodes),
        elements=tuple(int(e) for e in order),
        tip_masses=tuple(tips),
    )


__all__ = [
    "DEFAULT_MODES",
    "INSTALL_HINT",
    "PAPER_ELEMENTS",
    "NastranBeam",
    "TipMass",
    "from_nastran",
    "to_nastran",
]
