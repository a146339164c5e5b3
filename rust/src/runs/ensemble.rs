//! Monte Carlo (`tj.monte_carlo`, `sweep`, `sensitivity`; `python/thermojitter/montecarlo.py`):
//! batches of independent panels (samples, sweep points) run in parallel on rayon.
//!
//! Each sample is one panel integrated over a whole number of orbits from its sunlit equilibrium,
//! plus the flutter analysis of that equilibrium, reduced to a few numbers. A sample is computed
//! by one thread from its own inputs only, so the results do not depend on the number of threads
//! or on how a batch is cut into chunks.

use crate::analysis::flutter::{analyse, critical_damping};
use crate::analysis::steady::equilibrium;
use crate::cancel::Cancel;
use crate::error::{require_positive, Error, Result};
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use crate::numerics::cpu::Kernel;
use crate::numerics::integrate::{DenseStep, Method, Observer};
use crate::runs::hybrid::{run_orbits_hybrid, HybridSettings};
use crate::runs::lockstep::{solve_lockstep, Job, LaneObserver, StepReads, RUNS_PER_CORE};
use crate::runs::orbits::{
    finish_orbits, prepare_orbits, run_orbits_cancellable, OrbitRun, OrbitRunRequest, OrbitRunSpec,
    SummaryObserver, SummaryOptions, TwoLayerView,
};
use nalgebra::{Vector4, U4};
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

/// The numbers kept from one sample. Angles rad, times s; NaN where not defined.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleMetrics {
    /// Sunlit equilibrium angle at full Sun.
    pub theta_eq: f64,
    /// Largest real part of the Jacobian's eigenvalues at that equilibrium, 1/s.
    pub growth_rate: f64,
    pub frequency_hz: f64,
    /// Damping at which the growth rate crosses zero, N m s/rad.
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

fn reduce(run: &OrbitRun) -> (f64, f64, f64, f64, f64, f64) {
    let s = &run.summaries;
    let theta_abs_max = max_defined(s.iter().map(|o| o.theta_max.abs().max(o.theta_min.abs())));
    let amplitude = max_defined(s.iter().map(|o| o.amplitude));
    let entry = max_defined(s.iter().map(|o| o.entry_peak));
    let exit = max_defined(s.iter().map(|o| o.exit_peak));
    let jitter_peak = max_defined(s.iter().map(|o| o.jitter_peak));
    // Each orbit's RMS weighted by the time integrated in it (the last may be cut short).
    let (mut sq, mut total) = (0.0, 0.0);
    for o in s {
        let span = (o.t_end.min(run.stats.t_end) - o.t_start).max(0.0);
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

/// First orbit whose largest |θ| passed `limit`, as a float (NaN: none).
fn first_orbit_beyond(run: &OrbitRun, limit: f64) -> f64 {
    run.summaries
        .iter()
        .find(|o| o.theta_max.abs().max(o.theta_min.abs()) > limit)
        .map_or(f64::NAN, |o| o.index as f64)
}

/// Least-squares slope of ln(amplitude) against the orbit index (orbits with amplitude > 0).
fn log_slope(run: &OrbitRun) -> f64 {
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

/// One sample: the flutter analysis and the summarised run of `panel` (stops with
/// `Error::Cancelled` within one step of `cancel` being cancelled).
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
            let out = run_orbits_hybrid(&req, h, cancel)?;
            (out.run, out.t_exponential + out.t_fallback)
        }
    };
    Ok(sample_metrics(&head, settings, &run, t_nonlinear))
}

/// What a sample knows before its run: the flutter analysis of its equilibrium.
struct SampleHead {
    theta_eq: f64,
    growth_rate: f64,
    frequency_hz: f64,
    critical_damping: f64,
}

/// The flutter analysis of a sample, its initial state and its summary options.
fn sample_head(
    panel: &Panel,
    settings: &EnsembleSettings,
    cancel: &Cancel,
) -> Result<(SampleHead, OrbitRunRequest)> {
    cancel.check()?;
    panel.validate()?;
    let s = settings;
    let flutter = analyse(panel, s.model, s.coupling, 1.0)?;
    let critical = critical_damping(panel, s.model, s.coupling, 1.0)?;
    let eq = equilibrium(panel, s.coupling, s.orbit.flux_scale(0.0))?;
    let req = OrbitRunRequest {
        spec: orbit_spec(panel, s),
        y0: Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0),
    };
    let head = SampleHead {
        theta_eq: flutter.equilibrium.theta,
        growth_rate: flutter.growth_rate,
        frequency_hz: flutter.frequency_hz,
        critical_damping: critical,
    };
    Ok((head, req))
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
        options: SummaryOptions {
            window: s.window,
            // Without a threshold nothing is timed: a limit no angle reaches.
            theta_limit: s.threshold.unwrap_or(f64::MAX),
            stop_at_limit: s.stop_at_threshold && s.threshold.is_some(),
            steps_per_period: crate::runs::orbits::STEPS_PER_HINGE_PERIOD,
        },
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
    let n = out.y_end.len();
    let run = OrbitRun {
        summaries: out.summaries,
        stats: out.stats,
        // The metrics read the summaries only; the faces stand for the thermal state.
        y_end: Vector4::new(
            out.y_end[0],
            out.y_end[n - 3],
            out.y_end[n - 2],
            out.y_end[n - 1],
        ),
        crossing: out.crossing,
    };
    Ok(sample_metrics(&head, settings, &run, t_nonlinear))
}

/// [`run_batch`] with the N-node model (one sample at a time per thread).
pub fn run_batch_layered(
    pool: &ThreadPool,
    panels: &[Panel],
    settings: &EnsembleSettings,
    layers: &Layers,
    cancel: &Cancel,
) -> Result<Vec<SampleMetrics>> {
    settings.validate()?;
    let out = pool.install(|| {
        panels
            .par_iter()
            .with_max_len(1)
            .map(|p| {
                run_sample_layered(p, settings, layers, cancel)
                    .unwrap_or_else(SampleMetrics::failed)
            })
            .collect()
    });
    cancel.check()?;
    Ok(out)
}

/// A sample's metrics from its head and its run.
fn sample_metrics(
    head: &SampleHead,
    settings: &EnsembleSettings,
    run: &OrbitRun,
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
        t_reached: run.stats.t_end,
        n_steps: run.stats.n_steps,
        error: None,
    }
}

/// A sample's run in a lane, with what it needs to become a row.
struct LaneSample<'c> {
    index: usize,
    head: SampleHead,
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

/// Runs `panels` (hinge-resolved Dormand–Prince samples) on this thread, up to
/// [`RUNS_PER_CORE`] at a time in lockstep; results in input order, each the same, bit for bit,
/// as [`run_sample`]'s.
fn run_group(panels: &[Panel], settings: &EnsembleSettings, cancel: &Cancel) -> Vec<SampleMetrics> {
    // Rows are written by `next` (a sample that fails before its run) and by `done`.
    let out = RefCell::new(vec![None; panels.len()]);
    let mut queue = panels.iter().enumerate();
    let s = settings;
    let next = || {
        for (index, panel) in queue.by_ref() {
            let prepared = sample_head(panel, s, cancel)
                .and_then(|(head, req)| Ok((head, prepare_orbits(&req, cancel)?)));
            match prepared {
                Ok((head, run)) => {
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
                            observer: run.observer,
                        },
                    });
                }
                Err(e) => out.borrow_mut()[index] = Some(SampleMetrics::failed(e)),
            }
        }
        None
    };
    let done = |sample: LaneSample<'_>, outcome| {
        let row = finish_orbits(sample.observer, outcome)
            .map(|run| sample_metrics(&sample.head, s, &run, run.stats.t_end))
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

/// [`run_batch`] along `path`.
pub fn run_batch_on(
    pool: &ThreadPool,
    panels: &[Panel],
    settings: &EnsembleSettings,
    cancel: &Cancel,
    path: Path,
) -> Result<Vec<SampleMetrics>> {
    settings.validate()?;
    // The lanes take the front's sunlight only: Earth heating and other attitudes run one
    // sample at a time.
    let lockstep = path == Path::Lockstep
        && settings.hybrid.is_none()
        && !settings.orbit.has_face_loads()
        && matches!(settings.method, Method::Dopri5(_));
    let scalar = |p: &Panel| run_sample(p, settings, cancel).unwrap_or_else(SampleMetrics::failed);
    let out = pool.install(|| {
        if lockstep {
            let group = group_size(panels.len(), rayon::current_num_threads());
            let groups: Vec<Vec<SampleMetrics>> = panels
                .par_chunks(group)
                .with_max_len(1)
                .map(|group| match group {
                    [p] => vec![scalar(p)],
                    _ => run_group(group, settings, cancel),
                })
                .collect();
            groups.into_iter().flatten().collect()
        } else {
            panels.par_iter().with_max_len(1).map(scalar).collect()
        }
    });
    cancel.check()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::integrate::Tolerances;
    use crate::runs::orbits::run_orbits;

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

    #[test]
    fn a_bad_panel_fails_alone() {
        let mut ps = panels();
        ps[2].emissivity_front = 1.5;
        let out = run_batch(&pool(2).unwrap(), &ps, &settings(), &Cancel::new()).unwrap();
        let err = out[2].error.as_deref().unwrap();
        assert!(err.starts_with("emissivity_front"), "{err}");
        assert!(out[2].growth_rate.is_nan());
        assert!(out
            .iter()
            .enumerate()
            .all(|(i, m)| (i == 2) == m.error.is_some()));
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
        // On a low orbit the hybrid falls back on the full integration every orbit; each
        // stretch used to get the whole budget, so the run took that many steps per orbit.
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
        let err = run_sample(&Panel::paper(), &s, &Cancel::new()).expect_err("budget");
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
