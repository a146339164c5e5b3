//! Engine micro-benchmarks with std-only timing (no harness): the coupled right-hand side, one
//! Dormand–Prince step, one GEO orbit at rtol 1e-8 / atol 1e-10, and Monte Carlo samples of one
//! orbit on one thread, one at a time and in lockstep lanes.
//!
//!     cargo bench --bench engine
//!
//! Each figure is the median over several batches, in ns per call (per step for the orbit).
//! A word after `--` keeps only the benches whose name contains it: rhs, step, orbit-none,
//! orbit-end, orbit-every (`-- orbit` runs the three orbits), ensemble. The first line names the
//! processor and the instruction sets it has and the build uses.

use nalgebra::Vector4;
use std::hint::black_box;
use std::time::Instant;
use thermojitter::analysis::steady::equilibrium;
use thermojitter::cancel::Cancel;
use thermojitter::models::coupled::{Coupled, Coupling};
use thermojitter::models::hinge::HingeModel;
use thermojitter::numerics::cpu::ScalarKernel;
use thermojitter::numerics::integrate::dopri5;
use thermojitter::numerics::integrate::{
    solve, solve_on, FusedRhs, Method, OdeSystem, Recorder, Span, StepCounter, Tolerances,
};
use thermojitter::runs::ensemble::{pool, run_batch_on, EnsembleSettings, Path};
use thermojitter::runs::lockstep::RUNS_PER_CORE;
use thermojitter::{Orbit, Panel};

/// Median over `batches` of the time per call of `f`, run `per_batch` times a batch, ns.
fn median_ns(batches: usize, per_batch: u64, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..batches)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..per_batch {
                f();
            }
            start.elapsed().as_nanos() as f64 / per_batch as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[batches / 2]
}

/// CPU time of this process so far, ns: the sum over its threads of the time on a CPU as the
/// Linux scheduler counts it (/proc/self/task/*/schedstat); None elsewhere. Less sensitive than
/// wall time to other work sharing the machine.
fn process_cpu_ns() -> Option<u64> {
    let mut total = 0;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let stat = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        total += stat.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(total)
}

/// `n` calls of the right-hand side as `kernel`'s integration loop has it: the portable one, or
/// the fused one compiled for AVX and FMA.
fn rhs_calls(kernel: ScalarKernel, sys: &Coupled, y: &Vector4<f64>, n: u64) {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,fma")]
    unsafe fn fused(sys: &Coupled, y: &Vector4<f64>, n: u64) {
        for _ in 0..n {
            black_box(sys.rhs_fused(black_box(100.0), black_box(y)));
        }
    }
    match kernel {
        // SAFETY: `ScalarKernel::available` lists the fused kernel only where it runs.
        #[cfg(target_arch = "x86_64")]
        ScalarKernel::Fma => unsafe { fused(sys, y, n) },
        _ => {
            for _ in 0..n {
                black_box(sys.rhs(black_box(100.0), black_box(y)));
            }
        }
    }
}

/// One Dormand–Prince step as `kernel`'s loop takes it.
fn step_on(kernel: ScalarKernel, sys: &Coupled, y: &Vector4<f64>, k1: &Vector4<f64>) {
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,fma")]
    unsafe fn fused(sys: &Coupled, y: &Vector4<f64>, k1: &Vector4<f64>) {
        let sys = FusedRhs(sys);
        black_box(dopri5::step(
            &sys,
            black_box(100.0),
            black_box(100.37),
            y,
            k1,
        ));
    }
    match kernel {
        // SAFETY: as in `rhs_calls`.
        #[cfg(target_arch = "x86_64")]
        ScalarKernel::Fma => unsafe { fused(sys, black_box(y), black_box(k1)) },
        _ => {
            black_box(dopri5::step(
                sys,
                black_box(100.0),
                black_box(100.37),
                black_box(y),
                black_box(k1),
            ));
        }
    }
}

fn main() {
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let wanted = |name: &str| filter.is_empty() || filter.iter().any(|f| name.contains(f.as_str()));
    println!("{}", thermojitter::numerics::cpu::describe());
    let panel = Panel::paper();
    let orbit = Orbit::geo_equinox();
    let eq = equilibrium(&panel, Coupling::ProjectedArea, 1.0).expect("equilibrium");
    let y0 = Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0);
    let mut sys = Coupled::new(panel, orbit, HingeModel::Nonlinear, Coupling::ProjectedArea);
    let (a, b) = (0.0, orbit.breakpoints(0.0, orbit.period)[0]);
    sys.enter_segment(a, b);

    // A state slightly off equilibrium so that the hinge terms are all non-trivial.
    let y = y0 + Vector4::new(0.5, -0.3, 1e-3, 2e-4);
    if wanted("rhs") {
        for kernel in ScalarKernel::available() {
            let rhs = median_ns(21, 1, || rhs_calls(kernel, &sys, &y, 1_000_000)) * 1e-6;
            let label = format!("rhs (coupled, nonlinear), {}", kernel.name());
            println!("{label:<36}{rhs:8.1} ns/call");
        }
    }

    if wanted("step") {
        for kernel in ScalarKernel::available() {
            let (k1, label) = (
                sys.rhs(100.0, &y),
                format!("dopri5 step (6 rhs), {}", kernel.name()),
            );
            let step = median_ns(21, 200_000, || step_on(kernel, &sys, &y, &k1));
            println!("{label:<36}{step:8.1} ns/step");
        }
    }

    let method = Method::Dopri5(Tolerances::default());
    let orbit_run = |key: &str, name: &str, observe: &mut dyn FnMut() -> u64| {
        if !wanted(key) {
            return;
        }
        let mut steps = 0;
        let ns = median_ns(7, 1, || steps = observe());
        println!(
            "one GEO orbit, {name:<21} {:8.3} ms, {steps} steps, {:.1} ns/step",
            ns * 1e-6,
            ns / steps as f64
        );
    };
    for kernel in ScalarKernel::available() {
        let name = format!("no output, {}", kernel.name());
        orbit_run("orbit-none", &name, &mut || {
            let mut counter = StepCounter::default();
            let (stats, y_end) = solve_on(
                kernel,
                &mut sys,
                &method,
                Span {
                    t0: 0.0,
                    y0: black_box(y0),
                    t1: orbit.period,
                },
                &mut counter,
            )
            .expect("orbit");
            black_box(y_end);
            stats.n_steps
        });
    }
    orbit_run("orbit-end", "sampled at the end", &mut || {
        let mut recorder = Recorder::new(vec![orbit.period]);
        let (stats, _) = solve(
            &mut sys,
            &method,
            0.0,
            black_box(y0),
            orbit.period,
            &mut recorder,
        )
        .expect("orbit");
        black_box(&recorder.y);
        stats.n_steps
    });
    orbit_run("orbit-every", "sampled every 0.5 s", &mut || {
        let mut recorder = Recorder::every(0.0, orbit.period, 0.5);
        let (stats, _) = solve(
            &mut sys,
            &method,
            0.0,
            black_box(y0),
            orbit.period,
            &mut recorder,
        )
        .expect("orbit");
        black_box(&recorder.y);
        stats.n_steps
    });

    let paths = [
        ("ensemble-scalar", "one at a time ", Path::Scalar),
        ("ensemble-lockstep", "lockstep lanes", Path::Lockstep),
    ];
    if paths.iter().any(|(key, _, _)| wanted(key)) {
        // As many panels around Table 1 as one thread runs in lockstep at once, each one GEO
        // orbit with the per-orbit summary and the flutter analysis (a Monte Carlo sample),
        // alternating the two paths.
        let panels: Vec<Panel> = (0..RUNS_PER_CORE)
            .map(|k| Panel {
                damping: 2.0 + 0.25 * k as f64,
                conductance: 22.0 + 0.75 * k as f64,
                ..panel
            })
            .collect();
        let settings = EnsembleSettings {
            orbit,
            model: HingeModel::Nonlinear,
            coupling: Coupling::ProjectedArea,
            method,
            n_orbits: 1,
            window: 600.0,
            threshold: None,
            stop_at_threshold: false,
            validity_limit: 0.35,
            hybrid: None,
        };
        let one = pool(1).expect("pool");
        // CPU time where the OS reports it (the machine may be shared), else wall time.
        let clock = if process_cpu_ns().is_some() {
            "CPU"
        } else {
            "wall"
        };
        let mut per_sample = [Vec::new(), Vec::new()];
        for _ in 0..3 {
            for (i, (key, _, path)) in paths.iter().enumerate() {
                if !wanted(key) {
                    continue;
                }
                let (start, cpu) = (Instant::now(), process_cpu_ns());
                let rows = run_batch_on(&one, &panels, &settings, &Cancel::new(), *path);
                black_box(rows.expect("batch"));
                let seconds = match (cpu, process_cpu_ns()) {
                    (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
                    _ => start.elapsed().as_secs_f64(),
                };
                per_sample[i].push(seconds / panels.len() as f64);
            }
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied()
        };
        let scalar = median(&mut per_sample[0]);
        let lanes = median(&mut per_sample[1]);
        if let Some(s) = scalar {
            println!(
                "ensemble sample, {}    {:8.2} ms/sample ({clock} time)",
                paths[0].1,
                1e3 * s
            );
        }
        if let Some(l) = lanes {
            let ratio = scalar.map_or(String::new(), |s| format!(" ({:.2}x)", s / l));
            println!(
                "ensemble sample, {}    {:8.2} ms/sample ({clock} time){ratio}",
                paths[1].1,
                1e3 * l
            );
        }
    }
}
