//! Heat balance of the plate per unit area (paper eqs. 1 and 2) and the trait every
//! through-thickness thermal model implements.
//!
//! `flux` is the absorbed-side solar flux factor: illumination × flux scale × projected-area
//! factor, so that the absorbed power is α C · flux.
//!
//! Each equation is written once, as a balance whose coefficients carry the unit: in W/m² (the
//! heat flows, divided by the heat capacity to give rates) or already divided by the capacity
//! (K/s, the form the integrator's hot path uses, with no division left in it).

use crate::inputs::panel::Panel;
use crate::numerics::simd::{Fused, Num};

/// Stefan–Boltzmann constant, W/(m² K⁴) (CODATA 2018, exact).
pub const STEFAN_BOLTZMANN: f64 = 5.670_374_419e-8;

/// Highest temperature a panel is described at, K: above any structural material's melting point
/// (and σT⁴ stays a number; at 1e300 K it is inf).
pub const MAX_TEMPERATURE: f64 = 1e4;

/// A through-thickness thermal model of the plate: its temperatures, their rates under an
/// absorbed flux, and the thermal moment they bend the plate with.
///
/// Temperatures are passed as slices in the model's own order (its [`ThermalModel::names`]);
/// the coupled system ([`crate::models::coupled::Coupled`]) puts them first in its state vector.
pub trait ThermalModel {
    /// Number of temperatures.
    fn size(&self) -> usize;

    /// Name of each temperature, as results label it ("T_front", "T_back", ...).
    fn names(&self) -> Vec<String>;

    /// Net heat flow into each temperature's share of the plate under the absorbed flux factor
    /// `flux`, W/m², into `out`.
    fn heat_flows(&self, flux: f64, temps: &[f64], out: &mut [f64]);

    /// Heat capacity of temperature `i`'s share of the plate, J/(m² K).
    fn capacity(&self, i: usize) -> f64;

    /// dT/dt of every temperature, K/s, into `out`. By default [`ThermalModel::flow_rates`]; a
    /// model may override it with coefficients already divided by the capacities, the same
    /// equation with no division left on the integrator's hot path (rounded differently).
    #[inline]
    fn rates(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        self.flow_rates(flux, temps, out);
    }

    /// [`ThermalModel::rates`] with its multiply-adds fused where the model has a fused form
    /// (the two-layer plate does), else `rates` itself. Only code compiled for FMA calls it
    /// (`numerics::cpu::ScalarKernel::Fma`).
    #[inline(always)]
    fn rates_fused(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        self.rates(flux, temps, out);
    }

    /// dT/dt as written: the heat flows over the capacities, K/s. Not meant to be overridden.
    #[inline]
    fn flow_rates(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        self.heat_flows(flux, temps, out);
        for (i, rate) in out.iter_mut().enumerate() {
            *rate /= self.capacity(i);
        }
    }

    /// Equivalent through-thickness temperature difference ΔT, K, with the thermal moment
    /// M_T = [`ThermalModel::moment_per_kelvin`] · ΔT (T_f − T_b for two layers).
    fn gradient(&self, temps: &[f64]) -> f64;

    /// Thermal moment per kelvin of [`ThermalModel::gradient`], N m/K (0: the model does not
    /// bend the plate).
    fn moment_per_kelvin(&self) -> f64;

    /// The thermal moment M_T, N m.
    #[inline]
    fn moment(&self, temps: &[f64]) -> f64 {
        self.moment_per_kelvin() * self.gradient(temps)
    }

    /// The thermal moment of each of a row of plates (`temps` holds their temperatures one plate
    /// after another), into `out`: one call for a whole panel of elements.
    fn moments_of(&self, temps: &[f64], out: &mut [f64]) {
        for (t, m) in temps.chunks_exact(self.size()).zip(out) {
            *m = self.moment(t);
        }
    }

    /// A starting point for the steady state under `flux`: every temperature at the isothermal
    /// plate's equilibrium.
    fn initial_guess(&self, flux: f64, out: &mut [f64]);

    /// Refuses a start of the temperatures `temps` the model does not describe: by default each
    /// an absolute temperature, finite and > 0 K (a model whose states include a perturbation
    /// checks those as it must).
    fn check_start(&self, temps: &[f64]) -> crate::error::Result<()> {
        crate::models::hinge::check_start_state(temps, temps.len(), None)
    }

    /// The temperatures of the front and of the back face (the first and the last; the same
    /// one for the isothermal plate).
    #[inline]
    fn faces(&self) -> (usize, usize) {
        (0, self.size() - 1)
    }

    /// Adds loads absorbed on the front and on the back face, W/m², to the heat flows `out`.
    #[inline]
    fn add_face_flows(&self, front: f64, back: f64, out: &mut [f64]) {
        let (f, b) = self.faces();
        out[f] += front;
        out[b] += back;
    }

    /// Adds loads absorbed on the front and on the back face, W/m², to the rates `out`, K/s.
    #[inline]
    fn add_face_rates(&self, front: f64, back: f64, out: &mut [f64]) {
        let (f, b) = self.faces();
        out[f] += front / self.capacity(f);
        out[b] += back / self.capacity(b);
    }
}

/// A boxed model is a model (what [`crate::models::thermal_model`] returns).
impl<M: ThermalModel + ?Sized> ThermalModel for Box<M> {
    fn size(&self) -> usize {
        (**self).size()
    }
    fn names(&self) -> Vec<String> {
        (**self).names()
    }
    fn rates(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        (**self).rates(flux, temps, out)
    }
    fn rates_fused(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        (**self).rates_fused(flux, temps, out)
    }
    fn heat_flows(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        (**self).heat_flows(flux, temps, out)
    }
    fn capacity(&self, i: usize) -> f64 {
        (**self).capacity(i)
    }
    fn gradient(&self, temps: &[f64]) -> f64 {
        (**self).gradient(temps)
    }
    fn moments_of(&self, temps: &[f64], out: &mut [f64]) {
        (**self).moments_of(temps, out)
    }
    fn moment_per_kelvin(&self) -> f64 {
        (**self).moment_per_kelvin()
    }
    fn initial_guess(&self, flux: f64, out: &mut [f64]) {
        (**self).initial_guess(flux, out)
    }
    fn check_start(&self, temps: &[f64]) -> crate::error::Result<()> {
        (**self).check_start(temps)
    }
    fn faces(&self) -> (usize, usize) {
        (**self).faces()
    }
}

/// A thermal model whose rates are computed as written, heat flows over capacities: the form of
/// the reference oracle, whose steps the thermal models alone reproduce (tests/test_controller.py).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsWritten<M>(pub M);

impl<M: ThermalModel> ThermalModel for AsWritten<M> {
    fn size(&self) -> usize {
        self.0.size()
    }
    fn names(&self) -> Vec<String> {
        self.0.names()
    }
    fn heat_flows(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        self.0.heat_flows(flux, temps, out)
    }
    fn capacity(&self, i: usize) -> f64 {
        self.0.capacity(i)
    }
    fn gradient(&self, temps: &[f64]) -> f64 {
        self.0.gradient(temps)
    }
    fn moment_per_kelvin(&self) -> f64 {
        self.0.moment_per_kelvin()
    }
    fn initial_guess(&self, flux: f64, out: &mut [f64]) {
        self.0.initial_guess(flux, out)
    }
    fn check_start(&self, temps: &[f64]) -> crate::error::Result<()> {
        self.0.check_start(temps)
    }
    fn faces(&self) -> (usize, usize) {
        self.0.faces()
    }
}

/// The isothermal plate (eq. 1): m c dT/dt = α C s − σ (ε_f + ε_b) T⁴. It does not bend.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneNode {
    /// α C, W/m² per unit flux factor.
    heating: f64,
    /// σ (ε_f + ε_b), W/(m² K⁴).
    radiation: f64,
    /// m c, J/(m² K).
    capacity: f64,
}

impl OneNode {
    pub fn new(panel: &Panel) -> Self {
        OneNode {
            heating: panel.absorptivity * panel.solar_constant,
            radiation: STEFAN_BOLTZMANN * (panel.emissivity_front + panel.emissivity_back),
            capacity: panel.heat_capacity(),
        }
    }

    /// Eq. 1's heat balance, W/m².
    #[inline(always)]
    fn flow(&self, flux: f64, t: f64) -> f64 {
        let t4 = (t * t) * (t * t);
        self.heating * flux - self.radiation * t4
    }

    /// dT/dt, K/s.
    #[inline]
    pub fn rate(&self, flux: f64, t: f64) -> f64 {
        self.flow(flux, t) / self.capacity
    }

    /// Equilibrium temperature under constant flux factor `flux`, K.
    pub fn equilibrium(&self, flux: f64) -> f64 {
        (self.heating * flux / self.radiation).powf(0.25)
    }
}

impl ThermalModel for OneNode {
    fn size(&self) -> usize {
        1
    }
    fn names(&self) -> Vec<String> {
        vec!["T".into()]
    }
    fn heat_flows(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        out[0] = self.flow(flux, temps[0]);
    }
    fn capacity(&self, _i: usize) -> f64 {
        self.capacity
    }
    #[inline]
    fn gradient(&self, _temps: &[f64]) -> f64 {
        0.0
    }
    fn moment_per_kelvin(&self) -> f64 {
        0.0
    }
    fn initial_guess(&self, flux: f64, out: &mut [f64]) {
        out[0] = self.equilibrium(flux);
    }
}

/// Coefficients of eq. 2's two heat balances, in W/m² per unit of their variable, or divided by
/// the layer's heat capacity (per second).
/// `T` is f64, or one value per lane for several panels at once (`integrate::lockstep`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Balance<T = f64> {
    /// α C: absorbed per unit flux factor.
    pub(crate) heating: T,
    /// K: conducted per kelvin of T_f − T_b.
    pub(crate) conduction: T,
    /// σ ε_f and σ ε_b: emitted per T⁴.
    pub(crate) radiation_front: T,
    pub(crate) radiation_back: T,
}

impl Balance {
    /// The same coefficients as values of `T`.
    #[inline(always)]
    pub(crate) fn to<T: From<f64>>(&self) -> Balance<T> {
        Balance {
            heating: T::from(self.heating),
            conduction: T::from(self.conduction),
            radiation_front: T::from(self.radiation_front),
            radiation_back: T::from(self.radiation_back),
        }
    }

    fn per_capacity(&self, capacity: f64) -> Self {
        Balance {
            heating: self.heating / capacity,
            conduction: self.conduction / capacity,
            radiation_front: self.radiation_front / capacity,
            radiation_back: self.radiation_back / capacity,
        }
    }
}

impl<T: Num> Balance<T> {
    /// Eq. 2: (front, back) = (α C flux − K (T_f − T_b) − σ ε_f T_f⁴, K (T_f − T_b) − σ ε_b T_b⁴).
    #[inline(always)]
    pub(crate) fn flows(&self, flux: T, t_front: T, t_back: T) -> (T, T) {
        let conducted = self.conduction * (t_front - t_back);
        let tf4 = (t_front * t_front) * (t_front * t_front);
        let tb4 = (t_back * t_back) * (t_back * t_back);
        // (α C flux − conducted) − σ ε_f T_f⁴ and conducted − σ ε_b T_b⁴.
        let absorbed = self.heating.mul_sub(flux, conducted);
        let front = self.radiation_front.neg_mul_add(tf4, absorbed);
        let back = self.radiation_back.neg_mul_add(tb4, conducted);
        (front, back)
    }
}

/// The two-layer plate (eq. 2), each layer holding half the heat capacity; temperatures
/// (T_f, T_b); thermal moment χ a E I (T_f − T_b) / d.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoLayer {
    /// The balance in W/m².
    heat: Balance,
    /// The balance per half capacity, K/s: the right-hand side holds no division.
    rate: Balance,
    /// m c / 2, J/(m² K).
    half_capacity: f64,
    /// 2 / (m c): the faces' loads to rates without a division.
    per_half_capacity: f64,
    /// χ a E I / d, N m/K.
    moment_per_kelvin: f64,
    isothermal: OneNode,
}

impl TwoLayer {
    pub fn new(panel: &Panel) -> Self {
        let heat = Balance {
            heating: panel.absorptivity * panel.solar_constant,
            conduction: panel.conductance,
            radiation_front: STEFAN_BOLTZMANN * panel.emissivity_front,
            radiation_back: STEFAN_BOLTZMANN * panel.emissivity_back,
        };
        let half_capacity = 0.5 * panel.heat_capacity();
        TwoLayer {
            heat,
            rate: heat.per_capacity(half_capacity),
            half_capacity,
            per_half_capacity: 1.0 / half_capacity,
            moment_per_kelvin: panel.moment_per_kelvin(),
            isothermal: OneNode::new(panel),
        }
    }

    /// (dT_f/dt, dT_b/dt), K/s.
    /// The balance per half capacity that [`TwoLayer::rates_of`] evaluates.
    pub(crate) fn rate_balance(&self) -> Balance {
        self.rate
    }

    #[inline(always)]
    pub fn rates_of(&self, flux: f64, t_front: f64, t_back: f64) -> (f64, f64) {
        self.rate.flows(flux, t_front, t_back)
    }
}

impl ThermalModel for TwoLayer {
    fn size(&self) -> usize {
        2
    }
    fn names(&self) -> Vec<String> {
        vec!["T_front".into(), "T_back".into()]
    }
    #[inline(always)]
    fn rates(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        let (front, back) = self.rates_of(flux, temps[0], temps[1]);
        out[0] = front;
        out[1] = back;
    }
    #[inline(always)]
    fn rates_fused(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        let (front, back) =
            self.rate
                .to::<Fused>()
                .flows(Fused(flux), Fused(temps[0]), Fused(temps[1]));
        out[0] = front.0;
        out[1] = back.0;
    }
    fn heat_flows(&self, flux: f64, temps: &[f64], out: &mut [f64]) {
        let (front, back) = self.heat.flows(flux, temps[0], temps[1]);
        out[0] = front;
        out[1] = back;
    }
    fn capacity(&self, _i: usize) -> f64 {
        self.half_capacity
    }
    #[inline(always)]
    fn add_face_rates(&self, front: f64, back: f64, out: &mut [f64]) {
        out[0] += front * self.per_half_capacity;
        out[1] += back * self.per_half_capacity;
    }
    #[inline(always)]
    fn gradient(&self, temps: &[f64]) -> f64 {
        temps[0] - temps[1]
    }
    fn moment_per_kelvin(&self) -> f64 {
        self.moment_per_kelvin
    }
    fn initial_guess(&self, flux: f64, out: &mut [f64]) {
        out.fill(self.isothermal.equilibrium(flux));
    }
}

/// dT/dt of the isothermal plate (eq. 1), K/s.
pub fn one_node_rate(panel: &Panel, flux: f64, t: f64) -> f64 {
    OneNode::new(panel).rate(flux, t)
}

/// (dT_f/dt, dT_b/dt) of the two-layer plate (eq. 2) from its heat flows over the half capacity.
pub fn two_layer_rates(panel: &Panel, flux: f64, t_front: f64, t_back: f64) -> (f64, f64) {
    let model = TwoLayer::new(panel);
    let (front, back) = model.heat.flows(flux, t_front, t_back);
    (front / model.half_capacity, back / model.half_capacity)
}

/// Equilibrium temperature of the isothermal plate under constant flux factor `flux`, K.
pub fn one_node_equilibrium(panel: &Panel, flux: f64) -> f64 {
    OneNode::new(panel).equilibrium(flux)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_node_equilibrium_is_a_fixed_point() {
        let p = Panel::paper();
        let t = one_node_equilibrium(&p, 1.0);
        assert!(one_node_rate(&p, 1.0, t).abs() < 1e-12);
        assert!(t > 350.0 && t < 380.0, "{t}");
    }

    #[test]
    fn two_layers_conserve_energy_without_radiation_or_sun() {
        // With σ-terms negligible (cold plate) and no Sun, conduction only moves heat around.
        let p = Panel::paper();
        let (df, db) = two_layer_rates(&p, 0.0, 1e-3, 0.0);
        assert!((df + db).abs() < 1e-15 * df.abs().max(1e-300) + 1e-30);
        assert!(df < 0.0 && db > 0.0);
    }

    #[test]
    fn rates_are_heat_flows_over_the_half_capacity() {
        let p = Panel::paper();
        let m = TwoLayer::new(&p);
        let half = 0.5 * p.heat_capacity();
        for (flux, tf, tb) in [
            (1.0, 380.0, 368.0),
            (0.3, 250.0, 262.0),
            (0.0, 120.0, 119.0),
        ] {
            let (mut rates, mut flows) = ([0.0; 2], [0.0; 2]);
            m.rates(flux, &[tf, tb], &mut rates);
            m.heat_flows(flux, &[tf, tb], &mut flows);
            for i in 0..2 {
                assert!((rates[i] * half - flows[i]).abs() <= 1e-12 * flows[i].abs().max(1.0));
            }
            // The textbook form, term by term.
            let sigma = STEFAN_BOLTZMANN;
            let front = p.absorptivity * p.solar_constant * flux
                - p.conductance * (tf - tb)
                - sigma * p.emissivity_front * tf.powi(4);
            assert!((flows[0] - front).abs() <= 1e-12 * front.abs().max(1.0));
        }
        assert_eq!(m.moment(&[300.0, 290.0]), 10.0 * p.moment_per_kelvin());
    }
}
