//! The panel as an Euler–Bernoulli beam of Hermite cubic elements (the element matrices of
//! [`crate::models::beam`]), on either support, and its modal reduction under element-wise thermal
//! moments.
//!
//! Degrees of freedom: node j (x = j h, h = L/n) carries the deflection w_j and the slope w'_j.
//! w is positive away from the Sun (towards the back face), so a hot front face (M_T > 0) bends
//! the panel to w'' = M_T/EI > 0: the tips of a free panel rise away from the Sun, as the hinge
//! model's halves do for θ > 0. The cantilever is clamped at x = 0 (w₀ = w'₀ = 0, those two
//! degrees of freedom removed); the free–free panel keeps all of them and sets its two rigid-body
//! modes apart (inertia relief: a thermal load is self-equilibrated and does no work on them).
//!
//! An element's constant thermal moment M_e loads it with the consistent nodal loads of the
//! virtual work ∫ M_e δw'' dx = M_e (δw'₂ − δw'₁): −M_e on the slope of its first node, +M_e on
//! that of its second. A uniform moment thus reduces to the comparator's two end moments.

use crate::error::{Error, Result};
use crate::inputs::panel::Panel;
use crate::models::beam::{assemble_uniform, element_mass, element_stiffness, generalised_modes};
use nalgebra::{Cholesky, DMatrix, DVector};

/// Largest element count accepted: the modes come from a dense eigenproblem, O((2n)³), and the
/// right-hand side holds an n × n residual-flexibility product.
pub const MAX_ELEMENTS: usize = 400;

/// β₁L of the first cantilever bending mode (root of cos x cosh x = −1).
pub const CANTILEVER_BETA1_L: f64 = 1.875_104_068_711_961;

/// How the panel is held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Support {
    /// Free in space, attitude held by the spacecraft (the paper's panel).
    FreeFree,
    /// Clamped at x = 0 to a rigid bus (a boom or an array wing).
    Cantilever,
}

impl Support {
    pub fn from_name(name: &str) -> Result<Support> {
        match name {
            "free-free" => Ok(Support::FreeFree),
            "cantilever" => Ok(Support::Cantilever),
            other => Err(Error::invalid(
                "support",
                format!("{other:?}"),
                "must be 'free-free' or 'cantilever'",
            )),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Support::FreeFree => "free-free",
            Support::Cantilever => "cantilever",
        }
    }

    /// Number of rigid-body modes the support leaves free.
    pub fn rigid_modes(self) -> usize {
        match self {
            Support::FreeFree => 2,
            Support::Cantilever => 0,
        }
    }

    /// Full-index offset of the first free degree of freedom (the clamp removes w₀, w'₀).
    fn offset(self) -> usize {
        match self {
            Support::FreeFree => 0,
            Support::Cantilever => 2,
        }
    }
}

/// The mesh: n equal elements over the panel length, on a support.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    pub support: Support,
    pub n_elements: usize,
    /// L, m.
    pub length: f64,
    /// E I, N m².
    pub flexural_rigidity: f64,
    /// m, kg/m.
    pub mass_per_length: f64,
}

impl Mesh {
    /// `n_elements` between 2 and [`MAX_ELEMENTS`]; any parity (θ_f reads the centre by the
    /// element's own cubic when the centre is not a node).
    pub fn new(panel: &Panel, support: Support, n_elements: usize) -> Result<Self> {
        panel.validate()?;
        if !(2..=MAX_ELEMENTS).contains(&n_elements) {
            return Err(Error::invalid(
                "elements",
                n_elements,
                &format!("must be between 2 and {MAX_ELEMENTS}"),
            ));
        }
        Ok(Mesh {
            support,
            n_elements,
            length: panel.length,
            flexural_rigidity: panel.youngs_modulus * panel.bending_inertia,
            mass_per_length: panel.mass_per_length,
        })
    }

    /// h = L/n, m.
    pub fn element_length(&self) -> f64 {
        self.length / self.n_elements as f64
    }

    /// Number of free degrees of freedom.
    pub fn dofs(&self) -> usize {
        2 * (self.n_elements + 1) - self.support.offset()
    }

    /// Number of elastic modes the mesh has.
    pub fn elastic_modes(&self) -> usize {
        self.dofs() - self.support.rigid_modes()
    }

    /// Node positions, m.
    pub fn node_x(&self) -> Vec<f64> {
        let h = self.element_length();
        (0..=self.n_elements).map(|j| j as f64 * h).collect()
    }

    /// Element centres, m.
    pub fn element_x(&self) -> Vec<f64> {
        let h = self.element_length();
        (0..self.n_elements).map(|e| (e as f64 + 0.5) * h).collect()
    }

    /// The full matrix restricted to the free degrees of freedom.
    fn restrict(&self, full: DMatrix<f64>) -> DMatrix<f64> {
        let o = self.support.offset();
        let n = self.dofs();
        full.view((o, o), (n, n)).into_owned()
    }

    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        let e = element_stiffness(self.flexural_rigidity, self.element_length());
        self.restrict(assemble_uniform(self.n_elements, &e))
    }

    pub fn mass_matrix(&self) -> DMatrix<f64> {
        let e = element_mass(self.mass_per_length, self.element_length());
        self.restrict(assemble_uniform(self.n_elements, &e))
    }

    /// Free index of the full degree of freedom `full` (None where the clamp removed it).
    fn free(&self, full: usize) -> Option<usize> {
        full.checked_sub(self.support.offset())
    }

    /// Load matrix B (dofs × n): column e holds element e's consistent nodal loads per unit
    /// thermal moment, −1 on the slope of node e and +1 on that of node e + 1.
    pub fn moment_load(&self) -> DMatrix<f64> {
        let mut b = DMatrix::zeros(self.dofs(), self.n_elements);
        for e in 0..self.n_elements {
            if let Some(i) = self.free(2 * e + 1) {
                b[(i, e)] = -1.0;
            }
            let i = self
                .free(2 * e + 3)
                .expect("the second node of an element is never clamped");
            b[(i, e)] = 1.0;
        }
        b
    }

    /// Reader D (n × dofs) of the element chord slopes (w_{e+1} − w_e)/h.
    pub fn chord_slope_reader(&self) -> DMatrix<f64> {
        let h = self.element_length();
        let mut d = DMatrix::zeros(self.n_elements, self.dofs());
        for e in 0..self.n_elements {
            if let Some(i) = self.free(2 * e) {
                d[(e, i)] = -1.0 / h;
            }
            d[(e, self.free(2 * e + 2).unwrap())] = 1.0 / h;
        }
        d
    }

    /// Row reading the deflection at x (m) from the free degrees of freedom: the Hermite cubic of
    /// the element holding x.
    pub fn deflection_reader(&self, x: f64) -> DVector<f64> {
        let h = self.element_length();
        let e = ((x / h).floor() as usize).min(self.n_elements - 1);
        let s = x / h - e as f64;
        // Hermite shape functions on (w₁, w₁', w₂, w₂').
        let n = [
            1.0 - 3.0 * s * s + 2.0 * s * s * s,
            h * (s - 2.0 * s * s + s * s * s),
            3.0 * s * s - 2.0 * s * s * s,
            h * (s * s * s - s * s),
        ];
        let mut r = DVector::zeros(self.dofs());
        for (k, v) in n.iter().enumerate() {
            if let Some(i) = self.free(2 * e + k) {
                r[i] += v;
            }
        }
        r
    }

    /// Arm of the hinge-equivalent angle: L/2 for the free panel (centre to tip), L for the
    /// cantilever (root to tip), m.
    pub fn arm(&self) -> f64 {
        match self.support {
            Support::FreeFree => 0.5 * self.length,
            Support::Cantilever => self.length,
        }
    }

    /// Row reading the rise of the tip over the arm's base, whose ratio to [`Mesh::arm`] is
    /// sin θ_f: free–free, the mean of the two tips minus the centre, η = (w(0) + w(L))/2 − w(L/2)
    /// (the paper's η_f; θ_f = asin(2η/L)); cantilever, the tip deflection w(L) (the root does not
    /// move; θ_f = asin(w(L)/L), the angle of a rigid arm hinged at the root with the same tip).
    pub fn rise_reader(&self) -> DVector<f64> {
        let tip = self.deflection_reader(self.length);
        match self.support {
            Support::FreeFree => {
                (self.deflection_reader(0.0) + tip) * 0.5
                    - self.deflection_reader(0.5 * self.length)
            }
            Support::Cantilever => tip,
        }
    }

    /// The free–free rigid-body modes (translation, rotation about the centre), mass-orthonormal.
    fn rigid_shapes(&self, m: &DMatrix<f64>) -> DMatrix<f64> {
        let n = self.dofs();
        let h = self.element_length();
        let c = 0.5 * self.length;
        let mut r = DMatrix::zeros(n, 2);
        for j in 0..=self.n_elements {
            r[(2 * j, 0)] = 1.0;
            r[(2 * j, 1)] = j as f64 * h - c;
            r[(2 * j + 1, 1)] = 1.0;
        }
        // Gram–Schmidt in the mass inner product (the pair is already orthogonal for a uniform
        // panel about its centre; this keeps it so to rounding).
        for col in 0..2 {
            let mut v = r.column(col).into_owned();
            for prev in 0..col {
                let p = r.column(prev).into_owned();
                v -= &p * p.dot(&(m * &v));
            }
            let norm = v.dot(&(m * &v)).sqrt();
            r.set_column(col, &(v / norm));
        }
        r
    }

    /// Static deflection under unit thermal moment in each element, S (dofs × n), solved
    /// directly rather than summed over modes. Free–free: (K + M Φ_r Φ_rᵀ M) w = B, whose
    /// solution for a self-equilibrated load is the elastic one with no rigid-body part (mean
    /// axes: Φ_rᵀ M w = 0), which is what inertia relief computes.
    pub fn static_flexibility(&self) -> Result<DMatrix<f64>> {
        let k = self.stiffness_matrix();
        let a = match self.support {
            Support::Cantilever => k,
            Support::FreeFree => {
                let m = self.mass_matrix();
                let r = self.rigid_shapes(&m);
                let mr = &m * r;
                k + &mr * mr.transpose()
            }
        };
        let chol = Cholesky::new(a).ok_or_else(|| Error::NoConvergence {
            what: "static deflection".into(),
            reason: "the stiffness matrix is not positive definite".into(),
        })?;
        Ok(chol.solve(&self.moment_load()))
    }

    /// Elastic modes: ω² ascending and mass-normalised shapes (dofs × count), the rigid-body
    /// pair of the free panel set apart.
    pub fn elastic_modes_all(&self) -> Result<(Vec<f64>, DMatrix<f64>)> {
        let (eig, shapes) =
            generalised_modes(self.stiffness_matrix(), self.mass_matrix(), "panel modes")?;
        let r = self.support.rigid_modes();
        if eig.len() <= r || (r > 0 && eig[r - 1].abs() > 1e-6 * eig[r]) {
            return Err(Error::NoConvergence {
                what: "panel modes".into(),
                reason: format!(
                    "the rigid-body modes did not separate (ω² = {:?})",
                    &eig[..eig.len().min(r + 1)]
                ),
            });
        }
        let n = eig.len() - r;
        Ok((eig[r..].to_vec(), shapes.columns(r, n).into_owned()))
    }
}

/// The modal reduction: the first `k` elastic modes as dynamic coordinates q (with w = Φ q + R M
/// for element moments M), every other mode quasi-static through the residual flexibility R.
#[derive(Debug, Clone)]
pub struct Reduction {
    pub mesh: Mesh,
    /// ω of the kept modes, rad/s, ascending.
    pub omega: Vec<f64>,
    /// Kept shapes Φ (dofs × k).
    pub shapes: DMatrix<f64>,
    /// Modal force per unit element moment, G = Φᵀ B (k × n).
    pub force: DMatrix<f64>,
    /// Residual flexibility R = S − Φ diag(1/ω²) G (dofs × n).
    pub residual: DMatrix<f64>,
    /// Chord slope per unit modal coordinate, D Φ (n × k).
    pub slope_modal: DMatrix<f64>,
    /// Chord slope per unit element moment through the residual, D R (n × n).
    pub slope_residual: DMatrix<f64>,
    /// Static chord slope per unit element moment, D S (n × n).
    pub slope_static: DMatrix<f64>,
    /// Tip rise per unit modal coordinate (k) and per unit element moment through R (n).
    pub rise_modal: DVector<f64>,
    pub rise_residual: DVector<f64>,
    /// Free–free only: the rigid rotation's mass-weighted reader Mφ_rot (dofs) and its constant
    /// chord slope, to put the integrated static shape in mean axes.
    rotation: Option<(DVector<f64>, f64)>,
}

impl Reduction {
    /// Keeps `k` elastic modes, between 1 and what the mesh has.
    pub fn new(mesh: Mesh, k: usize) -> Result<Self> {
        let available = mesh.elastic_modes();
        if k < 1 || k > available {
            return Err(Error::invalid(
                "modes",
                k,
                &format!(
                    "must be between 1 and {available} (the elastic modes of {} elements)",
                    mesh.n_elements
                ),
            ));
        }
        let (eig, all) = mesh.elastic_modes_all()?;
        let omega: Vec<f64> = eig[..k].iter().map(|l| l.sqrt()).collect();
        let shapes = all.columns(0, k).into_owned();
        let b = mesh.moment_load();
        let force = shapes.transpose() * &b;
        let s = mesh.static_flexibility()?;
        let mut modal_static = force.clone();
        for (i, w) in omega.iter().enumerate() {
            modal_static.row_mut(i).scale_mut(1.0 / (w * w));
        }
        let residual = &s - &shapes * modal_static;
        let d = mesh.chord_slope_reader();
        let rise = mesh.rise_reader();
        let rotation = match mesh.support {
            Support::Cantilever => None,
            Support::FreeFree => {
                let m = mesh.mass_matrix();
                let rot = mesh.rigid_shapes(&m).column(1).into_owned();
                Some((&m * &rot, rot[1]))
            }
        };
        Ok(Reduction {
            rotation,
            slope_modal: &d * &shapes,
            slope_residual: &d * &residual,
            slope_static: &d * &s,
            rise_modal: shapes.transpose() * &rise,
            rise_residual: residual.transpose() * &rise,
            omega,
            shapes,
            force,
            residual,
            mesh,
        })
    }

    /// Static chord slopes under element moments, D S M, in O(n): the static shape of element-wise
    /// constant curvature M_e/EI is piecewise quadratic, which the cubic elements hold exactly,
    /// so it is integrated from node 0 (slope and deflection zero: the clamp, or a gauge) and, for
    /// the free panel, rotated into mean axes (Φ_rᵀ M w = 0; the translation moves no chord).
    pub fn static_slopes(&self, moments: &[f64], out: &mut [f64]) {
        let h = self.mesh.element_length();
        let ei = self.mesh.flexural_rigidity;
        let (mut w, mut slope, mut weighted) = (0.0, 0.0, 0.0);
        for (e, m) in moments.iter().enumerate() {
            let kappa = m / ei;
            out[e] = slope + 0.5 * kappa * h;
            if let Some((p, _)) = &self.rotation {
                weighted += p[2 * e] * w + p[2 * e + 1] * slope;
            }
            w += (slope + 0.5 * kappa * h) * h;
            slope += kappa * h;
        }
        if let Some((p, chord)) = &self.rotation {
            let n = moments.len();
            weighted += p[2 * n] * w + p[2 * n + 1] * slope;
            for v in out.iter_mut() {
                *v -= chord * weighted;
            }
        }
    }

    /// Number of kept modes.
    pub fn modes(&self) -> usize {
        self.omega.len()
    }

    /// Deflections (dofs) from the modal coordinates and the element moments.
    pub fn deflection(&self, q: &[f64], moments: &[f64]) -> DVector<f64> {
        let q = DVector::from_column_slice(q);
        let m = DVector::from_column_slice(moments);
        &self.shapes * q + &self.residual * m
    }

    /// Nodal deflections and slopes (n + 1 each, zero at the clamp) from the free ones.
    pub fn nodal(&self, w: &DVector<f64>) -> (Vec<f64>, Vec<f64>) {
        let o = self.mesh.support.offset();
        let nodes = self.mesh.n_elements + 1;
        let full = |i: usize| if i < o { 0.0 } else { w[i - o] };
        (
            (0..nodes).map(|j| full(2 * j)).collect(),
            (0..nodes).map(|j| full(2 * j + 1)).collect(),
        )
    }

    /// θ_f from the tip rise: asin(rise / arm); an error when the rise exceeds the arm.
    pub fn theta_f(&self, rise: f64, t: f64) -> Result<f64> {
        let s = rise / self.mesh.arm();
        if s.is_nan() || s.abs() > 1.0 {
            return Err(Error::Integration {
                t,
                reason: format!(
                    "tip rise {rise} m exceeds the arm {} m: θ_f is undefined",
                    self.mesh.arm()
                ),
            });
        }
        Ok(s.asin())
    }

    /// Tip rise from the modal coordinates and the element moments, m.
    pub fn rise(&self, q: &[f64], moments: &[f64]) -> f64 {
        let a: f64 = self.rise_modal.iter().zip(q).map(|(r, v)| r * v).sum();
        let b: f64 = self
            .rise_residual
            .iter()
            .zip(moments)
            .map(|(r, v)| r * v)
            .sum();
        a + b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(support: Support, n: usize) -> Mesh {
        Mesh::new(&Panel::paper(), support, n).unwrap()
    }

    /// (β L)² sqrt(EI/(m L⁴)), rad/s.
    fn closed_form(m: &Mesh, beta_l: f64) -> f64 {
        beta_l * beta_l * (m.flexural_rigidity / (m.mass_per_length * m.length.powi(4))).sqrt()
    }

    #[test]
    fn bad_settings_name_the_setting() {
        for n in [0, 1, MAX_ELEMENTS + 1] {
            let err = Mesh::new(&Panel::paper(), Support::FreeFree, n).unwrap_err();
            assert!(err.to_string().starts_with("elements"), "{err}");
        }
        let err = Support::from_name("pinned").unwrap_err();
        assert!(err.to_string().starts_with("support"), "{err}");
        for (support, k) in [(Support::FreeFree, 0), (Support::Cantilever, 21)] {
            let err = Reduction::new(mesh(support, 10), k).unwrap_err();
            assert!(err.to_string().starts_with("modes"), "{err}");
        }
        assert!(Reduction::new(mesh(Support::Cantilever, 10), 20).is_ok());
    }

    #[test]
    fn element_loads_of_a_uniform_moment_are_the_end_moments() {
        let m = mesh(Support::FreeFree, 7);
        let total = m.moment_load() * DVector::from_element(7, 1.0);
        let beam = crate::models::beam::FreeFreeBeam::new(&Panel::paper(), 8).unwrap();
        let ends = beam.end_moment_load();
        assert_eq!(total[1], ends[1]);
        assert_eq!(total[m.dofs() - 1], ends[beam.dofs() - 1]);
        assert_eq!(total.amax(), 1.0);
        assert_eq!(total.iter().filter(|v| **v != 0.0).count(), 2);
    }

    #[test]
    fn uniform_moment_bends_to_constant_curvature() {
        // w'' = M/EI: free panel tips rise M L²/(8EI) over the centre, cantilever tip M L²/(2EI).
        for n in [2, 5, 40] {
            for support in [Support::FreeFree, Support::Cantilever] {
                let m = mesh(support, n);
                let moment = 400.0;
                let w = m.static_flexibility().unwrap() * DVector::from_element(n, moment);
                let rise = m.rise_reader().dot(&w);
                let (ei, l) = (m.flexural_rigidity, m.length);
                let exact = match support {
                    Support::FreeFree => moment * l * l / (8.0 * ei),
                    Support::Cantilever => moment * l * l / (2.0 * ei),
                };
                // Exact in exact arithmetic (cubics hold the parabola); the solve's rounding grows
                // with the condition number of K, about (ω_max/ω₁)² ≈ 1e9 at n = 40.
                assert!(
                    (rise - exact).abs() < 1e-9 * exact,
                    "{support:?} n={n}: {rise} vs {exact}"
                );
                // The slope at every node is the exact κ (x − x₀).
                let red = Reduction::new(m.clone(), 1).unwrap();
                let (_, slope) = red.nodal(&w);
                let x0 = if support == Support::FreeFree {
                    0.5 * l
                } else {
                    0.0
                };
                for (x, s) in m.node_x().iter().zip(&slope) {
                    let want = moment / ei * (x - x0);
                    assert!(
                        (s - want).abs() < 1e-9 * moment / ei * l,
                        "{x}: {s} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn first_frequencies_match_the_continuous_beam() {
        for (support, beta) in [
            (Support::FreeFree, crate::inputs::panel::BETA1_L),
            (Support::Cantilever, CANTILEVER_BETA1_L),
        ] {
            let mut last = f64::INFINITY;
            for n in [2, 4, 8, 16] {
                let m = mesh(support, n);
                let (eig, _) = m.elastic_modes_all().unwrap();
                let exact = closed_form(&m, beta);
                let err = (eig[0].sqrt() - exact).abs() / exact;
                assert!(err < last, "{support:?} n = {n}: {err}");
                last = err;
            }
        }
    }

    #[test]
    fn integrated_static_slopes_are_the_solved_ones() {
        for support in [Support::FreeFree, Support::Cantilever] {
            for n in [3, 12, 40] {
                let red = Reduction::new(mesh(support, n), 2).unwrap();
                let moments: Vec<f64> = (0..n).map(|e| 300.0 + 50.0 * (e as f64).sin()).collect();
                let mut fast = vec![0.0; n];
                red.static_slopes(&moments, &mut fast);
                let solved = &red.slope_static * DVector::from_column_slice(&moments);
                let scale = solved.amax();
                for e in 0..n {
                    assert!(
                        (fast[e] - solved[e]).abs() < 1e-10 * scale,
                        "{support:?} n={n} e={e}: {} vs {}",
                        fast[e],
                        solved[e]
                    );
                }
            }
        }
    }

    #[test]
    fn reduction_is_exact_in_the_static_limit() {
        let m = mesh(Support::FreeFree, 12);
        let red = Reduction::new(m.clone(), 3).unwrap();
        let moments: Vec<f64> = (0..12).map(|e| 100.0 + 7.0 * e as f64).collect();
        let q: Vec<f64> = (0..3)
            .map(|i| {
                (0..12).map(|e| red.force[(i, e)] * moments[e]).sum::<f64>()
                    / (red.omega[i] * red.omega[i])
            })
            .collect();
        let w = red.deflection(&q, &moments);
        let exact = m.static_flexibility().unwrap() * DVector::from_column_slice(&moments);
        assert!((w - &exact).amax() < 1e-12 * exact.amax());
    }
}
