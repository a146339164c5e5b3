"""The beam comparison as a report (``thermojitter beam`` and the paper's Sec. 4.3): paper
Figs. 22–24, the convergence of the beam's frequency with its elements, the hinge model fitted to
the beam, ``beam_summary.json`` and ``beam_report.md``. The comparison itself is
:func:`thermojitter.compare_with_beam`."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from thermojitter import _core
from thermojitter.beam import (
    FIGURES,
    PAPER_NUMBERS,
    BeamComparison,
    FreeFreeBeam,
    compare_with_beam,
)
from thermojitter.calibrate import calibrate as calibrate_hinge
from thermojitter.checkpoint import write_bytes_atomic
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel, beam_frequency, hinge_stiffness
from thermojitter.reports import plots
from thermojitter.reports.distributed import hinge_vs_distributed, hinge_vs_distributed_markdown


def frequency_convergence(
    panel: Panel, element_counts: Sequence[int] = (4, 8, 16, 32, 64, 100)
) -> list[dict[str, float]]:
    """First elastic frequency (Hz) for each element count, beside the closed form
    (β₁L)² sqrt(EI/(mL⁴))/2π, with the relative error."""
    exact = beam_frequency(panel)
    rows = []
    for n in element_counts:
        f = float(FreeFreeBeam(panel, n).natural_frequencies(1)[0])
        rows.append({"n_elements": n, "frequency_hz": f, "relative_error": (f - exact) / exact})
    return rows


def _calibrations(cmp: BeamComparison, panel: Panel, orbit: Orbit) -> dict[str, Any]:
    """Fits of the hinge model to the beam's θ_f over the first 600 s after shadow entry."""
    enter = orbit.shadow_intervals(cmp.t[0], cmp.t[-1])[0][0]
    m = (cmp.t >= enter - 60.0) & (cmp.t <= enter + 600.0)
    out: dict[str, Any] = {"window": [float(cmp.t[m][0]), float(cmp.t[m][-1])]}
    freq = hinge_stiffness(panel, "frequency")
    chi = _core.derived(panel.replace(hinge_stiffness=freq).as_dict())["matching_moment_scale"]
    small_angle = hinge_stiffness(panel, "deflection_small_angle")
    ei_over_l = _core.derived(panel.as_dict())["rigidity_per_length"]
    cases: dict[str, tuple[tuple[str, ...], dict[str, float]]] = {
        "stiffness_damping": (("hinge_stiffness", "damping"), {}),
        "stiffness_damping_chi": (
            ("hinge_stiffness", "damping", "moment_scale"),
            {"hinge_stiffness": freq, "moment_scale": chi},
        ),
    }
    for name, (fit, initial) in cases.items():
        r = calibrate_hinge(
            cmp.t[m], cmp.theta_f[m], panel=panel, orbit=orbit, fit=fit, initial=initial
        )
        summary = r.summary()
        summary["initial"] = {k: float(getattr(panel, k)) for k in fit} | initial
        # In units of EI/L (4 for the small-angle deflection criterion).
        summary["hinge_stiffness_over_EI_L"] = r.parameters["hinge_stiffness"] / ei_over_l
        out[name] = summary
    out["criteria"] = {
        "deflection": hinge_stiffness(panel, "deflection"),
        "deflection_small_angle": small_angle,
        "frequency": freq,
    }
    out["note"] = calibration_note(out["stiffness_damping"], panel.damping, cmp.frequency_mismatch)
    return out


def calibration_note(fit: dict[str, Any], damping: float, mismatch: float) -> str:
    """What the fit of K_el and c_d alone to the beam's θ_f means, in words: its damping is not a
    physical estimate (the report and summary.json carry this beside the numbers)."""
    c = fit["parameters"]["damping"]
    c_err = fit["standard_errors"]["damping"]
    k = fit["parameters"]["hinge_stiffness"]
    return (
        f"Fitting K_el and c_d alone to the beam's θ_f gives K_el = {k:.0f} N m/rad "
        f"({fit['hinge_stiffness_over_EI_L']:.2f} EI/L, the static deflection of the beam) "
        f"and c_d = {c:.0f} ± {c_err:.0f} N m s/rad against the {damping:g} of the run: with "
        f"K_el matching the deflection, the hinge rings {100 * abs(mismatch):.0f}% "
        f"{'below' if mismatch < 0 else 'above'} the beam's f_n, so the least-squares fit "
        "cannot put its jitter in phase with the beam's and removes it with a "
        "large damping instead. That c_d describes the mismatch of frequencies, not the "
        "structure's damping; fitting χ as well (K_el, c_d, χ) matches both and gives a "
        "physical damping."
    )


def beam_comparison_figures(
    panel: Panel | None = None,
    orbit: Orbit | None = None,
    out_dir: str | Path = ".",
    *,
    n_elements: int = 100,
    t_span: Sequence[float] | None = None,
    calibrate: bool = True,
) -> dict[str, Any]:
    """Paper Figs. 22–24 as PNG files in ``out_dir`` and the comparison numbers.

    Cases: ``"deflection"`` (the panel's own K_el — Table 1's 4438 N m/rad is the deflection
    criterion), ``"frequency"`` (K_el = 5.21 EI/L) and ``"frequency_scaled"`` (5.21 EI/L with
    M_T scaled by χ). Figures (:data:`FIGURES`): θ and θ_f for the first two, and the spectra of
    θ and θ_f with f_n marked. Returns a JSON-ready dict: ``figures`` (paths), ``cases``
    (:meth:`BeamComparison.summary` of each), ``beam`` (frequencies and their convergence with
    the element count), ``paper`` (:data:`PAPER_NUMBERS`) and, with ``calibrate``, the hinge
    parameters fitted to the beam's θ_f (``calibration``).
    """
    panel = Panel.paper() if panel is None else panel
    orbit = Orbit.geo_equinox() if orbit is None else orbit
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    kw: dict[str, Any] = {"n_elements": n_elements, "t_span": t_span}
    cases = {
        "deflection": compare_with_beam(panel, orbit, **kw),
        "frequency": compare_with_beam(panel, orbit, criterion="frequency", **kw),
        "frequency_scaled": compare_with_beam(
            panel, orbit, criterion="frequency", scale_moment=True, **kw
        ),
    }
    figures: dict[str, str] = {}
    for key, case in (("fig22", cases["deflection"]), ("fig22b", cases["frequency"])):
        path = out / FIGURES[key]
        figures[key] = str(plots.beam_time_figure(case, orbit, plots.BEAM_NUMBERS[key], path))
    for key, case in (("fig23", cases["deflection"]), ("fig24", cases["frequency"])):
        path = out / FIGURES[key]
        figures[key] = str(plots.beam_spectrum_figure(case, plots.BEAM_NUMBERS[key], path))

    beam = FreeFreeBeam(panel, n_elements)
    result: dict[str, Any] = {
        "figures": figures,
        "cases": {name: case.summary() for name, case in cases.items()},
        "beam": {
            "n_elements": n_elements,
            "natural_frequencies_hz": [float(f) for f in beam.natural_frequencies(3)],
            "closed_form_first_hz": beam_frequency(panel),
            "convergence": frequency_convergence(panel),
            "rigid_eigenvalues": [float(v) for v in beam.rigid_eigenvalues],
            "total_mass": beam.total_mass,
            "residual_fraction": beam.residual_fraction,
        },
        "paper": dict(PAPER_NUMBERS),
    }
    if calibrate:
        result["calibration"] = _calibrations(cases["deflection"], panel, orbit)
    return result


def beam_report_markdown(result: dict[str, Any]) -> str:
    """A Markdown section for report.md from :func:`beam_comparison_figures`' result: the
    comparison numbers beside the paper's (Sec. 4.3), the frequency convergence and the fits."""
    cases = result["cases"]
    paper = result["paper"]
    beam = result["beam"]
    d, f, s = cases["deflection"], cases["frequency"], cases["frequency_scaled"]
    lines = [
        "## Hinge model against the finite-element beam (paper Sec. 4.3, Figs. 22–24)",
        "",
        f"Free–free beam, {beam['n_elements']} Hermite elements, modal transient; "
        f"modal damping ζ = {d['damping_ratio']:.3g}.",
        "",
        "| quantity | this run | paper |",
        "|---|---|---|",
        f"| beam f_n (Hz) | {beam['natural_frequencies_hz'][0]:.4f} "
        f"| {paper['natural_frequency_hz']} |",
        f"| jitter frequency of θ, K_el = {d['hinge_stiffness']:.0f} (Table 1) (Hz) "
        f"| {d['hinge_frequency_hz']:.4f} | – |",
        f"| its mismatch with f_n | {100 * d['frequency_mismatch']:+.1f}% "
        f"| about {100 * paper['frequency_mismatch']:.0f}% |",
        f"| RMSE θ − θ_f, K_el = {d['hinge_stiffness']:.0f} (Table 1) | {d['rmse_deg']:.2f}° | – |",
        f"| RMSE θ − θ_f, K_el = {f['hinge_stiffness']:.0f} = 5.21 EI/L (frequency) | "
        f"{f['rmse_deg']:.2f}° | {paper['rmse_deg']}° |",
        f"| its frequency mismatch | {100 * f['frequency_mismatch']:+.2f}% | ≈ 0 |",
        f"| RMSE θ − θ_f, 5.21 EI/L and χ = {s['moment_scale']:.3f} | {s['rmse_deg']:.2f}° | – |",
        "",
        "First free–free frequency against the element count (closed form "
        f"{beam['closed_form_first_hz']:.6f} Hz):",
        "",
        "| elements | f₁ (Hz) | relative error |",
        "|---|---|---|",
    ]
    lines += [
        f"| {row['n_elements']} | {row['frequency_hz']:.6f} | {row['relative_error']:.2e} |"
        for row in beam["convergence"]
    ]
    cal = result.get("calibration")
    if cal:
        two, three = cal["stiffness_damping"], cal["stiffness_damping_chi"]
        crit = cal["criteria"]
        lines += [
            "",
            "Hinge model fitted to the beam's θ_f (first 600 s after shadow entry):",
            "",
            f"- K_el, c_d: K_el = {two['parameters']['hinge_stiffness']:.0f} N m/rad "
            f"({two['hinge_stiffness_over_EI_L']:.2f} EI/L), c_d = "
            f"{two['parameters']['damping']:.0f} ± {two['standard_errors']['damping']:.0f} "
            f"N m s/rad, residual {two['residual_rms_deg']:.3f}°. {cal['note']}",
            f"- K_el, c_d, χ: K_el = {three['parameters']['hinge_stiffness']:.0f} N m/rad "
            f"({three['hinge_stiffness_over_EI_L']:.2f} EI/L), c_d = "
            f"{three['parameters']['damping']:.1f}, χ = {three['parameters']['moment_scale']:.3f},"
            f" residual {three['residual_rms_deg']:.4f}°",
            f"- criteria: deflection {crit['deflection']:.0f}, 4EI/L "
            f"{crit['deflection_small_angle']:.0f}, frequency {crit['frequency']:.0f} N m/rad",
        ]
    return "\n".join(lines) + "\n"


def write_beam_comparison(
    out: str | Path, n_elements: int = 100, calibrate: bool = True, distributed: bool = True
) -> int:
    """The paper's beam comparison (Figs. 22–24) for Table 1, written to ``out`` with
    ``beam_summary.json`` and ``beam_report.md``; prints one line per case. With
    ``distributed``, also the section "Hinge model vs coupled distributed panel"
    (:mod:`thermojitter.reports.distributed`)."""
    result = beam_comparison_figures(out_dir=out, n_elements=n_elements, calibrate=calibrate)
    report = beam_report_markdown(result)
    if distributed:
        result["distributed"] = hinge_vs_distributed(out_dir=out)
        report += "\n" + hinge_vs_distributed_markdown(result["distributed"])
    # Atomic: a failed write (a full disk) leaves no partial file.
    path = Path(out) / "beam_summary.json"
    write_bytes_atomic(path, json.dumps(result, indent=2).encode())
    write_bytes_atomic(Path(out) / "beam_report.md", report.encode())
    for name, case in result["cases"].items():
        print(
            f"{name:17s} K_el = {case['hinge_stiffness']:8.1f} N m/rad  chi = "
            f"{case['moment_scale']:.3f}  RMSE = {case['rmse_deg']:.3f} deg  "
            f"f_hinge = {case['hinge_frequency_hz']:.4f} Hz  "
            f"mismatch = {100 * case['frequency_mismatch']:+.1f}%"
        )
    if distributed:
        for name, case in result["distributed"]["cases"].items():
            print(f"distributed vs hinge ({name}): RMSE θ − θ_f = {case['rmse_deg']:.3f} deg")
        for row in result["distributed"]["critical_damping"]:
            print(
                f"c_d* at {row['where']:10s}: hinge {row['hinge_deflection']:.3f} (deflection), "
                f"{row['hinge_frequency']:.3f} (frequency); distributed {row['distributed']:.3f}"
            )
    print(f"beam f_n = {result['beam']['natural_frequencies_hz'][0]:.4f} Hz; wrote {path}")
    return 0
