//! The finite-element comparator of the hinge model (paper Sec. 4.3): a free–free Euler–Bernoulli
//! beam of Hermite cubic elements with consistent mass, its modes from the generalised symmetric
//! eigenproblem K φ = ω² M φ, and the modal transient response to opposite end moments ±M_T(t).
//!
//! Degrees of freedom: node j (x = j h, h = L/n) carries the deflection w_j (index 2j) and the
//! slope w'_j (index 2j + 1). The end moments enter as −M on the slope of node 0 and +M on the
//! slope of node n, which bends the beam into uniform curvature w'' = M/EI: the tips rise above
//! the centre by η = M L²/(8EI), as the hinge model's tips rise by (L/2) sin θ for θ > 0.
//!
//! The two rigid-body modes (translation and rotation) come out with eigenvalues at rounding
//! level and are set apart; a self-equilibrated pair of end moments does no work on them, which is
//! what inertia relief achieves in the paper's static-support-free analysis. The transient keeps
//! the first [`BEAM_MODES`] elastic modes that the end moments excite (the symmetric ones; the
//! antisymmetric modes get exactly zero modal force) as the ODE state, and adds the quasi-static
//! contribution of every other elastic mode (residual flexibility, the "mode acceleration"
//! correction), so a slowly varying moment gives the exact static deflection.

use crate::error::{require_finite, Error, Result};
use crate::inputs::panel::{beam_first_angular_frequency, Panel};
use crate::models::coupled::MomentHistory;
use crate::numerics::integrate::{Const, OdeSystem};
use nalgebra::{DMatrix, DVector, SVector, SymmetricEigen};

/// Number of elastic modes integrated in the transient response.
pub const BEAM_MODES: usize = 8;
/// State size of the modal system: (q₁..q₈, q̇₁..q̇₈).
pub const BEAM_STATE: usize = 2 * BEAM_MODES;
/// Largest element count accepted (the eigenproblem is dense, O((2n)³)).
pub const MAX_ELEMENTS: usize = 1000;

/// A uniform free–free beam discretised into `n_elements` Hermite cubic elements.
#[derive(Debug, Clone, PartialEq)]
pub struct FreeFreeBeam {
    pub n_elements: usize,
    /// L, m.
    pub length: f64,
    /// E I, N m².
    pub flexural_rigidity: f64,
    /// m, kg/m.
    pub mass_per_length: f64,
}

/// Mass-normalised modes, ascending: the two rigid-body modes first, then the elastic ones.
#[derive(Debug, Clone)]
pub struct Modes {
    /// ω², (rad/s)², ascending; the first two are the rigid-body modes (≈ 0).
    pub eigenvalues: Vec<f64>,
    /// φ as columns (φᵀ M φ = 1), in the order of `eigenvalues`.
    pub shapes: DMatrix<f64>,
}

impl Modes {
    /// Elastic angular frequencies ω, rad/s (rigid modes excluded).
    pub fn elastic_angular_frequencies(&self) -> Vec<f64> {
        self.eigenvalues[2..].iter().map(|l| l.sqrt()).collect()
    }
    /// The two rigid-body eigenvalues, (rad/s)² (zero up to rounding).
    pub fn rigid_eigenvalues(&self) -> [f64; 2] {
        [self.eigenvalues[0], self.eigenvalues[1]]
    }
    /// Number of elastic modes of the mesh.
    pub fn elastic_count(&self) -> usize {
        self.eigenvalues.len() - 2
    }
    /// Deflection w of elastic mode `k` (0: the first) at every node, in node order: the
    /// translation entries (even DOFs) of its shape.
    pub fn elastic_deflection(&self, k: usize) -> Vec<f64> {
        let shape = self.shapes.column(k + 2);
        shape.iter().step_by(2).copied().collect()
    }
}

impl FreeFreeBeam {
    /// The panel as a beam: L, E I and m of `panel`. `n_elements` must be even (the centre is a
    /// node) and between 2 and [`MAX_ELEMENTS`].
    pub fn new(panel: &Panel, n_elements: usize) -> Result<Self> {
        panel.validate()?;
        if n_elements < 2 || !n_elements.is_multiple_of(2) || n_elements > MAX_ELEMENTS {
            return Err(Error::invalid(
                "n_elements",
                n_elements,
                &format!("must be even, between 2 and {MAX_ELEMENTS} (the centre must be a node)"),
            ));
        }
        Ok(FreeFreeBeam {
            n_elements,
            length: panel.length,
            flexural_rigidity: panel.youngs_modulus * panel.bending_inertia,
            mass_per_length: panel.mass_per_length,
        })
    }

    /// Number of degrees of freedom, 2 (n + 1).
    pub fn dofs(&self) -> usize {
        2 * (self.n_elements + 1)
    }

    /// Position of every node along the beam, m (0 to L).
    pub fn node_positions(&self) -> Vec<f64> {
        (0..=self.n_elements)
            .map(|j| self.length * j as f64 / self.n_elements as f64)
            .collect()
    }

    /// Total mass as the consistent mass matrix carries it, kg: tᵀ M t for the unit
    /// translation t (equal to m L).
    pub fn total_mass(&self) -> f64 {
        let t = self.translation();
        t.dot(&(self.mass_matrix() * &t))
    }

    fn element_length(&self) -> f64 {
        self.length / self.n_elements as f64
    }

    /// Assembles a global matrix from the 4×4 element matrix shared by every element.
    fn assemble(&self, element: &[[f64; 4]; 4]) -> DMatrix<f64> {
        assemble_uniform(self.n_elements, element)
    }

    /// Global stiffness matrix, assembled from [`element_stiffness`].
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        self.assemble(&element_stiffness(
            self.flexural_rigidity,
            self.element_length(),
        ))
    }

    /// Global consistent mass matrix, assembled from [`element_mass`].
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        self.assemble(&element_mass(self.mass_per_length, self.element_length()))
    }

    /// Unit rigid translation (w = 1, w' = 0 at every node).
    pub fn translation(&self) -> DVector<f64> {
        DVector::from_fn(self.dofs(), |i, _| if i % 2 == 0 { 1.0 } else { 0.0 })
    }

    /// Load vector of unit end moments: −1 on the slope of node 0, +1 on the slope of node n.
    pub fn end_moment_load(&self) -> DVector<f64> {
        let mut f = DVector::zeros(self.dofs());
        f[1] = -1.0;
        f[self.dofs() - 1] = 1.0;
        f
    }

    /// Row that reads η, the mean tip deflection relative to the centre node: (w₀ + w_n)/2 − w_c.
    pub fn tip_relative_reader(&self) -> DVector<f64> {
        let mut r = DVector::zeros(self.dofs());
        r[0] = 0.5;
        r[2 * self.n_elements] = 0.5;
        r[self.n_elements] = -1.0; // node n/2 → index 2 (n/2)
        r
    }

    /// Solves K φ = ω² M φ (see [`generalised_modes`]).
    pub fn modes(&self) -> Result<Modes> {
        let (eigenvalues, shapes) =
            generalised_modes(self.stiffness_matrix(), self.mass_matrix(), "beam modes")?;
        let n = eigenvalues.len();
        // The rigid-body pair must sit far below the first elastic mode.
        if n < 3 || eigenvalues[1].abs() > 1e-6 * eigenvalues[2] {
            return Err(Error::NoConvergence {
                what: "beam modes".into(),
                reason: format!(
                    "the rigid-body modes did not separate (ω² = {:?})",
                    &eigenvalues[..n.min(3)]
                ),
            });
        }
        Ok(Modes {
            eigenvalues,
            shapes,
        })
    }

    /// Modal data for the end-moment transient: per elastic mode its ω, modal force per unit
    /// moment g = φᵀ f and tip reading h = r φ.
    pub fn end_moment_modes(&self) -> Result<EndMomentModes> {
        let modes = self.modes()?;
        let f = self.end_moment_load();
        let r = self.tip_relative_reader();
        let mut all = Vec::new();
        for (col, &lambda) in modes.eigenvalues.iter().enumerate().skip(2) {
            let phi = modes.shapes.column(col);
            all.push((lambda.sqrt(), phi.dot(&f), phi.dot(&r)));
        }
        let g_max = all.iter().map(|m| m.1.abs()).fold(0.0, f64::max);
        let excited: Vec<(f64, f64, f64)> = all
            .iter()
            .copied()
            .filter(|m| m.1.abs() > 1e-9 * g_max)
            .collect();
        let flexibility: f64 = excited.iter().map(|(w, g, h)| g * h / (w * w)).sum();
        let kept: Vec<(f64, f64, f64)> = excited.iter().copied().take(BEAM_MODES).collect();
        let kept_flex: f64 = kept.iter().map(|(w, g, h)| g * h / (w * w)).sum();
        Ok(EndMomentModes {
            kept,
            flexibility,
            residual_flexibility: flexibility - kept_flex,
        })
    }

    /// Static η (m) under end moments ±`moment` (N m), summed over every elastic mode.
    pub fn static_tip_deflection(&self, moment: f64) -> Result<f64> {
        require_finite("moment", moment)?;
        Ok(self.end_moment_modes()?.flexibility * moment)
    }
}

/// Modal damping ratio that makes a beam's first mode decay at the hinge's rate c_d/(2 I_B):
/// ζ = c_d / (2 I_B ω₁), ω₁ the first free–free frequency of the continuous panel. It equals the
/// hinge's own c_d / (2 sqrt(K_el I_B)) when K_el follows the frequency criterion.
pub fn hinge_equivalent_damping_ratio(panel: &Panel) -> f64 {
    panel.damping / (2.0 * panel.hinge_inertia() * beam_first_angular_frequency(panel))
}

/// The hinge damping c_d (N m s/rad) equivalent to the modal damping ratio `zeta`: the inverse
/// of [`hinge_equivalent_damping_ratio`].
pub fn hinge_equivalent_damping(panel: &Panel, zeta: f64) -> f64 {
    2.0 * panel.hinge_inertia() * beam_first_angular_frequency(panel) * zeta
}

/// Global matrix on the 2 (n + 1) nodal degrees of freedom (w_j at 2j, w'_j at 2j + 1) of a
/// chain of `n_elements` equal elements sharing the 4×4 `element` matrix.
pub fn assemble_uniform(n_elements: usize, element: &[[f64; 4]; 4]) -> DMatrix<f64> {
    let n = 2 * (n_elements + 1);
    let mut g = DMatrix::zeros(n, n);
    for e in 0..n_elements {
        let base = 2 * e;
        for (i, row) in element.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                g[(base + i, base + j)] += v;
            }
        }
    }
    g
}

/// Stiffness matrix of one Hermite cubic element of length `h` and rigidity `ei` (N m²), on
/// (w₁, w₁', w₂, w₂'): EI/h³ [12 6h −12 6h; 6h 4h² −6h 2h²; −12 −6h 12 −6h; 6h 2h² −6h 4h²].
pub fn element_stiffness(ei: f64, h: f64) -> [[f64; 4]; 4] {
    let k = ei / (h * h * h);
    [
        [12.0, 6.0 * h, -12.0, 6.0 * h],
        [6.0 * h, 4.0 * h * h, -6.0 * h, 2.0 * h * h],
        [-12.0, -6.0 * h, 12.0, -6.0 * h],
        [6.0 * h, 2.0 * h * h, -6.0 * h, 4.0 * h * h],
    ]
    .map(|r| r.map(|v| v * k))
}

/// Consistent mass matrix of one Hermite cubic element of length `h` and mass per length `m`
/// (kg/m): m h/420 [156 22h 54 −13h; 22h 4h² 13h −3h²; 54 13h 156 −22h; −13h −3h² −22h 4h²].
pub fn element_mass(m: f64, h: f64) -> [[f64; 4]; 4] {
    let c = m * h / 420.0;
    [
        [156.0, 22.0 * h, 54.0, -13.0 * h],
        [22.0 * h, 4.0 * h * h, 13.0 * h, -3.0 * h * h],
        [54.0, 13.0 * h, 156.0, -22.0 * h],
        [-13.0 * h, -3.0 * h * h, -22.0 * h, 4.0 * h * h],
    ]
    .map(|r| r.map(|v| v * c))
}

/// Solves K φ = ω² M φ for symmetric K and positive definite M: Cholesky M = L Lᵀ, eigen-
/// decomposition of L⁻¹ K L⁻ᵀ, φ = L⁻ᵀ z. Returns ω² ascending and the mass-normalised shapes
/// (φᵀ M φ = 1) as columns in that order, each signed so that its first entry that is not
/// negligible (deflection at the first node, else the slope there) is positive.
pub fn generalised_modes(
    k: DMatrix<f64>,
    m: DMatrix<f64>,
    what: &str,
) -> Result<(Vec<f64>, DMatrix<f64>)> {
    let chol = nalgebra::Cholesky::new(m).ok_or_else(|| Error::NoConvergence {
        what: what.into(),
        reason: "the mass matrix is not positive definite".into(),
    })?;
    let l = chol.l();
    let no_solve = || Error::NoConvergence {
        what: what.into(),
        reason: "triangular solve failed".into(),
    };
    let x = l.solve_lower_triangular(&k).ok_or_else(no_solve)?; // L⁻¹ K
    let a = l
        .solve_lower_triangular(&x.transpose())
        .ok_or_else(no_solve)?; // L⁻¹ K L⁻ᵀ
    let a = (&a + a.transpose()) * 0.5;
    let eig = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let n = order.len();
    let mut eigenvalues = Vec::with_capacity(n);
    let mut z = DMatrix::zeros(n, n);
    for (col, &i) in order.iter().enumerate() {
        eigenvalues.push(eig.eigenvalues[i]);
        z.set_column(col, &eig.eigenvectors.column(i));
    }
    let mut shapes = l.tr_solve_lower_triangular(&z).ok_or_else(no_solve)?;
    for mut c in shapes.column_iter_mut() {
        let lead = if c[0].abs() > 1e-12 * c.amax() {
            c[0]
        } else {
            c[1]
        };
        if lead < 0.0 {
            c.neg_mut();
        }
    }
    Ok((eigenvalues, shapes))
}

/// The elastic modes excited by opposite end moments.
#[derive(Debug, Clone)]
pub struct EndMomentModes {
    /// (ω rad/s, g = φᵀf per N m, h = η per unit modal coordinate) of the kept modes, ascending.
    pub kept: Vec<(f64, f64, f64)>,
    /// Σ g h / ω² over every excited elastic mode: static η per unit moment, m/(N m).
    pub flexibility: f64,
    /// The part of `flexibility` carried by the modes not kept.
    pub residual_flexibility: f64,
}

/// The modal equations q̈ᵢ + 2ζωᵢ q̇ᵢ + ωᵢ² qᵢ = gᵢ M(t), state (q, q̇).
#[derive(Debug, Clone)]
pub struct ModalBeam {
    omega: [f64; BEAM_MODES],
    force: [f64; BEAM_MODES],
    /// ζ, the modal damping ratio of every kept mode.
    pub damping_ratio: f64,
    pub moment: MomentHistory,
}

impl ModalBeam {
    pub fn new(modes: &EndMomentModes, damping_ratio: f64, moment: MomentHistory) -> Self {
        let mut omega = [0.0; BEAM_MODES];
        let mut force = [0.0; BEAM_MODES];
        for (i, (w, g, _)) in modes.kept.iter().enumerate() {
            omega[i] = *w;
            force[i] = *g;
        }
        ModalBeam {
            omega,
            force,
            damping_ratio,
            moment,
        }
    }

    /// Static modal state under moment `m` (q = g m/ω², q̇ = 0).
    pub fn static_state(&self, m: f64) -> SVector<f64, BEAM_STATE> {
        let mut y = SVector::zeros();
        for i in 0..BEAM_MODES {
            if self.omega[i] > 0.0 {
                y[i] = self.force[i] * m / (self.omega[i] * self.omega[i]);
            }
        }
        y
    }
}

impl OdeSystem<Const<BEAM_STATE>> for ModalBeam {
    #[inline]
    fn rhs(&self, t: f64, y: &SVector<f64, BEAM_STATE>) -> SVector<f64, BEAM_STATE> {
        let m = self.moment.at(t);
        let mut d = SVector::zeros();
        for i in 0..BEAM_MODES {
            let (q, v, w) = (y[i], y[BEAM_MODES + i], self.omega[i]);
            d[i] = v;
            d[BEAM_MODES + i] = self.force[i] * m - 2.0 * self.damping_ratio * w * v - w * w * q;
        }
        d
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        match &self.moment {
            MomentHistory::Constant(_) => Vec::new(),
            MomentHistory::Samples { t, .. } => {
                t.iter().copied().filter(|&x| x > t0 && x < t1).collect()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use std::f64::consts::PI;

    fn paper_beam(n: usize) -> FreeFreeBeam {
        FreeFreeBeam::new(&Panel::paper(), n).unwrap()
    }

    /// (β L)² sqrt(EI/(m L⁴)), rad/s.
    fn closed_form(beam: &FreeFreeBeam, beta_l: f64) -> f64 {
        beta_l
            * beta_l
            * (beam.flexural_rigidity / (beam.mass_per_length * beam.length.powi(4))).sqrt()
    }

    #[test]
    fn rejects_bad_element_counts() {
        for n in [0, 1, 3, 101, MAX_ELEMENTS + 2] {
            let err = FreeFreeBeam::new(&Panel::paper(), n).unwrap_err();
            assert!(err.to_string().starts_with("n_elements"), "{err}");
        }
    }

    #[test]
    fn mass_matrix_holds_the_whole_mass() {
        let b = paper_beam(100);
        let t = b.translation();
        let total = t.dot(&(b.mass_matrix() * &t));
        assert!((total - 5.51 * 50.0).abs() < 1e-9 * total, "{total}");
        assert!((b.total_mass() - 5.51 * 50.0).abs() < 1e-9 * total);
    }

    #[test]
    fn node_deflections_read_the_translation_dofs() {
        let b = paper_beam(20);
        let x = b.node_positions();
        assert_eq!((x.len(), x[0], x[20]), (21, 0.0, b.length));
        let modes = b.modes().unwrap();
        assert_eq!(modes.elastic_count(), b.dofs() - 2);
        // The first free–free mode is symmetric about the centre, with the ends moving against
        // it; the second is antisymmetric. Read from the shape's even entries directly.
        let first = modes.elastic_deflection(0);
        let second = modes.elastic_deflection(1);
        assert_eq!(first.len(), 21);
        for j in 0..=20 {
            assert_eq!(first[j], modes.shapes[(2 * j, 2)]);
            assert!((first[j] - first[20 - j]).abs() < 1e-9 * first[0].abs());
            assert!((second[j] + second[20 - j]).abs() < 1e-9 * second[0].abs());
        }
        assert!(first[0] * first[10] < 0.0);
    }

    #[test]
    fn stiffness_has_the_two_rigid_modes_in_its_null_space() {
        let b = paper_beam(10);
        let k = b.stiffness_matrix();
        let x = DVector::from_fn(b.dofs(), |i, _| {
            let node = (i / 2) as f64 * b.element_length();
            if i % 2 == 0 {
                node
            } else {
                1.0
            }
        });
        assert!((&k * b.translation()).amax() < 1e-6);
        assert!((&k * x).amax() < 1e-6);
    }

    #[test]
    fn modes_are_mass_normalised_and_rigid_pair_is_zero() {
        let b = paper_beam(20);
        let modes = b.modes().unwrap();
        let m = b.mass_matrix();
        let gram = modes.shapes.transpose() * &m * &modes.shapes;
        let eye = DMatrix::<f64>::identity(b.dofs(), b.dofs());
        assert!((gram - eye).amax() < 1e-8);
        let w1 = modes.eigenvalues[2];
        for r in modes.rigid_eigenvalues() {
            assert!(r.abs() < 1e-9 * w1, "{r}");
        }
    }

    #[test]
    fn first_frequency_is_the_papers_and_converges() {
        let exact = closed_form(&paper_beam(2), 4.730_040_7);
        let mut last_err = f64::INFINITY;
        for n in [4, 8, 16, 32, 64] {
            let w = paper_beam(n).modes().unwrap().elastic_angular_frequencies()[0];
            let err = (w - exact).abs() / exact;
            assert!(err < last_err, "n = {n}: {err}");
            last_err = err;
        }
        let w = paper_beam(100)
            .modes()
            .unwrap()
            .elastic_angular_frequencies()[0];
        assert!((w - exact).abs() < 1e-3 * exact);
        assert!(
            (w / (2.0 * PI) - 0.144).abs() < 0.0005,
            "{}",
            w / (2.0 * PI)
        );
    }

    #[test]
    fn higher_frequencies_match_the_continuous_beam() {
        let b = paper_beam(100);
        let w = b.modes().unwrap().elastic_angular_frequencies();
        for (i, beta_l) in [4.730_040_7, 7.853_204_6, 10.995_607_8].iter().enumerate() {
            let exact = closed_form(&b, *beta_l);
            assert!((w[i] - exact).abs() < 1e-4 * exact, "mode {}", i + 1);
        }
    }

    #[test]
    fn static_end_moments_give_uniform_curvature() {
        let b = paper_beam(100);
        let m = 400.0;
        let eta = b.static_tip_deflection(m).unwrap();
        let exact = m * 50.0 * 50.0 / (8.0 * b.flexural_rigidity);
        assert!(eta > 0.0);
        // A modal sum: its rounding grows with ω²_max/ω²₁ ≈ 1e8 at n = 100, hence 1e-6.
        assert!((eta - exact).abs() < 1e-6 * exact, "{eta} vs {exact}");
    }
}
