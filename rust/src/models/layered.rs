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
use crate::inputs::heating::Loads;
use crate::inputs::panel::Panel;
use crate::models::conduction::{Conduction, Modes};
use crate::models::coupled::Coupling;
use crate::models::hinge::{
    angular_acceleration, generalised_moment, hinge_load, sin_cos, HingeModel,
};

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
    /// C₀ and C_{N−1}, J/(m² K): the face nodes that take the loads on each face.
    capacity_front: f64,
    capacity_back: f64,
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
            capacity_front: c.capacity[0],
            capacity_back: c.capacity[n - 1],
        }
    }

    /// Adds the loads absorbed on each face (W/m², projected area included) to the face nodes'
    /// rates, as [`crate::models::thermal::ThermalModel::add_face_rates`] does.
    #[inline]
    fn add_face_rates(&self, front: f64, back: f64, dy: &mut [f64]) {
        dy[0] += front / self.capacity_front;
        dy[dy.len() - 1] += back / self.capacity_back;
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

/// The heat absorbed on the front and the back face, W/m² (projected area included), and its
/// rate through the projected area, W/(m² s).
#[derive(Debug, Clone, Copy)]
struct FaceHeat {
    heat: [f64; 2],
    rate: [f64; 2],
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

/// The first M mode rows, the M amplitudes and the first M rates, as arrays of that length
/// (see [`Layered::evaluate`]).
#[inline(always)]
fn kept<'a, 'b, 'c, const M: usize>(
    rows: &'a [ModeRow],
    amp: &'b [f64],
    dy: &'c mut [f64],
) -> (&'a [ModeRow; M], &'b [f64; M], &'c mut [f64; M]) {
    let rows = rows[..M].try_into().expect("one row per kept mode");
    let amp = amp.try_into().expect("one amplitude per kept mode");
    let dy = (&mut dy[..M]).try_into().expect("one rate per kept mode");
    (rows, amp, dy)
}

/// The coupled N-node system's coefficients (no orbit: the flux factor is an argument).
#[derive(Debug, Clone, PartialEq)]
pub struct Layered {
    pub conduction: Conduction,
    pub thermal: Thermal,
    pub(crate) model: HingeModel,
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
            damping: panel.damping_rate(),
            stiffness: panel.stiffness_rate(),
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
        self.rhs_at_loads(Loads::sun(flux), y, dy)
    }

    /// dy/dt under `loads` (the front's sunlight as a flux factor and the further loads on each
    /// face, W/m², all before the projected area), written into `dy`.
    #[inline]
    pub fn rhs_at_loads(&self, loads: Loads, y: &[f64], dy: &mut [f64]) {
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
                let moment_rate = r.rates(loads.sun * area, &y[..m], dy);
                if loads.has_face_loads() {
                    r.add_face_rates(loads.front * area, loads.back * area, &mut dy[..m]);
                }
                let forced = generalised_moment(moment_rate, self.damping, self.stiffness, th, om);
                dy[m + 1] = angular_acceleration(self.model, forced, om, sin, cos);
            }
            // θ̈ = M_T r/I_B − bias: the hinge's terms, and the non-linear model's division, are
            // ready before the faces are solved, so that M_T is two operations from the end.
            Thermal::Modal(r) => {
                let (reciprocal, bias) = self.hinge_terms(th, om, sin, cos);
                let heat = self.face_heat(loads, area, self.area_rate(sin, om));
                let moment = r.evaluate(&self.conduction, heat, &y[..m], dy).0;
                dy[m + 1] = moment * (reciprocal * self.inverse_inertia) - bias;
            }
        }
    }

    /// The heat absorbed on each face, W/m², and its rate through the projected area, under
    /// `loads` at area factor `area` changing at `area_rate`.
    #[inline(always)]
    fn face_heat(&self, loads: Loads, area: f64, area_rate: f64) -> FaceHeat {
        let c = &self.conduction;
        let flux_rate = area_rate * loads.sun;
        FaceHeat {
            heat: [
                c.absorbed * (loads.sun * area) + loads.front * area,
                loads.back * area,
            ],
            rate: [
                c.absorbed * flux_rate + loads.front * area_rate,
                loads.back * area_rate,
            ],
        }
    }

    /// The hinge's equation of motion as (1 + 3 sin² θ, load) ([`hinge_load`]).
    #[inline(always)]
    fn hinge_equation(&self, th: f64, om: f64, sin: f64, cos: f64) -> (f64, f64) {
        hinge_load(self.model, self.damping, self.stiffness, th, om, sin, cos)
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

    /// The heat on each face and its rate in state y under `loads`.
    fn face_heat_of(&self, loads: Loads, y: &[f64]) -> FaceHeat {
        let m = self.thermal_size();
        let (sin, cos) = sin_cos(y[m]);
        let area = match self.coupling {
            Coupling::ProjectedArea => cos,
            Coupling::Frozen => 1.0,
        };
        self.face_heat(loads, area, self.area_rate(sin, y[m + 1]))
    }

    /// M_T of a state under `loads` (before the projected area), N m.
    pub fn moment_of(&self, loads: Loads, y: &[f64]) -> f64 {
        let m = self.thermal_size();
        match &self.thermal {
            Thermal::Nodal(_) => self.conduction.moment(&y[..m]),
            Thermal::Modal(r) => r.moment(&self.conduction, self.face_heat_of(loads, y), &y[..m]),
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

    /// Node temperatures of a state under `loads` (front first).
    pub fn node_temperatures(&self, loads: Loads, y: &[f64]) -> Vec<f64> {
        let m = self.thermal_size();
        match &self.thermal {
            Thermal::Nodal(_) => y[..m].to_vec(),
            Thermal::Modal(r) => {
                r.node_temperatures(&self.conduction, self.face_heat_of(loads, y), &y[..m])
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
    fn faces(&self, c: &Conduction, heat: [f64; 2], s: [f64; 2]) -> Faces {
        let sigma = [c.radiation_front, c.radiation_back];
        let s2 = [s[0] * s[0], s[1] * s[1]];
        // Radiation alone at the slow faces; b(u_slow) = radiated + heat.
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
            newton[0] * inv_det + jf[0][0] * heat[0] + jf[0][1] * heat[1],
            newton[1] * inv_det + jf[1][0] * heat[0] + jf[1][1] * heat[1],
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
            heat[0] - sigma[0] * (n2[0] * n2[0]),
            heat[1] - sigma[1] * (n2[1] * n2[1]),
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

    /// Rates of the kept modes (into dy[..m]) and the thermal moment, under the heat absorbed on
    /// each face `heat`; see [`Self::evaluate_rows`].
    #[inline(always)]
    fn evaluate(
        &self,
        c: &Conduction,
        heat: FaceHeat,
        amp: &[f64],
        dy: &mut [f64],
    ) -> (f64, [f64; 2], [f64; 2]) {
        // A state keeps a few slow modes: on a length known at compile time the pass over them
        // unrolls, without bounds checks.
        macro_rules! sized {
            ($($m:literal)*) => {
                match amp.len() {
                    $($m => {
                        let (rows, amp, dy) = kept::<$m>(&self.rows, amp, dy);
                        self.evaluate_rows(c, heat, rows, amp, dy)
                    })*
                    _ => self.evaluate_rows(c, heat, &self.rows, amp, dy),
                }
            };
        }
        sized!(1 2 3 4 5 6 7 8)
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
        heat: FaceHeat,
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
        } = self.faces(c, heat.heat, slow);
        // The lag needs ḃ = ḣ − D u̇ (ḣ: the rate of the heat absorbed on each face), with
        // (I + F D) u̇ = u̇_slow + F ḣ and the slow modes' zero-order face rates u̇_slow = P b −
        // (Σ φ_face,k λ_k q_k) (the Jacobian is taken at the slow faces: the difference is of the
        // next order in this first-order term). Written as ḃ = c − A b, with A = D J⁻¹ P and
        // c = ḣ + D J⁻¹ (decay − F ḣ), which do not wait for b.
        let f = &self.compliance;
        let heating_rate = heat.rate;
        let a = [
            [d[0] * inverse_gain[0][0], d[0] * inverse_gain[0][1]],
            [d[1] * inverse_gain[1][0], d[1] * inverse_gain[1][1]],
        ];
        // Without a load on the back its terms add zeros: the front's sunlight alone keeps its
        // arithmetic.
        let v = [
            decay[0] - f[0][0] * heating_rate[0] - f[0][1] * heating_rate[1],
            decay[1] - f[1][0] * heating_rate[0] - f[1][1] * heating_rate[1],
        ];
        let offset = [
            heating_rate[0] + d[0] * (inverse[0][0] * v[0] + inverse[0][1] * v[1]),
            heating_rate[1] + d[1] * (inverse[1][0] * v[0] + inverse[1][1] * v[1]),
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

    fn moment(&self, c: &Conduction, heat: FaceHeat, amp: &[f64]) -> f64 {
        Self::with_scratch(amp.len(), |dy| self.evaluate(c, heat, amp, dy).0)
    }

    fn node_temperatures(&self, c: &Conduction, heat: FaceHeat, amp: &[f64]) -> Vec<f64> {
        let n = c.nodes();
        let (_, b, b_rate) = Self::with_scratch(amp.len(), |dy| self.evaluate(c, heat, amp, dy));
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
