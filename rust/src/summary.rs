//! Per-orbit summaries of long runs: memory grows with the number of orbits, not of steps.
//!
//! Each accepted step is read at its midpoint (from the dense output) and at its end, and at
//! eight points where it may hold an extreme of the orbit (judged from θ̇ at those points) or
//! overlaps an eclipse window: the step is capped at a fortieth of the hinge period, so the peaks
//! are read at 320 points per period, the rest at 80. Against 64 points in every step the peaks
//! stay within 1e-5 of the amplitude (`two_reads_per_step_keep_the_peaks` below measures it) at
//! about half the cost of the four points per step read before.

use crate::cancel::Cancel;
use crate::dynamics::HingeModel;
use crate::error::Result;
use crate::integrate::{solve, DenseStep, Method, Observer, Stats};
use crate::orbit::Orbit;
use crate::params::Panel;
use crate::steady::equilibrium;
use crate::system::{Coupled, Coupling};
use nalgebra::{Vector4, U4};
use std::ops::ControlFlow;

/// Points read per step: the midpoint and the end.
const READS_PER_STEP: usize = 2;

/// Angles below which a missed peak does not matter, rad (a nanoradian: jitter is measured in
/// microradians and more).
const NEGLIGIBLE_ANGLE: f64 = 1e-9;

/// Points read in a step that may hold an extreme (a multiple of [`READS_PER_STEP`], so that its
/// points include the coarse ones).
const DETAILED_READS: usize = 8;

/// What one orbit did. Angles in rad, times in s; NaN where an orbit has no eclipse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitSummary {
    pub index: u64,
    pub t_start: f64,
    pub t_end: f64,
    /// Sunlit equilibrium angle at this orbit's solar flux.
    pub theta_eq: f64,
    pub theta_max: f64,
    pub theta_min: f64,
    /// max |θ − θ_eq|.
    pub amplitude: f64,
    /// RMS and peak of the dynamic part θ − M_T/K_el (the quasi-static deflection removed).
    pub jitter_rms: f64,
    pub jitter_peak: f64,
    /// Umbra entry and exit times of this orbit's eclipse.
    pub t_entry: f64,
    pub t_exit: f64,
    /// Extremes of θ within the window after entry and after exit.
    pub entry_theta_min: f64,
    pub exit_theta_max: f64,
    /// max |θ − θ_eq| within the windows after entry and after exit.
    pub entry_peak: f64,
    pub exit_peak: f64,
}

impl OrbitSummary {
    fn new(
        index: u64,
        t_start: f64,
        t_end: f64,
        theta_eq: f64,
        eclipse: Option<(f64, f64)>,
    ) -> Self {
        let (t_entry, t_exit) = eclipse.unwrap_or((f64::NAN, f64::NAN));
        OrbitSummary {
            index,
            t_start,
            t_end,
            theta_eq,
            theta_max: f64::NEG_INFINITY,
            theta_min: f64::INFINITY,
            amplitude: 0.0,
            jitter_rms: 0.0,
            jitter_peak: 0.0,
            t_entry,
            t_exit,
            entry_theta_min: f64::NAN,
            exit_theta_max: f64::NAN,
            entry_peak: f64::NAN,
            exit_peak: f64::NAN,
        }
    }
}

/// Where a run left the hinge model's range of validity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimitCrossing {
    pub t: f64,
    pub orbit: u64,
    pub theta: f64,
}

/// Settings of a summarised run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SummaryOptions {
    /// Window after shadow entry and exit in which the transient peaks are taken, s.
    pub window: f64,
    /// |θ| beyond which the hinge model is no longer trusted, rad.
    pub theta_limit: f64,
    /// Stop at the first crossing of the limit (else only record it).
    pub stop_at_limit: bool,
    /// Cap the adaptive step at T_n / steps_per_period, T_n the hinge's natural period (0: no
    /// cap). Error control alone lets the step grow to the stability limit of the hinge mode
    /// once the oscillation is small against atol, and the method's own dissipation there can
    /// exceed a weak flutter's growth rate: it would hide flutter near the critical damping.
    pub steps_per_period: f64,
}

/// Default of [`SummaryOptions::steps_per_period`]: Dormand–Prince's dissipation then stays
/// below 1 % of a growth rate of 1e-6 1/s (it falls as the fifth power of the step).
pub const STEPS_PER_HINGE_PERIOD: f64 = 40.0;

/// `method` with its step capped at T_n / steps_per_period (adaptive methods only).
pub fn resolve_hinge(method: &Method, panel: &Panel, steps_per_period: f64) -> Method {
    match method {
        Method::Dopri5(tol) if steps_per_period > 0.0 => {
            let period = 2.0 * std::f64::consts::PI / panel.natural_angular_frequency();
            let mut tol = *tol;
            tol.max_step = tol.max_step.min(period / steps_per_period);
            Method::Dopri5(tol)
        }
        other => *other,
    }
}

struct Collector {
    panel: Panel,
    /// M_T/K_el per kelvin of T_f − T_b (M_T as in `dynamics::thermal_moment`), computed once.
    static_per_kelvin: f64,
    orbit: Orbit,
    coupling: Coupling,
    options: SummaryOptions,
    first_index: u64,
    t_start: f64,
    done: Vec<OrbitSummary>,
    current: OrbitSummary,
    sq_sum: f64,
    duration: f64,
    crossing: Option<LimitCrossing>,
}

impl Collector {
    fn open(&mut self, index: u64) -> Result<OrbitSummary> {
        let t0 = self.t_start + (index - self.first_index) as f64 * self.orbit.period;
        let t1 = t0 + self.orbit.period;
        let flux = self.orbit.flux_scale(0.5 * (t0 + t1));
        let theta_eq = if flux > 0.0 {
            equilibrium(&self.panel, self.coupling, flux)?.theta
        } else {
            0.0
        };
        let eclipse = self.orbit.shadow_intervals(t0, t1).first().copied();
        Ok(OrbitSummary::new(index, t0, t1, theta_eq, eclipse))
    }

    fn close(&mut self) {
        let mut s = self.current;
        s.jitter_rms = if self.duration > 0.0 {
            (self.sq_sum / self.duration).sqrt()
        } else {
            0.0
        };
        self.done.push(s);
        self.sq_sum = 0.0;
        self.duration = 0.0;
    }

    /// θ − M_T/K_el, the dynamic part of the deflection.
    #[inline]
    fn dynamic(&self, y: &Vector4<f64>) -> f64 {
        y[2] - self.static_per_kelvin * (y[0] - y[1])
    }

    /// Whether a step could change an extreme of the current orbit or crosses into an eclipse
    /// window, the next orbit or the limit, judged from its start, midpoint and end (with a
    /// margin for what may lie between them). A margin below [`NEGLIGIBLE_ANGLE`] never asks for
    /// detail.
    #[inline]
    fn may_hold_an_extreme(&self, step: &DenseStep<U4>, y_mid: &Vector4<f64>) -> bool {
        let s = &self.current;
        let (t0, t1) = (step.t0, step.t1);
        let w = self.options.window;
        // NaN eclipse times compare false: no window.
        if t1 > s.t_end
            || (t1 >= s.t_entry && t0 <= s.t_entry + w)
            || (t1 >= s.t_exit && t0 <= s.t_exit + w)
        {
            return true;
        }
        let (a, b, c) = (&step.y0, y_mid, &step.y1);
        // Points `half` apart: where θ turns between two of them, it passes the larger by about
        // |Δθ̇| half / 8 (exactly so for a sinusoid sampled finely); four times that is the margin.
        let half = 0.5 * (t1 - t0);
        let margin = (b[3] - a[3]).abs().max((c[3] - b[3]).abs()) * (0.5 * half);
        let k = self.static_per_kelvin;
        let (qa, qb, qc) = (k * (a[0] - a[1]), k * (b[0] - b[1]), k * (c[0] - c[1]));
        // The quasi-static part bends slowly: twice its second difference bounds its share.
        let bend = 2.0 * (qa - 2.0 * qb + qc).abs();
        if margin + bend <= NEGLIGIBLE_ANGLE {
            // Nothing between the points can pass them by more than a negligible angle (the
            // hinge at rest: on a plateau every point may equal the extreme).
            return false;
        }
        let hi = a[2].max(b[2]).max(c[2]);
        let lo = a[2].min(b[2]).min(c[2]);
        let dev = (hi - s.theta_eq).abs().max((lo - s.theta_eq).abs());
        let dynamic = (a[2] - qa)
            .abs()
            .max((b[2] - qb).abs())
            .max((c[2] - qc).abs());
        let limit_near = self.crossing.is_none() && hi.max(-lo) + margin > self.options.theta_limit;
        // Any comparison with NaN (a state gone non-finite) asks for detail too.
        !(hi + margin <= s.theta_max
            && lo - margin >= s.theta_min
            && dev + margin <= s.amplitude
            && dynamic + margin + bend <= s.jitter_peak)
            || limit_near
    }

    fn read(&mut self, t: f64, y: &Vector4<f64>, dt: f64) -> Result<()> {
        while t > self.current.t_end {
            self.close();
            let next = self.current.index + 1;
            self.current = self.open(next)?;
        }
        let th = y[2];
        let dynamic = self.dynamic(y);
        let s = &mut self.current;
        s.theta_max = s.theta_max.max(th);
        s.theta_min = s.theta_min.min(th);
        let dev = (th - s.theta_eq).abs();
        s.amplitude = s.amplitude.max(dev);
        s.jitter_peak = s.jitter_peak.max(dynamic.abs());
        self.sq_sum += dynamic * dynamic * dt;
        self.duration += dt;
        let w = self.options.window;
        if t >= s.t_entry && t <= s.t_entry + w {
            s.entry_theta_min = if s.entry_theta_min.is_nan() {
                th
            } else {
                s.entry_theta_min.min(th)
            };
            s.entry_peak = if s.entry_peak.is_nan() {
                dev
            } else {
                s.entry_peak.max(dev)
            };
        }
        if t >= s.t_exit && t <= s.t_exit + w {
            s.exit_theta_max = if s.exit_theta_max.is_nan() {
                th
            } else {
                s.exit_theta_max.max(th)
            };
            s.exit_peak = if s.exit_peak.is_nan() {
                dev
            } else {
                s.exit_peak.max(dev)
            };
        }
        if self.crossing.is_none() && th.abs() > self.options.theta_limit {
            self.crossing = Some(LimitCrossing {
                t,
                orbit: s.index,
                theta: th,
            });
        }
        Ok(())
    }
}

/// The observer of a summarised run (see [`prepare_orbits`]).
pub(crate) struct SummaryObserver<'c> {
    collector: Collector,
    error: Option<crate::Error>,
    cancel: &'c Cancel,
    /// Points read in a step: [`READS_PER_STEP`], or [`DETAILED_READS`] in a step that may hold
    /// an extreme; with `detail` false, always `reads` (the fine reference of the tests).
    reads: usize,
    detail: bool,
}

impl SummaryObserver<'_> {
    /// Reads `reads` evenly spaced points of the step, the last its end.
    fn read_step(&mut self, step: &DenseStep<U4>, reads: usize) -> Result<()> {
        let h = (step.t1 - step.t0) / reads as f64;
        for j in 1..reads {
            let t = step.t0 + j as f64 * h;
            self.collector.read(t, &step.eval(t), h)?;
        }
        self.collector.read(step.t1, &step.y1, h)
    }
}

impl Observer<U4> for SummaryObserver<'_> {
    fn on_step(&mut self, step: &DenseStep<U4>) -> ControlFlow<()> {
        if let Err(e) = self.cancel.check() {
            self.error = Some(e);
            return ControlFlow::Break(());
        }
        let read = if !self.detail {
            self.read_step(step, self.reads)
        } else {
            // The midpoint, then either the two points or, where the step may hold an extreme,
            // a finer reading (which includes them).
            let h = 0.5 * (step.t1 - step.t0);
            let t_mid = step.t0 + h;
            let y_mid = step.eval(t_mid);
            if self.collector.may_hold_an_extreme(step, &y_mid) {
                self.read_step(step, DETAILED_READS)
            } else {
                self.collector
                    .read(t_mid, &y_mid, h)
                    .and_then(|()| self.collector.read(step.t1, &step.y1, h))
            }
        };
        if let Err(e) = read {
            self.error = Some(e);
            return ControlFlow::Break(());
        }
        if self.collector.options.stop_at_limit && self.collector.crossing.is_some() {
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    }
}

/// Result of a summarised run over whole orbits.
#[derive(Debug, Clone)]
pub struct OrbitRun {
    pub summaries: Vec<OrbitSummary>,
    pub stats: Stats,
    pub y_end: Vector4<f64>,
    pub crossing: Option<LimitCrossing>,
}

/// Integrates the coupled system over orbits `first_index .. first_index + n_orbits`, the first
/// starting at `t_start`, from `y0`, and summarises each orbit.
#[allow(clippy::too_many_arguments)]
pub fn run_orbits(
    panel: &Panel,
    orbit: &Orbit,
    model: HingeModel,
    coupling: Coupling,
    method: &Method,
    t_start: f64,
    first_index: u64,
    n_orbits: u64,
    y0: Vector4<f64>,
    options: SummaryOptions,
) -> Result<OrbitRun> {
    run_orbits_cancellable(
        panel,
        orbit,
        model,
        coupling,
        method,
        t_start,
        first_index,
        n_orbits,
        y0,
        options,
        &Cancel::new(),
    )
}

/// [`run_orbits`] that stops with [`crate::Error::Cancelled`] within one step of `cancel` being
/// cancelled (the orbits finished before are lost with the call: callers that keep them run
/// fewer orbits per call).
#[allow(clippy::too_many_arguments)]
pub fn run_orbits_cancellable(
    panel: &Panel,
    orbit: &Orbit,
    model: HingeModel,
    coupling: Coupling,
    method: &Method,
    t_start: f64,
    first_index: u64,
    n_orbits: u64,
    y0: Vector4<f64>,
    options: SummaryOptions,
    cancel: &Cancel,
) -> Result<OrbitRun> {
    let mut run = prepare_orbits(
        panel,
        orbit,
        model,
        coupling,
        method,
        t_start,
        first_index,
        n_orbits,
        y0,
        options,
        cancel,
    )?;
    let outcome = solve(
        &mut run.system,
        &run.method,
        run.t0,
        run.y0,
        run.t1,
        &mut run.observer,
    );
    finish_orbits(run.observer, outcome)
}

/// A summarised run set up but not yet integrated: integrate `system` with `method` from
/// (`t0`, `y0`) to `t1` into `observer` (with [`solve`], or in lockstep with other runs), then
/// hand the outcome to [`finish_orbits`].
pub(crate) struct PreparedOrbits<'c> {
    pub system: Coupled,
    pub method: Method,
    pub t0: f64,
    pub t1: f64,
    pub y0: Vector4<f64>,
    pub observer: SummaryObserver<'c>,
}

/// Checks the settings and sets up a summarised run (see [`run_orbits_cancellable`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn prepare_orbits<'c>(
    panel: &Panel,
    orbit: &Orbit,
    model: HingeModel,
    coupling: Coupling,
    method: &Method,
    t_start: f64,
    first_index: u64,
    n_orbits: u64,
    y0: Vector4<f64>,
    options: SummaryOptions,
    cancel: &'c Cancel,
) -> Result<PreparedOrbits<'c>> {
    cancel.check()?;
    crate::error::require_positive("window", options.window)?;
    crate::error::require_positive("theta_limit", options.theta_limit)?;
    crate::error::require_non_negative("steps_per_period", options.steps_per_period)?;
    let method = resolve_hinge(method, panel, options.steps_per_period);
    if n_orbits == 0 {
        return Err(crate::Error::invalid("n_orbits", 0, "must be >= 1"));
    }
    let mut collector = Collector {
        panel: *panel,
        static_per_kelvin: panel.moment_per_kelvin() / panel.hinge_stiffness,
        orbit: *orbit,
        coupling,
        options,
        first_index,
        t_start,
        done: Vec::with_capacity(n_orbits as usize),
        current: OrbitSummary::new(first_index, 0.0, 0.0, 0.0, None),
        sq_sum: 0.0,
        duration: 0.0,
        crossing: None,
    };
    collector.current = collector.open(first_index)?;
    let y0_theta = y0[2];
    collector.current.theta_max = y0_theta;
    collector.current.theta_min = y0_theta;
    Ok(PreparedOrbits {
        system: Coupled::new(*panel, *orbit, model, coupling),
        method,
        t0: t_start,
        t1: t_start + n_orbits as f64 * orbit.period,
        y0,
        observer: SummaryObserver {
            collector,
            error: None,
            cancel,
            reads: READS_PER_STEP,
            detail: true,
        },
    })
}

/// The summaries of a prepared run from the outcome of its integration.
pub(crate) fn finish_orbits(
    observer: SummaryObserver<'_>,
    outcome: Result<(Stats, Vector4<f64>)>,
) -> Result<OrbitRun> {
    let (stats, y_end) = outcome?;
    if let Some(e) = observer.error {
        return Err(e);
    }
    let mut c = observer.collector;
    c.close();
    Ok(OrbitRun {
        summaries: c.done,
        stats,
        y_end,
        crossing: c.crossing,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::Tolerances;

    /// GEO equinox orbits `first .. first + n` of `panel` from `y0` (default: its sunlit
    /// equilibrium at t_start = 0), stopping where |θ| passes `theta_limit`.
    fn run(
        panel: &Panel,
        theta_limit: f64,
        first: u64,
        n: u64,
        y0: Option<Vector4<f64>>,
    ) -> OrbitRun {
        let o = Orbit::geo_equinox();
        let y0 = y0.unwrap_or_else(|| {
            let eq = equilibrium(panel, Coupling::ProjectedArea, 1.0).unwrap();
            Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0)
        });
        let opts = SummaryOptions {
            window: 600.0,
            theta_limit,
            stop_at_limit: true,
            steps_per_period: STEPS_PER_HINGE_PERIOD,
        };
        let method = Method::Dopri5(Tolerances::default());
        let t_start = first as f64 * o.period;
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        run_orbits(
            panel, &o, model, coupling, &method, t_start, first, n, y0, opts,
        )
        .unwrap()
    }

    fn paper_run(n: u64) -> OrbitRun {
        run(&Panel::paper(), 0.5, 0, n, None)
    }

    #[test]
    fn one_summary_per_orbit_with_the_eclipse_transients() {
        let run = paper_run(3);
        assert_eq!(run.summaries.len(), 3);
        let o = Orbit::geo_equinox();
        for (k, s) in run.summaries.iter().enumerate() {
            assert_eq!(s.index, k as u64);
            assert!((s.t_end - s.t_start - o.period).abs() < 1e-6);
            assert!(s.t_entry > s.t_start && s.t_exit < s.t_end);
            assert!(s.entry_theta_min < 0.0, "the gradient reverses in shadow");
            assert!(s.exit_theta_max > s.theta_eq, "overshoot at sunrise");
            assert!(s.theta_min <= s.entry_theta_min && s.theta_max >= s.exit_theta_max);
            assert!(s.amplitude >= s.entry_peak.max(s.exit_peak));
            assert!(s.jitter_rms > 0.0 && s.jitter_rms < s.jitter_peak);
        }
        // Damped (c_d = 3 > c_d*): every orbit repeats the same transients.
        let (a, b) = (run.summaries[1], run.summaries[2]);
        assert!((a.exit_theta_max - b.exit_theta_max).abs() < 1e-6);
        assert!(run.crossing.is_none());
    }

    #[test]
    fn chunked_runs_equal_one_run_orbit_for_orbit() {
        // Resuming from the end state of orbit k must give the same summaries as running on.
        let whole = paper_run(2);
        let first = paper_run(1);
        let second = run(&Panel::paper(), 0.5, 1, 1, Some(first.y_end));
        let d = (whole.summaries[1].exit_theta_max - second.summaries[0].exit_theta_max).abs();
        assert!(d < 1e-8, "{d}");
        assert_eq!(second.summaries[0].index, 1);
    }

    /// The summaries of `n` GEO orbits of `panel` read at `reads` points per step.
    fn run_reading(panel: &Panel, n: u64, reads: usize, detail: bool) -> OrbitRun {
        let o = Orbit::geo_equinox();
        let eq = equilibrium(panel, Coupling::ProjectedArea, 1.0).unwrap();
        let y0 = Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0);
        let opts = SummaryOptions {
            window: 600.0,
            theta_limit: 10.0,
            stop_at_limit: false,
            steps_per_period: STEPS_PER_HINGE_PERIOD,
        };
        let method = Method::Dopri5(Tolerances::default());
        let cancel = Cancel::new();
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        let mut run = prepare_orbits(
            panel, &o, model, coupling, &method, 0.0, 0, n, y0, opts, &cancel,
        )
        .unwrap();
        run.observer.reads = reads;
        run.observer.detail = detail;
        let outcome = solve(
            &mut run.system,
            &run.method,
            run.t0,
            run.y0,
            run.t1,
            &mut run.observer,
        );
        finish_orbits(run.observer, outcome).unwrap()
    }

    #[test]
    fn two_reads_per_step_keep_the_peaks() {
        // Against 64 reads per step of the same steps: every peak within 1e-4 of the orbit's
        // amplitude (peaks of θ itself sit on the equilibrium angle), the jitter's peak within
        // 1e-4 and its RMS within 0.1 % of themselves. Measured: peaks 5e-7 (damped) and 7e-6
        // (undamped, growing to 0.56 rad), jitter peak 8e-6, RMS 1.3e-4 and 4.9e-4, with 1.5 %
        // and 8 % of the steps read in detail. Four reads in every step (before): peaks 6e-5,
        // jitter peak 1.4e-4, RMS 1.9e-4.
        for damping in [3.0, 0.0] {
            let panel = Panel {
                damping,
                ..Panel::paper()
            };
            let fine = run_reading(&panel, 2, 64, false);
            let coarse = run_reading(&panel, 2, READS_PER_STEP, true);
            assert_eq!(fine.stats, coarse.stats);
            for (f, c) in fine.summaries.iter().zip(&coarse.summaries) {
                let scale = f.amplitude;
                // (name, fine, coarse, +1 for a maximum, −1 for a minimum)
                let peaks = [
                    ("theta_max", f.theta_max, c.theta_max, 1.0),
                    ("theta_min", f.theta_min, c.theta_min, -1.0),
                    ("amplitude", f.amplitude, c.amplitude, 1.0),
                    (
                        "entry_theta_min",
                        f.entry_theta_min,
                        c.entry_theta_min,
                        -1.0,
                    ),
                    ("exit_theta_max", f.exit_theta_max, c.exit_theta_max, 1.0),
                    ("entry_peak", f.entry_peak, c.entry_peak, 1.0),
                    ("exit_peak", f.exit_peak, c.exit_peak, 1.0),
                ];
                for (name, want, got, sense) in peaks {
                    let rel = (got - want).abs() / scale;
                    assert!(
                        rel < 1e-3,
                        "damping {damping} {name}: {got} vs {want} ({rel:e})"
                    );
                    // The points read are a subset of the fine ones (j/2 = 32j/64 and
                    // j/8 = 8j/64 exactly):
                    // a sparser reading can only miss a peak, never pass it.
                    assert!(sense * got <= sense * want, "{name}: {got} beyond {want}");
                }
                let rel = (c.jitter_peak - f.jitter_peak).abs() / f.jitter_peak;
                assert!(rel < 1e-4, "damping {damping} jitter_peak: {rel:e}");
                let rel = (c.jitter_rms - f.jitter_rms).abs() / f.jitter_rms;
                assert!(rel < 1e-3, "damping {damping} jitter_rms: {rel:e}");
            }
        }
    }

    #[test]
    fn the_limit_stops_an_undamped_panel() {
        let p = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        let run = run(&p, 0.35, 0, 20, None);
        let c = run
            .crossing
            .expect("an undamped panel below c_d* must leave the limit");
        assert!(c.theta.abs() > 0.35);
        let period = Orbit::geo_equinox().period;
        assert!(run.stats.stopped && run.stats.t_end < 20.0 * period);
        assert_eq!(run.summaries.last().unwrap().index, c.orbit);
    }
}
