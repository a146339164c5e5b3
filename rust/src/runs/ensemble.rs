//! Monte Carlo (`tj.monte_carlo`, `sweep`, `sensitivity`; `python/thermojitter/montecarlo.py`):
//! batches of independent panels (samples, sweep points) run in parallel on rayon.
//!
//! Each sample is one panel (or one boom) on its orbit, integrated over a whole number of orbits
//! from its sunlit equilibrium, plus the flutter analysis of that equilibrium, reduced to a few
//! numbers. A sample's orbit is the batch's, or the batch's with the sample's own orbit inputs
//! ([`ORBIT_INPUTS`]: the Earth's heat and the orbit plane). A sample is computed by one thread
//! from its own inputs only, so the results do not depend on the number of threads or on how a
//! batch is cut into chunks.

use crate::analysis::flutter::{analyse, analyse_system_at, critical_damping, critical_damping_at};
use crate::cancel::Cancel;
use crate::error::{require_positive, Error, Result};
use crate::inputs::boom::Boom;
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::coupled::{Coupled, Coupling};
use crate::models::hinge::HingeModel;
use crate::numerics::cpu::Kernel;
use crate::numerics::integrate::{DenseStep, Method, Observer};
use crate::runs::hybrid::{run_orbits_hybrid, HybridSettings};
use crate::runs::lockstep::{solve_lockstep, Job, LaneObserver, StepReads, RUNS_PER_CORE};
use crate::runs::orbits::{
    finish_orbits, prepare_orbits, run_orbits_cancellable, start_state, LimitCrossing, OrbitRun,
    OrbitRunRequest, OrbitRunSpec, OrbitSummary, SummaryObserver, SummaryOptions, TwoLayerView,
};
use nalgebra::U4;
use rayon::prelude::*;
use rayon::ThreadPool;
use std::cell::RefCell;
use std::ops::ControlFlow;

/// What every sample of a batch shares.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnsembleSettings {
    pub orbit: Orbit,
    pub model: HingeModel,
    pub coupling: Coupling,
    pub method: Method,
    /// Whole orbits integrated from t = 0, the first starting at the sunlit equilibrium.
    pub n_orbits: u64,
    /// Window after shadow entry and exit in which the transient peaks are taken, s.
    pub window: f64,
    /// |θ| whose first crossing is timed, rad.
    pub threshold: Option<f64>,
    /// Stop a sample at the first crossing of the threshold (its metrics then cover the run so
    /// far).
    pub stop_at_threshold: bool,
    /// |θ| beyond which the hinge model is not trusted, rad: the first orbit that passes it is
    /// reported.
    pub validity_limit: f64,
    /// Propagate with the hybrid propagator (`method` is then its fallback) instead of the
    /// hinge-resolved integration.
    pub hybrid: Option<HybridSettings>,
}

impl EnsembleSettings {
    /// The settings of a sample run on `orbit` (the batch's with the sample's orbit inputs).
    pub fn on(&self, orbit: Orbit) -> EnsembleSettings {
        EnsembleSettings { orbit, ..*self }
    }

    pub fn validate(&self) -> Result<()> {
        self.orbit.validate()?;
        self.method.validate()?;
        require_positive("window", self.window)?;
        if self.n_orbits == 0 {
            return Err(Error::invalid("horizon", 0, "must be >= 1 orbit"));
        }
        let t_end = self.n_orbits as f64 * self.orbit.period;
        if self.orbit.check_span(0.0, t_end).is_err() {
            return Err(Error::invalid(
                "horizon",
                self.n_orbits,
                &format!(
                    "reaches t = {t_end:e} s; at most {:e} s and {:e} eclipses per sample",
                    crate::numerics::integrate::MAX_TIME,
                    crate::inputs::orbit::MAX_ECLIPSES
                ),
            ));
        }
        if let Some(th) = self.threshold {
            require_positive("threshold", th)?;
        }
        require_positive("validity_limit", self.validity_limit)?;
        if let Some(h) = &self.hybrid {
            h.validate()?;
        }
        Ok(())
    }
}

/// The orbit inputs a batch may vary sample by sample, named as the parameters of
/// `Orbit.circular`: the Earth's albedo and infrared flux, the orbit plane's inclination and its
/// node's right ascension. Neither changes the period, so every sample of a batch runs the same
/// span of time.
pub const ORBIT_INPUTS: [&str; 4] = ["albedo", "earth_ir", "inclination", "raan"];

/// The valid range of each of [`ORBIT_INPUTS`] as [`Orbit::validate`] checks it, `(low, high,
/// low end open)`, both ends closed here.
pub const ORBIT_INPUT_RANGES: [(f64, f64, bool); 4] = [
    (0.0, 1.0, false),
    (0.0, crate::inputs::attitude::MAX_EARTH_IR, false),
    (0.0, std::f64::consts::PI, false),
    (
        -crate::inputs::orbit::MAX_PHASE0,
        crate::inputs::orbit::MAX_PHASE0,
        false,
    ),
];

/// `orbit` with the orbit input `name` ([`ORBIT_INPUTS`]) set to `value`, unchecked (a sample's
/// run validates its orbit).
pub fn orbit_with(orbit: Orbit, name: &str, value: f64) -> Result<Orbit> {
    let mut o = orbit;
    match name {
        "albedo" => o.albedo = value,
        "earth_ir" => o.earth_ir = value,
        "inclination" => o.inclination = value,
        "raan" => o.raan = value,
        _ => {
            return Err(Error::invalid(
                "orbit input",
                name,
                &format!("must be one of {}", ORBIT_INPUTS.join(", ")),
            ))
        }
    }
    Ok(o)
}

/// One sample of a batch: its panel and the orbit it runs on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub panel: Panel,
    pub orbit: Orbit,
}

/// The numbers kept from one sample. Angles rad, times s; NaN where not defined.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleMetrics {
    /// Sunlit equilibrium angle at full Sun.
    pub theta_eq: f64,
    /// Largest real part of the Jacobian's eigenvalues at that equilibrium, 1/s.
    pub growth_rate: f64,
    pub frequency_hz: f64,
    /// Damping at which the growth rate crosses zero, N m s/rad (a boom's: the critical damping
    /// ratio of its first mode).
    pub critical_damping: f64,
    /// max |θ| over the horizon.
    pub theta_abs_max: f64,
    /// max |θ − θ_eq| over the horizon.
    pub amplitude: f64,
    /// max |θ − θ_eq| within the window after any shadow entry, and after any exit.
    pub entry_peak: f64,
    pub exit_peak: f64,
    /// RMS and peak of θ − M_T/K_el over the horizon.
    pub jitter_rms: f64,
    pub jitter_peak: f64,
    /// First time |θ| passed the threshold (NaN: never, or no threshold), and its orbit.
    pub t_threshold: f64,
    pub orbit_threshold: f64,
    /// First orbit whose |θ| passed the validity limit (NaN: none).
    pub orbit_limit: f64,
    /// Growth (> 0) or decay of the per-orbit amplitude over the run: the least-squares slope of
    /// ln(amplitude) against the orbit index, 1/orbit (NaN with fewer than two orbits).
    pub amplitude_slope: f64,
    /// Simulated time integrated with the full non-linear model, s (the whole run unless hybrid).
    pub t_nonlinear: f64,
    /// Time the integration reached (the horizon unless stopped at the threshold).
    pub t_reached: f64,
    pub n_steps: u64,
    /// Why the sample could not be computed; every number is then NaN.
    pub error: Option<String>,
}

impl SampleMetrics {
    fn failed(err: Error) -> Self {
        SampleMetrics {
            theta_eq: f64::NAN,
            growth_rate: f64::NAN,
            frequency_hz: f64::NAN,
            critical_damping: f64::NAN,
            theta_abs_max: f64::NAN,
            amplitude: f64::NAN,
            entry_peak: f64::NAN,
            exit_peak: f64::NAN,
            jitter_rms: f64::NAN,
            jitter_peak: f64::NAN,
            t_threshold: f64::NAN,
            orbit_threshold: f64::NAN,
            orbit_limit: f64::NAN,
            amplitude_slope: f64::NAN,
            t_nonlinear: f64::NAN,
            t_reached: f64::NAN,
            n_steps: 0,
            error: Some(err.to_string()),
        }
    }

    pub fn stable(&self) -> bool {
        self.growth_rate < 0.0
    }
}

/// Largest value, ignoring NaN (the windows of an orbit without an eclipse); NaN if all are.
fn max_defined(values: impl Iterator<Item = f64>) -> f64 {
    values.fold(f64::NAN, |acc, v| if v.is_nan() { acc } else { acc.max(v) })
}

/// What a sample's metrics read of its run over orbits, whatever its model.
struct Ran<'a> {
    summaries: &'a [OrbitSummary],
    t_end: f64,
    n_steps: u64,
    crossing: Option<LimitCrossing>,
}

impl<'a> From<&'a OrbitRun> for Ran<'a> {
    fn from(run: &'a OrbitRun) -> Self {
        Ran {
            summaries: &run.summaries,
            t_end: run.stats.t_end,
            n_steps: run.stats.n_steps,
            crossing: run.crossing,
        }
    }
}

impl<'a> From<&'a crate::runs::layered::LayeredSummaries> for Ran<'a> {
    fn from(run: &'a crate::runs::layered::LayeredSummaries) -> Self {
        Ran {
            summaries: &run.summaries,
            t_end: run.stats.t_end,
            n_steps: run.stats.n_steps,
            crossing: run.crossing,
        }
    }
}

fn reduce(run: &Ran<'_>) -> (f64, f64, f64, f64, f64, f64) {
    let s = run.summaries;
    let theta_abs_max = max_defined(s.iter().map(|o| o.theta_max.abs().max(o.theta_min.abs())));
    let amplitude = max_defined(s.iter().map(|o| o.amplitude));
    let entry = max_defined(s.iter().map(|o| o.entry_peak));
    let exit = max_defined(s.iter().map(|o| o.exit_peak));
    let jitter_peak = max_defined(s.iter().map(|o| o.jitter_peak));
    // Each orbit's RMS weighted by the time integrated in it (the last may be cut short).
    let (mut sq, mut total) = (0.0, 0.0);
    for o in s {
        let span = (o.t_end.min(run.t_end) - o.t_start).max(0.0);
        sq += o.jitter_rms * o.jitter_rms * span;
        total += span;
    }
    let rms = if total > 0.0 {
        (sq / total).sqrt()
    } else {
        f64::NAN
    };
    (theta_abs_max, amplitude, entry, exit, rms, jitter_peak)
}

/// What a study reads off the summaries of a run that ended at `t_end`, for runs summarised
/// outside a batch (the distributed panel's): max |θ|, the largest amplitude, entry and exit
/// peaks, the jitter's RMS over the run and its peak, and the amplitude's log slope per orbit.
pub fn summary_metrics(summaries: &[OrbitSummary], t_end: f64) -> [f64; 7] {
    let run = Ran {
        summaries,
        t_end,
        n_steps: 0,
        crossing: None,
    };
    let (theta_abs_max, amplitude, entry, exit, rms, peak) = reduce(&run);
    [
        theta_abs_max,
        amplitude,
        entry,
        exit,
        rms,
        peak,
        log_slope(&run),
    ]
}

/// First orbit whose largest |θ| passed `limit`, as a float (NaN: none).
fn first_orbit_beyond(run: &Ran<'_>, limit: f64) -> f64 {
    run.summaries
        .iter()
        .find(|o| o.theta_max.abs().max(o.theta_min.abs()) > limit)
        .map_or(f64::NAN, |o| o.index as f64)
}

/// Least-squares slope of ln(amplitude) against the orbit index (orbits with amplitude > 0).
fn log_slope(run: &Ran<'_>) -> f64 {
    let points: Vec<(f64, f64)> = run
        .summaries
        .iter()
        .filter(|o| o.amplitude > 0.0)
        .map(|o| (o.index as f64, o.amplitude.ln()))
        .collect();
    let n = points.len() as f64;
    if points.len() < 2 {
        return f64::NAN;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

/// One sample: the flutter analysis and the summarised run of `panel` on the batch's orbit
/// (stops with `Error::Cancelled` within one step of `cancel` being cancelled).
pub fn run_sample(
    panel: &Panel,
    settings: &EnsembleSettings,
    cancel: &Cancel,
) -> Result<SampleMetrics> {
    let (head, req) = sample_head(panel, settings, cancel)?;
    let (run, t_nonlinear) = match &settings.hybrid {
        None => {
            let run = run_orbits_cancellable(&req, cancel)?;
            let t = run.stats.t_end;
            (run, t)
        }
        Some(h) => {
            // The Earth's loads and attitudes other than Sun-pointing are integrated in full
            // (their time counted in t_nonlinear), as a single hybrid run does.
            let out = run_orbits_hybrid(&req, h, cancel)?;
            (out.run, out.t_exponential + out.t_fallback)
        }
    };
    Ok(sample_metrics(&head, settings, &(&run).into(), t_nonlinear))
}

/// What a sample knows before its run: the flutter analysis of its equilibrium.
struct SampleHead {
    theta_eq: f64,
    growth_rate: f64,
    frequency_hz: f64,
    critical_damping: f64,
}

/// The flutter analysis of a sample, its initial state and its summary options: at full Sun
/// (the flux factor 1) on an orbit of the Sun alone, as `tj.flutter(panel)`; under every load
/// of its orbit at t = 0 (the Earth's, the attitude's incidence) when it has them, as
/// `tj.flutter(panel, orbit=..., t=0)`. The run starts where a single run does
/// ([`start_state`]).
fn sample_head(
    panel: &Panel,
    settings: &EnsembleSettings,
    cancel: &Cancel,
) -> Result<(SampleHead, OrbitRunRequest)> {
    cancel.check()?;
    panel.validate()?;
    let s = settings;
    let head = if s.orbit.has_face_loads() {
        let system = Coupled::new(*panel, s.orbit, s.model, s.coupling);
        let (eq, _, spectrum) = analyse_system_at(&system, 0.0)?;
        SampleHead {
            theta_eq: eq[2],
            growth_rate: spectrum.growth_rate,
            frequency_hz: spectrum.frequency_hz,
            critical_damping: critical_damping_at(panel, &s.orbit, 0.0, s.model, s.coupling)?,
        }
    } else {
        let flutter = analyse(panel, s.model, s.coupling, 1.0)?;
        SampleHead {
            theta_eq: flutter.equilibrium.theta,
            growth_rate: flutter.growth_rate,
            frequency_hz: flutter.frequency_hz,
            critical_damping: critical_damping(panel, s.model, s.coupling, 1.0)?,
        }
    };
    let req = OrbitRunRequest {
        spec: orbit_spec(panel, s),
        y0: start_state(panel, &s.orbit, s.coupling, 0.0)?,
    };
    Ok((head, req))
}

/// The summary options of every sample of a batch.
fn summary_options(s: &EnsembleSettings) -> SummaryOptions {
    SummaryOptions {
        window: s.window,
        // Without a threshold nothing is timed: a limit no angle reaches.
        theta_limit: s.threshold.unwrap_or(f64::MAX),
        stop_at_limit: s.stop_at_threshold && s.threshold.is_some(),
        steps_per_period: crate::runs::orbits::STEPS_PER_HINGE_PERIOD,
    }
}

/// The run over orbits every sample of a batch takes (`panel` being the sample's), from t = 0,
/// with its per-orbit summaries.
fn orbit_spec(panel: &Panel, s: &EnsembleSettings) -> OrbitRunSpec {
    OrbitRunSpec {
        panel: *panel,
        orbit: s.orbit,
        model: s.model,
        coupling: s.coupling,
        method: s.method,
        t_start: 0.0,
        first_index: 0,
        n_orbits: s.n_orbits,
        options: summary_options(s),
    }
}

/// The N-node through-thickness model of every sample of a batch: `nodes` nodes through the
/// thickness of `layup`, or of each sample's panel as one homogeneous layer when `layup` is None
/// (see [`crate::models::conduction::Conduction::homogeneous`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Layers {
    pub layup: Option<crate::inputs::laminate::Laminate>,
    pub nodes: usize,
}

/// One sample with the N-node model: the N-node flutter analysis and the summarised N-node run
/// of `panel` from its sunlit equilibrium, the same computations as a single run of it
/// (`LayeredPoint::analyse`, `LayeredPoint::critical_damping`, `layered::run_orbits`).
pub fn run_sample_layered(
    panel: &Panel,
    settings: &EnsembleSettings,
    layers: &Layers,
    cancel: &Cancel,
) -> Result<SampleMetrics> {
    cancel.check()?;
    panel.validate()?;
    let s = settings;
    let c = match &layers.layup {
        Some(l) => crate::models::conduction::Conduction::new(panel, l, layers.nodes)?,
        None => crate::models::conduction::Conduction::homogeneous(panel, layers.nodes)?,
    };
    let point = crate::analysis::layered::LayeredPoint {
        panel,
        conduction: &c,
        model: s.model,
        coupling: s.coupling,
        loads: crate::inputs::heating::Loads::sun(1.0),
    };
    let flutter = point.analyse()?;
    let critical = point.critical_damping()?;
    let eq = crate::analysis::layered::equilibrium(panel, &c, s.coupling, s.orbit.flux_scale(0.0))?;
    let mut y0 = eq.temperatures;
    y0.extend([eq.theta, 0.0]);
    let head = SampleHead {
        theta_eq: flutter.equilibrium.theta,
        growth_rate: flutter.growth_rate,
        frequency_hz: flutter.frequency_hz,
        critical_damping: critical,
    };
    let req = crate::runs::layered::LayeredRunRequest {
        spec: orbit_spec(panel, s),
        conduction: c,
        y0,
    };
    let (out, t_nonlinear) = match &s.hybrid {
        None => {
            let out = crate::runs::layered::run_orbits(&req, cancel)?;
            let t = out.stats.t_end;
            (out, t)
        }
        Some(h) => {
            let out = crate::runs::hybrid::layered::run_orbits_hybrid(&req, h, cancel)?;
            (out.run, out.split.t_exponential + out.split.t_fallback)
        }
    };
    Ok(sample_metrics(&head, settings, &(&out).into(), t_nonlinear))
}

/// [`run_batch`] with the N-node model (one sample at a time per thread).
pub fn run_batch_layered(
    pool: &ThreadPool,
    samples: &[Sample],
    settings: &EnsembleSettings,
    layers: &Layers,
    cancel: &Cancel,
) -> Result<Vec<SampleMetrics>> {
    let run = |x: &Sample, s: &EnsembleSettings| run_sample_layered(&x.panel, s, layers, cancel);
    one_at_a_time(pool, samples, settings, cancel, run, |x| x.orbit)
}

/// Runs `items` on `pool`, one at a time per thread, each with the batch's settings on its orbit
/// (`orbit_of`); results in input order, an item that fails keeping its error, as [`run_batch`].
fn one_at_a_time<T: Sync>(
    pool: &ThreadPool,
    items: &[T],
    settings: &EnsembleSettings,
    cancel: &Cancel,
    run: impl Fn(&T, &EnsembleSettings) -> Result<SampleMetrics> + Sync,
    orbit_of: impl Fn(&T) -> Orbit + Sync,
) -> Result<Vec<SampleMetrics>> {
    settings.validate()?;
    let out = pool.install(|| {
        items
            .par_iter()
            .with_max_len(1)
            .map(|x| {
                checked_on(&orbit_of(x), settings)
                    .and_then(|s| run(x, &s))
                    .unwrap_or_else(SampleMetrics::failed)
            })
            .collect()
    });
    cancel.check()?;
    Ok(out)
}

/// The settings of a sample on `orbit` (the batch's on it), the orbit checked as the batch's is.
fn checked_on(orbit: &Orbit, settings: &EnsembleSettings) -> Result<EnsembleSettings> {
    if *orbit == settings.orbit {
        return Ok(*settings);
    }
    let s = settings.on(*orbit);
    s.validate()?;
    Ok(s)
}

/// One boom: the tube's flutter analysis at full Sun (its growth rate, frequency and critical
/// damping ratio, as `tj.flutter(boom)`) and its summarised run over the orbits from its steady
/// state at t = 0, as a single run of it (`runs::boom::run_orbits`). The tube has no hybrid
/// form: a hybrid batch integrates it in full.
pub fn run_boom_sample(
    boom: &Boom,
    settings: &EnsembleSettings,
    cancel: &Cancel,
) -> Result<SampleMetrics> {
    cancel.check()?;
    let s = settings;
    let flutter = crate::analysis::tube::flutter(boom, s.coupling, 1.0)?;
    let head = SampleHead {
        theta_eq: flutter.equilibrium[2],
        growth_rate: flutter.spectrum.growth_rate,
        frequency_hz: flutter.spectrum.frequency_hz,
        critical_damping: flutter.critical_damping_ratio,
    };
    let system = crate::models::tube::boom_system(boom, s.orbit, s.coupling)?;
    let y0 = system.steady_state(s.orbit.flux_scale(0.0))?;
    let out = crate::runs::boom::run_orbits(
        boom,
        s.orbit,
        s.coupling,
        &s.method,
        (0.0, 0, s.n_orbits),
        y0.as_slice(),
        summary_options(s),
        cancel,
    )?;
    let t_nonlinear = out.stats.t_end;
    Ok(sample_metrics(&head, settings, &(&out).into(), t_nonlinear))
}

/// Runs every boom on `pool` (one at a time per thread), each on its orbit; results in input
/// order, a failed boom keeping its error, as [`run_batch`].
pub fn run_boom_batch(
    pool: &ThreadPool,
    booms: &[(Boom, Orbit)],
    settings: &EnsembleSettings,
    cancel: &Cancel,
) -> Result<Vec<SampleMetrics>> {
    let run = |x: &(Boom, Orbit), s: &EnsembleSettings| run_boom_sample(&x.0, s, cancel);
    one_at_a_time(pool, booms, settings, cancel, run, |x| x.1)
}

/// A sample's metrics from its head and its run.
fn sample_metrics(
    head: &SampleHead,
    settings: &EnsembleSettings,
    run: &Ran<'_>,
    t_nonlinear: f64,
) -> SampleMetrics {
    let (theta_abs_max, amplitude, entry_peak, exit_peak, jitter_rms, jitter_peak) = reduce(run);
    SampleMetrics {
        theta_eq: head.theta_eq,
        growth_rate: head.growth_rate,
        frequency_hz: head.frequency_hz,
        critical_damping: head.critical_damping,
        theta_abs_max,
        amplitude,
        entry_peak,
        exit_peak,
        jitter_rms,
        jitter_peak,
        t_threshold: run.crossing.map_or(f64::NAN, |c| c.t),
        orbit_threshold: run.crossing.map_or(f64::NAN, |c| c.orbit as f64),
        orbit_limit: first_orbit_beyond(run, settings.validity_limit),
        amplitude_slope: log_slope(run),
        t_nonlinear,
        t_reached: run.t_end,
        n_steps: run.n_steps,
        error: None,
    }
}

/// A sample's run in a lane, with what it needs to become a row.
struct LaneSample<'c> {
    index: usize,
    head: SampleHead,
    settings: EnsembleSettings,
    observer: SummaryObserver<'c, TwoLayerView>,
}

impl Observer<U4> for LaneSample<'_> {
    #[inline]
    fn on_step(&mut self, step: &DenseStep<U4>) -> ControlFlow<()> {
        self.observer.on_step(step)
    }
}

impl LaneObserver for LaneSample<'_> {
    fn dynamic_form(&self) -> Option<(f64, f64)> {
        self.observer.dynamic_form()
    }
    #[inline(always)]
    fn on_reads(&mut self, reads: &StepReads) -> Option<ControlFlow<()>> {
        self.observer.on_reads(reads)
    }
}

/// Whether a sample on `orbit` can run in a lane: the lanes take the front's sunlight only, so a
/// sample with the Earth's loads or another attitude runs alone (on the scalar path, whose rows
/// the lanes reproduce bit for bit).
fn fits_a_lane(orbit: &Orbit) -> bool {
    !orbit.has_face_loads()
}

/// Runs `samples` (hinge-resolved Dormand–Prince samples) on this thread, up to
/// [`RUNS_PER_CORE`] at a time in lockstep, those that do not fit a lane one at a time; results
/// in input order, each the same, bit for bit, as [`run_sample`]'s.
fn run_group(
    samples: &[Sample],
    settings: &EnsembleSettings,
    cancel: &Cancel,
) -> Vec<SampleMetrics> {
    // Rows are written by `next` (a sample that fails before its run, or runs alone) and by
    // `done`.
    let out = RefCell::new(vec![None; samples.len()]);
    let mut queue = samples.iter().enumerate();
    let next = || {
        for (index, sample) in queue.by_ref() {
            let prepared = checked_on(&sample.orbit, settings).and_then(|s| {
                if !fits_a_lane(&s.orbit) {
                    return Ok(Err(run_sample(&sample.panel, &s, cancel)?));
                }
                let (head, req) = sample_head(&sample.panel, &s, cancel)?;
                Ok(Ok((head, s, prepare_orbits(&req, cancel)?)))
            });
            match prepared {
                Ok(Ok((head, settings, run))) => {
                    let Method::Dopri5(tol) = run.method else {
                        unreachable!("only Dormand–Prince batches run in lockstep")
                    };
                    return Some(Job {
                        system: run.system,
                        tol,
                        t0: run.t0,
                        t1: run.t1,
                        y0: run.y0,
                        observer: LaneSample {
                            index,
                            head,
                            settings,
                            observer: run.observer,
                        },
                    });
                }
                Ok(Err(row)) => out.borrow_mut()[index] = Some(row),
                Err(e) => out.borrow_mut()[index] = Some(SampleMetrics::failed(e)),
            }
        }
        None
    };
    let done = |sample: LaneSample<'_>, outcome| {
        let row = finish_orbits(sample.observer, outcome)
            .map(|run| {
                let t = run.stats.t_end;
                sample_metrics(&sample.head, &sample.settings, &(&run).into(), t)
            })
            .unwrap_or_else(SampleMetrics::failed);
        out.borrow_mut()[sample.index] = Some(row);
    };
    solve_lockstep(Kernel::detect(), next, done);
    out.into_inner()
        .into_iter()
        .map(|row| row.expect("every sample ends"))
        .collect()
}

/// Most worker threads a pool may have: more than any machine's cores, few enough that a typo
/// (or 2**63) does not spawn threads until the operating system refuses.
pub const MAX_THREADS: usize = 1024;

/// A rayon pool of its own with `threads` workers (0: rayon's default, one per core).
pub fn pool(threads: usize) -> Result<ThreadPool> {
    if threads > MAX_THREADS {
        return Err(Error::invalid(
            "threads",
            threads,
            &format!("must be in [1, {MAX_THREADS}] (or None for one per core)"),
        ));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::invalid("threads", threads, &e.to_string()))
}

/// Runs every panel on `pool`, results in input order. A sample that fails (an invalid panel,
/// an integration that cannot finish) keeps its error in its metrics; the batch goes on.
/// Cancelling `cancel` stops every sample within one step and the batch returns
/// `Error::Cancelled` (a batch is kept whole or not at all).
pub fn run_batch(
    pool: &ThreadPool,
    panels: &[Panel],
    settings: &EnsembleSettings,
    cancel: &Cancel,
) -> Result<Vec<SampleMetrics>> {
    run_batch_on(pool, panels, settings, cancel, Path::Lockstep)
}

/// How a batch's samples are integrated; both give the same rows, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Path {
    /// Up to [`RUNS_PER_CORE`] samples at a time per thread, in SIMD lanes (hinge-resolved
    /// Dormand–Prince batches; others run one at a time).
    Lockstep,
    /// One sample at a time per thread.
    Scalar,
}

/// Samples given to one thread's lockstep loop at a time: as many as it runs at once, or fewer
/// so that every thread of the pool has some. Samples of a batch take about the same number of
/// steps, so the lanes end together; a group of one runs alone.
fn group_size(samples: usize, threads: usize) -> usize {
    RUNS_PER_CORE.min(samples.div_ceil(threads.max(1))).max(1)
}

/// [`run_batch`] along `path`, every panel on the batch's orbit.
pub fn run_batch_on(
    pool: &ThreadPool,
    panels: &[Panel],
    settings: &EnsembleSettings,
    cancel: &Cancel,
    path: Path,
) -> Result<Vec<SampleMetrics>> {
    let samples: Vec<Sample> = panels
        .iter()
        .map(|&panel| Sample {
            panel,
            orbit: settings.orbit,
        })
        .collect();
    run_samples(pool, &samples, settings, cancel, path)
}

/// [`run_batch_on`] with each sample on its own orbit (the batch's with the sample's orbit
/// inputs); a sample whose orbit is invalid fails alone, naming the input.
pub fn run_samples(
    pool: &ThreadPool,
    samples: &[Sample],
    settings: &EnsembleSettings,
    cancel: &Cancel,
    path: Path,
) -> Result<Vec<SampleMetrics>> {
    settings.validate()?;
    // The lanes take hinge-resolved Dormand–Prince runs; each group runs those of its samples
    // that do not fit a lane (the Earth's loads, other attitudes) one at a time.
    let lockstep = path == Path::Lockstep
        && settings.hybrid.is_none()
        && matches!(settings.method, Method::Dopri5(_));
    let scalar = |x: &Sample| {
        checked_on(&x.orbit, settings)
            .and_then(|s| run_sample(&x.panel, &s, cancel))
            .unwrap_or_else(SampleMetrics::failed)
    };
    let out = pool.install(|| {
        if lockstep {
            let group = group_size(samples.len(), rayon::current_num_threads());
            let groups: Vec<Vec<SampleMetrics>> = samples
                .par_chunks(group)
                .with_max_len(1)
                .map(|group| match group {
                    [x] => vec![scalar(x)],
                    _ => run_group(group, settings, cancel),
                })
                .collect();
            groups.into_iter().flatten().collect()
        } else {
            samples.par_iter().with_max_len(1).map(scalar).collect()
        }
    });
    cancel.check()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::steady::equilibrium;
    use crate::numerics::integrate::Tolerances;
    use crate::runs::orbits::run_orbits;
    use nalgebra::Vector4;

    fn settings() -> EnsembleSettings {
        EnsembleSettings {
            orbit: Orbit {
                radius: 7.0e6,
                period: 5828.5,
                ..Orbit::geo_equinox()
            },
            model: HingeModel::Nonlinear,
            coupling: Coupling::ProjectedArea,
            method: Method::Dopri5(Tolerances {
                rtol: 1e-6,
                atol: 1e-8,
                ..Tolerances::default()
            }),
            n_orbits: 1,
            window: 600.0,
            threshold: Some(0.2),
            stop_at_threshold: false,
            validity_limit: 0.35,
            hybrid: None,
        }
    }

    fn panels() -> Vec<Panel> {
        (0..6)
            .map(|k| Panel {
                damping: 0.5 * k as f64,
                conductance: 20.0 + k as f64,
                ..Panel::paper()
            })
            .collect()
    }

    #[test]
    fn lockstep_groups_give_every_thread_work_and_fill_a_core() {
        for threads in 1..=9 {
            for samples in 1..=4 * RUNS_PER_CORE * threads {
                let group = group_size(samples, threads);
                assert!((1..=RUNS_PER_CORE).contains(&group));
                // The smallest group with which one per thread takes every sample, unless a
                // core's worth is not enough.
                let covers = |g: usize| g * threads >= samples;
                assert!(
                    covers(group) || group == RUNS_PER_CORE,
                    "{samples} on {threads}"
                );
                assert!(!covers(group - 1), "{samples} on {threads}: {group}");
            }
        }
    }

    /// Every number of a batch by its bits (NaN equals NaN), with the errors.
    fn bits(batch: &[SampleMetrics]) -> Vec<(Vec<u64>, Option<String>)> {
        batch
            .iter()
            .map(|m| {
                let v = [
                    m.theta_eq,
                    m.growth_rate,
                    m.frequency_hz,
                    m.critical_damping,
                    m.theta_abs_max,
                    m.amplitude,
                    m.entry_peak,
                    m.exit_peak,
                    m.jitter_rms,
                    m.jitter_peak,
                    m.t_threshold,
                    m.orbit_threshold,
                    m.orbit_limit,
                    m.amplitude_slope,
                    m.t_nonlinear,
                    m.t_reached,
                ];
                let mut b: Vec<u64> = v.iter().map(|x| x.to_bits()).collect();
                b.push(m.n_steps);
                (b, m.error.clone())
            })
            .collect()
    }

    #[test]
    fn results_do_not_depend_on_threads_or_order() {
        let s = settings();
        let one = run_batch(&pool(1).unwrap(), &panels(), &s, &Cancel::new()).unwrap();
        let two = run_batch(&pool(2).unwrap(), &panels(), &s, &Cancel::new()).unwrap();
        assert_eq!(bits(&one), bits(&two));
        let mut reversed = panels();
        reversed.reverse();
        let mut back = run_batch(&pool(2).unwrap(), &reversed, &s, &Cancel::new()).unwrap();
        back.reverse();
        assert_eq!(bits(&one), bits(&back));
    }

    #[test]
    fn lockstep_rows_equal_scalar_rows() {
        // Eleven samples: groups of four, four and three; one invalid panel, some
        // that stop at their threshold early.
        let mut ps: Vec<Panel> = (0..11)
            .map(|k| Panel {
                damping: 0.35 * k as f64,
                conductance: 20.0 + k as f64,
                emissivity_back: 0.25 + 0.01 * k as f64,
                ..Panel::paper()
            })
            .collect();
        ps[4].emissivity_front = 1.5;
        let mut s = settings();
        // |θ| peaks from 0.128 (most damped) to 0.183 (undamped) in this set.
        s.threshold = Some(0.15);
        s.stop_at_threshold = true;
        let p = pool(2).unwrap();
        let scalar = run_batch_on(&p, &ps, &s, &Cancel::new(), Path::Scalar).unwrap();
        let lanes = run_batch_on(&p, &ps, &s, &Cancel::new(), Path::Lockstep).unwrap();
        assert_eq!(bits(&lanes), bits(&scalar));
        assert!(scalar[4].error.is_some());
        assert!(scalar.iter().any(|m| m.t_reached < s.orbit.period));
        assert!(scalar.iter().any(|m| m.t_reached == s.orbit.period));
        // The same with the other models and two orbits.
        for (model, coupling) in [
            (HingeModel::Linear, Coupling::ProjectedArea),
            (HingeModel::Nonlinear, Coupling::Frozen),
        ] {
            let s = EnsembleSettings {
                model,
                coupling,
                n_orbits: 2,
                ..settings()
            };
            let scalar = run_batch_on(&p, &ps[..5], &s, &Cancel::new(), Path::Scalar).unwrap();
            let lanes = run_batch_on(&p, &ps[..5], &s, &Cancel::new(), Path::Lockstep).unwrap();
            assert_eq!(bits(&lanes), bits(&scalar), "{model:?} {coupling:?}");
        }
    }

    /// The one long run a sample of `s` should equal: the batch's run over orbits (as
    /// [`orbit_spec`] sets it) through [`run_orbits_cancellable`] alone, from the sunlit
    /// equilibrium, the summary's θ limit `theta_limit` (built here rather than by the ensemble).
    fn single_run(panel: Panel, s: &EnsembleSettings, theta_limit: f64) -> OrbitRunRequest {
        let eq = equilibrium(&panel, s.coupling, s.orbit.flux_scale(0.0)).unwrap();
        let options = SummaryOptions {
            window: s.window,
            theta_limit,
            stop_at_limit: false,
            steps_per_period: crate::runs::orbits::STEPS_PER_HINGE_PERIOD,
        };
        OrbitRunRequest {
            spec: OrbitRunSpec {
                options,
                ..orbit_spec(&panel, s)
            },
            y0: Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0),
        }
    }

    #[test]
    fn a_sample_equals_its_single_run_and_flutter_analysis() {
        let s = settings();
        let p = panels()[3];
        let m = run_sample(&p, &s, &Cancel::new()).unwrap();
        let a = analyse(&p, s.model, s.coupling, 1.0).unwrap();
        assert_eq!(m.growth_rate, a.growth_rate);
        assert_eq!(m.stable(), a.stable());
        let eq = equilibrium(&p, s.coupling, 1.0).unwrap();
        let run = run_orbits(&single_run(p, &s, 0.2)).unwrap();
        let o = run.summaries[0];
        assert_eq!(m.exit_peak, o.exit_peak);
        assert_eq!(m.theta_abs_max, o.theta_max.abs().max(o.theta_min.abs()));
        assert!((m.jitter_rms - o.jitter_rms).abs() <= 1e-15 * o.jitter_rms);
        assert_eq!(m.theta_eq, eq.theta);
    }

    #[test]
    fn hybrid_samples_do_not_depend_on_threads_and_equal_their_single_run() {
        let s = EnsembleSettings {
            orbit: Orbit::geo_year(70.0),
            n_orbits: 3,
            hybrid: Some(HybridSettings::default()),
            threshold: None,
            ..settings()
        };
        let one = run_batch(&pool(1).unwrap(), &panels(), &s, &Cancel::new()).unwrap();
        let two = run_batch(&pool(2).unwrap(), &panels(), &s, &Cancel::new()).unwrap();
        assert_eq!(bits(&one), bits(&two));
        let p = Panel::paper();
        let m = run_sample(&p, &s, &Cancel::new()).unwrap();
        let req = single_run(p, &s, f64::MAX);
        let single = run_orbits_hybrid(&req, &HybridSettings::default(), &Cancel::new()).unwrap();
        let amp = single.run.summaries.iter().map(|o| o.amplitude);
        assert_eq!(m.amplitude, amp.fold(f64::NAN, f64::max));
        assert_eq!(m.t_nonlinear, single.t_exponential + single.t_fallback);
        assert!(m.t_nonlinear > 0.0 && m.t_nonlinear < 0.2 * m.t_reached);
        assert!(m.amplitude_slope.is_finite());
    }

    /// Samples of `panels()` on orbits that vary their inputs: some with the Earth's loads, one
    /// with an albedo out of range.
    fn samples_on_orbits(s: &EnsembleSettings) -> Vec<Sample> {
        panels()
            .into_iter()
            .enumerate()
            .map(|(k, panel)| {
                let mut orbit = orbit_with(s.orbit, "inclination", 0.2 * k as f64).unwrap();
                orbit = orbit_with(orbit, "raan", 0.5 * k as f64).unwrap();
                if k % 2 == 1 {
                    orbit = orbit_with(orbit, "albedo", 0.1 * k as f64).unwrap();
                    orbit = orbit_with(orbit, "earth_ir", 40.0 * k as f64).unwrap();
                }
                Sample { panel, orbit }
            })
            .collect()
    }

    #[test]
    fn a_sample_on_its_own_orbit_equals_a_batch_on_that_orbit() {
        let s = settings();
        let samples = samples_on_orbits(&s);
        let p = pool(2).unwrap();
        let lanes = run_samples(&p, &samples, &s, &Cancel::new(), Path::Lockstep).unwrap();
        let scalar = run_samples(&p, &samples, &s, &Cancel::new(), Path::Scalar).unwrap();
        let one = run_samples(
            &pool(1).unwrap(),
            &samples,
            &s,
            &Cancel::new(),
            Path::Lockstep,
        );
        assert_eq!(bits(&lanes), bits(&scalar));
        assert_eq!(bits(&lanes), bits(&one.unwrap()));
        for (x, row) in samples.iter().zip(&lanes) {
            let alone = run_batch(
                &pool(1).unwrap(),
                &[x.panel],
                &s.on(x.orbit),
                &Cancel::new(),
            );
            assert_eq!(bits(&alone.unwrap()), bits(std::slice::from_ref(row)));
        }
        // The Earth's loads move the equilibrium.
        assert_ne!(lanes[1].theta_eq, lanes[0].theta_eq);
        let mut bad = samples.clone();
        bad[2].orbit.albedo = 1.5;
        let out = run_samples(&p, &bad, &s, &Cancel::new(), Path::Lockstep).unwrap();
        assert_fails_alone(&out, 2, "albedo");
    }

    /// Sample `k` of `out`, alone, failed with an error naming `name`.
    fn assert_fails_alone(out: &[SampleMetrics], k: usize, name: &str) {
        let err = out[k].error.as_deref().unwrap();
        assert!(err.starts_with(name), "{err}");
        assert!(out[k].growth_rate.is_nan());
        assert!(out
            .iter()
            .enumerate()
            .all(|(i, m)| (i == k) == m.error.is_some()));
    }

    #[test]
    fn a_loaded_sample_starts_and_is_analysed_where_a_single_run_is() {
        let mut s = settings();
        s.orbit.albedo = 0.3;
        s.orbit.earth_ir = 237.0;
        s.orbit.attitude = crate::inputs::attitude::Attitude::Nadir;
        let p = panels()[3];
        let m = run_sample(&p, &s, &Cancel::new()).unwrap();
        let system = Coupled::new(p, s.orbit, s.model, s.coupling);
        let (eq, _, spectrum) = analyse_system_at(&system, 0.0).unwrap();
        assert_eq!(m.theta_eq, eq[2]);
        assert_eq!(m.growth_rate, spectrum.growth_rate);
        let y0 = Coupled::new(p, s.orbit, HingeModel::Nonlinear, s.coupling)
            .sunlit_steady_state(0.0)
            .unwrap();
        let req = OrbitRunRequest {
            spec: OrbitRunSpec {
                options: SummaryOptions {
                    theta_limit: 0.2,
                    ..summary_options(&s)
                },
                ..orbit_spec(&p, &s)
            },
            y0,
        };
        let run = run_orbits(&req).unwrap();
        assert_eq!(m.exit_peak, run.summaries[0].exit_peak);
        assert_eq!(m.n_steps, run.stats.n_steps);
    }

    #[test]
    fn booms_do_not_depend_on_threads_and_equal_their_single_run() {
        let s = settings();
        let booms: Vec<(Boom, Orbit)> = (0..5)
            .map(|k| {
                let boom = Boom {
                    damping: 0.002 * k as f64,
                    solar_inclination: 0.6 + 0.4 * k as f64,
                    ..Boom::example()
                };
                (
                    boom,
                    orbit_with(s.orbit, "inclination", 0.1 * k as f64).unwrap(),
                )
            })
            .collect();
        let one = run_boom_batch(&pool(1).unwrap(), &booms, &s, &Cancel::new()).unwrap();
        let two = run_boom_batch(&pool(2).unwrap(), &booms, &s, &Cancel::new()).unwrap();
        assert_eq!(bits(&one), bits(&two));
        let (boom, orbit) = booms[3];
        let system = crate::models::tube::boom_system(&boom, orbit, s.coupling).unwrap();
        let y0 = system.steady_state(orbit.flux_scale(0.0)).unwrap();
        let single = crate::runs::boom::run_orbits(
            &boom,
            orbit,
            s.coupling,
            &s.method,
            (0.0, 0, 1),
            y0.as_slice(),
            summary_options(&s),
            &Cancel::new(),
        )
        .unwrap();
        let o = single.summaries[0];
        assert_eq!(one[3].exit_peak, o.exit_peak);
        assert_eq!(one[3].amplitude, o.amplitude);
        assert_eq!(one[3].n_steps, single.stats.n_steps);
        let f = crate::analysis::tube::flutter(&boom, s.coupling, 1.0).unwrap();
        assert_eq!(one[3].critical_damping, f.critical_damping_ratio);
        assert_eq!(one[3].theta_eq, f.equilibrium[2]);
        // A boom refuses the Earth's loads: that sample fails alone.
        let mut loaded = booms.clone();
        loaded[1].1.albedo = 0.3;
        let out = run_boom_batch(&pool(2).unwrap(), &loaded, &s, &Cancel::new()).unwrap();
        assert_fails_alone(&out, 1, "orbit");
    }

    #[test]
    fn a_bad_panel_fails_alone() {
        let mut ps = panels();
        ps[2].emissivity_front = 1.5;
        let out = run_batch(&pool(2).unwrap(), &ps, &settings(), &Cancel::new()).unwrap();
        assert_fails_alone(&out, 2, "emissivity_front");
    }

    #[test]
    fn threshold_timing_and_stopping() {
        let mut s = settings();
        let p = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        let base = run_sample(&p, &s, &Cancel::new()).unwrap();
        let limit = 0.5 * (base.theta_abs_max + base.theta_eq.abs());
        s.threshold = Some(limit);
        let flagged = run_sample(&p, &s, &Cancel::new()).unwrap();
        assert!(flagged.t_threshold > 0.0 && flagged.t_threshold < s.orbit.period);
        assert_eq!(flagged.t_reached, s.orbit.period);
        s.stop_at_threshold = true;
        let stopped = run_sample(&p, &s, &Cancel::new()).unwrap();
        assert_eq!(stopped.t_threshold, flagged.t_threshold);
        assert!(stopped.t_reached < s.orbit.period);
        s.threshold = None;
        assert!(run_sample(&p, &s, &Cancel::new())
            .unwrap()
            .t_threshold
            .is_nan());
    }

    #[test]
    fn settings_are_checked() {
        let mut s = settings();
        s.n_orbits = 0;
        let e = run_batch(&pool(1).unwrap(), &panels(), &s, &Cancel::new()).unwrap_err();
        assert!(e.to_string().starts_with("horizon"), "{e}");
        let mut s = settings();
        s.threshold = Some(-1.0);
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("threshold"));
    }

    #[test]
    fn a_cancelled_batch_stops_within_a_step() {
        let mut s = settings();
        // Hours of work if nothing stopped it: 2 samples of 100 000 orbits each.
        s.n_orbits = 100_000;
        let cancel = Cancel::new();
        let started = std::time::Instant::now();
        let out = std::thread::scope(|scope| {
            let batch = scope.spawn(|| run_batch(&pool(2).unwrap(), &panels()[..2], &s, &cancel));
            std::thread::sleep(std::time::Duration::from_millis(200));
            cancel.cancel();
            batch.join().unwrap()
        });
        assert_eq!(out.unwrap_err(), Error::Cancelled);
        assert!(
            started.elapsed().as_secs_f64() < 5.0,
            "{:?}",
            started.elapsed()
        );
        // Cancelled before it starts: nothing runs.
        let e = run_batch(&pool(1).unwrap(), &panels(), &settings(), &cancel).unwrap_err();
        assert_eq!(e, Error::Cancelled);
    }

    #[test]
    fn pools_beyond_the_thread_limit_are_refused_before_any_thread_starts() {
        for threads in [MAX_THREADS + 1, usize::MAX] {
            let err = pool(threads).expect_err("refused");
            assert!(err.to_string().starts_with("threads = "), "{err}");
            assert!(err.to_string().contains(&MAX_THREADS.to_string()), "{err}");
        }
    }

    #[test]
    fn a_hybrid_sample_stops_at_its_budget_every_step_counted() {
        // A panel whose thermal rates are not slow against its hinge: on a low orbit the
        // hybrid's slow time refuses it and integrates the run in full. Each stretch of a
        // fallback used to get the whole budget, so the run took that many steps per orbit.
        // A budget of a few orbits' steps, each stretch well within it.
        let budget = 100_000;
        let s = EnsembleSettings {
            n_orbits: 50,
            hybrid: Some(HybridSettings::default()),
            method: Method::Dopri5(Tolerances {
                rtol: 1e-6,
                atol: 1e-8,
                max_steps: budget,
                ..Tolerances::default()
            }),
            ..settings()
        };
        let fast = Panel {
            specific_heat: Panel::paper().specific_heat / 10.0,
            ..Panel::paper()
        };
        let err = run_sample(&fast, &s, &Cancel::new()).expect_err("budget");
        assert!(
            err.to_string().contains("max_steps = 100000 reached"),
            "{err}"
        );
        // A few orbits in, not after the 50 (~30,000 steps an orbit here).
        let Error::Integration { t, .. } = err else {
            panic!("{err}")
        };
        assert!(t < 6.0 * s.orbit.period, "stopped at t = {t}");
    }
}
