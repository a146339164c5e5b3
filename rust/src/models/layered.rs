//! The N-node laminate coupled to the hinge: state (thermal coordinates…, θ, θ̇).
//!
//! The thermal coordinates are either the node temperatures (when every conduction mode is slow
//! enough for explicit steps the size of the hinge's) or the amplitudes of the slow conduction
//! modes, with the fast modes quasi-static.
//!
//! Why modes: the conduction operator is linear and constant, so its modes decouple; only the
//! face nodes see the non-linear radiation and the cos θ heating. A mode k with rate λ_k driven
//! at the hinge's angular frequency ω lags it by atan(ω/λ_k); when λ_k ≫ ω the lag is small and
//! the mode follows its forcing, q_k = φ_kᵀ b / (C_tot λ_k) (b: the heat entering at the faces),
//! so it can leave the state. That removes exactly the fast modes that would force explicit steps
//! of microseconds, keeps the slow ones (where the physics of the lag is) exact, and is exact in
//! every steady state. The fast modes change the face temperatures, which change the radiation,
//! so the two face temperatures are found by Newton's method at every evaluation (two unknowns;
//! it converges in two or three iterations because the fast modes' face compliance is tiny
//! against radiation). Measured against the full nodal model in docs/laminates.md.

use crate::error::{Error, Result};
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::conduction::{Conduction, Modes};
use crate::models::coupled::{Coupling, Sunlight};
use crate::models::hinge::{sin_cos, Hinge, HingeModel};
use crate::numerics::integrate::{Dyn, OdeSystem, State};
use crate::runs::hybrid::model::HybridModel;
use nalgebra::allocator::Allocator;
use nalgebra::{Const, DMatrix, DVector, DefaultAllocator, Dim, SMatrix, SVector};

/// A conduction mode is kept as a state when λ_k ≤ FAST_MODE_FACTOR × ω_n (ω_n = sqrt(K_el/I_B),
/// the hinge's angular frequency), and quasi-static above. See docs/laminates.md for the
/// measurement behind the value.
pub const FAST_MODE_FACTOR: f64 = 2.0;

/// The thermal coordinates of the state.
#[derive(Debug, Clone, PartialEq)]
pub enum Thermal {
    /// Node temperatures, front to back.
    Nodal(Box<NodalRates>),
    /// Amplitudes of the slow modes, the fast ones quasi-static.
    Modal(Box<Reduced>),
}

/// The nodal model's coefficients, each divided by the capacity or inertia it is divided by, in
/// the order of operations of the two-layer system ([`crate::models::coupled::Coupled`]), so that two
/// nodes on a plain panel give its right-hand side to the bit.
#[derive(Debug, Clone, PartialEq)]
pub struct NodalRates {
    /// α C / C₀, K/s per unit flux factor.
    heating: f64,
    /// σ ε_f / C₀ and σ ε_b / C_{N−1}, 1/(s K³).
    radiation_front: f64,
    radiation_back: f64,
    /// G_e / C_e and G_e / C_{e+1}: element e seen from its first and second node, 1/s.
    down: Vec<f64>,
    up: Vec<f64>,
    /// μ_i / I_B and Σ μ_i / I_B, 1/(s² K).
    moment: Vec<f64>,
    moment_total: f64,
    reference_temperature: f64,
}

impl NodalRates {
    fn new(c: &Conduction, inertia: f64) -> Self {
        let n = c.nodes();
        NodalRates {
            heating: c.absorbed / c.capacity[0],
            radiation_front: c.radiation_front / c.capacity[0],
            radiation_back: c.radiation_back / c.capacity[n - 1],
            down: (0..n - 1)
                .map(|e| c.conductance[e] / c.capacity[e])
                .collect(),
            up: (0..n - 1)
                .map(|e| c.conductance[e] / c.capacity[e + 1])
                .collect(),
            moment: c.moment_weight.iter().map(|m| m / inertia).collect(),
            moment_total: c.moment_total / inertia,
            reference_temperature: c.reference_temperature,
        }
    }

    /// Node rates into `dy[..n]`; returns M_T / I_B.
    #[inline]
    fn rates(&self, flux: f64, t: &[f64], dy: &mut [f64]) -> f64 {
        let n = t.len();
        let last = n - 1;
        let (t0, tl) = (t[0], t[last]);
        let f4 = (t0 * t0) * (t0 * t0);
        let b4 = (tl * tl) * (tl * tl);
        dy[0] = self.heating * flux - self.down[0] * (t0 - t[1]);
        for i in 1..last {
            dy[i] = self.up[i - 1] * (t[i - 1] - t[i]) - self.down[i] * (t[i] - t[i + 1]);
        }
        dy[0] -= self.radiation_front * f4;
        dy[last] = self.up[last - 1] * (t[last - 1] - tl) - self.radiation_back * b4;
        let mut moment = 0.0;
        for (mu, x) in self.moment.iter().zip(t) {
            moment += mu * (x - t0);
        }
        moment + self.moment_total * (t0 - self.reference_temperature)
    }
}

/// The slow-mode model.
#[derive(Debug, Clone, PartialEq)]
pub struct Reduced {
    /// λ_k of the kept modes, 1/s.
    pub rates: Vec<f64>,
    /// The kept modes' coefficients, one row each, read together in one pass per evaluation.
    rows: Vec<ModeRow>,
    /// How the face inputs drive the kept modes' face temperatures:
    /// P = Σ_kept φ_face φ_faceᵀ / C_tot, 1/(J/(m² K)).
    slow_gain: [[f64; 2]; 2],
    /// Face temperatures of the quasi-static fast modes per unit face input,
    /// F = Σ_fast φ_face φ_faceᵀ / (C_tot λ_k), K m²/W.
    compliance: [[f64; 2]; 2],
    /// Moment of the fast modes per unit face input, Σ_fast (μᵀφ_k) φ_face / (C_tot λ_k).
    fast_moment: [f64; 2],
    /// The same with λ_k², for the first-order lag: G = Σ_fast φ_face φ_faceᵀ / (C_tot λ_k²)
    /// (K m² s/W) and Σ_fast (μᵀφ_k) φ_face / (C_tot λ_k²).
    lag_compliance: [[f64; 2]; 2],
    lag_moment: [f64; 2],
    /// Indices of the kept modes in `modes`.
    kept: Vec<usize>,
    /// The full modal basis (for initial states and node temperatures).
    pub modes: Modes,
}

/// The faces of a state: their heat inputs b(u), the radiative conductances
/// D = diag(4 σ ε u³) (at the Newton point) and (I + F D)⁻¹ at the slow faces.
struct Faces {
    inputs: [f64; 2],
    /// b at the Newton point u_slow + δ (within ~2e-6 K of u: a relative 1e-8 in b), which the
    /// first-order lag terms use with D (`radiative`, also taken there).
    newton_inputs: [f64; 2],
    radiative: [f64; 2],
    inverse: [[f64; 2]; 2],
    /// J⁻¹ P.
    inverse_gain: [[f64; 2]; 2],
}

/// The 2×2 product a b.
#[inline(always)]
fn mul2(a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

/// The 2×2 matrix a times x.
#[inline(always)]
fn scale2(a: &[[f64; 2]; 2], x: f64) -> [[f64; 2]; 2] {
    [[a[0][0] * x, a[0][1] * x], [a[1][0] * x, a[1][1] * x]]
}

/// One kept conduction mode k.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ModeRow {
    /// λ_k, 1/s.
    rate: f64,
    /// φ_k at the front and back nodes, divided by C_tot (the forcing of the mode).
    front: f64,
    back: f64,
    /// φ_k at the front and back nodes (the face temperatures the mode carries).
    front_shape: f64,
    back_shape: f64,
    /// μᵀ φ_k: the moment of the mode, N m/K.
    moment: f64,
}

/// The coupled N-node system's coefficients (no orbit: the flux factor is an argument).
#[derive(Debug, Clone, PartialEq)]
pub struct Layered {
    pub conduction: Conduction,
    pub thermal: Thermal,
    model: HingeModel,
    coupling: Coupling,
    /// 1/I_B, c_d/I_B, K_el/I_B and I_B/K_el.
    inverse_inertia: f64,
    damping: f64,
    stiffness: f64,
    compliance: f64,
}

impl Layered {
    /// The system of `conduction` on `panel`'s hinge. `fast_factor` sets which conduction modes
    /// are quasi-static (λ_k > fast_factor ω_n); `f64::INFINITY` keeps every node.
    pub fn new(
        panel: &Panel,
        conduction: Conduction,
        model: HingeModel,
        coupling: Coupling,
        fast_factor: f64,
    ) -> Result<Self> {
        panel.validate()?;
        if fast_factor.is_nan() || fast_factor <= 0.0 {
            return Err(Error::invalid("fast_factor", fast_factor, "must be > 0"));
        }
        let inertia = panel.hinge_inertia();
        let cut = fast_factor * panel.natural_angular_frequency();
        let modes = conduction.modes();
        let thermal = if modes.rates.iter().all(|&l| l <= cut) {
            Thermal::Nodal(Box::new(NodalRates::new(&conduction, inertia)))
        } else {
            Thermal::Modal(Box::new(Reduced::new(&conduction, modes, cut)))
        };
        Ok(Layered {
            conduction,
            thermal,
            model,
            coupling,
            inverse_inertia: 1.0 / inertia,
            damping: panel.damping / inertia,
            stiffness: panel.hinge_stiffness / inertia,
            compliance: inertia / panel.hinge_stiffness,
        })
    }

    /// Number of thermal coordinates in the state.
    pub fn thermal_size(&self) -> usize {
        match &self.thermal {
            Thermal::Nodal(_) => self.conduction.nodes(),
            Thermal::Modal(r) => r.rates.len(),
        }
    }

    /// State size: thermal coordinates + θ + θ̇.
    pub fn size(&self) -> usize {
        self.thermal_size() + 2
    }

    #[inline]
    fn sin_cos(&self, theta: f64) -> (f64, f64) {
        match (self.coupling, self.model) {
            (Coupling::Frozen, HingeModel::Linear) => (0.0, 1.0),
            _ => sin_cos(theta),
        }
    }

    /// dy/dt at illumination factor `flux` (written into `dy`).
    #[inline]
    pub fn rhs_at_flux(&self, flux: f64, y: &[f64], dy: &mut [f64]) {
        let m = self.thermal_size();
        let (th, om) = (y[m], y[m + 1]);
        let (sin, cos) = self.sin_cos(th);
        let area = match self.coupling {
            Coupling::ProjectedArea => cos,
            Coupling::Frozen => 1.0,
        };
        dy[m] = om;
        match &self.thermal {
            // In the order of operations of the two-layer system, to the bit.
            Thermal::Nodal(r) => {
                let moment_rate = r.rates(flux * area, &y[..m], dy);
                let forced = moment_rate - self.damping * om - self.stiffness * th;
                dy[m + 1] = match self.model {
                    HingeModel::Linear => forced,
                    HingeModel::Nonlinear => {
                        (forced - 3.0 * om * om * sin * cos) / (1.0 + 3.0 * sin * sin)
                    }
                };
            }
            // θ̈ = M_T r/I_B − bias: the hinge's terms, and the non-linear model's division, are
            // ready before the faces are solved, so that M_T is two operations from the end.
            Thermal::Modal(r) => {
                let (reciprocal, bias) = self.hinge_terms(th, om, sin, cos);
                let flux_rate = self.area_rate(sin, om) * flux;
                let moment = r
                    .evaluate(&self.conduction, flux * area, flux_rate, &y[..m], dy)
                    .0;
                dy[m + 1] = moment * (reciprocal * self.inverse_inertia) - bias;
            }
        }
    }

    /// The hinge's equation of motion (1 + 3 sin² θ) θ̈ = M_T/I_B − load, load = c_d θ̇/I_B +
    /// K_el θ/I_B + 3 θ̇² sin θ cos θ, as (1 + 3 sin² θ, load) (the non-linear model; 1 and no
    /// θ̇² term for the linear one).
    #[inline(always)]
    fn hinge_equation(&self, th: f64, om: f64, sin: f64, cos: f64) -> (f64, f64) {
        let restoring = self.damping * om + self.stiffness * th;
        match self.model {
            HingeModel::Linear => (1.0, restoring),
            HingeModel::Nonlinear => (1.0 + 3.0 * sin * sin, restoring + 3.0 * om * om * sin * cos),
        }
    }

    /// (r, bias) of [`Layered::hinge_equation`] solved for θ̈: θ̈ = M_T r/I_B − bias, with
    /// r = 1/(1 + 3 sin² θ) (1 for the linear model, no division).
    #[inline(always)]
    fn hinge_terms(&self, th: f64, om: f64, sin: f64, cos: f64) -> (f64, f64) {
        let (factor, load) = self.hinge_equation(th, om, sin, cos);
        match self.model {
            HingeModel::Linear => (1.0, load),
            HingeModel::Nonlinear => {
                let r = 1.0 / factor;
                (r, load * r)
            }
        }
    }

    /// d(projected-area factor)/dt = −sin θ θ̇ with the two-way coupling, 0 when frozen.
    #[inline]
    fn area_rate(&self, sin: f64, theta_dot: f64) -> f64 {
        match self.coupling {
            Coupling::ProjectedArea => -sin * theta_dot,
            Coupling::Frozen => 0.0,
        }
    }

    /// (flux × area factor, its rate) in state y under the illumination factor `flux`.
    fn flux_and_rate(&self, flux: f64, y: &[f64]) -> (f64, f64) {
        let m = self.thermal_size();
        let (sin, cos) = sin_cos(y[m]);
        let area = match self.coupling {
            Coupling::ProjectedArea => cos,
            Coupling::Frozen => 1.0,
        };
        (flux * area, flux * self.area_rate(sin, y[m + 1]))
    }

    /// M_T of a state at illumination factor `flux` (before the projected area), N m.
    pub fn moment_of(&self, flux: f64, y: &[f64]) -> f64 {
        let m = self.thermal_size();
        match &self.thermal {
            Thermal::Nodal(_) => self.conduction.moment(&y[..m]),
            Thermal::Modal(r) => {
                let (f, rate) = self.flux_and_rate(flux, y);
                r.moment(&self.conduction, f, rate, &y[..m])
            }
        }
    }

    /// M_T/K_el of state y read off the equation of motion from its rate dy = f(y) (the hinge's
    /// angular acceleration): what [`Layered::moment_of`] gives over K_el, without evaluating
    /// the faces again.
    pub fn quasi_static_from_rate(&self, y: &[f64], dy: &[f64]) -> f64 {
        let m = self.thermal_size();
        let (th, om, acc) = (y[m], y[m + 1], dy[m + 1]);
        let (sin, cos) = self.sin_cos(th);
        // [`Layered::hinge_equation`] solved for M_T/I_B, which needs no division.
        let (factor, load) = self.hinge_equation(th, om, sin, cos);
        let moment = acc * factor + load;
        moment * self.compliance
    }

    /// Node temperatures of a state at illumination factor `flux` (front first).
    pub fn node_temperatures(&self, flux: f64, y: &[f64]) -> Vec<f64> {
        let m = self.thermal_size();
        match &self.thermal {
            Thermal::Nodal(_) => y[..m].to_vec(),
            Thermal::Modal(r) => {
                let (f, rate) = self.flux_and_rate(flux, y);
                r.node_temperatures(&self.conduction, f, rate, &y[..m])
            }
        }
    }

    /// The state of node temperatures `t` and hinge (θ, θ̇) in this system's coordinates (the
    /// fast modes of `t` are dropped: they follow from the rest).
    pub fn state_from_nodes(&self, t: &[f64], theta: f64, theta_dot: f64) -> Vec<f64> {
        let mut y = match &self.thermal {
            Thermal::Nodal(_) => t.to_vec(),
            Thermal::Modal(r) => r.project(&self.conduction, t),
        };
        y.push(theta);
        y.push(theta_dot);
        y
    }
}

impl Reduced {
    fn new(conduction: &Conduction, modes: Modes, cut: f64) -> Self {
        let n = conduction.nodes();
        let total = modes.total_capacity;
        let mu = &conduction.moment_weight;
        let mut r = Reduced {
            rates: Vec::new(),
            rows: Vec::new(),
            slow_gain: [[0.0; 2]; 2],
            compliance: [[0.0; 2]; 2],
            fast_moment: [0.0; 2],
            lag_compliance: [[0.0; 2]; 2],
            lag_moment: [0.0; 2],
            kept: Vec::new(),
            modes: modes.clone(),
        };
        for (k, &lambda) in modes.rates.iter().enumerate() {
            let phi = modes.shapes.column(k);
            let face = [phi[0], phi[n - 1]];
            let mode_moment: f64 = (0..n).map(|i| mu[i] * phi[i]).sum();
            // The uniform mode (λ = 0) is always slow.
            if k == 0 || lambda <= cut {
                r.kept.push(k);
                r.rates.push(lambda);
                r.rows.push(ModeRow {
                    rate: lambda,
                    front: face[0] / total,
                    back: face[1] / total,
                    front_shape: face[0],
                    back_shape: face[1],
                    moment: mode_moment,
                });
                for i in 0..2 {
                    for j in 0..2 {
                        r.slow_gain[i][j] += face[i] * face[j] / total;
                    }
                }
            } else {
                let w = 1.0 / (total * lambda);
                let w2 = w / lambda;
                for i in 0..2 {
                    for j in 0..2 {
                        r.compliance[i][j] += face[i] * face[j] * w;
                        r.lag_compliance[i][j] += face[i] * face[j] * w2;
                    }
                    r.fast_moment[i] += mode_moment * face[i] * w;
                    r.lag_moment[i] += mode_moment * face[i] * w2;
                }
            }
        }
        r
    }

    /// Face temperatures u = u_slow + F b(u) (u_slow: the faces of the kept modes), with the
    /// face inputs b(u), D = diag(4 σ ε u³), and J⁻¹ P, J⁻¹ = (I + F D(u_slow))⁻¹ the inverse
    /// Jacobian of that equation at the slow faces (reused for the face rates).
    ///
    /// One Newton step from the slow faces, δ = J⁻¹ F b(u_slow), then one chord step with the
    /// same J⁻¹ on the residual at u_slow + δ, which is exactly F σ ε (6 s² δ² + 4 s δ³ + δ⁴)
    /// per face (the Taylor remainder of the fourth power): together u = u_slow + J⁻¹ F (b(u_slow)
    /// − that remainder), and no face input is evaluated twice. The fast modes' face compliance F
    /// is small against radiation (|F D| ≈ 4e-3 for the example wing's honeycomb, 8e-6 for the
    /// aluminium boom; δ ≈ 0.3 K and 1e-3 K), so the Newton step is within ½ |3 F D/u| δ² ≈ 2e-6 K
    /// of the root and the chord step within ~1e-11 K.
    ///
    /// Written for latency (each evaluation waits for the last in a step): the heating, which
    /// waits for cos θ, enters δ and u linearly and last; J⁻¹ F = adj(J) F / det(J) is formed
    /// while the division runs.
    #[inline(always)]
    fn faces(&self, c: &Conduction, heat: f64, s: [f64; 2]) -> Faces {
        let sigma = [c.radiation_front, c.radiation_back];
        let s2 = [s[0] * s[0], s[1] * s[1]];
        // Radiation alone at the slow faces; b(u_slow) = radiated + (heat, 0).
        let radiated = [-sigma[0] * (s2[0] * s2[0]), -sigma[1] * (s2[1] * s2[1])];
        let d_slow = [
            (4.0 * sigma[0] * s[0]) * s2[0],
            (4.0 * sigma[1] * s[1]) * s2[1],
        ];
        let f = &self.compliance;
        let j = [
            [1.0 + f[0][0] * d_slow[0], f[0][1] * d_slow[1]],
            [f[1][0] * d_slow[0], 1.0 + f[1][1] * d_slow[1]],
        ];
        let inv_det = 1.0 / (j[0][0] * j[1][1] - j[0][1] * j[1][0]);
        let adj = [[j[1][1], -j[0][1]], [-j[1][0], j[0][0]]];
        let adj_f = mul2(&adj, f);
        let inverse = scale2(&adj, inv_det);
        let jf = scale2(&adj_f, inv_det);
        let newton = [
            adj_f[0][0] * radiated[0] + adj_f[0][1] * radiated[1],
            adj_f[1][0] * radiated[0] + adj_f[1][1] * radiated[1],
        ];
        let delta = [
            newton[0] * inv_det + jf[0][0] * heat,
            newton[1] * inv_det + jf[1][0] * heat,
        ];
        // The remainder σ (6 s² δ² + 4 s δ³ + δ⁴), its coefficients ready before δ.
        let (six, four) = (
            [6.0 * sigma[0] * s2[0], 6.0 * sigma[1] * s2[1]],
            [4.0 * sigma[0] * s[0], 4.0 * sigma[1] * s[1]],
        );
        let d2 = [delta[0] * delta[0], delta[1] * delta[1]];
        let rest = [
            d2[0] * (six[0] + four[0] * delta[0]) + sigma[0] * (d2[0] * d2[0]),
            d2[1] * (six[1] + four[1] * delta[1]) + sigma[1] * (d2[1] * d2[1]),
        ];
        // The Newton point u_slow + δ, within ~2e-6 K of u, for the first-order lag terms: they
        // need not wait for the chord step.
        let n = [s[0] + delta[0], s[1] + delta[1]];
        let n2 = [n[0] * n[0], n[1] * n[1]];
        let newton_inputs = [
            heat - sigma[0] * (n2[0] * n2[0]),
            -sigma[1] * (n2[1] * n2[1]),
        ];
        let radiative = [
            (4.0 * sigma[0] * n[0]) * n2[0],
            (4.0 * sigma[1] * n[1]) * n2[1],
        ];
        // The chord step moves the faces from the Newton point by u − (u_slow + δ) = −J⁻¹ F ·
        // rest, and what they take in by D times as much: b(u) = b(u_slow + δ) + D J⁻¹ F rest,
        // up to 6 σ u² (J⁻¹ F rest)², the order of the chord step's own error (and ~1e-16 W/m²
        // for the example panels), which does not wait for u's fourth power.
        let chord = [
            jf[0][0] * rest[0] + jf[0][1] * rest[1],
            jf[1][0] * rest[0] + jf[1][1] * rest[1],
        ];
        Faces {
            inputs: [
                newton_inputs[0] + radiative[0] * chord[0],
                newton_inputs[1] + radiative[1] * chord[1],
            ],
            newton_inputs,
            radiative,
            inverse_gain: mul2(&inverse, &self.slow_gain),
            inverse,
        }
    }

    /// Rates of the kept modes (into dy[..m]) and the thermal moment, under the flux factor
    /// `flux` (projected area included) changing at `flux_rate` (1/s); see [`Self::evaluate_rows`].
    #[inline(always)]
    fn evaluate(
        &self,
        c: &Conduction,
        flux: f64,
        flux_rate: f64,
        amp: &[f64],
        dy: &mut [f64],
    ) -> (f64, [f64; 2], [f64; 2]) {
        // A state keeps a few slow modes: on a length known at compile time the pass over them
        // unrolls, without bounds checks.
        macro_rules! sized {
            ($($m:literal)*) => {
                match amp.len() {
                    $($m => self.evaluate_sized::<$m>(c, flux, flux_rate, amp, dy),)*
                    _ => self.evaluate_rows(c, flux, flux_rate, &self.rows, amp, dy),
                }
            };
        }
        sized!(1 2 3 4 5 6 7 8)
    }

    #[inline(always)]
    fn evaluate_sized<const M: usize>(
        &self,
        c: &Conduction,
        flux: f64,
        flux_rate: f64,
        amp: &[f64],
        dy: &mut [f64],
    ) -> (f64, [f64; 2], [f64; 2]) {
        let rows: &[ModeRow; M] = self.rows[..M].try_into().expect("one row per kept mode");
        let amp: &[f64; M] = amp.try_into().expect("one amplitude per kept mode");
        let dy: &mut [f64; M] = (&mut dy[..M]).try_into().expect("one rate per kept mode");
        self.evaluate_rows(c, flux, flux_rate, rows, amp, dy)
    }

    /// The evaluation itself, on the kept modes' `rows`.
    ///
    /// A fast mode k follows its forcing g_k = φ_kᵀ b / C_tot (b: the heat entering at the faces)
    /// as q_k = g_k/λ_k − ġ_k/λ_k² + …: the first term is the quasi-static response, the second
    /// its lag to first order, which is what lets a swinging panel pump energy through the
    /// conduction (thermal flutter); without it the slaved modes would have no lag at all.
    /// ḃ comes from the rate of the flux and of the face temperatures (the slow modes' rates
    /// plus the fast modes' own F ḃ, a 2×2 solve); the lag's effect on ḃ is of the next order.
    #[inline(always)]
    fn evaluate_rows(
        &self,
        c: &Conduction,
        flux: f64,
        flux_rate: f64,
        rows: &[ModeRow],
        amp: &[f64],
        dy: &mut [f64],
    ) -> (f64, [f64; 2], [f64; 2]) {
        // One pass over the kept modes: the faces they carry, the part of the faces' rate that
        // comes from their own decay, and their moment (the uniform mode is always kept: the
        // sums start from the first mode's terms).
        let (first, rest) = rows.split_first().expect("the uniform mode is always kept");
        let fall = first.rate * amp[0];
        let mut slow = [first.front_shape * amp[0], first.back_shape * amp[0]];
        let mut decay = [first.front_shape * fall, first.back_shape * fall];
        let mut slow_moment = first.moment * amp[0];
        for (row, &a) in rest.iter().zip(&amp[1..]) {
            slow[0] += row.front_shape * a;
            slow[1] += row.back_shape * a;
            let fall = row.rate * a;
            decay[0] += row.front_shape * fall;
            decay[1] += row.back_shape * fall;
            slow_moment += row.moment * a;
        }
        let Faces {
            inputs: b,
            newton_inputs: b_near,
            radiative: d,
            inverse,
            inverse_gain,
        } = self.faces(c, c.absorbed * flux, slow);
        // The lag needs ḃ = (α C ḟ, 0) − D u̇, with (I + F D) u̇ = u̇_slow + F (α C ḟ, 0) and the
        // slow modes' zero-order face rates u̇_slow = P b − (Σ φ_face,k λ_k q_k) (the Jacobian is
        // taken at the slow faces: the difference is of the next order in this first-order
        // term). Written as ḃ = c − A b, with A = D J⁻¹ P and c = (α C ḟ, 0) + D J⁻¹ (decay −
        // F (α C ḟ, 0)), which do not wait for b.
        let f = &self.compliance;
        let heating_rate = c.absorbed * flux_rate;
        let a = [
            [d[0] * inverse_gain[0][0], d[0] * inverse_gain[0][1]],
            [d[1] * inverse_gain[1][0], d[1] * inverse_gain[1][1]],
        ];
        let v = [
            decay[0] - f[0][0] * heating_rate,
            decay[1] - f[1][0] * heating_rate,
        ];
        let offset = [
            heating_rate + d[0] * (inverse[0][0] * v[0] + inverse[0][1] * v[1]),
            d[1] * (inverse[1][0] * v[0] + inverse[1][1] * v[1]),
        ];
        let b_rate = [
            offset[0] - (a[0][0] * b_near[0] + a[0][1] * b_near[1]),
            offset[1] - (a[1][0] * b_near[0] + a[1][1] * b_near[1]),
        ];
        // The lag lowers the faces by G ḃ, which raises what they take in by D G ḃ.
        let g = &self.lag_compliance;
        let dg = [
            [d[0] * g[0][0], d[0] * g[0][1]],
            [d[1] * g[1][0], d[1] * g[1][1]],
        ];
        let b = [
            b[0] + (dg[0][0] * b_rate[0] + dg[0][1] * b_rate[1]),
            b[1] + (dg[1][0] * b_rate[0] + dg[1][1] * b_rate[1]),
        ];
        // The terms that do not wait for the lagged inputs first.
        let settled = (slow_moment - c.moment_offset)
            - (self.lag_moment[0] * b_rate[0] + self.lag_moment[1] * b_rate[1]);
        let moment = settled + (self.fast_moment[0] * b[0] + self.fast_moment[1] * b[1]);
        for ((row, &a), d) in rows.iter().zip(amp).zip(dy.iter_mut()) {
            *d = -row.rate * a + row.front * b[0] + row.back * b[1];
        }
        (moment, b, b_rate)
    }

    /// Runs `f` with a scratch slice of `m` rates (on the stack for the usual sizes).
    fn with_scratch<R>(m: usize, f: impl FnOnce(&mut [f64]) -> R) -> R {
        let mut stack = [0.0; 32];
        if m <= stack.len() {
            f(&mut stack[..m])
        } else {
            f(&mut vec![0.0; m])
        }
    }

    fn moment(&self, c: &Conduction, flux: f64, flux_rate: f64, amp: &[f64]) -> f64 {
        Self::with_scratch(amp.len(), |dy| self.evaluate(c, flux, flux_rate, amp, dy).0)
    }

    fn node_temperatures(
        &self,
        c: &Conduction,
        flux: f64,
        flux_rate: f64,
        amp: &[f64],
    ) -> Vec<f64> {
        let n = c.nodes();
        let (_, b, b_rate) =
            Self::with_scratch(amp.len(), |dy| self.evaluate(c, flux, flux_rate, amp, dy));
        let total = self.modes.total_capacity;
        let mut t = vec![0.0; n];
        for (k, &lambda) in self.modes.rates.iter().enumerate() {
            let phi = self.modes.shapes.column(k);
            let q = match self.kept.iter().position(|&j| j == k) {
                Some(p) => amp[p],
                None => {
                    let g = (phi[0] * b[0] + phi[n - 1] * b[1]) / total;
                    let g_rate = (phi[0] * b_rate[0] + phi[n - 1] * b_rate[1]) / total;
                    (g - g_rate / lambda) / lambda
                }
            };
            for i in 0..n {
                t[i] += phi[i] * q;
            }
        }
        t
    }

    /// Amplitudes of the kept modes of a nodal profile: q_k = φ_kᵀ C T / C_tot.
    fn project(&self, c: &Conduction, t: &[f64]) -> Vec<f64> {
        let total = self.modes.total_capacity;
        self.kept
            .iter()
            .map(|&k| {
                let phi = self.modes.shapes.column(k);
                (0..c.nodes())
                    .map(|i| phi[i] * c.capacity[i] * t[i])
                    .sum::<f64>()
                    / total
            })
            .collect()
    }
}

/// The N-node system in orbit: the illumination of the current segment drives it.
#[derive(Debug, Clone)]
pub struct LayeredOrbit {
    pub system: Layered,
    sun: Sunlight,
}

impl LayeredOrbit {
    pub fn new(system: Layered, orbit: Orbit) -> Self {
        LayeredOrbit {
            system,
            sun: Sunlight::new(orbit),
        }
    }
}

impl OdeSystem<Dyn> for LayeredOrbit {
    #[inline]
    fn rhs(&self, t: f64, y: &State<Dyn>) -> State<Dyn> {
        let mut dy = DVector::zeros(y.len());
        self.system
            .rhs_at_flux(self.sun.flux(t), y.as_slice(), dy.as_mut_slice());
        dy
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.sun.orbit.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.sun.enter(a, b);
    }
}

/// The N-node system on a state whose size S is known at compile time: the integrator's
/// vectors then live on the stack, with no allocation per evaluation (the run-time size `Dyn`
/// allocates every intermediate vector, which costs more than the physics of a small state).
struct Fixed<const S: usize>(LayeredOrbit);

impl<const S: usize> OdeSystem<Const<S>> for Fixed<S> {
    #[inline]
    fn rhs(&self, t: f64, y: &State<Const<S>>) -> State<Const<S>> {
        let mut dy = SVector::<f64, S>::zeros();
        self.0
            .system
            .rhs_at_flux(self.0.sun.flux(t), y.as_slice(), dy.as_mut_slice());
        dy
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.0.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.0.enter_segment(a, b);
    }
}

/// A state vector of dimension `D` from its components.
fn state_of<D: Dim>(v: &[f64]) -> State<D>
where
    DefaultAllocator: Allocator<D>,
{
    State::<D>::from_column_slice_generic(D::from_usize(v.len()), Const::<1>, v)
}

/// Calls `$run(system, state)` with the N-node system `$orb` on a compile-time state size when
/// its size is one of the common ones (slow-mode models keep a few modes; nodal models have a
/// few nodes), else on the run-time size.
macro_rules! on_fastest_state {
    ($orb:expr, $size:expr, $run:ident ( $($arg:expr),* )) => {
        match $size {
            3 => $run(&mut Fixed::<3>($orb), $($arg),*),
            4 => $run(&mut Fixed::<4>($orb), $($arg),*),
            5 => $run(&mut Fixed::<5>($orb), $($arg),*),
            6 => $run(&mut Fixed::<6>($orb), $($arg),*),
            7 => $run(&mut Fixed::<7>($orb), $($arg),*),
            8 => $run(&mut Fixed::<8>($orb), $($arg),*),
            9 => $run(&mut Fixed::<9>($orb), $($arg),*),
            10 => $run(&mut Fixed::<10>($orb), $($arg),*),
            11 => $run(&mut Fixed::<11>($orb), $($arg),*),
            12 => $run(&mut Fixed::<12>($orb), $($arg),*),
            13 => $run(&mut Fixed::<13>($orb), $($arg),*),
            14 => $run(&mut Fixed::<14>($orb), $($arg),*),
            16 => $run(&mut Fixed::<16>($orb), $($arg),*),
            18 => $run(&mut Fixed::<18>($orb), $($arg),*),
            22 => $run(&mut Fixed::<22>($orb), $($arg),*),
            _ => { let mut dynamic = $orb; $run(&mut dynamic, $($arg),*) }
        }
    };
}

/// A sampled run of the N-node system, with the temperature of every node.
#[derive(Debug, Clone)]
pub struct LayeredRun {
    pub t: Vec<f64>,
    /// Node temperatures at each sample (sample-major: t.len() × nodes).
    pub temperatures: Vec<f64>,
    pub theta: Vec<f64>,
    pub theta_dot: Vec<f64>,
    pub moment: Vec<f64>,
    pub stats: crate::numerics::integrate::Stats,
    /// The end state as node temperatures, θ, θ̇ (a run can resume from it).
    pub y_end: Vec<f64>,
    /// The integrator settings the run used.
    pub method: crate::numerics::integrate::Method,
    /// Where |θ| first passed the validity limit, when one was watched.
    pub crossing: Option<crate::runs::orbits::LimitCrossing>,
}

/// Integrates the N-node system over `t_span` from `y0` (node temperatures, θ, θ̇; default the
/// sunlit equilibrium at the start's solar flux) and samples it as `output` asks, watching
/// `limit` (see [`crate::runs::simulate::run_watched`]) and stopping within a step of `cancel`.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    panel: &Panel,
    conduction: Conduction,
    orbit: &Orbit,
    model: HingeModel,
    coupling: Coupling,
    method: &crate::numerics::integrate::Method,
    t_span: (f64, f64),
    y0: Option<&[f64]>,
    output: &crate::runs::simulate::Output,
    limit: Option<crate::runs::simulate::OnLimit>,
    cancel: &crate::cancel::Cancel,
) -> Result<LayeredRun> {
    let n = conduction.nodes();
    let start: Vec<f64> = match y0 {
        Some(v) => {
            check_start(panel, v, n)?;
            v.to_vec()
        }
        None => start_state(panel, &conduction, coupling, orbit, t_span.0)?,
    };
    let system = Layered::new(panel, conduction, model, coupling, FAST_MODE_FACTOR)?;
    let y_start = system.state_from_nodes(&start[..n], start[n], start[n + 1]);
    let size = y_start.len();
    let orb = LayeredOrbit::new(system.clone(), *orbit);
    let m = system.thermal_size();
    // θ is the state's component m in every form of the system.
    let watch = limit.map(|l| l.on_component(m));
    let (t, y, stats, y_end, used, crossing) = on_fastest_state!(
        orb,
        size,
        sample_run(method, t_span, &y_start, output, watch.as_ref(), cancel)
    )?;
    let area_free = |t: f64| orbit.illumination(t) * orbit.flux_scale(t);
    let mut run = LayeredRun {
        theta: y.iter().map(|v| v[m]).collect(),
        theta_dot: y.iter().map(|v| v[m + 1]).collect(),
        temperatures: Vec::with_capacity(t.len() * n),
        moment: Vec::with_capacity(t.len()),
        t,
        stats,
        y_end: Vec::new(),
        method: used,
        crossing: crossing
            .map(|(t, y)| crate::runs::orbits::LimitCrossing::in_run(orbit, t_span.0, t, y[m])),
    };
    for (t, y) in run.t.iter().zip(&y) {
        let temps = system.node_temperatures(area_free(*t), y);
        run.moment.push(system.conduction.moment(&temps));
        run.temperatures.extend(temps);
    }
    let mut end = system.node_temperatures(area_free(stats.t_end), &y_end);
    end.push(y_end[m]);
    end.push(y_end[m + 1]);
    run.y_end = end;
    Ok(run)
}

/// Samples of one run of `system`: times, states, counters, the end state, the settings used
/// and where the limit was first passed (t, state).
type Samples = (
    Vec<f64>,
    Vec<Vec<f64>>,
    crate::numerics::integrate::Stats,
    Vec<f64>,
    crate::numerics::integrate::Method,
    Option<(f64, Vec<f64>)>,
);

fn sample_run<D: Dim, S: OdeSystem<D>>(
    system: &mut S,
    method: &crate::numerics::integrate::Method,
    t_span: (f64, f64),
    y0: &[f64],
    output: &crate::runs::simulate::Output,
    limit: Option<&crate::runs::simulate::Limit>,
    cancel: &crate::cancel::Cancel,
) -> Result<Samples>
where
    DefaultAllocator: Allocator<D>,
{
    let traj = crate::runs::simulate::run_watched(
        system,
        method,
        t_span,
        state_of::<D>(y0),
        output,
        limit,
        cancel,
    )?;
    let y = traj.y.iter().map(|v| v.as_slice().to_vec()).collect();
    Ok((
        traj.t,
        y,
        traj.stats,
        traj.y_end.as_slice().to_vec(),
        traj.method,
        traj.crossing.map(|(t, y)| (t, y.as_slice().to_vec())),
    ))
}

/// The summaries' view of the N-node system.
struct LayeredView {
    system: Layered,
    panel: Panel,
    orbit: Orbit,
    coupling: Coupling,
    /// (from, to, s): the illumination s holds on [from, to) (between two breakpoints of a
    /// shadow without penumbra), so the reads of a step need not recompute the geometry.
    sunlit: std::cell::Cell<(f64, f64, f64)>,
    /// Whether the slow-mode model's points inside a step read M_T off the interpolant's slope
    /// (true but in the test that compares the two reads).
    slope_reads: bool,
}

impl LayeredView {
    fn new(system: Layered, panel: Panel, orbit: Orbit, coupling: Coupling) -> Self {
        LayeredView {
            system,
            panel,
            orbit,
            coupling,
            sunlit: std::cell::Cell::new((0.0, 0.0, 0.0)),
            slope_reads: true,
        }
    }

    /// Illumination s(t). Without a penumbra s is constant between breakpoints: it is taken at
    /// the middle of the interval that starts at t (a read exactly on a shadow boundary takes
    /// the side after it) and kept for the reads that follow inside that interval.
    fn illumination(&self, t: f64) -> f64 {
        let (from, to, s) = self.sunlit.get();
        if t >= from && t < to {
            return s;
        }
        if matches!(self.orbit.shadow, crate::inputs::orbit::Shadow::Penumbra) {
            return self.orbit.illumination(t);
        }
        let next = self.orbit.breakpoints(t, t + self.orbit.period);
        let to = next
            .into_iter()
            .find(|&b| b > t)
            .unwrap_or(t + self.orbit.period);
        let s = self.orbit.illumination(0.5 * (t + to));
        self.sunlit.set((t, to, s));
        s
    }
}

impl crate::runs::orbits::SummaryView for LayeredView {
    fn theta_eq(&self, flux: f64) -> Result<f64> {
        Ok(equilibrium(&self.panel, &self.system.conduction, self.coupling, flux)?.theta)
    }
    fn angles(&self, t: f64, y: &[f64]) -> (f64, f64) {
        let flux = self.illumination(t) * self.orbit.flux_scale(t);
        let theta = y[self.system.thermal_size()];
        (
            theta,
            self.system.moment_of(flux, y) / self.panel.hinge_stiffness,
        )
    }
    fn rate(&self, y: &[f64]) -> f64 {
        y[self.system.thermal_size() + 1]
    }
    /// With the fast modes quasi-static, M_T costs a solve of the faces: read it off the
    /// step's end slope instead, except where t is a breakpoint of a shadow without penumbra
    /// (the slope there saw the illumination before it, the summaries read the one after).
    fn angles_at_end(&self, t: f64, y: &[f64], dy: &[f64]) -> (f64, f64) {
        if let Thermal::Modal(_) = self.system.thermal {
            self.illumination(t);
            let penumbra = matches!(self.orbit.shadow, crate::inputs::orbit::Shadow::Penumbra);
            if penumbra || self.sunlit.get().0 != t {
                let theta = y[self.system.thermal_size()];
                return (theta, self.system.quasi_static_from_rate(y, dy));
            }
        }
        self.angles(t, y)
    }
    /// With the fast modes quasi-static, inside a step too: M_T off the equation of motion with
    /// the interpolant's slope, which is within a relative (ωh)⁴/1920 of the system's (at the
    /// middle; 4e-7 at the default 40 steps per hinge period) — against a solve of the faces.
    fn reads_slopes(&self) -> bool {
        self.slope_reads && matches!(self.system.thermal, Thermal::Modal(_))
    }
    fn angles_inside(&self, _t: f64, y: &[f64], dy: &[f64]) -> (f64, f64) {
        let theta = y[self.system.thermal_size()];
        (theta, self.system.quasi_static_from_rate(y, dy))
    }
}

/// What a run of the N-node system over whole orbits is asked, as
/// [`crate::runs::orbits::OrbitRunRequest`] is for the two-layer model: its conduction model, and
/// `y0` = (node temperatures, θ, θ̇).
#[derive(Debug, Clone)]
pub struct LayeredRunRequest {
    pub panel: Panel,
    pub conduction: Conduction,
    pub orbit: Orbit,
    pub model: HingeModel,
    pub coupling: Coupling,
    pub method: crate::numerics::integrate::Method,
    pub t_start: f64,
    pub first_index: u64,
    pub n_orbits: u64,
    pub y0: Vec<f64>,
    pub options: crate::runs::orbits::SummaryOptions,
}

/// Per-orbit summaries of the N-node system (as [`crate::runs::orbits::run_orbits`]); the end state
/// is returned as (node temperatures, θ, θ̇).
pub fn run_orbits(
    req: &LayeredRunRequest,
    cancel: &crate::cancel::Cancel,
) -> Result<LayeredSummaries> {
    run_orbits_reading(req, cancel, true)
}

/// [`run_orbits`], the points inside a step read off the interpolant's slope or not.
fn run_orbits_reading(
    req: &LayeredRunRequest,
    cancel: &crate::cancel::Cancel,
    slope_reads: bool,
) -> Result<LayeredSummaries> {
    check_start(&req.panel, &req.y0, req.conduction.nodes())?;
    let (system, start) = req.system()?;
    let mut view = LayeredView::new(system.clone(), req.panel, req.orbit, req.coupling);
    view.slope_reads = slope_reads;
    let orb = LayeredOrbit::new(system.clone(), req.orbit);
    let size = start.len();
    let args = (
        view,
        &req.panel,
        &req.orbit,
        &req.method,
        req.t_start,
        req.first_index,
        req.n_orbits,
        req.options,
        cancel,
    );
    let mut run = on_fastest_state!(
        orb,
        size,
        summarised_run(&start, system.thermal_size(), args)
    )?;
    run.y_end = req.nodal(&system, run.stats.t_end, &run.y_end);
    Ok(run)
}

impl LayeredRunRequest {
    /// The system of the request (its slow conduction modes) and y0 in its coordinates.
    fn system(&self) -> Result<(Layered, Vec<f64>)> {
        let n = self.conduction.nodes();
        let system = Layered::new(
            &self.panel,
            self.conduction.clone(),
            self.model,
            self.coupling,
            FAST_MODE_FACTOR,
        )?;
        let start = system.state_from_nodes(&self.y0[..n], self.y0[n], self.y0[n + 1]);
        Ok((system, start))
    }

    /// The same request of the two-layer model (whose state is that of two nodes on a plain
    /// panel: `y0` = (T_front, T_back, θ, θ̇), checked by the caller).
    pub fn two_layer(&self) -> crate::runs::orbits::OrbitRunRequest {
        crate::runs::orbits::OrbitRunRequest {
            panel: self.panel,
            orbit: self.orbit,
            model: self.model,
            coupling: self.coupling,
            method: self.method,
            t_start: self.t_start,
            first_index: self.first_index,
            n_orbits: self.n_orbits,
            y0: nalgebra::Vector4::from_column_slice(&self.y0),
            options: self.options,
        }
    }

    /// A state `y` of `system` at time t as (node temperatures, θ, θ̇).
    fn nodal(&self, system: &Layered, t: f64, y: &[f64]) -> Vec<f64> {
        let m = system.thermal_size();
        let flux = self.orbit.illumination(t) * self.orbit.flux_scale(t);
        let mut out = system.node_temperatures(flux, y);
        out.extend([y[m], y[m + 1]]);
        out
    }
}

/// The summarised run's settings, passed through the size dispatch.
type SummaryArgs<'a> = (
    LayeredView,
    &'a Panel,
    &'a Orbit,
    &'a crate::numerics::integrate::Method,
    f64,
    u64,
    u64,
    crate::runs::orbits::SummaryOptions,
    &'a crate::cancel::Cancel,
);

/// Per-orbit summaries of the N-node system, the end state as a plain vector.
pub struct LayeredSummaries {
    pub summaries: Vec<crate::runs::orbits::OrbitSummary>,
    pub stats: crate::numerics::integrate::Stats,
    /// Node temperatures, θ, θ̇.
    pub y_end: Vec<f64>,
    pub crossing: Option<crate::runs::orbits::LimitCrossing>,
}

/// The summaries of any model's run (a two-layer [`crate::runs::orbits::OrbitRun`] among them), the
/// end state as a plain vector.
impl<D: Dim> From<crate::runs::orbits::Summarised<D>> for LayeredSummaries
where
    DefaultAllocator: Allocator<D>,
{
    fn from(run: crate::runs::orbits::Summarised<D>) -> Self {
        LayeredSummaries {
            summaries: run.summaries,
            stats: run.stats,
            y_end: run.y_end.as_slice().to_vec(),
            crossing: run.crossing,
        }
    }
}

fn summarised_run<D: Dim, S: OdeSystem<D>>(
    system: &mut S,
    y0: &[f64],
    theta_index: usize,
    args: SummaryArgs<'_>,
) -> Result<LayeredSummaries>
where
    DefaultAllocator: Allocator<D>,
{
    let (view, panel, orbit, method, t_start, first_index, n_orbits, options, cancel) = args;
    let run = crate::runs::orbits::run_summarised(
        system,
        view,
        panel,
        orbit,
        method,
        t_start,
        first_index,
        n_orbits,
        state_of::<D>(y0),
        theta_index,
        options,
        cancel,
    )?;
    Ok(run.into())
}

/// Checks a start state of node temperatures, θ and θ̇: its size here, its values as every
/// start state's ([`crate::models::hinge::check_start_state`]).
fn check_start(panel: &Panel, v: &[f64], n: usize) -> Result<()> {
    if v.len() != n + 2 {
        return Err(Error::invalid(
            "y0",
            format!("{} components", v.len()),
            &format!(
                "must hold the {n} node temperatures, θ and θ̇ ({} values)",
                n + 2
            ),
        ));
    }
    // The bound on θ̇ is the same for both hinge models: the linear one stands for either.
    let hinge = Hinge::new(panel, HingeModel::Linear);
    crate::models::hinge::check_start_state(v, n, Some(&hinge))
}

/// The steady state of the coupled N-node system under a constant illumination factor: node
/// temperatures (front first) and θ, with θ̇ = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct LayeredEquilibrium {
    pub temperatures: Vec<f64>,
    pub theta: f64,
    pub moment: f64,
}

/// Newton's method on the N heat balances and the static hinge (M_T = K_el θ), with the
/// analytic Jacobian, from the uncoupled steady profile.
pub fn equilibrium(
    panel: &Panel,
    c: &Conduction,
    coupling: Coupling,
    flux: f64,
) -> Result<LayeredEquilibrium> {
    let n = c.nodes();
    if c.two_layer {
        // Two nodes on a plain panel are eq. 2: the same steady state to the bit, so that a run
        // from it is the two-layer run.
        let eq = crate::analysis::steady::equilibrium(panel, coupling, flux)?;
        let temperatures = vec![eq.t_front, eq.t_back];
        return Ok(LayeredEquilibrium {
            moment: c.moment(&temperatures),
            temperatures,
            theta: eq.theta,
        });
    }
    let profile = c.steady_profile(flux)?;
    let k_el = panel.hinge_stiffness;
    let mut x = DVector::zeros(n + 1);
    for i in 0..n {
        x[i] = profile[i];
    }
    x[n] = c.moment(&profile) / k_el;
    let k = c.conduction_matrix();
    let residual_and_jacobian = |x: &DVector<f64>| {
        let th = x[n];
        let (area, d_area) = match coupling {
            Coupling::ProjectedArea => (th.cos(), -th.sin()),
            Coupling::Frozen => (1.0, 0.0),
        };
        let t: Vec<f64> = x.rows(0, n).iter().copied().collect();
        let (qf, qb) = c.face_inputs(flux * area, t[0], t[n - 1]);
        let mut f = DVector::zeros(n + 1);
        let kt = &k * x.rows(0, n);
        for i in 0..n {
            f[i] = -kt[i];
        }
        f[0] += qf;
        f[n - 1] += qb;
        f[n] = (c.moment(&t) - k_el * th) / k_el;
        let mut jac = DMatrix::zeros(n + 1, n + 1);
        jac.view_mut((0, 0), (n, n)).copy_from(&(-&k));
        jac[(0, 0)] -= 4.0 * c.radiation_front * t[0].powi(3);
        jac[(n - 1, n - 1)] -= 4.0 * c.radiation_back * t[n - 1].powi(3);
        jac[(0, n)] = c.absorbed * flux * d_area;
        for i in 0..n {
            jac[(n, i)] = c.moment_weight[i] / k_el;
        }
        jac[(n, n)] = -1.0;
        (f, jac)
    };
    let settled = |x: &DVector<f64>, dx: &DVector<f64>| {
        (0..n).all(|i| dx[i].abs() < 1e-12 * x[i]) && dx[n].abs() < 1e-14
    };
    let x = crate::numerics::newton::newton("steady state", x, n, residual_and_jacobian, settled)?;
    if x[n].abs() >= std::f64::consts::FRAC_PI_2 {
        return Err(Error::NoConvergence {
            what: "steady state".into(),
            reason: format!(
                "hinge angle {} rad is beyond 90°: the panel is far too soft",
                x[n]
            ),
        });
    }
    let temperatures: Vec<f64> = x.rows(0, n).iter().copied().collect();
    let moment = c.moment(&temperatures);
    Ok(LayeredEquilibrium {
        temperatures,
        theta: x[n],
        moment,
    })
}

/// The default start of a layered run beginning at `t0`: the sunlit equilibrium at that time's
/// solar flux, at rest, as the state (node temperatures front first, θ, θ̇ = 0).
pub fn start_state(
    panel: &Panel,
    c: &Conduction,
    coupling: Coupling,
    orbit: &Orbit,
    t0: f64,
) -> Result<Vec<f64>> {
    Orbit::check_time(t0)?;
    let eq = equilibrium(panel, c, coupling, orbit.flux_scale(t0))?;
    let mut y = eq.temperatures;
    y.push(eq.theta);
    y.push(0.0);
    Ok(y)
}

/// The analytic Jacobian of the nodal system (N node temperatures, θ, θ̇) at a steady state.
pub fn jacobian(
    panel: &Panel,
    c: &Conduction,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
    eq: &LayeredEquilibrium,
) -> DMatrix<f64> {
    let n = c.nodes();
    let t = &eq.temperatures;
    let mut j = DMatrix::zeros(n + 2, n + 2);
    let k = c.conduction_matrix();
    for r in 0..n {
        for col in 0..n {
            j[(r, col)] = -k[(r, col)] / c.capacity[r];
        }
    }
    j[(0, 0)] -= 4.0 * c.radiation_front * t[0].powi(3) / c.capacity[0];
    j[(n - 1, n - 1)] -= 4.0 * c.radiation_back * t[n - 1].powi(3) / c.capacity[n - 1];
    let s = eq.theta.sin();
    if coupling == Coupling::ProjectedArea {
        j[(0, n)] = -c.absorbed * flux * s / c.capacity[0];
    }
    j[(n, n + 1)] = 1.0;
    // The static residual is zero at the equilibrium, so the derivative of the non-linear
    // inertia factor drops out (as in the two-layer Jacobian).
    let inertia = panel.hinge_inertia()
        * match model {
            HingeModel::Nonlinear => 1.0 + 3.0 * s * s,
            HingeModel::Linear => 1.0,
        };
    for col in 0..n {
        j[(n + 1, col)] = c.moment_weight[col] / inertia;
    }
    j[(n + 1, n)] = -panel.hinge_stiffness / inertia;
    j[(n + 1, n + 1)] = -panel.damping / inertia;
    j
}

/// Linear stability of the N-node system's sunlit equilibrium (the full nodal Jacobian: an
/// eigen-analysis has no step to protect from fast modes).
#[derive(Debug, Clone, PartialEq)]
pub struct LayeredFlutter {
    pub equilibrium: LayeredEquilibrium,
    /// ∂f/∂y at the equilibrium, state (node temperatures, θ, θ̇).
    pub jacobian: DMatrix<f64>,
    /// Its eigenvalues, 1/s, by decreasing real part.
    pub eigenvalues: Vec<nalgebra::Complex<f64>>,
    /// Largest real part of the eigenvalues, 1/s.
    pub growth_rate: f64,
    /// Frequency of the fastest oscillatory pair, Hz.
    pub frequency_hz: f64,
}

pub fn analyse(
    panel: &Panel,
    c: &Conduction,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
) -> Result<LayeredFlutter> {
    let eq = equilibrium(panel, c, coupling, flux)?;
    let (growth_rate, frequency_hz, eigenvalues) = growth(panel, c, model, coupling, flux, &eq)?;
    Ok(LayeredFlutter {
        jacobian: jacobian(panel, c, model, coupling, flux, &eq),
        equilibrium: eq,
        eigenvalues,
        growth_rate,
        frequency_hz,
    })
}

/// (growth rate, frequency, eigenvalues by decreasing real part) of the Jacobian at `eq`.
fn growth(
    panel: &Panel,
    c: &Conduction,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
    eq: &LayeredEquilibrium,
) -> Result<(f64, f64, Vec<nalgebra::Complex<f64>>)> {
    let n = c.nodes();
    let jac = jacobian(panel, c, model, coupling, flux, eq);
    // Balance kelvin rows against radian rows.
    let tmax = eq.temperatures.iter().fold(1.0_f64, |a, &b| a.max(b));
    let mut scale = vec![1.0; n + 2];
    scale[n] = 1.0 / tmax;
    scale[n + 1] = panel.natural_angular_frequency() / tmax;
    let spectrum = crate::analysis::flutter::Spectrum::of(&jac, &scale)?;
    Ok((
        spectrum.growth_rate,
        spectrum.frequency_hz,
        spectrum.eigenvalues,
    ))
}

/// The damping c_d (N m s/rad) at which the growth rate crosses zero (bisection); 0 when the
/// panel is stable without damping.
pub fn critical_damping(
    panel: &Panel,
    c: &Conduction,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
) -> Result<f64> {
    // The equilibrium does not depend on c_d.
    let eq = equilibrium(panel, c, coupling, flux)?;
    let rate = |cd: f64| -> Result<f64> {
        let p = Panel {
            damping: cd,
            ..*panel
        };
        Ok(growth(&p, c, model, coupling, flux, &eq)?.0)
    };
    let start = panel
        .damping
        .max(1e-3 * (panel.hinge_stiffness * panel.hinge_inertia()).sqrt());
    crate::analysis::flutter::critical_value(rate, start, 1e-12)
}

/// The N-node system as the hybrid propagator's model, on a state of S components (the slow
/// thermal coordinates, θ, θ̇): the same right-hand side as the full run, its derivatives by
/// central differences (the slow-mode model's faces are solved by Newton's method, so it has no
/// closed-form Jacobian; S is small, so 2S evaluations a Jacobian are cheap).
#[derive(Debug, Clone)]
struct HybridLayered<const S: usize> {
    orbit: LayeredOrbit,
    panel: Panel,
    coupling: Coupling,
}

/// Relative step of the central differences, and the magnitudes below which each kind of
/// component is stepped absolutely: K, rad, rad/s. Larger than the cube root of the rounding
/// unit (6e-6) because the faces are solved by Newton's method, whose tolerance is noise in
/// the right-hand side. The 20-node wing's growth rate in the hybrid run against the 20-node
/// eigenvalue, at steps 6e-6, 6e-5, 2e-4, 6e-4: −1.45e-10, +3.0e-11, +6.6e-11, +6.9e-11 /s;
/// the last two are the slow-mode cut's own +5.5e-3 of the rate (docs/laminates.md).
const DIFFERENCE_STEP: f64 = 2e-4;
const DIFFERENCE_FLOOR: [f64; 3] = [1.0, 1e-3, 1e-3];

impl<const S: usize> HybridLayered<S> {
    fn step(&self, y: &SVector<f64, S>, j: usize) -> f64 {
        let floor = DIFFERENCE_FLOOR[match S - j {
            2 => 1,
            1 => 2,
            _ => 0,
        }];
        DIFFERENCE_STEP * y[j].abs().max(floor)
    }

    /// ∂g/∂y_j of a function of the state by central differences, for every j.
    fn gradient<R>(
        &self,
        y: &SVector<f64, S>,
        g: impl Fn(&SVector<f64, S>) -> R,
        mut column: impl FnMut(usize, R, R, f64),
    ) {
        for j in 0..S {
            let h = self.step(y, j);
            let (mut plus, mut minus) = (*y, *y);
            plus[j] += h;
            minus[j] -= h;
            // The step actually taken, so that rounding of y ± h does not bias the quotient.
            column(j, g(&plus), g(&minus), plus[j] - minus[j]);
        }
    }

    fn angle(&self, flux: f64, y: &SVector<f64, S>) -> f64 {
        self.orbit.system.moment_of(flux, y.as_slice()) / self.panel.hinge_stiffness
    }
}

impl<const S: usize> OdeSystem<Const<S>> for HybridLayered<S> {
    #[inline]
    fn rhs(&self, t: f64, y: &State<Const<S>>) -> State<Const<S>> {
        HybridModel::rhs_at_flux(self, self.orbit.sun.flux(t), y)
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.orbit.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.orbit.enter_segment(a, b);
    }
}

impl<const S: usize> HybridModel<S> for HybridLayered<S> {
    type View = LayeredView;

    fn view(&self) -> LayeredView {
        LayeredView::new(
            self.orbit.system.clone(),
            self.panel,
            self.orbit.sun.orbit,
            self.coupling,
        )
    }
    fn panel(&self) -> &Panel {
        &self.panel
    }
    fn hinge(&self) -> HingeModel {
        self.orbit.system.model
    }
    fn rhs_at_flux(&self, flux: f64, y: &SVector<f64, S>) -> SVector<f64, S> {
        let mut dy = SVector::<f64, S>::zeros();
        self.orbit
            .system
            .rhs_at_flux(flux, y.as_slice(), dy.as_mut_slice());
        dy
    }
    fn flux_at(&self, t: f64) -> f64 {
        self.orbit.sun.flux(t)
    }
    fn jacobian(&self, flux: f64, y: &SVector<f64, S>) -> SMatrix<f64, S, S> {
        let mut jac = SMatrix::<f64, S, S>::zeros();
        self.gradient(
            y,
            |x| HybridModel::rhs_at_flux(self, flux, x),
            |j, plus, minus, h| jac.set_column(j, &((plus - minus) / h)),
        );
        jac
    }
    fn flux_sensitivity(&self, flux: f64, y: &SVector<f64, S>) -> SVector<f64, S> {
        let h = 1e-6;
        (self.rhs_at_flux(flux + h, y) - self.rhs_at_flux(flux - h, y)) / (2.0 * h)
    }
    fn equilibrium(&self, flux: f64, from: Option<&SVector<f64, S>>) -> Result<SVector<f64, S>> {
        let start = match from {
            Some(y) => *y,
            None => {
                let c = &self.orbit.system.conduction;
                let eq = equilibrium(&self.panel, c, self.coupling, flux)?;
                let y = self
                    .orbit
                    .system
                    .state_from_nodes(&eq.temperatures, eq.theta, 0.0);
                SVector::from_column_slice(&y)
            }
        };
        // Refined on this model's own right-hand side (the slow-mode model's steady state in its
        // coordinates): every component but θ̇, every equation but θ' = θ̇.
        let rows: Vec<usize> = (0..S).filter(|&i| i != S - 2).collect();
        let state = |x: &DVector<f64>| {
            let mut y = SVector::<f64, S>::zeros();
            y.as_mut_slice()[..S - 1].copy_from_slice(x.as_slice());
            y
        };
        let system = |x: &DVector<f64>| {
            let y = state(x);
            let (f, jac) = (self.rhs_at_flux(flux, &y), self.jacobian(flux, &y));
            (
                DVector::from_fn(S - 1, |i, _| f[rows[i]]),
                DMatrix::from_fn(S - 1, S - 1, |i, j| jac[(rows[i], j)]),
            )
        };
        let settled = |x: &DVector<f64>, dx: &DVector<f64>| {
            (0..S - 2).all(|i| dx[i].abs() < 1e-12 * x[i].abs().max(1.0)) && dx[S - 2].abs() < 1e-14
        };
        let x0 = DVector::from_column_slice(&start.as_slice()[..S - 1]);
        Ok(state(&crate::numerics::newton::newton(
            "sunlit equilibrium",
            x0,
            0,
            system,
            settled,
        )?))
    }
    fn static_angle(&self, flux: f64, y: &SVector<f64, S>, f: &SVector<f64, S>) -> (f64, f64) {
        // The rate along the flow by a central difference over 10 ms.
        let dt = 1e-2;
        let rate = (self.angle(flux, &(y + f * dt)) - self.angle(flux, &(y - f * dt))) / (2.0 * dt);
        (self.angle(flux, y), rate)
    }
    fn quasi_static(&self, flux: f64, y: &SVector<f64, S>) -> f64 {
        self.angle(flux, y)
    }
    fn dynamic_weights(&self, flux: f64, y_ref: &SVector<f64, S>) -> (SVector<f64, S>, f64) {
        // M_T/K_el ≈ m(y_ref) + ∇m·(y − y_ref): affine in the slow-mode coordinates, so
        // θ − M_T/K_el ≈ w·y + c with w = e_θ − ∇m and c = ∇m·y_ref − m(y_ref).
        let mut grad = SVector::<f64, S>::zeros();
        self.gradient(
            y_ref,
            |x| self.angle(flux, x),
            |j, plus, minus, h| grad[j] = (plus - minus) / h,
        );
        let offset = grad.dot(y_ref) - self.angle(flux, y_ref);
        let mut w = -grad;
        w[S - 2] += 1.0;
        (w, offset)
    }
}

/// A hybrid run of the N-node system: the summaries (end state as node temperatures, θ, θ̇)
/// and how the time was split.
pub struct LayeredHybrid {
    pub run: LayeredSummaries,
    pub split: crate::runs::hybrid::HybridRun,
}

/// The largest state (slow thermal coordinates, θ, θ̇) the hybrid propagator is built for.
pub const HYBRID_MAX_STATE: usize = 24;

/// Per-orbit summaries of the N-node system by the hybrid propagator (as
/// [`crate::runs::hybrid::run_orbits_hybrid`]); `req.method` is the full integration of its fallback.
pub fn run_orbits_hybrid(
    req: &LayeredRunRequest,
    settings: &crate::runs::hybrid::HybridSettings,
    cancel: &crate::cancel::Cancel,
) -> Result<LayeredHybrid> {
    let (y0, n) = (&req.y0, req.conduction.nodes());
    check_start(&req.panel, y0, n)?;
    crate::runs::hybrid::check_request(
        &req.orbit,
        &req.method,
        req.t_start,
        req.n_orbits,
        y0,
        &req.options,
        settings,
        cancel,
    )?;
    if req.conduction.two_layer {
        // Two nodes on a plain panel are eq. 2: the two-layer hybrid run, to the bit.
        let out = crate::runs::hybrid::run_orbits_hybrid(&req.two_layer(), settings, cancel)?;
        let run = out.run.clone().into();
        return Ok(LayeredHybrid { run, split: out });
    }
    let (system, start) = req.system()?;
    let args = HybridArgs {
        orbit: &req.orbit,
        method: &req.method,
        t_start: req.t_start,
        first_index: req.first_index,
        n_orbits: req.n_orbits,
        options: req.options,
        settings,
        cancel,
    };
    macro_rules! sizes {
        ($($s:literal)*) => {
            match start.len() {
                $($s => hybrid_run::<$s>(
                    HybridLayered {
                        orbit: LayeredOrbit::new(system.clone(), req.orbit),
                        panel: req.panel,
                        coupling: req.coupling,
                    },
                    &start,
                    &args,
                ),)*
                other => Err(Error::invalid(
                    "layers",
                    other,
                    &format!(
                        "gives a state of {other} components; the hybrid propagator takes 3 to \
                         {HYBRID_MAX_STATE} (use method = \"rk45\")"
                    ),
                )),
            }
        };
    }
    let (mut run, split) = sizes!(3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24)?;
    run.y_end = req.nodal(&system, run.stats.t_end, &run.y_end);
    Ok(LayeredHybrid { run, split })
}

/// What a hybrid run is asked, passed through the size dispatch.
struct HybridArgs<'a> {
    orbit: &'a Orbit,
    method: &'a crate::numerics::integrate::Method,
    t_start: f64,
    first_index: u64,
    n_orbits: u64,
    options: crate::runs::orbits::SummaryOptions,
    settings: &'a crate::runs::hybrid::HybridSettings,
    cancel: &'a crate::cancel::Cancel,
}

fn hybrid_run<const S: usize>(
    model: HybridLayered<S>,
    y0: &[f64],
    a: &HybridArgs<'_>,
) -> Result<(LayeredSummaries, crate::runs::hybrid::HybridRun)> {
    let done = crate::runs::hybrid::propagate(
        model,
        a.orbit,
        a.method,
        a.t_start,
        a.first_index,
        a.n_orbits,
        SVector::from_column_slice(y0),
        a.options,
        a.settings,
        a.cancel,
    )?;
    Ok((done.run.into(), done.split))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::laminate::{Laminate, MATERIALS};
    use crate::models::coupled::Coupled;
    use crate::Orbit;

    /// A CFRP/honeycomb solar-array substrate with Kapton on the Sun side.
    pub(crate) fn wing_layup() -> Laminate {
        Laminate {
            layers: vec![
                MATERIALS[4].layer(50e-6),
                MATERIALS[2].layer(0.3e-3),
                MATERIALS[3].layer(20e-3),
                MATERIALS[2].layer(0.3e-3),
            ],
            emissivity_front: 0.8,
            emissivity_back: 0.8,
            absorptivity: 0.9,
            reference_temperature: 293.15,
        }
    }

    #[test]
    fn two_nodes_on_a_plain_panel_are_the_two_layer_system() {
        let p = Panel {
            damping: 2.0,
            ..Panel::paper()
        };
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
                let c = Conduction::homogeneous(&p, 2).unwrap();
                let sys = Layered::new(&p, c, model, coupling, FAST_MODE_FACTOR).unwrap();
                assert!(matches!(sys.thermal, Thermal::Nodal(_)));
                let two = Coupled::new(p, Orbit::geo_equinox(), model, coupling);
                for y in [[380.0, 368.0, 0.085, 0.0], [250.0, 262.0, -0.3, 0.02]] {
                    let mut dy = [0.0; 4];
                    sys.rhs_at_flux(0.97, &y, &mut dy);
                    let want = two.rhs_at_flux(0.97, &nalgebra::Vector4::from(y));
                    for i in 0..4 {
                        assert!((dy[i] - want[i]).abs() <= 1e-13 * want[i].abs().max(1e-3));
                    }
                }
                let eq = equilibrium(&p, &sys.conduction, coupling, 1.0).unwrap();
                let two_eq = crate::analysis::steady::equilibrium(&p, coupling, 1.0).unwrap();
                assert!((eq.theta / two_eq.theta - 1.0).abs() < 1e-10);
                assert!((eq.temperatures[0] / two_eq.t_front - 1.0).abs() < 1e-12);
                let a = analyse(&p, &sys.conduction, model, coupling, 1.0).unwrap();
                let b = crate::analysis::flutter::analyse(&p, model, coupling, 1.0).unwrap();
                assert!(
                    (a.growth_rate - b.growth_rate).abs() < 1e-9 * b.growth_rate.abs().max(1e-6)
                );
            }
        }
    }

    #[test]
    fn start_state_is_at_rest_in_the_equilibrium_at_the_start_dates_flux() {
        let p = Panel::paper();
        // The eccentric Sun: the flux is highest near perihelion (early January), lowest near
        // aphelion (early July).
        let orbit = Orbit::geo_year(0.0);
        let (january, july) = (3.0 * 86400.0, 185.0 * 86400.0);
        let c = Conduction::new(&p, &wing_layup(), 9).unwrap();
        let sys = Layered::new(
            &p,
            c.clone(),
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
            f64::INFINITY,
        )
        .unwrap();
        let mut fronts = Vec::new();
        for t0 in [january, july] {
            let y = start_state(&p, &c, Coupling::ProjectedArea, &orbit, t0).unwrap();
            assert_eq!(y.len(), c.nodes() + 2);
            assert_eq!(y[c.nodes() + 1], 0.0);
            let mut dy = vec![0.0; y.len()];
            sys.rhs_at_flux(orbit.flux_scale(t0), &y, &mut dy);
            assert!(dy.iter().all(|v| v.abs() < 1e-9), "not at rest: {dy:?}");
            fronts.push(y[0]);
        }
        assert!(fronts[0] > fronts[1] + 1.0, "January {fronts:?} vs July");
        // Two nodes on a plain panel start where the two-layer run starts, to the bit.
        let two = Conduction::homogeneous(&p, 2).unwrap();
        for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
            let y = start_state(&p, &two, coupling, &orbit, july).unwrap();
            let eq =
                crate::analysis::steady::equilibrium(&p, coupling, orbit.flux_scale(july)).unwrap();
            assert_eq!(y, eq.state().as_slice());
        }
        let err = start_state(&p, &c, Coupling::ProjectedArea, &orbit, f64::NAN).unwrap_err();
        assert!(matches!(err, Error::InvalidParameter { ref name, .. } if name == "t"));
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let p = Panel {
            damping: 0.5,
            ..Panel::paper()
        };
        let c = Conduction::new(&p, &wing_layup(), 9).unwrap();
        let sys = Layered::new(
            &p,
            c.clone(),
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
            f64::INFINITY,
        )
        .unwrap();
        let eq = equilibrium(&p, &c, Coupling::ProjectedArea, 1.0).unwrap();
        let jac = jacobian(
            &p,
            &c,
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
            1.0,
            &eq,
        );
        let y = sys.state_from_nodes(&eq.temperatures, eq.theta, 0.0);
        let n = y.len();
        let mut f0 = vec![0.0; n];
        sys.rhs_at_flux(1.0, &y, &mut f0);
        assert!(f0.iter().all(|v| v.abs() < 1e-9), "equilibrium: {f0:?}");
        for j in 0..n {
            let h = if j < n - 2 { 1e-6 * y[j] } else { 1e-5 };
            let (mut yp, mut ym) = (y.clone(), y.clone());
            yp[j] += h;
            ym[j] -= h;
            let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
            sys.rhs_at_flux(1.0, &yp, &mut fp);
            sys.rhs_at_flux(1.0, &ym, &mut fm);
            let scale = (0..n).map(|i| jac[(i, j)].abs()).fold(1e-12, f64::max);
            for i in 0..n {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                assert!(
                    (fd - jac[(i, j)]).abs() < 1e-6 * scale,
                    "({i},{j}) {fd} vs {}",
                    jac[(i, j)]
                );
            }
        }
    }

    #[test]
    fn quasi_static_fast_modes_are_exact_in_steady_state() {
        // An aluminium boom wall: every non-uniform conduction mode is fast.
        let lam = Laminate {
            layers: vec![MATERIALS[0].layer(1e-3)],
            ..wing_layup()
        };
        let p = lam.equivalent_panel(&Panel::paper()).unwrap();
        for layup in [lam, wing_layup()] {
            let c = Conduction::new(&p, &layup, 20).unwrap();
            let sys = Layered::new(
                &p,
                c.clone(),
                HingeModel::Nonlinear,
                Coupling::ProjectedArea,
                FAST_MODE_FACTOR,
            )
            .unwrap();
            assert!(matches!(sys.thermal, Thermal::Modal(_)));
            let eq = equilibrium(&p, &c, Coupling::ProjectedArea, 1.0).unwrap();
            let y = sys.state_from_nodes(&eq.temperatures, eq.theta, 0.0);
            let mut dy = vec![0.0; y.len()];
            sys.rhs_at_flux(1.0, &y, &mut dy);
            let m = sys.conduction.moment(&sys.node_temperatures(1.0, &y));
            // The moment is a sum of large terms that nearly cancel (M_T = Σ μ_i T_i − Σ μ_i T_ref):
            // compare against their size.
            let size: f64 = c
                .moment_weight
                .iter()
                .zip(&eq.temperatures)
                .map(|(m, t)| (m * t).abs())
                .sum();
            assert!((m - eq.moment).abs() < 1e-13 * size, "{m} vs {}", eq.moment);
            let t = sys.node_temperatures(1.0, &y);
            for (a, b) in t.iter().zip(&eq.temperatures) {
                assert!((a / b - 1.0).abs() < 1e-12);
            }
            for (i, v) in dy.iter().enumerate() {
                assert!(v.abs() < 1e-9 * (1.0 + y[i].abs()), "{i}: {v}");
            }
        }
    }

    /// The example wing (CFRP/honeycomb, 20 m) and boom (1 mm aluminium, 2 m) as panels.
    pub(crate) fn examples() -> Vec<(&'static str, Panel, Laminate)> {
        let boom = Laminate {
            layers: vec![MATERIALS[0].layer(1e-3)],
            emissivity_front: 0.8,
            emissivity_back: 0.8,
            absorptivity: 0.4,
            reference_temperature: 293.15,
        };
        let mut out = Vec::new();
        for (name, lam, length) in [("wing", wing_layup(), 20.0), ("boom", boom, 2.0)] {
            let base = Panel {
                length,
                damping: 0.0,
                ..Panel::paper()
            };
            let mut p = lam.equivalent_panel(&base).unwrap();
            p.hinge_stiffness = crate::inputs::panel::hinge_stiffness(
                &p,
                crate::inputs::panel::StiffnessCriterion::DeflectionSmallAngle,
                0.0,
            )
            .unwrap();
            out.push((name, p, lam));
        }
        out
    }

    /// Measurement behind FAST_MODE_FACTOR: one eclipse exit of the example wing and boom with
    /// 20 nodes, for several cuts; prints the jitter after exit, the steps and the critical
    /// damping of the reduced model. `cargo test --release -- --ignored fast_mode --nocapture`
    #[test]
    #[ignore]
    fn fast_mode_factor_measurement() {
        use crate::numerics::integrate::{Method, Tolerances};
        use crate::runs::simulate::{run, Output};
        let orbit = Orbit::geo_equinox();
        let (entry, exit) = orbit.shadow_intervals(0.0, orbit.period)[0];
        for (name, p, lam) in examples() {
            let p = Panel { damping: 0.0, ..p };
            let c = Conduction::new(&p, &lam, 20).unwrap();
            let eq = equilibrium(&p, &c, Coupling::ProjectedArea, 1.0).unwrap();
            let full =
                analyse(&p, &c, HingeModel::Nonlinear, Coupling::ProjectedArea, 1.0).unwrap();
            let cd = critical_damping(&p, &c, HingeModel::Nonlinear, Coupling::ProjectedArea, 1.0)
                .unwrap();
            let wn = p.natural_angular_frequency();
            let rates = c.modes().rates;
            println!(
                "{name}: omega_n {wn:.3} rad/s, theta_eq {:.3e} rad, conduction rates {:.3e}..{:.3e} 1/s, full-model growth(c_d=0) {:.4e} 1/s, c_d* {cd:.5e}",
                eq.theta, rates[1], rates[19], full.growth_rate
            );
            let t0 = entry - 600.0;
            let t1 = exit + 1200.0;
            let tn = 2.0 * std::f64::consts::PI / wn;
            for factor in [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 200.0, 1000.0] {
                let sys = Layered::new(
                    &p,
                    c.clone(),
                    HingeModel::Nonlinear,
                    Coupling::ProjectedArea,
                    factor,
                )
                .unwrap();
                let kept = sys.thermal_size();
                let y0 = DVector::from_vec(sys.state_from_nodes(&eq.temperatures, eq.theta, 0.0));
                let mut orb = LayeredOrbit::new(sys, orbit);
                let method = Method::Dopri5(Tolerances {
                    rtol: 1e-8,
                    atol: 1e-10,
                    max_step: tn / 40.0,
                    max_steps: 50_000_000,
                });
                let start = std::time::Instant::now();
                let traj = run(&mut orb, &method, (t0, t1), y0, &Output::Every(0.05)).unwrap();
                let secs = start.elapsed().as_secs_f64();
                let m = kept;
                let peak = traj
                    .t
                    .iter()
                    .zip(&traj.y)
                    .filter(|(t, _)| **t > exit)
                    .map(|(_, y)| (y[m] - eq.theta).abs())
                    .fold(0.0, f64::max);
                println!("  factor {factor:>6}: kept {kept:>2} modes, steps {:>9}, {secs:.2} s, exit peak |theta - theta_eq| {peak:.6e}", traj.stats.n_steps);
            }
        }
    }

    #[test]
    fn two_nodes_reproduce_the_two_layer_orbit_to_1e10() {
        // On the portable kernel: the fused one rounds the two-layer plate's multiply-adds once,
        // which the nodal model (no fused form) does not, so their steps part.
        crate::numerics::cpu::on_portable(two_nodes_reproduce_the_two_layer_orbit);
    }

    fn two_nodes_reproduce_the_two_layer_orbit() {
        use crate::numerics::integrate::{Method, Tolerances};
        use crate::runs::simulate::{run, Output};
        // The nodal right-hand side on two nodes does eq. 2's arithmetic in eq. 2's order, so
        // the runs take the same steps; anything but rounding-level agreement would show here
        // (a near-undamped hinge amplifies any difference in the step sequence to ~1e-6).
        let p = Panel::paper();
        let o = Orbit::geo_equinox();
        let method = Method::Dopri5(Tolerances::default());
        let out = Output::Every(30.0);
        let span = (0.0, o.period);
        let c = Conduction::homogeneous(&p, 2).unwrap();
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        // Both from the same start (the equilibria agree to 1e-10 on their own, tested above).
        let eq = crate::analysis::steady::equilibrium(&p, coupling, 1.0).unwrap();
        let y0 = nalgebra::Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0);
        let start = [eq.t_front, eq.t_back, eq.theta, 0.0];
        let lay = simulate(
            &p,
            c,
            &o,
            model,
            coupling,
            &method,
            span,
            Some(&start),
            &out,
            None,
            &crate::cancel::Cancel::new(),
        )
        .unwrap();
        let two = run(
            &mut Coupled::new(p, o, model, coupling),
            &method,
            span,
            y0,
            &out,
        )
        .unwrap();
        assert_eq!(lay.t.len(), two.t.len());
        assert_eq!(lay.method, two.method, "the settings the run reports");
        let theta_scale = two.column(2).iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        let mut worst: f64 = 0.0;
        for (k, y) in two.y.iter().enumerate() {
            worst = worst
                .max((lay.temperatures[2 * k] / y[0] - 1.0).abs())
                .max((lay.temperatures[2 * k + 1] / y[1] - 1.0).abs())
                .max((lay.theta[k] - y[2]).abs() / theta_scale);
        }
        println!("two nodes vs two layers over one GEO orbit: worst relative difference {worst:e}; steps {} vs {}", lay.stats.n_steps, two.stats.n_steps);

        assert!(worst < 1e-10, "{worst}");
    }

    #[test]
    fn the_seams_coupled_system_runs_the_nodal_model_alike() {
        // The N-node model registered as a thermal model of the seam (models::thermal_model) and run by
        // its generic coupled system agrees with this module's nodal system.
        use crate::models::coupled::Coupled as Generic;
        use crate::models::hinge::Hinge;
        use crate::numerics::integrate::{Dyn, Method, Tolerances};
        use crate::runs::simulate::{run, Output};
        let p = Panel::paper();
        let o = Orbit::geo_equinox();
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        let nodes = 7;
        let thermal = crate::models::thermal_model(&p, nodes as u32).unwrap();
        let mut generic =
            Generic::compose(thermal, Hinge::new(&p, model), o, coupling, Dyn(nodes + 2)).unwrap();
        let eq = equilibrium(
            &p,
            &Conduction::homogeneous(&p, nodes).unwrap(),
            coupling,
            1.0,
        )
        .unwrap();
        let mut start = eq.temperatures.clone();
        start.extend([eq.theta, 0.0]);
        let method = Method::Dopri5(Tolerances::default());
        let (entry, _) = o.shadow_intervals(0.0, o.period)[0];
        let span = (entry - 100.0, entry + 900.0);
        let out = Output::Every(50.0);
        let c = Conduction::homogeneous(&p, nodes).unwrap();
        let ours = simulate(
            &p,
            c,
            &o,
            model,
            coupling,
            &method,
            span,
            Some(&start),
            &out,
            None,
            &crate::cancel::Cancel::new(),
        )
        .unwrap();
        let theirs = run(&mut generic, &method, span, DVector::from_vec(start), &out).unwrap();
        for (k, y) in theirs.y.iter().enumerate() {
            assert!(
                (ours.theta[k] - y[nodes]).abs() < 1e-7 * eq.theta.abs(),
                "{k}"
            );
            for i in 0..nodes {
                assert!((ours.temperatures[k * nodes + i] / y[i] - 1.0).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn summaries_read_the_shadow_of_each_interval() {
        // The quasi-static angle M_T/K_el of the summaries must follow the shadow: with the fast
        // modes quasi-static, M_T jumps with the illumination, and a run that rests at its
        // sunlit and its eclipse steady states has a jitter RMS near zero, not the size of the
        // angle (the aluminium boom: every non-uniform mode is fast).
        let (_, p, lam) = examples().pop().unwrap();
        let p = Panel { damping: 50.0, ..p };
        let c = Conduction::new(&p, &lam, 20).unwrap();
        let o = Orbit::geo_equinox();
        let eq = equilibrium(&p, &c, Coupling::ProjectedArea, 1.0).unwrap();
        let req = one_orbit_from_equilibrium(p, c, o, &eq);
        let run = run_orbits(&req, &crate::cancel::Cancel::new()).unwrap();
        let s = run.summaries[0];
        assert!(
            s.jitter_rms < 0.05 * eq.theta,
            "{} vs θ_eq {}",
            s.jitter_rms,
            eq.theta
        );
    }

    /// One orbit of the non-linear, two-way coupled model from the sunlit equilibrium `eq`,
    /// rk45 at the default tolerances, summarised with 600 s windows and a 1 rad limit.
    fn one_orbit_from_equilibrium(
        panel: Panel,
        conduction: Conduction,
        orbit: Orbit,
        eq: &LayeredEquilibrium,
    ) -> LayeredRunRequest {
        use crate::numerics::integrate::{Method, Tolerances};
        use crate::runs::orbits::{SummaryOptions, STEPS_PER_HINGE_PERIOD};
        let mut y0 = eq.temperatures.clone();
        y0.extend([eq.theta, 0.0]);
        LayeredRunRequest {
            panel,
            conduction,
            orbit,
            model: HingeModel::Nonlinear,
            coupling: Coupling::ProjectedArea,
            method: Method::Dopri5(Tolerances::default()),
            t_start: 0.0,
            first_index: 0,
            n_orbits: 1,
            y0,
            options: SummaryOptions {
                window: 600.0,
                theta_limit: 1.0,
                stop_at_limit: false,
                steps_per_period: STEPS_PER_HINGE_PERIOD,
            },
        }
    }

    #[test]
    fn slope_reads_inside_a_step_match_a_solve_of_the_faces() {
        // The slow-mode model's summaries read M_T inside a step off the interpolant's slope;
        // against reading it by solving the faces at each point, on both example panels
        // through a LEO orbit's eclipse (1 % of critical damping, so the jitter lives on).
        for (name, p, lam) in examples() {
            let p = Panel {
                damping: 0.01 * (p.hinge_stiffness * p.hinge_inertia()).sqrt(),
                ..p
            };
            let c = Conduction::new(&p, &lam, 20).unwrap();
            let o = Orbit::leo(500e3);
            let eq = equilibrium(&p, &c, Coupling::ProjectedArea, 1.0).unwrap();
            let req = one_orbit_from_equilibrium(p, c, o, &eq);
            let cancel = crate::cancel::Cancel::new();
            let system = req.system().unwrap().0;
            assert!(matches!(system.thermal, Thermal::Modal(_)), "{name}");
            let slope = run_orbits_reading(&req, &cancel, true).unwrap().summaries[0];
            let solve = run_orbits_reading(&req, &cancel, false).unwrap().summaries[0];
            // θ is read from the same interpolant either way.
            assert_eq!(slope.theta_max, solve.theta_max, "{name}");
            assert_eq!(slope.theta_min, solve.theta_min, "{name}");
            let scale = solve.jitter_peak;
            assert!(scale > 0.0, "{name}");
            for (what, a, b) in [
                ("jitter_rms", slope.jitter_rms, solve.jitter_rms),
                ("jitter_peak", slope.jitter_peak, solve.jitter_peak),
            ] {
                let rel = (a - b).abs() / scale;
                println!("{name}: {what} {a:e} vs {b:e}: {rel:.1e} of the peak");
                assert!(rel < 1e-5, "{name}: {what} {a} vs {b}");
            }
        }
    }

    /// The growth rate of the reduced model (finite-difference Jacobian) for several cuts,
    /// against the full nodal model's. `cargo test --release -- --ignored reduced_growth --nocapture`
    #[test]
    #[ignore]
    fn reduced_growth_measurement() {
        for (name, p, lam) in examples() {
            let p = Panel { damping: 0.0, ..p };
            let c = Conduction::new(&p, &lam, 20).unwrap();
            let full =
                analyse(&p, &c, HingeModel::Nonlinear, Coupling::ProjectedArea, 1.0).unwrap();
            let eq = full.equilibrium.clone();
            println!("{name}: full growth {:.6e}", full.growth_rate);
            for factor in [1.0, 2.0, 5.0, 10.0, 20.0, 1e9] {
                let sys = Layered::new(
                    &p,
                    c.clone(),
                    HingeModel::Nonlinear,
                    Coupling::ProjectedArea,
                    factor,
                )
                .unwrap();
                let y = sys.state_from_nodes(&eq.temperatures, eq.theta, 0.0);
                let n = y.len();
                let mut jac = DMatrix::zeros(n, n);
                for j in 0..n {
                    // θ and θ̇ enter through small terms: a step large enough to rise above
                    // rounding (the right-hand side is smooth, the truncation error O(h²)).
                    let h = if j + 2 >= n {
                        1e-4
                    } else {
                        1e-6 * y[j].abs().max(1e-6)
                    };
                    let (mut yp, mut ym) = (y.clone(), y.clone());
                    yp[j] += h;
                    ym[j] -= h;
                    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
                    sys.rhs_at_flux(1.0, &yp, &mut fp);
                    sys.rhs_at_flux(1.0, &ym, &mut fm);
                    for i in 0..n {
                        jac[(i, j)] = (fp[i] - fm[i]) / (2.0 * h);
                    }
                }
                let g = jac
                    .complex_eigenvalues()
                    .iter()
                    .map(|z| z.re)
                    .fold(f64::NEG_INFINITY, f64::max);
                println!(
                    "  factor {factor:>6}: state {n:>2}, growth {g:.6e} ({:+.2e} relative)",
                    g / full.growth_rate - 1.0
                );
            }
        }
    }

    /// Physics review of the node count: the plain paper panel's c_d* is 2.16 with two nodes
    /// and about 5.6 with many. Not a bug: (1) with two nodes the N-node model is eq. 2 and its
    /// c_d* is the two-layer one, which the Sec. 4.2 closed form approximates; (2) as the nodes
    /// double, c_d* converges (second order in the element size) to the continuum's; (3) the
    /// two lumped nodes relax the gradient at 4 K/(m c), the continuum slab at π² K/(m c) (its
    /// first odd conduction mode), so at the hinge frequency the gradient answers the swinging
    /// flux with another lag, and another thermal pumping.
    #[test]
    fn critical_damping_converges_with_the_nodes_and_two_nodes_are_the_two_layer_model() {
        let p = Panel::paper();
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        let cd = |nodes: usize| {
            let c = Conduction::homogeneous(&p, nodes).unwrap();
            critical_damping(&p, &c, model, coupling, 1.0).unwrap()
        };
        // (1) Two nodes: the two-layer model's c_d* (to the bisection's tolerance).
        let two = crate::analysis::flutter::critical_damping(&p, model, coupling, 1.0).unwrap();
        assert!((cd(2) / two - 1.0).abs() < 1e-10, "{} vs {two}", cd(2));
        // ... which the closed form of Sec. 4.2 approximates on a panel with ε_f = ε_b (the
        // form it assumes; linear hinge, first order in the pumping).
        let equal = Panel {
            emissivity_front: 0.55,
            emissivity_back: 0.55,
            ..p
        };
        let c2 = Conduction::homogeneous(&equal, 2).unwrap();
        let exact = critical_damping(&equal, &c2, HingeModel::Linear, coupling, 1.0).unwrap();
        let closed = crate::analysis::linear::LinearThermal::new(&equal, 1.0, None, None)
            .unwrap()
            .critical_damping_estimate();
        println!("ε_f = ε_b: c_d* two nodes {exact:.5}, Sec. 4.2 closed form {closed:.5}");
        assert!((closed / exact - 1.0).abs() < 1e-3, "{closed} vs {exact}");
        // (2) Convergence as the elements double (nodes 2^k + 1).
        let values: Vec<f64> = [3, 5, 9, 17, 33, 65].iter().map(|&n| cd(n)).collect();
        let changes: Vec<f64> = values.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
        let orders: Vec<f64> = changes.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        let doubling: Vec<f64> = [4, 8, 16, 32, 64].iter().map(|&n| cd(n)).collect();
        println!(
            "c_d* at 3..65 nodes {values:?}, changes {changes:?}, observed orders {orders:?}; \
             at 4, 8, 16, 32, 64 nodes {doubling:?}"
        );
        for &o in &orders[2..] {
            assert!(o > 1.7, "observed order {o}: {orders:?}");
        }
        let limit = values[5] + changes[4] / 3.0; // Richardson, second order
        assert!((values[5] / limit - 1.0).abs() < 1e-3, "{values:?}");
        assert!((doubling[4] / limit - 1.0).abs() < 1e-3, "{doubling:?}");
        assert!(limit > 2.0 * two, "{limit} vs {two}");
        // (3) The gradient's relaxation: 4 K/(m c) for two lumped nodes, π² K/(m c) for the
        // continuum, which the first odd conduction mode approaches at second order.
        let unit = p.conductance / p.heat_capacity();
        let first = |nodes: usize| Conduction::homogeneous(&p, nodes).unwrap().modes().rates[1];
        assert!((first(2) / (4.0 * unit) - 1.0).abs() < 1e-12);
        let pi2 = std::f64::consts::PI.powi(2) * unit;
        let errors: Vec<f64> = [9, 17, 33, 65]
            .iter()
            .map(|&n| (first(n) / pi2 - 1.0).abs())
            .collect();
        println!("first odd mode against π² K/(m c) at 9..65 nodes: {errors:?}");
        for w in errors.windows(2) {
            assert!(((w[0] / w[1]).log2() - 2.0).abs() < 0.1, "{errors:?}");
        }
    }

    /// One GEO orbit of the example `LAMINATE_PANEL` (wing or boom) with `LAMINATE_NODES` nodes
    /// (2: the two-layer model on the same panel), for instruction counts under callgrind:
    /// `LAMINATE_PANEL=wing LAMINATE_NODES=20 valgrind --tool=callgrind <test binary>
    /// --ignored --exact layered::tests::orbit_cost`
    #[test]
    #[ignore]
    fn orbit_cost() {
        use crate::runs::simulate::run;
        let want = std::env::var("LAMINATE_PANEL").unwrap_or_else(|_| "wing".into());
        let nodes: usize = std::env::var("LAMINATE_NODES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(20);
        let (_, p, lam) = examples().into_iter().find(|e| e.0 == want).unwrap();
        let case = CostCase::of(p);
        let CostCase {
            p,
            o,
            ref method,
            ref out,
            model,
            coupling,
        } = case;
        let orbits = std::env::var("LAMINATE_RUN").is_ok_and(|v| v == "orbits");
        let options = crate::runs::orbits::SummaryOptions {
            window: 600.0,
            theta_limit: 0.5,
            stop_at_limit: false,
            steps_per_period: crate::runs::orbits::STEPS_PER_HINGE_PERIOD,
        };
        let cancel = crate::cancel::Cancel::new();
        let steps = if nodes == 2 {
            let mut sys = Coupled::new(p, o, model, coupling);
            let y0 = sys.steady_state(1.0).unwrap();
            if orbits {
                let req = crate::runs::orbits::OrbitRunRequest {
                    panel: p,
                    orbit: o,
                    model,
                    coupling,
                    method: *method,
                    t_start: 0.0,
                    first_index: 0,
                    n_orbits: 1,
                    y0,
                    options,
                };
                crate::runs::orbits::run_orbits_cancellable(&req, &cancel)
                    .unwrap()
                    .stats
            } else {
                run(&mut sys, method, (0.0, o.period), y0, out)
                    .unwrap()
                    .stats
            }
        } else {
            let c = Conduction::new(&p, &lam, nodes).unwrap();
            if orbits {
                let eq = equilibrium(&p, &c, coupling, 1.0).unwrap();
                let mut y0 = eq.temperatures.clone();
                y0.extend([eq.theta, 0.0]);
                let req = LayeredRunRequest {
                    panel: p,
                    conduction: c,
                    orbit: o,
                    model,
                    coupling,
                    method: *method,
                    t_start: 0.0,
                    first_index: 0,
                    n_orbits: 1,
                    y0,
                    options,
                };
                run_orbits(&req, &cancel).unwrap().stats
            } else {
                case.simulate(c).stats
            }
        };
        println!("{want}, {nodes} nodes: {steps:?}");
    }

    /// The setting of the cost measurements: one GEO orbit of an example panel at 1 % of its
    /// critical damping, rk45 at the default tolerances, sampled at the orbit's end.
    struct CostCase {
        p: Panel,
        o: Orbit,
        method: crate::numerics::integrate::Method,
        out: crate::runs::simulate::Output,
        model: HingeModel,
        coupling: Coupling,
    }

    impl CostCase {
        fn of(p: Panel) -> Self {
            let o = Orbit::geo_equinox();
            CostCase {
                p: Panel {
                    damping: 0.01 * (p.hinge_stiffness * p.hinge_inertia()).sqrt(),
                    ..p
                },
                o,
                method: crate::numerics::integrate::Method::Dopri5(
                    crate::numerics::integrate::Tolerances::default(),
                ),
                out: crate::runs::simulate::Output::Times(vec![o.period]),
                model: HingeModel::Nonlinear,
                coupling: Coupling::ProjectedArea,
            }
        }

        /// The N-node `simulate` of the orbit from its sunlit equilibrium.
        fn simulate(&self, c: Conduction) -> LayeredRun {
            let span = (0.0, self.o.period);
            let (p, o) = (&self.p, &self.o);
            simulate(
                p,
                c,
                o,
                self.model,
                self.coupling,
                &self.method,
                span,
                None,
                &self.out,
                None,
                &crate::cancel::Cancel::new(),
            )
            .unwrap()
        }
    }

    /// Wall time of one GEO orbit (`simulate`), 20 nodes against the two-layer model, both
    /// example panels, interleaved, best of 7: `cargo test --release -- --ignored orbit_time
    /// --nocapture`. (The bench through Python is benches/laminate.py.)
    #[test]
    #[ignore]
    fn orbit_time() {
        use crate::runs::simulate::run;
        for (name, p, lam) in examples() {
            let case = CostCase::of(p);
            let CostCase {
                p,
                o,
                ref method,
                ref out,
                model,
                coupling,
            } = case;
            let mut best = [f64::INFINITY; 2];
            for _ in 0..7 {
                let start = std::time::Instant::now();
                let mut sys = Coupled::new(p, o, model, coupling);
                let y0 = sys.steady_state(1.0).unwrap();
                run(&mut sys, method, (0.0, o.period), y0, out).unwrap();
                best[0] = best[0].min(start.elapsed().as_secs_f64());
                let start = std::time::Instant::now();
                case.simulate(Conduction::new(&p, &lam, 20).unwrap());
                best[1] = best[1].min(start.elapsed().as_secs_f64());
            }
            println!(
                "{name}: two-layer {:.4} s, 20 nodes {:.4} s, ratio {:.2}",
                best[0],
                best[1],
                best[1] / best[0]
            );
        }
    }

    /// The right-hand side's cost, 20 nodes against the two-layer model on the same panel:
    /// throughput (independent evaluations) and latency (each waits for the last, as the stages
    /// of a step do). `cargo test --release --lib -- --ignored rhs_cost --nocapture`
    #[test]
    #[ignore]
    fn rhs_cost() {
        let n = 10_000_000;
        let time = |f: &mut dyn FnMut()| {
            let start = std::time::Instant::now();
            for _ in 0..n {
                f();
            }
            start.elapsed().as_secs_f64() / n as f64 * 1e9
        };
        for (name, p, lam) in examples() {
            let c = Conduction::new(&p, &lam, 20).unwrap();
            let sys = Layered::new(
                &p,
                c.clone(),
                HingeModel::Nonlinear,
                Coupling::ProjectedArea,
                FAST_MODE_FACTOR,
            )
            .unwrap();
            let eq = equilibrium(&p, &c, Coupling::ProjectedArea, 1.0).unwrap();
            let y = sys.state_from_nodes(&eq.temperatures, eq.theta, 1e-3);
            let mut dy = vec![0.0; y.len()];
            let mut flux = 1.0;
            let through = time(&mut || {
                flux = 2.0 - flux;
                sys.rhs_at_flux(std::hint::black_box(flux), &y, &mut dy);
                std::hint::black_box(&dy);
            });
            let mut z = y.clone();
            let latency = time(&mut || {
                sys.rhs_at_flux(1.0, &z, &mut dy);
                for (zi, (yi, di)) in z.iter_mut().zip(y.iter().zip(&dy)) {
                    *zi = yi + 1e-30 * di;
                }
            });
            let two = Coupled::new(
                p,
                Orbit::geo_equinox(),
                HingeModel::Nonlinear,
                Coupling::ProjectedArea,
            );
            let y4 =
                nalgebra::Vector4::new(eq.temperatures[0], eq.temperatures[19], eq.theta, 1e-3);
            let mut out = y4;
            let two_through = time(&mut || {
                flux = 2.0 - flux;
                out = two.rhs_at_flux(std::hint::black_box(flux), &y4);
                std::hint::black_box(&out);
            });
            let mut z4 = y4;
            let two_latency = time(&mut || {
                let d = two.rhs_at_flux(1.0, &z4);
                z4 = y4 + d * 1e-30;
            });
            println!(
                "{name}: state {}: rhs {through:.1} ns, latency {latency:.1} ns; \
                 two-layer rhs {two_through:.1} ns, latency {two_latency:.1} ns",
                y.len()
            );
        }
    }
}
