//! The hybrid propagator on the N-node model, against the full integration of the same model
//! and the N-node flutter analysis.

use super::tests::{compare, spec};
use super::HybridSettings;
use crate::analysis::layered::{start_state, LayeredPoint};
use crate::cancel::Cancel;
use crate::inputs::orbit::{Orbit, Shadow};
use crate::inputs::panel::Panel;
use crate::models::conduction::Conduction;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use crate::runs::hybrid::layered::{run_orbits_hybrid, LayeredHybrid};
use crate::runs::layered::{run_orbits, LayeredRunRequest, LayeredSummaries};

const MODEL: HingeModel = HingeModel::Nonlinear;
const COUPLING: Coupling = Coupling::ProjectedArea;

/// The operating point of `panel` and `c` at full sun.
fn point<'a>(panel: &'a Panel, c: &'a Conduction) -> LayeredPoint<'a> {
    LayeredPoint {
        panel,
        conduction: c,
        model: MODEL,
        coupling: COUPLING,
        loads: crate::inputs::heating::Loads::sun(1.0),
    }
}

fn start(panel: &Panel, c: &Conduction, orbit: &Orbit, kick: f64) -> Vec<f64> {
    let mut y = start_state(panel, c, COUPLING, orbit, 0.0).unwrap();
    let n = y.len();
    y[n - 2] += kick;
    y
}

/// The N-node run of `n` orbits from `y0` at the tests' settings.
fn request(panel: &Panel, c: &Conduction, orbit: &Orbit, n: u64, y0: &[f64]) -> LayeredRunRequest {
    LayeredRunRequest {
        spec: spec(panel, orbit, n),
        conduction: c.clone(),
        y0: y0.to_vec(),
    }
}

fn hybrid(panel: &Panel, c: &Conduction, orbit: &Orbit, n: u64, y0: &[f64]) -> LayeredHybrid {
    let req = request(panel, c, orbit, n, y0);
    run_orbits_hybrid(&req, &HybridSettings::default(), &Cancel::new()).unwrap()
}

fn full(panel: &Panel, c: &Conduction, orbit: &Orbit, n: u64, y0: &[f64]) -> LayeredSummaries {
    run_orbits(&request(panel, c, orbit, n, y0), &Cancel::new()).unwrap()
}

#[test]
fn three_nodes_through_penumbra_eclipses_match_the_full_run() {
    // Three orbits of the spring eclipse season, as the two-layer test; damped above the
    // three-node c_d* (4.3 N m s/rad: the paper's 3.0 flutters with three nodes).
    let panel = Panel {
        damping: 5.0,
        ..Panel::paper()
    };
    let c = Conduction::homogeneous(&panel, 3).unwrap();
    let orbit = Orbit::geo_year(70.0);
    let y0 = start(&panel, &c, &orbit, 0.0);
    let reference = full(&panel, &c, &orbit, 3, &y0);
    let hyb = hybrid(&panel, &c, &orbit, 3, &y0);
    compare(&reference.summaries, &hyb.run.summaries);
    let s = &hyb.split;
    assert!(s.t_linear > 2.0 * orbit.period, "{}", s.t_linear);
    assert!(s.t_exponential > 0.0, "{}", s.t_exponential);
    // The guard on the linear arcs' drift hands part of the recovery to the full integration.
    assert!(
        hyb.run.stats.n_steps * 5 < reference.stats.n_steps,
        "{} steps against {}; {s:?}",
        hyb.run.stats.n_steps,
        reference.stats.n_steps
    );
    let total = s.t_linear + s.t_exponential + s.t_fallback;
    assert!((total - 3.0 * orbit.period).abs() < 1e-6 * total);
    // The end state in node temperatures (and θ) as the full run's: within 0.01 K (5e-6 rad).
    let n = y0.len();
    assert_eq!(hyb.run.y_end.len(), n);
    for (i, (a, b)) in hyb.run.y_end.iter().zip(&reference.y_end).enumerate() {
        let tol = if i < n - 2 { 1e-2 } else { 5e-6 };
        assert!(i == n - 1 || (a - b).abs() < tol, "y_end[{i}]: {a} vs {b}");
    }
}

#[test]
fn weak_flutter_of_three_nodes_grows_at_the_n_node_eigenvalue() {
    let base = Panel {
        solar_constant: 1361.0 * 1.034,
        ..Panel::paper()
    };
    let c = Conduction::homogeneous(&base, 3).unwrap();
    let crit = point(&base, &c).critical_damping().unwrap();
    let orbit = Orbit {
        shadow: Shadow::None,
        ..Orbit::geo_equinox()
    };
    for damping in [crit - 0.1, crit + 0.1] {
        let panel = Panel { damping, ..base };
        let c = Conduction::homogeneous(&panel, 3).unwrap();
        let predicted = point(&panel, &c).analyse().unwrap().growth_rate;
        let run = hybrid(&panel, &c, &orbit, 4, &start(&panel, &c, &orbit, 1e-6));
        let s = &run.run.summaries;
        let measured = (s[3].amplitude / s[1].amplitude).ln() / (2.0 * orbit.period);
        assert!(
            (measured / predicted - 1.0).abs() < 0.01,
            "c_d {damping}: {measured:e} vs {predicted:e}"
        );
        assert_eq!(run.split.t_linear, 4.0 * orbit.period);
    }
}

#[test]
fn two_nodes_are_the_two_layer_hybrid_to_the_bit() {
    let panel = Panel::paper();
    let c = Conduction::homogeneous(&panel, 2).unwrap();
    let orbit = Orbit::geo_year(70.0);
    let y0 = start(&panel, &c, &orbit, 1e-6);
    let req = request(&panel, &c, &orbit, 2, &y0).two_layer();
    let two = super::run_orbits_hybrid(&req, &HybridSettings::default(), &Cancel::new()).unwrap();
    let n = hybrid(&panel, &c, &orbit, 2, &y0);
    assert_eq!(n.run.summaries, two.run.summaries);
    assert_eq!(n.run.y_end, two.run.y_end.as_slice());
    assert_eq!(n.run.stats.n_steps, two.run.stats.n_steps);
}
