//! The distributed panel: a finite-element Euler–Bernoulli panel whose every element carries its
//! own two-layer thermal state, absorbs sunlight at its own incidence and bends under its own
//! thermal moment — the continuous counterpart of the hinge model, two-way coupled the same way.
//!
//! Element e (chord slope ρ_e = (w_{e+1} − w_e)/h, see [`structure`]) has the heat balance of
//! eq. 2 with the absorbed flux factor s(t) · (flux scale) · cos(ψ + atan ρ_e): ψ is the Sun's
//! angle to the undeformed front normal (the rigid attitude; 0 for the Sun-pointing panel) and
//! atan ρ_e the elastic rotation of the element's chord, so the Sun sees each element at its own
//! angle. Its thermal moment M_e = a E I (T_f − T_b)/d (the physical rigidity: the hinge model's χ
//! is a calibration of the hinge, not of the panel) loads the structure as consistent nodal loads.
//! With the coupling frozen the factor is cos ψ for every element.
//!
//! The structure is reduced to its first k elastic modes q (state), the others quasi-static:
//! w = Φ q + R M. The state is y = (T_f[0..n], T_b[0..n], q[0..k], q̇[0..k]) and the modal
//! equations are q̈ᵢ + 2ζωᵢ q̇ᵢ + ωᵢ² qᵢ = Σ_e Gᵢₑ M_e.
//!
//! Not modelled: conduction along the panel (as in the paper's model; the incidence varies by a
//! few degrees along it) and the rigid-body attitude dynamics of a free panel, whose attitude the
//! spacecraft holds (the rigid modes receive no thermal load).

pub mod run;
pub mod structure;

use crate::dynamics::thermal_moment;
use crate::error::{require_finite, require_non_negative, Error, Result};
use crate::params::Panel;
use crate::steady::equilibrium;
use crate::system::Coupling;
use crate::thermal::two_layer_rates;
use crate::STEFAN_BOLTZMANN;
use nalgebra::{Complex, DMatrix, DVector};
use std::f64::consts::{FRAC_PI_2, PI};
pub use structure::{Mesh, Reduction, Support, CANTILEVER_BETA1_L, MAX_ELEMENTS};

/// Default number of elements (the convergence study in the module tests and docs/distributed.md).
pub const DEFAULT_ELEMENTS: usize = 40;
/// Default number of elastic modes integrated (the others quasi-static).
pub const DEFAULT_MODES: usize = 4;

/// What the distributed model is built from, besides the panel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    pub support: Support,
    pub elements: usize,
    pub modes: usize,
    /// ζ of every kept mode.
    pub damping_ratio: f64,
    /// ψ, the Sun's angle to the undeformed front normal, rad, |ψ| < π/2.
    pub sun_angle: f64,
    pub coupling: Coupling,
}

impl Settings {
    /// Defaults for `panel`: free–free, [`DEFAULT_ELEMENTS`], [`DEFAULT_MODES`], the
    /// hinge-equivalent damping ratio of the panel's c_d, Sun on the normal, two-way coupled.
    pub fn new(panel: &Panel) -> Self {
        Settings {
            support: Support::FreeFree,
            elements: DEFAULT_ELEMENTS,
            modes: DEFAULT_MODES,
            damping_ratio: crate::beam::hinge_equivalent_damping_ratio(panel),
            sun_angle: 0.0,
            coupling: Coupling::ProjectedArea,
        }
    }

    pub fn validate(&self) -> Result<()> {
        require_non_negative("damping_ratio", self.damping_ratio)?;
        require_finite("sun_angle", self.sun_angle)?;
        if self.sun_angle.abs() >= FRAC_PI_2 {
            return Err(Error::invalid(
                "sun_angle",
                self.sun_angle,
                "must be within (−π/2, π/2) rad: the front face must see the Sun",
            ));
        }
        Ok(())
    }
}

/// The coupled distributed model: panel, settings and the modal reduction.
#[derive(Debug, Clone)]
pub struct DistributedPanel {
    pub panel: Panel,
    pub settings: Settings,
    pub reduction: Reduction,
    /// The panel with χ = 1: the physical thermal moment.
    physical: Panel,
}

/// Absorbed-area factor of an element: cos(ψ + atan ρ), zero once the Sun is behind the front.
#[inline]
fn incidence(sun_angle: f64, slope: f64) -> f64 {
    (sun_angle + slope.atan()).cos().max(0.0)
}

/// d incidence / d ρ.
#[inline]
fn incidence_slope(sun_angle: f64, slope: f64) -> f64 {
    let a = sun_angle + slope.atan();
    if a.cos() <= 0.0 {
        0.0
    } else {
        -a.sin() / (1.0 + slope * slope)
    }
}

impl DistributedPanel {
    pub fn new(panel: &Panel, settings: Settings) -> Result<Self> {
        settings.validate()?;
        let mesh = Mesh::new(panel, settings.support, settings.elements)?;
        let reduction = Reduction::new(mesh, settings.modes)?;
        Ok(DistributedPanel {
            panel: *panel,
            settings,
            reduction,
            physical: Panel {
                moment_scale: 1.0,
                ..*panel
            },
        })
    }

    /// Number of elements.
    pub fn n(&self) -> usize {
        self.settings.elements
    }

    /// Number of kept modes.
    pub fn k(&self) -> usize {
        self.settings.modes
    }

    /// State size 2n + 2k.
    pub fn state_size(&self) -> usize {
        2 * (self.n() + self.k())
    }

    /// Thermal moment of one element, N m.
    #[inline]
    pub fn element_moment(&self, t_front: f64, t_back: f64) -> f64 {
        thermal_moment(&self.physical, t_front, t_back)
    }

    /// Element moments from the state.
    pub fn moments(&self, y: &[f64]) -> Vec<f64> {
        let n = self.n();
        (0..n)
            .map(|e| self.element_moment(y[e], y[n + e]))
            .collect()
    }

    /// Per-element chord slopes ρ = D Φ q + D R M.
    fn slopes(&self, q: &[f64], moments: &[f64]) -> DVector<f64> {
        let r = &self.reduction;
        let mut rho = &r.slope_residual * DVector::from_column_slice(moments);
        rho.gemv(1.0, &r.slope_modal, &DVector::from_column_slice(q), 1.0);
        rho
    }

    /// Absorbed-area factor of each element for chord slopes `rho`.
    fn areas(&self, rho: &[f64]) -> Vec<f64> {
        let psi = self.settings.sun_angle;
        match self.settings.coupling {
            Coupling::ProjectedArea => rho.iter().map(|r| incidence(psi, *r)).collect(),
            Coupling::Frozen => vec![psi.cos(); rho.len()],
        }
    }

    /// The right-hand side under illumination factor `flux` (s × flux scale).
    pub fn rhs_at_flux(&self, flux: f64, y: &[f64], dy: &mut [f64]) {
        let (n, k) = (self.n(), self.k());
        let r = &self.reduction;
        let moments = self.moments(y);
        let q = &y[2 * n..2 * n + k];
        let v = &y[2 * n + k..];
        let areas = match self.settings.coupling {
            Coupling::ProjectedArea => self.areas(self.slopes(q, &moments).as_slice()),
            Coupling::Frozen => self.areas(&vec![0.0; n]),
        };
        for e in 0..n {
            let (df, db) = two_layer_rates(&self.panel, flux * areas[e], y[e], y[n + e]);
            dy[e] = df;
            dy[n + e] = db;
        }
        let force = &r.force * DVector::from_column_slice(&moments);
        let zeta = self.settings.damping_ratio;
        for i in 0..k {
            let w = r.omega[i];
            dy[2 * n + i] = v[i];
            dy[2 * n + k + i] = force[i] - 2.0 * zeta * w * v[i] - w * w * q[i];
        }
    }

    /// The modal coordinates in static equilibrium with the element moments: q = G M / ω².
    pub fn static_modal(&self, moments: &[f64]) -> Vec<f64> {
        let r = &self.reduction;
        (0..self.k())
            .map(|i| {
                let f: f64 = moments
                    .iter()
                    .enumerate()
                    .map(|(e, m)| r.force[(i, e)] * m)
                    .sum();
                f / (r.omega[i] * r.omega[i])
            })
            .collect()
    }

    /// The full state at rest in static equilibrium with the given temperatures.
    pub fn static_state(&self, t_front: &[f64], t_back: &[f64]) -> Vec<f64> {
        let moments: Vec<f64> = t_front
            .iter()
            .zip(t_back)
            .map(|(f, b)| self.element_moment(*f, *b))
            .collect();
        let mut y = Vec::with_capacity(self.state_size());
        y.extend_from_slice(t_front);
        y.extend_from_slice(t_back);
        y.extend(self.static_modal(&moments));
        y.extend(std::iter::repeat_n(0.0, self.k()));
        y
    }

    /// θ_f of a state, rad.
    pub fn theta_f(&self, y: &[f64], t: f64) -> Result<f64> {
        let n = self.n();
        let moments = self.moments(y);
        let rise = self.reduction.rise(&y[2 * n..2 * n + self.k()], &moments);
        self.reduction.theta_f(rise, t)
    }

    /// Nodal deflections and slopes of a state.
    pub fn nodal(&self, y: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = self.n();
        let w = self
            .reduction
            .deflection(&y[2 * n..2 * n + self.k()], &self.moments(y));
        self.reduction.nodal(&w)
    }

    /// Sunlit equilibrium under illumination factor `flux`: Newton on the 2n heat balances with
    /// the structure in its static shape (exact whatever the number of kept modes).
    pub fn equilibrium(&self, flux: f64) -> Result<Vec<f64>> {
        if !(flux.is_finite() && flux > 0.0) {
            return Err(Error::invalid("flux", flux, "must be finite and > 0"));
        }
        let n = self.n();
        let p = &self.panel;
        let psi = self.settings.sun_angle;
        let coupled = self.settings.coupling == Coupling::ProjectedArea;
        let hc = 0.5 * p.heat_capacity();
        let mu = self.element_moment(1.0, 0.0);
        let absorbed = p.absorptivity * p.solar_constant * flux;
        // Start from the uniform panel at the rigid incidence (the frozen hinge's temperatures).
        let start = equilibrium(p, Coupling::Frozen, flux * psi.cos())?;
        let mut x = DVector::from_fn(
            2 * n,
            |i, _| {
                if i < n {
                    start.t_front
                } else {
                    start.t_back
                }
            },
        );
        let fs = &self.reduction.slope_static;
        for _ in 0..100 {
            let moments: Vec<f64> = (0..n).map(|e| mu * (x[e] - x[n + e])).collect();
            let rho: Vec<f64> = if coupled {
                (0..n)
                    .map(|e| (0..n).map(|j| fs[(e, j)] * moments[j]).sum())
                    .collect()
            } else {
                vec![0.0; n]
            };
            let areas = self.areas(&rho);
            let mut f = DVector::zeros(2 * n);
            let mut jac = DMatrix::zeros(2 * n, 2 * n);
            for e in 0..n {
                let (tf, tb) = (x[e], x[n + e]);
                let (df, db) = two_layer_rates(p, flux * areas[e], tf, tb);
                // Residuals in W/m².
                f[e] = df * hc;
                f[n + e] = db * hc;
                let (jff, jfb, jbf, jbb) = layer_partials(p, tf, tb);
                jac[(e, e)] += jff;
                jac[(e, n + e)] += jfb;
                jac[(n + e, e)] += jbf;
                jac[(n + e, n + e)] += jbb;
                if coupled {
                    let g = absorbed * incidence_slope(psi, rho[e]) * mu;
                    for j in 0..n {
                        jac[(e, j)] += g * fs[(e, j)];
                        jac[(e, n + j)] -= g * fs[(e, j)];
                    }
                }
            }
            let dx = jac.lu().solve(&(-&f)).ok_or_else(|| Error::NoConvergence {
                what: "distributed steady state".into(),
                reason: "singular Jacobian".into(),
            })?;
            let mut lambda = 1.0;
            while (0..2 * n).any(|i| x[i] + lambda * dx[i] <= 0.0) {
                lambda *= 0.5;
            }
            x += &dx * lambda;
            if (0..2 * n).all(|i| dx[i].abs() < 1e-12 * x[i]) {
                let y = self.static_state(&x.as_slice()[..n], &x.as_slice()[n..]);
                let rise = self
                    .reduction
                    .rise(&y[2 * n..2 * n + self.k()], &self.moments(&y));
                self.reduction
                    .theta_f(rise, 0.0)
                    .map_err(|_| Error::NoConvergence {
                        what: "distributed steady state".into(),
                        reason: "the tip rise exceeds the arm: the panel is far too soft".into(),
                    })?;
                return Ok(y);
            }
        }
        Err(Error::NoConvergence {
            what: "distributed steady state".into(),
            reason: "Newton did not converge in 100 iterations".into(),
        })
    }

    /// ∂f/∂y of the right-hand side at state `y` under illumination factor `flux`.
    pub fn jacobian(&self, flux: f64, y: &[f64]) -> DMatrix<f64> {
        let (n, k) = (self.n(), self.k());
        let p = &self.panel;
        let r = &self.reduction;
        let hc = 0.5 * p.heat_capacity();
        let mu = self.element_moment(1.0, 0.0);
        let psi = self.settings.sun_angle;
        let moments = self.moments(y);
        let q = &y[2 * n..2 * n + k];
        let mut j = DMatrix::zeros(2 * n + 2 * k, 2 * n + 2 * k);
        let rho = self.slopes(q, &moments);
        let absorbed = p.absorptivity * p.solar_constant * flux;
        for e in 0..n {
            let (jff, jfb, jbf, jbb) = layer_partials(p, y[e], y[n + e]);
            j[(e, e)] += jff / hc;
            j[(e, n + e)] += jfb / hc;
            j[(n + e, e)] += jbf / hc;
            j[(n + e, n + e)] += jbb / hc;
            if self.settings.coupling == Coupling::ProjectedArea {
                // Heating through the chord slope, which moves with every moment and mode.
                let g = absorbed * incidence_slope(psi, rho[e]) / hc;
                for m in 0..n {
                    j[(e, m)] += g * r.slope_residual[(e, m)] * mu;
                    j[(e, n + m)] -= g * r.slope_residual[(e, m)] * mu;
                }
                for i in 0..k {
                    j[(e, 2 * n + i)] += g * r.slope_modal[(e, i)];
                }
            }
        }
        let zeta = self.settings.damping_ratio;
        for i in 0..k {
            let w = r.omega[i];
            j[(2 * n + i, 2 * n + k + i)] = 1.0;
            for e in 0..n {
                j[(2 * n + k + i, e)] = r.force[(i, e)] * mu;
                j[(2 * n + k + i, n + e)] = -r.force[(i, e)] * mu;
            }
            j[(2 * n + k + i, 2 * n + i)] = -w * w;
            j[(2 * n + k + i, 2 * n + k + i)] = -2.0 * zeta * w;
        }
        j
    }
}

/// Partial derivatives of the two heat balances of eq. 2 (W/m² per K) with respect to (T_f, T_b)
/// at fixed absorbed flux: (∂f/∂T_f, ∂f/∂T_b, ∂b/∂T_f, ∂b/∂T_b).
fn layer_partials(p: &Panel, tf: f64, tb: f64) -> (f64, f64, f64, f64) {
    let k = p.conductance;
    let rf = 4.0 * STEFAN_BOLTZMANN * p.emissivity_front * tf * tf * tf;
    let rb = 4.0 * STEFAN_BOLTZMANN * p.emissivity_back * tb * tb * tb;
    (-k - rf, k, k, -k - rb)
}

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

/// Eigenvalues of a real matrix, after a diagonal balancing (a similarity, so the eigenvalues
/// are unchanged) that evens out the kelvin and modal-coordinate scales.
fn eigenvalues(j: &DMatrix<f64>) -> Result<Vec<Complex<f64>>> {
    let n = j.nrows();
    let mut a = j.clone();
    // Parlett–Reinsch: scale row and column i by powers of two until their norms match.
    for _ in 0..100 {
        let mut done = true;
        for i in 0..n {
            let c: f64 = (0..n).filter(|&r| r != i).map(|r| a[(r, i)].abs()).sum();
            let r: f64 = (0..n).filter(|&c| c != i).map(|c| a[(i, c)].abs()).sum();
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let mut f = 1.0;
            let (mut cc, mut rr) = (c, r);
            while cc < rr / 2.0 {
                cc *= 2.0;
                rr /= 2.0;
                f *= 2.0;
            }
            while cc > rr * 2.0 {
                cc /= 2.0;
                rr *= 2.0;
                f /= 2.0;
            }
            if (cc + rr) < 0.95 * (c + r) {
                done = false;
                for k in 0..n {
                    a[(i, k)] /= f;
                    a[(k, i)] *= f;
                }
            }
        }
        if done {
            break;
        }
    }
    let ev = a.complex_eigenvalues();
    if ev.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()) {
        return Err(Error::NoConvergence {
            what: "eigenvalues".into(),
            reason: "non-finite result".into(),
        });
    }
    let mut v: Vec<Complex<f64>> = ev.iter().copied().collect();
    v.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
    Ok(v)
}

impl DistributedPanel {
    /// Eigen-analysis at the equilibrium `y_eq` under `flux`, with the modal damping ratio `zeta`.
    fn spectrum(&self, flux: f64, y_eq: &[f64], zeta: f64) -> Result<Vec<Complex<f64>>> {
        let mut model = self.clone();
        model.settings.damping_ratio = zeta;
        eigenvalues(&model.jacobian(flux, y_eq))
    }

    /// Linear stability of the sunlit equilibrium under illumination factor `flux` (1: full Sun
    /// at 1 au), with the critical damping ratio found by bisection.
    pub fn flutter(&self, flux: f64) -> Result<DistributedFlutter> {
        let y = self.equilibrium(flux)?;
        let ev = self.spectrum(flux, &y, self.settings.damping_ratio)?;
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
        let growth = |zeta: f64| -> Result<f64> { Ok(self.spectrum(flux, &y, zeta)?[0].re) };
        let zeta_star = if growth(0.0)? < 0.0 {
            0.0
        } else {
            let mut hi = self.settings.damping_ratio.max(1e-6);
            let mut tries = 0;
            while growth(hi)? >= 0.0 {
                hi *= 2.0;
                tries += 1;
                if tries > 60 {
                    return Err(Error::NoConvergence {
                        what: "critical damping".into(),
                        reason: "no stabilising damping ratio found".into(),
                    });
                }
            }
            let mut lo = 0.0;
            while hi - lo > 1e-10 * hi {
                let mid = 0.5 * (lo + hi);
                if growth(mid)? >= 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            0.5 * (lo + hi)
        };
        Ok(DistributedFlutter {
            theta_f: self.theta_f(&y, 0.0)?,
            equilibrium: y,
            growth_rate: ev[0].re,
            eigenvalues: ev,
            modes,
            critical_damping_ratio: zeta_star,
            critical_damping: crate::beam::hinge_equivalent_damping(&self.panel, zeta_star),
        })
    }
}

#[cfg(test)]
mod tests;
