use super::*;

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
            let (mut yp, mut ym) = (y.clone(), y.clone());
            yp[c] += h;
            ym[c] -= h;
            let (mut fp, mut fm) = (vec![0.0; size], vec![0.0; size]);
            m.rhs_at_flux(0.9, &yp, &mut fp);
            m.rhs_at_flux(0.9, &ym, &mut fm);
            let scale = jac.column(c).amax().max(1e-12);
            for r in 0..size {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                assert!(
                    (fd - jac[(r, c)]).abs() < 1e-6 * scale,
                    "{support:?} ({r},{c}): {fd} vs {}",
                    jac[(r, c)]
                );
            }
        }
    }
}
