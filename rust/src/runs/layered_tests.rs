//! Tests of the N-node laminate on the hinge: the model, its steady state and flutter, its runs.

use crate::analysis::layered::{equilibrium, start_state, LayeredEquilibrium, LayeredPoint};
use crate::error::Error;
use crate::inputs::heating::Loads;
use crate::inputs::laminate::{wing_layup, Laminate, MATERIALS};
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::conduction::Conduction;
use crate::models::coupled::Coupled;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use crate::models::layered::{Layered, Thermal, FAST_MODE_FACTOR};
use crate::runs::layered::{
    run_orbits, run_orbits_reading, simulate, LayeredOrbit, LayeredRun, LayeredRunRequest,
};
use nalgebra::{DMatrix, DVector};

/// The operating point of `p` and `c` at full sun.
fn point<'a>(
    p: &'a Panel,
    c: &'a Conduction,
    model: HingeModel,
    coupling: Coupling,
) -> LayeredPoint<'a> {
    LayeredPoint {
        panel: p,
        conduction: c,
        model,
        coupling,
        loads: crate::inputs::heating::Loads::sun(1.0),
    }
}

/// The non-linear, two-way coupled system of `p` and `c`, its conduction modes faster than
/// `fast_mode_factor` (see [`FAST_MODE_FACTOR`]) slaved; infinity slaves none.
fn nonlinear_system(p: &Panel, c: &Conduction, fast_mode_factor: f64) -> Layered {
    let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
    Layered::new(p, c.clone(), model, coupling, fast_mode_factor).unwrap()
}

/// Column `j` of ∂f/∂y of `sys` at `y` in full sun, by central differences with step `h`.
fn central_difference(sys: &Layered, y: &[f64], j: usize, h: f64) -> Vec<f64> {
    let f = |y: &[f64], dy: &mut [f64]| sys.rhs_at_flux(1.0, y, dy);
    crate::numerics::testing::central_difference(f, y, j, h)
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
            let a = point(&p, &sys.conduction, model, coupling)
                .analyse()
                .unwrap();
            let b = crate::analysis::flutter::analyse(&p, model, coupling, 1.0).unwrap();
            assert!((a.growth_rate - b.growth_rate).abs() < 1e-9 * b.growth_rate.abs().max(1e-6));
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
    let sys = nonlinear_system(&p, &c, f64::INFINITY);
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
    let sys = nonlinear_system(&p, &c, f64::INFINITY);
    let eq = equilibrium(&p, &c, Coupling::ProjectedArea, 1.0).unwrap();
    let jac = point(&p, &c, HingeModel::Nonlinear, Coupling::ProjectedArea).jacobian(&eq);
    let y = sys.state_from_nodes(&eq.temperatures, eq.theta, 0.0);
    let n = y.len();
    let mut f0 = vec![0.0; n];
    sys.rhs_at_flux(1.0, &y, &mut f0);
    assert!(f0.iter().all(|v| v.abs() < 1e-9), "equilibrium: {f0:?}");
    for j in 0..n {
        let h = if j < n - 2 { 1e-6 * y[j] } else { 1e-5 };
        let column = central_difference(&sys, &y, j, h);
        let scale = (0..n).map(|i| jac[(i, j)].abs()).fold(1e-12, f64::max);
        for (i, &fd) in column.iter().enumerate() {
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
        let sys = nonlinear_system(&p, &c, FAST_MODE_FACTOR);
        assert!(matches!(sys.thermal, Thermal::Modal(_)));
        let eq = equilibrium(&p, &c, Coupling::ProjectedArea, 1.0).unwrap();
        let y = sys.state_from_nodes(&eq.temperatures, eq.theta, 0.0);
        let mut dy = vec![0.0; y.len()];
        sys.rhs_at_flux(1.0, &y, &mut dy);
        let m = sys
            .conduction
            .moment(&sys.node_temperatures(Loads::sun(1.0), &y));
        // The moment is a sum of large terms that nearly cancel (M_T = Σ μ_i T_i − Σ μ_i T_ref):
        // compare against their size.
        let size: f64 = c
            .moment_weight
            .iter()
            .zip(&eq.temperatures)
            .map(|(m, t)| (m * t).abs())
            .sum();
        assert!((m - eq.moment).abs() < 1e-13 * size, "{m} vs {}", eq.moment);
        let t = sys.node_temperatures(Loads::sun(1.0), &y);
        for (a, b) in t.iter().zip(&eq.temperatures) {
            assert!((a / b - 1.0).abs() < 1e-12);
        }
        for (i, v) in dy.iter().enumerate() {
            assert!(v.abs() < 1e-9 * (1.0 + y[i].abs()), "{i}: {v}");
        }
    }
}

/// Under loads on both faces (the Earth's, sunlight on the back) the steady state is a fixed
/// point of the nodal model and of the slow-mode model alike (whose fast modes take the back's
/// load through their face compliance), and the moment and node temperatures it reads are the
/// equilibrium's; the loads raise the back face.
#[test]
fn face_loads_on_both_forms_are_exact_in_steady_state() {
    let lam = wing_layup();
    let p = lam.equivalent_panel(&Panel::paper()).unwrap();
    let c = Conduction::new(&p, &lam, 20).unwrap();
    let loads = Loads {
        sun: 0.8,
        front: 60.0,
        back: 250.0,
    };
    for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
        let eq = crate::analysis::layered::equilibrium_loaded(&p, &c, coupling, loads).unwrap();
        let bare = crate::analysis::layered::equilibrium_loaded(&p, &c, coupling, Loads::sun(0.8))
            .unwrap();
        assert!(eq.temperatures[19] > bare.temperatures[19] + 5.0);
        for factor in [FAST_MODE_FACTOR, f64::INFINITY] {
            let sys = Layered::new(&p, c.clone(), HingeModel::Nonlinear, coupling, factor).unwrap();
            let y = sys.state_from_nodes(&eq.temperatures, eq.theta, 0.0);
            let mut dy = vec![0.0; y.len()];
            sys.rhs_at_loads(loads, &y, &mut dy);
            for (i, v) in dy.iter().enumerate() {
                assert!(v.abs() < 1e-9 * (1.0 + y[i].abs()), "{factor} {i}: {v}");
            }
            let t = sys.node_temperatures(loads, &y);
            for (a, b) in t.iter().zip(&eq.temperatures) {
                assert!((a / b - 1.0).abs() < 1e-12, "{a} {b}");
            }
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
        let full = point(&p, &c, HingeModel::Nonlinear, Coupling::ProjectedArea)
            .analyse()
            .unwrap();
        let cd = point(&p, &c, HingeModel::Nonlinear, Coupling::ProjectedArea)
            .critical_damping()
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
            let sys = nonlinear_system(&p, &c, factor);
            let kept = sys.thermal_size();
            let y0 = DVector::from_vec(sys.state_from_nodes(&eq.temperatures, eq.theta, 0.0));
            let mut orb = LayeredOrbit::new(sys, &p, orbit);
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
    use crate::runs::simulate::{run, Output};
    // The nodal right-hand side on two nodes does eq. 2's arithmetic in eq. 2's order, so
    // the runs take the same steps; anything but rounding-level agreement would show here
    // (a near-undamped hinge amplifies any difference in the step sequence to ~1e-6).
    let case = Case::paper(Output::Every(30.0));
    let (p, o) = (case.p, case.o);
    let span = (0.0, o.period);
    let c = Conduction::homogeneous(&p, 2).unwrap();
    let (model, coupling) = (case.model, case.coupling);
    // Both from the same start (the equilibria agree to 1e-10 on their own, tested above).
    let eq = crate::analysis::steady::equilibrium(&p, coupling, 1.0).unwrap();
    let y0 = nalgebra::Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0);
    let start = [eq.t_front, eq.t_back, eq.theta, 0.0];
    let lay = case.simulate_from(c, span, Some(&start));
    let sys = &mut Coupled::new(p, o, model, coupling);
    let two = run(sys, &case.method, span, y0, &case.out).unwrap();
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
    use crate::numerics::integrate::Dyn;
    use crate::runs::simulate::{run, Output};
    let case = Case::paper(Output::Every(50.0));
    let (p, o) = (case.p, case.o);
    let (model, coupling) = (case.model, case.coupling);
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
    let (entry, _) = o.shadow_intervals(0.0, o.period)[0];
    let span = (entry - 100.0, entry + 900.0);
    let c = Conduction::homogeneous(&p, nodes).unwrap();
    let ours = case.simulate_from(c, span, Some(&start));
    let start = DVector::from_vec(start);
    let theirs = run(&mut generic, &case.method, span, start, &case.out).unwrap();
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
    use crate::runs::orbits::{OrbitRunSpec, SummaryOptions, STEPS_PER_HINGE_PERIOD};
    let mut y0 = eq.temperatures.clone();
    y0.extend([eq.theta, 0.0]);
    let spec = OrbitRunSpec {
        panel,
        orbit,
        model: HingeModel::Nonlinear,
        coupling: Coupling::ProjectedArea,
        method: Method::Dopri5(Tolerances::default()),
        t_start: 0.0,
        first_index: 0,
        n_orbits: 1,
        options: SummaryOptions {
            window: 600.0,
            theta_limit: 1.0,
            stop_at_limit: false,
            steps_per_period: STEPS_PER_HINGE_PERIOD,
        },
    };
    LayeredRunRequest {
        spec,
        conduction,
        y0,
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
        let full = point(&p, &c, HingeModel::Nonlinear, Coupling::ProjectedArea)
            .analyse()
            .unwrap();
        let eq = full.equilibrium.clone();
        println!("{name}: full growth {:.6e}", full.growth_rate);
        for factor in [1.0, 2.0, 5.0, 10.0, 20.0, 1e9] {
            let sys = nonlinear_system(&p, &c, factor);
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
                let column = central_difference(&sys, &y, j, h);
                jac.set_column(j, &DVector::from_vec(column));
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
        point(&p, &c, model, coupling).critical_damping().unwrap()
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
    let exact = point(&equal, &c2, HingeModel::Linear, coupling)
        .critical_damping()
        .unwrap();
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
    let want = std::env::var("LAMINATE_PANEL").unwrap_or_else(|_| "wing".into());
    let nodes: usize = std::env::var("LAMINATE_NODES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let (_, p, lam) = examples().into_iter().find(|e| e.0 == want).unwrap();
    let case = Case::of(p);
    let Case {
        p,
        o,
        ref method,
        model,
        coupling,
        ..
    } = case;
    let orbits = std::env::var("LAMINATE_RUN").is_ok_and(|v| v == "orbits");
    let spec = crate::runs::orbits::OrbitRunSpec {
        panel: p,
        orbit: o,
        model,
        coupling,
        method: *method,
        t_start: 0.0,
        first_index: 0,
        n_orbits: 1,
        options: crate::runs::orbits::SummaryOptions {
            window: 600.0,
            theta_limit: 0.5,
            stop_at_limit: false,
            steps_per_period: crate::runs::orbits::STEPS_PER_HINGE_PERIOD,
        },
    };
    let cancel = crate::cancel::Cancel::new();
    let steps = if nodes == 2 {
        if orbits {
            let y0 = Coupled::new(p, o, model, coupling)
                .steady_state(1.0)
                .unwrap();
            let req = crate::runs::orbits::OrbitRunRequest { spec, y0 };
            crate::runs::orbits::run_orbits_cancellable(&req, &cancel)
                .unwrap()
                .stats
        } else {
            case.run_two_layer()
        }
    } else {
        let c = Conduction::new(&p, &lam, nodes).unwrap();
        if orbits {
            let eq = equilibrium(&p, &c, coupling, 1.0).unwrap();
            let mut y0 = eq.temperatures.clone();
            y0.extend([eq.theta, 0.0]);
            let req = LayeredRunRequest {
                spec,
                conduction: c,
                y0,
            };
            run_orbits(&req, &cancel).unwrap().stats
        } else {
            case.simulate(c).stats
        }
    };
    println!("{want}, {nodes} nodes: {steps:?}");
}

/// A run of these tests: the non-linear, two-way coupled hinge, rk45 at the default tolerances.
struct Case {
    p: Panel,
    o: Orbit,
    method: crate::numerics::integrate::Method,
    out: crate::runs::simulate::Output,
    model: HingeModel,
    coupling: Coupling,
}

impl Case {
    /// The paper's panel on the GEO equinox orbit, sampled as `out` asks.
    fn paper(out: crate::runs::simulate::Output) -> Self {
        Case {
            p: Panel::paper(),
            o: Orbit::geo_equinox(),
            method: crate::numerics::integrate::Method::Dopri5(
                crate::numerics::integrate::Tolerances::default(),
            ),
            out,
            model: HingeModel::Nonlinear,
            coupling: Coupling::ProjectedArea,
        }
    }

    /// The setting of the cost measurements: one GEO orbit of an example panel at 1 % of its
    /// critical damping, sampled at the orbit's end.
    fn of(p: Panel) -> Self {
        let o = Orbit::geo_equinox();
        Case {
            p: Panel {
                damping: 0.01 * (p.hinge_stiffness * p.hinge_inertia()).sqrt(),
                ..p
            },
            o,
            ..Case::paper(crate::runs::simulate::Output::Times(vec![o.period]))
        }
    }

    /// The N-node `simulate` of the orbit from its sunlit equilibrium.
    fn simulate(&self, c: Conduction) -> LayeredRun {
        self.simulate_from(c, (0.0, self.o.period), None)
    }

    /// The N-node `simulate` over `span` from `start` (default: the sunlit equilibrium).
    fn simulate_from(&self, c: Conduction, span: (f64, f64), start: Option<&[f64]>) -> LayeredRun {
        simulate(
            &self.p,
            c,
            &self.o,
            self.model,
            self.coupling,
            &self.method,
            span,
            start,
            &self.out,
            None,
            &crate::cancel::Cancel::new(),
        )
        .unwrap()
    }

    /// The two-layer run of the orbit from its sunlit steady state.
    fn run_two_layer(&self) -> crate::numerics::integrate::Stats {
        let mut sys = Coupled::new(self.p, self.o, self.model, self.coupling);
        let y0 = sys.steady_state(1.0).unwrap();
        let span = (0.0, self.o.period);
        let run = crate::runs::simulate::run(&mut sys, &self.method, span, y0, &self.out);
        run.unwrap().stats
    }
}

/// Wall time of one GEO orbit (`simulate`), 20 nodes against the two-layer model, both
/// example panels, interleaved, best of 7: `cargo test --release -- --ignored orbit_time
/// --nocapture`. (The bench through Python is benches/laminate.py.)
#[test]
#[ignore]
fn orbit_time() {
    for (name, p, lam) in examples() {
        let case = Case::of(p);
        let mut best = [f64::INFINITY; 2];
        for _ in 0..7 {
            let start = std::time::Instant::now();
            case.run_two_layer();
            best[0] = best[0].min(start.elapsed().as_secs_f64());
            let start = std::time::Instant::now();
            case.simulate(Conduction::new(&case.p, &lam, 20).unwrap());
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
        let sys = nonlinear_system(&p, &c, FAST_MODE_FACTOR);
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
        let y4 = nalgebra::Vector4::new(eq.temperatures[0], eq.temperatures[19], eq.theta, 1e-3);
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
