//! Whole orbits by the exponential integrator, for short orbits (an eclipse every orbit or
//! nearly) of a linear hinge: the sunlit arcs are too short for the ringing that each terminator
//! starts to decay (on Table 1 it decays over three low orbits), so the linear arcs about the
//! sunlit equilibrium never start and every orbit would go to the hinge-resolved fallback.
//!
//! Each orbit is cut at its shadow contacts and its end, and each piece of full Sun or umbra is
//! integrated by [`exprb`] linearised about the centre of the hinge's oscillation
//! ([`exprb::Linearise::AtCentre`]): the ringing is part of the linear problem, carried exactly
//! over the step, which the slow thermal non-linearity sets (the temperatures' transient after a
//! terminator, their drift in shadow), not the hinge period. Every step is read in closed form:
//! the step's linear problem y' = f0 + J (y − y0) + v τ is the linear arc ([`linear::Arc`])
//! about its own fixed point y0 − J⁻¹ f0, whose θ extremes, dynamic part and ∫(dynamic)² the
//! summaries take over the step (the windows after entry and exit at their exact edges). A
//! partial shadow, where the flux moves fast, and the first hinge periods after it are resolved
//! by fixed-step RK4 as on the other path.
//!
//! Only the linear hinge (eq. 28) runs here. The non-linear hinge's inertia (1 + 3 sin²θ) makes
//! the ringing's frequency depend on its amplitude: over a step of many periods that is a
//! remainder at the hinge's own frequency, which the step's error estimate (the remainder at the
//! step's end) does not measure, and its terms at twice the frequency make the estimate refuse
//! any step longer than a fraction of a period; such runs keep the other path.
//!
//! The guard: each step's read is checked against the step's own third-order formula at its
//! middle and end (the linear problem's path against the solution with the non-linear
//! remainder); where they differ in θ or in the dynamic part by more than a tenth of the
//! accuracy gate, where the closed form cannot be found, or where the oscillation or θ leaves the
//! range of the linear reads (`linear_amplitude`, the validity limit), the orbit goes on from the
//! step's start in the hinge-resolved full integration.

use super::exprb::{self, ExpStep, Linearise};
use super::linear::Arc;
use super::model::HybridModel;
use super::{Driver, BAND_RTOL, READ_ATOL, RESOLVED_AFTER_PARTIAL_SHADOW};
use crate::error::{Error, Result};
use crate::inputs::orbit::breakpoints_of;
use crate::models::hinge::HingeModel;
use nalgebra::SVector;

/// Orbits shorter than this (s) run whole by the exponential integrator: every low and medium
/// orbit up to six hours, none of the geostationary ones (whose sunlit arcs of a day leave the
/// ringing time to decay into linear arcs).
pub(crate) const WHOLE_ORBIT_PERIOD: f64 = 6.0 * 3600.0;

/// The error of θ an exponential step may make, relative to the largest oscillation the
/// summaries read: errors of every step add up over the ringing's life (three orbits on Table 1)
/// and grow with a fluttering panel's ringing, against a gate of 2 % on every orbit.
const RINGING_RTOL: f64 = 1e-3;
/// Its floor, rad: a thousandth of the gate's absolute part (1e-6 rad).
const RINGING_FLOOR: f64 = 1e-9;

/// Whether a run on `orbit` of a model with this hinge goes whole by the exponential integrator.
pub(crate) fn applies(orbit: &crate::inputs::orbit::Orbit, hinge: HingeModel) -> bool {
    orbit.period < WHOLE_ORBIT_PERIOD && hinge == HingeModel::Linear
}

impl<const N: usize, M: HybridModel<N>> Driver<'_, N, M> {
    /// Every orbit from t to the end of the run, whole by the exponential integrator, each rest
    /// of an orbit where the guard fails in the hinge-resolved full integration.
    pub(super) fn whole_orbits(&mut self) -> Result<()> {
        let period = 2.0 * std::f64::consts::PI / self.judge.panel.natural_angular_frequency();
        while self.t < self.t_end && !self.stopped() {
            self.obs.cancel.check()?;
            self.check_budget()?;
            let end = self.orbit_end(self.t);
            let eclipses = self.eclipses.overlapping(self.t, end).to_vec();
            if self.exponential_orbit(end, &eclipses, period)? {
                self.full(end, &eclipses)?;
            }
        }
        Ok(())
    }

    /// The orbit from t to `end` by exponential steps read in closed form (partial shadow
    /// resolved); true where the guard failed, with t and the state at the failing step's start.
    fn exponential_orbit(
        &mut self,
        end: f64,
        eclipses: &[crate::inputs::orbit::Eclipse],
        period: f64,
    ) -> Result<bool> {
        let mut cuts = vec![self.t];
        cuts.extend(breakpoints_of(eclipses, self.t, end));
        cuts.push(end);
        let mut resolve_until = f64::NEG_INFINITY;
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b <= self.t {
                continue;
            }
            if self.stopped() {
                return Ok(false);
            }
            let lit = self.orbit.illumination(0.5 * (a + b));
            if lit > 0.0 && lit < 1.0 {
                self.resolved(b, period)?;
                resolve_until = b + RESOLVED_AFTER_PARTIAL_SHADOW * period;
                continue;
            }
            if self.t < resolve_until {
                let until = resolve_until.min(b);
                self.resolved(until, period)?;
                if self.stopped() || until >= b {
                    continue;
                }
            }
            if self.exponential_segment(a, b)? {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// The segment [a, b] (no contact inside) from t by exponential steps read in closed form;
    /// true where the guard failed.
    fn exponential_segment(&mut self, a: f64, b: f64) -> Result<bool> {
        self.system.enter_segment(a, b);
        let system = self.system.clone();
        let tolerances = self.settings.tolerances;
        // The ringing's error held to a fraction of the largest oscillation the summaries read
        // (the last orbit's jitter peak, this orbit's so far), with a floor for a panel at rest.
        let peak = match self.obs.collector.done.last() {
            Some(s) if s.jitter_peak.is_finite() => s.jitter_peak,
            _ => 0.0,
        }
        .max(self.obs.collector.current.jitter_peak);
        let theta = (RINGING_RTOL * peak).max(RINGING_FLOOR);
        let rate = theta * self.judge.panel.natural_angular_frequency();
        let (mut t, mut y, mut h) = (self.t, self.y, self.h_exp);
        let start = self.t;
        let mut failed: Option<(f64, SVector<f64, N>)> = None;
        let this = &mut *self;
        let (acc, rej, _) = exprb::segment(
            &system,
            a,
            b,
            &mut t,
            &mut y,
            &mut h,
            &tolerances,
            Linearise::AtCentre { theta, rate },
            |st: &ExpStep<N>| -> Result<bool> {
                this.obs.cancel.check()?;
                if !this.read_closed_form(st)? {
                    failed = Some((st.t0, st.y0));
                    return Ok(true);
                }
                Ok(this.stopped())
            },
        )
        .or_else(|e| match e {
            // A step that cannot be made small enough: the full integration takes over.
            Error::Integration { .. } => {
                failed = Some((self.t, self.y));
                Ok((0, 0, true))
            }
            other => Err(other),
        })?;
        if let Some((t0, y0)) = failed {
            (t, y) = (t0, y0);
        }
        self.t = t;
        self.y = y;
        self.h_exp = h;
        self.out.t_exponential += t - start;
        self.out.n_exp_steps += acc;
        self.stats.n_steps += acc;
        self.stats.n_rejected += rej;
        self.stats.n_rhs += 3 * (acc + rej);
        Ok(failed.is_some())
    }

    /// Reads one exponential step into the summaries in closed form; false (nothing read) where
    /// the guard fails.
    fn read_closed_form(&mut self, st: &ExpStep<N>) -> Result<bool> {
        let length = st.t1 - st.t0;
        let Some(inverse) = st.jac.try_inverse() else {
            return Ok(false);
        };
        // The fixed point of the step's linear problem.
        let y_ref = st.y0 - inverse * st.f0;
        let Ok(arc) = Arc::new(&st.jac, &st.v, &y_ref, &st.y0, length, &self.judge.scale) else {
            return Ok(false);
        };
        let e_theta = SVector::<f64, N>::from_fn(|i, _| if i == N - 2 { 1.0 } else { 0.0 });
        let theta = arc.signal(&e_theta);
        let (w, offset) = self.judge.model.dynamic_weights(st.flux0, &y_ref);
        let dynamic = arc.signal(&w).shifted(offset);
        if dynamic.envelope_max(0.0, length) > self.settings.linear_amplitude {
            return Ok(false);
        }
        let (lo, hi) = theta.extremes(0.0, length);
        let limit = self.obs.collector.options.theta_limit;
        if hi > limit || lo < -limit {
            return Ok(false);
        }
        let (dlo, dhi) = dynamic.extremes(0.0, length);
        let dynamic_abs = dlo.abs().max(dhi.abs());
        // The linear problem's path against the step's own formula, with the remainder, at the
        // middle and the end: a tenth of the gate on θ's deviation and on the dynamic part.
        let eq = self.obs.collector.current.theta_eq;
        let peak = match self.obs.collector.done.last() {
            Some(s) if s.jitter_peak.is_finite() => s.jitter_peak,
            _ => 0.0,
        }
        .max(self.obs.collector.current.jitter_peak)
        .max(dynamic_abs);
        let deviation = (hi - eq).abs().max((lo - eq).abs());
        let theta_tol = READ_ATOL + BAND_RTOL * deviation.max(peak);
        let dynamic_tol = READ_ATOL + BAND_RTOL * peak;
        for (tau, y) in [(0.5 * length, st.y_mid), (length, st.y1)] {
            let read = arc.state(tau);
            let d_read = w.dot(&read) + offset;
            let d_formula = w.dot(&y) + offset;
            if (read[N - 2] - y[N - 2]).abs() > theta_tol
                || (d_read - d_formula).abs() > dynamic_tol
            {
                return Ok(false);
            }
        }
        let sq = dynamic.integral_sq(length);
        let (t0, t1) = (st.t0, st.t1);
        let extremes = |ta: f64, tb: f64| {
            if (ta, tb) == (t0, t1) {
                (lo, hi)
            } else {
                theta.extremes(ta - t0, tb - t0)
            }
        };
        self.obs
            .collector
            .record_span(t0, t1, &extremes, dynamic_abs, sq)?;
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{compare, spec};
    use super::super::{run_orbits_hybrid, HybridSettings};
    use crate::analysis::steady::equilibrium;
    use crate::cancel::Cancel;
    use crate::inputs::orbit::{Orbit, Shadow};
    use crate::inputs::panel::Panel;
    use crate::models::coupled::Coupling;
    use crate::models::hinge::HingeModel;
    use crate::numerics::integrate::{Method, Tolerances};
    use crate::runs::orbits::{run_orbits, OrbitRunRequest};
    use nalgebra::Vector4;

    /// Table 1 with the linear hinge on a 540 km orbit, each shadow model: whole orbits by
    /// exponential steps, every summary within the gate of a tight hinge-resolved run.
    #[test]
    fn a_low_orbit_of_a_linear_hinge_runs_whole_within_the_gate() {
        let panel = Panel::paper();
        for shadow in [Shadow::Cylindrical, Shadow::Penumbra] {
            let orbit = Orbit {
                shadow,
                ..Orbit::leo(540e3)
            };
            let eq = equilibrium(&panel, Coupling::ProjectedArea, orbit.flux_scale(0.0)).unwrap();
            let y0 = Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0);
            let mut spec = spec(&panel, &orbit, 6);
            spec.model = HingeModel::Linear;
            let hybrid = run_orbits_hybrid(
                &OrbitRunRequest { spec, y0 },
                &HybridSettings::default(),
                &Cancel::new(),
            )
            .unwrap();
            spec.method = Method::Dopri5(Tolerances {
                rtol: 1e-9,
                atol: 1e-12,
                ..Tolerances::default()
            });
            let full = run_orbits(&OrbitRunRequest { spec, y0 }).unwrap();
            // The orbits asked for (a step ending on the run's end may open a stub of the next
            // orbit, in both runs alike).
            assert!(full.summaries.len() >= 6 && hybrid.run.summaries.len() >= 6);
            compare(&full.summaries[..6], &hybrid.run.summaries[..6]);
            assert_eq!(hybrid.t_linear, 0.0);
            assert!(hybrid.t_exponential > 0.95 * 6.0 * orbit.period);
            assert!(hybrid.run.stats.n_steps * 20 < full.stats.n_steps);
        }
    }
}
