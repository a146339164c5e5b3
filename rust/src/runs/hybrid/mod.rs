//! The hybrid long-run propagator: the same per-orbit summaries as the hinge-resolved integration
//! of [`crate::runs::orbits::run_orbits`], at a small fraction of the cost.
//!
//! Three regimes, chosen as the run goes:
//!
//! - **Linear arcs** (sunlit, near the equilibrium): the linearised system about the sunlit
//!   equilibrium, with the Sun's slow distance drift as a forcing, propagated exactly in modal form
//!   ([`linear`]), one arc per orbit at most; the summaries over the arc come from the closed form.
//!   No numerical dissipation, so weak flutter grows at exactly the eigenvalue's rate.
//! - **Exponential stretches** (shadow crossings and the thermal recovery after them): the full
//!   non-linear model, integrated by the exponential Rosenbrock method [`exprb`], whose step is set
//!   by the slow thermal non-linearity rather than the hinge period.
//! - **Full integration** (the fallback): Dormand–Prince with the step capped at T_n/40, as
//!   [`crate::runs::orbits::run_orbits`], for an orbit at a time, where the oscillation is too large for
//!   the linearisation or the modal decomposition is ill-conditioned.
//!
//! The switch back to linear arcs is guarded by a measured criterion: the non-linear remainder
//! r = f(y) − A (y − y_eq), expressed as the static angle error it would cause (|A⁻¹|_θ·|r|), must
//! be below `linear_tolerance`, the oscillation below `linear_amplitude`, the plate in full Sun and
//! past the last shadow exit by the summary window.

pub mod expm;
pub mod exprb;
pub mod jacobian;
#[cfg(test)]
mod laminate_tests;
pub mod layered;
pub mod linear;
pub(crate) mod model;
pub mod pieces;
pub mod slow;
pub(crate) mod tabulated;

use crate::cancel::Cancel;
use crate::error::{require_positive, Error, Result};
use crate::inputs::orbit::{breakpoints_of, Eclipse, EclipseTable, Orbit};
use crate::inputs::panel::Panel;
use crate::numerics::chebyshev::EndpointInterpolant;
use crate::numerics::integrate::{solve, DenseStep, Method, Observer, OdeSystem, Stats};
use crate::runs::orbits::{
    resolve_hinge, Collector, OrbitRun, OrbitRunRequest, OrbitRunSpec, Summarised, SummaryObserver,
    STEPS_PER_HINGE_PERIOD,
};
use exprb::{ExpStep, ExpTolerances};
use linear::{Arc, HingeMode};
use model::{HybridModel, TwoLayerModel};
use nalgebra::{Const, SMatrix, SVector, Vector4};
use std::cell::Cell;
use std::ops::ControlFlow;

/// Settings of the hybrid propagator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HybridSettings {
    /// Error control of the exponential stretches.
    pub tolerances: ExpTolerances,
    /// Largest non-linear remainder, as a static angle error (rad), at which the state is handed
    /// back to linear propagation.
    pub linear_tolerance: f64,
    /// Largest oscillation amplitude |θ − θ_eq| (rad) propagated linearly; larger oscillations
    /// are integrated in full.
    pub linear_amplitude: f64,
    /// Largest hinge oscillation (about the quasi-static deflection, rad) left to the exponential
    /// integrator, whose summaries take it through its envelope; a larger one (the ringing after
    /// the flux jump of a cylindrical shadow) is integrated in full until the state is linear.
    pub resolved_amplitude: f64,
}

impl Default for HybridSettings {
    fn default() -> Self {
        HybridSettings {
            tolerances: ExpTolerances {
                rtol: 1e-4,
                atol_temperature: 1e-2,
                atol_angle: 1e-6,
                max_step: 300.0,
            },
            linear_tolerance: 1e-7,
            linear_amplitude: 0.01,
            resolved_amplitude: 1e-4,
        }
    }
}

impl HybridSettings {
    pub fn validate(&self) -> Result<()> {
        require_positive("hybrid.rtol", self.tolerances.rtol)?;
        require_positive("hybrid.atol_temperature", self.tolerances.atol_temperature)?;
        require_positive("hybrid.atol_angle", self.tolerances.atol_angle)?;
        require_positive("hybrid.max_step", self.tolerances.max_step)?;
        require_positive("hybrid.linear_tolerance", self.linear_tolerance)?;
        require_positive("hybrid.linear_amplitude", self.linear_amplitude)?;
        require_positive("hybrid.resolved_amplitude", self.resolved_amplitude)
    }
}

/// A hybrid run: the summaries and how the simulated time was split between the regimes.
#[derive(Debug, Clone)]
pub struct HybridRun {
    pub run: OrbitRun,
    /// Simulated time propagated by linear arcs, by the exponential integrator (full non-linear
    /// model) and by the hinge-resolved fallback (full non-linear model), s.
    pub t_linear: f64,
    pub t_exponential: f64,
    pub t_fallback: f64,
    pub n_arcs: u64,
    pub n_exp_steps: u64,
    pub n_fallback_steps: u64,
    /// Exponential steps whose band of θ failed its check and that were read again, resolving
    /// the hinge.
    pub n_reread_steps: u64,
    /// Simulated time carried on slow time ([`slow`]: short orbits, varying loads), s, and its
    /// steps.
    pub t_slow: f64,
    pub n_slow_steps: u64,
    /// Orbits the slow-time guards gave back to the full integration.
    pub n_refused_orbits: u64,
    /// Of those, how many each guard gave back: thermal rates not slow against the hinge, the
    /// ringing past its limit, a split that did not converge, |θ| past the run's limit, a
    /// summary too near 0 for the accuracy the orbit's check vouches for, and a ringing that
    /// grows over the orbit (flutter).
    pub n_refused_separation: u64,
    pub n_refused_ringing: u64,
    pub n_refused_split: u64,
    pub n_refused_limit: u64,
    pub n_refused_gate: u64,
    pub n_refused_growth: u64,
    /// Orbits of which slow time could not vouch for a window's summaries alone (too near 0):
    /// each ran in full from its start to that window's end, then on slow time (not given back,
    /// not in `n_refused_orbits`).
    pub n_refused_windows: u64,
    /// Pieces a long slow-time run was cut into to run on several cores ([`pieces`]; 1 for a
    /// run in one piece, 0 off slow time), the orbits their warm-ups ran (not summarised), and
    /// the pieces run again in order because their warmed-up start missed.
    pub n_pieces: u64,
    pub n_warmup_orbits: u64,
    pub n_pieces_rerun: u64,
}

impl HybridRun {
    /// Adds the counters of `other`, a run that follows this one (the `run`s are left).
    pub(crate) fn add(&mut self, other: &HybridRun) {
        self.t_linear += other.t_linear;
        self.t_exponential += other.t_exponential;
        self.t_fallback += other.t_fallback;
        self.n_arcs += other.n_arcs;
        self.n_exp_steps += other.n_exp_steps;
        self.n_fallback_steps += other.n_fallback_steps;
        self.n_reread_steps += other.n_reread_steps;
        self.t_slow += other.t_slow;
        self.n_slow_steps += other.n_slow_steps;
        self.n_refused_orbits += other.n_refused_orbits;
        self.n_refused_separation += other.n_refused_separation;
        self.n_refused_ringing += other.n_refused_ringing;
        self.n_refused_split += other.n_refused_split;
        self.n_refused_limit += other.n_refused_limit;
        self.n_refused_gate += other.n_refused_gate;
        self.n_refused_growth += other.n_refused_growth;
        self.n_refused_windows += other.n_refused_windows;
        self.n_pieces += other.n_pieces;
        self.n_warmup_orbits += other.n_warmup_orbits;
        self.n_pieces_rerun += other.n_pieces_rerun;
    }
}

impl Default for HybridRun {
    /// No orbit run, every time and count zero: what a run fills in, and what a path that has no
    /// hybrid reports.
    fn default() -> Self {
        HybridRun {
            run: OrbitRun {
                summaries: Vec::new(),
                stats: Stats::default(),
                y_end: Vector4::zeros(),
                crossing: None,
            },
            t_linear: 0.0,
            t_exponential: 0.0,
            t_fallback: 0.0,
            n_arcs: 0,
            n_exp_steps: 0,
            n_fallback_steps: 0,
            n_reread_steps: 0,
            t_slow: 0.0,
            n_slow_steps: 0,
            n_refused_orbits: 0,
            n_refused_separation: 0,
            n_refused_ringing: 0,
            n_refused_split: 0,
            n_refused_limit: 0,
            n_refused_gate: 0,
            n_refused_growth: 0,
            n_refused_windows: 0,
            n_pieces: 0,
            n_warmup_orbits: 0,
            n_pieces_rerun: 0,
        }
    }
}

/// What the state at a sunlit time allows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Regime {
    Linear,
    NonLinear,
    Large,
}

struct Driver<'a, const N: usize, M: HybridModel<N>> {
    orbit: Orbit,
    settings: &'a HybridSettings,
    fallback: Method,
    system: M,
    obs: SummaryObserver<'a, M::View>,
    t_start: f64,
    t_end: f64,
    t: f64,
    y: SVector<f64, N>,
    h_exp: f64,
    stats: Stats,
    out: HybridRun,
    judge: Judge<N, M>,
    eclipses: EclipseTable,
}

/// A hybrid run of any model: the summaries, the counters, the end state.
pub(crate) struct Propagated<const N: usize> {
    pub run: Summarised<Const<N>>,
    /// How the time was split (its `run` is left empty: `run` above holds it).
    pub split: HybridRun,
}

/// Integrates the orbits of `req` with the hybrid propagator and summarises each orbit;
/// `req.spec.method` is the full integration used as the fallback.
pub fn run_orbits_hybrid(
    req: &OrbitRunRequest,
    settings: &HybridSettings,
    cancel: &Cancel,
) -> Result<HybridRun> {
    let OrbitRunRequest { ref spec, y0 } = *req;
    spec.panel.validate()?;
    check_request(spec, y0.as_slice(), settings, cancel)?;
    if slow::applies(spec) {
        let done = pieces::run_in_pieces(spec, y0, cancel)?;
        return Ok(HybridRun {
            run: done.run,
            ..done.split
        });
    }
    if spec.orbit.has_face_loads() {
        return Ok(fully_integrated(
            crate::runs::orbits::run_orbits_cancellable(req, cancel)?,
        ));
    }
    let model = TwoLayerModel::new(&spec.panel, &spec.orbit, spec.model, spec.coupling);
    let done = propagate(model, spec, y0, settings, cancel)?;
    let mut out = done.split;
    out.run = done.run;
    Ok(out)
}

/// A run integrated in full, hinge resolved, reported as a hybrid run's: all of its time and
/// steps counted as the fallback's. The hybrid's linear arcs and exponential steps take the
/// sunlit forcing as constant between eclipses; the Earth's loads and an attitude other than
/// Sun-pointing make it vary along every arc, so such an orbit runs here, at the accuracy of
/// the full integration.
fn fully_integrated(run: OrbitRun) -> HybridRun {
    let split = counted_as_fallback(&run.summaries, run.stats.n_steps);
    HybridRun { run, ..split }
}

/// The split of a run integrated in full over `summaries`' orbits with `n_steps` steps: all of
/// its time and steps the fallback's (its `run` left empty, as [`Propagated::split`]'s).
pub(crate) fn counted_as_fallback(
    summaries: &[crate::runs::orbits::OrbitSummary],
    n_steps: u64,
) -> HybridRun {
    HybridRun {
        t_fallback: summaries.iter().map(|s| s.t_end - s.t_start).sum(),
        n_fallback_steps: n_steps,
        ..HybridRun::default()
    }
}

/// Checks what every hybrid run is asked (the panel is checked by its model).
pub(crate) fn check_request(
    spec: &OrbitRunSpec,
    y0: &[f64],
    settings: &HybridSettings,
    cancel: &Cancel,
) -> Result<()> {
    cancel.check()?;
    spec.options.check()?;
    settings.validate()?;
    spec.orbit.validate()?;
    spec.method.validate()?;
    if spec.n_orbits == 0 {
        return Err(Error::invalid("n_orbits", 0, "must be >= 1"));
    }
    crate::error::require_finite("t_start", spec.t_start)?;
    if let Some(v) = y0.iter().find(|v| !v.is_finite()) {
        return Err(Error::invalid("y0", v, "every component must be finite"));
    }
    Ok(())
}

/// The hybrid propagation of `model` (checked by the caller) over the orbits of `spec` from
/// (t_start, y0).
pub(crate) fn propagate<const N: usize, M: HybridModel<N>>(
    model: M,
    spec: &OrbitRunSpec,
    y0: SVector<f64, N>,
    settings: &HybridSettings,
    cancel: &Cancel,
) -> Result<Propagated<N>> {
    let (orbit, t_start, options) = (&spec.orbit, spec.t_start, spec.options);
    let panel = *model.panel();
    let steps = if options.steps_per_period > 0.0 {
        options.steps_per_period
    } else {
        STEPS_PER_HINGE_PERIOD
    };
    let collector = Collector::new(model.view(), spec, y0[N - 2])?;
    let t_end = spec.t_end();
    let flux0 = orbit.flux_scale(t_start);
    let y_eq = model.equilibrium(flux0, None).ok();
    let t_ref = y_eq.map(|e| e[0]).unwrap_or(300.0);
    let wn = panel.natural_angular_frequency();
    let scale = SVector::from_fn(|i, _| match N - i {
        2 => 1.0 / t_ref,
        1 => wn / t_ref,
        _ => 1.0,
    });
    let modal = y_eq.is_some_and(|y| has_fast_thermal_mode(&model.jacobian(flux0, &y), &scale, wn));
    let fastest_rate = y_eq.map_or(f64::INFINITY, |y| {
        fastest_rate(&model.jacobian(flux0, &y), &scale)
    });
    let mut d = Driver {
        orbit: *orbit,
        settings,
        fallback: resolve_hinge(&spec.method, &panel, steps),
        system: model.clone(),
        obs: SummaryObserver {
            collector,
            error: None,
            cancel,
        },
        t_start,
        t_end,
        t: t_start,
        y: y0,
        h_exp: 1.0,
        stats: Stats {
            t_end: t_start,
            ..Stats::default()
        },
        out: HybridRun::default(),
        judge: Judge {
            panel,
            orbit: *orbit,
            settings: *settings,
            model,
            last: Cell::new(None),
            scale,
            modal,
            fastest_rate,
            drift_spent: Cell::new(Drift::default()),
        },
        eclipses: EclipseTable::until(orbit, t_end),
    };
    d.run()?;
    let Driver {
        obs,
        out,
        mut stats,
        t,
        y,
        ..
    } = d;
    stats.t_end = t;
    stats.stopped = t < t_end && obs.collector.crossing.is_some();
    Ok(Propagated {
        run: obs.collector.finish(stats, y),
        split: out,
    })
}

/// A model over a span the caller knows to hold none of its breakpoints (a segment between
/// the exponential integrator's cuts): the integrator then does not search the orbit for them
/// again. The flux of the last time asked is kept: RK4 asks twice at each time (its two middle
/// stages, its last stage and the next step's first). Bit for bit the model's own right-hand
/// side, which is f(flux(t), y), except across a partial shadow ([`WithinSegment::partial`]).
struct WithinSegment<'a, M> {
    model: &'a mut M,
    last: Cell<(f64, f64)>,
    /// Whether the span is a partial shadow, whose flux (the two discs' overlap, a dozen
    /// trigonometric functions) is then read off an interpolant fitted on entering it.
    partial: bool,
    track: Option<EndpointInterpolant>,
}

/// The largest error of the flux's interpolant across a partial shadow (a fraction of the
/// flux at 1 au), checked on each of its parts after the fit (a part beyond it is evaluated
/// exactly). The exact flux's own rounding there is ~5e-11 (the lens of two discs near
/// tangency); 1e-10 moves the temperatures by ~1e-10 of themselves, far below the full
/// integration's tolerances and the summaries' gate.
const PARTIAL_SHADOW_FLUX_TOL: f64 = 1e-10;

impl<'a, M> WithinSegment<'a, M> {
    fn new(model: &'a mut M) -> Self {
        WithinSegment {
            model,
            last: Cell::new((f64::NAN, 0.0)),
            partial: false,
            track: None,
        }
    }

    /// Over a partial shadow: the flux through an interpolant ([`EndpointInterpolant`], its
    /// ends the shadow's contacts, where the overlap grows like (t − a)^{3/2}).
    fn partial(model: &'a mut M) -> Self {
        WithinSegment {
            partial: true,
            ..WithinSegment::new(model)
        }
    }
}

impl<const N: usize, M: HybridModel<N>> OdeSystem<Const<N>> for WithinSegment<'_, M> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &SVector<f64, N>) -> SVector<f64, N> {
        let flux = match self.last.get() {
            (at, flux) if at == t => flux,
            _ => {
                let flux = match self.track.as_ref().and_then(|p| p.at(t)) {
                    Some(flux) => flux,
                    None => self.model.flux_at(t),
                };
                self.last.set((t, flux));
                flux
            }
        };
        self.model.rhs_at_flux(flux, y)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.model.enter_segment(a, b);
        self.last.set((f64::NAN, 0.0));
        self.track = (self.partial && b > a).then(|| {
            let model = &*self.model;
            EndpointInterpolant::fit(|t| model.flux_at(t), a, b, PARTIAL_SHADOW_FLUX_TOL)
        });
    }
}

/// The tests that decide the regime: everything they need, apart from the driver so that the
/// fallback's observer can use them too.
#[derive(Clone)]
struct Judge<const N: usize, M> {
    panel: Panel,
    orbit: Orbit,
    settings: HybridSettings,
    model: M,
    /// The last equilibrium and its flux: the next one, at a flux that has barely changed, is
    /// found by Newton's method from it.
    last: Cell<Option<(f64, SVector<f64, N>)>>,
    /// Units of the state for the modal decompositions.
    scale: SVector<f64, N>,
    /// Whether a thermal mode is not slow against the hinge (thin metal: fast conduction); the
    /// oscillation is then measured on the hinge's own mode, not about M_T/K_el (whose rate
    /// follows the fast thermal transient, which the hinge does not).
    modal: bool,
    /// |λ| of the Jacobian's fastest mode at the start, 1/s (infinite where unknown): whether a
    /// fixed-step RK4 run of the model is stable.
    fastest_rate: f64,
    /// The drift in θ that linear arcs have left in the state.
    drift_spent: Cell<Drift>,
}

/// An error (rad) in the hinge's oscillation at time `at`: it decays (or grows) with the
/// oscillation, at the rate Re λ of the hinge mode.
#[derive(Debug, Clone, Copy, Default)]
struct Drift {
    error: f64,
    at: f64,
    rate: f64,
}

impl Drift {
    fn at(&self, t: f64) -> f64 {
        self.error * (self.rate * (t - self.at)).min(50.0).exp()
    }
}

/// A linear arc ready to run: the arc, its equilibrium and flux, and the drift it leaves.
struct ArcPlan<const N: usize> {
    arc: Arc<N>,
    y_ref: SVector<f64, N>,
    flux0: f64,
    drift: Drift,
}

/// A thermal mode faster than this fraction of the hinge's angular frequency makes the
/// quasi-static measure of the oscillation (about M_T/K_el with its rate) unreliable: the rate
/// it attributes to the hinge is off by about the ratio.
const QUASI_STATIC_RATIO: f64 = 0.1;

/// The largest drift in θ that linear arcs may leave, relative to the jitter the summaries read
/// and in rad: half the accuracy gate (2 %, 1e-6 rad). The estimate is an upper bound (the
/// largest error along the arc, and the arcs' errors added): on Table 1 near its critical
/// damping it is about three times the drift measured against the full integration.
pub(crate) const DRIFT_RTOL: f64 = 1e-2;
pub(crate) const DRIFT_ATOL: f64 = 5e-7;

/// How far the interpolant of an exponential step may stray from the step's own formula in what
/// the summaries read (θ and M_T/K_el), in rad and relative to the deviation from θ_eq.
const READ_ATOL: f64 = 1e-7;
const READ_RTOL: f64 = 1e-3;

/// How far the oscillation's amplitude measured at a step's middle may stray from the band's
/// interpolation between its ends, relative to the largest oscillation the summaries read (with
/// [`READ_ATOL`]): a tenth of the 2 % gate.
const BAND_RTOL: f64 = 2e-3;

/// Hinge periods resolved after partial shadow, where the flux stops moving and the hinge's lag
/// behind M_T/K_el is released (on Table 1 at equinox the orbit's jitter peak comes 1.7 s after
/// the last contact).
const RESOLVED_AFTER_PARTIAL_SHADOW: f64 = 2.0;

/// Points read per hinge period off a step's formula where its band cannot be trusted (the peak
/// of a sine sampled at 32 points is within 0.5 % of the true one). No cap: fewer would miss
/// the peaks silently.
const REREADS_PER_PERIOD: f64 = 32.0;
/// RK4 steps per hinge period where the hinge is resolved without a fast thermal mode: the
/// amplitude's error is (ωh)⁶/144 ≈ 7e-6 per step, 0.2 % over fifty periods (the summaries read
/// the extremes off each step's cubic, not at its ends).
const RK4_STEPS_PER_PERIOD: f64 = 20.0;

/// Largest |λ| dt of a fixed-step RK4 run of the hinge: well inside RK4's stability bound on the
/// real axis (2.78), so that a fast thermal mode decays in it as it does in the model.
const RK4_STABLE_STEP: f64 = 1.0;

/// Samples per hinge period of the linearisation's defect along an arc (the defect's harmonics
/// up to the third stay apart from the first), and how often the points where it is read
/// double in distance from the arc's start at most.
const DRIFT_SAMPLES: usize = 8;
const DRIFT_DOUBLINGS: f64 = 10.0;

/// The jitter RMS the summaries read, the scale of the smallest error the gate holds them to:
/// the last whole orbit's, else this orbit's so far (0 before any oscillation).
pub(crate) fn gate_scale<V: crate::runs::orbits::SummaryView>(collector: &Collector<V>) -> f64 {
    match collector.done.last() {
        Some(s) if s.jitter_rms.is_finite() => s.jitter_rms,
        _ => collector.rms_so_far(),
    }
}

/// Whether the Jacobian `a` has a real (thermal) mode faster than [`QUASI_STATIC_RATIO`] of the
/// hinge's angular frequency `wn`.
fn has_fast_thermal_mode<const N: usize>(
    a: &SMatrix<f64, N, N>,
    scale: &SVector<f64, N>,
    wn: f64,
) -> bool {
    linear::balanced_eigenvalues(a, scale)
        .1
        .iter()
        .any(|l| l.im.abs() <= 1e-9 * l.norm() && l.norm() > QUASI_STATIC_RATIO * wn)
}

/// |λ| of the fastest mode of the Jacobian `a`, 1/s.
fn fastest_rate<const N: usize>(a: &SMatrix<f64, N, N>, scale: &SVector<f64, N>) -> f64 {
    linear::balanced_eigenvalues(a, scale)
        .1
        .iter()
        .map(|l| l.norm())
        .fold(0.0, f64::max)
}

impl<const N: usize, M: HybridModel<N>> Judge<N, M> {
    /// The sunlit equilibrium and Jacobian at the flux of time t.
    fn reference(&self, flux: f64) -> Result<(SVector<f64, N>, SMatrix<f64, N, N>)> {
        let y_ref = match self.last.get() {
            Some((f, y)) if f == flux => y,
            Some((_, y)) => self.model.equilibrium(flux, Some(&y))?,
            None => self.model.equilibrium(flux, None)?,
        };
        self.last.set(Some((flux, y_ref)));
        Ok((y_ref, self.model.jacobian(flux, &y_ref)))
    }

    /// Amplitude of the hinge oscillation: about the quasi-static deflection M_T/K_el, from the
    /// dynamic part and its rate; with fast thermal modes, the θ amplitude of the hinge mode of
    /// the Jacobian at y, whose coordinate about the state's own fixed point y* = y − J⁻¹f is
    /// w·J⁻¹f = (w·f)/λ.
    fn oscillation(&self, flux: f64, y: &SVector<f64, N>, f: &SVector<f64, N>) -> f64 {
        if self.modal {
            if let Some(mode) = HingeMode::of(&self.model.jacobian(flux, y), &self.scale) {
                return mode.theta_amplitude(N - 2, mode.coordinate(f) / mode.lambda);
            }
        }
        let (quasi_static, rate) = self.model.static_angle(flux, y, f);
        let d = y[N - 2] - quasi_static;
        let d_rate = y[N - 1] - rate;
        let inertia = self.model.hinge().inertia_factor(y[N - 2].sin());
        let w2 = self.panel.hinge_stiffness / (self.panel.hinge_inertia() * inertia);
        (d * d + d_rate * d_rate / w2).sqrt()
    }

    /// The error (rad) that the linearisation makes over a sunlit arc from t0: (the largest the
    /// summaries see, in θ at its end, the hinge's rate Re λ at which it then decays). The arc's defect d(τ) = y_L' − f(y_L) drives the error of the
    /// hinge coordinate c as ε' = λε − w·d. Its secular part, the mean of e^{−λτ} w·d(τ) over one
    /// hinge period (terms of other frequencies average out), is μ c: the amplitude and phase
    /// drift at the relative rate μ (amplitude-dependent damping and frequency, the terms the
    /// linearisation drops, which decide a panel near its critical damping; the thermal
    /// transient's effect on the hinge, which decays with it).
    fn arc_drift(
        &self,
        arc: &Arc<N>,
        a: &SMatrix<f64, N, N>,
        t0: f64,
        length: f64,
    ) -> (f64, f64, f64) {
        let Some(mode) = HingeMode::of(a, &self.scale) else {
            return (0.0, 0.0, 0.0); // no oscillation to drift
        };
        let period = 2.0 * std::f64::consts::PI / mode.lambda.im;
        let c0 = mode.coordinate(&arc.transient(0.0));
        let amp0 = mode.theta_amplitude(N - 2, c0);
        if amp0 == 0.0 || length <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        // μ at τ: the mean over one period from τ of e^{−λs} w·d(s), relative to c(τ) = c0 e^{λτ}.
        // d is the defect the oscillation itself causes: along the arc, less along the arc
        // without its hinge part h(s) = 2 Re(v c0 e^{λs}) (the thermal transient's slow defect,
        // which one period cannot tell from a resonance, cancels).
        let rate_at = |p: f64| {
            let mut mean = nalgebra::Complex::new(0.0, 0.0);
            for j in 0..DRIFT_SAMPLES {
                let tau = p + period * j as f64 / DRIFT_SAMPLES as f64;
                let y = arc.state(tau);
                let turn = c0 * (mode.lambda * tau).exp();
                let hinge = SVector::<f64, N>::from_fn(|i, _| 2.0 * (mode.right[i] * turn).re);
                let flux = self.orbit.flux_scale(t0 + tau);
                let defect = a * hinge - self.model.rhs_at_flux(flux, &y)
                    + self.model.rhs_at_flux(flux, &(y - hinge));
                mean += (-mode.lambda * tau).exp() * mode.coordinate(&defect);
            }
            mean / (DRIFT_SAMPLES as f64) / c0
        };
        // The relative drift D(τ) = ∫ μ, by the trapezoid rule on points that double from one
        // period (μ changes fastest early, where the thermal transient still decays), and the
        // error a(τ)|D(τ)| it makes in θ, a(τ) = a0 e^{rτ}.
        let amp = |tau: f64| amp0 * (mode.lambda.re * tau).exp();
        let last = length - period;
        let mut points = vec![0.0];
        if last >= period {
            let doublings = (last / period).log2().floor().min(DRIFT_DOUBLINGS) as i32;
            points.extend((0..=doublings).rev().map(|k| last * 0.5f64.powi(k)));
        }
        let (mut drift, mut along) = (nalgebra::Complex::new(0.0, 0.0), 0.0f64);
        let mut before = (0.0, rate_at(0.0));
        for &p in &points[1..] {
            let mu = rate_at(p);
            drift += (before.1 + mu) * (0.5 * (p - before.0));
            // The summaries read the amplitude along the arc (its drift, Re D); the phase (Im D)
            // reaches them only through the state handed on at the arc's end.
            along = along.max(amp(p) * drift.re.abs());
            before = (p, mu);
        }
        drift += before.1 * (length - before.0);
        let end = amp(length) * drift.norm();
        (end.max(along), end, mode.lambda.re)
    }

    /// The drift a linear arc from t0 may add to what earlier arcs left in the state:
    /// [`DRIFT_RTOL`] of the jitter the summaries read (the last whole orbit's RMS, else this
    /// orbit's so far: the smallest value the gate holds), at least [`DRIFT_ATOL`].
    fn drift_allowed(&self, jitter_rms: f64, t0: f64) -> f64 {
        (DRIFT_RTOL * jitter_rms).max(DRIFT_ATOL) - self.drift_spent.get().at(t0)
    }

    /// The linear arc from (t0, y) to `end` in full Sun, with its equilibrium, flux and the drift
    /// at its end; None where the modal decomposition fails or the linearisation would drift out
    /// of the accuracy gate over the arc ([`Judge::arc_drift`] beyond [`Judge::drift_allowed`]
    /// for the summaries' `jitter_rms`).
    fn arc(
        &self,
        t0: f64,
        y: &SVector<f64, N>,
        end: f64,
        jitter_rms: f64,
    ) -> Result<Option<ArcPlan<N>>> {
        let flux0 = self.orbit.flux_scale(t0);
        let flux1 = self.orbit.flux_scale(end);
        let (y_ref, a) = self.reference(flux0)?;
        let b = self.model.flux_sensitivity(flux0, &y_ref) * ((flux1 - flux0) / (end - t0));
        let Ok(arc) = Arc::new(&a, &b, &y_ref, y, end - t0, &self.scale) else {
            return Ok(None);
        };
        let (largest, at_end, rate) = self.arc_drift(&arc, &a, t0, end - t0);
        if largest > self.drift_allowed(jitter_rms, t0) {
            return Ok(None);
        }
        let drift = Drift {
            error: self.drift_spent.get().at(end) + at_end,
            at: end,
            rate,
        };
        Ok(Some(ArcPlan {
            arc,
            y_ref,
            flux0,
            drift,
        }))
    }

    /// May the state at sunlit time t be propagated linearly?
    fn regime(&self, t: f64, y: &SVector<f64, N>) -> Result<Regime> {
        if self.orbit.illumination(t) < 1.0 {
            return Ok(Regime::NonLinear);
        }
        let flux = self.orbit.flux_scale(t);
        let f = self.model.rhs_at_flux(flux, y);
        let (y_ref, a) = self.reference(flux)?;
        let dev = y - y_ref;
        let amplitude = (dev[N - 2] * dev[N - 2]
            + dev[N - 1] * dev[N - 1] / self.panel.natural_angular_frequency().powi(2))
        .sqrt();
        if amplitude.max(self.oscillation(flux, y, &f)) > self.settings.linear_amplitude {
            return Ok(Regime::Large);
        }
        let r = f - a * dev;
        let Some(inv) = a.try_inverse() else {
            return Ok(Regime::NonLinear);
        };
        let static_error: f64 = (0..N).map(|i| (inv[(N - 2, i)] * r[i]).abs()).sum();
        Ok(if static_error <= self.settings.linear_tolerance {
            Regime::Linear
        } else {
            Regime::NonLinear
        })
    }
}

/// Watches the hinge-resolved fallback and ends it once the state may go back to linear arcs
/// (checked every `CHECK_EVERY` s of simulated time, in full Sun past the last shadow's window).
struct FallbackObserver<'a, 'c, const N: usize, M: HybridModel<N>> {
    inner: &'a mut SummaryObserver<'c, M::View>,
    judge: &'a Judge<N, M>,
    eclipses: &'a [Eclipse],
    window: f64,
    /// The end of the fallback's stretch.
    end: f64,
    next_check: f64,
    released: bool,
    error: Option<Error>,
}

const CHECK_EVERY: f64 = 60.0;

impl<const N: usize, M: HybridModel<N>> Observer<Const<N>> for FallbackObserver<'_, '_, N, M> {
    fn on_step(&mut self, step: &DenseStep<Const<N>>) -> ControlFlow<()> {
        self.inner.on_step(step)?;
        let t1 = step.t1;
        if t1 < self.next_check {
            return ControlFlow::Continue(());
        }
        self.next_check = t1 + CHECK_EVERY;
        let shadow = self
            .eclipses
            .iter()
            .any(|e| e.outer.0 <= t1 && t1 < e.outer.1);
        let release = self
            .eclipses
            .iter()
            .filter(|e| e.outer.0 <= t1)
            .map(|e| e.outer.1 + self.window)
            .fold(f64::NEG_INFINITY, f64::max);
        if shadow || t1 < release {
            return ControlFlow::Continue(());
        }
        // Released only where the arc that would follow holds the gate too.
        let arc_end = self
            .eclipses
            .iter()
            .map(|e| e.outer.0)
            .filter(|&c| c > t1)
            .fold(self.end, f64::min);
        let linear = self.judge.regime(t1, &step.y1).and_then(|r| match r {
            Regime::Linear if arc_end > t1 => {
                let jitter = gate_scale(&self.inner.collector);
                Ok(self.judge.arc(t1, &step.y1, arc_end, jitter)?.is_some())
            }
            _ => Ok(false),
        });
        match linear {
            Ok(true) => {
                self.released = true;
                ControlFlow::Break(())
            }
            Ok(false) => ControlFlow::Continue(()),
            Err(e) => {
                self.error = Some(e);
                ControlFlow::Break(())
            }
        }
    }
}

impl<const N: usize, M: HybridModel<N>> Driver<'_, N, M> {
    fn stopped(&self) -> bool {
        self.obs.collector.options.stop_at_limit && self.obs.collector.crossing.is_some()
    }

    /// End of the orbit that holds (t, t + dt].
    fn orbit_end(&self, t: f64) -> f64 {
        let p = self.orbit.period;
        let k = ((t - self.t_start) / p).floor();
        // The summaries' own orbit edges: start + k·p, end = that + p.
        let mut end = self.t_start + k * p + p;
        if end - t <= 1e-9 * p {
            end += p;
        }
        end.min(self.t_end)
    }

    fn run(&mut self) -> Result<()> {
        let mut fallback = false;
        while self.t < self.t_end && !self.stopped() {
            self.obs.cancel.check()?;
            self.check_budget()?;
            let horizon = (self.t + self.orbit.period).min(self.t_end);
            let eclipses = self.eclipses.overlapping(self.t, horizon).to_vec();
            if fallback {
                self.full(horizon, &eclipses)?;
                fallback = false;
                continue;
            }
            let in_shadow = eclipses
                .iter()
                .any(|e| e.outer.0 <= self.t && self.t < e.outer.1);
            if !in_shadow {
                match self.judge.regime(self.t, &self.y)? {
                    Regime::Linear => {
                        let next_contact = eclipses
                            .iter()
                            .map(|e| e.outer.0)
                            .filter(|&c| c > self.t)
                            .fold(f64::INFINITY, f64::min);
                        let end = next_contact.min(self.orbit_end(self.t));
                        fallback = self.linear(end)?.is_some();
                        continue;
                    }
                    Regime::Large => {
                        fallback = true;
                        continue;
                    }
                    Regime::NonLinear => {}
                }
            }
            fallback = self.exponential(horizon, &eclipses)?;
        }
        Ok(())
    }

    /// The fallback's step budget holds for the whole run, every kind of step counted: each
    /// fallback stretch alone stops at it, and without this check a run with one stretch per
    /// orbit could take that many steps per orbit.
    fn check_budget(&self) -> Result<()> {
        let budget = self.fallback.max_steps();
        if self.stats.n_steps + self.stats.n_rejected >= budget {
            return Err(Error::Integration {
                t: self.t,
                reason: format!("max_steps = {budget} reached"),
            });
        }
        Ok(())
    }

    /// A linear arc from t to `end` (same orbit, full Sun). Returns Some(()) when the arc had to
    /// stop early for the fallback (oscillation too large, decomposition ill-conditioned).
    fn linear(&mut self, end: f64) -> Result<Option<()>> {
        let t0 = self.t;
        let jitter = gate_scale(&self.obs.collector);
        let Some(ArcPlan {
            arc,
            y_ref,
            flux0,
            drift,
        }) = self.judge.arc(t0, &self.y, end, jitter)?
        else {
            return Ok(Some(()));
        };
        let theta = arc.signal(&SVector::from_fn(|i, _| if i == N - 2 { 1.0 } else { 0.0 }));
        let (w, offset) = self.judge.model.dynamic_weights(flux0, &y_ref);
        let dynamic = arc.signal(&w).shifted(offset);
        let limit = self.settings.linear_amplitude;
        let mut length = end - t0;
        let mut early = false;
        if theta.envelope_max(0.0, length) > limit {
            // Propagate only while the oscillation stays small (its envelope is monotonic).
            let (mut lo, mut hi) = (0.0, length);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if theta.envelope_max(0.0, mid) > limit {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            length = lo;
            early = true;
        }
        let (lo, hi) = theta.extremes(0.0, length);
        let theta_limit = self.obs.collector.options.theta_limit;
        if hi > theta_limit || lo < -theta_limit {
            // Leave the crossing of the validity limit to the full integration.
            return Ok(Some(()));
        }
        if length > 0.0 {
            let (dlo, dhi) = dynamic.extremes(0.0, length);
            let sq = dynamic.integral_sq(length);
            // The whole span's extremes are known already.
            let extremes = |a: f64, b: f64| {
                if (a, b) == (t0, t0 + length) {
                    (lo, hi)
                } else {
                    theta.extremes(a - t0, b - t0)
                }
            };
            self.obs.collector.record_span(
                t0,
                t0 + length,
                &extremes,
                dlo.abs().max(dhi.abs()),
                sq,
            )?;
            self.y = arc.state(length);
            self.t = if early { t0 + length } else { end };
            self.judge.drift_spent.set(drift);
            self.out.t_linear += length;
            self.out.n_arcs += 1;
        }
        Ok(early.then_some(()))
    }

    /// The hinge-resolved full integration from t to `end`, or until the state may go back to
    /// linear arcs.
    fn full(&mut self, end: f64, eclipses: &[Eclipse]) -> Result<()> {
        let window = self.judge_window();
        let mut watch = FallbackObserver {
            inner: &mut self.obs,
            judge: &self.judge,
            eclipses,
            window,
            end,
            next_check: self.t + CHECK_EVERY,
            released: false,
            error: None,
        };
        let (stats, y) = solve(
            &mut self.system,
            &self.fallback,
            self.t,
            self.y,
            end,
            &mut watch,
        )?;
        if let Some(e) = watch.error.take() {
            return Err(e);
        }
        if let Some(e) = self.obs.error.take() {
            return Err(e);
        }
        self.out.t_fallback += stats.t_end - self.t;
        self.out.n_fallback_steps += stats.n_steps;
        self.stats.n_steps += stats.n_steps;
        self.stats.n_rejected += stats.n_rejected;
        self.stats.n_rhs += stats.n_rhs;
        self.t = if stats.stopped { stats.t_end } else { end };
        self.y = y;
        Ok(())
    }

    fn judge_window(&self) -> f64 {
        self.obs.collector.options.window
    }

    /// The non-linear model by the exponential integrator from t, until the state may go back to
    /// linear arcs, or `horizon`. Returns true when the oscillation grew too large for it (the
    /// caller falls back to the full integration).
    fn exponential(&mut self, horizon: f64, eclipses: &[Eclipse]) -> Result<bool> {
        let start = self.t;
        let mut cuts = vec![self.t];
        cuts.extend(breakpoints_of(eclipses, self.t, horizon));
        cuts.push(horizon);
        let window = self.obs.collector.options.window;
        let period = 2.0 * std::f64::consts::PI / self.judge.panel.natural_angular_frequency();
        let mut large = false;
        let mut done = false;
        let mut resolved_time = 0.0;
        let mut resolve_until = f64::NEG_INFINITY;
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b <= a || done {
                continue;
            }
            // Partial shadow moves M_T/K_el fast (the flux follows the overlap of two discs):
            // the hinge lags it by terms of every order in the rate, which no band of θ holds.
            // Where no thermal mode is fast, resolving the hinge there costs less than the
            // exponential steps that the moving flux would ask for.
            let lit = self.orbit.illumination(0.5 * (a + b));
            if lit > 0.0 && lit < 1.0 {
                let before = self.t;
                self.resolved(b, period, true)?;
                resolved_time += self.t - before;
                resolve_until = b + RESOLVED_AFTER_PARTIAL_SHADOW * period;
                done = self.stopped();
                continue;
            }
            if self.t < resolve_until {
                // Where the flux stops moving (the partial shadow's last contact) the hinge's
                // lag behind it is released: its first swings are resolved too.
                let until = resolve_until.min(b);
                let before = self.t;
                self.resolved(until, period, false)?;
                resolved_time += self.t - before;
                if self.stopped() || until >= b {
                    done = self.stopped();
                    continue;
                }
            }
            self.system.enter_segment(a, b);
            if a == start {
                // An oscillation already too large for the exponential integrator's reads goes
                // to the full integration before any step: a step taken first would carry it
                // (its length set by the slow thermal part) before the check after it.
                let flux = self.system.flux_at(a);
                let f = self.system.rhs_at_flux(flux, &self.y);
                if self.judge.oscillation(flux, &self.y, &f) > self.settings.resolved_amplitude {
                    large = true;
                    break;
                }
            }
            let system = self.system.clone();
            let settings = self.settings;
            let mut t = self.t;
            let mut y = self.y;
            let mut h = self.h_exp;
            let mut failure: Option<Error> = None;
            let this = &mut *self;
            let (acc, rej, stop) = exprb::segment(
                &system,
                a,
                b,
                &mut t,
                &mut y,
                &mut h,
                &settings.tolerances,
                |st: &ExpStep<N>| -> Result<bool> {
                    this.obs.cancel.check()?;
                    this.read_step(st, period)?;
                    if this.stopped() {
                        return Ok(true);
                    }
                    let t1 = st.t1;
                    let shadow = eclipses.iter().any(|e| e.outer.0 <= t1 && t1 < e.outer.1);
                    let release = eclipses
                        .iter()
                        .filter(|e| e.outer.0 <= t1)
                        .map(|e| e.outer.1 + window)
                        .fold(f64::NEG_INFINITY, f64::max);
                    // The exponential integrator's summaries read a small oscillation through
                    // its envelope; a larger one is resolved by the full integration.
                    if this.judge.oscillation(st.flux1, &st.y1, &st.f1)
                        > settings.resolved_amplitude
                    {
                        large = true;
                        return Ok(true);
                    }
                    if !shadow && t1 >= release && t1 < b {
                        match this.judge.regime(t1, &st.y1) {
                            Ok(Regime::Linear) => return Ok(true),
                            Ok(_) => {}
                            Err(e) => failure = Some(e),
                        }
                    }
                    Ok(failure.is_some())
                },
            )
            .or_else(|e| match e {
                // A step that cannot be made small enough: let the full integration take over.
                Error::Integration { .. } => {
                    large = true;
                    Ok((0, 0, true))
                }
                other => Err(other),
            })?;
            if let Some(e) = failure {
                return Err(e);
            }
            self.t = t;
            self.y = y;
            self.h_exp = h;
            self.out.n_exp_steps += acc;
            self.stats.n_steps += acc;
            self.stats.n_rejected += rej;
            self.stats.n_rhs += 3 * (acc + rej);
            done = stop;
        }
        self.out.t_exponential += self.t - start - resolved_time;
        Ok(large)
    }

    /// Feeds one exponential step to the summaries: points of its Hermite interpolant when the
    /// step resolves the hinge period, else bands θ_qs ± a (the quasi-static deflection and the
    /// oscillation's amplitude, interpolated between the step's ends). Each step is checked
    /// against its own formula at its middle; where the check fails, the step is read off the
    /// formula instead, densely enough to resolve the hinge.
    fn read_step(&mut self, st: &ExpStep<N>, period: f64) -> Result<()> {
        let dense = DenseStep::<Const<N>>::hermite(st.t0, st.t1, st.y0, st.y1, st.f0, st.f1);
        let length = st.t1 - st.t0;
        let resolved = length <= period / 8.0;
        // The cubic through the ends against the step's own formula at its middle: where they
        // differ in what the summaries read (a fast thermal transient after a flux jump, which
        // a cubic overshoots), every point is read off the formula instead.
        let t_mid = st.t0 + 0.5 * length;
        let flux_mid = 0.5 * (st.flux0 + st.flux1);
        let reads = |y: &SVector<f64, N>| (y[N - 2], self.judge.model.quasi_static(flux_mid, y));
        let ((th_c, qs_c), (th_f, qs_f)) = (reads(&dense.eval(t_mid)), reads(&st.y_mid));
        let eq = self.obs.collector.current.theta_eq;
        let tol = READ_ATOL + READ_RTOL * (qs_f - eq).abs().max((th_f - eq).abs());
        let formula = (th_c - th_f).abs().max((qs_c - qs_f).abs()) > tol;
        let state = |frac: f64, t: f64| -> SVector<f64, N> {
            match (frac == 1.0, formula, frac == 0.5) {
                (true, _, _) => st.y1,
                (false, true, true) => st.y_mid,
                (false, true, false) => st.state_at(&self.system, t),
                (false, false, _) => dense.eval(t),
            }
        };
        if resolved {
            // Read at the quarters; off the formula, also just after the start, where a fast
            // transient has settled but the hinge's ringing has not yet decayed.
            let base: &[f64] = if formula {
                &[1.0 / 64.0, 1.0 / 16.0, 0.25, 0.5, 0.75, 1.0]
            } else {
                &[0.25, 0.5, 0.75, 1.0]
            };
            let mut before = 0.0;
            for (frac, t) in self.with_window_edges(base, st.t0, st.t1) {
                let y = state(frac, t);
                self.obs
                    .collector
                    .read(t, y.as_slice(), (frac - before) * length)?;
                before = frac;
            }
            return Ok(());
        }
        let (a0, a1) = (
            self.judge.oscillation(st.flux0, &st.y0, &st.f0),
            self.judge.oscillation(st.flux1, &st.y1, &st.f1),
        );
        // The band holds where the oscillation's amplitude, measured afresh at the middle, is
        // what the interpolation between the ends says; it does not (a thermal transient that
        // is not slow against the hinge, a fast-moving M_T/K_el that the hinge lags) where the
        // amplitude measured at the middle strays from it, or, on panels with a fast thermal
        // mode, where the cubic strayed from the formula after a flux jump.
        let f_mid = self.judge.model.rhs_at_flux(flux_mid, &st.y_mid);
        let a_mid = self.judge.oscillation(flux_mid, &st.y_mid, &f_mid);
        // Relative to the largest oscillation the summaries hold (this orbit's peak so far, the
        // last orbit's): an amplitude far below it reaches no extreme the gate reads.
        let peak = match self.obs.collector.done.last() {
            Some(s) if s.jitter_peak.is_finite() => s.jitter_peak,
            _ => 0.0,
        }
        .max(self.obs.collector.current.jitter_peak);
        let band_tol = READ_ATOL + BAND_RTOL * peak.max(a0).max(a1).max(a_mid);
        if (formula && self.judge.modal) || (a_mid - 0.5 * (a0 + a1)).abs() > band_tol {
            return self.reread(st, period);
        }
        let mut before = 0.0;
        for (frac, t) in self.with_window_edges(&[0.25, 0.5, 0.75, 1.0], st.t0, st.t1) {
            let dt = (frac - before) * length;
            before = frac;
            let y = state(frac, t);
            let amp = a0 + (a1 - a0) * frac;
            let flux = st.flux0 + (st.flux1 - st.flux0) * frac;
            let quasi_static = self.judge.model.quasi_static(flux, &y);
            self.obs.collector.record(
                t,
                quasi_static - amp,
                quasi_static + amp,
                amp,
                0.5 * amp * amp * dt,
                dt,
            )?;
        }
        Ok(())
    }

    /// The points (fraction, time) of the step (t0, t1] at the fractions `base`, with the edges
    /// of the current orbit's windows after entry and exit that fall inside it, at their exact
    /// times: a window's extreme is read where it ends, not at the nearest quarter (θ still
    /// falls there as the panel cools).
    fn with_window_edges(&self, base: &[f64], t0: f64, t1: f64) -> Vec<(f64, f64)> {
        let at = |frac: f64| {
            if frac == 1.0 {
                t1
            } else {
                t0 + frac * (t1 - t0)
            }
        };
        let mut points: Vec<(f64, f64)> = base.iter().map(|&f| (f, at(f))).collect();
        let (edges, n) = self.obs.collector.window_edges_in(t0, t1);
        for &edge in &edges[..n] {
            points.push(((edge - t0) / (t1 - t0), edge));
        }
        points.sort_by(|a, b| a.1.total_cmp(&b.1));
        points.dedup_by(|a, b| a.1 == b.1);
        points
    }

    /// The model from t to `end` by fixed-step RK4 at [`RK4_STEPS_PER_PERIOD`] steps to the hinge
    /// period, read as the full integration is, where the hinge must be resolved; by the full
    /// integration's adaptive method where a thermal mode is too fast for that step (RK4 is
    /// stable for |λ| dt below 2.78). `partial`: the span is a partial shadow
    /// ([`WithinSegment::partial`]).
    fn resolved(&mut self, end: f64, period: f64, partial: bool) -> Result<()> {
        let dt = period / RK4_STEPS_PER_PERIOD;
        let method = if self.judge.fastest_rate * dt <= RK4_STABLE_STEP {
            Method::Rk4 { dt }
        } else {
            self.fallback
        };
        let mut system = if partial {
            WithinSegment::partial(&mut self.system)
        } else {
            WithinSegment::new(&mut self.system)
        };
        let (stats, y) = solve(&mut system, &method, self.t, self.y, end, &mut self.obs)?;
        if let Some(e) = self.obs.error.take() {
            return Err(e);
        }
        self.out.t_fallback += stats.t_end - self.t;
        self.out.n_fallback_steps += stats.n_steps;
        self.stats.n_steps += stats.n_steps;
        self.stats.n_rhs += stats.n_rhs;
        self.t = if stats.stopped { stats.t_end } else { end };
        self.y = y;
        Ok(())
    }

    /// Reads a step whose band cannot be trusted at points that resolve the hinge: off the step's own formula where a thermal mode is
    /// fast (an explicit integrator would have to follow it; [`REREADS_PER_PERIOD`]), else by a
    /// fixed-step RK4 run ([`RK4_STEPS_PER_PERIOD`]) of
    /// the model over the step from its start (cheaper than evaluating the formula's φ
    /// functions at each point), whose steps the summaries read as those of the full
    /// integration. The run goes on from the exponential step's own end.
    fn reread(&mut self, st: &ExpStep<N>, period: f64) -> Result<()> {
        self.out.n_reread_steps += 1;
        let length = st.t1 - st.t0;
        if !self.judge.modal {
            let method = Method::Rk4 {
                dt: period / RK4_STEPS_PER_PERIOD,
            };
            let mut model = self.system.clone();
            let mut system = WithinSegment::new(&mut model);
            let (stats, _) = solve(&mut system, &method, st.t0, st.y0, st.t1, &mut self.obs)?;
            if let Some(e) = self.obs.error.take() {
                return Err(e);
            }
            self.stats.n_rhs += stats.n_rhs;
            return Ok(());
        }
        let n = (length / period * REREADS_PER_PERIOD).ceil().max(4.0) as usize;
        let base: Vec<f64> = (1..=n).map(|k| k as f64 / n as f64).collect();
        let mut before = st.t0;
        for (frac, t) in self.with_window_edges(&base, st.t0, st.t1) {
            let y = if frac == 1.0 {
                st.y1
            } else {
                st.state_at(&self.system, t)
            };
            self.obs.collector.read(t, y.as_slice(), t - before)?;
            before = t;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::flutter::{analyse, critical_damping};
    use crate::analysis::steady::equilibrium;
    use crate::inputs::orbit::Shadow;
    use crate::models::coupled::Coupling;
    use crate::models::hinge::HingeModel;
    use crate::numerics::integrate::Tolerances;
    use crate::runs::orbits::{run_orbits, OrbitSummary, SummaryOptions};

    pub(super) fn options() -> SummaryOptions {
        SummaryOptions {
            window: 600.0,
            theta_limit: 0.35,
            stop_at_limit: true,
            steps_per_period: STEPS_PER_HINGE_PERIOD,
        }
    }

    fn start(panel: &Panel, orbit: &Orbit, kick: f64) -> Vector4<f64> {
        let eq = equilibrium(panel, Coupling::ProjectedArea, orbit.flux_scale(0.0)).unwrap();
        Vector4::new(eq.t_front, eq.t_back, eq.theta + kick, 0.0)
    }

    /// Orbits 0 .. n of `panel`, the fallback (and the full run) rk45 at T_n/40.
    pub(super) fn spec(panel: &Panel, orbit: &Orbit, n: u64) -> OrbitRunSpec {
        OrbitRunSpec {
            panel: *panel,
            orbit: *orbit,
            model: HingeModel::Nonlinear,
            coupling: Coupling::ProjectedArea,
            method: Method::Dopri5(Tolerances::default()),
            t_start: 0.0,
            first_index: 0,
            n_orbits: n,
            options: options(),
        }
    }

    fn request(panel: &Panel, orbit: &Orbit, n: u64, y0: Vector4<f64>) -> OrbitRunRequest {
        let spec = spec(panel, orbit, n);
        OrbitRunRequest { spec, y0 }
    }

    fn hybrid(panel: &Panel, orbit: &Orbit, n: u64, y0: Vector4<f64>) -> HybridRun {
        let req = request(panel, orbit, n, y0);
        run_orbits_hybrid(&req, &HybridSettings::default(), &Cancel::new()).unwrap()
    }

    fn full(panel: &Panel, orbit: &Orbit, n: u64, y0: Vector4<f64>) -> OrbitRun {
        run_orbits(&request(panel, orbit, n, y0)).unwrap()
    }

    /// Within 2 %, or 1e-6 rad where the full run's value is below 5e-5 rad (NaN matches NaN).
    pub(super) fn close(name: &str, k: usize, full: f64, hyb: f64) {
        if full.is_nan() {
            assert!(
                hyb.is_nan(),
                "{name}[{k}]: {hyb} where the full run has none"
            );
            return;
        }
        let ok = if full.abs() < 5e-5 {
            (hyb - full).abs() <= 1e-6
        } else {
            (hyb / full - 1.0).abs() <= 0.02
        };
        assert!(ok, "{name}[{k}]: hybrid {hyb:e} vs full {full:e}");
    }

    pub(super) fn compare(full: &[OrbitSummary], hyb: &[OrbitSummary]) {
        assert_eq!(full.len(), hyb.len());
        for (k, (f, h)) in full.iter().zip(hyb).enumerate() {
            close("amplitude", k, f.amplitude, h.amplitude);
            close("exit_peak", k, f.exit_peak, h.exit_peak);
            close("entry_peak", k, f.entry_peak, h.entry_peak);
            close("jitter_rms", k, f.jitter_rms, h.jitter_rms);
            close("theta_max", k, f.theta_max, h.theta_max);
            close("theta_min", k, f.theta_min, h.theta_min);
        }
    }

    #[test]
    fn penumbra_eclipses_match_the_hinge_resolved_run() {
        // Three orbits of the spring eclipse season: penumbra, eccentric Sun, moving declination.
        let panel = Panel::paper();
        let orbit = Orbit::geo_year(70.0);
        let y0 = start(&panel, &orbit, 0.0);
        let full = full(&panel, &orbit, 3, y0);
        let hyb = hybrid(&panel, &orbit, 3, y0);
        compare(&full.summaries, &hyb.run.summaries);
        assert!(hyb.t_linear > 2.0 * orbit.period, "{}", hyb.t_linear);
        // The guard of the linear arcs' drift hands a few minutes to the full integration.
        assert!(hyb.t_exponential > 0.0 && hyb.t_fallback < 0.01 * 3.0 * orbit.period);
        assert!(hyb.run.stats.n_steps * 50 < full.stats.n_steps);
        let total = hyb.t_linear + hyb.t_exponential + hyb.t_fallback;
        assert!((total - 3.0 * orbit.period).abs() < 1e-6 * total);
    }

    #[test]
    fn weak_flutter_in_permanent_sunlight_grows_at_the_eigenvalue() {
        let base = Panel {
            solar_constant: 1361.0 * 1.034,
            ..Panel::paper()
        };
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        let crit = critical_damping(&base, model, coupling, 1.0).unwrap();
        let orbit = Orbit {
            shadow: Shadow::None,
            ..Orbit::geo_equinox()
        };
        for damping in [crit - 0.1, crit + 0.1] {
            let panel = Panel { damping, ..base };
            let predicted = analyse(&panel, model, coupling, 1.0).unwrap().growth_rate;
            let run = hybrid(&panel, &orbit, 4, start(&panel, &orbit, 1e-6));
            let s = &run.run.summaries;
            let measured = (s[3].amplitude / s[1].amplitude).ln() / (2.0 * orbit.period);
            assert!(
                (measured / predicted - 1.0).abs() < 0.01,
                "c_d {damping}: {measured:e} vs {predicted:e}"
            );
            assert_eq!(run.t_linear, 4.0 * orbit.period);
        }
    }

    #[test]
    fn a_flux_jump_rings_in_the_full_integration_and_matches_it() {
        let panel = Panel::paper();
        let orbit = Orbit::geo_equinox();
        let y0 = start(&panel, &orbit, 0.0);
        let full = full(&panel, &orbit, 2, y0);
        let hyb = hybrid(&panel, &orbit, 2, y0);
        compare(&full.summaries, &hyb.run.summaries);
        assert!(hyb.t_fallback > 0.0 && hyb.t_linear > orbit.period);
    }

    #[test]
    fn the_validity_limit_stops_a_fluttering_panel_like_the_full_run() {
        let panel = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        let orbit = Orbit::geo_equinox();
        let run = hybrid(&panel, &orbit, 20, start(&panel, &orbit, 0.0));
        let c = run
            .run
            .crossing
            .expect("an undamped panel must leave the limit");
        assert!(c.theta.abs() > 0.35 && run.run.stats.stopped);
        assert_eq!(run.run.summaries.last().unwrap().index, c.orbit);
    }

    #[test]
    fn a_partial_shadows_flux_is_read_off_its_interpolant() {
        // Every partial shadow of the first year and of the tenth of geo_year: the flux the
        // resolved integration sees against the model's, at 300 points of each.
        let panel = Panel::paper();
        let orbit = Orbit::geo_year(0.0);
        let mut model = TwoLayerModel::new(
            &panel,
            &orbit,
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
        );
        let mut exact = model;
        let year = 366.0 * orbit.period;
        let (mut parts, mut refused, mut largest) = (0, 0, [0.0f64; 2]);
        for (k, t0) in [0.0, 9.0 * year].into_iter().enumerate() {
            let cuts = orbit.breakpoints(t0, t0 + year);
            for w in cuts.windows(2) {
                let (a, b) = (w[0], w[1]);
                let lit = orbit.illumination(0.5 * (a + b));
                if !(lit > 0.0 && lit < 1.0) {
                    continue;
                }
                let mut within = WithinSegment::partial(&mut model);
                within.enter_segment(a, b);
                exact.enter_segment(a, b);
                let track = within.track.as_ref().unwrap();
                parts += crate::numerics::chebyshev::PIECES;
                refused += track.refused();
                for i in 0..=300 {
                    let t = a + (b - a) * i as f64 / 300.0;
                    if let Some(flux) = track.at(t) {
                        largest[k] = largest[k].max((flux - exact.flux_at(t)).abs());
                    }
                }
            }
        }
        assert!(
            parts > 300 && refused * 100 < parts,
            "{refused} of {parts} parts refused"
        );
        // Within 1e-10 of the flux at 1 au in the first year; in the tenth (t ~ 3e8 s) the
        // model's own flux is uncertain by its slope times the rounding of t (~1e-9).
        assert!(largest[0] <= 1e-10, "{largest:?}");
        assert!(largest[1] <= 1e-8, "{largest:?}");
    }

    #[test]
    fn settings_are_checked() {
        let s = HybridSettings {
            linear_tolerance: -1.0,
            ..HybridSettings::default()
        };
        let e = s.validate().unwrap_err().to_string();
        assert!(e.starts_with("hybrid.linear_tolerance"), "{e}");
    }
}
