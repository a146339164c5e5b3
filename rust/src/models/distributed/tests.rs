use super::*;
use crate::numerics::testing::central_difference;

fn model(support: Support, n: usize, k: usize, coupling: Coupling) -> DistributedPanel {
    let panel = Panel {
        damping: 0.0,
        ..Panel::paper()
    };
    let settings = Settings {
        support,
        elements: n,
        modes: k,
        coupling,
        sun_angle: if support == Support::Cantilever {
            0.3
        } else {
            0.0
        },
        ..Settings::new(&panel)
    };
    DistributedPanel::new(&panel, settings).unwrap()
}

#[test]
fn equilibrium_is_a_fixed_point() {
    for support in [Support::FreeFree, Support::Cantilever] {
        for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
            let m = model(support, 9, 3, coupling);
            let y = m.equilibrium(1.0).unwrap();
            let mut dy = vec![0.0; y.len()];
            m.rhs_at_flux(1.0, &y, &mut dy);
            let worst = dy.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(worst < 1e-10, "{support:?} {coupling:?}: {worst}");
        }
    }
}

#[test]
fn analytic_jacobian_matches_finite_differences() {
    for support in [Support::FreeFree, Support::Cantilever] {
        let m = model(support, 7, 3, Coupling::ProjectedArea);
        let mut y = m.equilibrium(1.0).unwrap();
        // Off equilibrium so that every term is exercised.
        for (i, v) in y.iter_mut().enumerate() {
            *v += 1e-2 * ((i * 7 % 5) as f64 - 2.0) * v.abs().max(1.0);
        }
        let jac = m.jacobian(0.9, &y);
        let size = y.len();
        for c in 0..size {
            let h = 1e-6 * y[c].abs().max(1e-2);
            let f = |y: &[f64], dy: &mut [f64]| m.rhs_at_flux(0.9, y, dy);
            let column = central_difference(f, &y, c, h);
            let scale = jac.column(c).amax().max(1e-12);
            for (r, &fd) in column.iter().enumerate() {
                assert!(
                    (fd - jac[(r, c)]).abs() < 1e-6 * scale,
                    "{support:?} ({r},{c}): {fd} vs {}",
                    jac[(r, c)]
                );
            }
        }
    }
}

mod runs {
    use super::*;
    use crate::inputs::orbit::{Orbit, Shadow};
    use crate::models::beam::FreeFreeBeam;
    use crate::models::coupled::MomentHistory;
    use crate::numerics::integrate::{Method, Tolerances};
    use crate::runs::beam::respond;
    use crate::runs::distributed::simulate;
    use crate::runs::simulate::{Output, TransientSettings};

    fn tight(rtol: f64) -> Method {
        Method::Dopri5(Tolerances {
            rtol,
            atol: rtol * 1e-2,
            ..Tolerances::default()
        })
    }

    /// Sample times every `dt` over `span`, plus the extra times (kinks of the moment).
    fn times(span: (f64, f64), dt: f64, extra: &[f64]) -> Vec<f64> {
        let mut t: Vec<f64> = (0..)
            .map(|i| span.0 + dt * i as f64)
            .take_while(|t| *t <= span.1)
            .collect();
        t.extend_from_slice(extra);
        t.sort_by(f64::total_cmp);
        t.dedup();
        t
    }

    #[test]
    fn frozen_uniform_panel_is_the_beam_comparator() {
        // Frozen coupling and the Sun on the normal: every element sees the same flux, so all
        // carry the same temperatures, the moment is uniform, and its consistent loads are the
        // comparator's end moments. With the same mesh and the same dynamic modes (the 8
        // symmetric ones among 16) the two must agree to integration accuracy.
        let panel = Panel::paper();
        let orbit = Orbit::geo_equinox();
        let (a, b) = orbit.shadow_intervals(0.0, orbit.period)[0];
        let span = (a - 1200.0, b + 1200.0);
        let settings = Settings {
            elements: 40,
            modes: 16,
            coupling: Coupling::Frozen,
            ..Settings::new(&panel)
        };
        let m = DistributedPanel::new(&panel, settings).unwrap();
        let method = tight(1e-10);
        // The moment is sampled finely (it is interpolated linearly by the comparator) and at
        // the shadow exit, where its slope jumps.
        let ts = times(span, 0.1, &[b]);
        let run_settings = TransientSettings {
            method,
            span,
            output: Output::Times(ts.clone()),
            y0: None,
            limit: None,
        };
        let run = simulate(&m, orbit, run_settings, &crate::cancel::Cancel::new()).unwrap();
        for sample in &run.temperatures {
            for row in sample {
                assert!(row.iter().all(|v| *v == row[0]), "temperatures differ");
            }
        }
        let moment: Vec<f64> = run.moment.iter().map(|row| row[0]).collect();
        let beam = FreeFreeBeam::new(&panel, 40).unwrap();
        let history = MomentHistory::Samples {
            t: run.t.clone(),
            moment,
        };
        let resp = respond(
            &beam,
            history,
            settings.damping_ratio,
            true,
            &method,
            span,
            &Output::Times(ts),
            &crate::cancel::Cancel::new(),
        )
        .unwrap();
        let worst = run
            .theta_f
            .iter()
            .zip(&resp.theta_f)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f64, f64::max);
        // The eclipse swings θ_f by about 0.085 rad.
        let swing = run.theta_f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(swing > 0.08, "{swing}");
        eprintln!("θ_f: distributed vs comparator, max difference {worst:.3e} rad");
        assert!(
            worst < 1e-6,
            "θ_f differs from the comparator by {worst} rad"
        );
    }

    /// Growth rate of the first mode's oscillation from the peaks of θ_f − θ_eq: a least-squares
    /// line through log(peak) against time, after the thermal transients have died out.
    fn measured_growth(panel: &Panel, zeta: f64) -> (f64, f64) {
        let settings = Settings {
            damping_ratio: zeta,
            ..Settings::new(panel)
        };
        let m = DistributedPanel::new(panel, settings).unwrap();
        let predicted = m.flutter(1.0).unwrap().growth_rate;
        let orbit = Orbit {
            shadow: Shadow::None,
            ..Orbit::geo_equinox()
        };
        let mut y0 = m.equilibrium(1.0).unwrap();
        let theta_eq = m.theta_f(&y0, 0.0).unwrap();
        // A small kick of the first mode (linear regime: about 1e-4 rad of θ_f).
        let nt = m.state_size() - 2 * m.k();
        y0[nt] += 1e-4 / m.reduction.rise_modal[0].abs() * m.reduction.mesh.arm();
        let span = (0.0, 8000.0);
        let ts = times(span, 0.05, &[]);
        let settings = TransientSettings {
            method: tight(1e-11),
            span,
            output: Output::Times(ts),
            y0: Some(y0),
            limit: None,
        };
        let run = simulate(&m, orbit, settings, &crate::cancel::Cancel::new()).unwrap();
        let x: Vec<f64> = run.theta_f.iter().map(|v| v - theta_eq).collect();
        let (mut tp, mut lp) = (Vec::new(), Vec::new());
        for i in 1..x.len() - 1 {
            if run.t[i] > 1000.0 && x[i] > x[i - 1] && x[i] >= x[i + 1] {
                // Parabola through the three samples around the peak.
                let (a, b, c) = (x[i - 1], x[i], x[i + 1]);
                let d = 0.5 * (a - c) / (a - 2.0 * b + c);
                tp.push(run.t[i] + d * 0.05);
                lp.push((b - 0.25 * (a - c) * d).ln());
            }
        }
        let k = tp.len() as f64;
        let (mt, ml) = (tp.iter().sum::<f64>() / k, lp.iter().sum::<f64>() / k);
        let num: f64 = tp.iter().zip(&lp).map(|(t, l)| (t - mt) * (l - ml)).sum();
        let den: f64 = tp.iter().map(|t| (t - mt) * (t - mt)).sum();
        (num / den, predicted)
    }

    #[test]
    fn growth_rate_agrees_with_integration_in_permanent_sunlight() {
        let panel = Panel::paper();
        let zeta_star = DistributedPanel::new(&panel, Settings::new(&panel))
            .unwrap()
            .flutter(1.0)
            .unwrap()
            .critical_damping_ratio;
        // One case below the critical damping (flutters), one above (decays).
        for zeta in [0.4 * zeta_star, 2.0 * zeta_star] {
            let (measured, predicted) = measured_growth(&panel, zeta);
            eprintln!("ζ = {zeta:.4e}: integration {measured:.6e}, eigenvalue {predicted:.6e} 1/s");
            assert!(
                (measured - predicted).abs() < 0.01 * predicted.abs(),
                "ζ = {zeta}: integration {measured:e} vs eigenvalue {predicted:e} 1/s"
            );
            assert_eq!(measured > 0.0, zeta < zeta_star);
        }
    }
}

/// The limit's affine reading of the state is the tip rise θ_f is taken from, whatever the state
/// (here the equilibrium, shifted in every component), and its bound is arm · sin(θ_limit).
#[test]
fn the_limit_reads_the_tip_rise() {
    for support in [Support::FreeFree, Support::Cantilever] {
        let m = model(support, 9, 3, Coupling::ProjectedArea);
        let on = crate::runs::simulate::OnLimit::new(0.3, false).unwrap();
        let limit = m.limit(on);
        let mut y = m.equilibrium(1.0).unwrap();
        for (i, v) in y.iter_mut().enumerate() {
            *v += 1e-3 * ((i * 7 % 5) as f64 - 2.0);
        }
        let rise = limit.value(&y);
        let theta_f = m.theta_f(&y, 0.0).unwrap();
        let arm = m.reduction.mesh.arm();
        assert!((theta_f - (rise / arm).asin()).abs() < 1e-12, "{support:?}");
        assert_eq!(limit.bound, arm * 0.3f64.sin());
    }
}
