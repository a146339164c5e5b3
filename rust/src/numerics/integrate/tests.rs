//! Integrator tests on problems with exact solutions.

use super::dopri5::{A21, A3, A4, A5, A6, B, B_HAT, C};
use super::output::EveryStep;
use super::*;
use nalgebra::{Vector2, U1, U2};

/// Harmonic oscillator y'' = −y with a jump of the forcing at t = 1 (a breakpoint).
struct Oscillator {
    forcing_on_segment: f64,
    jump_at: Option<f64>,
}

impl OdeSystem<U2> for Oscillator {
    fn rhs(&self, _t: f64, y: &Vector2<f64>) -> Vector2<f64> {
        Vector2::new(y[1], -y[0] + self.forcing_on_segment)
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.jump_at
            .into_iter()
            .filter(|&t| t > t0 && t < t1)
            .collect()
    }
    fn enter_segment(&mut self, a: f64, _b: f64) {
        self.forcing_on_segment = match self.jump_at {
            Some(tj) if a >= tj => 1.0,
            _ => 0.0,
        };
    }
}

fn exact_free(t: f64) -> Vector2<f64> {
    Vector2::new(t.cos(), -t.sin())
}

#[test]
fn butcher_tableau_is_consistent() {
    let rows: [&[f64]; 5] = [&[A21], &A3, &A4, &A5, &A6];
    for (i, row) in rows.iter().enumerate() {
        let s: f64 = row.iter().sum();
        assert!((s - C[i + 1]).abs() < 1e-14, "row {}", i + 2);
    }
    let sb: f64 = B.iter().sum();
    let sbh: f64 = B_HAT.iter().sum();
    assert!((sb - 1.0).abs() < 1e-14 && (sbh - 1.0).abs() < 1e-14);
    // Order conditions of the fifth-order weights up to the quadrature ones.
    for q in 1..=5 {
        let s: f64 = (0..7).map(|i| B[i] * C[i].powi(q - 1)).sum();
        assert!((s - 1.0 / q as f64).abs() < 1e-14, "quadrature order {q}");
    }
    for q in 1..=4 {
        let s: f64 = (0..7).map(|i| B_HAT[i] * C[i].powi(q - 1)).sum();
        assert!(
            (s - 1.0 / q as f64).abs() < 1e-14,
            "embedded quadrature order {q}"
        );
    }
}

#[test]
fn dopri5_meets_tolerance_on_oscillator() {
    let mut sys = Oscillator {
        forcing_on_segment: 0.0,
        jump_at: None,
    };
    let tol = Tolerances {
        rtol: 1e-10,
        atol: 1e-12,
        ..Default::default()
    };
    let mut obs = EveryStep::default();
    let t1 = 20.0;
    let (stats, y) = solve(
        &mut sys,
        &Method::Dopri5(tol),
        0.0,
        exact_free(0.0),
        t1,
        &mut obs,
    )
    .unwrap();
    let err = (y - exact_free(t1)).amax();
    assert!(err < 1e-8, "{err}");
    assert_eq!(stats.n_steps as usize, obs.t.len() - 1);
    assert_eq!(stats.n_rhs, 2 + 6 * (stats.n_steps + stats.n_rejected));
    // Tighter tolerance -> more steps and smaller error.
    let tol2 = Tolerances {
        rtol: 1e-6,
        atol: 1e-8,
        ..Default::default()
    };
    let (s2, y2) = solve(
        &mut sys,
        &Method::Dopri5(tol2),
        0.0,
        exact_free(0.0),
        t1,
        &mut StepCounter::default(),
    )
    .unwrap();
    assert!(s2.n_steps < stats.n_steps);
    assert!((y2 - exact_free(t1)).amax() > err);
}

#[test]
fn dense_output_is_fourth_order_accurate() {
    let mut sys = Oscillator {
        forcing_on_segment: 0.0,
        jump_at: None,
    };
    let times: Vec<f64> = (0..=1000).map(|i| i as f64 * 0.0137).collect();
    let mut max_err = Vec::new();
    for rtol in [1e-6, 1e-8] {
        let tol = Tolerances {
            rtol,
            atol: rtol * 1e-2,
            ..Default::default()
        };
        let mut recorder = Recorder::new(times.clone());
        solve(
            &mut sys,
            &Method::Dopri5(tol),
            0.0,
            exact_free(0.0),
            times[1000],
            &mut recorder,
        )
        .unwrap();
        assert_eq!(recorder.t.len(), times.len());
        let e = recorder
            .t
            .iter()
            .zip(&recorder.y)
            .map(|(t, y)| (y - exact_free(*t)).amax())
            .fold(0.0, f64::max);
        max_err.push(e);
    }
    // Interpolation error must follow the tolerance, not stay at a fixed interpolation floor.
    assert!(max_err[0] < 5e-5, "{max_err:?}");
    assert!(max_err[1] < max_err[0] / 20.0, "{max_err:?}");
}

#[test]
fn rk4_converges_at_fourth_order() {
    let mut sys = Oscillator {
        forcing_on_segment: 0.0,
        jump_at: None,
    };
    let err = |dt: f64, sys: &mut Oscillator| {
        let (_, y) = solve(
            sys,
            &Method::Rk4 { dt },
            0.0,
            exact_free(0.0),
            10.0,
            &mut StepCounter::default(),
        )
        .unwrap();
        (y - exact_free(10.0)).amax()
    };
    let e1 = err(0.1, &mut sys);
    let e2 = err(0.05, &mut sys);
    let ratio = e1 / e2;
    assert!(ratio > 14.0 && ratio < 18.0, "ratio {ratio}");
}

#[test]
fn steps_stop_exactly_at_breakpoints() {
    // After the jump at t = 1 the oscillator is centred at 1: y = 1 + A cos(t − 1) + B sin(t − 1).
    for method in [
        Method::Dopri5(Tolerances {
            rtol: 1e-10,
            atol: 1e-12,
            ..Default::default()
        }),
        Method::Rk4 { dt: 0.003 },
    ] {
        let mut sys = Oscillator {
            forcing_on_segment: 0.0,
            jump_at: Some(1.0),
        };
        let mut obs = EveryStep::default();
        let (_, y) = solve(&mut sys, &method, 0.0, exact_free(0.0), 5.0, &mut obs).unwrap();
        assert!(
            obs.t.contains(&1.0),
            "{method:?} did not stop at the breakpoint"
        );
        let y1 = exact_free(1.0);
        let (a, b) = (y1[0] - 1.0, y1[1]);
        let tt: f64 = 4.0;
        let exact = Vector2::new(
            1.0 + a * tt.cos() + b * tt.sin(),
            -a * tt.sin() + b * tt.cos(),
        );
        assert!(
            (y - exact).amax() < 1e-8,
            "{method:?}: {}",
            (y - exact).amax()
        );
    }
}

#[test]
fn bad_settings_are_refused_with_their_name() {
    let mut sys = Oscillator {
        forcing_on_segment: 0.0,
        jump_at: None,
    };
    let y0 = exact_free(0.0);
    let cases: Vec<(Method, f64, f64, &str)> = vec![
        (Method::Rk4 { dt: 0.0 }, 0.0, 1.0, "dt"),
        (Method::Rk4 { dt: f64::NAN }, 0.0, 1.0, "dt"),
        (
            Method::Dopri5(Tolerances {
                rtol: -1.0,
                ..Default::default()
            }),
            0.0,
            1.0,
            "rtol",
        ),
        (
            Method::Dopri5(Tolerances {
                atol: 0.0,
                ..Default::default()
            }),
            0.0,
            1.0,
            "atol",
        ),
        (Method::Rk4 { dt: 0.1 }, 1.0, 0.0, "t_span"),
        (Method::Rk4 { dt: 0.1 }, 0.0, f64::INFINITY, "t_span[1]"),
    ];
    for (m, t0, t1, name) in cases {
        let e = solve(&mut sys, &m, t0, y0, t1, &mut StepCounter::default()).unwrap_err();
        assert!(e.to_string().starts_with(name), "{e}");
    }
    let e = solve(
        &mut sys,
        &Method::Rk4 { dt: 0.1 },
        0.0,
        Vector2::new(f64::NAN, 0.0),
        1.0,
        &mut StepCounter::default(),
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("y0"));
}

#[test]
fn step_guard_stops_runaway_integrations() {
    let mut sys = Oscillator {
        forcing_on_segment: 0.0,
        jump_at: None,
    };
    let tol = Tolerances {
        max_steps: 10,
        ..Default::default()
    };
    let e = solve(
        &mut sys,
        &Method::Dopri5(tol),
        0.0,
        exact_free(0.0),
        100.0,
        &mut StepCounter::default(),
    )
    .unwrap_err();
    assert!(matches!(e, crate::error::Error::Integration { .. }), "{e}");
}

/// y' = y², blowing up at t = 1: the integrator must report an error, not return inf or NaN.
struct BlowUp;
impl OdeSystem<U1> for BlowUp {
    fn rhs(&self, _t: f64, y: &nalgebra::Vector1<f64>) -> nalgebra::Vector1<f64> {
        nalgebra::Vector1::new(y[0] * y[0])
    }
}

#[test]
fn blow_up_is_an_error() {
    let y0 = nalgebra::Vector1::new(1.0);
    let r = solve(
        &mut BlowUp,
        &Method::Dopri5(Tolerances::default()),
        0.0,
        y0,
        2.0,
        &mut StepCounter::default(),
    );
    assert!(r.is_err());
    let r = solve(
        &mut BlowUp,
        &Method::Rk4 { dt: 0.01 },
        0.0,
        y0,
        2.0,
        &mut StepCounter::default(),
    );
    assert!(r.is_err());
}

/// The oscillator with its size chosen at run time.
struct DynOscillator(Oscillator);

impl OdeSystem<Dyn> for DynOscillator {
    fn rhs(&self, t: f64, y: &State<Dyn>) -> State<Dyn> {
        let f = self.0.rhs(t, &Vector2::new(y[0], y[1]));
        State::<Dyn>::from_column_slice(f.as_slice())
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.0.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.0.enter_segment(a, b);
    }
}

#[test]
fn a_run_time_size_gives_the_same_bits_as_a_fixed_one() {
    let times: Vec<f64> = (0..=40).map(|i| i as f64 * 0.07).collect();
    let methods = [
        Method::Dopri5(Tolerances::default()),
        Method::Rk4 { dt: 0.01 },
    ];
    for method in methods {
        let jump = || Oscillator {
            forcing_on_segment: 0.0,
            jump_at: Some(1.0),
        };
        let mut fixed = Recorder::new(times.clone());
        let (s1, y1) = solve(&mut jump(), &method, 0.0, exact_free(0.0), 2.8, &mut fixed).unwrap();
        let mut dynamic = Recorder::new(times.clone());
        let y0 = State::<Dyn>::from_column_slice(exact_free(0.0).as_slice());
        let mut sys = DynOscillator(jump());
        let (s2, y2) = solve(&mut sys, &method, 0.0, y0, 2.8, &mut dynamic).unwrap();
        assert_eq!(s1, s2);
        assert_eq!(y1.as_slice(), y2.as_slice());
        assert_eq!(fixed.t, dynamic.t);
        for (a, b) in fixed.y.iter().zip(&dynamic.y) {
            assert_eq!(a.as_slice(), b.as_slice());
        }
    }
}

#[test]
fn least_steps_is_the_fixed_count_or_the_span_over_the_cap() {
    assert_eq!(Method::Rk4 { dt: 0.3 }.least_steps(3.0), 10.0);
    assert_eq!(Method::Rk4 { dt: 0.4 }.least_steps(3.0), 8.0);
    let capped = Tolerances {
        max_step: 0.2,
        ..Tolerances::default()
    };
    assert_eq!(Method::Dopri5(capped).least_steps(100.0), 500.0);
    // Error control alone has no lower bound known up front.
    assert_eq!(Method::Dopri5(Tolerances::default()).least_steps(1e6), 0.0);
    assert_eq!(Method::Dopri5(capped).max_steps(), 500_000_000);
    assert_eq!(Method::Rk4 { dt: 1.0 }.max_steps(), MAX_FIXED_STEPS as u64);
}

/// One Dormand–Prince step of y'' = −y from the exact state at t0, as the integrator builds it.
fn oscillator_step(t0: f64, h: f64) -> DenseStep<U2> {
    let sys = Oscillator {
        forcing_on_segment: 0.0,
        jump_at: None,
    };
    let y0 = exact_free(t0);
    let k1 = sys.rhs(t0, &y0);
    let s = dopri5::step(&sys, t0, t0 + h, &y0, &k1);
    let [k1, _, k3, k4, k5, k6, k7] = s.k;
    DenseStep::dopri5(t0, t0 + h, y0, s.y_new, [k1, k3, k4, k5, k6, k7])
}

#[test]
fn the_interpolants_slope_is_the_derivative_at_fourth_order() {
    // Against the exact derivative (−sin t, −cos t): at the middle the error falls as h⁴ and
    // is h⁴ |y⁽⁵⁾|/1920 to leading order; inside the step it falls at least as h⁴ too.
    let t0 = 0.3;
    let exact_slope = |t: f64| Vector2::new(-t.sin(), -t.cos());
    let mut mid = Vec::new();
    let mut inside = Vec::new();
    for h in [0.2, 0.1, 0.05] {
        let step = oscillator_step(t0, h);
        let t_mid = step.midpoint().0;
        mid.push((step.slope(t_mid) - exact_slope(t_mid)).amax() / h.powi(4));
        let worst = (1..8)
            .map(|j| {
                let t = t0 + h * j as f64 / 8.0;
                (step.slope(t) - exact_slope(t)).amax()
            })
            .fold(0.0, f64::max);
        inside.push(worst);
        // The ends: the slopes the step was built from.
        assert!((step.slope(t0) - exact_slope(t0)).amax() < 1e-15);
    }
    for w in mid.windows(2) {
        // err/h⁴ settles on a constant no larger than the leading term's bound.
        assert!((w[1] / w[0] - 1.0).abs() < 0.1, "{mid:?}");
    }
    assert!(mid[2] < 1.05 / 1920.0, "{mid:?}");
    for w in inside.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(order > 3.8, "observed order {order}: {inside:?}");
    }
}

/// θ of the paper's panel over one GEO orbit at 13 times, on `kernel`, at (rtol, atol).
fn paper_theta(kernel: ScalarKernel, rtol: f64, atol: f64) -> (Vec<f64>, Stats) {
    use crate::models::coupled::{Coupled, Coupling};
    use crate::models::hinge::HingeModel;
    let (p, o) = (
        crate::inputs::panel::Panel::paper(),
        crate::inputs::orbit::Orbit::geo_equinox(),
    );
    let eq = crate::analysis::steady::equilibrium(&p, Coupling::ProjectedArea, 1.0).unwrap();
    let y0 = nalgebra::Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0);
    let times = (0..=12).map(|k| o.period * k as f64 / 12.0).collect();
    let mut sys = Coupled::new(p, o, HingeModel::Nonlinear, Coupling::ProjectedArea);
    let mut samples = Recorder::new(times);
    let method = Method::Dopri5(Tolerances {
        rtol,
        atol,
        ..Tolerances::default()
    });
    let (stats, _) = solve_on(
        kernel,
        &mut sys,
        &method,
        Span {
            t0: 0.0,
            y0,
            t1: o.period,
        },
        &mut samples,
    )
    .unwrap();
    (samples.y.iter().map(|y| y[2]).collect(), stats)
}

#[test]
fn the_fused_kernel_is_as_accurate_as_the_portable_one() {
    // Against a tight solution: at the default tolerances both kernels' errors in θ are those
    // of the integration (~1e-7 rad after the eclipse), the fused one's no larger than 1.25
    // times the portable one's; at rtol 1e-12 the two agree to 1e-10 rad. (Their steps part
    // at the default tolerances: a rejection here or there, and the near-undamped hinge keeps
    // the difference, so the two are not the same bits.)
    if !ScalarKernel::Fma.runs_here() {
        eprintln!("no FMA here: nothing to compare");
        return;
    }
    let (truth, _) = paper_theta(ScalarKernel::Portable, 1e-12, 1e-14);
    let worst = |theta: &[f64]| {
        theta
            .iter()
            .zip(&truth)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    let (portable, ps) = paper_theta(ScalarKernel::Portable, 1e-8, 1e-10);
    let (fused, fs) = paper_theta(ScalarKernel::Fma, 1e-8, 1e-10);
    let (tight, _) = paper_theta(ScalarKernel::Fma, 1e-12, 1e-14);
    let (e_portable, e_fused) = (worst(&portable), worst(&fused));
    assert!(e_portable > 1e-8 && e_portable < 5e-6, "{e_portable:e}");
    assert!(
        e_fused <= 1.25 * e_portable,
        "{e_fused:e} against {e_portable:e}"
    );
    assert!(worst(&tight) < 1e-10, "{:e}", worst(&tight));
    assert_ne!(portable, fused, "the fused kernel gave the portable bits");
    assert_eq!(ps.n_steps, fs.n_steps);
}
