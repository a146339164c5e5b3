//! The distributed panel over whole orbits (`tj.simulate_orbits(..., model="distributed")`):
//! the per-orbit summaries of the hinge runs ([`crate::runs::orbits`]), θ read as the panel's
//! hinge-equivalent angle θ_f, plus the tip deflection's extremes per orbit.
//!
//! The quasi-static part of θ_f (what the jitter columns remove) is θ_f of the static state
//! with the same temperatures: the kept modes at rest in equilibrium with the element moments,
//! q = G M/ω².
//!
//! Two methods:
//!
//! - **Full**: the generic integrator on [`DistributedSystem`], every step read at its middle and
//!   end, and at eight evenly spaced points where the modes' share of the tip rise turns (the
//!   step is capped at T₁/`steps_per_period`, T₁ the first kept mode's period, as the hinge runs
//!   cap theirs at the hinge's).
//! - **Linear arcs** (with hybrid settings): on sunlit arcs near the equilibrium, past the last
//!   shadow exit by the summary window, the linearised system is propagated exactly
//!   ([`crate::runs::distributed_arc`]) and the summaries read off it; in the umbra the
//!   temperatures are integrated alone and the modes propagated exactly
//!   ([`crate::runs::distributed_umbra`]); the penumbra and the thermal recovery after the exit
//!   are integrated in full. An arc is taken only where its own checks
//!   hold: the non-linear remainder at its start as a static θ_f error below
//!   `linear_tolerance`, the oscillation below `linear_amplitude`, the structural pairs and
//!   their eigenvectors found to rounding, the reads' interpolation error within their
//!   tolerance, and the drift the dropped non-linear terms cause in each pair (their secular
//!   part, as the hinge's propagator estimates it) within half the accuracy gate. Elsewhere the
//!   run goes on in full and tries again a minute later. The split is reported.

use crate::cancel::Cancel;
use crate::error::{Error, Result};
use crate::inputs::heating::Optics;
use crate::inputs::orbit::{EclipseTable, Orbit};
use crate::models::distributed::{DistributedPanel, ElementHeat};
use crate::numerics::integrate::{solve, DenseStep, Method, Observer, Stats};
use crate::runs::distributed::DistributedSystem;
use crate::runs::distributed_arc::{structural_pairs, LinearArc};
use crate::runs::distributed_umbra::{ShadowedThermal, Umbra, UmbraStep};
use crate::runs::hybrid::{gate_scale, HybridSettings, DRIFT_ATOL, DRIFT_RTOL};
use crate::runs::orbits::{Collector, LimitCrossing, OrbitRunSpec, OrbitSummary, SummaryView};
use nalgebra::{DVector, Dyn as D};
use std::ops::ControlFlow;

/// Points read in a step of the full integration where the modes' share of the tip rise turns
/// (evenly spaced, the last at its end); two (the middle and the end) elsewhere.
const READS_PER_STEP: usize = 8;

/// Simulated time between two attempts at a linear arc, s.
const CHECK_EVERY: f64 = 60.0;

/// The reads of an arc are found to this fraction of the signal's variation (the pairs'
/// envelopes and the thermal part's range): a fiftieth of the 2 % gate on the smallest column
/// they feed (the amplitude, the jitter peak).
const READ_RTOL: f64 = 4e-4;

/// The reads' absolute floor: READ_RTOL of the gate's absolute 1e-6 rad as a rise (m) at the
/// arm `arm`.
fn read_floor(arm: f64) -> f64 {
    READ_RTOL * 1e-6 * arm
}

/// Largest spread of asin's slope over an arc, relative: the jitter (a difference of two θ_f)
/// is read as the difference of the tip rises times that slope.
const SLOPE_SPREAD: f64 = 1e-3;

/// Samples per period of a pair in the estimate of its drift (the harmonics of the defect up to
/// the third stay apart from the first), and the most doublings of the points where it is read.
const DRIFT_SAMPLES: usize = 8;
const DRIFT_DOUBLINGS: f64 = 10.0;

/// An affine functional w·y + c of the state.
#[derive(Debug, Clone)]
pub(crate) struct Affine {
    pub w: DVector<f64>,
    pub c: f64,
}

impl Affine {
    #[inline]
    pub fn at(&self, y: &[f64]) -> f64 {
        self.w
            .as_slice()
            .iter()
            .zip(y)
            .map(|(a, b)| a * b)
            .sum::<f64>()
            + self.c
    }

    /// The functional a·q + b·M of the modal coordinates q and the element moments M, as one of
    /// the state (the moments are affine in the temperatures).
    pub(crate) fn of(model: &DistributedPanel, a: &[f64], b: &[f64]) -> Affine {
        let s = model.layers();
        let zero = vec![0.0; s];
        let m0 = model.thermal.moment(&zero);
        let dm: Vec<f64> = (0..s)
            .map(|j| {
                let mut unit = zero.clone();
                unit[j] = 1.0;
                model.thermal.moment(&unit) - m0
            })
            .collect();
        let mut w = DVector::zeros(model.state_size());
        for (e, be) in b.iter().enumerate() {
            for (j, d) in dm.iter().enumerate() {
                w[e * s + j] = be * d;
            }
        }
        for (i, ai) in a.iter().enumerate() {
            w[model.temps() + i] = *ai;
        }
        Affine {
            w,
            c: m0 * b.iter().sum::<f64>(),
        }
    }

    fn minus(&self, other: &Affine) -> Affine {
        Affine {
            w: &self.w - &other.w,
            c: self.c - other.c,
        }
    }
}

/// The state's readers: the tip rise (θ_f = asin(rise/arm)), the rise of the static state with
/// the same temperatures, and the tip deflection.
#[derive(Debug, Clone)]
pub(crate) struct Readers {
    pub rise: Affine,
    pub rise_static: Affine,
    pub tip: Affine,
    pub arm: f64,
}

impl Readers {
    pub fn of(model: &DistributedPanel) -> Readers {
        let r = &model.reduction;
        let k = model.k();
        let rise_modal = r.rise_modal.as_slice();
        let rise_residual = r.rise_residual.as_slice();
        // The static modes q = G M/ω² through the rise: Σ_i rise_modal_i G_ie/ω_i² per moment.
        let static_b: Vec<f64> = (0..model.n())
            .map(|e| {
                rise_residual[e]
                    + (0..k)
                        .map(|i| rise_modal[i] * r.force[(i, e)] / (r.omega[i] * r.omega[i]))
                        .sum::<f64>()
            })
            .collect();
        let tip_reader = r.mesh.deflection_reader(r.mesh.length);
        let tip_modal = r.shapes.tr_mul(&tip_reader);
        let tip_residual = r.residual.tr_mul(&tip_reader);
        Readers {
            rise: Affine::of(model, rise_modal, rise_residual),
            rise_static: Affine::of(model, &vec![0.0; k], &static_b),
            tip: Affine::of(model, tip_modal.as_slice(), tip_residual.as_slice()),
            arm: r.mesh.arm(),
        }
    }

    /// The tip rise, the static state's rise and the tip deflection of the state `y`, in one
    /// pass (each sum in the order and from the -0.0 of [`Affine::at`]'s: the same bits).
    pub fn values(&self, y: &[f64]) -> (f64, f64, f64) {
        let (mut rise, mut rise_static, mut tip) = (-0.0, -0.0, -0.0);
        let (a, b, c) = (
            self.rise.w.as_slice(),
            self.rise_static.w.as_slice(),
            self.tip.w.as_slice(),
        );
        for (i, v) in y.iter().enumerate().take(a.len()) {
            rise += a[i] * v;
            rise_static += b[i] * v;
            tip += c[i] * v;
        }
        (
            rise + self.rise.c,
            rise_static + self.rise_static.c,
            tip + self.tip.c,
        )
    }

    /// asin(rise/arm), the rise clamped to the arm (runs refuse a rise beyond it first).
    #[inline]
    pub fn angle(&self, rise: f64) -> f64 {
        (rise / self.arm).clamp(-1.0, 1.0).asin()
    }
}

/// How the summaries read the distributed panel: θ_f and θ_f of the static state.
pub(crate) struct DistributedView {
    model: DistributedPanel,
    readers: Readers,
}

impl SummaryView for DistributedView {
    fn theta_eq(&self, flux: f64) -> Result<f64> {
        let y = self.model.equilibrium(flux)?;
        self.model.theta_f(&y, 0.0)
    }
    fn theta_eq_loaded(&self, orbit: &Orbit, t: f64) -> Result<f64> {
        let optics = Optics::of(&self.model.panel);
        let y = self
            .model
            .equilibrium_loaded(&ElementHeat::at(orbit, t, 1.0, optics))?;
        self.model.theta_f(&y, t)
    }
    #[inline]
    fn angles(&self, _t: f64, y: &[f64]) -> (f64, f64) {
        let r = &self.readers;
        (r.angle(r.rise.at(y)), r.angle(r.rise_static.at(y)))
    }
    #[inline]
    fn rate(&self, y: &[f64]) -> f64 {
        let nt = self.model.temps();
        let k = self.model.k();
        let modal = self.model.reduction.rise_modal.as_slice();
        modal.iter().zip(&y[nt + k..]).map(|(a, v)| a * v).sum()
    }
}

/// How a run with linear arcs split its simulated time and work.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DistributedSplit {
    /// Simulated time propagated by linear arcs and integrated in full, s.
    pub t_linear: f64,
    pub t_full: f64,
    pub n_arcs: u64,
    pub n_full_steps: u64,
    /// Attempts at an arc refused by its checks (the run went on in full).
    pub n_refused: u64,
    /// Simulated time through the umbra (the temperatures integrated alone, the modes exact),
    /// s, and the steps of that integration.
    pub t_umbra: f64,
    pub n_umbra_steps: u64,
}

/// A summarised run of the distributed panel over whole orbits.
#[derive(Debug, Clone)]
pub struct DistributedOrbitRun {
    pub summaries: Vec<OrbitSummary>,
    /// Largest and smallest tip deflection of each orbit, m (positive away from the Sun).
    pub tip_max: Vec<f64>,
    pub tip_min: Vec<f64>,
    pub stats: Stats,
    pub y_end: Vec<f64>,
    pub crossing: Option<LimitCrossing>,
    /// With linear arcs: how the time was split.
    pub split: Option<DistributedSplit>,
}

/// The summaries' reader of the run: the collector of the hinge runs and the tip's extremes.
struct Reads<'c> {
    collector: Collector<DistributedView>,
    readers: Readers,
    tips: Vec<(f64, f64)>,
    first: u64,
    error: Option<Error>,
    cancel: &'c Cancel,
}

impl Reads<'_> {
    fn stopped(&self) -> bool {
        self.collector.options.stop_at_limit && self.collector.crossing.is_some()
    }

    /// The tip's range [lo, hi] in the orbit the collector is in.
    fn tip(&mut self, lo: f64, hi: f64) {
        let k = (self.collector.current.index - self.first) as usize;
        let slot = &mut self.tips[k];
        slot.0 = slot.0.min(lo);
        slot.1 = slot.1.max(hi);
    }

    /// One point (t, y) of the solution standing for the interval dt before it.
    fn read(&mut self, t: f64, y: &[f64], dt: f64) -> Result<()> {
        let (rise, rise_static, tip) = self.readers.values(y);
        self.read_values(t, rise, rise_static, tip, dt)
    }

    /// One point at t, given by its tip rise, its static state's rise and its tip deflection,
    /// standing for the interval dt before it.
    fn read_values(
        &mut self,
        t: f64,
        rise: f64,
        rise_static: f64,
        tip: f64,
        dt: f64,
    ) -> Result<()> {
        if rise.is_nan() || rise.abs() > self.readers.arm {
            return Err(Error::Integration {
                t,
                reason: format!(
                    "tip rise {rise} m exceeds the arm {} m: θ_f is undefined",
                    self.readers.arm
                ),
            });
        }
        let (theta, quasi_static) = (self.readers.angle(rise), self.readers.angle(rise_static));
        let dynamic = theta - quasi_static;
        self.collector
            .record(t, theta, theta, dynamic.abs(), dynamic * dynamic * dt, dt)?;
        self.tip(tip, tip);
        Ok(())
    }
}

impl Observer<D> for Reads<'_> {
    /// Each step read at its middle and end, and at [`READS_PER_STEP`] evenly spaced points
    /// where the modes' share of the tip rise changes direction within it (an extreme of θ_f
    /// lies there), as the hinge runs read theirs.
    fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()> {
        if let Err(e) = self.cancel.check() {
            self.error = Some(e);
            return ControlFlow::Break(());
        }
        let (t_mid, y_mid) = step.midpoint();
        let rising = |y: &[f64]| self.collector.view.rate(y) > 0.0;
        let (r0, r_mid, r1) = (
            rising(step.y0.as_slice()),
            rising(y_mid.as_slice()),
            rising(step.y1.as_slice()),
        );
        let reads = if r0 == r_mid && r_mid == r1 {
            2
        } else {
            READS_PER_STEP
        };
        let h = (step.t1 - step.t0) / reads as f64;
        for j in 1..=reads {
            let read = if j == reads {
                self.read(step.t1, step.y1.as_slice(), h)
            } else if 2 * j == reads {
                self.read(t_mid, y_mid.as_slice(), h)
            } else {
                let t = step.t0 + j as f64 * h;
                self.read(t, step.eval(t).as_slice(), h)
            };
            if let Err(e) = read {
                self.error = Some(e);
                return ControlFlow::Break(());
            }
        }
        if self.stopped() {
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    }
}

/// Runs `model` over the orbits of `spec` from `y0` (its state: the temperatures of each element,
/// then q and q̇), in full, or with linear arcs where they hold when `hybrid` is given (an
/// orbit with the Earth's loads or an attitude runs in full, counted as such).
pub fn run_distributed_orbits(
    model: &DistributedPanel,
    spec: &OrbitRunSpec,
    y0: &[f64],
    hybrid: Option<&HybridSettings>,
    cancel: &Cancel,
) -> Result<DistributedOrbitRun> {
    // What every hybrid run is asked (the hybrid's settings checked when given).
    let defaults = HybridSettings::default();
    crate::runs::hybrid::check_request(spec, y0, hybrid.unwrap_or(&defaults), cancel)?;
    model.check_orbit(&spec.orbit)?;
    crate::runs::distributed::check_state(model, y0)?;
    let options = spec.options;
    if !(0.0..=crate::runs::orbits::MAX_STEPS_PER_PERIOD).contains(&options.steps_per_period) {
        return Err(Error::invalid(
            "steps_per_period",
            options.steps_per_period,
            "must be in [0, 1e4] (0: error control alone)",
        ));
    }
    let readers = Readers::of(model);
    let theta0 = readers.angle(readers.rise.at(y0));
    let view = DistributedView {
        model: model.clone(),
        readers: readers.clone(),
    };
    let tip0 = readers.tip.at(y0);
    let mut tips = vec![(f64::INFINITY, f64::NEG_INFINITY); spec.n_orbits as usize];
    tips[0] = (tip0, tip0);
    let umbra = Umbra::new(
        model,
        [&readers.rise, &readers.rise_static, &readers.tip],
        READ_RTOL,
        read_floor(readers.arm),
    );
    let mut reads = Reads {
        collector: Collector::new(view, spec, theta0)?,
        readers,
        tips,
        first: spec.first_index,
        error: None,
        cancel,
    };
    let method = capped(&spec.method, model, options.steps_per_period);
    let mut driver = Driver {
        model,
        orbit: spec.orbit,
        method,
        shadow_method: spec.method,
        umbra,
        system: DistributedSystem::new(model.clone(), spec.orbit),
        reads: &mut reads,
        t_end: spec.t_end(),
        t: spec.t_start,
        y: DVector::from_column_slice(y0),
        stats: Stats {
            t_end: spec.t_start,
            ..Stats::default()
        },
        split: DistributedSplit::default(),
        drift: (0.0, spec.t_start, 0.0),
        eclipses: EclipseTable::until(&spec.orbit, spec.t_end()),
        reference: None,
    };
    let arcs = hybrid.filter(|_| !spec.orbit.has_face_loads());
    match arcs {
        Some(h) => driver.run_with_arcs(h)?,
        None => driver.full(driver.t_end)?,
    }
    let Driver {
        mut stats,
        t,
        y,
        split,
        t_end,
        ..
    } = driver;
    stats.t_end = t;
    stats.stopped = t < t_end && reads.collector.crossing.is_some();
    let done = reads
        .collector
        .finish(stats, DVector::from_column_slice(y.as_slice()));
    let n = done.summaries.len();
    let tips = &reads.tips[..n];
    Ok(DistributedOrbitRun {
        summaries: done.summaries,
        tip_max: tips.iter().map(|t| t.1).collect(),
        tip_min: tips.iter().map(|t| t.0).collect(),
        stats: done.stats,
        y_end: done.y_end.as_slice().to_vec(),
        crossing: done.crossing,
        split: hybrid.map(|_| {
            let mut s = split;
            if arcs.is_none() {
                // Integrated in full: all of it counted so.
                s.t_full = t - spec.t_start;
                s.n_full_steps = stats.n_steps;
            }
            s
        }),
    })
}

/// The right-hand side of `model` in full Sun under the flux factor `flux`.
fn rhs(model: &DistributedPanel, flux: f64, y: &DVector<f64>) -> DVector<f64> {
    let mut dy = DVector::zeros(y.len());
    model.rhs_at_flux(flux, y.as_slice(), dy.as_mut_slice());
    dy
}

/// `method` with its step capped at T₁/steps_per_period (adaptive methods; 0: no cap), T₁ the
/// first kept mode's period.
fn capped(method: &Method, model: &DistributedPanel, steps_per_period: f64) -> Method {
    match method {
        Method::Dopri5(tol) if steps_per_period > 0.0 => {
            let period = 2.0 * std::f64::consts::PI / model.reduction.omega[0];
            let mut tol = *tol;
            tol.max_step = tol.max_step.min(period / steps_per_period);
            Method::Dopri5(tol)
        }
        other => *other,
    }
}

struct Driver<'a, 'c> {
    model: &'a DistributedPanel,
    orbit: Orbit,
    method: Method,
    /// The method of the temperatures alone in the umbra: the run's, its step not capped by the
    /// modes (they are propagated exactly).
    shadow_method: Method,
    umbra: Umbra,
    system: DistributedSystem,
    reads: &'a mut Reads<'c>,
    t_end: f64,
    t: f64,
    y: DVector<f64>,
    stats: Stats,
    split: DistributedSplit,
    /// The drift in θ_f that arcs have left in the state: (error rad, at t, decay rate 1/s).
    drift: (f64, f64, f64),
    eclipses: EclipseTable,
    /// The last linearisation: kept while the flux stays within [`REFERENCE_SPAN`] of its own.
    reference: Option<Reference>,
}

/// A sunlit equilibrium and what the arcs need of it.
struct Reference {
    flux: f64,
    y: DVector<f64>,
    a: nalgebra::DMatrix<f64>,
    lu: nalgebra::LU<f64, D, D>,
    /// ∂f/∂flux at the equilibrium (the rates are linear in the flux).
    sensitivity: DVector<f64>,
    /// The structural pairs, once found (None inside: not found).
    pairs: Option<Option<Vec<crate::runs::distributed_arc::Pair>>>,
}

/// Relative change of the flux over which a linearisation is kept: the flux's offset from it
/// is a forcing of the arc, and the non-linear remainder at each arc's start (checked) holds
/// what the offset leaves out.
const REFERENCE_SPAN: f64 = 1e-4;

/// A linear arc ready to be read: the arc and the drift it leaves at its end.
struct Plan {
    arc: LinearArc,
    drift: (f64, f64, f64),
}

impl Driver<'_, '_> {
    /// The full integration from t to `end` (or to where the reads stopped it).
    fn full(&mut self, end: f64) -> Result<()> {
        let start = self.y.clone();
        let outcome = solve(
            &mut self.system,
            &self.method,
            self.t,
            start,
            end,
            &mut *self.reads,
        );
        let (done, y) = match (outcome, self.reads.error.take()) {
            (_, Some(e)) | (Err(e), None) => return Err(e),
            (Ok(run), None) => run,
        };
        let reached = if done.stopped { done.t_end } else { end };
        self.split.t_full += reached - self.t;
        self.split.n_full_steps += done.n_steps;
        self.add_work(&done);
        (self.t, self.y) = (reached, y);
        Ok(())
    }

    /// Adds the steps and evaluations of a finished integration to the run's.
    fn add_work(&mut self, done: &Stats) {
        let s = &mut self.stats;
        (s.n_steps, s.n_rejected, s.n_rhs) = (
            s.n_steps + done.n_steps,
            s.n_rejected + done.n_rejected,
            s.n_rhs + done.n_rhs,
        );
    }

    /// From t to `end` inside the umbra: the temperatures integrated alone, the modes propagated
    /// exactly over each of their steps, and the reads evenly spaced in each step at the spacing
    /// [`UmbraStep::spacing`] allows (or to where they stopped the run).
    fn through_umbra(&mut self, end: f64) -> Result<()> {
        let (nt, k) = (self.model.temps(), self.model.k());
        let y = self.y.as_slice();
        let mut observer = UmbraReads {
            umbra: &self.umbra,
            reads: &mut *self.reads,
            q: y[nt..nt + k].to_vec(),
            v: y[nt + k..].to_vec(),
            stop: None,
            error: None,
        };
        let mut system = ShadowedThermal { model: self.model };
        let temps = DVector::from_column_slice(&y[..nt]);
        let outcome = solve(
            &mut system,
            &self.shadow_method,
            self.t,
            temps,
            end,
            &mut observer,
        );
        let (done, temps) = match (outcome, observer.error.take()) {
            (_, Some(e)) | (Err(e), None) => return Err(e),
            (Ok(run), None) => run,
        };
        let (reached, y) = match observer.stop.take() {
            Some(stop) => stop,
            None => {
                let mut y = temps.as_slice().to_vec();
                y.extend_from_slice(&observer.q);
                y.extend_from_slice(&observer.v);
                (end, DVector::from_vec(y))
            }
        };
        self.split.t_umbra += reached - self.t;
        self.split.n_umbra_steps += done.n_steps;
        self.add_work(&done);
        (self.t, self.y) = (reached, y);
        Ok(())
    }

    /// End of the orbit that holds (t, t + dt]: the collector's current orbit (that of the last
    /// point read, t), or the next when t is its end.
    fn orbit_end(&self, t: f64) -> f64 {
        let current = self.reads.collector.current.t_end;
        let end = if current - t <= 1e-9 * self.orbit.period {
            current + self.orbit.period
        } else {
            current
        };
        end.min(self.t_end)
    }

    fn run_with_arcs(&mut self, settings: &HybridSettings) -> Result<()> {
        let window = self.reads.collector.options.window;
        let budget = self.method.max_steps();
        while self.t < self.t_end && !self.reads.stopped() {
            self.reads.cancel.check()?;
            if self.stats.n_steps + self.stats.n_rejected >= budget {
                return Err(Error::Integration {
                    t: self.t,
                    reason: format!("max_steps = {budget} reached"),
                });
            }
            let t = self.t;
            let p = self.orbit.period;
            let near = self.eclipses.overlapping(t - p - window, t + p).to_vec();
            let shadow = near.iter().find(|e| e.outer.0 <= t && t < e.outer.1);
            let release = near
                .iter()
                .filter(|e| e.outer.0 <= t)
                .map(|e| e.outer.1 + window)
                .fold(f64::NEG_INFINITY, f64::max);
            let next = if let Some(e) = shadow {
                match e.umbra {
                    // The umbra, the temperatures alone: first the penumbra before it in full.
                    Some((u0, u1)) if t < u1 && matches!(self.shadow_method, Method::Dopri5(_)) => {
                        if t < u0 {
                            u0
                        } else {
                            self.through_umbra(u1.min(self.t_end))?;
                            continue;
                        }
                    }
                    _ => e.outer.1 + window,
                }
            } else if t < release {
                release
            } else {
                let contact = near
                    .iter()
                    .map(|e| e.outer.0)
                    .filter(|&c| c > t)
                    .fold(f64::INFINITY, f64::min);
                let end = contact.min(self.orbit_end(t));
                if self.arc(end, settings)? {
                    continue;
                }
                self.split.n_refused += 1;
                t + CHECK_EVERY
            };
            self.full(next.min(self.t_end))?;
        }
        Ok(())
    }

    /// A linear arc from t to `end` if its checks hold: read into the summaries, the state moved
    /// to its end. Returns whether it was taken.
    fn arc(&mut self, end: f64, settings: &HybridSettings) -> Result<bool> {
        let t0 = self.t;
        if end - t0 <= CHECK_EVERY {
            return Ok(false);
        }
        let Some(Plan { arc, drift }) = self.plan(end, settings)? else {
            return Ok(false);
        };
        let r = &self.reads.readers;
        let rise = arc.signal(&r.rise.w, r.rise.c);
        let dynamic = {
            let d = r.rise.minus(&r.rise_static);
            arc.signal(&d.w, d.c)
        };
        let rise_static = arc.signal(&r.rise_static.w, r.rise_static.c);
        let tip = arc.signal(&r.tip.w, r.tip.c);
        let length = end - t0;
        let floor = read_floor(r.arm);
        let tol = |s: &crate::runs::distributed_arc::ArcSignal| READ_RTOL * s.variation() + floor;
        let signals = [&rise, &dynamic, &rise_static, &tip];
        if signals.iter().any(|s| s.max_interpolation_error() > tol(s)) {
            return Ok(false);
        }
        let (lo, hi) = rise.extremes(0.0, length, tol(&rise));
        let (slo, shi) = rise_static.extremes(0.0, length, tol(&rise_static));
        let arm = r.arm;
        let limit = self.reads.collector.options.theta_limit;
        if hi.abs().max(lo.abs()).max(shi.abs()).max(slo.abs()) >= arm
            || r.angle(hi) > limit
            || r.angle(lo) < -limit
        {
            return Ok(false); // the crossing is the full integration's to find
        }
        // asin(x) − asin(x_s) = (x − x_s)/√(1 − ξ²), ξ between them: its slope over the arc.
        let xi = hi.abs().max(lo.abs()).max(shi.abs()).max(slo.abs()) / arm;
        let xi_low = if lo.signum() == hi.signum() && slo.signum() == lo.signum() {
            lo.abs().min(hi.abs()).min(slo.abs()).min(shi.abs()) / arm
        } else {
            0.0
        };
        let (g_hi, g_lo) = (
            1.0 / (1.0 - xi * xi).sqrt(),
            1.0 / (1.0 - xi_low * xi_low).sqrt(),
        );
        if g_hi / g_lo - 1.0 > SLOPE_SPREAD {
            return Ok(false);
        }
        let g = 0.5 * (g_hi + g_lo) / arm;
        let (dlo, dhi) = dynamic.extremes(0.0, length, tol(&dynamic));
        let (tlo, thi) = tip.extremes(0.0, length, tol(&tip));
        let sq = g * g * dynamic.integral_sq();
        let angle = |v: f64| r.angle(v);
        let extremes = |a: f64, b: f64| {
            if (a, b) == (t0, end) {
                (angle(lo), angle(hi))
            } else {
                let (l, h) = rise.extremes(a - t0, b - t0, tol(&rise));
                (angle(l), angle(h))
            }
        };
        self.reads
            .collector
            .record_span(t0, end, &extremes, g * dlo.abs().max(dhi.abs()), sq)?;
        self.reads.tip(tlo, thi);
        self.y = arc.state_at_node(arc.cells());
        self.t = end;
        self.drift = drift;
        self.split.t_linear += length;
        self.split.n_arcs += 1;
        Ok(true)
    }

    /// Keeps the linearisation for `flux`: the kept one, or a new one at that flux.
    fn refresh(&mut self, flux: f64) -> Result<()> {
        let stale = self
            .reference
            .as_ref()
            .is_none_or(|r| (r.flux - flux).abs() > REFERENCE_SPAN * flux);
        if stale {
            let model = self.model;
            let y = DVector::from_vec(model.equilibrium(flux)?);
            let a = model.jacobian(flux, y.as_slice());
            let sensitivity = rhs(model, 1.0, &y) - rhs(model, 0.0, &y);
            self.reference = Some(Reference {
                flux,
                lu: a.clone().lu(),
                y,
                a,
                sensitivity,
                pairs: None,
            });
        }
        Ok(())
    }

    /// The arc from (t, y) to `end` with its checks; None where one fails.
    fn plan(&mut self, end: f64, settings: &HybridSettings) -> Result<Option<Plan>> {
        let model = self.model;
        let t0 = self.t;
        let flux0 = self.orbit.flux_scale(t0);
        let flux1 = self.orbit.flux_scale(end);
        let scale = self.scale();
        self.refresh(flux0)?;
        let reference = self.reference.as_mut().expect("refreshed");
        let offset = &reference.sensitivity * (flux0 - reference.flux);
        let (y_ref, a) = (reference.y.clone(), reference.a.clone());
        let y = &self.y;
        let r = &self.reads.readers;
        let x_ref = r.rise.at(y_ref.as_slice()) / r.arm;
        let theta = |y: &DVector<f64>| r.angle(r.rise.at(y.as_slice()));
        if (theta(y) - theta(&y_ref)).abs() > settings.linear_amplitude {
            return Ok(None);
        }
        // The non-linear remainder at the start as a static θ_f error.
        let remainder = rhs(model, flux0, y) - &a * (y - &y_ref) - &offset;
        let Some(z) = reference.lu.solve(&remainder) else {
            return Ok(None);
        };
        let grad = &r.rise.w / (r.arm * (1.0 - x_ref * x_ref).sqrt());
        if grad.dot(&z).abs() > settings.linear_tolerance {
            return Ok(None);
        }
        let slowest = 0.1 * model.reduction.omega[0];
        let pairs = reference
            .pairs
            .get_or_insert_with(|| structural_pairs(&a, &scale, model.k(), slowest));
        let Some(pairs) = pairs.clone() else {
            return Ok(None);
        };
        let b = &reference.sensitivity * ((flux1 - flux0) / (end - t0));
        let Ok(arc) = LinearArc::new(&a, &offset, &b, &y_ref, y, pairs, end - t0) else {
            return Ok(None);
        };
        // The drift of the dropped non-linear terms, against what the gate allows.
        let (error, at, rate) = self.drift;
        let spent = error * (rate * (t0 - at)).min(50.0).exp();
        let jitter = gate_scale(&self.reads.collector);
        let allowed = (DRIFT_RTOL * jitter).max(DRIFT_ATOL) - spent;
        let (largest, at_end, slowest) = self.arc_drift(&arc, &a, &grad, t0);
        if largest > allowed {
            return Ok(None);
        }
        Ok(Some(Plan {
            arc,
            drift: (
                spent * (slowest * (end - t0)).min(50.0).exp() + at_end,
                end,
                slowest,
            ),
        }))
    }

    /// Units of the state for the eigen-solve: kelvin, and the modes' static response to one
    /// kelvin (q) and that times ω (q̇).
    fn scale(&self) -> DVector<f64> {
        let m = self.model;
        let r = &m.reduction;
        let (nt, k) = (m.temps(), m.k());
        let zero = vec![0.0; m.layers()];
        let m0 = m.thermal.moment(&zero);
        let dm = (0..m.layers()).fold(0.0f64, |acc, j| {
            let mut unit = zero.clone();
            unit[j] = 1.0;
            acc.max((m.thermal.moment(&unit) - m0).abs())
        });
        let mut s = DVector::from_element(nt + 2 * k, 1.0);
        for i in 0..k {
            let w = r.omega[i];
            let force: f64 = (0..m.n()).map(|e| r.force[(i, e)].abs()).sum();
            let q = force * dm / (w * w);
            let q = if q > 0.0 && q.is_finite() { q } else { 1.0 };
            s[nt + i] = q;
            s[nt + k + i] = q * w;
        }
        s
    }

    /// The error in θ_f that the linearisation makes over the arc from t0, by each structural
    /// pair's secular drift: the defect d(τ) = y' − f(y) of the arc drives the pair's coordinate
    /// c as ε' = λε − w·d; the mean of e^{−λτ} w·d over one period is μ c, the relative rate at
    /// which the dropped terms change the pair's amplitude and phase. Returns (the largest error
    /// along the arc, the error at its end, the slowest pair's decay rate).
    fn arc_drift(
        &self,
        arc: &LinearArc,
        a: &nalgebra::DMatrix<f64>,
        grad: &DVector<f64>,
        t0: f64,
    ) -> (f64, f64, f64) {
        let model = self.model;
        let (mut largest, mut at_end, mut slowest) = (0.0, 0.0, f64::NEG_INFINITY);
        let length = arc.length;
        for (pair, &c) in arc.pairs.iter().zip(&arc.coeff) {
            slowest = slowest.max(pair.lambda.re);
            let gv: crate::runs::distributed_arc::C64 = pair
                .right
                .iter()
                .zip(grad.iter())
                .map(|(v, g)| v * *g)
                .sum();
            let amp0 = 2.0 * (gv * c).norm();
            if amp0.is_nan() || amp0 <= 0.0 {
                continue;
            }
            let period = 2.0 * std::f64::consts::PI / pair.lambda.im;
            let rate_at = |node: usize| {
                let p = node as f64 * arc.step;
                let mut mean = crate::runs::distributed_arc::C64::new(0.0, 0.0);
                for j in 0..DRIFT_SAMPLES {
                    let tau = p + period * j as f64 / DRIFT_SAMPLES as f64;
                    let y = arc.state_near_node(node, tau);
                    let h = pair.part(c, tau);
                    let flux = self.orbit.flux_scale(t0 + tau);
                    let defect = a * &h - rhs(model, flux, &y) + rhs(model, flux, &(&y - &h));
                    mean += (-pair.lambda * tau).exp() * pair.coordinate(&defect);
                }
                mean / DRIFT_SAMPLES as f64 / c
            };
            let amp = |tau: f64| amp0 * (pair.lambda.re * tau).exp();
            let last = length - period;
            let mut nodes = vec![0usize];
            if last >= period {
                let doublings = (last / period).log2().floor().min(DRIFT_DOUBLINGS) as i32;
                for k in (0..=doublings).rev() {
                    let node = ((last * 0.5f64.powi(k)) / arc.step).floor() as usize;
                    if node > *nodes.last().unwrap_or(&0) {
                        nodes.push(node);
                    }
                }
            }
            let mut drift = crate::runs::distributed_arc::C64::new(0.0, 0.0);
            let mut along = 0.0f64;
            let mut before = (0.0, rate_at(0));
            for &node in &nodes[1..] {
                let p = node as f64 * arc.step;
                let mu = rate_at(node);
                drift += (before.1 + mu) * (0.5 * (p - before.0));
                along = along.max(amp(p) * drift.re.abs());
                before = (p, mu);
            }
            drift += before.1 * (length - before.0);
            let end = amp(length) * drift.norm();
            largest += end.max(along);
            at_end += end;
        }
        (
            largest,
            at_end,
            if slowest.is_finite() { slowest } else { 0.0 },
        )
    }
}

/// The reads of a span through the umbra: evenly spaced in each step of the temperatures (the
/// last at its end), the modes carried from step to step.
struct UmbraReads<'r, 'c> {
    umbra: &'r Umbra,
    reads: &'r mut Reads<'c>,
    q: Vec<f64>,
    v: Vec<f64>,
    /// Where the reads stopped the run (the limit), and the state there.
    stop: Option<(f64, DVector<f64>)>,
    error: Option<Error>,
}

impl Observer<D> for UmbraReads<'_, '_> {
    fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()> {
        if let Err(e) = self.reads.cancel.check() {
            self.error = Some(e);
            return ControlFlow::Break(());
        }
        let arc = UmbraStep::new(self.umbra, step, &self.q, &self.v);
        let h = step.t1 - step.t0;
        let count = (h / arc.spacing(self.umbra)).ceil().clamp(1.0, 1e9) as usize;
        let dt = h / count as f64;
        let time = |j: usize| {
            if j == count {
                step.t1
            } else {
                step.t0 + j as f64 * dt
            }
        };
        let mut stopped = None;
        let reads = &mut *self.reads;
        let error = &mut self.error;
        arc.read_uniform(time(1), dt, count, |i, [rise, rs, tip]| {
            let t = time(i + 1);
            if let Err(e) = reads.read_values(t, rise, rs, tip, dt) {
                *error = Some(e);
                return false;
            }
            if reads.stopped() {
                stopped = Some(t);
                return false;
            }
            true
        });
        if self.error.is_some() {
            return ControlFlow::Break(());
        }
        if let Some(t) = stopped {
            let (q, v) = arc.modes_at(t);
            let mut y = step.eval(t).as_slice().to_vec();
            y.extend_from_slice(&q);
            y.extend_from_slice(&v);
            self.stop = Some((t, DVector::from_vec(y)));
            return ControlFlow::Break(());
        }
        (self.q, self.v) = arc.modes_at(step.t1);
        ControlFlow::Continue(())
    }
}
