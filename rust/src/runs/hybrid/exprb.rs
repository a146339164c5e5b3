//! The exponential Rosenbrock method exprb32 (Hochbruck, Ostermann & Schweitzer 2009) with error
//! control, for the stretches that need the non-linear model: shadow crossings and the thermal
//! recovery after them.
//!
//! Each step linearises the coupled system about the current state, u' = J u + v t + g(t, u), and
//! propagates the linear part exactly through φ-functions of hJ. The lightly damped hinge is part of
//! J, so its oscillation is carried without numerical dissipation and the step is set by the slow
//! non-linear remainder (T⁴ radiation, the cos θ projected area, the penumbra's s(t)), not by the
//! hinge period:
//!
//! ```text
//! U  = u + h φ1(hJ) f(t, u) + h² φ2(hJ) v
//! D  = g(t + h, U) − g(t, u)
//! u⁺ = U + 2h φ3(hJ) D          (third order; U is the embedded second-order solution)
//! ```

use super::expm::phi_matrices_and_half;
use super::model::HybridModel;
use crate::error::{Error, Result};
use nalgebra::{SMatrix, SVector};

/// Error-control settings of the exponential stretches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpTolerances {
    pub rtol: f64,
    /// Absolute tolerances of (T_f, T_b) in K and of (θ, θ̇) in rad and rad/s.
    pub atol_temperature: f64,
    pub atol_angle: f64,
    pub max_step: f64,
}

/// One accepted step: both ends and the slopes there (for Hermite interpolation).
#[derive(Debug, Clone, Copy)]
pub struct ExpStep<const N: usize> {
    pub t0: f64,
    pub t1: f64,
    pub y0: SVector<f64, N>,
    pub y1: SVector<f64, N>,
    pub f0: SVector<f64, N>,
    pub f1: SVector<f64, N>,
    /// The illumination factor at t0 and t1.
    pub flux0: f64,
    pub flux1: f64,
    /// The state at the step's middle by the step's own formula over half the step: a second
    /// evaluation, independent of the interpolant through the ends.
    pub y_mid: SVector<f64, N>,
    /// The Jacobian at the step's start and the time derivative of the forcing: with y0 and f0,
    /// what [`ExpStep::state_at`] evaluates the step's formula from.
    pub jac: SMatrix<f64, N, N>,
    pub v: SVector<f64, N>,
}

impl<const N: usize> ExpStep<N> {
    /// The state at t = t0 + τ by the step's own formula over τ (not the interpolant).
    pub(crate) fn state_at<M: HybridModel<N>>(&self, system: &M, t: f64) -> SVector<f64, N> {
        let tau = t - self.t0;
        let phi = super::expm::phi_matrices(&(self.jac * tau));
        advance(system, &phi, &self.jac, &self.v, &self.y0, &self.f0, t, tau).0
    }
}

/// The exprb32 formula over τ from (t0, y0) with slope f0, Jacobian `jac`, time derivative `v`
/// and φ_k(τ J) in `phi`: the state at t = t0 + τ, its correction (the error estimate) and the
/// flux there.
#[allow(clippy::too_many_arguments)]
fn advance<const N: usize, M: HybridModel<N>>(
    system: &M,
    phi: &[SMatrix<f64, N, N>; 4],
    jac: &SMatrix<f64, N, N>,
    v: &SVector<f64, N>,
    y0: &SVector<f64, N>,
    f0: &SVector<f64, N>,
    t: f64,
    tau: f64,
) -> (SVector<f64, N>, SVector<f64, N>, f64) {
    let [_, phi1, phi2, phi3] = phi;
    let du = phi1 * (f0 * tau) + phi2 * (v * (tau * tau));
    let u_mid = y0 + du;
    let flux = system.flux_at(t);
    let f_mid = system.rhs_at_flux(flux, &u_mid);
    // g(t0 + τ, U) − g(t0, u) with g(t, u) = f(t, u) − J u − v t.
    let d = f_mid - f0 - jac * du - v * tau;
    let corr = phi3 * (d * (2.0 * tau));
    (u_mid + corr, corr, flux)
}

/// ∂f/∂t through the illumination (s(t) in a penumbra, the Sun's distance) inside the segment
/// [a, b], by a one-sided difference that stays inside it; `flux` is the flux at t.
fn time_derivative<const N: usize, M: HybridModel<N>>(
    system: &M,
    t: f64,
    flux: f64,
    y: &SVector<f64, N>,
    a: f64,
    b: f64,
) -> SVector<f64, N> {
    let delta = 1e-2_f64.min(0.5 * (b - a));
    let dflux = if t + delta <= b {
        (system.flux_at(t + delta) - flux) / delta
    } else {
        (flux - system.flux_at((t - delta).max(a))) / delta
    };
    system.flux_sensitivity(flux, y) * dflux
}

/// Integrates the segment [a, b] (no breakpoint inside; the system has entered it) from (t, y),
/// t in [a, b), calling `on_step` after every accepted step; stops early when it returns true.
/// `h` carries the step size from segment to segment. Returns the number of (accepted,
/// rejected) steps.
#[allow(clippy::too_many_arguments)]
pub(crate) fn segment<const N: usize, M: HybridModel<N>>(
    system: &M,
    a: f64,
    b: f64,
    t: &mut f64,
    y: &mut SVector<f64, N>,
    h: &mut f64,
    tol: &ExpTolerances,
    mut on_step: impl FnMut(&ExpStep<N>) -> Result<bool>,
) -> Result<(u64, u64, bool)> {
    let (mut accepted, mut rejected) = (0u64, 0u64);
    // The flux at the step's start, carried from the end of the last one (s(t) is costly in a
    // penumbra).
    let mut flux = system.flux_at(*t);
    let mut f0 = system.rhs_at_flux(flux, y);
    while *t < b {
        let t0 = *t;
        let y0 = *y;
        let jac = system.jacobian(flux, &y0);
        let v = time_derivative(system, t0, flux, &y0, a, b);
        let mut rejected_here = false;
        loop {
            let step = h.min(tol.max_step).min(b - t0);
            let t1 = if t0 + step >= b { b } else { t0 + step };
            let hs = t1 - t0;
            if hs.is_nan() || hs <= 1e-9 * t0.abs().max(1.0) {
                return Err(Error::Integration {
                    t: t0,
                    reason: format!(
                        "the exponential integrator's step fell to {hs:e} s (state {:?})",
                        y0.as_slice()
                    ),
                });
            }
            let [phi, phi_half] = phi_matrices_and_half(&(jac * hs));
            let (y1, corr, flux1) = advance(system, &phi, &jac, &v, &y0, &f0, t1, hs);
            let mut acc = 0.0;
            for i in 0..N {
                let atol = if i < N - 2 {
                    tol.atol_temperature
                } else {
                    tol.atol_angle
                };
                let r = corr[i] / (atol + tol.rtol * y0[i].abs().max(y1[i].abs()));
                acc += r * r;
            }
            let err = (acc / N as f64).sqrt();
            if err <= 1.0 {
                let mut factor = if err == 0.0 {
                    5.0
                } else {
                    (0.9 * err.powf(-1.0 / 3.0)).min(5.0)
                };
                if rejected_here {
                    factor = factor.min(1.0);
                }
                // A step cut short by the segment's end does not shrink the next one.
                if t1 < b || hs >= *h {
                    *h = hs * factor;
                }
                let f1 = system.rhs_at_flux(flux1, &y1);
                let (y_mid, _, _) = advance(
                    system,
                    &phi_half,
                    &jac,
                    &v,
                    &y0,
                    &f0,
                    t0 + 0.5 * hs,
                    0.5 * hs,
                );
                let flux0 = flux;
                flux = flux1;
                accepted += 1;
                *t = t1;
                *y = y1;
                let stop = on_step(&ExpStep {
                    t0,
                    t1,
                    y0,
                    y1,
                    f0,
                    f1,
                    flux0,
                    flux1,
                    y_mid,
                    jac,
                    v,
                })?;
                f0 = f1;
                if stop {
                    return Ok((accepted, rejected, true));
                }
                break;
            }
            rejected += 1;
            rejected_here = true;
            *h = hs
                * if err.is_finite() {
                    (0.9 * err.powf(-1.0 / 3.0)).max(0.2)
                } else {
                    0.2
                };
        }
    }
    Ok((accepted, rejected, false))
}
