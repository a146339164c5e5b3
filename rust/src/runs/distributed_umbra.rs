//! The distributed panel through the umbra, the thermal field integrated alone and the modes
//! propagated exactly.
//!
//! Without sunlight the elements' heat balances do not depend on the structure (the incidence
//! multiplies a zero flux): the temperatures obey T' = g(T) on their own, and the kept modes are
//! linear oscillators driven by the element moments, q̈ + 2ζω q̇ + ω² q = G M(T), M affine in T.
//! The temperatures are integrated by the run's adaptive method with its error control (steps on
//! the thermal time scales, not the modes' periods); over each step the forcing is a quartic in
//! the step's fraction θ (the integrator's continuous extension, exact for an affine functional),
//! and each mode's response to it is exact: the quartic particular solution plus the free
//! oscillation from the mode's state at the step's start.
//!
//! A functional w·y + c of the state (the tip rise, the rise of the static state, the tip
//! deflection) is then, inside a step, a quartic in θ plus Re(Σ α_k e^{λ_k τ}).

use crate::models::distributed::DistributedPanel;
use crate::numerics::integrate::{DenseStep, OdeSystem, State};
use crate::runs::distributed_arc::C64;
use crate::runs::distributed_orbits::Affine;
use nalgebra::{DVector, Dyn as D};

/// The temperatures alone in the umbra.
pub(crate) struct ShadowedThermal<'a> {
    pub model: &'a DistributedPanel,
}

impl OdeSystem<D> for ShadowedThermal<'_> {
    fn rhs(&self, _t: f64, y: &State<D>) -> State<D> {
        let mut dy = DVector::zeros(y.len());
        self.model.rates_in_shadow(y.as_slice(), dy.as_mut_slice());
        dy
    }
}

/// A functional of the state split as the umbra propagates it: its weights on the
/// temperatures, on q and on q̇, and its constant.
#[derive(Debug, Clone)]
struct Split {
    temps: Vec<f64>,
    q: Vec<f64>,
    v: Vec<f64>,
    c: f64,
}

impl Split {
    fn of(f: &Affine, nt: usize, k: usize) -> Split {
        let w = f.w.as_slice();
        Split {
            temps: w[..nt].to_vec(),
            q: w[nt..nt + k].to_vec(),
            v: w[nt + k..nt + 2 * k].to_vec(),
            c: f.c,
        }
    }
}

/// What the umbra's propagation needs of the model, built once per run.
#[derive(Debug, Clone)]
pub(crate) struct Umbra {
    omega: Vec<f64>,
    zeta: f64,
    lambda: Vec<C64>,
    /// Each mode's forcing G M(T) as a functional of the temperatures.
    forcing: Vec<Split>,
    /// The functionals read: the tip rise, the static state's rise, the tip deflection.
    reads: [Split; 3],
    /// The reads miss no extreme of a read functional or of the dynamic part (the rise less
    /// the static state's) by more than `read_rtol` of its modes' amplitudes plus `read_floor`.
    read_rtol: f64,
    read_floor: f64,
}

impl Umbra {
    /// `reads`: the tip rise, the static state's rise and the tip deflection; `read_rtol` and
    /// `read_floor`: what the reads may miss of an extreme (see [`UmbraStep::spacing`]).
    pub fn new(
        model: &DistributedPanel,
        reads: [&Affine; 3],
        read_rtol: f64,
        read_floor: f64,
    ) -> Umbra {
        let (nt, k, n) = (model.temps(), model.k(), model.n());
        let r = &model.reduction;
        let zeta = model.settings.damping_ratio;
        let omega: Vec<f64> = (0..k).map(|i| r.omega[i]).collect();
        let lambda = omega
            .iter()
            .map(|w| C64::new(-zeta * w, w * (1.0 - zeta * zeta).sqrt()))
            .collect();
        let forcing = (0..k)
            .map(|i| {
                let row: Vec<f64> = (0..n).map(|e| r.force[(i, e)]).collect();
                Split::of(&Affine::of(model, &vec![0.0; k], &row), nt, k)
            })
            .collect();
        Umbra {
            omega,
            zeta,
            lambda,
            forcing,
            reads: reads.map(|f| Split::of(f, nt, k)),
            read_rtol,
            read_floor,
        }
    }
}

/// The monomial coefficients in θ of the continuous extension's form
/// a + θ(b + (1 − θ)(c + θ(d + (1 − θ) e))).
fn monomial([a, b, c, d, e]: [f64; 5]) -> [f64; 5] {
    [a, b + c, d + e - c, -(d + 2.0 * e), e]
}

/// p(θ) = Σ p_k θ^k.
#[inline]
fn horner(p: &[f64; 5], th: f64) -> f64 {
    p[0] + th * (p[1] + th * (p[2] + th * (p[3] + th * p[4])))
}

/// dp/dθ.
fn derivative(p: &[f64; 5]) -> [f64; 5] {
    [p[1], 2.0 * p[2], 3.0 * p[3], 4.0 * p[4], 0.0]
}

/// One step of the thermal integration with the modes' exact response over it.
pub(crate) struct UmbraStep {
    pub t0: f64,
    pub h: f64,
    /// Each read functional's smooth part (a quartic in θ) and its modes' amplitudes α_k.
    smooth: [[f64; 5]; 3],
    amps: [Vec<C64>; 3],
    /// Each mode's particular solution (a quartic in θ) and its free part's C_k.
    particular: Vec<[f64; 5]>,
    free: Vec<C64>,
    lambda: Vec<C64>,
}

impl UmbraStep {
    /// The step `step` of the temperatures, the modes at its start (q, q̇).
    pub fn new(u: &Umbra, step: &DenseStep<D>, q: &[f64], v: &[f64]) -> UmbraStep {
        let h = step.t1 - step.t0;
        let k = u.omega.len();
        let mut particular = Vec::with_capacity(k);
        let mut free = Vec::with_capacity(k);
        for i in 0..k {
            let f = &u.forcing[i];
            let mut force = monomial(step.coefficients_along(&f.temps));
            force[0] += f.c;
            // (1/h²) p'' + (2ζω/h) p' + ω² p = F, coefficient by coefficient from θ⁴ down.
            let (w, damp) = (u.omega[i], 2.0 * u.zeta * u.omega[i]);
            let mut p = [0.0; 7];
            for m in (0..5).rev() {
                let (m1, m2) = (m as f64 + 1.0, m as f64 + 2.0);
                p[m] =
                    (force[m] - m2 * m1 * p[m + 2] / (h * h) - damp * m1 * p[m + 1] / h) / (w * w);
            }
            let p = [p[0], p[1], p[2], p[3], p[4]];
            // The free oscillation Re(C e^{λτ}) from what the particular solution leaves.
            let (u0, du0) = (q[i] - p[0], v[i] - p[1] / h);
            let l = u.lambda[i];
            free.push(C64::new(u0, (l.re * u0 - du0) / l.im));
            particular.push(p);
        }
        let mut smooth = [[0.0; 5]; 3];
        let mut amps: [Vec<C64>; 3] = Default::default();
        for (j, f) in u.reads.iter().enumerate() {
            let mut s = monomial(step.coefficients_along(&f.temps));
            s[0] += f.c;
            for ((p, wq), wv) in particular.iter().zip(&f.q).zip(&f.v) {
                for (m, dp) in derivative(p).iter().enumerate() {
                    s[m] += wq * p[m] + wv * dp / h;
                }
            }
            smooth[j] = s;
            amps[j] = (0..k)
                .map(|i| (f.q[i] + f.v[i] * u.lambda[i]) * free[i])
                .collect();
        }
        UmbraStep {
            t0: step.t0,
            h,
            smooth,
            amps,
            particular,
            free,
            lambda: u.lambda.clone(),
        }
    }

    /// The largest spacing of the reads in this step: an extreme of a signal s between two reads
    /// Δ apart is missed by at most max|s''| Δ²/8, max|s''| bounded by its smooth part's
    /// coefficients and its modes' amplitudes |α_k| |λ_k|²; that is kept within `read_rtol` of
    /// Σ|α_k| plus `read_floor`, for each read functional and the dynamic part.
    pub fn spacing(&self, u: &Umbra) -> f64 {
        let dynamic = (
            std::array::from_fn(|m| self.smooth[0][m] - self.smooth[1][m]),
            self.amps[0]
                .iter()
                .zip(&self.amps[1])
                .map(|(a, b)| a - b)
                .collect::<Vec<C64>>(),
        );
        let signals = [
            (&self.smooth[0], &self.amps[0]),
            (&self.smooth[2], &self.amps[2]),
            (&dynamic.0, &dynamic.1),
        ];
        let h2 = self.h * self.h;
        signals
            .iter()
            .map(|(smooth, amps)| {
                let curvature: f64 = (2..5)
                    .map(|m| (m * (m - 1)) as f64 * smooth[m].abs() / h2)
                    .sum::<f64>()
                    + amps
                        .iter()
                        .zip(&self.lambda)
                        .map(|(a, l)| a.norm() * l.norm_sqr())
                        .sum::<f64>();
                let size: f64 = amps.iter().map(|a| a.norm()).sum();
                let tol = u.read_rtol * size + u.read_floor;
                if curvature > 0.0 {
                    (8.0 * tol / curvature).sqrt()
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The read functionals at the times t_first + j Δ (j = 0 .. count), each handed to `read`
    /// with its time; stops early when `read` returns false. Returns how many were read.
    pub fn read_uniform(
        &self,
        t_first: f64,
        spacing: f64,
        count: usize,
        mut read: impl FnMut(usize, [f64; 3]) -> bool,
    ) -> usize {
        let tau = t_first - self.t0;
        let mut terms: Vec<C64> = self.lambda.iter().map(|l| (l * tau).exp()).collect();
        let factors: Vec<C64> = self.lambda.iter().map(|l| (l * spacing).exp()).collect();
        for j in 0..count {
            let th = (tau + j as f64 * spacing) / self.h;
            let values = std::array::from_fn(|f| {
                let mut v = horner(&self.smooth[f], th);
                for (a, z) in self.amps[f].iter().zip(&terms) {
                    v += (a * z).re;
                }
                v
            });
            if !read(j, values) {
                return j + 1;
            }
            for (z, f) in terms.iter_mut().zip(&factors) {
                *z *= f;
            }
        }
        count
    }

    /// The modes (q, q̇) at t inside the step.
    pub fn modes_at(&self, t: f64) -> (Vec<f64>, Vec<f64>) {
        let tau = t - self.t0;
        let th = tau / self.h;
        self.particular
            .iter()
            .zip(&self.free)
            .zip(&self.lambda)
            .map(|((p, c), l)| {
                let z = c * (l * tau).exp();
                (
                    horner(p, th) + z.re,
                    horner(&derivative(p), th) / self.h + (l * z).re,
                )
            })
            .unzip()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::panel::Panel;
    use crate::models::distributed::Settings;
    use crate::numerics::integrate::{solve, Method, Observer, Tolerances};
    use crate::runs::distributed_orbits::Readers;
    use std::ops::ControlFlow;

    /// The whole model without sunlight, the truth the umbra's split is checked against.
    struct Dark<'a>(&'a DistributedPanel);

    impl OdeSystem<D> for Dark<'_> {
        fn rhs(&self, _t: f64, y: &State<D>) -> State<D> {
            let mut dy = DVector::zeros(y.len());
            self.0.rhs_at_flux(0.0, y.as_slice(), dy.as_mut_slice());
            dy
        }
    }

    /// The full state at `probe` of a run.
    struct Probe {
        t: f64,
        y: Option<DVector<f64>>,
    }

    impl Observer<D> for Probe {
        fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()> {
            if step.t0 < self.t && self.t <= step.t1 {
                self.y = Some(step.eval(self.t));
            }
            ControlFlow::Continue(())
        }
    }

    /// The modes carried over the temperatures' steps, and the read functionals at `probe`.
    struct Carry<'a> {
        umbra: &'a Umbra,
        q: Vec<f64>,
        v: Vec<f64>,
        probe: f64,
        read: Option<[f64; 3]>,
    }

    impl Observer<D> for Carry<'_> {
        fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()> {
            let s = UmbraStep::new(self.umbra, step, &self.q, &self.v);
            if step.t0 < self.probe && self.probe <= step.t1 {
                s.read_uniform(self.probe, 1.0, 1, |_, values| {
                    self.read = Some(values);
                    true
                });
            }
            (self.q, self.v) = s.modes_at(step.t1);
            ControlFlow::Continue(())
        }
    }

    fn tight(rtol: f64) -> Method {
        Method::Dopri5(Tolerances {
            rtol,
            atol: rtol * 1e-2,
            ..Tolerances::default()
        })
    }

    #[test]
    fn the_umbra_split_is_the_whole_model_without_sunlight() {
        // The shadow entered from the sunlit equilibrium with every mode ringing (ζ = 1e-3).
        let panel = Panel::paper();
        let settings = Settings {
            elements: 6,
            modes: 3,
            damping_ratio: 1e-3,
            ..Settings::new(&panel)
        };
        let model = DistributedPanel::new(&panel, settings).unwrap();
        let (nt, k) = (model.temps(), model.k());
        let mut y0 = model.equilibrium(1.0).unwrap();
        for i in 0..k {
            y0[nt + i] *= 1.0 + 0.3 / (i + 1) as f64;
            y0[nt + k + i] = 0.1 * y0[nt + i] * model.reduction.omega[i];
        }
        let (end, probe) = (900.0, 437.3);
        let mut truth = Probe { t: probe, y: None };
        let (_, full) = solve(
            &mut Dark(&model),
            &tight(1e-12),
            0.0,
            DVector::from_vec(y0.clone()),
            end,
            &mut truth,
        )
        .unwrap();
        let readers = Readers::of(&model);
        let umbra = Umbra::new(
            &model,
            [&readers.rise, &readers.rise_static, &readers.tip],
            4e-4,
            0.0,
        );
        let mut carry = Carry {
            umbra: &umbra,
            q: y0[nt..nt + k].to_vec(),
            v: y0[nt + k..].to_vec(),
            probe,
            read: None,
        };
        let (stats, temps) = solve(
            &mut ShadowedThermal { model: &model },
            &tight(1e-10),
            0.0,
            DVector::from_column_slice(&y0[..nt]),
            end,
            &mut carry,
        )
        .unwrap();
        // Steps on the thermal time scale, not the modes' periods (T₁ about 7 s).
        assert!(stats.n_steps < 200, "{} steps", stats.n_steps);
        for i in 0..nt {
            assert!(
                (temps[i] - full[i]).abs() < 1e-8 * full[i],
                "T[{i}]: {} vs {}",
                temps[i],
                full[i]
            );
        }
        let qmax = (0..k).fold(0.0f64, |a, i| a.max(full[nt + i].abs()));
        for i in 0..k {
            let w = model.reduction.omega[i];
            assert!((carry.q[i] - full[nt + i]).abs() < 1e-7 * qmax, "q[{i}]");
            assert!(
                (carry.v[i] - full[nt + k + i]).abs() < 1e-7 * qmax * w,
                "v[{i}]"
            );
        }
        // The read functionals inside a step: the tip rise, the static rise, the tip.
        let y = truth.y.unwrap();
        let read = carry.read.unwrap();
        for (value, f) in read
            .iter()
            .zip([&readers.rise, &readers.rise_static, &readers.tip])
        {
            let exact = f.at(y.as_slice());
            assert!(
                (value - exact).abs() < 1e-7 * exact.abs().max(readers.arm * 1e-3),
                "{value} vs {exact}"
            );
        }
    }
}
