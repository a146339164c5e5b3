//! The distributed panel: a finite-element Euler–Bernoulli panel whose every element carries its
//! own through-thickness thermal state, absorbs sunlight at its own incidence and bends under its
//! own thermal moment — the continuous counterpart of the hinge model, two-way coupled the same
//! way.
//!
//! Element e (chord slope ρ_e = (w_{e+1} − w_e)/h, see [`structure`]) has the heat balance of its
//! thermal model ([`crate::models::thermal::ThermalModel`], two layers by default: eq. 2) with the
//! absorbed flux factor s(t) · (flux scale) · cos(ψ + atan ρ_e): ψ is the Sun's
//! angle to the undeformed front normal (the rigid attitude; 0 for the Sun-pointing panel) and
//! atan ρ_e the elastic rotation of the element's chord, so the Sun sees each element at its own
//! angle. Its thermal moment M_e (a E I (T_f − T_b)/d for two layers, with the physical rigidity:
//! the hinge model's χ is a calibration of the hinge, not of the panel) loads the structure as
//! consistent nodal loads.
//! With the coupling frozen the factor is cos ψ for every element.
//!
//! Under an orbit's Earth heating or an attitude other than Sun-pointing ([`ElementHeat`]) the
//! rigid front normal n is the attitude's and each element's normal is (n + ρ_e x̂)/√(1 + ρ_e²),
//! x̂ the panel's length direction ([`crate::inputs::orbit::Orbit::length_direction`], from
//! element 0 to the last; the deflection is positive along −n, away from a Sun on the normal):
//! every element takes the loads of [`crate::inputs::heating`] — sunlight on either face, albedo
//! and Earth infrared through its own view factor — at its own orientation, which is how the
//! deflection feeds back on the heating (the flat panel's normal for every element with the
//! coupling frozen). ψ is then set by the attitude and must be 0.
//!
//! The structure is reduced to its first k elastic modes q (state), the others quasi-static:
//! w = Φ q + R M. The state is y = (temperatures of element 0, of element 1, ..., q[0..k],
//! q̇[0..k]) and the modal equations are q̈ᵢ + 2ζωᵢ q̇ᵢ + ωᵢ² qᵢ = Σ_e Gᵢₑ M_e.
//!
//! Not modelled: conduction along the panel (as in the paper's model; the incidence varies by a
//! few degrees along it) and the rigid-body attitude dynamics of a free panel, whose attitude the
//! spacecraft holds (the rigid modes receive no thermal load).

pub mod structure;

use crate::error::{require_finite, require_non_negative, Error, Result};
use crate::inputs::attitude::Attitude;
use crate::inputs::heating::{Loads, Optics, Sources};
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::coupled::Coupling;
use crate::models::thermal::ThermalModel;
use crate::numerics::newton::newton;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::FRAC_PI_2;
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
    /// Layers of every element's through-thickness model ([`crate::models::thermal_model`]).
    pub layers: u32,
}

impl Settings {
    /// Defaults for `panel`: free–free, [`DEFAULT_ELEMENTS`], [`DEFAULT_MODES`], the
    /// hinge-equivalent damping ratio of the panel's c_d, Sun on the normal, two-way coupled.
    pub fn new(panel: &Panel) -> Self {
        Settings {
            support: Support::FreeFree,
            elements: DEFAULT_ELEMENTS,
            modes: DEFAULT_MODES,
            damping_ratio: crate::models::beam::hinge_equivalent_damping_ratio(panel),
            sun_angle: 0.0,
            coupling: Coupling::ProjectedArea,
            layers: 2,
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

/// The coupled distributed model: panel, settings, each element's thermal model and the modal
/// reduction.
pub struct DistributedPanel {
    pub panel: Panel,
    pub settings: Settings,
    pub reduction: Reduction,
    /// The through-thickness model every element carries (registered in [`crate::models::thermal_model`]),
    /// built with χ = 1: the panel's physical thermal moment.
    pub(crate) thermal: Box<dyn ThermalModel + Send + Sync>,
}

impl std::fmt::Debug for DistributedPanel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DistributedPanel")
            .field("settings", &self.settings)
            .field("temperatures", &self.thermal.names())
            .finish()
    }
}

impl Clone for DistributedPanel {
    fn clone(&self) -> Self {
        DistributedPanel::new(&self.panel, self.settings)
            .expect("settings that built a model build it again")
    }
}

/// The orbit's heat on the elements at one time: what reaches a flat face, the rigid front
/// normal n, the panel's length direction x̂ and the panel's optics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementHeat {
    pub sources: Sources,
    pub normal: [f64; 3],
    pub length: [f64; 3],
    pub optics: Optics,
    /// The attitude is Sun-pointing: the flat panel's incidence is exactly 0.
    on_sun: bool,
}

impl ElementHeat {
    /// The heat of `orbit` at time t for the Sun's illuminated fraction `s`.
    pub fn at(orbit: &Orbit, t: f64, s: f64, optics: Optics) -> Self {
        let g = orbit.geometry(t);
        ElementHeat {
            sources: orbit.sources(&g, s, optics.solar_constant, &orbit.earth_view()),
            normal: g.normal,
            length: orbit.length_direction(t, g.normal),
            optics,
            on_sun: orbit.attitude == Attitude::SunPointing,
        }
    }

    /// The loads absorbed by an element whose chord has slope ρ (normal (n + ρ x̂)/√(1 + ρ²)).
    pub fn loads(&self, slope: f64) -> Loads {
        if slope == 0.0 {
            return self
                .sources
                .fluxes(self.normal, self.on_sun)
                .absorbed(&self.optics);
        }
        let r = 1.0 / (1.0 + slope * slope).sqrt();
        let normal = [0, 1, 2].map(|k| (self.normal[k] + slope * self.length[k]) * r);
        self.sources.fluxes(normal, false).absorbed(&self.optics)
    }
}

/// Absorbed-area factor of an element: cos(ψ + atan ρ), zero once the Sun is behind the front.
/// Written as (cos ψ − ρ sin ψ)/√(1 + ρ²), one square root instead of an arctangent and a
/// cosine on the hot path; `sun` is (sin ψ, cos ψ).
#[inline]
fn incidence(sun: (f64, f64), slope: f64) -> f64 {
    let (s, c) = sun;
    ((c - slope * s) / (1.0 + slope * slope).sqrt()).max(0.0)
}

/// d incidence / d ρ = −(sin ψ + ρ cos ψ)/(1 + ρ²)^{3/2} (zero where the factor is clamped).
#[inline]
fn incidence_slope(sun: (f64, f64), slope: f64) -> f64 {
    let (s, c) = sun;
    if c - slope * s <= 0.0 {
        return 0.0;
    }
    let r2 = 1.0 + slope * slope;
    -(s + slope * c) / (r2 * r2.sqrt())
}

impl DistributedPanel {
    pub fn new(panel: &Panel, settings: Settings) -> Result<Self> {
        settings.validate()?;
        let mesh = Mesh::new(panel, settings.support, settings.elements)?;
        let reduction = Reduction::new(mesh, settings.modes)?;
        let physical = Panel {
            moment_scale: 1.0,
            ..*panel
        };
        Ok(DistributedPanel {
            panel: *panel,
            settings,
            reduction,
            thermal: crate::models::thermal_model(&physical, settings.layers)?,
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

    /// Temperatures per element.
    pub fn layers(&self) -> usize {
        self.thermal.size()
    }

    /// Names of an element's temperatures ("T_front", "T_back", ...).
    pub fn temperature_names(&self) -> Vec<String> {
        self.thermal.names()
    }

    /// Number of temperatures, n × layers: the modal coordinates start there.
    pub(crate) fn temps(&self) -> usize {
        self.n() * self.layers()
    }

    /// State size n × layers + 2k.
    pub fn state_size(&self) -> usize {
        self.temps() + 2 * self.k()
    }

    /// Element e's temperatures in the state.
    fn element<'a>(&self, y: &'a [f64], e: usize) -> &'a [f64] {
        let s = self.layers();
        &y[e * s..(e + 1) * s]
    }

    /// Modal coordinates q of the state.
    fn modal<'a>(&self, y: &'a [f64]) -> &'a [f64] {
        &y[self.temps()..self.temps() + self.k()]
    }

    /// Element moments from the state, N m.
    pub fn moments(&self, y: &[f64]) -> Vec<f64> {
        let mut m = vec![0.0; self.n()];
        self.thermal.moments_of(&y[..self.temps()], &mut m);
        m
    }

    /// Per-element chord slopes ρ = D Φ q + D R M, written as D S M + D Φ (q − Ω⁻² G M) so that
    /// the static part is integrated in O(n) ([`Reduction::static_slopes`]); `gm` is G M.
    fn slopes_with(&self, q: &[f64], moments: &[f64], gm: &[f64]) -> Vec<f64> {
        let mut rho = vec![0.0; self.n()];
        self.slopes_into(q, moments, gm, &mut rho);
        rho
    }

    /// [`Self::slopes_with`] into `rho`.
    fn slopes_into(&self, q: &[f64], moments: &[f64], gm: &[f64], rho: &mut [f64]) {
        let r = &self.reduction;
        let n = self.n();
        r.static_slopes(moments, rho);
        // Column by column (column-major): each pass is a contiguous axpy.
        for (i, col) in r.slope_modal.as_slice().chunks_exact(n).enumerate() {
            let w = r.omega[i];
            let x = q[i] - gm[i] / (w * w);
            for (out, a) in rho.iter_mut().zip(col) {
                *out += a * x;
            }
        }
    }

    /// G M: the modal forces of the element moments.
    fn modal_forces(&self, moments: &[f64]) -> Vec<f64> {
        let mut gm = vec![0.0; self.k()];
        self.modal_forces_into(moments, &mut gm);
        gm
    }

    /// [`Self::modal_forces`] into `gm`.
    fn modal_forces_into(&self, moments: &[f64], gm: &mut [f64]) {
        // Every mode's sum over the elements in their order, the modes side by side (from -0.0,
        // the neutral element of f64's `Sum`: each the same bits as summed alone).
        gm.fill(-0.0);
        let columns = self.reduction.force.as_slice().chunks_exact(gm.len());
        for (column, m) in columns.zip(moments) {
            for (g, f) in gm.iter_mut().zip(column) {
                *g += f * m;
            }
        }
    }

    /// Per-element chord slopes ρ.
    fn slopes(&self, q: &[f64], moments: &[f64]) -> Vec<f64> {
        self.slopes_with(q, moments, &self.modal_forces(moments))
    }

    /// Absorbed-area factor of each element for chord slopes `rho`.
    fn areas(&self, rho: &[f64]) -> Vec<f64> {
        let sun = self.settings.sun_angle.sin_cos();
        match self.settings.coupling {
            Coupling::ProjectedArea => rho.iter().map(|r| incidence(sun, *r)).collect(),
            Coupling::Frozen => vec![sun.1; rho.len()],
        }
    }

    /// The right-hand side under illumination factor `flux` (s × flux scale).
    pub fn rhs_at_flux(&self, flux: f64, y: &[f64], dy: &mut [f64]) {
        let sun = self.settings.sun_angle.sin_cos();
        let frozen = self.settings.coupling == Coupling::Frozen;
        self.rhs_with(y, dy, |slope, temps, out| {
            let area = if frozen { sun.1 } else { incidence(sun, slope) };
            self.thermal.rates(flux * area, temps, out);
        });
    }

    /// The temperatures' rates of every element in the umbra (`temps` and `out`: the
    /// temperatures alone): without sunlight the structure does not enter them, and each element
    /// cools on its own, as [`Self::rhs_at_flux`] at flux 0 has it.
    pub fn rates_in_shadow(&self, temps: &[f64], out: &mut [f64]) {
        let s = self.layers();
        for (t, o) in temps.chunks_exact(s).zip(out.chunks_exact_mut(s)) {
            self.thermal.rates(0.0, t, o);
        }
    }

    /// The right-hand side under the orbit's `heat` (each element at its own orientation).
    pub fn rhs_loaded(&self, heat: &ElementHeat, y: &[f64], dy: &mut [f64]) {
        self.rhs_with(y, dy, |slope, temps, out| {
            let loads = heat.loads(slope);
            self.thermal.rates(loads.sun, temps, out);
            self.thermal.add_face_rates(loads.front, loads.back, out);
        });
    }

    /// The right-hand side, each element's temperature rates written by `heat(ρ, temps, out)`
    /// from its chord slope ρ (0 with the coupling frozen) and its temperatures.
    #[inline]
    fn rhs_with(&self, y: &[f64], dy: &mut [f64], heat: impl Fn(f64, &[f64], &mut [f64])) {
        let (n, k, s, nt) = (self.n(), self.k(), self.layers(), self.temps());
        let r = &self.reduction;
        // The moments, G M and the chord slopes in one buffer.
        let mut scratch = vec![0.0; 2 * n + k];
        let (moments, rest) = scratch.split_at_mut(n);
        let (gm, slopes) = rest.split_at_mut(k);
        self.thermal.moments_of(&y[..nt], moments);
        let q = self.modal(y);
        let v = &y[nt + k..];
        self.modal_forces_into(moments, gm);
        if self.settings.coupling == Coupling::ProjectedArea {
            self.slopes_into(q, moments, gm, slopes);
        }
        for ((&slope, temps), out) in slopes
            .iter()
            .zip(y[..nt].chunks_exact(s))
            .zip(dy[..nt].chunks_exact_mut(s))
        {
            heat(slope, temps, out);
        }
        let zeta = self.settings.damping_ratio;
        for i in 0..k {
            let w = r.omega[i];
            dy[nt + i] = v[i];
            dy[nt + k + i] = gm[i] - 2.0 * zeta * w * v[i] - w * w * q[i];
        }
    }

    /// The equilibrium under the orbit's constant `heat`: Newton on every element's heat
    /// balance with the structure in its static shape, its Jacobian by differences.
    pub fn equilibrium_loaded(&self, heat: &ElementHeat) -> Result<Vec<f64>> {
        let (n, s, nt) = (self.n(), self.layers(), self.temps());
        let coupled = self.settings.coupling == Coupling::ProjectedArea;
        let fs = &self.reduction.slope_static;
        // Start from the uniform flat panel under its loads, heating it as the front's sunlight
        // would as much.
        let flat = heat.loads(0.0);
        let mut guess = vec![0.0; s];
        self.thermal
            .initial_guess(flat.equivalent_flux(&heat.optics), &mut guess);
        let x = DVector::from_fn(nt, |i, _| guess[i % s]);
        let residual = |x: &DVector<f64>| {
            let moments = self.moments(x.as_slice());
            let mut f = DVector::zeros(nt);
            let mut flows = vec![0.0; s];
            for e in 0..n {
                let slope = if coupled {
                    (0..n).map(|j| fs[(e, j)] * moments[j]).sum()
                } else {
                    0.0
                };
                let loads = heat.loads(slope);
                self.thermal
                    .heat_flows(loads.sun, self.element(x.as_slice(), e), &mut flows);
                self.thermal
                    .add_face_flows(loads.front, loads.back, &mut flows);
                f.rows_mut(e * s, s).copy_from_slice(&flows);
            }
            f
        };
        let residual_and_jacobian = |x: &DVector<f64>| {
            let f = residual(x);
            let mut jac = DMatrix::zeros(nt, nt);
            for j in 0..nt {
                let h = 1e-6 * x[j].abs().max(1.0);
                let mut xp = x.clone();
                xp[j] += h;
                jac.set_column(j, &((residual(&xp) - &f) / h));
            }
            (f, jac)
        };
        self.settle(x, residual_and_jacobian)
    }

    /// Newton on every element's heat balance from the temperatures `x`, then the state at rest
    /// in static equilibrium with them, refused when its tip rise exceeds the arm.
    fn settle(
        &self,
        x: DVector<f64>,
        residual_and_jacobian: impl FnMut(&DVector<f64>) -> (DVector<f64>, DMatrix<f64>),
    ) -> Result<Vec<f64>> {
        let nt = self.temps();
        let settled =
            |x: &DVector<f64>, dx: &DVector<f64>| (0..nt).all(|i| dx[i].abs() < 1e-12 * x[i]);
        let x = newton(
            "distributed steady state",
            x,
            nt,
            residual_and_jacobian,
            settled,
        )?;
        let y = self.static_state(x.as_slice());
        self.theta_f(&y, 0.0).map_err(|_| Error::NoConvergence {
            what: "distributed steady state".into(),
            reason: "the tip rise exceeds the arm: the panel is far too soft".into(),
        })?;
        Ok(y)
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

    /// The full state at rest in static equilibrium with the given temperatures (element-major:
    /// element 0's temperatures, then element 1's, ...).
    pub fn static_state(&self, temps: &[f64]) -> Vec<f64> {
        let mut y = temps.to_vec();
        y.extend(std::iter::repeat_n(0.0, 2 * self.k()));
        let moments = self.moments(&y);
        let q = self.static_modal(&moments);
        y[self.temps()..self.temps() + self.k()].copy_from_slice(&q);
        y
    }

    /// The temperatures of every element, one row per name in [`Self::temperature_names`].
    pub fn temperature_rows(&self, y: &[f64]) -> Vec<Vec<f64>> {
        let s = self.layers();
        (0..s)
            .map(|i| (0..self.n()).map(|e| y[e * s + i]).collect())
            .collect()
    }

    /// θ_f of a state, rad.
    pub fn theta_f(&self, y: &[f64], t: f64) -> Result<f64> {
        let rise = self.reduction.rise(self.modal(y), &self.moments(y));
        self.reduction.theta_f(rise, t)
    }

    /// Nodal deflections and slopes of a state.
    pub fn nodal(&self, y: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let w = self.reduction.deflection(self.modal(y), &self.moments(y));
        self.reduction.nodal(&w)
    }

    /// ∂(heat flows or rates)/∂(temperatures) of one element (s × s, row-major) and
    /// ∂/∂flux (s), by central differences of the thermal model at flux factor `flux` —
    /// whatever the model, the steady state and the Jacobian need only its `heat_flows` or
    /// `rates`. The flux enters linearly, and the step in each temperature is small enough
    /// (1e-4 K) for the T⁴ terms to be exact to about 1e-10.
    fn element_partials(
        &self,
        flux: f64,
        temps: &[f64],
        per_capacity: bool,
    ) -> (Vec<f64>, Vec<f64>) {
        let s = temps.len();
        let eval = |f: f64, t: &[f64], out: &mut [f64]| {
            if per_capacity {
                self.thermal.rates(f, t, out)
            } else {
                self.thermal.heat_flows(f, t, out)
            }
        };
        let (mut plus, mut minus) = (vec![0.0; s], vec![0.0; s]);
        let mut d_temps = vec![0.0; s * s];
        let mut t = temps.to_vec();
        for j in 0..s {
            let h = 1e-4;
            t[j] = temps[j] + h;
            eval(flux, &t, &mut plus);
            t[j] = temps[j] - h;
            eval(flux, &t, &mut minus);
            t[j] = temps[j];
            for i in 0..s {
                d_temps[i * s + j] = (plus[i] - minus[i]) / (2.0 * h);
            }
        }
        eval(1.0, temps, &mut plus);
        eval(0.0, temps, &mut minus);
        let d_flux = plus.iter().zip(&minus).map(|(a, b)| a - b).collect();
        (d_temps, d_flux)
    }

    /// ∂M/∂T of an element's temperatures, N m/K (M is linear in them).
    fn moment_partials(&self) -> Vec<f64> {
        let s = self.layers();
        let zero = vec![0.0; s];
        let m0 = self.thermal.moment(&zero);
        (0..s)
            .map(|j| {
                let mut unit = zero.clone();
                unit[j] = 1.0;
                self.thermal.moment(&unit) - m0
            })
            .collect()
    }

    /// Sunlit equilibrium under illumination factor `flux`: Newton on the heat balances of every
    /// element with the structure in its static shape (exact whatever the number of kept modes).
    pub fn equilibrium(&self, flux: f64) -> Result<Vec<f64>> {
        if !(flux.is_finite() && flux > 0.0) {
            return Err(Error::invalid("flux", flux, "must be finite and > 0"));
        }
        let (n, s, nt) = (self.n(), self.layers(), self.temps());
        let sun = self.settings.sun_angle.sin_cos();
        let coupled = self.settings.coupling == Coupling::ProjectedArea;
        let dm = self.moment_partials();
        // Start from the uniform panel at the rigid incidence.
        let mut guess = vec![0.0; s];
        self.thermal.initial_guess(flux * sun.1, &mut guess);
        let x = DVector::from_fn(nt, |i, _| guess[i % s]);
        let fs = &self.reduction.slope_static;
        let mut flows = vec![0.0; s];
        let residual_and_jacobian = |x: &DVector<f64>| {
            let moments = self.moments(x.as_slice());
            let rho: Vec<f64> = if coupled {
                (0..n)
                    .map(|e| (0..n).map(|j| fs[(e, j)] * moments[j]).sum())
                    .collect()
            } else {
                vec![0.0; n]
            };
            let areas = self.areas(&rho);
            let mut f = DVector::zeros(nt);
            let mut jac = DMatrix::zeros(nt, nt);
            for e in 0..n {
                let temps = self.element(x.as_slice(), e);
                // Residuals in W/m².
                self.thermal.heat_flows(flux * areas[e], temps, &mut flows);
                f.rows_mut(e * s, s).copy_from_slice(&flows);
                let (d_temps, d_flux) = self.element_partials(flux * areas[e], temps, false);
                for i in 0..s {
                    for j in 0..s {
                        jac[(e * s + i, e * s + j)] += d_temps[i * s + j];
                    }
                }
                if coupled {
                    let g = flux * incidence_slope(sun, rho[e]);
                    for i in 0..s {
                        for m in 0..n {
                            for (j, dmj) in dm.iter().enumerate() {
                                jac[(e * s + i, m * s + j)] += d_flux[i] * g * fs[(e, m)] * dmj;
                            }
                        }
                    }
                }
            }
            (f, jac)
        };
        self.settle(x, residual_and_jacobian)
    }

    /// ∂f/∂y of the right-hand side at state `y` under illumination factor `flux`.
    pub fn jacobian(&self, flux: f64, y: &[f64]) -> DMatrix<f64> {
        let (n, k, s, nt) = (self.n(), self.k(), self.layers(), self.temps());
        let r = &self.reduction;
        let sun = self.settings.sun_angle.sin_cos();
        let dm = self.moment_partials();
        let moments = self.moments(y);
        let q = self.modal(y);
        let rho = self.slopes(q, &moments);
        let areas = self.areas(&rho);
        let mut j = DMatrix::zeros(nt + 2 * k, nt + 2 * k);
        for e in 0..n {
            let (d_temps, d_flux) =
                self.element_partials(flux * areas[e], self.element(y, e), true);
            for a in 0..s {
                for b in 0..s {
                    j[(e * s + a, e * s + b)] += d_temps[a * s + b];
                }
            }
            if self.settings.coupling == Coupling::ProjectedArea {
                // Heating through the chord slope, which moves with every moment and mode.
                let g = flux * incidence_slope(sun, rho[e]);
                for a in 0..s {
                    let ga = g * d_flux[a];
                    for m in 0..n {
                        for (b, dmb) in dm.iter().enumerate() {
                            j[(e * s + a, m * s + b)] += ga * r.slope_residual[(e, m)] * dmb;
                        }
                    }
                    for i in 0..k {
                        j[(e * s + a, nt + i)] += ga * r.slope_modal[(e, i)];
                    }
                }
            }
        }
        let zeta = self.settings.damping_ratio;
        for i in 0..k {
            let w = r.omega[i];
            j[(nt + i, nt + k + i)] = 1.0;
            for e in 0..n {
                for (b, dmb) in dm.iter().enumerate() {
                    j[(nt + k + i, e * s + b)] = r.force[(i, e)] * dmb;
                }
            }
            j[(nt + k + i, nt + i)] = -w * w;
            j[(nt + k + i, nt + k + i)] = -2.0 * zeta * w;
        }
        j
    }
}

#[cfg(test)]
mod tests;
