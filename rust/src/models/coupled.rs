//! The right-hand sides: a thermal model coupled to a structural model (or alone), and the hinge
//! driven by a prescribed moment. Each implements [`OdeSystem`].

use crate::error::{Error, Result};
use crate::inputs::heating::{EarthView, Loads, Optics};
use crate::inputs::orbit::{Frame, Orbit, Shadow};
use crate::inputs::panel::Panel;
use crate::models::hinge::{
    hinge_acceleration, sin_cos_as, Hinge, HingeModel, Rigid, StructuralModel,
};
use crate::models::thermal::{AsWritten, Balance, ThermalModel, TwoLayer};
use crate::numerics::integrate::{OdeSystem, State};
use nalgebra::allocator::Allocator;
use nalgebra::{
    DefaultAllocator, Dim, DimName, Dyn, Matrix4, SVector, Vector2, Vector4, U1, U2, U4,
};

/// How the hinge angle feeds back on the heating (paper Sec. 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coupling {
    /// Absorbed flux ∝ cos θ: the projected area follows the hinge angle (two-way coupling).
    ProjectedArea,
    /// Projected area frozen (cos θ → 1): one-way coupling, paper Fig. 18.
    Frozen,
}

/// Illumination bookkeeping shared by every orbit-driven system: the segment being integrated
/// decides s, so a step that ends on a shadow boundary sees the segment's own side.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sunlight {
    pub(crate) orbit: Orbit,
    segment: (f64, f64),
    /// s over the current segment when it cannot change there: every segment of a cylindrical
    /// shadow, and the full-Sun and umbra segments of a penumbral one (the breakpoints include
    /// every contact). None inside a penumbra, where s(t) is evaluated at each call.
    constant_s: Option<f64>,
    /// The panel's optics, which turn the Earth's heat and sunlight on the back into absorbed
    /// loads; None for a system that takes the front's sunlight only.
    optics: Option<Optics>,
    /// The orbit's constants its geometry reads at every time.
    frame: Frame,
    /// The Earth seen from the orbit, for the view factors.
    earth: EarthView,
    /// The orbit heats more than the front's sunlight and the optics are known: the right-hand
    /// side takes [`Sunlight::loads`] instead of [`Sunlight::flux`].
    pub(crate) face_loads: bool,
}

impl Sunlight {
    /// Sunlight on the front only: a system built on it refuses an orbit with more
    /// ([`Sunlight::check`]).
    pub(crate) fn new(orbit: Orbit) -> Self {
        Sunlight {
            orbit,
            segment: (0.0, 0.0),
            constant_s: None,
            optics: None,
            frame: orbit.frame(),
            earth: orbit.earth_view(),
            face_loads: false,
        }
    }

    /// Every load of the orbit, the Earth's and the attitude's included, absorbed with `optics`.
    pub(crate) fn with_optics(orbit: Orbit, optics: Optics) -> Self {
        Sunlight {
            optics: Some(optics),
            face_loads: orbit.has_face_loads(),
            ..Sunlight::new(orbit)
        }
    }

    /// Refuses an orbit whose loads this system cannot take: Earth heating or an attitude other
    /// than Sun-pointing on a model that takes the front's sunlight only.
    /// The panel's optics, when the system absorbs every load of its orbit.
    pub(crate) fn optics(&self) -> Option<Optics> {
        self.optics
    }

    pub(crate) fn check(&self, what: &str) -> crate::error::Result<()> {
        if self.orbit.has_face_loads() && self.optics.is_none() {
            return Err(unsupported_face_loads(&self.orbit, what));
        }
        Ok(())
    }

    /// The illuminated fraction s at time t inside the current segment.
    #[inline]
    pub(crate) fn illumination(&self, t: f64) -> f64 {
        match self.constant_s {
            Some(s) => s,
            None => {
                let (a, b) = self.segment;
                self.orbit.illumination_on_in(&self.frame, t, a, b)
            }
        }
    }

    /// Every absorbed load at time t inside the current segment (the front's sunlight alone
    /// without optics).
    pub(crate) fn loads(&self, t: f64) -> Loads {
        match &self.optics {
            Some(optics) if self.face_loads => {
                // One geometry for the loads and, inside a penumbra, the illumination.
                let g = self.orbit.geometry_in(&self.frame, t);
                let s = match self.constant_s {
                    None if self.orbit.shadow == Shadow::Penumbra => self
                        .orbit
                        .illumination_between(&self.frame, g.position, g.sun, t),
                    _ => self.illumination(t),
                };
                self.orbit.loads_of(&g, s, optics, &self.earth)
            }
            _ => Loads::sun(self.flux(t)),
        }
    }

    /// The loads at time t in full sunlight (s = 1): what a run's default start is the steady
    /// state of.
    pub(crate) fn sunlit_loads(&self, t: f64) -> Loads {
        match &self.optics {
            Some(optics) if self.face_loads => self.orbit.loads(t, 1.0, optics),
            _ => Loads::sun(self.orbit.flux_scale(t)),
        }
    }

    pub(crate) fn enter(&mut self, a: f64, b: f64) {
        self.segment = (a, b);
        // The segment's loads turn the Sun's and the node's angles from its start.
        self.frame = self.orbit.frame_near(a);
        let mid = self
            .orbit
            .illumination_on_in(&self.frame, 0.5 * (a + b), a, b);
        let varies = matches!(self.orbit.shadow, Shadow::Penumbra) && mid > 0.0 && mid < 1.0;
        self.constant_s = if varies { None } else { Some(mid) };
    }

    /// The flux over the current segment when it is the same at every time of it (s constant
    /// there and the Sun at 1 au): what [`Sunlight::flux`] returns at any t of the segment.
    pub(crate) fn constant_flux(&self) -> Option<f64> {
        match self.constant_s {
            Some(s) if !self.orbit.eccentric_sun => Some(s * self.orbit.flux_scale(self.segment.0)),
            _ => None,
        }
    }

    // Always inlined: it is on every right-hand side of the full integration, and the
    // compiler's own weighing of it changes with the code around it (it once left it a call,
    // and a low orbit's rk45 run took 4 % longer).
    #[inline(always)]
    pub(crate) fn flux(&self, t: f64) -> f64 {
        let s = self.illumination(t);
        // At 1 au the scale is exactly 1: no multiplication, no division on the right-hand
        // side's path (with the multiplication the compiler merged both paths into a division).
        // In the umbra s = 0 is the flux whatever the scale (s × scale is s, its sign too).
        if self.orbit.eccentric_sun && s != 0.0 {
            s * self.orbit.flux_scale_in(&self.frame, t)
        } else {
            s
        }
    }
}

/// The refusal of an orbit's Earth heating or attitude by a model or path that cannot take them
/// (`what`), naming the setting that asks for them.
pub(crate) fn unsupported_face_loads(orbit: &Orbit, what: &str) -> Error {
    let (name, value) = if orbit.albedo != 0.0 {
        ("albedo", orbit.albedo.to_string())
    } else if orbit.earth_ir != 0.0 {
        ("earth_ir", orbit.earth_ir.to_string())
    } else {
        ("attitude", orbit.attitude.name().to_string())
    };
    Error::invalid(
        name,
        value,
        &format!(
            "is not modelled by {what}: Earth heating and attitudes other than Sun-pointing \
             run on the hinge models (tj.simulate, tj.simulate_orbits); set albedo = earth_ir \
             = 0 and a Sun-pointing attitude here"
        ),
    )
}

/// A thermal model and a structural model coupled through the thermal moment (thermal →
/// structure) and the projected-area factor (structure → thermal), driven by the orbit's Sun.
///
/// State: the thermal model's temperatures, then the structural model's states; `D` is its
/// dimension, `Const<N>` when N is known at compile time (the paper's model, [`Coupled::new`]:
/// (T_f, T_b, θ, θ̇)) or `Dyn`. Each model keeps its coefficients folded into per-second rates;
/// the moment's division by the structure's inertia is folded here, once.
#[derive(Debug, Clone, Copy)]
pub struct Coupled<T = TwoLayer, S = Hinge, D = U4> {
    thermal: T,
    structure: S,
    coupling: Coupling,
    sun: Sunlight,
    /// M_T per kelvin of the thermal gradient over the structure's inertia.
    load_per_kelvin: f64,
    dim: D,
}

impl Coupled<TwoLayer, Hinge, U4> {
    /// The paper's model: two layers (eq. 2) and the hinge (eq. 20 or 28).
    pub fn new(panel: Panel, orbit: Orbit, model: HingeModel, coupling: Coupling) -> Self {
        let (thermal, structure) = (TwoLayer::new(&panel), Hinge::new(&panel, model));
        Self::compose(thermal, structure, orbit, coupling, U4::name())
            .expect("two temperatures and two hinge states make four")
            .with_optics(Optics::of(&panel))
    }
}

/// What a kernel that evaluates [`Coupled::rhs_at_flux`] of the panel model for several panels at
/// once needs, so that it can do the same arithmetic lane by lane (the ensemble's lockstep lanes).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LaneForm {
    pub model: HingeModel,
    pub coupling: Coupling,
    /// The two-layer balance per half capacity.
    pub balance: Balance,
    /// Thermal moment per kelvin over I_B.
    pub load_per_kelvin: f64,
    /// c_d / I_B and K_el / I_B.
    pub damping: f64,
    pub stiffness: f64,
}

impl Coupled<TwoLayer, Hinge, U4> {
    /// The two temperatures' rates under `loads` with the hinge at θ, the hinge's own rates
    /// not computed: [`Coupled::rhs_at_loads`]'s first two (the slow-time path's thermal flow).
    #[inline]
    pub(crate) fn temperature_rates(&self, loads: Loads, temps: [f64; 2], theta: f64) -> [f64; 2] {
        // cos θ as the hinge's rates take it, bit for bit: a Monte Carlo sample must equal its
        // single run, and a bare cos may or may not be merged with a sine nearby into one
        // sincos as inlining goes (the last bit differs).
        let area = match self.coupling {
            Coupling::ProjectedArea => sin_cos_as::<f64>(theta).1,
            Coupling::Frozen => 1.0,
        };
        let mut out = [0.0; 2];
        self.thermal.rates(loads.sun * area, &temps, &mut out);
        if loads.has_face_loads() {
            self.thermal
                .add_face_rates(loads.front * area, loads.back * area, &mut out);
        }
        out
    }

    /// [`Sunlight::constant_flux`] of the current segment.
    pub(crate) fn constant_flux(&self) -> Option<f64> {
        self.sun.constant_flux()
    }

    pub(crate) fn lane_form(&self) -> LaneForm {
        let (model, damping, stiffness) = self.structure.rate_form();
        LaneForm {
            model,
            coupling: self.coupling,
            balance: self.thermal.rate_balance(),
            load_per_kelvin: self.load_per_kelvin,
            damping,
            stiffness,
        }
    }
}

impl<T: ThermalModel> Coupled<AsWritten<T>, Rigid, Dyn> {
    /// A thermal model alone, the plate held flat (θ = 0), its rates as written.
    pub fn thermal_only(thermal: T, orbit: Orbit) -> Self {
        let n = thermal.size();
        Self::compose(AsWritten(thermal), Rigid, orbit, Coupling::Frozen, Dyn(n))
            .expect("the state is the temperatures")
    }
}

impl<T: ThermalModel, S: StructuralModel, D: Dim> Coupled<T, S, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// Couples `thermal` and `structure`; `dim` must hold both models' states.
    pub fn compose(
        thermal: T,
        structure: S,
        orbit: Orbit,
        coupling: Coupling,
        dim: D,
    ) -> Result<Self> {
        let n = thermal.size() + structure.size();
        if dim.value() != n {
            return Err(Error::invalid(
                "state size",
                dim.value(),
                &format!("the models have {n} states"),
            ));
        }
        Ok(Coupled {
            load_per_kelvin: thermal.moment_per_kelvin() / structure.inertia(),
            thermal,
            structure,
            coupling,
            sun: Sunlight::new(orbit),
            dim,
        })
    }

    /// The same system absorbing every load of its orbit with the panel's `optics` (without
    /// them, an orbit with Earth heating or an attitude other than Sun-pointing is refused).
    pub fn with_optics(mut self, optics: Optics) -> Self {
        self.sun = Sunlight::with_optics(self.sun.orbit, optics);
        self
    }

    /// Whether the right-hand side takes loads on both faces (the orbit's Earth heating or
    /// attitude), not only the front's sunlight.
    pub fn has_face_loads(&self) -> bool {
        self.sun.face_loads
    }

    /// The solar constant of the panel's optics, W/m² (None without them).
    pub fn solar_constant(&self) -> Option<f64> {
        self.sun.optics.map(|o| o.solar_constant)
    }

    /// The loads at time t in full sunlight (the front's sunlight alone, at the Sun's distance
    /// there, when the orbit has no other).
    pub fn sunlit_loads(&self, t: f64) -> Loads {
        self.sun.sunlit_loads(t)
    }

    /// Whether the Sun's illuminated fraction changes along the current segment (a penumbra).
    pub(crate) fn illumination_varies(&self) -> bool {
        self.sun.constant_s.is_none()
    }

    /// The absorbed loads at time t inside the current segment.
    pub fn loads_at(&self, t: f64) -> Loads {
        self.sun.loads(t)
    }

    /// The steady state in full sunlight at time t, velocities zero: the default start of a
    /// run (under the Sun's distance at t, and the Earth's loads and the attitude's incidence
    /// there when the orbit has them).
    pub fn sunlit_steady_state(&self, t: f64) -> Result<State<D>> {
        if self.sun.face_loads {
            self.steady_state_under(self.sun.sunlit_loads(t))
        } else {
            self.steady_state(self.sun.orbit.flux_scale(t))
        }
    }

    /// The steady state under constant `loads`, velocities zero (loads on the faces need the
    /// panel's optics: the system must have them).
    pub fn steady_state_under(&self, loads: Loads) -> Result<State<D>> {
        if !loads.has_face_loads() {
            return self.steady_state(loads.sun);
        }
        match self.sun.optics {
            Some(optics) => self.steady_state_loaded(loads, loads.equivalent_flux(&optics)),
            None => Err(unsupported_face_loads(
                &self.sun.orbit,
                "a model without optics",
            )),
        }
    }

    pub fn thermal(&self) -> &T {
        &self.thermal
    }

    pub fn structure(&self) -> &S {
        &self.structure
    }

    pub fn orbit(&self) -> &Orbit {
        &self.sun.orbit
    }

    pub fn coupling(&self) -> Coupling {
        self.coupling
    }

    /// The state's dimension.
    pub fn dim(&self) -> D {
        self.dim
    }

    /// The thermal moment in state `y`, N m.
    pub fn moment(&self, y: &State<D>) -> f64 {
        self.thermal.moment(&y.as_slice()[..self.thermal.size()])
    }

    /// Refuses a start state the models do not describe: a temperature not above 0 K, the hinge
    /// beyond ±π/2 or faster than it can move ([`crate::models::hinge::check_start_state`]).
    pub fn check_start(&self, y: &State<D>) -> Result<()> {
        let n = self.thermal.size();
        self.thermal.check_start(&y.as_slice()[..n])?;
        self.structure.check_start(n, &y.as_slice()[n..])
    }

    /// Names of the state's components, temperatures first.
    pub fn names(&self) -> Vec<String> {
        let mut names = self.thermal.names();
        names.extend(self.structure.names());
        names
    }

    /// The right-hand side at a given illumination factor (used by the equilibrium solver too).
    #[inline(always)]
    pub fn rhs_at_flux(&self, flux: f64, y: &State<D>) -> State<D> {
        self.rhs_at_loads_as::<false>(Loads::sun(flux), y)
    }

    /// The right-hand side under loads on both faces.
    #[inline(always)]
    pub fn rhs_at_loads(&self, loads: Loads, y: &State<D>) -> State<D> {
        self.rhs_at_loads_as::<false>(loads, y)
    }

    /// [`Coupled::rhs_at_loads`] with the models' fused rates (the loop compiled for FMA).
    #[inline(always)]
    pub(crate) fn rhs_at_loads_fused(&self, loads: Loads, y: &State<D>) -> State<D> {
        self.rhs_at_loads_as::<true>(loads, y)
    }

    /// [`Coupled::rhs_at_loads`], with the models' fused rates when `FUSED`.
    #[inline(always)]
    fn rhs_at_loads_as<const FUSED: bool>(&self, loads: Loads, y: &State<D>) -> State<D> {
        let mut out = State::<D>::zeros_generic(self.dim, U1);
        let n = self.thermal.size();
        let (temps, q) = y.as_slice().split_at(n);
        let (temp_rates, q_rates) = out.as_mut_slice().split_at_mut(n);
        let load = self.load_per_kelvin * self.thermal.gradient(temps);
        let area = match self.coupling {
            Coupling::ProjectedArea => self.structure_rates::<FUSED>(load, q, q_rates),
            Coupling::Frozen => {
                self.structure_rates::<FUSED>(load, q, q_rates);
                1.0
            }
        };
        if FUSED {
            self.thermal
                .rates_fused(loads.sun * area, temps, temp_rates);
        } else {
            self.thermal.rates(loads.sun * area, temps, temp_rates);
        }
        if loads.has_face_loads() {
            self.thermal
                .add_face_rates(loads.front * area, loads.back * area, temp_rates);
        }
        out
    }

    #[inline(always)]
    fn structure_rates<const FUSED: bool>(&self, load: f64, q: &[f64], out: &mut [f64]) -> f64 {
        if FUSED {
            self.structure.rates_fused(load, q, out)
        } else {
            self.structure.rates(load, q, out)
        }
    }

    /// Illumination factor (s × flux scale) inside the current segment at time t.
    pub fn flux_at(&self, t: f64) -> f64 {
        self.sun.flux(t)
    }

    /// The right-hand side at time t: the front's sunlight alone (the paper's path, kept to the
    /// bit) or every load of the orbit.
    #[inline(always)]
    fn rhs_as<const FUSED: bool>(&self, t: f64, y: &State<D>) -> State<D> {
        let loads = if self.sun.face_loads {
            self.sun.loads(t)
        } else {
            Loads::sun(self.sun.flux(t))
        };
        self.rhs_at_loads_as::<FUSED>(loads, y)
    }
}

impl<T: ThermalModel, S: StructuralModel, D: Dim> OdeSystem<D> for Coupled<T, S, D>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline(always)]
    fn rhs(&self, t: f64, y: &State<D>) -> State<D> {
        self.rhs_as::<false>(t, y)
    }
    #[inline(always)]
    fn rhs_fused(&self, t: f64, y: &State<D>) -> State<D> {
        self.rhs_as::<true>(t, y)
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.sun.orbit.breakpoints(t0, t1)
    }
    fn check_span(&self, t0: f64, t1: f64) -> crate::error::Result<()> {
        self.sun.check("a model without the panel's optics")?;
        self.sun.orbit.check_span(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.sun.enter(a, b);
    }
}

/// A thermal-moment history M(t), N m: constant, or linear between samples (held at the ends).
#[derive(Debug, Clone, PartialEq)]
pub enum MomentHistory {
    Constant(f64),
    Samples { t: Vec<f64>, moment: Vec<f64> },
}

impl MomentHistory {
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        match self {
            MomentHistory::Constant(m) => *m,
            MomentHistory::Samples { t: ts, moment } => {
                let n = ts.len();
                if t <= ts[0] {
                    return moment[0];
                }
                if t >= ts[n - 1] {
                    return moment[n - 1];
                }
                let i = ts.partition_point(|&x| x <= t) - 1;
                let w = (t - ts[i]) / (ts[i + 1] - ts[i]);
                moment[i] + w * (moment[i + 1] - moment[i])
            }
        }
    }

    /// Checks every value against the hinge model's range for this panel
    /// ([`crate::models::hinge::check_moment`]).
    pub fn check_against(&self, panel: &crate::inputs::panel::Panel) -> Result<()> {
        match self {
            MomentHistory::Constant(m) => crate::models::hinge::check_moment(panel, *m),
            MomentHistory::Samples { moment, .. } => moment
                .iter()
                .try_for_each(|&m| crate::models::hinge::check_moment(panel, m)),
        }
    }

    /// Checks sample times increasing and values finite.
    pub fn validate(&self) -> Result<()> {
        match self {
            MomentHistory::Constant(m) => crate::error::require_finite("moment", *m),
            MomentHistory::Samples { t, moment } => {
                if t.len() < 2 || t.len() != moment.len() {
                    return Err(Error::invalid(
                        "moment",
                        format!("{} times, {} values", t.len(), moment.len()),
                        "needs at least two (time, moment) samples of equal length",
                    ));
                }
                if let Some(i) = t
                    .windows(2)
                    .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
                {
                    return Err(Error::invalid(
                        "moment_t",
                        t[i + 1],
                        "times must be finite and increasing",
                    ));
                }
                if let Some(v) = t.iter().chain(moment).find(|v| !v.is_finite()) {
                    return Err(Error::invalid("moment", v, "samples must be finite"));
                }
                Ok(())
            }
        }
    }
}

/// The hinge alone, driven by a prescribed thermal moment; state (θ, θ̇).
#[derive(Debug, Clone)]
pub struct DrivenHinge {
    pub panel: Panel,
    pub model: HingeModel,
    pub moment: MomentHistory,
}

impl OdeSystem<U2> for DrivenHinge {
    #[inline]
    fn rhs(&self, t: f64, y: &Vector2<f64>) -> Vector2<f64> {
        let m = self.moment.at(t);
        Vector2::new(
            y[1],
            hinge_acceleration(&self.panel, self.model, m, y[0], y[1]),
        )
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        // Kinks of the piecewise-linear history would cost accuracy if straddled.
        match &self.moment {
            MomentHistory::Constant(_) => Vec::new(),
            MomentHistory::Samples { t, .. } => {
                t.iter().copied().filter(|&x| x > t0 && x < t1).collect()
            }
        }
    }
}

/// Convenience: a state vector from its four components.
pub fn state(t_front: f64, t_back: f64, theta: f64, theta_dot: f64) -> SVector<f64, 4> {
    Vector4::new(t_front, t_back, theta, theta_dot)
}

/// The Jacobian of the two-layer plate on the hinge, state (T_front, T_back, θ, θ̇), from its
/// rows: the front layer's ∂/∂(T_front, T_back, θ), the back layer's ∂/∂(T_front, T_back) (its
/// balance does not see θ) and θ̈'s; θ̇'s own row is (0, 0, 0, 1).
#[inline]
#[rustfmt::skip] // a row a line
pub fn jacobian_from_rows(front: [f64; 3], back: [f64; 2], hinge: [f64; 4]) -> Matrix4<f64> {
    Matrix4::new(
        front[0], front[1], front[2], 0.0,
        back[0], back[1], 0.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
        hinge[0], hinge[1], hinge[2], hinge[3],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::hinge::thermal_moment;
    use crate::models::thermal::two_layer_rates;

    #[test]
    fn the_temperature_rates_alone_are_those_of_the_whole_right_hand_side() {
        let panel = Panel::paper();
        let loads = [
            Loads::sun(0.93),
            Loads {
                sun: 0.4,
                front: 160.0,
                back: 210.0,
            },
        ];
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
                let sys = Coupled::new(panel, Orbit::geo_equinox(), model, coupling);
                for l in loads {
                    for (tf, tb, th) in [(380.0, 368.0, 0.085), (250.0, 262.0, -0.3)] {
                        let whole = sys.rhs_at_loads(l, &Vector4::new(tf, tb, th, 0.4));
                        let alone = sys.temperature_rates(l, [tf, tb], th);
                        assert_eq!(alone, [whole[0], whole[1]]);
                    }
                }
            }
        }
    }

    #[test]
    fn one_geometry_for_loads_and_penumbra_gives_the_orbits_values() {
        // Drawn inclined orbits under the Earth's heat, at times in and around each penumbra:
        // the loads a system reads with the orbit's constants computed once, its slow angles
        // turned from the segment's start and one geometry for the loads and the illumination
        // are those of the orbit alone, to rounding.
        let mut draw = crate::numerics::testing::uniform_draws(2024);
        let optics = Optics::of(&Panel::paper());
        for _ in 0..40 {
            let orbit = Orbit {
                inclination: 1.5 * draw() + 0.01,
                raan: 6.0 * draw(),
                epoch_day: 365.0 * draw(),
                phase0: draw() - 0.5,
                season: true,
                eccentric_sun: true,
                j2: true,
                shadow: Shadow::Penumbra,
                albedo: 0.3,
                earth_ir: 237.0,
                ..Orbit::leo(400e3 + 800e3 * draw())
            };
            let sun = Sunlight::with_optics(orbit, optics);
            let frame = orbit.frame();
            for e in orbit.eclipses(0.0, 3.0 * orbit.period) {
                let (a, b) = e.outer;
                let (ua, ub) = e.umbra.unwrap_or((b, b));
                for (from, to) in [(a - 30.0, a), (a, ua), (ua, ub), (ub, b), (b, b + 30.0)] {
                    let mut seg = sun;
                    seg.enter(from, to);
                    for k in 0..=8 {
                        let t = from + (to - from) * k as f64 / 8.0;
                        // The segment's s: constant outside a penumbra, the orbit's inside.
                        // The segment turns the slow angles from its start: the orbit's
                        // values to rounding.
                        let s = seg.illumination(t);
                        if seg.constant_s.is_none() {
                            let direct = orbit.illumination(t);
                            assert!((s - direct).abs() <= 1e-12, "t = {t}: {s} vs {direct}");
                        }
                        let (got, want) = (seg.loads(t), orbit.loads(t, s, &optics));
                        for (g, w) in [
                            (got.sun, want.sun),
                            (got.front, want.front),
                            (got.back, want.back),
                        ] {
                            assert!((g - w).abs() <= 1e-13 * w.abs().max(1.0), "t = {t}");
                        }
                        assert_eq!(orbit.position_in(&frame, t), orbit.position(t));
                    }
                }
            }
        }
    }

    /// A system integrated over cuts its caller lists (an orbit's from its eclipse table) is the
    /// system integrated over its own: the same bits, on a heated inclined orbit with its
    /// penumbrae over two orbits, and over one penumbra alone with no cut inside it.
    #[test]
    fn an_integration_over_known_cuts_is_the_systems_own() {
        use crate::numerics::integrate::{solve, Method, StepCounter, Tolerances, WithCuts};
        let p = Panel::paper();
        let o = Orbit {
            shadow: Shadow::Penumbra,
            albedo: 0.3,
            earth_ir: 237.0,
            inclination: 0.5,
            season: true,
            eccentric_sun: true,
            j2: true,
            ..Orbit::leo(540e3)
        };
        let mut sys = Coupled::new(p, o, HingeModel::Linear, Coupling::ProjectedArea);
        let method = Method::Dopri5(Tolerances::default());
        let y0 = sys.sunlit_steady_state(0.0).unwrap();
        let (t0, t1) = (0.0, 2.0 * o.period);
        let cuts = o.breakpoints(t0, t1);
        assert!(cuts.len() >= 8, "{cuts:?}");
        let penumbra = (cuts[0], cuts[1]);
        for ((a, b), listed) in [((t0, t1), cuts.clone()), (penumbra, Vec::new())] {
            let (own, y_own) =
                solve(&mut sys, &method, a, y0, b, &mut StepCounter::default()).unwrap();
            let mut known = WithCuts {
                system: &mut sys,
                cuts: &listed,
            };
            let (with, y_with) =
                solve(&mut known, &method, a, y0, b, &mut StepCounter::default()).unwrap();
            assert_eq!(own, with);
            assert_eq!(y_own.as_slice(), y_with.as_slice());
        }
    }

    /// The folded coefficients give the rates of the textbook form of the equations.
    #[test]
    fn coupled_rhs_matches_the_equations_term_by_term() {
        let panel = Panel {
            damping: 2.0,
            ..Panel::paper()
        };
        let states = [
            Vector4::new(380.0, 368.0, 0.085, 0.0),
            Vector4::new(250.0, 262.0, -0.3, 0.02),
            Vector4::new(120.0, 119.0, 1.2, -0.7),
        ];
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
                let sys = Coupled::new(panel, Orbit::geo_equinox(), model, coupling);
                for y in &states {
                    for flux in [0.0, 1.0, 0.97] {
                        let got = sys.rhs_at_flux(flux, y);
                        let area = match coupling {
                            Coupling::ProjectedArea => y[2].cos(),
                            Coupling::Frozen => 1.0,
                        };
                        let (dtf, dtb) = two_layer_rates(&panel, flux * area, y[0], y[1]);
                        let m = thermal_moment(&panel, y[0], y[1]);
                        let acc = hinge_acceleration(&panel, model, m, y[2], y[3]);
                        let want = Vector4::new(dtf, dtb, y[3], acc);
                        for i in 0..4 {
                            let tol = 1e-13 * want[i].abs().max(1e-3);
                            assert!(
                                (got[i] - want[i]).abs() <= tol,
                                "{model:?} {coupling:?} {y} flux {flux}: component {i} {} vs {}",
                                got[i],
                                want[i]
                            );
                        }
                    }
                }
            }
        }
    }

    /// The same models behind a run-time size and dynamic dispatch give the same bits.
    #[test]
    fn a_run_time_sized_system_reproduces_the_paper_model() {
        use crate::numerics::integrate::{Method, Tolerances};
        use crate::runs::simulate::{run, Output};
        let p = Panel::paper();
        let o = Orbit::geo_year(273.0);
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        let mut fixed = Coupled::new(p, o, model, coupling);
        let thermal = crate::models::thermal_model(&p, 2).unwrap();
        let mut dynamic =
            Coupled::compose(thermal, Hinge::new(&p, model), o, coupling, Dyn(4)).unwrap();
        let flux = o.flux_scale(40_000.0);
        let y0 = fixed.steady_state(flux).unwrap();
        let y0_dyn = dynamic.steady_state(flux).unwrap();
        assert_eq!(y0.as_slice(), y0_dyn.as_slice());
        let method = Method::Dopri5(Tolerances::default());
        let out = Output::Every(60.0);
        let span = (40_000.0, 50_000.0);
        let a = run(&mut fixed, &method, span, y0, &out).unwrap();
        let b = run(&mut dynamic, &method, span, y0_dyn, &out).unwrap();
        assert_eq!(a.stats, b.stats);
        for (x, y) in a.y.iter().zip(&b.y) {
            assert_eq!(x.as_slice(), y.as_slice());
        }
        assert!(Coupled::compose(
            TwoLayer::new(&p),
            Hinge::new(&p, model),
            o,
            coupling,
            Dyn(5)
        )
        .is_err());
    }
}
