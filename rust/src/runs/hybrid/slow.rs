//! Slow-time propagation of the two-layer panel on orbits that leave the hybrid no linear arc:
//! an eclipse every orbit (low orbits), or loads that vary along every arc (the Earth's heat, an
//! attitude other than Sun-pointing).
//!
//! The state is split as y = ȳ(t, T̄) + Re(z v):
//!
//! - ȳ = (T̄, θ̄, θ̄') is the hinge's slow manifold over the temperatures T̄. With θ₀ = M_T(T̄)/K_el
//!   and its derivatives along the thermal flow T̄' = g(t, T̄, θ̄),
//!   θ̄ = θ₀ − (c_d θ₀' + I_eff θ₀'' + N)/K_el and its rate along the flow
//!   θ̄' = θ₀' − (c_d θ₀'' + I_eff θ₀''' + I_eff' θ₀'' + N')/K_el: the hinge equation balanced by
//!   the slow motion's own damping, inertia (I_B (1 + 3 sin²θ) for the non-linear hinge) and, for
//!   the non-linear hinge, its velocity term N = 3 I_B θ₀'² sin θ₀ cos θ₀. The inertia's term
//!   I_eff θ₀''' is ε² of θ₀' (ε the thermal rates over the hinge's angular frequency): as large
//!   as the ringing a penumbra excites, so a split without it misreads that ringing.
//! - z is the ringing along the hinge eigenvector v (θ component 1) of the Jacobian at ȳ, λ its
//!   eigenvalue and w the left eigenvector (wᵀv = 1): z' = (λ − wᵀv' + i Δω(|z|)) z, where Δω is the
//!   non-linear hinge's frequency shift at amplitude |z| (from its conservative period, exact by
//!   quadrature). The thermal coupling, and with it flutter, is in λ.
//!
//! T̄ is integrated on the thermal time scale (Dormand–Prince 8(5,3) on two states, its
//! continuous extension held to the tolerance inside each step: the reads are made there); z is
//! carried in
//! closed form over each step (the exponent's rate a quadratic through three Gauss nodes). Where
//! the loads change on the hinge's time scale, the penumbra, the full model is integrated with
//! the hinge resolved, and the state is split again after it; at a cylindrical shadow's jump the
//! split is made again on the new side, so the jump of ȳ goes into z.
//!
//! Guards: the thermal rates must be slow against the hinge (the split's premise), the ringing
//! small (the closed form is linear in it, with the non-linear hinge's frequency shift), the
//! split must converge, |θ| stay within the run's limit, and every summary of the orbit hold
//! the accuracy gate by twice the error the ringing may carry ([`RING_ACCURACY`] of its
//! amplitude). An orbit where one fails is integrated again in full from its start; the next
//! orbit tries slow time again. Where only a window's summaries fail the last (a column near 0
//! read after entry or exit), the orbit runs in full from its start to that window's end and on
//! slow time after it: those summaries are the full integration's, as in an orbit given back.

use crate::cancel::Cancel;
use crate::error::Result;
use crate::inputs::heating::Loads;
use crate::inputs::orbit::{breakpoints_of, EclipseTable, Shadow};
use crate::inputs::panel::Panel;
use crate::models::coupled::Coupled;
use crate::models::hinge::{quasi_static, sin_cos_as, HingeModel};
use crate::numerics::integrate::dop853::{self, Dop853Step};
use crate::numerics::integrate::{solve, OdeSystem, State, Tolerances, WithCuts};
use crate::numerics::quadrature::GAUSS_5;
use crate::runs::hybrid::jacobian::Linearisation;
use crate::runs::hybrid::tabulated::{self, LoadTable, Tabulated};
use crate::runs::hybrid::{counted_as_fallback, HybridRun, Propagated};
use crate::runs::orbits::STEPS_PER_HINGE_PERIOD;
use crate::runs::orbits::{resolve_hinge, Collector, OrbitRunSpec, SummaryObserver, TwoLayerView};
use nalgebra::{Complex, Matrix4, Vector2, Vector4, U2};
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// Largest ratio of the thermal block's rates (a Gershgorin bound) to the hinge's angular
/// frequency at which the split is trusted.
pub const SEPARATION_LIMIT: f64 = 0.1;
/// Largest ringing amplitude |z| (rad) carried in closed form.
pub const RING_LIMIT: f64 = 0.03;
/// Reads per hinge period of a span shorter than a period, and the half-width of the parabola
/// that refines a peak, as a fraction of the period.
const READS_PER_PERIOD: f64 = 16.0;
/// Time step (s) of the derivative of θ₀' along the thermal flow.
const FLOW_STEP: f64 = 0.5;
/// Error control of the slow integration, on its scaled state ([`SlowModel::scaled`]): each
/// component's absolute tolerance is 1e-3 of its scale. (A relative tolerance of 1e-5 took 14 %
/// fewer steps and held every column of the heated 540 km year as well, but a non-linear
/// ringing carried over 30 orbits drifted in phase to 1.0 % of its peak against 0.8 %.)
const SLOW_TOLERANCES: Tolerances = Tolerances {
    rtol: 1e-6,
    atol: 1e-3,
    max_step: 600.0,
    max_steps: 50_000_000,
};
/// Absolute tolerance of the slow integration on θ₀ = M_T/K_el (rad), 5 % of the accuracy
/// gate's 1e-6 rad: θ follows T_f − T_b one for one, so a column near 0 (θ_min of a panel that
/// barely bends back in shadow) needs the difference that closely.
const ANGLE_TOLERANCE: f64 = 5e-8;
/// Absolute tolerance of the slow integration on the mean temperature, K.
const MEAN_TOLERANCE: f64 = 1e-3;
/// The longest first step of a segment, as a fraction of the thermal block's time scale (the
/// inverse of its rate bound, ~45 s for Table 1). A segment starts at a terminator, where the
/// transient is steepest, and a step reads the lag θ̄ − θ₀ and the ringing's rate from a
/// parabola through three points: the thermal error control alone lets the first step grow to
/// ~35 s, where the heated 540 km year's `entry_theta_min` (read in that first step) strayed to
/// 2.1 of the accuracy gate against rk45 (non-linear hinge); at 0.4 it reads 0.59 of it, at
/// 0.75 0.73 and at 1 1.7 (0.71 when the steps grew ten-fold from 0.17 s, 8 % more of them).
const FIRST_STEP_SHARE: f64 = 0.4;

/// The two-layer panel on its hinge, read on slow time.
#[derive(Clone)]
struct SlowModel {
    system: Coupled,
    /// The system's Jacobian in closed form.
    linear: Linearisation,
    model: HingeModel,
    stiffness: f64,
    damping: f64,
    inertia: f64,
    /// The slow integration's scales ([`SlowModel::scaled`]), and their reciprocals.
    scales: (f64, f64),
    per_scales: (f64, f64),
    /// θ₀ per kelvin of T_f − T_b, M_T per kelvin / K_el: the right-hand side multiplies.
    theta0_per_kelvin: f64,
    /// 1 / K_el.
    per_stiffness: f64,
    /// cos u at the Gauss–Legendre nodes of [0, π] (u = π (x + 1)/2) and their weights: the
    /// frequency shift's quadrature.
    gauss_cosines: [(f64, f64); 5],
    /// The segment being integrated: the loads' side of each shadow edge, and the flow's
    /// derivative kept inside it.
    segment: (f64, f64),
    /// The segment's loads, tabulated on entering it (under the Earth's heat or an attitude).
    table: Option<LoadTable>,
}

/// A point of the slow manifold.
#[derive(Clone, Copy, Debug)]
struct Manifold {
    y: Vector4<f64>,
    /// θ̄ − θ₀: the quasi-static deflection's lag, the slow part of the dynamic part.
    lag: f64,
}

/// The loads at `t` and at three times around it (one of them t) inside the segment.
#[derive(Clone, Copy)]
struct FlowLoads {
    t: f64,
    times: [f64; 3],
    loads: [Loads; 3],
    /// Which of `times` is t.
    now: usize,
}

impl FlowLoads {
    fn at_t(&self) -> Loads {
        self.loads[self.now]
    }
}

/// The hinge mode at a point of the slow manifold.
#[derive(Clone, Copy, Debug)]
struct Mode {
    lambda: Complex<f64>,
    v: [Complex<f64>; 4],
    w: [Complex<f64>; 4],
    /// A bound on the thermal block's rates over the hinge's angular frequency.
    separation: f64,
}

impl SlowModel {
    fn new(spec: &OrbitRunSpec) -> Self {
        let p = &spec.panel;
        let theta0_per_kelvin = p.moment_per_kelvin() / p.hinge_stiffness;
        let (mean, difference) = scales(theta0_per_kelvin);
        SlowModel {
            system: Coupled::new(spec.panel, spec.orbit, spec.model, spec.coupling),
            linear: Linearisation::new(&spec.panel, spec.model, spec.coupling),
            model: spec.model,
            stiffness: p.hinge_stiffness,
            damping: p.damping,
            inertia: p.hinge_inertia(),
            scales: (mean, difference),
            per_scales: (1.0 / mean, 1.0 / difference),
            theta0_per_kelvin,
            per_stiffness: 1.0 / p.hinge_stiffness,
            gauss_cosines: GAUSS_5.map(|(x, wt)| ((0.5 * PI * (x + 1.0)).cos(), wt)),
            segment: (f64::NEG_INFINITY, f64::INFINITY),
            table: None,
        }
    }

    fn enter(&mut self, a: f64, b: f64) {
        self.segment = (a, b);
        self.system.enter_segment(a, b);
        self.table = LoadTable::fit(&self.system, a, b);
    }

    fn loads(&self, t: f64) -> Loads {
        if self.system.has_face_loads() {
            tabulated::loads_at(&self.system, self.table.as_ref(), t)
        } else {
            Loads::sun(self.system.flux_at(t))
        }
    }

    fn scaled(&self, temps: &Vector2<f64>) -> Vector2<f64> {
        let (per_mean, per_difference) = self.per_scales;
        Vector2::new(
            0.5 * (temps[0] + temps[1]) * per_mean,
            (temps[0] - temps[1]) * per_difference,
        )
    }

    fn temps(&self, u: &Vector2<f64>) -> Vector2<f64> {
        let (mean, difference) = self.scales;
        let (m, d) = (u[0] * mean, u[1] * difference);
        Vector2::new(m + 0.5 * d, m - 0.5 * d)
    }

    /// θ₀ = M_T/K_el of the temperatures (by the ratio taken once: the slow flow's chain of
    /// stages holds no division).
    fn theta0(&self, temps: &Vector2<f64>) -> f64 {
        self.theta0_per_kelvin * (temps[0] - temps[1])
    }

    /// T' with the hinge at θ, at rest.
    fn thermal(&self, loads: Loads, temps: &Vector2<f64>, theta: f64) -> Vector2<f64> {
        Vector2::from(
            self.system
                .temperature_rates(loads, [temps[0], temps[1]], theta),
        )
    }

    /// θ₀' at time t (temperatures `temps`), on θ₀.
    fn theta0_rate(&self, t: f64, temps: &Vector2<f64>) -> (f64, Vector2<f64>) {
        let rates = self.thermal(self.loads(t), temps, self.theta0(temps));
        (self.theta0(&rates), rates)
    }

    /// The loads at t and at the two times next to it that the flow's derivatives read.
    fn flow_loads(&self, t: f64) -> FlowLoads {
        let (a, b) = self.segment;
        let h = FLOW_STEP;
        let (times, now) = if t - h >= a && t + h <= b {
            ([t - h, t, t + h], 1)
        } else if t + 2.0 * h <= b || t - 2.0 * h < a {
            ([t, t + h, t + 2.0 * h], 0)
        } else {
            ([t - 2.0 * h, t - h, t], 2)
        };
        FlowLoads {
            t,
            times,
            loads: times.map(|s| self.loads(s)),
            now,
        }
    }

    /// The slow manifold at (t, T̄), `flow` the loads around t.
    fn manifold(&self, flow: &FlowLoads, temps: &Vector2<f64>) -> Manifold {
        let th0 = self.theta0(temps);
        let rates0 = self.thermal(flow.at_t(), temps, th0);
        let th0_rate = self.theta0(&rates0);
        let [accel, jerk] = self.flow_derivatives(flow, temps, th0_rate, &rates0);
        let (sin, cos) = th0.sin_cos();
        let (inertia, velocity, moving) = match self.model {
            HingeModel::Linear => (self.inertia, 0.0, 0.0),
            HingeModel::Nonlinear => {
                // d/dt of I_eff θ₀'' + N beyond I_eff θ₀''': the inertia's and the velocity
                // term's own change along the flow.
                let (sc, cos2) = (sin * cos, cos * cos - sin * sin);
                let moving = self.inertia
                    * (6.0 * sc * th0_rate * accel
                        + 3.0 * (2.0 * th0_rate * accel * sc + th0_rate.powi(3) * cos2));
                (
                    self.inertia * self.model.inertia_factor(sin),
                    3.0 * self.inertia * th0_rate * th0_rate * sc,
                    moving,
                )
            }
        };
        let lag = -(self.damping * th0_rate + inertia * accel + velocity) * self.per_stiffness;
        // θ̄' = θ₀' + lag'. Its inertia term I θ₀'''/K_el is ε² of θ₀' (ε the thermal rates over
        // the hinge's angular frequency): without it a split leaves that much in the ringing.
        let theta_rate =
            th0_rate - (self.damping * accel + inertia * jerk + moving) * self.per_stiffness;
        Manifold {
            y: Vector4::new(temps[0], temps[1], th0 + lag, theta_rate),
            lag,
        }
    }

    /// θ₀'' and θ₀''' along the thermal flow at t, by differences over three times
    /// [`FLOW_STEP`] apart inside the segment: θ₀' along T + T' s (its slope is θ₀''), then along
    /// T + T' s + T'' s²/2, T'' from the first pass (its curvature is θ₀''').
    fn flow_derivatives(
        &self,
        flow: &FlowLoads,
        temps: &Vector2<f64>,
        th0_rate: f64,
        rates0: &Vector2<f64>,
    ) -> [f64; 2] {
        let (t, times) = (flow.t, flow.times);
        // θ₀' and T' at the three times, the temperatures along `curve` (of s = time − t).
        let along = |curve: &dyn Fn(f64) -> Vector2<f64>| {
            let mut values = [th0_rate; 3];
            let mut rates = [*rates0; 3];
            for k in 0..3 {
                if k != flow.now {
                    let at = temps + curve(times[k] - t);
                    rates[k] = self.thermal(flow.loads[k], &at, self.theta0(&at));
                    values[k] = self.theta0(&rates[k]);
                }
            }
            (values, rates)
        };
        let (first, rates) = along(&|s| rates0 * s);
        let accel = parabola_at(&times, &first, t).0;
        let t_accel = parabola_at(&times, &rates, t).0;
        let (second, _) = along(&|s| rates0 * s + t_accel * (0.5 * s * s));
        [accel, parabola_at(&times, &second, t).1]
    }

    /// The hinge mode of the Jacobian at (t, y), its eigenvalue found by Newton's method on the
    /// characteristic polynomial from `guess`.
    fn mode(&self, loads: Loads, y: &Vector4<f64>, guess: Complex<f64>) -> Option<Mode> {
        let j = self.linear.jacobian_at_loads(loads, y);
        let lambda = hinge_eigenvalue(&j, guess)?;
        let c = |r: usize, k: usize| Complex::new(j[(r, k)], 0.0);
        // v = (v0, v1, 1, λ): the two thermal rows.
        let (a, b, cc, d) = (c(0, 0) - lambda, c(0, 1), c(1, 0), c(1, 1) - lambda);
        let r0 = -(c(0, 2) + c(0, 3) * lambda);
        let r1 = -(c(1, 2) + c(1, 3) * lambda);
        let det = a * d - b * cc;
        if det == Complex::new(0.0, 0.0) {
            return None;
        }
        let v0 = (r0 * d - b * r1) / det;
        let v1 = (a * r1 - cc * r0) / det;
        let v = [v0, v1, Complex::new(1.0, 0.0), lambda];
        // wᵀ(J − λ) = 0 with w3 = 1; θ' = θ̇ makes J's θ row (0, 0, 0, 1).
        // The same 2×2 block, transposed: the same determinant.
        let (s0, s1) = (-c(3, 0), -c(3, 1));
        let w0 = (s0 * d - cc * s1) / det;
        let w1 = (a * s1 - b * s0) / det;
        let w2 = -(w0 * c(0, 3) + w1 * c(1, 3) + c(3, 3) - lambda);
        let mut w = [w0, w1, w2, Complex::new(1.0, 0.0)];
        let norm: Complex<f64> = (0..4).map(|k| w[k] * v[k]).sum();
        if norm == Complex::new(0.0, 0.0) {
            return None;
        }
        for x in &mut w {
            *x /= norm;
        }
        let block = j[(0, 0)].abs().max(j[(1, 1)].abs()) + j[(0, 1)].abs().max(j[(1, 0)].abs());
        Some(Mode {
            lambda,
            v,
            w,
            separation: block / lambda.im.abs(),
        })
    }

    /// The non-linear hinge's angular frequency at amplitude `amp` about `theta` minus its
    /// small-oscillation value: the conservative hinge's period 2 ∫₀^π sqrt(m(θ + A cos u)/K_el) du,
    /// m(θ) = I_B (1 + 3 sin²θ), by Gauss–Legendre quadrature (the integrand is smooth); at zero
    /// amplitude the integrand is constant, the period 2π sqrt(m(θ)/K_el).
    fn frequency_shift(&self, theta: f64, amp: f64) -> f64 {
        if self.model == HingeModel::Linear || amp == 0.0 {
            return 0.0;
        }
        // sqrt(m(θ)/K_el): the sine by the hinge's own polynomial (the angles are small), the
        // ratio of the constants taken once.
        let inertia_per_stiffness = self.inertia / self.stiffness;
        let root = |angle: f64| {
            let sin = sin_cos_as::<f64>(angle).0;
            (inertia_per_stiffness * self.model.inertia_factor(sin)).sqrt()
        };
        let sum: f64 = self
            .gauss_cosines
            .iter()
            .map(|&(cos, wt)| wt * root(theta + amp * cos))
            .sum();
        2.0 * PI / (PI * sum) - 2.0 * PI / (2.0 * PI * root(theta))
    }

    /// Splits the state y at t into the slow manifold over T̄ and the ringing z: the fixed point
    /// of T̄ = T − Re(z v_T), z = 2 wᵀ(y − ȳ).
    fn split(
        &self,
        t: f64,
        y: &Vector4<f64>,
        guess: Complex<f64>,
    ) -> Option<(Manifold, Mode, Complex<f64>)> {
        let mut temps = Vector2::new(y[0], y[1]);
        let mut lambda = guess;
        let flow = self.flow_loads(t);
        for _ in 0..20 {
            let m = self.manifold(&flow, &temps);
            let mode = self.mode(flow.at_t(), &m.y, lambda)?;
            lambda = mode.lambda;
            let d = y - m.y;
            let z: Complex<f64> = 2.0 * (0..4).map(|k| mode.w[k] * d[k]).sum::<Complex<f64>>();
            let next = Vector2::new(y[0] - (z * mode.v[0]).re, y[1] - (z * mode.v[1]).re);
            let moved = (next - temps).abs().max();
            temps = next;
            if moved <= 1e-12 * temps.abs().max() {
                let m = self.manifold(&flow, &temps);
                let mode = self.mode(flow.at_t(), &m.y, lambda)?;
                let d = y - m.y;
                let z = 2.0 * (0..4).map(|k| mode.w[k] * d[k]).sum::<Complex<f64>>();
                return Some((m, mode, z));
            }
        }
        None
    }
}

/// The slope and curvature at t of the parabola through (xs, fs).
fn parabola_at<T>(xs: &[f64; 3], fs: &[T; 3], t: f64) -> (T, T)
where
    T: Copy
        + std::ops::Add<Output = T>
        + std::ops::Sub<Output = T>
        + std::ops::Mul<f64, Output = T>,
{
    // The three gaps' reciprocals: one division each, shared by the components.
    let [per01, per12, per02] =
        [(1, 0), (2, 1), (2, 0)].map(|(i, j): (usize, usize)| 1.0 / (xs[i] - xs[j]));
    let d01 = (fs[1] - fs[0]) * per01;
    let d12 = (fs[2] - fs[1]) * per12;
    let second = (d12 - d01) * per02;
    (d01 + second * (2.0 * t - xs[0] - xs[1]), second * 2.0)
}

/// The slow integration's state is the mean temperature and T_f − T_b, each over its absolute
/// tolerance in units of [`SLOW_TOLERANCES`]' atol (T_f − T_b's from [`ANGLE_TOLERANCE`] through
/// θ₀ per kelvin, `per_kelvin`): these scales.
fn scales(per_kelvin: f64) -> (f64, f64) {
    let per_kelvin = per_kelvin.abs();
    let difference = if per_kelvin > 0.0 {
        (ANGLE_TOLERANCE / per_kelvin).min(MEAN_TOLERANCE)
    } else {
        MEAN_TOLERANCE
    };
    let unit = SLOW_TOLERANCES.atol;
    (MEAN_TOLERANCE / unit, difference / unit)
}

/// The share of the θ error an orbit's gate check allows for ([`THETA_ACCURACY`] of the
/// ringing) by which two states slow time holds for the same may differ.
const STATE_MATCH: f64 = 0.2;

/// Whether slow time cannot tell the states `a` and `b` of `panel` apart, `ring` the largest
/// dynamic part of the orbit they end (its `jitter_peak`): their mean temperatures within one
/// step's error tolerance of its integration (atol plus rtol of the value, in its scaled unit),
/// and their quasi-static angles θ₀ = M_T/K_el, dynamic parts θ − θ₀ and rates (over the
/// hinge's angular frequency) within [`ANGLE_TOLERANCE`] or [`STATE_MATCH`] of the θ error the
/// gate check allows the orbit for its ringing, whichever is larger. A run of slow time from
/// either is then as good as from the other: two histories of the same heated orbits end them
/// this far apart (a step across the albedo's kink accepted or not on a hair; the non-linear
/// hinge's ringing, its frequency set by its amplitude), ~1e-7 rad at Table 1's 1.3e-3 rad.
pub(crate) fn indistinct(panel: &Panel, a: &Vector4<f64>, b: &Vector4<f64>, ring: f64) -> bool {
    let (moment, stiffness) = (panel.moment_per_kelvin(), panel.hinge_stiffness);
    let omega = panel.natural_angular_frequency();
    let (mean, _) = scales(moment / stiffness);
    let Tolerances { rtol, atol, .. } = SLOW_TOLERANCES;
    let (ma, mb) = (0.5 * (a[0] + a[1]) / mean, 0.5 * (b[0] + b[1]) / mean);
    // θ₀, the dynamic part and the rate over ω.
    let angles = |y: &Vector4<f64>| {
        let th0 = quasi_static(moment, stiffness, y[0], y[1]);
        [th0, y[2] - th0, y[3] / omega]
    };
    let (pa, pb) = (angles(a), angles(b));
    let ring = [pa, pb]
        .iter()
        .map(|p| p[1].hypot(p[2]))
        .fold(ring.abs(), f64::max);
    let allowed = ANGLE_TOLERANCE.max(STATE_MATCH * THETA_ACCURACY * ring);
    (ma - mb).abs() <= atol + rtol * ma.abs().max(mb.abs())
        && (0..3).all(|k| (pa[k] - pb[k]).abs() <= allowed)
}

/// ln(1 − δ), its imaginary part in (−π, π]: for the small δ of a ringing's thermal share by
/// the series −Σ δⁿ/n, cut where its next term is below 1e-19, without the logarithm and
/// arctangent of 1 − δ; else those.
fn ln_one_minus(delta: Complex<f64>) -> Complex<f64> {
    // −δ (1 + δ (1/2 + δ (1/3 + … δ/n))).
    fn series<const N: usize>(d: Complex<f64>) -> Complex<f64> {
        let mut sum = Complex::new(1.0 / N as f64, 0.0);
        for n in (1..N).rev() {
            sum = sum * d + Complex::new(1.0 / n as f64, 0.0);
        }
        -(d * sum)
    }
    let size = delta.norm_sqr();
    if size <= 1e-6 {
        // |δ|⁷/7 ≤ 1.5e-22.
        series::<6>(delta)
    } else if size <= 1.0 / 256.0 {
        // |δ|¹⁶/16 ≤ 4e-21.
        series::<15>(delta)
    } else {
        let kappa = Complex::new(1.0, 0.0) - delta;
        Complex::new(0.5 * kappa.norm_sqr().ln(), kappa.arg())
    }
}

/// ln |z| from |z|² (no hypotenuse), where |z|² does not underflow.
fn log_norm(z: Complex<f64>) -> f64 {
    let square = z.norm_sqr();
    if square >= f64::MIN_POSITIVE {
        0.5 * square.ln()
    } else {
        z.norm().ln()
    }
}

/// det(λ − J) = λ⁴ + c₃λ³ + c₂λ² + c₁λ + c₀ of a Jacobian whose θ row is (0, 0, 0, 1) (θ' =
/// θ̇): [c₃, c₂, c₁, c₀] = [−E₁, E₂, −E₃, E₄], E_k the sum of J's k×k principal minors, of
/// which that row zeroes or shortens all but four.
fn characteristic(j: &Matrix4<f64>) -> [f64; 4] {
    let a = |r: usize, k: usize| j[(r, k)];
    debug_assert!((0..4).all(|k| a(2, k) == if k == 3 { 1.0 } else { 0.0 }));
    let minor = |r: usize, s: usize, k: usize, l: usize| a(r, k) * a(s, l) - a(r, l) * a(s, k);
    // The 2×2 principal minors: (0,1), (0,3), (1,3) and (2,3) = −a₃₂; (0,2), (1,2) are 0.
    let e2 = minor(0, 1, 0, 1) + minor(0, 3, 0, 3) + minor(1, 3, 1, 3) - a(3, 2);
    // The 3×3: (0,1,3) in full, (0,2,3) and (1,2,3) down to a 2×2 each; (0,1,2) is 0.
    let d013 =
        a(0, 0) * minor(1, 3, 1, 3) - a(0, 1) * minor(1, 3, 0, 3) + a(0, 3) * minor(1, 3, 0, 1);
    let e3 = d013 - minor(0, 3, 0, 2) - minor(1, 3, 1, 2);
    // det J along the θ row: −det of rows (0, 1, 3) and columns (0, 1, 2).
    let e4 =
        -(a(0, 0) * minor(1, 3, 1, 2) - a(0, 1) * minor(1, 3, 0, 2) + a(0, 2) * minor(1, 3, 0, 1));
    [-(a(0, 0) + a(1, 1) + a(3, 3)), e2, -e3, e4]
}

/// The root of det(λ − J) nearest `guess` by Newton's method on the characteristic polynomial
/// ([`characteristic`]); None unless it converges to an oscillation.
fn hinge_eigenvalue(j: &Matrix4<f64>, guess: Complex<f64>) -> Option<Complex<f64>> {
    let [c3, c2, c1, c0] = characteristic(j);
    let mut x = guess;
    for _ in 0..50 {
        let p = (((x + c3) * x + c2) * x + c1) * x + c0;
        let dp = ((x * 4.0 + 3.0 * c3) * x + 2.0 * c2) * x + c1;
        if dp.norm_sqr() == 0.0 {
            return None;
        }
        let dx = p / dp;
        x -= dx;
        if dx.norm_sqr() <= 1e-28 * x.norm_sqr() {
            return (x.im.abs() > 0.0 && x.is_finite()).then_some(x);
        }
    }
    None
}

/// T̄' on the slow manifold, scaled ([`SlowModel::scaled`]): the system the slow integration
/// solves.
struct SlowFlow<'m> {
    model: &'m SlowModel,
}

impl OdeSystem<U2> for SlowFlow<'_> {
    /// T' with the hinge at θ₀ = M_T/K_el: the slow manifold's lag θ̄ − θ₀ (~1e-4 rad in a
    /// thermal transient) changes the absorbed flux by its sine (~1e-5 of it), and θ̄ and θ₀ by
    /// the same amount, so the dynamic part not at all.
    fn rhs(&self, t: f64, y: &State<U2>) -> State<U2> {
        let m = self.model;
        let rates = m.theta0_rate(t, &m.temps(y)).1;
        m.scaled(&rates)
    }
}

/// Why the slow path gave an orbit back to the full integration.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Refusal {
    Separation,
    Ringing,
    Split,
    Limit,
    /// A summary the orbit's accuracy check could not vouch for.
    Gate,
    /// A ringing that grows over the orbit (flutter): its error, a fraction of it, would grow
    /// into the later orbits, where no check of this orbit sees it.
    Growth,
}

impl Refusal {
    /// Counts an orbit given back for this reason.
    fn count(self, run: &mut HybridRun) {
        run.n_refused_orbits += 1;
        *match self {
            Refusal::Separation => &mut run.n_refused_separation,
            Refusal::Ringing => &mut run.n_refused_ringing,
            Refusal::Split => &mut run.n_refused_split,
            Refusal::Limit => &mut run.n_refused_limit,
            Refusal::Gate => &mut run.n_refused_gate,
            Refusal::Growth => &mut run.n_refused_growth,
        } += 1;
    }
}

/// What the slow integration carries from step to step, and reads into the summaries.
struct Ringing<'a, 'c> {
    model: &'a SlowModel,
    obs: &'a mut SummaryObserver<'c, TwoLayerView>,
    /// z and the hinge mode at the last step's end.
    z: Complex<f64>,
    mode: Mode,
    manifold: Manifold,
    refusal: Option<Refusal>,
    error: Option<crate::Error>,
    steps: u64,
    /// The largest |z| of the segment.
    largest: f64,
    /// log |z| gained over the segment by the ringing's own rate (not by the splits).
    growth: f64,
}

/// The polynomial through N points in Newton's form (divided differences once, then N − 1
/// multiply-adds a value).
#[derive(Clone, Copy)]
struct Newton<T, const N: usize> {
    xs: [f64; N],
    cs: [T; N],
}

impl<T, const N: usize> Newton<T, N>
where
    T: Copy
        + std::ops::Mul<f64, Output = T>
        + std::ops::Add<Output = T>
        + std::ops::Sub<Output = T>,
{
    fn new(xs: &[f64; N], ys: &[T; N]) -> Self {
        let mut cs = *ys;
        for level in 1..N {
            for i in (level..N).rev() {
                cs[i] = (cs[i] - cs[i - 1]) * (1.0 / (xs[i] - xs[i - level]));
            }
        }
        Newton { xs: *xs, cs }
    }

    #[inline]
    fn at(&self, x: f64) -> T {
        let mut acc = self.cs[N - 1];
        for i in (0..N - 1).rev() {
            acc = acc * (x - self.xs[i]) + self.cs[i];
        }
        acc
    }
}

impl Ringing<'_, '_> {
    /// Carries z over the accepted step and reads the step into the summaries.
    fn take(&mut self, step: &Dop853Step<U2>) -> std::result::Result<(), Refusal> {
        let (t0, t1) = (step.t0, step.t1);
        let h = t1 - t0;
        let m = self.model;
        // The manifold and mode at the step's middle and end (its start is the last step's end).
        let ts = [t0, t0 + 0.5 * h, t1];
        let mut points = [self.manifold; 3];
        let mut modes = [self.mode; 3];
        let mut guess = self.mode.lambda;
        for k in 1..3 {
            let temps = m.temps(&if k == 2 { step.y1 } else { step.eval(ts[k]) });
            let flow = m.flow_loads(ts[k]);
            points[k] = m.manifold(&flow, &temps);
            modes[k] = m
                .mode(flow.at_t(), &points[k].y, guess)
                .ok_or(Refusal::Split)?;
            guess = modes[k].lambda;
        }
        if modes.iter().any(|md| md.separation > SEPARATION_LIMIT) {
            return Err(Refusal::Separation);
        }
        // In x = 2 (t − t0)/h − 1 the three points are x = −1, 0, 1. The exponent's rate there:
        // λ − wᵀv' + i Δω, v' from the parabola through the three modes (d/dt = (2/h) d/dx).
        // |z| where the non-linear hinge's shift needs it (a hypotenuse a step saved otherwise).
        let amp = match m.model {
            HingeModel::Nonlinear => self.z.norm(),
            HingeModel::Linear => 0.0,
        };
        let slope = |c: usize, k: usize| -> Complex<f64> {
            let (a, b, d) = (modes[0].v[c], modes[1].v[c], modes[2].v[c]);
            let dx = match k {
                0 => b * 4.0 - a * 3.0 - d,
                1 => d - a,
                _ => a - b * 4.0 + d * 3.0,
            };
            dx * (1.0 / h)
        };
        let mut rate: [Complex<f64>; 3] = std::array::from_fn(|k| {
            let md = &modes[k];
            let wv: Complex<f64> = (0..4).map(|c| md.w[c] * slope(c, k)).sum();
            md.lambda - wv
        });
        if m.model == HingeModel::Nonlinear && amp > 0.0 {
            // The non-linear hinge's frequency shift at each node's own amplitude: the shift goes
            // as A², and the amplitude decays along a step (the shift changes only the phase, so
            // the amplitude comes from the real rate alone, its parabola integrated to the node).
            let (r0, r1, r2) = (
                rate[1].re,
                0.5 * (rate[2].re - rate[0].re),
                0.5 * (rate[2].re + rate[0].re) - rate[1].re,
            );
            let growth = [
                0.0,
                0.5 * h * (r0 - 0.5 * r1 + r2 / 3.0),
                0.5 * h * (2.0 * r0 + 2.0 * r2 / 3.0),
            ];
            for (k, r) in rate.iter_mut().enumerate() {
                let shift = m.frequency_shift(points[k].y[2], amp * growth[k].exp());
                *r += Complex::new(0.0, shift);
            }
        }
        // The rate as q0 + q1 x + q2 x² through them, and ∫ rate from t0, that parabola
        // integrated exactly.
        let q0 = rate[1];
        let q1 = (rate[2] - rate[0]) * 0.5;
        let q2 = (rate[2] + rate[0]) * 0.5 - rate[1];
        let scaled = |t: f64| 2.0 * (t - t0) / h - 1.0;
        let exponent = |t: f64| -> Complex<f64> {
            let x = scaled(t);
            (q0 * (x + 1.0) + q1 * (0.5 * (x * x - 1.0)) + q2 * ((x * x * x + 1.0) / 3.0))
                * (0.5 * h)
        };
        let rate_at = |t: f64| {
            let x = scaled(t);
            q0 + q1 * x + q2 * (x * x)
        };
        let z0 = self.z;
        let z_at = |t: f64| z0 * exponent(t).exp();
        // θ̄ = θ₀(T̄) + lag: T̄ from the slow integration's own interpolant, the lag (small and
        // smooth) from the parabola through the three points.
        let lags = Newton::new(&ts, &points.map(|p| p.lag));
        let theta_bar = |t: f64| m.theta0(&m.temps(&step.eval(t))) + lags.at(t);
        // κ = 1 − (M_T per kelvin / K_el)(v_f − v_b): the dynamic part's share of the ringing
        // (the ringing's own thermal swing moves the quasi-static angle); its modulus and angle
        // interpolated apart, so that reads take no complex transcendental.
        let log_kappa: [Complex<f64>; 3] = std::array::from_fn(|k| {
            ln_one_minus((modes[k].v[0] - modes[k].v[1]) * m.theta0_per_kelvin)
        });
        let arg_kappa = Newton::new(&ts, &log_kappa.map(|l| l.im));
        let log_kappa = Newton::new(&ts, &log_kappa.map(|l| l.re));
        let (log_z0, arg0) = (log_norm(z0), z0.arg());
        let log_amp = |t: f64| log_z0 + exponent(t).re;
        let phase = |t: f64| arg0 + exponent(t).im;
        let period = 2.0 * PI / modes[2].lambda.im.abs();
        let speed = |t: f64| rate_at(t).im;
        // κ z at t: one complex exponential of log κ + log z0 + the exponent.
        let kappa_z_at = |t: f64| {
            let e = exponent(t);
            Complex::new(
                log_kappa.at(t) + log_z0 + e.re,
                arg_kappa.at(t) + arg0 + e.im,
            )
            .exp()
        };
        // θ = θ̄ + A cos φ and the dynamic part = lag + |κ| A cos(φ + arg κ).
        let theta = Wave {
            slow: &theta_bar,
            amplitude: &|t: f64| log_amp(t).exp(),
            phase: &phase,
            speed: &speed,
            period,
        };
        let dynamic = Wave {
            slow: &|t: f64| lags.at(t),
            amplitude: &|t: f64| (log_amp(t) + log_kappa.at(t)).exp(),
            phase: &|t: f64| phase(t) + arg_kappa.at(t),
            speed: &speed,
            period,
        };
        // |dynamic| ≤ max |lag| + max |κ| A over the step, each of the three read exactly off its
        // polynomial: where that bound cannot raise the orbit's peak so far, the peak is not read.
        let log_amp_max = log_z0 + 0.5 * h * cubic_max(q0.re, q1.re, q2.re);
        let bound = largest_magnitude(&lags, t0, t1)
            + (log_amp_max + parabola_range(&log_kappa, t0, t1).1).exp();
        let current = &self.obs.collector.current;
        let peak_so_far = if current.t_start <= t0 && t1 <= current.t_end {
            current.jitter_peak
        } else {
            f64::NEG_INFINITY
        };
        let dyn_abs = if bound <= peak_so_far {
            bound
        } else {
            let (lo, hi) = dynamic.range(t0, t1);
            hi.max(-lo)
        };
        // ∫ (dynamic)²: lag² + |κz|²/2 by Gauss–Legendre, and the oscillating terms
        // 2 lag Re(κz) + Re((κz)²)/2 by their leading term [F/L']: they swing at the hinge's
        // frequency, L' the exponent's rate.
        let mut sq = 0.0;
        for (x, wt) in GAUSS_5 {
            let t = t0 + 0.5 * h * (1.0 + x);
            // |κz|² takes no phase: the exponential of twice its log.
            let (lag, log_w) = (lags.at(t), log_kappa.at(t) + log_z0 + exponent(t).re);
            sq += 0.5 * h * wt * (lag * lag + 0.5 * (2.0 * log_w).exp());
        }
        let swing = |t: f64| {
            let (lag, w, r) = (lags.at(t), kappa_z_at(t), rate_at(t));
            (w * (2.0 * lag) / r + w * w / (4.0 * r)).re
        };
        sq += swing(t1) - swing(t0);
        let sq = sq.max(0.0);
        let z1 = z_at(t1);
        let beyond = |z: Complex<f64>| z.norm_sqr() > RING_LIMIT * RING_LIMIT;
        if beyond(z1) || beyond(z0) {
            return Err(Refusal::Ringing);
        }
        // θ's bounds over the step: θ̄'s (θ₀ per unit of the scaled T_f − T_b, over the
        // extension's bounds, and the lag's parabola) widened by the ringing's largest amplitude
        // and a rounding margin. A side whose bound cannot move the orbit's extremes, its
        // amplitude or the limit, outside its windows, is not read: it leaves the summaries as
        // they are.
        let per_unit = m.theta0(&m.temps(&Vector2::new(0.0, 1.0)));
        let (u_lo, u_hi) = step.bounds(1);
        let (lag_lo, lag_hi) = parabola_range(&lags, t0, t1);
        let swing = log_amp_max.exp();
        let bar_lo = (per_unit * u_lo).min(per_unit * u_hi) + lag_lo;
        let bar_hi = (per_unit * u_lo).max(per_unit * u_hi) + lag_hi;
        let margin = |v: f64| 1e-12 * v.abs() + 1e-15;
        let (lo_bound, hi_bound) = (bar_lo - swing, bar_hi + swing);
        let (lo_bound, hi_bound) = (lo_bound - margin(lo_bound), hi_bound + margin(hi_bound));
        let limit = self.obs.collector.options.theta_limit;
        let (need_lo, need_hi) = {
            let c = &self.obs.collector.current;
            let w = self.obs.collector.options.window;
            let in_window = [c.t_entry, c.t_exit]
                .into_iter()
                .any(|start| t0 <= start + w && t1 >= start);
            let settled = c.t_start <= t0 && t1 <= c.t_end && !in_window;
            let moves = |bound: f64| (bound - c.theta_eq).abs() > c.amplitude;
            (
                !settled || lo_bound < c.theta_min || moves(lo_bound) || lo_bound < -limit,
                !settled || hi_bound > c.theta_max || moves(hi_bound) || hi_bound > limit,
            )
        };
        let (lo, hi) = theta.sides(t0, t1, need_lo, need_hi);
        let (lo, hi) = (
            if need_lo { lo } else { lo_bound },
            if need_hi { hi } else { hi_bound },
        );
        if hi > limit || lo < -limit {
            return Err(Refusal::Limit);
        }
        // The whole step's extremes are those just read; a window's part of it is read anew.
        let extremes = |a: f64, b: f64| {
            if (a, b) == (t0, t1) {
                (lo, hi)
            } else {
                theta.range(a, b)
            }
        };
        if let Err(e) = self
            .obs
            .collector
            .record_span(t0, t1, &extremes, dyn_abs, sq)
        {
            self.error = Some(e);
        }
        self.growth += exponent(t1).re;
        self.z = z1;
        self.mode = modes[2];
        self.manifold = points[2];
        self.steps += 1;
        // z0 was the step before's z1, or the segment's start (`largest` starts there).
        self.largest = self.largest.max(z1.norm());
        Ok(())
    }
}

/// A slow value plus a swing at the hinge's frequency, s(t) + A(t) cos φ(t): its largest value
/// over a span is at one of the peaks (φ = 2πm) next to the envelope's largest, s + A, or at an
/// end of the span; its smallest, that of −s + A cos(φ + π).
struct Wave<'f> {
    slow: &'f dyn Fn(f64) -> f64,
    amplitude: &'f dyn Fn(f64) -> f64,
    phase: &'f dyn Fn(f64) -> f64,
    /// φ'.
    speed: &'f dyn Fn(f64) -> f64,
    period: f64,
}

impl Wave<'_> {
    /// The smallest and largest of s + A cos φ over [a, b]: the envelope's samples shared.
    fn range(&self, a: f64, b: f64) -> (f64, f64) {
        self.sides(a, b, true, true)
    }

    /// The smallest (if `low`) and largest (if `high`) of s + A cos φ over [a, b]; NaN for a
    /// side not asked for.
    fn sides(&self, a: f64, b: f64, low: bool, high: bool) -> (f64, f64) {
        if !(low || high) {
            return (f64::NAN, f64::NAN);
        }
        // The ends' values serve both signs.
        let ends = [self.value(a), self.value(b)];
        let samples: Option<[(f64, f64, f64); ENVELOPE_READS + 1]> =
            (b - a > self.period).then(|| {
                std::array::from_fn(|i| {
                    let t = a + (b - a) * i as f64 / ENVELOPE_READS as f64;
                    (t, (self.slow)(t), (self.amplitude)(t))
                })
            });
        let side = |on: bool, sign: f64| {
            if on {
                sign * self.extreme(a, b, sign, ends, samples.as_ref())
            } else {
                f64::NAN
            }
        };
        (side(low, -1.0), side(high, 1.0))
    }

    /// s + A cos φ at t.
    fn value(&self, t: f64) -> f64 {
        (self.slow)(t) + (self.amplitude)(t) * (self.phase)(t).cos()
    }

    /// The largest of `sign` (s + A cos φ) over [a, b]; `ends` its values (unsigned) at a and b;
    /// `samples` (t, s, A) at the [`ENVELOPE_READS`] + 1 points that find the envelope's largest
    /// on a span longer than a period.
    fn extreme(
        &self,
        a: f64,
        b: f64,
        sign: f64,
        ends: [f64; 2],
        samples: Option<&[(f64, f64, f64); ENVELOPE_READS + 1]>,
    ) -> f64 {
        let f = |t: f64| sign * self.value(t);
        let envelope = |t: f64| sign * (self.slow)(t) + (self.amplitude)(t);
        // The peaks of −(s + A cos φ) are those of cos(φ + π).
        let turn = if sign < 0.0 { PI } else { 0.0 };
        let mut best = (sign * ends[0]).max(sign * ends[1]);
        if b <= a {
            return best;
        }
        let d = self.period / READS_PER_PERIOD;
        let Some(samples) = samples else {
            // At least the middle: a peak inside a span shorter than d.
            let n = ((b - a) / d).ceil().max(2.0) as usize;
            for i in 1..n {
                best = best.max(refined(
                    &f,
                    a + (b - a) * i as f64 / n as f64,
                    None,
                    d,
                    a,
                    b,
                ));
            }
            return best;
        };
        // The envelope's largest on a few points, then the peaks around it.
        let mut t_star = a;
        let mut e_best = f64::NEG_INFINITY;
        for &(t, slow, amplitude) in samples {
            let e = sign * slow + amplitude;
            if e > e_best {
                (e_best, t_star) = (e, t);
            }
        }
        // Where the envelope barely moves over a period, a peak next to t* reaches it to within
        // that movement: the envelope is then the value (an upper bound, within 1 % of the
        // accuracy gate's 2 %).
        let (lo, hi) = (
            (t_star - 0.5 * self.period).max(a),
            (t_star + 0.5 * self.period).min(b),
        );
        let moved = (envelope(hi) - envelope(lo)).abs();
        if moved <= 2e-4 * e_best.abs().max(5e-5) {
            return best.max(e_best);
        }
        let phase = |t: f64| (self.phase)(t) + turn;
        let ph = phase(t_star);
        let m0 = (ph / (2.0 * PI)).round();
        // The three peaks around t*; the highest refined (the refinement moves a peak's value
        // by far less than the gap between two peaks of a moving envelope).
        let mut top: Option<(f64, f64)> = None;
        for dm in [-1.0, 0.0, 1.0] {
            let target = 2.0 * PI * (m0 + dm);
            let mut t = t_star + (target - ph) / (self.speed)(t_star);
            for _ in 0..2 {
                t -= (phase(t) - target) / (self.speed)(t);
            }
            if t >= a && t <= b {
                let v = f(t);
                if top.is_none_or(|(_, w)| v > w) {
                    top = Some((t, v));
                }
            }
        }
        if let Some((t, v)) = top {
            best = best.max(refined(&f, t, Some(v), d, a, b));
        }
        best
    }
}

/// f near t, refined by the parabola through t ± d (kept within [a, b]); `at` is f(t) when
/// known.
fn refined(f: &dyn Fn(f64) -> f64, t: f64, at: Option<f64>, d: f64, a: f64, b: f64) -> f64 {
    let (lo, hi) = ((t - d).max(a), (t + d).min(b));
    let (p, c, q) = (f(lo), at.unwrap_or_else(|| f(t)), f(hi));
    let mut best = c.max(p).max(q);
    if hi - t == t - lo && t > lo {
        let curv = p - 2.0 * c + q;
        if curv < 0.0 {
            let off = (0.5 * (p - q) / curv).clamp(-1.0, 1.0);
            // The half-width is d but where both ends are clipped (a span shorter than 2 d).
            best = best.max(f(t + off * (hi - t)));
        }
    } else if lo < t && t < hi {
        // Clipped at an end of the span: the parabola through the three unequal points (a
        // peak just after a span's start, as the first of a ringing split there, is otherwise
        // read only at the points around it).
        let (l, r) = (t - lo, hi - t);
        let (sl, sr) = ((c - p) / l, (q - c) / r);
        let curv = (sr - sl) / (l + r);
        if curv < 0.0 {
            // p(x) = c + s (x − t) + curv (x − t)², s the slope at t: (l sr + r sl) / (l + r).
            let slope = (l * sr + r * sl) / (l + r);
            let x = (t - 0.5 * slope / curv).clamp(lo, hi);
            best = best.max(f(x));
        }
    }
    best
}

/// The largest of the cubic ∫₋₁ˣ (r0 + r1 u + r2 u²) du over x in [−1, 1]: at an end or where
/// its rate vanishes.
fn cubic_max(r0: f64, r1: f64, r2: f64) -> f64 {
    let value = |x: f64| r0 * (x + 1.0) + r1 * 0.5 * (x * x - 1.0) + r2 * (x * x * x + 1.0) / 3.0;
    let mut best = value(-1.0).max(value(1.0));
    let roots = if r2 != 0.0 {
        let disc = r1 * r1 - 4.0 * r2 * r0;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            [(-r1 - sq) / (2.0 * r2), (-r1 + sq) / (2.0 * r2)]
        } else {
            [f64::NAN; 2]
        }
    } else if r1 != 0.0 {
        [-r0 / r1, f64::NAN]
    } else {
        [f64::NAN; 2]
    };
    for x in roots {
        if x > -1.0 && x < 1.0 {
            best = best.max(value(x));
        }
    }
    best
}

/// The smallest and largest of the parabola `p` over [a, b]: at an end or its vertex.
fn parabola_range(p: &Newton<f64, 3>, a: f64, b: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (p.at(a).min(p.at(b)), p.at(a).max(p.at(b)));
    let [x0, x1, _] = p.xs;
    let [_, c1, c2] = p.cs;
    if c2 != 0.0 {
        // p' = c1 + c2 (2t − x0 − x1).
        let vertex = 0.5 * (x0 + x1) - c1 / (2.0 * c2);
        if vertex > a && vertex < b {
            let v = p.at(vertex);
            (lo, hi) = (lo.min(v), hi.max(v));
        }
    }
    (lo, hi)
}

/// The largest |p| of the parabola `p` over [a, b].
fn largest_magnitude(p: &Newton<f64, 3>, a: f64, b: f64) -> f64 {
    let (lo, hi) = parabola_range(p, a, b);
    hi.max(-lo)
}

/// Points at which a span's envelope is read to find its largest.
const ENVELOPE_READS: usize = 8;

impl Ringing<'_, '_> {
    /// Takes one accepted step of the slow integration; stops it on cancellation, an error or a
    /// guard's refusal.
    fn on_step(&mut self, step: &Dop853Step<U2>) -> ControlFlow<()> {
        if let Err(e) = self.obs.cancel.check() {
            self.error = Some(e);
            return ControlFlow::Break(());
        }
        match self.take(step) {
            Ok(()) if self.error.is_none() => ControlFlow::Continue(()),
            Ok(()) => ControlFlow::Break(()),
            Err(r) => {
                self.refusal = Some(r);
                ControlFlow::Break(())
            }
        }
    }
}

/// Orbits shorter than this (s) leave the hybrid no linear arc when they have an eclipse: an
/// eclipse every orbit and a thermal recovery after it.
pub const SHORT_ORBIT: f64 = 6.0 * 3600.0;

/// Whether the hybrid runs `spec` on slow time: a two-layer run on a short orbit (with or
/// without the Earth's heat and an attitude). Longer orbits keep the hybrid's linear arcs, and
/// under varying loads its full integration: at GEO the dynamic part is a few 1e-5 rad, where
/// the slow manifold's truncation was measured at up to 2.3 % of it (1.1e-6 rad, past the gate).
pub(crate) fn applies(spec: &OrbitRunSpec) -> bool {
    spec.orbit.period < SHORT_ORBIT
}

/// The ringing's error on slow time, as a fraction of its largest amplitude over the orbit:
/// measured at up to 0.24 % on drawn panels (the slow manifold's and the closed form's
/// truncations, against the hinge-resolved integration) in the dynamic part's RMS and peak.
const RING_ACCURACY: f64 = 3e-3;
/// The non-linear hinge's ringing error grows as its amplitude squared: the closed form keeps
/// the frequency's shift with amplitude but none of the hinge's other A² terms. Its fraction is
/// [`RING_ACCURACY`] plus this times A² (per rad²): measured 0.8 % at 0.022 rad (half Table 1's
/// heat capacity on the cylindrical shadow, 30 orbits) and 1.2 % at a fluttering panel's
/// 0.03 rad, where 0.3 % would let a ringing of 0.03 rad pass the gate check.
const NONLINEAR_RING_ACCURACY: f64 = 10.0;

/// The ringing's error as a fraction of its amplitude `ring`, for the hinge `model`.
fn ring_accuracy(model: HingeModel, ring: f64) -> f64 {
    match model {
        HingeModel::Linear => RING_ACCURACY,
        HingeModel::Nonlinear => RING_ACCURACY + NONLINEAR_RING_ACCURACY * ring * ring,
    }
}

/// The same for the extremes of θ itself, which also carry the slow manifold's error. Measured
/// without the check over the heated 540 km year (Table 1, 28.5°, against rk45 reading every
/// window's edge and every orbit's start): a column near 0 (`entry_theta_min` as it changes
/// sign with the seasons) off by at most 0.05 % of the ringing (6.6e-7 rad at 1.3e-3, the
/// nonlinear hinge; 0.06 of the gate with the linear one), so that at 0.2 % the orbits kept
/// read within 0.15 of the gate and 26 of 5511 are given back (148 at 1 %). The 1 % before
/// covered reads since mended: a peak next to a span's end, rk45's own reads of a window's
/// edge and of an orbit's start.
const THETA_ACCURACY: f64 = 2e-3;

/// Which summaries of the orbit just run (the collector's current one) slow time cannot vouch
/// for: those that do not hold the accuracy gate (2 %, or 1e-6 rad below 5e-5 rad) by twice the
/// error the ringing of amplitude up to `ring` may carry (a column near 0, θ_min of a panel that
/// barely bends back, cannot); the RMS of the dynamic part scales with the ringing, so its error
/// is that fraction of itself. A window that ends by `full_until` was read in full: its
/// summaries are not slow time's.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Unvouched {
    /// The orbit's own: the RMS and peak of the dynamic part, θ's extremes and amplitude.
    orbit: bool,
    /// The window after entry's (its θ_min and peak), and after exit's.
    entry: bool,
    exit: bool,
}

impl Unvouched {
    fn none(&self) -> bool {
        !(self.orbit || self.entry || self.exit)
    }

    /// The end of the last window not vouched for, within the orbit.
    fn windows_end<V: crate::runs::orbits::SummaryView>(&self, c: &Collector<V>) -> f64 {
        let s = &c.current;
        let end = |on: bool, start: f64| {
            if on {
                c.window_end(start)
            } else {
                f64::NEG_INFINITY
            }
        };
        end(self.entry, s.t_entry).max(end(self.exit, s.t_exit))
    }
}

fn unvouched<V: crate::runs::orbits::SummaryView>(
    c: &Collector<V>,
    ring: f64,
    model: HingeModel,
    full_until: f64,
) -> Unvouched {
    let s = &c.current;
    let holds = |v: f64, bound: f64| {
        let gate = if v.abs() < 5e-5 { 1e-6 } else { 0.02 * v.abs() };
        v.is_nan() || bound <= 0.5 * gate
    };
    let rms = c.rms_so_far();
    let fraction = ring_accuracy(model, ring);
    let theta = |v: f64| holds(v, THETA_ACCURACY * ring);
    // A window read in full (or absent: its start NaN) needs no vouching.
    let read_in_full = |start: f64| start.is_nan() || c.window_end(start) <= full_until;
    Unvouched {
        orbit: !(holds(rms, fraction * rms)
            && holds(s.jitter_peak, fraction * ring)
            && [s.theta_max, s.theta_min, s.amplitude]
                .into_iter()
                .all(theta)),
        entry: !(read_in_full(s.t_entry) || theta(s.entry_theta_min) && theta(s.entry_peak)),
        exit: !(read_in_full(s.t_exit) || theta(s.exit_theta_max) && theta(s.exit_peak)),
    }
}

/// Runs the orbits of `spec` from `y0` on slow time, each orbit in full where a guard refuses it
/// (the full integration: `spec.method`, the step capped at the hinge period as the run's
/// options ask).
pub(crate) fn run_slow(
    spec: &OrbitRunSpec,
    y0: Vector4<f64>,
    cancel: &Cancel,
) -> Result<Propagated<4>> {
    let options = spec.options;
    let steps = if options.steps_per_period > 0.0 {
        options.steps_per_period
    } else {
        STEPS_PER_HINGE_PERIOD
    };
    let full_method = resolve_hinge(&spec.method, &spec.panel, steps);
    let view = TwoLayerView {
        panel: spec.panel,
        coupling: spec.coupling,
    };
    let mut obs = SummaryObserver {
        collector: Collector::new(view, spec, y0[2])?,
        error: None,
        cancel,
    };
    let mut model = SlowModel::new(spec);
    let mut full = model.system;
    let t_end = spec.t_end();
    let mut eclipses = EclipseTable::until(&spec.orbit, t_end);
    // How the time was split: slow time, and in full (penumbrae, refused orbits) as the
    // fallback's.
    let mut split = counted_as_fallback(&[], 0);
    let mut stats = crate::numerics::integrate::Stats {
        t_end: spec.t_start,
        ..Default::default()
    };
    let mut y = y0;
    let mut t = spec.t_start;
    // Each segment's split starts the hinge eigenvalue's Newton iteration from the natural
    // frequency: its root's last bits depend on the start, and a start carried over from the
    // last segment made a run's numbers depend, by an ulp, on how it was cut into calls.
    let natural = Complex::new(0.0, spec.panel.natural_angular_frequency());
    // The full integration's step budget holds for the whole run, every kind of step counted
    // (as the hybrid's): each full stretch alone stops at it, and a run of one stretch an orbit
    // would otherwise take that many steps an orbit.
    let budget = full_method.max_steps();
    let check_budget = |used: u64, t: f64| {
        if used >= budget {
            return Err(crate::Error::Integration {
                t,
                reason: format!("max_steps = {budget} reached"),
            });
        }
        Ok(())
    };
    for k in 0..spec.n_orbits {
        let orbit_start = t;
        check_budget(stats.n_steps + stats.n_rejected, t)?;
        let orbit_end = if k + 1 == spec.n_orbits {
            t_end
        } else {
            spec.t_start + (k + 1) as f64 * spec.orbit.period
        };
        obs.collector.orbit_starts(orbit_start, y[2]);
        let mark = obs.collector.mark();
        let y_start = y;
        let mut cuts = vec![orbit_start];
        cuts.extend(breakpoints_of(
            eclipses.overlapping(orbit_start, orbit_end),
            orbit_start,
            orbit_end,
        ));
        cuts.push(orbit_end);
        // The orbit on slow time from `full_until` (before it in full): at first all of it;
        // then, where only a window's summaries were too near 0 for slow time, from that
        // window's end.
        let mut full_until = orbit_start;
        let (mut slow_steps, mut full_steps, mut slow_time);
        let refused = loop {
            let mut attempt_cuts = cuts.clone();
            if full_until > orbit_start && !attempt_cuts.contains(&full_until) {
                let at = attempt_cuts.partition_point(|&c| c < full_until);
                attempt_cuts.insert(at, full_until);
            }
            let mut refused = None;
            let mut ring_max: f64 = 0.0;
            // log |z| the ringing gains over the orbit's slow time.
            let mut growth = 0.0;
            (slow_steps, full_steps, slow_time) = (0, 0, 0.0);
            for pair in attempt_cuts.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                if b <= a {
                    continue;
                }
                let mid = spec.orbit.illumination_on(0.5 * (a + b), a, b);
                let penumbra =
                    matches!(spec.orbit.shadow, Shadow::Penumbra) && mid > 0.0 && mid < 1.0;
                if b <= full_until || penumbra {
                    check_budget(
                        stats.n_steps + stats.n_rejected + slow_steps + full_steps,
                        a,
                    )?;
                    // [a, b] lies between two of the orbit's breakpoints: none inside.
                    let mut tabulated = Tabulated::new(&mut full);
                    let mut within = WithCuts {
                        system: &mut tabulated,
                        cuts: &[],
                    };
                    let (st, y1) = solve(&mut within, &full_method, a, y, b, &mut obs)?;
                    if let Some(e) = obs.error.take() {
                        return Err(e);
                    }
                    full_steps += st.n_steps;
                    stats.n_rejected += st.n_rejected;
                    stats.n_rhs += st.n_rhs;
                    y = y1;
                    if st.stopped {
                        // The full integration stopped at the run's limit.
                        split.n_slow_steps += slow_steps;
                        split.n_fallback_steps += full_steps;
                        split.t_slow += slow_time;
                        split.t_fallback += (st.t_end - orbit_start) - slow_time;
                        stats.n_steps += slow_steps + full_steps;
                        stats.stopped = true;
                        stats.t_end = st.t_end;
                        return Ok(Propagated {
                            run: obs.collector.finish(stats, y),
                            split,
                        });
                    }
                    continue;
                }
                model.enter(a, b);
                let Some((manifold, mode, z)) = model.split(a, &y, natural) else {
                    refused = Some(Refusal::Split);
                    break;
                };
                if mode.separation > SEPARATION_LIMIT {
                    refused = Some(Refusal::Separation);
                    break;
                }
                if z.norm() > RING_LIMIT {
                    refused = Some(Refusal::Ringing);
                    break;
                }
                let mut ring = Ringing {
                    model: &model,
                    obs: &mut obs,
                    z,
                    mode,
                    manifold,
                    refusal: None,
                    error: None,
                    steps: 0,
                    largest: z.norm(),
                    growth: 0.0,
                };
                let flow = SlowFlow { model: &model };
                let temps = model.scaled(&Vector2::new(manifold.y[0], manifold.y[1]));
                // The thermal block's rate bound (1/s): the segment's first step within its
                // share.
                let block = mode.separation * mode.lambda.im.abs();
                let first = FIRST_STEP_SHARE / block;
                let (st, _) = dop853::solve_from_within(
                    &flow,
                    &SLOW_TOLERANCES,
                    a,
                    temps,
                    b,
                    first,
                    &mut |step| ring.on_step(step),
                )?;
                if let Some(e) = ring.error.take() {
                    return Err(e);
                }
                if ring.refusal.is_some() {
                    refused = ring.refusal;
                    break;
                }
                stats.n_rhs += st.n_rhs;
                stats.n_rejected += st.n_rejected;
                slow_steps += ring.steps;
                check_budget(
                    stats.n_steps + stats.n_rejected + slow_steps + full_steps,
                    b,
                )?;
                ring_max = ring_max.max(ring.largest);
                growth += ring.growth;
                slow_time += b - a;
                let (m, md, z1) = (ring.manifold, ring.mode, ring.z);
                y = m.y + Vector4::from_fn(|i, _| (z1 * md.v[i]).re);
            }
            // A ringing that grows over the orbit carries this orbit's error, a fraction of the
            // ringing, into the next ones, grown with it: flutter goes to the full integration.
            if refused.is_none() && growth > 0.0 {
                refused = Some(Refusal::Growth);
            }
            if refused.is_some() {
                break refused;
            }
            let unvouched = unvouched(&obs.collector, ring_max, spec.model, full_until);
            if unvouched.none() {
                break None;
            }
            // Only a window's summaries, read on slow time: that window in full, from the
            // orbit's start (its state is this orbit's start), and slow time after it.
            let window_end = unvouched.windows_end(&obs.collector);
            if unvouched.orbit || full_until > orbit_start || window_end >= orbit_end {
                break Some(Refusal::Gate);
            }
            obs.collector.rewind(mark);
            y = y_start;
            full_until = window_end;
        };
        if let Some(reason) = refused {
            // This orbit in full, from its start; the next one tries slow time again.
            obs.collector.rewind(mark);
            check_budget(stats.n_steps + stats.n_rejected, orbit_start)?;
            // The orbit's breakpoints, as slow time cut it.
            let mut tabulated = Tabulated::new(&mut full);
            let mut orbit = WithCuts {
                system: &mut tabulated,
                cuts: &cuts,
            };
            let (st, y1) = solve(
                &mut orbit,
                &full_method,
                orbit_start,
                y_start,
                orbit_end,
                &mut obs,
            )?;
            if let Some(e) = obs.error.take() {
                return Err(e);
            }
            reason.count(&mut split);
            split.n_fallback_steps += st.n_steps;
            stats.n_rejected += st.n_rejected;
            split.t_fallback += st.t_end - orbit_start;
            stats.n_rhs += st.n_rhs;
            stats.n_steps += st.n_steps;
            stats.stopped = st.stopped;
            stats.t_end = st.t_end;
            y = y1;
            t = st.t_end;
            if st.stopped {
                break;
            }
            continue;
        }
        if full_until > orbit_start {
            split.n_refused_windows += 1;
        }
        split.n_slow_steps += slow_steps;
        split.n_fallback_steps += full_steps;
        split.t_slow += slow_time;
        split.t_fallback += (orbit_end - orbit_start) - slow_time;
        stats.n_steps += slow_steps + full_steps;
        t = orbit_end;
        stats.t_end = t;
    }
    Ok(Propagated {
        run: obs.collector.finish(stats, y),
        split,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::inputs::orbit::Orbit;
    use crate::inputs::panel::Panel;
    use crate::models::coupled::Coupling;
    use crate::runs::hybrid::HybridRun;
    use crate::runs::orbits::{
        run_orbits, start_state, OrbitRunRequest, OrbitSummary, SummaryOptions,
    };

    pub(crate) fn spec(panel: Panel, orbit: Orbit, model: HingeModel, n: u64) -> OrbitRunSpec {
        OrbitRunSpec {
            panel,
            orbit,
            model,
            coupling: Coupling::ProjectedArea,
            method: crate::numerics::integrate::Method::Dopri5(Tolerances::default()),
            t_start: 0.0,
            first_index: 0,
            n_orbits: n,
            options: SummaryOptions {
                window: 600.0,
                theta_limit: 0.5,
                stop_at_limit: true,
                steps_per_period: STEPS_PER_HINGE_PERIOD,
            },
        }
    }

    /// The largest error of `got` against `want` over every θ column, as a fraction of the
    /// accuracy gate (2 %, or 1e-6 rad below 5e-5 rad).
    fn gate(want: &[OrbitSummary], got: &[OrbitSummary]) -> f64 {
        assert_eq!(want.len(), got.len());
        let cols = |s: &OrbitSummary| {
            [
                s.theta_max,
                s.theta_min,
                s.amplitude,
                s.jitter_rms,
                s.jitter_peak,
                s.entry_theta_min,
                s.exit_theta_max,
                s.entry_peak,
                s.exit_peak,
            ]
        };
        let mut worst: f64 = 0.0;
        for (w, g) in want.iter().zip(got) {
            for (a, b) in cols(w).into_iter().zip(cols(g)) {
                assert_eq!(a.is_nan(), b.is_nan());
                if a.is_nan() {
                    continue;
                }
                let r = if a.abs() >= 5e-5 {
                    (b - a).abs() / (0.02 * a.abs())
                } else {
                    (b - a).abs() / 1e-6
                };
                worst = worst.max(r);
            }
        }
        worst
    }

    fn compare(panel: Panel, orbit: Orbit, model: HingeModel, n: u64) -> (f64, HybridRun) {
        let s = spec(panel, orbit, model, n);
        let y0 = start_state(&panel, &orbit, Coupling::ProjectedArea, 0.0).unwrap();
        let full = run_orbits(&OrbitRunRequest { spec: s, y0 }).unwrap();
        let slow = run_slow(&s, y0, &Cancel::new()).unwrap();
        (gate(&full.summaries, &slow.run.summaries), slow.split)
    }

    #[test]
    fn low_orbits_on_slow_time_hold_the_gate_of_the_full_integration() {
        let leo = Orbit::leo(540e3);
        let conical = Orbit {
            shadow: Shadow::Penumbra,
            ..leo
        };
        for (orbit, model) in [
            (leo, HingeModel::Nonlinear),
            (leo, HingeModel::Linear),
            (conical, HingeModel::Nonlinear),
        ] {
            let (worst, split) = compare(Panel::paper(), orbit, model, 4);
            assert!(
                worst < 0.5,
                "{model:?} {:?}: {worst} of the gate",
                orbit.shadow
            );
            assert_eq!(split.n_refused_orbits, 0);
            assert!(split.t_slow > 0.99 * 4.0 * orbit.period);
        }
    }

    #[test]
    fn a_fluttering_panel_is_given_back_to_the_full_integration() {
        // Half the critical damping: the ringing grows over each orbit. Slow time's error, a
        // fraction of the ringing, would grow with it into the later orbits (given back to the
        // full integration once the ringing passes its limit, from slow time's state): the
        // last orbit's exit_peak read 0.60 of the gate here, and a drawn light panel at 400 km
        // 1.71 x the gate (`test_a_fluttering_panel_on_a_low_orbit_holds_the_gate`). Every
        // orbit goes to the full integration from the first, each from the full integration's
        // state (the reference integrates the 8 orbits in one stretch: its steps across the
        // orbits' ends differ, 8e-4 of the gate).
        let panel = Panel {
            damping: 1.08,
            ..Panel::paper()
        };
        let (worst, split) = compare(panel, Orbit::leo(540e3), HingeModel::Nonlinear, 8);
        assert!(worst < 0.01, "{worst} of the gate");
        assert_eq!(split.n_refused_orbits, 8, "{split:?}");
        assert!(split.n_refused_growth > 0, "{split:?}");
    }

    /// ln(1 − δ) by its series is the logarithm's on drawn δ of every size up to and past the
    /// series' reach, to four roundings of |δ| (of 1 where the logarithm is taken).
    #[test]
    fn the_logarithm_near_one_is_the_logarithm() {
        let mut draw = crate::numerics::testing::uniform_draws(11);
        for _ in 0..20_000 {
            let size = 10f64.powf(-9.0 + 8.9 * draw());
            let angle = 2.0 * PI * draw();
            let delta = Complex::from_polar(size, angle);
            let got = ln_one_minus(delta);
            // ln(1 − δ) = ln|1 − δ| + i arg(1 − δ), |1 − δ|² − 1 taken without rounding 1 away.
            let kappa = Complex::new(1.0, 0.0) - delta;
            let excess = -2.0 * delta.re + delta.norm_sqr();
            let want = Complex::new(0.5 * excess.ln_1p(), kappa.im.atan2(kappa.re));
            let tol = 4.0 * f64::EPSILON * (size + if size > 1.0 / 16.0 { 1.0 } else { 0.0 });
            assert!((got - want).norm() <= tol, "{delta}: {got} vs {want}");
        }
    }

    /// The characteristic polynomial by principal minors is Faddeev–LeVerrier's on drawn
    /// Jacobians of the coupled panel's shape (θ row (0, 0, 0, 1)), and its roots are the
    /// eigenvalues.
    #[test]
    fn the_characteristic_polynomial_is_faddeev_leverriers() {
        let mut draw = crate::numerics::testing::uniform_draws(5);
        for _ in 0..2000 {
            let mut j = Matrix4::from_fn(|_, _| 10f64.powf(4.0 * draw() - 3.0) * (draw() - 0.5));
            for k in 0..4 {
                j[(2, k)] = if k == 3 { 1.0 } else { 0.0 };
            }
            let c3 = -j.trace();
            let m2 = j + Matrix4::identity() * c3;
            let c2 = -(j * m2).trace() / 2.0;
            let m3 = j * m2 + Matrix4::identity() * c2;
            let c1 = -(j * m3).trace() / 3.0;
            let m4 = j * m3 + Matrix4::identity() * c1;
            let c0 = -(j * m4).trace() / 4.0;
            let scale = j.abs().max().max(1.0);
            for (k, (got, want)) in characteristic(&j).iter().zip([c3, c2, c1, c0]).enumerate() {
                assert!(
                    (got - want).abs() <= 1e-12 * scale.powi(k as i32 + 1),
                    "c{}: {got} vs {want}",
                    3 - k
                );
            }
            let [c3, c2, c1, c0] = characteristic(&j);
            for e in j.complex_eigenvalues().iter() {
                let p = (((e + c3) * e + c2) * e + c1) * e + c0;
                assert!(p.norm() <= 1e-10 * scale.max(e.norm()).powi(4), "{p}");
            }
        }
    }

    #[test]
    fn the_hinge_eigenvalue_is_a_root_of_the_jacobian() {
        let panel = Panel::paper();
        let orbit = Orbit::leo(540e3);
        let s = spec(panel, orbit, HingeModel::Nonlinear, 1);
        let mut model = SlowModel::new(&s);
        model.enter(0.0, 100.0);
        let y = start_state(&panel, &orbit, Coupling::ProjectedArea, 0.0).unwrap();
        let m = model.manifold(&model.flow_loads(0.0), &Vector2::new(y[0], y[1]));
        let mode = model
            .mode(
                model.loads(0.0),
                &m.y,
                Complex::new(0.0, panel.natural_angular_frequency()),
            )
            .unwrap();
        let j = model.linear.jacobian_at_loads(model.loads(0.0), &m.y);
        let nearest = j
            .complex_eigenvalues()
            .iter()
            .map(|e| (e - mode.lambda).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-10 * mode.lambda.norm(), "{nearest}");
        // v and w are the right and left eigenvectors, w·v = 1.
        let jc = j.map(|x| Complex::new(x, 0.0));
        let v = nalgebra::Vector4::from(mode.v);
        let w = nalgebra::Vector4::from(mode.w);
        let scale = mode.lambda.norm();
        assert!((jc * v - v * mode.lambda).norm() < 1e-10 * scale);
        assert!((jc.transpose() * w - w * mode.lambda).norm() < 1e-10 * scale * w.norm());
        assert!((w.dot(&v) - Complex::new(1.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn the_split_gives_back_the_state() {
        let panel = Panel::paper();
        let orbit = Orbit::leo(540e3);
        let s = spec(panel, orbit, HingeModel::Nonlinear, 1);
        let mut model = SlowModel::new(&s);
        model.enter(1900.0, 3000.0); // in the umbra
        let mut y = start_state(&panel, &orbit, Coupling::ProjectedArea, 0.0).unwrap();
        y[2] += 0.004;
        y[3] -= 0.002;
        let guess = Complex::new(0.0, panel.natural_angular_frequency());
        let (m, mode, z) = model.split(1900.0, &y, guess).unwrap();
        let back = m.y + Vector4::from_fn(|i, _| (z * mode.v[i]).re);
        assert!((back - y).abs().max() < 1e-9, "{back} vs {y}");
        assert!(z.norm() > 1e-3);
    }

    #[test]
    fn the_manifold_velocity_is_the_rate_of_its_angle_along_the_flow() {
        // Just inside the umbra the temperatures fall fastest: θ̄' must be dθ̄/dt along the
        // thermal flow, read here by central differences of θ̄ over a trajectory integrated by
        // RK4 at a small step. Without the inertia's term I θ₀'''/K_el (ε² of θ₀') it is not.
        for hinge in [HingeModel::Linear, HingeModel::Nonlinear] {
            let panel = Panel {
                specific_heat: 450.0,
                ..Panel::paper()
            };
            let orbit = Orbit::leo(540e3);
            let mut model = SlowModel::new(&spec(panel, orbit, hinge, 1));
            model.enter(1900.0, 3000.0);
            let y = start_state(&panel, &orbit, Coupling::ProjectedArea, 0.0).unwrap();
            let flow = |t: f64, temps: &Vector2<f64>| model.theta0_rate(t, temps).1;
            let dt = 1e-3;
            let (mut t, mut temps) = (1900.0, Vector2::new(y[0], y[1]));
            let mut points = Vec::new();
            for n in 0..60_005 {
                if n >= 60_000 {
                    points.push((t, temps));
                }
                let k1 = flow(t, &temps);
                let k2 = flow(t + 0.5 * dt, &(temps + k1 * (0.5 * dt)));
                let k3 = flow(t + 0.5 * dt, &(temps + k2 * (0.5 * dt)));
                let k4 = flow(t + dt, &(temps + k3 * dt));
                temps += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
                t = 1900.0 + (n + 1) as f64 * dt;
            }
            let angle = |k: usize| {
                model
                    .manifold(&model.flow_loads(points[k].0), &points[k].1)
                    .y[2]
            };
            // The fourth-order central difference at the middle point (t = 1960.002).
            let d = (angle(0) - 8.0 * angle(1) + 8.0 * angle(3) - angle(4)) / (12.0 * dt);
            let (t_mid, temps_mid) = points[2];
            let m = model.manifold(&model.flow_loads(t_mid), &temps_mid);
            let rate = model.theta0_rate(t_mid, &temps_mid).0;
            // θ₀' − θ̄': the lag's rate, mostly the inertia's term.
            let lag_rate = (rate - m.y[3]).abs();
            assert!(
                lag_rate > 1e-3 * rate.abs(),
                "{hinge:?}: {lag_rate} vs {rate}"
            );
            assert!(
                (m.y[3] - d).abs() < 0.05 * lag_rate,
                "{hinge:?}: θ̄' {} vs dθ̄/dt {d} (the lag's rate {lag_rate})",
                m.y[3]
            );
        }
    }

    #[test]
    fn the_bounds_of_the_reads_are_their_polynomials_extremes() {
        // Drawn cubics and parabolas against a fine sampling: the closed forms are the extremes
        // (no larger: a bound that is too high only reads more; no smaller: it would skip one).
        let mut uniform = crate::numerics::testing::uniform_draws(12345);
        let mut draw = || uniform() * 2.0 - 1.0;
        for _ in 0..2000 {
            let (r0, r1, r2) = (draw(), draw(), draw());
            let value =
                |x: f64| r0 * (x + 1.0) + r1 * 0.5 * (x * x - 1.0) + r2 * (x * x * x + 1.0) / 3.0;
            let sampled = (0..=20_000)
                .map(|i| value(-1.0 + i as f64 / 10_000.0))
                .fold(f64::NEG_INFINITY, f64::max);
            let got = cubic_max(r0, r1, r2);
            assert!(
                got >= sampled - 1e-12 && got <= sampled + 1e-7,
                "{got} {sampled}"
            );
            let xs = [0.0, 0.5 + 0.5 * draw(), 2.0];
            let p = Newton::new(&xs, &[draw(), draw(), draw()]);
            let (a, b) = (0.3 * draw().abs(), 2.0 - 0.3 * draw().abs());
            let (lo, hi) = (0..=20_000)
                .map(|i| p.at(a + (b - a) * i as f64 / 20_000.0))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                    (l.min(v), h.max(v))
                });
            let (glo, ghi) = parabola_range(&p, a, b);
            // The sampling misses a vertex by up to c2 (spacing)²/4.
            let miss = 1e-8 * (1.0 + p.cs[2].abs());
            assert!(glo <= lo + 1e-12 && glo >= lo - miss, "{glo} {lo}");
            assert!(ghi >= hi - 1e-12 && ghi <= hi + miss, "{ghi} {hi}");
            assert_eq!(largest_magnitude(&p, a, b), ghi.max(-glo));
        }
    }

    #[test]
    fn a_peak_anywhere_in_a_short_span_is_read() {
        // Drawn ringings on a slow ramp over spans up to a period, their peaks anywhere (just
        // after the span's start, as the first trough of a ringing split there, or inside a
        // span shorter than the reads' spacing): the range that of a fine sampling.
        let mut draw = crate::numerics::testing::uniform_draws(777);
        let period = 6.4;
        let omega = 2.0 * PI / period;
        for _ in 0..2000 {
            let (amp, ramp, phi0) = (
                1e-3 * (0.1 + draw()),
                1e-4 * (draw() - 0.5),
                2.0 * PI * draw(),
            );
            let length = period * draw().powi(2);
            let decay = 1e-3 * draw();
            let slow = |t: f64| 0.01 + ramp * t;
            let amplitude = |t: f64| amp * (-decay * t).exp();
            let phase = |t: f64| phi0 + omega * t;
            let speed = |_: f64| omega;
            let wave = Wave {
                slow: &slow,
                amplitude: &amplitude,
                phase: &phase,
                speed: &speed,
                period,
            };
            let (a, b) = (10.0, 10.0 + length);
            let (lo, hi) = (0..=20_000)
                .map(|i| wave.value(a + (b - a) * i as f64 / 20_000.0))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                    (l.min(v), h.max(v))
                });
            let (glo, ghi) = wave.range(a, b);
            // The parabola's vertex within 1.5e-4 of the amplitude on these draws; the points
            // around a peak, unrefined where clipped at an end, read it up to 1.8 % low.
            let tol = 3e-4 * amp;
            assert!((glo - lo).abs() <= tol, "min {glo} {lo} over {length} s");
            assert!((ghi - hi).abs() <= tol, "max {ghi} {hi} over {length} s");
        }
    }

    #[test]
    fn the_frequency_shift_is_that_of_the_conservative_hinge() {
        // The period of I_B (1 + 3 sin²θ) θ̈ + 3 I_B θ̇² sin θ cos θ + K (θ − θc) = 0 from rest at
        // θc + A, by RK4 at a small step: the time to the next turning point, twice.
        let panel = Panel::paper();
        let s = spec(panel, Orbit::leo(540e3), HingeModel::Nonlinear, 1);
        let model = SlowModel::new(&s);
        let (i, k) = (panel.hinge_inertia(), panel.hinge_stiffness);
        let (centre, amp) = (0.085, 0.02);
        let accel = |th: f64, om: f64| {
            let (sn, cs) = th.sin_cos();
            (-k * (th - centre) - 3.0 * i * om * om * sn * cs) / (i * (1.0 + 3.0 * sn * sn))
        };
        let (mut th, mut om, mut t) = (centre + amp, 0.0_f64, 0.0);
        let dt = 1e-4;
        loop {
            let f = |th: f64, om: f64| (om, accel(th, om));
            let k1 = f(th, om);
            let k2 = f(th + 0.5 * dt * k1.0, om + 0.5 * dt * k1.1);
            let k3 = f(th + 0.5 * dt * k2.0, om + 0.5 * dt * k2.1);
            let k4 = f(th + dt * k3.0, om + dt * k3.1);
            let next = om + dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
            th += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            if om < 0.0 && next >= 0.0 {
                // The turning point by linear interpolation of θ̇ within the step.
                t += dt * (-om) / (next - om);
                break;
            }
            om = next;
            t += dt;
        }
        let measured = 2.0 * PI / (2.0 * t);
        let small = 2.0 * PI / (2.0 * PI * (i * (1.0 + 3.0 * centre.sin().powi(2)) / k).sqrt());
        let shift = model.frequency_shift(centre, amp);
        assert!(shift < 0.0);
        assert!(
            (small + shift - measured).abs() < 1e-3 * shift.abs(),
            "{} vs {measured}",
            small + shift
        );
    }
}
