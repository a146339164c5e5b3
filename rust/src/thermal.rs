//! Heat balance of the plate per unit area (paper eqs. 1 and 2).
//!
//! `flux` is the absorbed-side solar flux factor: illumination × flux scale × projected-area
//! factor, so that the absorbed power is α C · flux.

use crate::params::Panel;
use crate::STEFAN_BOLTZMANN;

/// dT/dt of the isothermal plate (eq. 1): m c dT/dt = α C s − σ (ε_f + ε_b) T⁴.
#[inline]
pub fn one_node_rate(panel: &Panel, flux: f64, t: f64) -> f64 {
    let t4 = (t * t) * (t * t);
    let absorbed = panel.absorptivity * panel.solar_constant * flux;
    let emitted = STEFAN_BOLTZMANN * (panel.emissivity_front + panel.emissivity_back) * t4;
    (absorbed - emitted) / panel.heat_capacity()
}

/// (dT_f/dt, dT_b/dt) of the two-layer plate (eq. 2); each layer holds half the heat capacity.
#[inline]
pub fn two_layer_rates(panel: &Panel, flux: f64, t_front: f64, t_back: f64) -> (f64, f64) {
    let half_capacity = 0.5 * panel.heat_capacity();
    let conducted = panel.conductance * (t_front - t_back);
    let tf4 = (t_front * t_front) * (t_front * t_front);
    let tb4 = (t_back * t_back) * (t_back * t_back);
    let absorbed = panel.absorptivity * panel.solar_constant * flux;
    let front = absorbed - conducted - STEFAN_BOLTZMANN * panel.emissivity_front * tf4;
    let back = conducted - STEFAN_BOLTZMANN * panel.emissivity_back * tb4;
    (front / half_capacity, back / half_capacity)
}

/// Equilibrium temperature of the isothermal plate under constant flux factor `flux`, K.
pub fn one_node_equilibrium(panel: &Panel, flux: f64) -> f64 {
    let absorbed = panel.absorptivity * panel.solar_constant * flux;
    (absorbed / (STEFAN_BOLTZMANN * (panel.emissivity_front + panel.emissivity_back))).powf(0.25)
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
}
