//! Long runs (`tj.simulate_orbits`, `python/thermojitter/longrun.py`): per-orbit summaries, so
//! that memory grows with the number of orbits, not of steps.
//!
//! Each accepted step is read at two points of its dense output, the middle and the end, and at
//! eight evenly spaced points where θ̇ changes sign within the step (an extreme of θ lies there).
//! With the step capped at T_n/40 ([`STEPS_PER_HINGE_PERIOD`]) two reads are at most T_n/80
//! apart, so a peak between them is missed by at most 1 − cos(π/80) ≈ 7.7e-4 of the oscillation's
//! amplitude; the eight reads around each extreme bring that to about 5e-5, and keep the peaks
//! when the step is not capped (`tests::two_reads_keep_the_peaks`).

use crate::analysis::steady::equilibrium;
use crate::cancel::Cancel;
use crate::error::Result;
use crate::inputs::orbit::{EclipseTable, Orbit};
use crate::inputs::panel::Panel;
use crate::models::coupled::{Coupled, Coupling};
use crate::models::hinge::{quasi_static, HingeModel};
use crate::numerics::integrate::{solve, DenseStep, Method, Observer, OdeSystem, State, Stats};
use crate::runs::lockstep::{LaneObserver, StepReads};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, Vector4, U4};
use std::ops::ControlFlow;

/// How the summaries read a model's state: the hinge angle and the quasi-static angle
/// M_T/K_el at (t, y), and the sunlit equilibrium angle under a flux factor.
pub trait SummaryView {
    fn theta_eq(&self, flux: f64) -> Result<f64>;
    /// The sunlit equilibrium angle under every load of `orbit` at time t (its Earth heating
    /// and attitude); by default refused: the model's summaries take the front's sunlight only.
    fn theta_eq_loaded(&self, orbit: &Orbit, t: f64) -> Result<f64> {
        let _ = t;
        Err(crate::models::coupled::unsupported_face_loads(
            orbit,
            "this model's orbit summaries",
        ))
    }
    /// (θ, M_T/K_el) at time t in state y.
    fn angles(&self, t: f64, y: &[f64]) -> (f64, f64);
    /// θ̇ in state y, rad/s: where its sign changes within a step, θ has an extreme there and
    /// the step is read more finely.
    fn rate(&self, y: &[f64]) -> f64;
    /// (θ, M_T/K_el) at the end t of a step, with the slope `dy` = f(t, y) the integrator
    /// evaluated there: a view whose M_T costs a model evaluation reads it off the equation of
    /// motion instead. By default as [`SummaryView::angles`].
    #[inline]
    fn angles_at_end(&self, t: f64, y: &[f64], dy: &[f64]) -> (f64, f64) {
        let _ = dy;
        self.angles(t, y)
    }
    /// Whether the points inside a step are read with the interpolant's slope there
    /// ([`crate::numerics::integrate::DenseStep::slope`]), through [`SummaryView::angles_inside`]: a
    /// view whose M_T costs a model evaluation reads it off the equation of motion. By default
    /// no: the slope is not formed.
    #[inline]
    fn reads_slopes(&self) -> bool {
        false
    }
    /// (θ, M_T/K_el) at a time t strictly inside a step, with `dy` the interpolant's slope
    /// there (when [`SummaryView::reads_slopes`]). By default as [`SummaryView::angles`].
    #[inline]
    fn angles_inside(&self, t: f64, y: &[f64], dy: &[f64]) -> (f64, f64) {
        let _ = dy;
        self.angles(t, y)
    }
}

/// The two-layer system's view: state (T_f, T_b, θ, θ̇).
pub(crate) struct TwoLayerView {
    pub(crate) panel: Panel,
    pub(crate) coupling: Coupling,
}

impl SummaryView for TwoLayerView {
    fn theta_eq(&self, flux: f64) -> Result<f64> {
        Ok(equilibrium(&self.panel, self.coupling, flux)?.theta)
    }
    fn theta_eq_loaded(&self, orbit: &Orbit, t: f64) -> Result<f64> {
        let system = Coupled::new(self.panel, *orbit, HingeModel::Nonlinear, self.coupling);
        Ok(system.sunlit_steady_state(t)?[2])
    }
    #[inline]
    fn angles(&self, _t: f64, y: &[f64]) -> (f64, f64) {
        let p = &self.panel;
        (
            y[2],
            quasi_static(p.moment_per_kelvin(), p.hinge_stiffness, y[0], y[1]),
        )
    }
    #[inline]
    fn rate(&self, y: &[f64]) -> f64 {
        y[3]
    }
}

/// Points read in a step where θ̇ changes sign (evenly spaced, the last at the step's end); two
/// (the middle and the end) elsewhere.
const FINE_READS: usize = 8;

/// One point read from a step: time, θ, the dynamic part θ − M_T/K_el, and the point's share of
/// ∫(dynamic)² dt over the step.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Point {
    pub(crate) t: f64,
    pub(crate) theta: f64,
    pub(crate) dynamic: f64,
    pub(crate) sq: f64,
}

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

impl LimitCrossing {
    /// The crossing at t of a run that began at `t_start`: `orbit` counts the whole orbits
    /// since then, as the long runs number theirs from their start.
    pub fn in_run(orbit: &Orbit, t_start: f64, t: f64, theta: f64) -> Self {
        LimitCrossing {
            t,
            orbit: ((t - t_start) / orbit.period).floor().max(0.0) as u64,
            theta,
        }
    }
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

impl SummaryOptions {
    /// Refuses a window or limit that is not positive, and a negative step cap.
    pub fn check(&self) -> Result<()> {
        crate::error::require_positive("window", self.window)?;
        crate::error::require_positive("theta_limit", self.theta_limit)?;
        crate::error::require_non_negative("steps_per_period", self.steps_per_period)
    }
}

/// Largest [`SummaryOptions::steps_per_period`]: finer steps than T_n/10⁴ resolve nothing more
/// and only multiply the cost.
pub const MAX_STEPS_PER_PERIOD: f64 = 1e4;

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

/// A span (from, to) of one orbit that holds no window edge, and whether it lies in the window
/// after entry and after exit.
#[derive(Debug, Clone, Copy)]
struct Calm {
    from: f64,
    to: f64,
    in_entry: bool,
    in_exit: bool,
}

/// Builds the per-orbit summaries from what the propagator reports: points of the solution
/// (the integrators' dense output) or bands [θ_lo, θ_hi] that hold it (the hybrid propagator's
/// oscillation envelopes and exactly propagated arcs).
pub(crate) struct Collector<V> {
    pub(crate) view: V,
    pub(crate) orbit: Orbit,
    pub(crate) options: SummaryOptions,
    pub(crate) first_index: u64,
    /// The run's last orbit: the end of its final step may round past that orbit's end.
    last_index: u64,
    pub(crate) t_start: f64,
    pub(crate) done: Vec<OrbitSummary>,
    pub(crate) current: OrbitSummary,
    pub(crate) sq_sum: f64,
    pub(crate) duration: f64,
    pub(crate) crossing: Option<LimitCrossing>,
    /// The last step's end as read: (t, dynamic part), the next step's start.
    pub(crate) end: (f64, f64),
    /// Where the next steps' points are known to lie inside one orbit and on one side of each
    /// window's edges.
    calm: Calm,
    /// θ where the current orbit ends, once read: the next orbit starts there
    /// ([`Collector::orbit_starts`]).
    next_start: Option<f64>,
    /// The orbit's eclipses, searched a stretch of orbits at a time.
    eclipses: EclipseTable,
}

/// What a collector has taken up to a time between two of its reads, to go back to
/// ([`Collector::rewind`]): a propagator that gives an orbit back reads it again another way.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Mark {
    done: usize,
    current: OrbitSummary,
    sq_sum: f64,
    duration: f64,
    crossing: Option<LimitCrossing>,
    end: (f64, f64),
    calm: Calm,
    next_start: Option<f64>,
}

impl<V: SummaryView> Collector<V> {
    /// A collector of the orbits of `spec`, the first starting with hinge angle θ0.
    pub(crate) fn new(view: V, spec: &OrbitRunSpec, theta0: f64) -> Result<Self> {
        let OrbitRunSpec {
            ref orbit,
            options,
            t_start,
            first_index,
            n_orbits,
            ..
        } = *spec;
        // The span (and with it the eclipses and the rows kept) is checked before anything is
        // allocated for it.
        let t_end = spec.t_end();
        orbit.check_span(t_start, t_end).map_err(|_| {
            crate::Error::invalid(
                "n_orbits",
                n_orbits,
                &format!(
                    "with t_start = {t_start} s reaches t = {t_end:e} s; at most {:e} s and \
                     {:e} eclipses",
                    crate::numerics::integrate::MAX_TIME,
                    crate::inputs::orbit::MAX_ECLIPSES
                ),
            )
        })?;
        let mut collector = Collector {
            view,
            orbit: *orbit,
            options,
            first_index,
            last_index: first_index + n_orbits.saturating_sub(1),
            t_start,
            done: Vec::with_capacity(n_orbits as usize),
            current: OrbitSummary::new(first_index, 0.0, 0.0, 0.0, None),
            sq_sum: 0.0,
            duration: 0.0,
            crossing: None,
            end: (f64::NAN, 0.0),
            calm: Calm {
                from: f64::NAN,
                to: f64::NAN,
                in_entry: false,
                in_exit: false,
            },
            next_start: None,
            eclipses: EclipseTable::until(orbit, t_end),
        };
        collector.current = collector.open(first_index)?;
        collector.starts_with(theta0);
        Ok(collector)
    }

    fn open(&mut self, index: u64) -> Result<OrbitSummary> {
        let t0 = self.t_start + (index - self.first_index) as f64 * self.orbit.period;
        let t1 = t0 + self.orbit.period;
        let flux = self.orbit.flux_scale(0.5 * (t0 + t1));
        let theta_eq = if self.orbit.has_face_loads() {
            // Under the Earth's loads and the attitude's incidence at the orbit's start (its
            // noon for `Orbit.circular`), in full sunlight.
            self.view.theta_eq_loaded(&self.orbit, t0)?
        } else if flux > 0.0 {
            self.view.theta_eq(flux)?
        } else {
            0.0
        };
        // The first eclipse overlapping the orbit, clipped to it (Orbit::shadow_intervals).
        let eclipse = self
            .eclipses
            .overlapping(t0, t1)
            .first()
            .map(|e| (e.outer.0.max(t0), e.outer.1.min(t1)));
        Ok(OrbitSummary::new(index, t0, t1, theta_eq, eclipse))
    }

    /// The current orbit, just opened, starts with hinge angle θ: its extremes start there, and
    /// so do its windows when it opens in an eclipse carried over from the last orbit (or
    /// leaves it at once).
    fn starts_with(&mut self, theta: f64) {
        let s = &self.current;
        let (t0, in_entry, in_exit) = (s.t_start, s.t_entry, s.t_exit);
        self.take(theta, theta, 0.0, 0.0, 0.0, in_entry == t0, in_exit == t0);
    }

    /// θ at t, where a reader has reached the current orbit's end (its last read): the next
    /// orbit starts with it. Elsewhere nothing.
    pub(crate) fn orbit_starts(&mut self, t: f64, theta: f64) {
        if t == self.current.t_end && self.current.index < self.last_index {
            self.next_start = Some(theta);
        }
    }

    pub(crate) fn mark(&self) -> Mark {
        Mark {
            done: self.done.len(),
            current: self.current,
            sq_sum: self.sq_sum,
            duration: self.duration,
            crossing: self.crossing,
            end: self.end,
            calm: self.calm,
            next_start: self.next_start,
        }
    }

    /// Forgets everything taken since `mark`.
    pub(crate) fn rewind(&mut self, mark: Mark) {
        self.done.truncate(mark.done);
        self.current = mark.current;
        self.sq_sum = mark.sq_sum;
        self.duration = mark.duration;
        self.crossing = mark.crossing;
        self.end = mark.end;
        self.calm = mark.calm;
        self.next_start = mark.next_start;
    }

    /// The run's summaries, with its counters and end state: the last orbit closed.
    pub(crate) fn finish<D: Dim>(mut self, stats: Stats, y_end: State<D>) -> Summarised<D>
    where
        DefaultAllocator: Allocator<D>,
    {
        self.close();
        Summarised {
            summaries: self.done,
            stats,
            y_end,
            crossing: self.crossing,
        }
    }

    pub(crate) fn close(&mut self) {
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

    /// One point of the solution, standing for the interval dt before it.
    /// The RMS of the dynamic part over the current orbit so far (0 before any of it).
    pub(crate) fn rms_so_far(&self) -> f64 {
        if self.duration > 0.0 {
            (self.sq_sum / self.duration).sqrt()
        } else {
            0.0
        }
    }

    pub(crate) fn read(&mut self, t: f64, y: &[f64], dt: f64) -> Result<()> {
        let p = self.point(t, y);
        self.record(
            t,
            p.theta,
            p.theta,
            p.dynamic.abs(),
            p.dynamic * p.dynamic * dt,
            dt,
        )
    }

    /// The point of the solution (t, y) as the summaries read it.
    #[inline]
    pub(crate) fn point(&self, t: f64, y: &[f64]) -> Point {
        let (theta, quasi_static) = self.view.angles(t, y);
        Point {
            t,
            theta,
            dynamic: theta - quasi_static,
            sq: 0.0,
        }
    }

    /// A point (t, y) strictly inside `step`, as the summaries read it: with the interpolant's
    /// slope there when the view reads slopes.
    #[inline]
    pub(crate) fn inside_point<D: Dim>(&self, step: &DenseStep<D>, t: f64, y: &[f64]) -> Point
    where
        DefaultAllocator: Allocator<D>,
    {
        if !self.view.reads_slopes() {
            return self.point(t, y);
        }
        let (theta, quasi_static) = self.view.angles_inside(t, y, step.slope(t).as_slice());
        Point {
            t,
            theta,
            dynamic: theta - quasi_static,
            sq: 0.0,
        }
    }

    /// θ at t strictly inside `step` read beside the step's own points (no share of
    /// ∫(dynamic)²): a window's edge or the orbit's end. Past the limit the step's own reads
    /// mark the crossing. Returns θ there.
    pub(crate) fn read_inside<D: Dim>(&mut self, step: &DenseStep<D>, t: f64) -> Result<f64>
    where
        DefaultAllocator: Allocator<D>,
    {
        let p = self.inside_point(step, t, step.eval(t).as_slice());
        if p.theta.abs() <= self.options.theta_limit {
            self.record(t, p.theta, p.theta, p.dynamic.abs(), 0.0, 0.0)?;
        }
        Ok(p.theta)
    }

    /// The end (t, y) of a step with its slope `dy` there, as the summaries read it.
    #[inline]
    pub(crate) fn end_point(&self, t: f64, y: &[f64], dy: &[f64]) -> Point {
        let (theta, quasi_static) = self.view.angles_at_end(t, y, dy);
        Point {
            t,
            theta,
            dynamic: theta - quasi_static,
            sq: 0.0,
        }
    }

    /// A step from t0 read at its middle and end (θ̇ keeps its sign over it), with the dynamic
    /// part at its start: ∫(dynamic)² by Simpson's rule.
    #[inline]
    pub(crate) fn read_two(
        &mut self,
        t0: f64,
        start: f64,
        mut mid: Point,
        mut end: Point,
    ) -> Result<()> {
        let dt = 0.5 * (end.t - t0);
        let third = dt / 3.0;
        mid.sq = third * (start * start + 4.0 * (mid.dynamic * mid.dynamic));
        end.sq = third * (end.dynamic * end.dynamic);
        self.end = (end.t, end.dynamic);
        self.read_points(&[mid, end], dt)
    }

    /// Points of one step, in time order, each standing for the interval dt before it with its
    /// share `sq` of ∫(dynamic)²: the same as [`Collector::record`] of each, taken together when
    /// the points lie inside the calm span (nearly every step) and within the limit. Generic in
    /// their number so that this common case unrolls into the caller.
    #[inline(always)]
    pub(crate) fn read_points<const N: usize>(
        &mut self,
        points: &[Point; N],
        dt: f64,
    ) -> Result<()> {
        let (first, last) = (points[0].t, points[N - 1].t);
        let calm = self.calm;
        if first > calm.from && last < calm.to {
            // The points are finite (the integrator accepts only finite states).
            let (mut lo, mut hi) = (points[0].theta, points[0].theta);
            let (mut peak, mut sq) = (points[0].dynamic.abs(), points[0].sq);
            for p in &points[1..] {
                lo = if p.theta < lo { p.theta } else { lo };
                hi = if p.theta > hi { p.theta } else { hi };
                let d = p.dynamic.abs();
                peak = if d > peak { d } else { peak };
                sq += p.sq;
            }
            let limit = self.options.theta_limit;
            if self.crossing.is_some() || (hi <= limit && lo >= -limit) {
                let span = dt * N as f64;
                self.take(lo, hi, peak, sq, span, calm.in_entry, calm.in_exit);
                return Ok(());
            }
        }
        self.record_each(points, dt)
    }

    /// [`Collector::record`] of each point, then the calm span after them: the steps near a
    /// window's edge or the limit.
    #[inline(never)]
    fn record_each(&mut self, points: &[Point], dt: f64) -> Result<()> {
        for p in points {
            self.record(p.t, p.theta, p.theta, p.dynamic.abs(), p.sq, dt)?;
        }
        self.calm = self.calm_around(points[points.len() - 1].t);
        Ok(())
    }

    /// The edges of the current orbit's windows after entry and exit strictly inside (t0, t1),
    /// in the order entry, entry + window, exit, exit + window, as (their times, how many):
    /// where a window's extreme lies while θ still moves, which a step's middle and end miss by
    /// up to half a step.
    pub(crate) fn window_edges_in(&self, t0: f64, t1: f64) -> ([f64; 4], usize) {
        let mut edges = [0.0; 4];
        let mut n = 0;
        let calm = self.calm;
        if t0 > calm.from && t1 < calm.to {
            return (edges, 0); // inside the calm span: no edge
        }
        let s = &self.current;
        let w = self.options.window;
        for edge in [s.t_entry, s.t_entry + w, s.t_exit, s.t_exit + w] {
            if edge > t0 && edge < t1 {
                edges[n] = edge;
                n += 1;
            }
        }
        (edges, n)
    }

    /// The end of the current orbit's window that starts at `start` (its entry or exit): a
    /// window's length on, or the orbit's end. NaN for a window the orbit does not have.
    pub(crate) fn window_end(&self, start: f64) -> f64 {
        (start + self.options.window).min(self.current.t_end)
    }

    /// Whether a window's edge lies strictly inside (t0, t1) or the current orbit ends by t1 (an
    /// edge past the orbit's end is then in the step too).
    #[cold]
    #[inline(never)]
    fn edge_or_end_in(&self, t0: f64, t1: f64) -> bool {
        self.window_edges_in(t0, t1).1 > 0 || t1 >= self.current.t_end
    }

    /// The span of the current orbit around t between the edges of its windows (and its end),
    /// where being inside a window or not cannot change.
    fn calm_around(&self, t: f64) -> Calm {
        let s = &self.current;
        let w = self.options.window;
        let (mut from, mut to) = (f64::NEG_INFINITY, s.t_end);
        for edge in [s.t_entry, s.t_entry + w, s.t_exit, s.t_exit + w] {
            if edge <= t && edge > from {
                from = edge;
            } else if edge > t && edge < to {
                to = edge;
            }
        }
        // Points strictly inside (from, to) are in a window if the whole span is.
        let inside = |start: f64| from >= start && to <= start + w;
        Calm {
            from,
            to,
            in_entry: inside(s.t_entry),
            in_exit: inside(s.t_exit),
        }
    }

    /// Adds to the current orbit: θ within [lo, hi], the dynamic part's magnitude at most
    /// `dynamic_abs`, ∫(dynamic)² = `sq` over `dt`, inside the entry and exit windows or not.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn take(
        &mut self,
        lo: f64,
        hi: f64,
        dynamic_abs: f64,
        sq: f64,
        dt: f64,
        in_entry: bool,
        in_exit: bool,
    ) {
        // Every accumulator is read before any is written: the compiler may merge two of the
        // updates into one masked vector store, and a later load of a neighbour would wait for
        // that store to retire (masked stores are not forwarded).
        let before = self.current;
        let s = &mut self.current;
        let dev = larger((hi - before.theta_eq).abs(), (lo - before.theta_eq).abs());
        s.theta_max = larger(before.theta_max, hi);
        s.theta_min = smaller(before.theta_min, lo);
        s.amplitude = larger(before.amplitude, dev);
        s.jitter_peak = larger(before.jitter_peak, dynamic_abs);
        self.sq_sum += sq;
        self.duration += dt;
        if in_entry {
            s.entry_theta_min = nan_min(before.entry_theta_min, lo);
            s.entry_peak = nan_max(before.entry_peak, dev);
        }
        if in_exit {
            s.exit_theta_max = nan_max(before.exit_theta_max, hi);
            s.exit_peak = nan_max(before.exit_peak, dev);
        }
    }

    /// Moves on to the orbit that holds t (closing the finished ones). The run ends at
    /// t_start + n P, which can round above the last orbit's t0 + P: no orbit opens past it.
    pub(crate) fn advance(&mut self, t: f64) -> Result<()> {
        while t > self.current.t_end && self.current.index < self.last_index {
            let start = self.next_start.take();
            self.close();
            let next = self.current.index + 1;
            self.current = self.open(next)?;
            if let Some(theta) = start {
                self.starts_with(theta);
            }
        }
        Ok(())
    }

    /// A span (t_a, t_b] inside one orbit whose θ extremes over any sub-interval `extremes` gives,
    /// with the dynamic part's largest magnitude and ∫(dynamic)² over the span. The caller keeps
    /// |θ| below the limit over the span.
    pub(crate) fn record_span(
        &mut self,
        t_a: f64,
        t_b: f64,
        extremes: &dyn Fn(f64, f64) -> (f64, f64),
        dynamic_abs: f64,
        sq: f64,
    ) -> Result<()> {
        // The orbit that holds the span's middle (its ends may round onto a neighbour's edge).
        self.advance(0.5 * (t_a + t_b))?;
        let (lo, hi) = extremes(t_a, t_b);
        let s = &mut self.current;
        s.theta_max = s.theta_max.max(hi);
        s.theta_min = s.theta_min.min(lo);
        let eq = s.theta_eq;
        let dev = |lo: f64, hi: f64| (hi - eq).abs().max((lo - eq).abs());
        s.amplitude = s.amplitude.max(dev(lo, hi));
        s.jitter_peak = s.jitter_peak.max(dynamic_abs);
        self.sq_sum += sq;
        self.duration += t_b - t_a;
        let w = self.options.window;
        let (entry, exit) = (s.t_entry, s.t_exit);
        for (start, is_entry) in [(entry, true), (exit, false)] {
            let (a, b) = (t_a.max(start), t_b.min(start + w));
            if start.is_nan() || a > b {
                continue; // no window, or no overlap
            }
            let (l, h) = extremes(a, b);
            let d = dev(l, h);
            let s = &mut self.current;
            if is_entry {
                s.entry_theta_min = nan_min(s.entry_theta_min, l);
                s.entry_peak = nan_max(s.entry_peak, d);
            } else {
                s.exit_theta_max = nan_max(s.exit_theta_max, h);
                s.exit_peak = nan_max(s.exit_peak, d);
            }
        }
        Ok(())
    }

    /// θ lies in [th_lo, th_hi] at t; the dynamic part's magnitude is at most `dynamic_abs`
    /// there, and ∫(dynamic)² over the interval dt before t is `sq`.
    pub(crate) fn record(
        &mut self,
        t: f64,
        th_lo: f64,
        th_hi: f64,
        dynamic_abs: f64,
        sq: f64,
        dt: f64,
    ) -> Result<()> {
        self.advance(t)?;
        let (s, w) = (&self.current, self.options.window);
        let in_entry = t >= s.t_entry && t <= s.t_entry + w;
        let in_exit = t >= s.t_exit && t <= s.t_exit + w;
        self.take(th_lo, th_hi, dynamic_abs, sq, dt, in_entry, in_exit);
        if self.crossing.is_none() {
            let limit = self.options.theta_limit;
            let theta = if th_hi > limit {
                Some(th_hi)
            } else if th_lo < -limit {
                Some(th_lo)
            } else {
                None
            };
            if let Some(theta) = theta {
                self.crossing = Some(LimitCrossing {
                    t,
                    orbit: self.current.index,
                    theta,
                });
            }
        }
        Ok(())
    }
}

/// max(acc, v) for values that are never NaN (the solution's, and accumulators that start at
/// ±∞ or 0): one comparison, where `f64::max` also sorts out NaN on every step.
#[inline(always)]
fn larger(acc: f64, v: f64) -> f64 {
    if v > acc {
        v
    } else {
        acc
    }
}

/// min(acc, v) for values that are never NaN, as [`larger`].
#[inline(always)]
fn smaller(acc: f64, v: f64) -> f64 {
    if v < acc {
        v
    } else {
        acc
    }
}

/// min(acc, v), where NaN in `acc` means "nothing yet".
fn nan_min(acc: f64, v: f64) -> f64 {
    if acc.is_nan() {
        v
    } else {
        acc.min(v)
    }
}

/// max(acc, v), where NaN in `acc` means "nothing yet".
fn nan_max(acc: f64, v: f64) -> f64 {
    if acc.is_nan() {
        v
    } else {
        acc.max(v)
    }
}

pub(crate) struct SummaryObserver<'c, V> {
    pub(crate) collector: Collector<V>,
    pub(crate) error: Option<crate::Error>,
    pub(crate) cancel: &'c Cancel,
}

impl<D: Dim, V: SummaryView> Observer<D> for SummaryObserver<'_, V>
where
    DefaultAllocator: Allocator<D>,
{
    fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()> {
        if let Err(e) = self.cancel.check() {
            self.error = Some(e);
            return ControlFlow::Break(());
        }
        let c = &mut self.collector;
        let (t0, t1) = (step.t0, step.t1);
        let end_point = |c: &Collector<V>| match step.end_slope() {
            Some(dy) => c.end_point(t1, step.y1.as_slice(), dy.as_slice()),
            None => c.point(t1, step.y1.as_slice()),
        };
        // The edges of the current orbit's windows inside the step, then its end inside the
        // step, read there too; the next orbit starts with θ at that end.
        let orbit_end = c.current.t_end;
        let (edges, n_edges) = c.window_edges_in(t0, t1);
        for &edge in edges[..n_edges].iter().filter(|&&e| e <= orbit_end) {
            if let Err(e) = c.read_inside(step, edge) {
                return self.after(Err(e));
            }
        }
        if t0 < orbit_end && orbit_end <= t1 {
            let theta = if orbit_end == t1 {
                end_point(c).theta
            } else {
                match c.read_inside(step, orbit_end) {
                    Ok(theta) => theta,
                    Err(e) => return self.after(Err(e)),
                }
            };
            c.orbit_starts(orbit_end, theta);
        }
        let (t_mid, y_mid) = step.midpoint();
        let rate = |y: &State<D>| c.view.rate(y.as_slice()) > 0.0;
        let (r0, r_mid, r1) = (rate(&step.y0), rate(&y_mid), rate(&step.y1));
        // ∫(dynamic)² by Simpson's rule over the step's start and the points. The start is the
        // last step's end (read then) unless the run began or resumed here.
        let start = match c.end {
            (t, dynamic) if t == t0 => dynamic,
            _ => c.point(t0, step.y0.as_slice()).dynamic,
        };
        let read = if r0 == r_mid && r_mid == r1 {
            let mid = c.inside_point(step, t_mid, y_mid.as_slice());
            let end = end_point(c);
            c.read_two(t0, start, mid, end)
        } else {
            let mut points = [Point::default(); FINE_READS];
            // t0 + 4 (h/8) is the midpoint, bit for bit (h/8 and 4 (h/8) are exact).
            let dt = (t1 - t0) / FINE_READS as f64;
            let third = dt / 3.0;
            for (j, p) in points.iter_mut().enumerate() {
                let k = j + 1;
                *p = if k == FINE_READS {
                    end_point(c)
                } else if 2 * k == FINE_READS {
                    c.inside_point(step, t_mid, y_mid.as_slice())
                } else {
                    let t = t0 + k as f64 * dt;
                    c.inside_point(step, t, step.eval(t).as_slice())
                };
                // Simpson's weights (1, 4, 2, 4, …, 2, 4, 1).
                let w = if k == FINE_READS {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                p.sq = w * third * (p.dynamic * p.dynamic);
            }
            points[0].sq += third * (start * start);
            c.end = (t1, points[FINE_READS - 1].dynamic);
            c.read_points(&points, dt)
        };
        self.after(read)
    }
}

impl<V> SummaryObserver<'_, V> {
    /// Whether the run goes on after a step was read.
    #[inline]
    fn after(&mut self, read: Result<()>) -> ControlFlow<()> {
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

impl LaneObserver for SummaryObserver<'_, TwoLayerView> {
    fn dynamic_form(&self) -> Option<(f64, f64)> {
        let p = &self.collector.view.panel;
        Some((p.moment_per_kelvin(), p.hinge_stiffness))
    }

    /// The steps `on_step` reads twice (θ̇ keeps its sign, the start read with the last step),
    /// from the reads the lanes computed; the others from their dense output. Inlined into the
    /// lanes' loop: called out of line, its loads of the reads just written there wait for the
    /// stores to retire (two 8-byte stores read back as one 16-byte load are not forwarded).
    #[inline(always)]
    fn on_reads(&mut self, r: &StepReads) -> Option<ControlFlow<()>> {
        let c = &mut self.collector;
        let [r0, r_mid, r1] = r.rising;
        if !(r0 == r_mid && r_mid == r1 && c.end.0 == r.t0) {
            return None;
        }
        // A window's edge or the orbit's end in the step: read from the dense step. A step that
        // ends inside the calm span (nearly every step; it starts where the last one read,
        // past the span's start) holds neither.
        let in_calm = r.t1 < c.calm.to; // false before any calm span (NaN)
        if !in_calm && c.edge_or_end_in(r.t0, r.t1) {
            return None;
        }
        if let Err(e) = self.cancel.check() {
            self.error = Some(e);
            return Some(ControlFlow::Break(()));
        }
        let point = |t, k: usize| Point {
            t,
            theta: r.theta[k],
            dynamic: r.dynamic[k],
            sq: 0.0,
        };
        let read = c.read_two(r.t0, c.end.1, point(r.t_mid, 0), point(r.t1, 1));
        Some(self.after(read))
    }
}

/// Result of a summarised run of the two-layer panel over whole orbits.
pub type OrbitRun = Summarised<U4>;

/// What every summarised run over whole orbits is asked, whatever its model's state: `panel` on
/// `orbit` with the hinge `model` and `coupling`, integrated with `method` (the hybrid
/// propagator's fallback when it runs them) over orbits `first_index .. first_index + n_orbits`,
/// the first starting at `t_start`, each summarised as `options` ask.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitRunSpec {
    pub panel: Panel,
    pub orbit: Orbit,
    pub model: HingeModel,
    pub coupling: Coupling,
    pub method: Method,
    pub t_start: f64,
    pub first_index: u64,
    pub n_orbits: u64,
    pub options: SummaryOptions,
}

impl OrbitRunSpec {
    /// The end of the last orbit.
    pub(crate) fn t_end(&self) -> f64 {
        self.t_start + self.n_orbits as f64 * self.orbit.period
    }
}

/// A summarised run of the two-layer panel over whole orbits: `spec` from `y0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitRunRequest {
    pub spec: OrbitRunSpec,
    pub y0: Vector4<f64>,
}

/// The default start of a run of `panel` on `orbit` at `t0`: the sunlit steady state at rest,
/// (T_f, T_b, θ, 0), under the Sun's distance at `t0`, and under the Earth's loads and the
/// attitude's incidence there when the orbit has them. Every run over orbits (single or in a
/// Monte Carlo batch) starts here unless given a state.
pub fn start_state(
    panel: &Panel,
    orbit: &Orbit,
    coupling: Coupling,
    t0: f64,
) -> Result<Vector4<f64>> {
    Orbit::check_time(t0)?;
    if orbit.has_face_loads() {
        panel.validate()?;
        let system = Coupled::new(*panel, *orbit, HingeModel::Nonlinear, coupling);
        return system.sunlit_steady_state(t0);
    }
    Ok(equilibrium(panel, coupling, orbit.flux_scale(t0))?.state())
}

/// Integrates the coupled system over the orbits of `req` and summarises each orbit.
pub fn run_orbits(req: &OrbitRunRequest) -> Result<OrbitRun> {
    run_orbits_cancellable(req, &Cancel::new())
}

/// [`run_orbits`] that stops with [`crate::Error::Cancelled`] within one step of `cancel` being
/// cancelled (the orbits finished before are lost with the call: callers that keep them run
/// fewer orbits per call).
pub fn run_orbits_cancellable(req: &OrbitRunRequest, cancel: &Cancel) -> Result<OrbitRun> {
    let s = &req.spec;
    let mut system = Coupled::new(s.panel, s.orbit, s.model, s.coupling);
    let view = TwoLayerView {
        panel: s.panel,
        coupling: s.coupling,
    };
    run_summarised(&mut system, view, s, req.y0, 2, cancel)
}

/// A summarised run of the two-layer panel set up but not yet integrated: integrate `system` with
/// `method` from (`t0`, `y0`) to `t1` into `observer` (with [`solve`], or in lockstep with
/// other runs), then hand the outcome to [`finish_orbits`]. The same checks and observer as
/// [`run_orbits_cancellable`].
pub(crate) struct PreparedOrbits<'c> {
    pub system: Coupled,
    pub method: Method,
    pub t0: f64,
    pub t1: f64,
    pub y0: Vector4<f64>,
    pub observer: SummaryObserver<'c, TwoLayerView>,
}

/// Sets up what [`run_orbits_cancellable`] integrates.
pub(crate) fn prepare_orbits<'c>(
    req: &OrbitRunRequest,
    cancel: &'c Cancel,
) -> Result<PreparedOrbits<'c>> {
    let OrbitRunRequest { spec, y0 } = *req;
    let (method, t1, observer) = prepare_summarised(
        TwoLayerView {
            panel: spec.panel,
            coupling: spec.coupling,
        },
        &spec,
        (2, [y0[2], y0[3]]),
        cancel,
    )?;
    Ok(PreparedOrbits {
        system: Coupled::new(spec.panel, spec.orbit, spec.model, spec.coupling),
        method,
        t0: spec.t_start,
        t1,
        y0,
        observer,
    })
}

/// The summaries of a prepared run from the outcome of its integration (as
/// [`run_orbits_cancellable`] and [`run_summarised`] return them).
pub(crate) fn finish_orbits<D: Dim, V: SummaryView>(
    observer: SummaryObserver<'_, V>,
    outcome: Result<(Stats, State<D>)>,
) -> Result<Summarised<D>>
where
    DefaultAllocator: Allocator<D>,
{
    let (stats, y_end) = outcome?;
    if let Some(e) = observer.error {
        return Err(e);
    }
    Ok(observer.collector.finish(stats, y_end))
}

/// The checks of a summarised run of the orbits of `spec` whose start state has θ and θ̇ =
/// `hinge.1` at components `hinge.0` and the next (its temperatures, if any, checked by the
/// caller), and what it integrates with: the method with its step capped as the options ask, the
/// end time, the observer.
fn prepare_summarised<'c, V: SummaryView>(
    view: V,
    spec: &OrbitRunSpec,
    hinge: (usize, [f64; 2]),
    cancel: &'c Cancel,
) -> Result<(Method, f64, SummaryObserver<'c, V>)> {
    let (panel, options) = (&spec.panel, spec.options);
    cancel.check()?;
    crate::error::require_positive("window", options.window)?;
    crate::error::require_positive("theta_limit", options.theta_limit)?;
    // The start's θ and θ̇ (at `hinge.0` and after it); the bound on θ̇ is the same for both
    // hinge models (Hinge::max_start_rate), so the linear one stands for either.
    let (index, start) = hinge;
    let bound = crate::models::hinge::Hinge::new(panel, HingeModel::Linear);
    crate::models::hinge::StructuralModel::check_start(&bound, index, &start)?;
    if !(0.0..=MAX_STEPS_PER_PERIOD).contains(&options.steps_per_period) {
        return Err(crate::Error::invalid(
            "steps_per_period",
            options.steps_per_period,
            &format!("must be in [0, {MAX_STEPS_PER_PERIOD:e}] (0: error control alone)"),
        ));
    }
    let method = resolve_hinge(&spec.method, panel, options.steps_per_period);
    if spec.n_orbits == 0 {
        return Err(crate::Error::invalid("n_orbits", 0, "must be >= 1"));
    }
    let collector = Collector::new(view, spec, start[0])?;
    let observer = SummaryObserver {
        collector,
        error: None,
        cancel,
    };
    Ok((method, spec.t_end(), observer))
}

/// A summarised run of any model: the summaries, the counters and the end state.
#[derive(Debug, Clone)]
pub struct Summarised<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub summaries: Vec<OrbitSummary>,
    pub stats: Stats,
    pub y_end: State<D>,
    pub crossing: Option<LimitCrossing>,
}

/// Integrates `system` over the orbits of `spec` from `y0` at its `t_start` (`y0`'s component
/// `theta_index` is θ) and summarises each orbit through `view`; the step is capped by the
/// panel's hinge period as [`SummaryOptions::steps_per_period`] asks.
pub fn run_summarised<D: Dim, S: OdeSystem<D>, V: SummaryView>(
    system: &mut S,
    view: V,
    spec: &OrbitRunSpec,
    y0: State<D>,
    theta_index: usize,
    cancel: &Cancel,
) -> Result<Summarised<D>>
where
    DefaultAllocator: Allocator<D>,
{
    let hinge = (theta_index, [y0[theta_index], y0[theta_index + 1]]);
    let (method, t_end, mut observer) = prepare_summarised(view, spec, hinge, cancel)?;
    let outcome = solve(system, &method, spec.t_start, y0, t_end, &mut observer);
    finish_orbits(observer, outcome)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::integrate::Tolerances;

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
        run_orbits(&OrbitRunRequest {
            spec: OrbitRunSpec {
                panel: *panel,
                orbit: o,
                model: HingeModel::Nonlinear,
                coupling: Coupling::ProjectedArea,
                method: Method::Dopri5(Tolerances::default()),
                t_start: first as f64 * o.period,
                first_index: first,
                n_orbits: n,
                options: opts,
            },
            y0,
        })
        .unwrap()
    }

    fn paper_run(n: u64) -> OrbitRun {
        run(&Panel::paper(), 0.5, 0, n, None)
    }

    #[test]
    fn the_run_end_rounding_past_the_last_orbit_opens_no_other() {
        // A low orbit whose 5 P + P rounds below 6 P: the run ends (t_start + 6 P) after the
        // last orbit's own end, and the collector must still close six orbits, not seven.
        let o = (0..2000)
            .map(|k| Orbit::leo(400e3 + 137.0 * k as f64))
            .find(|o| 5.0 * o.period + o.period < 6.0 * o.period)
            .expect("such a period exists");
        let panel = Panel::paper();
        let spec = OrbitRunSpec {
            panel,
            orbit: o,
            model: HingeModel::Nonlinear,
            coupling: Coupling::ProjectedArea,
            method: Method::Dopri5(Tolerances::default()),
            t_start: 0.0,
            first_index: 0,
            n_orbits: 6,
            options: SummaryOptions {
                window: 600.0,
                theta_limit: 0.5,
                stop_at_limit: true,
                steps_per_period: STEPS_PER_HINGE_PERIOD,
            },
        };
        let view = TwoLayerView {
            panel,
            coupling: Coupling::ProjectedArea,
        };
        let mut c = Collector::new(view, &spec, 0.0).unwrap();
        c.advance(spec.t_end()).unwrap();
        assert_eq!(c.current.index, 5);
        let done = c.finish(Stats::default(), Vector4::zeros());
        assert_eq!(done.summaries.len(), 6);
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

    /// Reads every step at 64 evenly spaced points: the fine-sampled reference of the peaks.
    struct Fine<'c>(SummaryObserver<'c, TwoLayerView>);

    /// Integrates `run` into its observer as `wrap` wraps it, and summarises the orbits.
    fn summarise<'c, O: Observer<nalgebra::U4>>(
        mut run: PreparedOrbits<'c>,
        wrap: impl FnOnce(SummaryObserver<'c, TwoLayerView>) -> O,
        unwrap: impl FnOnce(O) -> SummaryObserver<'c, TwoLayerView>,
    ) -> OrbitRun {
        let mut observer = wrap(run.observer);
        let (system, method) = (&mut run.system, &run.method);
        let outcome = solve(system, method, run.t0, run.y0, run.t1, &mut observer);
        finish_orbits(unwrap(observer), outcome).unwrap()
    }

    impl Observer<nalgebra::U4> for Fine<'_> {
        fn on_step(&mut self, step: &DenseStep<nalgebra::U4>) -> ControlFlow<()> {
            let h = (step.t1 - step.t0) / 64.0;
            for j in 1..=64 {
                let t = if j == 64 {
                    step.t1
                } else {
                    step.t0 + j as f64 * h
                };
                self.0
                    .collector
                    .read(t, step.eval(t).as_slice(), h)
                    .unwrap();
            }
            ControlFlow::Continue(())
        }
    }

    #[test]
    fn two_reads_keep_the_peaks() {
        // Against 64 reads per step, on the same steps: every peak within 0.1 %, the extremes
        // of θ within 0.1 % of the orbit's amplitude (max |θ − θ_eq|), with the step capped at
        // T_n/40 and with error control alone (steps of up to ~T_n/20).
        let o = Orbit::geo_equinox();
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        let method = Method::Dopri5(Tolerances::default());
        let cancel = Cancel::new();
        for damping in [3.0, 0.5] {
            let panel = Panel {
                damping,
                ..Panel::paper()
            };
            let eq = equilibrium(&panel, coupling, 1.0).unwrap();
            let y0 = Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0);
            for steps_per_period in [STEPS_PER_HINGE_PERIOD, 0.0] {
                let opts = SummaryOptions {
                    window: 600.0,
                    theta_limit: 0.5,
                    stop_at_limit: false,
                    steps_per_period,
                };
                let spec = OrbitRunSpec {
                    panel,
                    orbit: o,
                    model,
                    coupling,
                    method,
                    t_start: 0.0,
                    first_index: 0,
                    n_orbits: 2,
                    options: opts,
                };
                let req = OrbitRunRequest { spec, y0 };
                let prepare = || prepare_orbits(&req, &cancel).unwrap();
                let got = summarise(prepare(), |o| o, |o| o);
                let want = summarise(prepare(), Fine, |fine| fine.0);
                assert_eq!(got.stats, want.stats);
                for (g, w) in got.summaries.iter().zip(&want.summaries) {
                    let case = format!("c_d {damping}, steps_per_period {steps_per_period}");
                    let peaks = [
                        ("amplitude", g.amplitude, w.amplitude),
                        ("entry_peak", g.entry_peak, w.entry_peak),
                        ("exit_peak", g.exit_peak, w.exit_peak),
                        ("jitter_peak", g.jitter_peak, w.jitter_peak),
                        ("jitter_rms", g.jitter_rms, w.jitter_rms),
                    ];
                    for (name, g, w) in peaks {
                        let err = (g - w).abs() / w.abs();
                        assert!(err < 1e-3, "{case}: {name} {g} against {w}, {err:.1e}");
                    }
                    let extremes = [
                        ("theta_max", g.theta_max, w.theta_max),
                        ("theta_min", g.theta_min, w.theta_min),
                        ("entry_theta_min", g.entry_theta_min, w.entry_theta_min),
                        ("exit_theta_max", g.exit_theta_max, w.exit_theta_max),
                    ];
                    for (name, g, w) in extremes {
                        let err = (g - w).abs() / want.summaries[0].amplitude;
                        assert!(err < 1e-3, "{case}: {name} {g} against {w}, {err:.1e}");
                    }
                }
            }
        }
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
