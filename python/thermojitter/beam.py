"""The finite-element comparator of the hinge model (paper Sec. 4.3, Figs. 21–24).

A free–free Euler–Bernoulli beam with the panel's L, EI and m (Hermite cubic elements, consistent
mass, 100 elements by default) is loaded at its two free ends by the thermal moment ±M_T(t) of a
hinge-model run and solved by modal transient response (rigid-body modes set apart, the first
eight excited elastic modes integrated, the rest added quasi-statically). Its equivalent hinge
angle is θ_f = asin(2η_f/L), η_f the tip deflection relative to the centre node — the hinge
model's tips rise by (L/2) sin θ above its centre, so θ and θ_f are directly comparable.

    beam = tj.beam.FreeFreeBeam(panel)
    beam.natural_frequencies(3)                      # Hz, elastic modes only
    cmp = tj.compare_with_beam(panel, orbit, criterion="frequency")
    cmp.rmse_deg, cmp.hinge_frequency, cmp.beam_frequency
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.orbit import ECLIPSE_MARGIN, Orbit, eclipse_window
from thermojitter.panel import Panel, hinge_stiffness, natural_frequency
from thermojitter.persist import Persistent
from thermojitter.progress import interruptible
from thermojitter.signals import DEFAULT_F_MIN, dominant_frequency
from thermojitter.signals import spectrum as spectrum  # public here too, as before
from thermojitter.simulate import Method, Model, check_inputs, run_settings, simulate, time_span
from thermojitter.solver import ATOL, MAX_STEP, MAX_STEPS, RTOL, SolverSettings

Array = NDArray[np.float64]
Criterion = Literal["deflection", "deflection_small_angle", "frequency"]

DEFAULT_MARGIN = ECLIPSE_MARGIN
"""Time before shadow entry and after shadow exit in the default comparison window, s."""


def default_damping_ratio(panel: Panel) -> float:
    """Modal damping ratio of the beam matching the hinge's c_d: ζ = c_d / (2 I_B ω₁).

    ω₁ is the first free–free frequency of the continuous beam. The beam's first mode then decays
    at the hinge's rate c_d/(2 I_B), whatever K_el the hinge uses, and ζ equals the hinge's own
    c_d / (2 sqrt(K_el I_B)) when K_el follows the frequency criterion. Every mode gets this ζ.
    """
    check_inputs(panel)
    return float(_core.hinge_equivalent_damping_ratio(panel.as_dict()))


@dataclass(frozen=True)
class BeamResponse:
    """The beam under end moments ±M(t): η (m, tips relative to the centre) and θ_f (rad)."""

    t: Array
    eta: Array
    theta_f: Array
    damping_ratio: float
    n_steps: int
    n_rhs: int
    solver: SolverSettings | None = None
    """The integrator settings the engine used."""

    @property
    def theta_f_deg(self) -> Array:
        return np.degrees(self.theta_f)


class FreeFreeBeam:
    """The panel as a free–free Euler–Bernoulli beam of ``n_elements`` Hermite cubic elements
    (even, so that the centre is a node; 2 to 1000)."""

    def __init__(self, panel: Panel, n_elements: int = 100) -> None:
        check_inputs(panel)
        # Bounded here so that no integer overflows on its way (the engine wants it even, too).
        n_elements = checks.integer("n_elements", n_elements, 2, _core.BEAM_MAX_ELEMENTS)
        self.panel = panel
        self.n_elements = int(n_elements)
        self._modes = _core.beam_modes(panel.as_dict(), self.n_elements, 1)

    def __repr__(self) -> str:
        return f"FreeFreeBeam(n_elements={self.n_elements}, L={self.panel.length} m)"

    def _check_n(self, n: int) -> int:
        # At most the mesh's degrees of freedom (the engine checks the exact count).
        return checks.integer("n", n, 1, 2 * self.n_elements)

    def natural_frequencies(self, n: int = 3) -> Array:
        """The first ``n`` elastic free–free frequencies, Hz (rigid-body modes excluded)."""
        d = _core.beam_modes(self.panel.as_dict(), self.n_elements, self._check_n(n))
        return np.asarray(d["frequencies_hz"])

    def mode_shapes(self, n: int = 3) -> tuple[Array, Array]:
        """Node positions x (m) and the deflections of the first ``n`` elastic modes at the nodes,
        shape (nodes, n), mass-normalised (φᵀMφ = 1, in 1/sqrt(kg)), positive at x = 0."""
        d = _core.beam_modes(self.panel.as_dict(), self.n_elements, self._check_n(n))
        return np.asarray(d["x"]), np.asarray(d["shapes"])

    @property
    def rigid_eigenvalues(self) -> Array:
        """ω² of the two rigid-body modes, (rad/s)²: zero up to rounding."""
        return np.asarray(self._modes["rigid_eigenvalues"])

    @property
    def total_mass(self) -> float:
        """uᵀ M u for a unit rigid translation u: the mass the mesh carries, kg."""
        return float(self._modes["total_mass"])

    @property
    def residual_fraction(self) -> float:
        """Share of the static end-moment flexibility carried by the modes not integrated."""
        return float(self._modes["residual_flexibility"] / self._modes["flexibility"])

    def static_tip_deflection(self, moment: float) -> float:
        """η (m) under steady end moments ±``moment`` (N m); exact value M L²/(8EI)."""
        moment = checks.finite("moment", moment)
        return float(_core.beam_static(self.panel.as_dict(), self.n_elements, moment))

    def response(
        self,
        times: ArrayLike,
        moments: ArrayLike,
        *,
        t_span: Sequence[float] | None = None,
        damping_ratio: float | None = None,
        residual: bool = True,
        method: Method = "rk45",
        rtol: float = RTOL,
        atol: float = ATOL,
        dt: float | None = None,
        t_eval: ArrayLike | None = None,
        dt_out: float | None = None,
        max_step: float = MAX_STEP,
        max_steps: int = MAX_STEPS,
        solver: SolverSettings | None = None,
    ) -> BeamResponse:
        """Modal transient response to end moments ±M(t), M given as samples ``moments`` (N m)
        at ``times`` (s, increasing; linear in between, held beyond the ends).

        Starts at rest in the static deflection under M(t0). ``t_span`` defaults to the sample
        span and the output to the sample times. ``damping_ratio`` ζ applies to every mode
        (default :func:`default_damping_ratio`, from the panel's c_d). ``residual=False`` drops
        the quasi-static part of the modes not integrated. Ctrl-C stops the run within one
        integration step (``KeyboardInterrupt``).
        """
        ts = checks.real_array("times", times)
        ms = checks.real_array("moments", moments)
        if ts.size < 2 or ts.size != ms.size:
            raise checks.ParameterError(
                "times" if ts.size < 2 else "moments",
                times if ts.size < 2 else moments,
                message=f"times/moments hold {ts.size}/{ms.size} values: need two or more, equal "
                "lengths",
            )
        t0, t1 = (float(ts[0]), float(ts[-1])) if t_span is None else time_span(t_span)
        if t_eval is None and dt_out is None:
            t_eval = ts[(ts >= t0) & (ts <= t1)]
        zeta = (
            default_damping_ratio(self.panel)
            if damping_ratio is None
            else checks.finite("damping_ratio", damping_ratio)
        )
        residual = checks.flag("residual", residual)
        used, run = run_settings(
            solver, (t0, t1), t_eval, dt_out, method=method, rtol=rtol, atol=atol, dt=dt,
            max_step=max_step, max_steps=max_steps,
        )  # fmt: skip
        raw = interruptible(
            _core.beam_response,
            self.panel.as_dict(),
            self.n_elements,
            ts,
            ms,
            run,
            damping_ratio=float(zeta),
            residual=bool(residual),
        )
        return BeamResponse(
            t=raw["t"],
            eta=raw["eta"],
            theta_f=raw["theta_f"],
            damping_ratio=float(zeta),
            n_steps=raw["n_steps"],
            n_rhs=raw["n_rhs"],
            solver=SolverSettings(**raw["solver"]),
        )

    def theta_f(self, times: ArrayLike, moments: ArrayLike, **kwargs: Any) -> Array:
        """θ_f(t) = asin(2η/L) (rad) at ``times`` for the moment history; see :meth:`response`."""
        return self.response(times, moments, **kwargs).theta_f


CRITERION_LABELS = {
    "panel": "panel value",
    "deflection": "deflection criterion",
    "deflection_small_angle": "4EI/L",
    "frequency": "frequency criterion, 5.21 EI/L",
}
"""Words for each ``BeamComparison.criterion``."""


@dataclass(frozen=True)
class BeamComparison(Persistent):
    """The hinge model and the beam through an eclipse (paper Figs. 22–24).

    Angles in rad (``*_deg`` for degrees), frequencies in Hz, the moment in N m (the physical
    a E I ΔT/d that loads the beam, without χ).
    """

    t: Array
    theta: Array
    theta_f: Array
    moment: Array
    rmse_deg: float
    hinge_frequency: float
    """Dominant frequency of θ (FFT), Hz."""
    beam_frequency: float
    """Dominant frequency of θ_f (FFT), Hz."""
    natural_frequency: float
    """f_n, the beam's first elastic frequency (finite elements), Hz."""
    hinge_natural_frequency: float
    """sqrt(K_el/I_B)/2π of the hinge model, Hz."""
    hinge_stiffness: float
    moment_scale: float
    damping_ratio: float
    criterion: str
    settings: dict[str, Any] = field(default_factory=dict, repr=False)

    xarray_dims: ClassVar[dict[str, tuple[str, ...]]] = {
        name: ("t",) for name in ("t", "theta", "theta_f", "moment")
    }

    @property
    def frequency_mismatch(self) -> float:
        """(f_hinge − f_n)/f_n of the dominant jitter frequency of θ."""
        return (self.hinge_frequency - self.natural_frequency) / self.natural_frequency

    @property
    def criterion_label(self) -> str:
        """How K_el was chosen, in words (for figures and reports)."""
        return CRITERION_LABELS.get(self.criterion, self.criterion)

    @property
    def theta_deg(self) -> Array:
        return np.degrees(self.theta)

    @property
    def theta_f_deg(self) -> Array:
        return np.degrees(self.theta_f)

    def summary(self) -> dict[str, float | str]:
        """The comparison numbers (JSON-ready)."""
        return {
            "criterion": self.criterion,
            "hinge_stiffness": self.hinge_stiffness,
            "moment_scale": self.moment_scale,
            "damping_ratio": self.damping_ratio,
            "rmse_deg": self.rmse_deg,
            "hinge_frequency_hz": self.hinge_frequency,
            "beam_frequency_hz": self.beam_frequency,
            "natural_frequency_hz": self.natural_frequency,
            "hinge_natural_frequency_hz": self.hinge_natural_frequency,
            "frequency_mismatch": self.frequency_mismatch,
            "t_start": float(self.t[0]),
            "t_end": float(self.t[-1]),
        }


def compare_with_beam(
    panel: Panel,
    orbit: Orbit,
    *,
    criterion: Criterion | None = None,
    scale_moment: bool = False,
    t_span: Sequence[float] | None = None,
    dt_out: float = 0.5,
    n_elements: int = 100,
    damping_ratio: float | None = None,
    model: Model = "nonlinear",
    coupled: bool = True,
    f_min: float = DEFAULT_F_MIN,
    rtol: float = RTOL,
    atol: float = ATOL,
) -> BeamComparison:
    """Runs the hinge model and the beam through an eclipse and compares θ(t) with θ_f(t).

    - ``criterion``: ``None`` keeps the panel's own ``hinge_stiffness``; otherwise K_el is set by
      :func:`thermojitter.hinge_stiffness` (``"deflection"``, ``"deflection_small_angle"``,
      ``"frequency"`` ≈ 5.21 EI/L).
    - ``scale_moment``: also scale the thermal moment of the hinge model by
      χ = K_el L/(4EI) (paper Sec. 4.3: 5.21/4 ≈ 1.3 with the frequency criterion). The beam is
      always loaded by the physical moment a E I ΔT/d.
    - ``t_span``: default the first eclipse with :data:`DEFAULT_MARGIN` of sunlight either side;
      the hinge model starts from its sunlit equilibrium, the beam at rest in its static shape.
    - ``damping_ratio``: of every beam mode; default :func:`default_damping_ratio`, the same
      beam whatever the criterion.

    ``rmse_deg`` is the RMS of θ − θ_f over the window; the dominant frequencies come from the
    FFT of each signal above ``f_min`` (Hz).
    """
    check_inputs(panel, orbit)
    # Every argument checked before any work (the runs below would check some, too late).
    scale_moment = checks.flag("scale_moment", scale_moment)
    coupled = checks.flag("coupled", coupled)
    model = checks.choice("model", model, ("nonlinear", "linear"))  # type: ignore[assignment]
    dt_out = checks.positive("dt_out", dt_out)
    f_min = checks.positive("f_min", f_min)
    if damping_ratio is not None:
        damping_ratio = checks.finite("damping_ratio", damping_ratio)
    hinge_panel = panel
    if criterion is not None:
        hinge_panel = panel.replace(hinge_stiffness=hinge_stiffness(panel, criterion))
    if scale_moment:
        chi = _core.derived(hinge_panel.as_dict())["matching_moment_scale"]
        hinge_panel = hinge_panel.replace(moment_scale=chi)
    span = eclipse_window(orbit) if t_span is None else time_span(t_span)
    if span[1] - span[0] < 16 * dt_out:
        raise checks.ParameterError("t_span", span, "shorter than 16 samples of dt_out")
    if (span[1] - span[0]) / dt_out > _core.MAX_SAMPLES:
        raise checks.ParameterError(
            "dt_out", dt_out, f"would keep more than {_core.MAX_SAMPLES} samples of t_span"
        )
    # Uniform samples (the FFT needs them): the last one may fall short of t_span[1].
    samples = span[0] + dt_out * np.arange(int((span[1] - span[0]) / dt_out) + 1)
    sol = simulate(
        hinge_panel, orbit, span, model=model, coupled=coupled, t_eval=samples, rtol=rtol, atol=atol
    )
    beam_panel = panel.replace(moment_scale=1.0)
    physical = _core.moment(beam_panel.as_dict(), sol.T_front, sol.T_back)
    beam = FreeFreeBeam(beam_panel, n_elements)
    zeta = default_damping_ratio(panel) if damping_ratio is None else damping_ratio
    resp = beam.response(sol.t, physical, damping_ratio=zeta, rtol=rtol, atol=atol)
    theta = np.asarray(sol.theta)
    diff = theta - resp.theta_f
    f_n = float(beam.natural_frequencies(1)[0])
    return BeamComparison(
        t=np.asarray(sol.t),
        theta=theta,
        theta_f=resp.theta_f,
        moment=physical,
        rmse_deg=float(np.degrees(np.sqrt(np.mean(diff**2)))),
        hinge_frequency=dominant_frequency(sol.t, theta, f_min),
        beam_frequency=dominant_frequency(resp.t, resp.theta_f, f_min),
        natural_frequency=f_n,
        hinge_natural_frequency=natural_frequency(hinge_panel),
        hinge_stiffness=hinge_panel.hinge_stiffness,
        moment_scale=hinge_panel.moment_scale,
        damping_ratio=zeta,
        criterion="panel" if criterion is None else criterion,
        settings={"model": model, "coupled": coupled, "n_elements": n_elements, "dt_out": dt_out},
    )


PAPER_NUMBERS = {"natural_frequency_hz": 0.144, "rmse_deg": 0.93, "frequency_mismatch": 0.12}
"""What the paper reports for Table 1 (Sec. 4.3): f_n, RMSE of θ − θ_f with K_el = 5.21 EI/L,
and the jitter-frequency mismatch with the deflection criterion (about 12%)."""

FIGURES = {
    "fig22": "fig22_theta_deflection.png",
    "fig22b": "fig22b_theta_frequency.png",
    "fig23": "fig23_fft_deflection.png",
    "fig24": "fig24_fft_frequency.png",
}
"""File names of the beam comparison figures (paper Figs. 22–24), by figure."""
