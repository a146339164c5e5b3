//! Linear stability of the distributed panel's sunlit equilibrium: its eigenvalues, the
//! oscillatory pairs and the critical damping ratio.

use crate::analysis::flutter::{balancing, critical_value, Spectrum};
use crate::error::Result;
use crate::models::distributed::DistributedPanel;
use nalgebra::{Complex, DMatrix};

use std::f64::consts::PI;

/// One oscillatory eigen-pair of the linearised distributed system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OscillatoryMode {
    /// Re λ, 1/s (> 0: grows).
    pub growth_rate: f64,
    /// Im λ / 2π, Hz.
    pub frequency_hz: f64,
    /// Index (0-based) of the kept structural mode nearest in frequency.
    pub structural_mode: usize,
}

/// Linear stability of the distributed panel's sunlit equilibrium.
#[derive(Debug, Clone)]
pub struct DistributedFlutter {
    /// The equilibrium state (temperatures, static modal coordinates, zero rates).
    pub equilibrium: Vec<f64>,
    /// θ_f at the equilibrium, rad.
    pub theta_f: f64,
    pub eigenvalues: Vec<Complex<f64>>,
    /// The oscillatory pairs (Im λ > 0), by ascending frequency.
    pub modes: Vec<OscillatoryMode>,
    /// Largest real part of all eigenvalues, 1/s.
    pub growth_rate: f64,
    /// ζ at which the largest growth rate crosses zero (0 when stable without damping).
    pub critical_damping_ratio: f64,
    /// The same as a hinge damping c_d, 2 I_B ω₁ ζ* (N m s/rad).
    pub critical_damping: f64,
}

impl DistributedPanel {
    /// Eigenvalues of the Jacobian `base` with the modal damping ratio set to `zeta` (only the
    /// q̇ diagonal depends on it; the equilibrium does not).
    fn spectrum(&self, base: &DMatrix<f64>, zeta: f64) -> Result<Vec<Complex<f64>>> {
        let (k, nt) = (self.k(), self.temps());
        let mut j = base.clone();
        for (i, w) in self.reduction.omega.iter().enumerate() {
            j[(nt + k + i, nt + k + i)] = -2.0 * zeta * w;
        }
        // Balanced first: the kelvin and modal-coordinate scales differ by orders of magnitude.
        Ok(Spectrum::of(&j, &balancing(&j))?.eigenvalues)
    }

    /// Linear stability of the sunlit equilibrium under illumination factor `flux` (1: full Sun
    /// at 1 au), with the critical damping ratio found by bisection.
    pub fn flutter(&self, flux: f64) -> Result<DistributedFlutter> {
        let y = self.equilibrium(flux)?;
        let base = self.jacobian(flux, &y);
        let ev = self.spectrum(&base, self.settings.damping_ratio)?;
        let omega = &self.reduction.omega;
        // The n thermal eigenvalues are real and nearly equal (one per element); rounding can
        // split such a cluster into pairs with Im λ around 1e-5 rad/s. A structural pair sits
        // near its ωᵢ, far above that.
        let floor = 1e-2 * omega[0];
        let mut modes: Vec<OscillatoryMode> = ev
            .iter()
            .filter(|z| z.im > floor)
            .map(|z| {
                let nearest = (0..omega.len())
                    .min_by(|&a, &b| (omega[a] - z.im).abs().total_cmp(&(omega[b] - z.im).abs()))
                    .unwrap_or(0);
                OscillatoryMode {
                    growth_rate: z.re,
                    frequency_hz: z.im / (2.0 * PI),
                    structural_mode: nearest,
                }
            })
            .collect();
        modes.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
        let growth = |zeta: f64| -> Result<f64> { Ok(self.spectrum(&base, zeta)?[0].re) };
        let zeta_star = critical_value(growth, self.settings.damping_ratio.max(1e-6), 1e-10)?;
        Ok(DistributedFlutter {
            theta_f: self.theta_f(&y, 0.0)?,
            equilibrium: y,
            growth_rate: ev[0].re,
            eigenvalues: ev,
            modes,
            critical_damping_ratio: zeta_star,
            critical_damping: crate::models::beam::hinge_equivalent_damping(&self.panel, zeta_star),
        })
    }
}
