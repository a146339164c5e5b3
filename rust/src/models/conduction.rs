//! N-node heat conduction through the thickness of a laminate (finite volumes, vertex-centred).
//!
//! Nodes sit on both faces, on every layer interface and inside the layers; node i owns the half
//! of each element next to it (its heat capacity is lumped there), and neighbouring nodes exchange
//! heat through the element's conductance k/h. The faces radiate from the face nodes and the front
//! absorbs the solar flux there. Temperature is linear between nodes, which is how the thermal
//! moment M_T = ∫ E a (T − T_ref)(s_n − s) ds is integrated, exactly.
//!
//! With two nodes on one homogeneous layer this is eq. 2 of the paper: two face nodes, each with
//! half the heat capacity, joined by K, and a linear profile between them whose moment is
//! a E I (T_f − T_b)/d.
//!
//! Stiffness: thin metal layers make the conduction modes very fast (20 nodes through 1 mm of
//! aluminium: the fastest decays in ~10 µs) while the hinge moves in seconds. [`Modes`] holds the
//! modal decomposition of the conduction operator; [`crate::models::layered`] keeps the slow modes as
//! states and the fast ones quasi-static (exact in steady state), so that explicit steps are still
//! set by the hinge.

use crate::error::{Error, Result};
use crate::inputs::laminate::{linear_moment, Laminate};
use crate::inputs::panel::Panel;
use crate::models::thermal::ThermalModel;
use crate::models::thermal::STEFAN_BOLTZMANN;
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Most nodes through the thickness a model may have.
pub const MAX_NODES: usize = 1000;

/// The discretised conduction model of one laminate panel (per unit area, SI).
#[derive(Debug, Clone, PartialEq)]
pub struct Conduction {
    /// Depth of each node from the front face, m (front node first, back node last).
    pub depth: Vec<f64>,
    /// Heat capacity lumped at each node, J/(m² K).
    pub capacity: Vec<f64>,
    /// Conductance of the element between node e and e + 1, W/(m² K).
    pub conductance: Vec<f64>,
    /// Thermal moment per kelvin at each node, N m/K: M_T = Σ μ_i T_i − offset
    /// (whole width, with the panel's moment scale χ).
    pub moment_weight: Vec<f64>,
    /// Σ μ_i T_ref, N m.
    pub moment_offset: f64,
    /// Σ μ_i, N m/K (zero for a layup symmetric in E a about its neutral axis).
    pub moment_total: f64,
    /// T_ref, K.
    pub reference_temperature: f64,
    /// α C, W/m² absorbed at the front per unit flux factor.
    pub absorbed: f64,
    /// σ ε_f and σ ε_b, W/(m² K⁴).
    pub radiation_front: f64,
    pub radiation_back: f64,
    /// Index of the layer of each element.
    pub element_layer: Vec<usize>,
    /// The name of each layer of the layup.
    pub layer_names: Vec<String>,
    /// Built by [`Conduction::homogeneous`] with two nodes: eq. 2 itself, whose steady state is
    /// [`crate::analysis::steady::equilibrium`]'s.
    pub two_layer: bool,
}

/// How many elements each layer gets out of `elements` (at least one each): each further element
/// goes to the layer whose elements have the longest diffusion time (h/n)²/κ, so every element
/// relaxes on about the same time scale.
pub fn elements_per_layer(laminate: &Laminate, elements: usize) -> Vec<usize> {
    let weight: Vec<f64> = laminate
        .layers
        .iter()
        .map(|l| l.thickness / l.diffusivity().sqrt())
        .collect();
    let mut n = vec![1usize; weight.len()];
    for _ in weight.len()..elements {
        let mut best = 0;
        for i in 1..n.len() {
            if weight[i] / n[i] as f64 > weight[best] / n[best] as f64 {
                best = i;
            }
        }
        n[best] += 1;
    }
    n
}

impl Conduction {
    /// The model of `laminate` with `nodes` nodes through the thickness (at least one more than
    /// the number of layers, at most [`MAX_NODES`]). Surface properties (ε_f, ε_b, α), the solar
    /// constant, the width and the moment scale χ come from `panel`.
    pub fn new(panel: &Panel, laminate: &Laminate, nodes: usize) -> Result<Self> {
        panel.validate()?;
        laminate.validate()?;
        let n_layers = laminate.layers.len();
        if nodes < n_layers + 1 || nodes > MAX_NODES {
            return Err(Error::invalid(
                "layers",
                nodes,
                &format!(
                    "must be between {} (one more than the {n_layers} layer(s) of the layup) and {MAX_NODES}",
                    n_layers + 1
                ),
            ));
        }
        let per_layer = elements_per_layer(laminate, nodes - 1);
        let sn = laminate.neutral_axis();
        let scale = panel.width * panel.moment_scale;
        let mut depth = vec![0.0];
        let mut capacity = vec![0.0; nodes];
        let mut conductance = Vec::with_capacity(nodes - 1);
        let mut moment_weight = vec![0.0; nodes];
        let mut element_layer = Vec::with_capacity(nodes - 1);
        let interfaces = laminate.interfaces();
        for (li, (layer, &n)) in laminate.layers.iter().zip(&per_layer).enumerate() {
            let (top, bottom) = (interfaces[li], interfaces[li + 1]);
            let h = layer.thickness / n as f64;
            let ea = layer.youngs_modulus * layer.expansion_coeff * scale;
            for j in 0..n {
                let e = depth.len() - 1;
                let a = depth[e];
                // The last element of a layer ends exactly on the interface.
                let b = if j + 1 == n {
                    bottom
                } else {
                    top + (j + 1) as f64 * h
                };
                let he = b - a;
                depth.push(b);
                let half = 0.5 * layer.density * layer.specific_heat * he;
                capacity[e] += half;
                capacity[e + 1] += half;
                conductance.push(layer.conductivity / he);
                moment_weight[e] += ea * linear_moment(a, b, sn, 1.0, 0.0);
                moment_weight[e + 1] += ea * linear_moment(a, b, sn, 0.0, 1.0);
                element_layer.push(li);
            }
        }
        let moment_total: f64 = moment_weight.iter().sum();
        let moment_offset = moment_total * laminate.reference_temperature;
        Ok(Conduction {
            depth,
            capacity,
            conductance,
            moment_weight,
            moment_offset,
            moment_total,
            reference_temperature: laminate.reference_temperature,
            absorbed: panel.absorptivity * panel.solar_constant,
            radiation_front: STEFAN_BOLTZMANN * panel.emissivity_front,
            radiation_back: STEFAN_BOLTZMANN * panel.emissivity_back,
            element_layer,
            layer_names: laminate.layers.iter().map(|l| l.name.clone()).collect(),
            two_layer: false,
        })
    }

    /// The model of a plain panel: one homogeneous layer ([`Laminate::homogeneous`]) on equal
    /// elements, with its coefficients taken straight from the panel so that two nodes give
    /// eq. 2's coefficients to the bit: capacities m c/(N−1) (half at the faces), conductances
    /// K (N−1), and moment weights χ a E I/d × ν_i, with ν_i = 12 ∫ φ_i (1/2 − ξ) dξ in the
    /// thickness coordinate ξ = s/d (ν = ±(3δ − 2δ²) at the faces, 6δ − 12 i δ² inside,
    /// δ = 1/(N−1)).
    pub fn homogeneous(panel: &Panel, nodes: usize) -> Result<Self> {
        // Validation (and the node count's range) as for any laminate.
        let mut c = Self::new(panel, &Laminate::homogeneous(panel), nodes)?;
        let elements = (nodes - 1) as f64;
        let delta = 1.0 / elements;
        let d = panel.thickness;
        let interior = panel.heat_capacity() / elements;
        let face = 0.5 * panel.heat_capacity() / elements;
        let per_kelvin = panel.moment_per_kelvin();
        let face_weight = 3.0 * delta - 2.0 * delta * delta;
        for i in 0..nodes {
            let last = i + 1 == nodes;
            c.depth[i] = if last { d } else { i as f64 * d / elements };
            c.capacity[i] = if i == 0 || last { face } else { interior };
            let nu = if i == 0 {
                face_weight
            } else if last {
                -face_weight
            } else {
                6.0 * delta - 12.0 * i as f64 * delta * delta
            };
            c.moment_weight[i] = per_kelvin * nu;
        }
        for g in c.conductance.iter_mut() {
            *g = panel.conductance * elements;
        }
        // A homogeneous plate bends with the gradient only: no reference temperature.
        c.moment_offset = 0.0;
        c.moment_total = 0.0;
        c.two_layer = nodes == 2;
        Ok(c)
    }

    pub fn nodes(&self) -> usize {
        self.capacity.len()
    }

    /// Where each node sits, front to back: "front, L" and "back, L" for the face nodes of
    /// layers L, "L|M" for a node on the interface of layers L and M, and "L" inside layer L.
    pub fn node_labels(&self) -> Vec<String> {
        let n = self.nodes();
        let name = |e: usize| self.layer_names[self.element_layer[e]].as_str();
        (0..n)
            .map(|i| {
                if i == 0 {
                    format!("front, {}", name(0))
                } else if i + 1 == n {
                    format!("back, {}", name(n - 2))
                } else if self.element_layer[i - 1] != self.element_layer[i] {
                    format!("{}|{}", name(i - 1), name(i))
                } else {
                    name(i).to_string()
                }
            })
            .collect()
    }

    /// Total heat capacity per unit area, J/(m² K).
    pub fn total_capacity(&self) -> f64 {
        self.capacity.iter().sum()
    }

    /// Heat flowing into the two face nodes from outside, W/m²: absorbed minus emitted at the
    /// front (flux factor `flux` already includes the projected area), emitted at the back.
    #[inline(always)]
    pub fn face_inputs(&self, flux: f64, t_front: f64, t_back: f64) -> (f64, f64) {
        let f4 = (t_front * t_front) * (t_front * t_front);
        let b4 = (t_back * t_back) * (t_back * t_back);
        (
            self.absorbed * flux - self.radiation_front * f4,
            -self.radiation_back * b4,
        )
    }

    /// Net heat flow into every node, W/m² (writes into `out`): the face inputs and conduction.
    pub fn node_flows(&self, flux: f64, t: &[f64], out: &mut [f64]) {
        let n = self.nodes();
        let (qf, qb) = self.face_inputs(flux, t[0], t[n - 1]);
        out.fill(0.0);
        out[0] += qf;
        out[n - 1] += qb;
        for e in 0..n - 1 {
            let q = self.conductance[e] * (t[e] - t[e + 1]);
            out[e] -= q;
            out[e + 1] += q;
        }
    }

    /// The moment scale of [`ThermalModel`]: the moment per kelvin of a linear profile's
    /// face-to-face difference, N m/K (χ a E I / d for a homogeneous plate); 1 if that is zero.
    pub fn moment_per_face_kelvin(&self) -> f64 {
        let d = self.depth[self.nodes() - 1];
        let m: f64 = self
            .moment_weight
            .iter()
            .zip(&self.depth)
            .map(|(mu, s)| mu * (1.0 - s / d))
            .sum();
        if m != 0.0 && m.is_finite() {
            m
        } else {
            1.0
        }
    }

    /// M_T of a nodal temperature profile, N m: Σ μ_i (T_i − T_0) + Σ μ_i (T_0 − T_ref), the
    /// form that keeps the large Σ μ_i T_i from cancelling.
    pub fn moment(&self, t: &[f64]) -> f64 {
        let t0 = t[0];
        let mut m = 0.0;
        for (mu, x) in self.moment_weight.iter().zip(t) {
            m += mu * (x - t0);
        }
        m + self.moment_total * (t0 - self.reference_temperature)
    }

    /// The conduction matrix K (symmetric, tridiagonal): C dT/dt = −K T + face inputs.
    pub fn conduction_matrix(&self) -> DMatrix<f64> {
        let n = self.nodes();
        let mut k = DMatrix::zeros(n, n);
        for (e, &g) in self.conductance.iter().enumerate() {
            k[(e, e)] += g;
            k[(e + 1, e + 1)] += g;
            k[(e, e + 1)] -= g;
            k[(e + 1, e)] -= g;
        }
        k
    }

    /// Steady profile under a constant flux factor (projected area included): Newton on the N
    /// heat balances, from the isothermal plate's temperature.
    pub fn steady_profile(&self, flux: f64) -> Result<Vec<f64>> {
        if !(flux.is_finite() && flux > 0.0) {
            return Err(Error::invalid("flux", flux, "must be finite and > 0"));
        }
        let n = self.nodes();
        let t0 = (self.absorbed * flux / (self.radiation_front + self.radiation_back)).powf(0.25);
        let k = self.conduction_matrix();
        let residual_and_jacobian = |t: &DVector<f64>| {
            let (qf, qb) = self.face_inputs(flux, t[0], t[n - 1]);
            let mut f = -(&k * t);
            f[0] += qf;
            f[n - 1] += qb;
            let mut jac = -k.clone();
            jac[(0, 0)] -= 4.0 * self.radiation_front * t[0].powi(3);
            jac[(n - 1, n - 1)] -= 4.0 * self.radiation_back * t[n - 1].powi(3);
            (f, jac)
        };
        let settled = |t: &DVector<f64>, dt: &DVector<f64>| dt.amax() < 1e-12 * t.amax();
        let t = crate::numerics::newton::newton(
            "steady profile",
            DVector::from_element(n, t0),
            n,
            residual_and_jacobian,
            settled,
        )?;
        Ok(t.iter().copied().collect())
    }

    /// The conduction modes: K φ = λ C φ, φᵀ C φ = C_tot (so the first, uniform mode has unit
    /// entries and its amplitude is the capacity-weighted mean temperature), λ increasing.
    pub fn modes(&self) -> Modes {
        let n = self.nodes();
        let root: Vec<f64> = self.capacity.iter().map(|c| c.sqrt()).collect();
        let k = self.conduction_matrix();
        let sym = DMatrix::from_fn(n, n, |i, j| k[(i, j)] / (root[i] * root[j]));
        let eig = SymmetricEigen::new(sym);
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let total = self.total_capacity();
        let mut shapes = DMatrix::zeros(n, n);
        let mut rates = Vec::with_capacity(n);
        for (col, &k) in order.iter().enumerate() {
            let v = eig.eigenvectors.column(k);
            // Unit-norm v gives φᵀCφ = 1; scale to C_tot, and fix the sign by the front node.
            let sign = if v[0] < 0.0 { -1.0 } else { 1.0 };
            for i in 0..n {
                shapes[(i, col)] = sign * total.sqrt() * v[i] / root[i];
            }
            // The uniform mode's rate is zero up to rounding; make it exactly zero.
            rates.push(if col == 0 {
                0.0
            } else {
                eig.eigenvalues[k].max(0.0)
            });
        }
        Modes {
            rates,
            shapes,
            total_capacity: total,
        }
    }
}

/// The nodal model as a thermal model of the engine's seam: temperatures front to back, the
/// thermal moment as an equivalent face-to-face difference times
/// [`Conduction::moment_per_face_kelvin`]. (Laminates through the Python API run on
/// [`crate::models::layered`], which also removes the fast conduction modes.)
impl ThermalModel for Conduction {
    fn size(&self) -> usize {
        self.nodes()
    }
    fn names(&self) -> Vec<String> {
        let n = self.nodes();
        (0..n)
            .map(|i| match i {
                0 => "T_front".to_string(),
                i if i + 1 == n => "T_back".to_string(),
                i => format!("T_{i}"),
            })
            .collect()
    }
    fn heat_flows(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        self.node_flows(flux, temps, out);
    }
    fn capacity(&self, i: usize) -> f64 {
        self.capacity[i]
    }
    fn gradient(&self, temps: &[f64]) -> f64 {
        self.moment(temps) / self.moment_per_face_kelvin()
    }
    fn moment_per_kelvin(&self) -> f64 {
        self.moment_per_face_kelvin()
    }
    fn initial_guess(&self, flux: f64, out: &mut [f64]) {
        let t = (self.absorbed * flux / (self.radiation_front + self.radiation_back)).powf(0.25);
        out.fill(t);
    }
}

/// Modal decomposition of the conduction operator.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// λ_k, 1/s, increasing (λ₀ = 0: the uniform mode).
    pub rates: Vec<f64>,
    /// φ_k as columns (node × mode), normalised to φᵀ C φ = C_tot.
    pub shapes: DMatrix<f64>,
    pub total_capacity: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::laminate::{Layer, MATERIALS};

    fn panel() -> Panel {
        Panel::paper()
    }

    #[test]
    fn two_nodes_on_a_plain_panel_are_equation_two() {
        let p = panel();
        let c = Conduction::homogeneous(&p, 2).unwrap();
        let y = [381.0, 363.0];
        let mut rate = [0.0; 2];
        for flux in [0.0, 1.0, 0.97] {
            c.rates(flux, &y, &mut rate);
            let (df, db) = crate::models::thermal::two_layer_rates(&p, flux, y[0], y[1]);
            assert!((rate[0] - df).abs() < 1e-14 * df.abs().max(1e-3));
            assert!((rate[1] - db).abs() < 1e-14 * db.abs().max(1e-3));
        }
        let m = crate::models::hinge::thermal_moment(&p, y[0], y[1]);
        assert!((c.moment(&y) / m - 1.0).abs() < 1e-13);
    }

    #[test]
    fn linear_profile_moment_is_a_e_i_dt_over_d_for_any_node_count() {
        let p = panel();
        for nodes in [2, 3, 7, 40] {
            let c = Conduction::homogeneous(&p, nodes).unwrap();
            let d = p.thickness;
            let t: Vec<f64> = c
                .depth
                .iter()
                .map(|s| 350.0 + 12.0 * (1.0 - s / d))
                .collect();
            let want = p.expansion_coeff * p.youngs_modulus * p.bending_inertia * 12.0 / d;
            assert!((c.moment(&t) / want - 1.0).abs() < 1e-12, "{nodes}");
        }
    }

    #[test]
    fn capacity_and_resistance_add_up() {
        let lam = crate::inputs::laminate::wing_layup();
        let c = Conduction::new(&panel(), &lam, 20).unwrap();
        assert_eq!(c.nodes(), 20);
        assert!((c.total_capacity() / lam.heat_capacity() - 1.0).abs() < 1e-14);
        let r: f64 = c.conductance.iter().map(|g| 1.0 / g).sum();
        assert!((r / lam.thermal_resistance() - 1.0).abs() < 1e-14);
        assert!((c.depth[19] - lam.thickness()).abs() < 1e-18);
        assert!(Conduction::new(&panel(), &lam, 4).is_err());
        assert!(Conduction::new(&panel(), &lam, 5).is_ok());
        // One node per layer boundary, labelled with both layers; faces with theirs.
        let labels = c.node_labels();
        assert_eq!(labels[0], format!("front, {}", lam.layers[0].name));
        assert_eq!(labels[19], format!("back, {}", lam.layers[3].name));
        let interfaces: Vec<&String> = labels.iter().filter(|l| l.contains('|')).collect();
        assert_eq!(interfaces.len(), 3, "{labels:?}");
        assert_eq!(
            interfaces[1],
            &format!("{}|{}", lam.layers[1].name, lam.layers[2].name)
        );
    }

    #[test]
    fn modes_diagonalise_the_conduction() {
        let lam = Laminate {
            layers: vec![
                MATERIALS[0].layer(1e-3),
                Layer {
                    name: "glue".into(),
                    ..MATERIALS[4].layer(0.1e-3)
                },
            ],
            emissivity_front: 0.5,
            emissivity_back: 0.5,
            absorptivity: 0.5,
            reference_temperature: 293.15,
        };
        let c = Conduction::new(&panel(), &lam, 12).unwrap();
        let m = c.modes();
        let k = c.conduction_matrix();
        let cap = DMatrix::from_diagonal(&DVector::from_vec(c.capacity.clone()));
        let phi = &m.shapes;
        let gram = phi.transpose() * &cap * phi / m.total_capacity;
        let stiff = phi.transpose() * &k * phi / m.total_capacity;
        for i in 0..12 {
            for j in 0..12 {
                let id = if i == j { 1.0 } else { 0.0 };
                assert!((gram[(i, j)] - id).abs() < 1e-10, "gram {i} {j}");
                let want = if i == j { m.rates[i] } else { 0.0 };
                assert!((stiff[(i, j)] - want).abs() < 1e-9 * m.rates[11], "{i} {j}");
            }
        }
        assert!(phi.column(0).iter().all(|v| (v - 1.0).abs() < 1e-10));
    }

    /// A homogeneous slab (d = 5 mm of aluminium-like metal with a poor conductivity, so that the
    /// gradient is large) radiating from both faces.
    fn slab() -> (Panel, Laminate) {
        let p = Panel {
            thickness: 5e-3,
            ..Panel::paper()
        };
        let lam = Laminate {
            layers: vec![Layer {
                thickness: 5e-3,
                conductivity: 0.5,
                density: 2000.0,
                specific_heat: 900.0,
                youngs_modulus: 70e9,
                expansion_coeff: 2e-5,
                name: "slab".into(),
            }],
            emissivity_front: p.emissivity_front,
            emissivity_back: p.emissivity_back,
            absorptivity: p.absorptivity,
            reference_temperature: 293.15,
        };
        (p, lam)
    }

    /// The exact steady state of a slab (or any stack) with radiating faces: one heat flux q
    /// crosses the whole stack, so the profile is linear in each layer with
    /// T_f − T_b = q R, q = σ ε_b T_b⁴ and α C = σ ε_f T_f⁴ + σ ε_b T_b⁴. Solved by bisection on
    /// T_b, independently of the model's Newton solve.
    fn exact_steady(p: &Panel, lam: &Laminate) -> (f64, f64) {
        let sigma = STEFAN_BOLTZMANN;
        let absorbed = p.absorptivity * p.solar_constant;
        let r = lam.thermal_resistance();
        let residual = |tb: f64| {
            let q = sigma * p.emissivity_back * tb.powi(4);
            let tf = tb + q * r;
            sigma * p.emissivity_front * tf.powi(4) + q - absorbed
        };
        let (mut lo, mut hi) = (1.0, 1000.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if residual(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let tb = 0.5 * (lo + hi);
        (tb + sigma * p.emissivity_back * tb.powi(4) * r, tb)
    }

    #[test]
    fn steady_profile_is_the_exact_conduction_solution_at_every_node_count() {
        // Nodes on both faces and on every interface make the piecewise-linear steady profile
        // exact for any node count: the error stays at rounding as the nodes double (the
        // "order" is unbounded), for a slab and for a four-layer sandwich.
        let (p, slab) = slab();
        let sandwich = Laminate {
            layers: vec![
                MATERIALS[4].layer(50e-6),
                MATERIALS[2].layer(0.3e-3),
                MATERIALS[3].layer(20e-3),
                MATERIALS[2].layer(0.3e-3),
            ],
            ..slab.clone()
        };
        for lam in [&slab, &sandwich] {
            let (tf, tb) = exact_steady(&p, lam);
            let q = STEFAN_BOLTZMANN * p.emissivity_back * tb.powi(4);
            assert!(tf - tb > 1.0, "the test needs a real gradient: {}", tf - tb);
            let mut errors = Vec::new();
            for nodes in [5, 10, 20, 40, 80] {
                let c = Conduction::new(&p, lam, nodes).unwrap();
                let t = c.steady_profile(1.0).unwrap();
                // Exact profile: T_f minus q × resistance from the front face to the node.
                let err = (0..nodes)
                    .map(|i| {
                        let s = c.depth[i];
                        let mut r = 0.0;
                        let mut top = 0.0;
                        for l in &lam.layers {
                            r += (s.min(top + l.thickness) - top).max(0.0) / l.conductivity;
                            top += l.thickness;
                        }
                        (t[i] - (tf - q * r)).abs() / tf
                    })
                    .fold(0.0, f64::max);
                errors.push(err);
            }
            println!("steady profile, max relative nodal error at 5..80 nodes: {errors:?}");
            assert!(errors.iter().all(|&e| e < 1e-12), "{errors:?}");
        }
    }

    /// Carslaw & Jaeger (Conduction of Heat in Solids, 2nd ed., §3.3): slab 0 < x < L initially
    /// at T0, insulated at x = 0, constant flux q into the face x = L from t = 0:
    /// T − T0 = q t/(ρ c L) + (q L/k) [(3x² − L²)/(6L²)
    ///          − (2/π²) Σ (−1)ⁿ/n² exp(−κ n² π² t/L²) cos(nπx/L)].
    fn carslaw_jaeger(q: f64, k: f64, rho_c: f64, l: f64, x: f64, t: f64) -> f64 {
        let kappa = k / rho_c;
        let mut series = 0.0;
        for n in 1..2000 {
            let nf = n as f64;
            let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
            let decay = (-kappa * nf * nf * std::f64::consts::PI.powi(2) * t / (l * l)).exp();
            series += sign / (nf * nf) * decay * (nf * std::f64::consts::PI * x / l).cos();
        }
        q * t / (rho_c * l)
            + q * l / k
                * ((3.0 * x * x - l * l) / (6.0 * l * l)
                    - 2.0 / std::f64::consts::PI.powi(2) * series)
    }

    #[test]
    fn step_of_flux_converges_to_the_series_solution_at_second_order() {
        // Radiation off (a linear problem with the classical solution); the model's own
        // semi-discrete solution is evaluated exactly through its modes, so the error measured is
        // that of the discretisation in space alone.
        let (p, lam) = slab();
        let layer = &lam.layers[0];
        let (k, rho_c, l) = (
            layer.conductivity,
            layer.density * layer.specific_heat,
            layer.thickness,
        );
        let q = 1000.0;
        let fourier = [0.02, 0.1, 0.5];
        let mut errors = Vec::new();
        for nodes in [5, 9, 17, 33, 65] {
            let mut c = Conduction::new(&p, &lam, nodes).unwrap();
            c.radiation_front = 0.0;
            c.radiation_back = 0.0;
            let m = c.modes();
            let mut worst: f64 = 0.0;
            for fo in fourier {
                let t = fo * l * l * rho_c / k;
                for i in 0..nodes {
                    let mut rise = 0.0;
                    for (j, &lam_j) in m.rates.iter().enumerate() {
                        let force = m.shapes[(0, j)] * q / m.total_capacity;
                        let amp = if j == 0 {
                            force * t
                        } else {
                            force * (1.0 - (-lam_j * t).exp()) / lam_j
                        };
                        rise += m.shapes[(i, j)] * amp;
                    }
                    // The model's front face (depth 0) is the series' heated face x = L.
                    let x = l - c.depth[i];
                    let exact = carslaw_jaeger(q, k, rho_c, l, x, t);
                    worst = worst.max((rise - exact).abs() / (q * l / k));
                }
            }
            errors.push(worst);
        }
        let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        println!("step of flux: max error / (q L/k) at 5..65 nodes {errors:?}, orders {orders:?}");
        for &o in &orders[1..] {
            assert!((o - 2.0).abs() < 0.15, "observed order {o}: {orders:?}");
        }
        assert!(errors[4] < 2e-4, "{errors:?}");
    }
}
