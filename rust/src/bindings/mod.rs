//! The pyo3 layer: converts Python values to engine types, maps engine errors to exceptions and
//! releases the GIL around every integration. It holds no physics.

mod beam;
mod boom;
mod cancel;
mod convert;
mod distributed;
mod ensemble;
mod error;
mod flutter;
mod laminate;
mod orbit;
mod orbits;
mod spacecraft;

use crate::analysis::steady::equilibrium;
use crate::inputs::heating::Optics;
use crate::inputs::panel::{beam_first_angular_frequency, hinge_stiffness, StiffnessCriterion};
use crate::models::coupled::{Coupled, DrivenHinge, MomentHistory};
use crate::models::hinge::checked_hinge_energy;
use crate::models::hinge::{thermal_moment, Hinge};
use crate::numerics::integrate::{Method, Stats};
use crate::runs::request::{coupled_run, CoupledRun, RunRequest, ThermalChoice, Transient};
use crate::runs::simulate::{run_watched, state_from};
use cancel::{cancellable, CancelToken};
use convert::{
    coupling, crossing_tuple, hinge_model, orbit_from, panel_dict, panel_from, set_counters,
    set_named, solver_from, Grid, RunOptions,
};
use error::{invalid, shield, ConvergenceError, IntegrationError};
use nalgebra::U2;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::f64::consts::PI;

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

/// The counters, the end state and the settings common to every run.
fn run_info<'py>(
    py: Python<'py>,
    t: Vec<f64>,
    stats: &Stats,
    y_end: Vec<f64>,
    method: &Method,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(intern!(py, "t"), array(py, t))?;
    set_counters(&d, stats)?;
    d.set_item(intern!(py, "t_end"), stats.t_end)?;
    d.set_item(intern!(py, "y_end"), array(py, y_end))?;
    d.set_item(intern!(py, "solver"), convert::solver_dict(py, method)?)?;
    Ok(d)
}

/// Validates a solver mapping {method, rtol, atol, dt, max_step, max_steps} and returns it as the
/// engine reads it: `tj.SolverSettings` is checked here, by the same code that checks every run.
#[pyfunction]
fn check_solver<'py>(py: Python<'py>, solver: &Bound<'py, PyDict>) -> PyResult<Bound<'py, PyDict>> {
    let m = solver_from(solver)?;
    m.validate()?;
    convert::solver_dict(py, &m)
}

/// Validates a panel given as a mapping of its parameters.
#[pyfunction]
fn validate_panel(panel: &Bound<'_, PyDict>) -> PyResult<()> {
    shield(|| panel_from(panel).map(|_| ()))
}

/// Validates an orbit given as a mapping.
#[pyfunction]
fn validate_orbit(orbit: &Bound<'_, PyDict>) -> PyResult<()> {
    shield(|| orbit_from(orbit).map(|_| ()))
}

/// Sunlit equilibrium (T_f, T_b, θ) under flux factor `flux`.
#[pyfunction]
#[pyo3(signature = (panel, coupled=true, flux=1.0))]
fn steady_state(panel: &Bound<'_, PyDict>, coupled: bool, flux: f64) -> PyResult<(f64, f64, f64)> {
    shield(|| {
        let p = panel_from(panel)?;
        let coupling = coupling(coupled);
        let eq = equilibrium(&p, coupling, flux)?;
        Ok((eq.t_front, eq.t_back, eq.theta))
    })
}

/// The default start of a run beginning at `t0`: the sunlit equilibrium at that time's solar
/// flux, at rest, as the state (T_f, T_b, θ, θ̇), or with a `grid` the N-node model's state
/// (node temperatures…, θ, θ̇).
#[pyfunction]
#[pyo3(signature = (panel, orbit, t0, coupled, grid=None))]
fn start_state(
    panel: &Bound<'_, PyDict>,
    orbit: &Bound<'_, PyDict>,
    t0: f64,
    coupled: bool,
    grid: Option<Grid<'_>>,
) -> PyResult<Vec<f64>> {
    shield(|| {
        let p = panel_from(panel)?;
        let o = orbit_from(orbit)?;
        let coupling = coupling(coupled);
        if let Some(grid) = grid {
            let c = grid.conduction(&p)?;
            return Ok(crate::analysis::layered::start_state(
                &p, &c, coupling, &o, t0,
            )?);
        }
        let y0 = crate::runs::orbits::start_state(&p, &o, coupling, t0)?;
        Ok(y0.as_slice().to_vec())
    })
}

/// K_el by criterion ("deflection", "deflection_small_angle", "frequency").
#[pyfunction]
#[pyo3(signature = (panel, criterion, moment=0.0))]
fn stiffness(panel: &Bound<'_, PyDict>, criterion: &str, moment: f64) -> PyResult<f64> {
    shield(|| {
        let p = panel_from(panel)?;
        let c = match criterion {
            "deflection" => StiffnessCriterion::Deflection,
            "deflection_small_angle" => StiffnessCriterion::DeflectionSmallAngle,
            "frequency" => StiffnessCriterion::Frequency,
            other => {
                return Err(invalid(
                    "criterion",
                    format!("{other:?}"),
                    "must be 'deflection', 'deflection_small_angle' or 'frequency'",
                ))
            }
        };
        Ok(hinge_stiffness(&p, c, moment)?)
    })
}

/// Derived quantities of a panel: hinge inertia, frequencies, moment per kelvin.
#[pyfunction]
fn derived<'py>(py: Python<'py>, panel: &Bound<'py, PyDict>) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let p = panel_from(panel)?;
        let d = PyDict::new(py);
        set_named!(d, p; half_arm, hinge_inertia, moment_per_kelvin, flexural_stiffness,
            rigidity_per_length, matching_moment_scale);
        let natural = p.natural_angular_frequency() / (2.0 * PI);
        d.set_item("natural_frequency_hz", natural)?;
        let beam = beam_first_angular_frequency(&p) / (2.0 * PI);
        d.set_item("beam_frequency_hz", beam)?;
        Ok(d)
    })
}

/// Thermal moment M_T for temperature arrays.
#[pyfunction]
fn moment<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    t_front: PyReadonlyArray1<'py, f64>,
    t_back: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    shield(|| {
        let p = panel_from(panel)?;
        let m = t_front
            .as_array()
            .iter()
            .zip(t_back.as_array().iter())
            .map(|(&f, &b)| thermal_moment(&p, f, b))
            .collect();
        Ok(array(py, m))
    })
}

type Arrays2<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// Positions (x, y), m, of the point at `zeta` along one half of the hinge model at each angle.
#[pyfunction]
fn hinge_points<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    zeta: f64,
    theta: PyReadonlyArray1<'py, f64>,
) -> PyResult<Arrays2<'py>> {
    shield(|| {
        let p = panel_from(panel)?;
        let (x, y): (Vec<f64>, Vec<f64>) = theta
            .as_array()
            .iter()
            .map(|&th| crate::models::hinge::hinge_point(&p, zeta, th))
            .unzip();
        Ok((array(py, x), array(py, y)))
    })
}

/// Energy of the hinge in a constant moment field (conserved when c_d = 0).
#[pyfunction]
fn energy<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    model: &str,
    theta: PyReadonlyArray1<'py, f64>,
    theta_dot: PyReadonlyArray1<'py, f64>,
    moment: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    shield(|| {
        let p = panel_from(panel)?;
        let m = hinge_model(model)?;
        let e = theta
            .as_array()
            .iter()
            .zip(theta_dot.as_array().iter())
            .map(|(&a, &b)| checked_hinge_energy(&p, m, a, b, moment))
            .collect::<crate::Result<Vec<f64>>>()?;
        Ok(array(py, e))
    })
}

/// Integrates the coupled thermo-structural system: the thermal model with `layers`, the hinge;
/// watches |θ| against the `run`'s limit as its `on_limit` says ("flag", "stop", "ignore") and
/// stops with KeyboardInterrupt within a step of `cancel`.
#[pyfunction]
#[pyo3(signature = (panel, orbit, run, *, model, coupled, layers=2, cancel=None))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    run: RunOptions<'py>,
    model: &str,
    coupled: bool,
    layers: u32,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let hinge = (model, coupled);
        coupled_transient(py, panel, orbit, hinge, run, cancel, |_| {
            Ok(ThermalChoice::Layers(layers))
        })
    })
}

/// A coupled run (the two-layer or N-node thermal model, `thermal` of the checked panel, and the
/// hinge `model` with the `coupled` flag) converted and integrated with the GIL released: what
/// `simulate` and `simulate_layers` share.
pub(crate) fn coupled_transient<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    (model, coupled): (&str, bool),
    run: RunOptions<'py>,
    cancel: &crate::cancel::Cancel,
    thermal: impl FnOnce(&crate::Panel) -> PyResult<ThermalChoice>,
) -> PyResult<Bound<'py, PyDict>> {
    let (p, o, hinge) = (panel_from(panel)?, orbit_from(orbit)?, hinge_model(model)?);
    let settings = run.transient(true)?;
    let req = RunRequest {
        panel: p,
        orbit: o,
        thermal: thermal(&p)?,
        model: hinge,
        coupling: coupling(coupled),
        settings,
    };
    let run = py.detach(|| crate::runs::request::simulate(req, cancel))?;
    transient_dict(py, run)
}

/// A transient as a mapping: the counters, the end state and the settings used, every state
/// component by name (the N-node run: its node temperatures as a (time × node) array), θ's
/// limit crossing, the thermal moment and the illumination.
pub(crate) fn transient_dict(py: Python<'_>, run: Transient) -> PyResult<Bound<'_, PyDict>> {
    let (run, nodes) = match run {
        Transient::Coupled(run) => (run, None),
        Transient::Layered(run) => {
            let n_t = run.t.len();
            let temps = PyArray1::from_vec(py, run.temperatures).reshape([n_t, run.nodes])?;
            let run = CoupledRun {
                names: vec!["theta".into(), "theta_dot".into()],
                columns: vec![run.theta, run.theta_dot],
                sunlit: run.sunlit,
                fluxes: Some(run.fluxes),
                moment: run.moment,
                t: run.t,
                stats: run.stats,
                y_end: run.y_end,
                method: run.method,
                crossing: run.crossing,
                stopped: run.stopped,
            };
            (run, Some(temps))
        }
    };
    let d = run_info(py, run.t, &run.stats, run.y_end, &run.method)?;
    if let Some(temps) = nodes {
        d.set_item(intern!(py, "T_nodes"), temps)?;
    }
    d.set_item(intern!(py, "crossing"), crossing_tuple(run.crossing))?;
    d.set_item(intern!(py, "stopped"), run.stopped)?;
    for (name, column) in run.names.iter().zip(run.columns) {
        d.set_item(name, array(py, column))?;
    }
    d.set_item(intern!(py, "thermal_moment"), array(py, run.moment))?;
    d.set_item(intern!(py, "sunlit"), array(py, run.sunlit))?;
    if let Some((front, back)) = run.fluxes {
        d.set_item(intern!(py, "flux_front"), array(py, front))?;
        d.set_item(intern!(py, "flux_back"), array(py, back))?;
    }
    Ok(d)
}

/// Integrates a thermal model alone: one node (eq. 1) or two layers (eq. 2, θ = 0).
#[pyfunction]
#[pyo3(signature = (panel, orbit, run, *, layers, cancel=None))]
fn simulate_thermal<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    run: RunOptions<'py>,
    layers: u32,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let p = panel_from(panel)?;
        let o = orbit_from(orbit)?;
        let settings = run.transient(false)?;
        let thermal = crate::models::thermal_model(&p, layers)?;
        let sys = Coupled::thermal_only(thermal, o).with_optics(Optics::of(&p));
        let run = py.detach(|| coupled_run(sys, settings, cancel))?;
        transient_dict(py, Transient::Coupled(run))
    })
}

/// Integrates the hinge alone under a prescribed moment: a constant, or samples (t, M); the
/// `run`'s `y0` is (θ, θ̇).
#[pyfunction]
#[pyo3(signature = (panel, run, *, model, moment, moment_t, cancel=None))]
fn simulate_hinge<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    run: RunOptions<'py>,
    model: &str,
    moment: PyReadonlyArray1<'py, f64>,
    moment_t: Option<PyReadonlyArray1<'py, f64>>,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let p = panel_from(panel)?;
        let hinge = hinge_model(model)?;
        let (m, out) = run.integration()?;
        let values = moment.as_array().to_vec();
        let history = match moment_t {
            None if values.len() == 1 => MomentHistory::Constant(values[0]),
            None => {
                return Err(invalid(
                    "moment_t",
                    "None",
                    "is required when moment holds samples",
                ))
            }
            Some(ts) => MomentHistory::Samples {
                t: ts.as_array().to_vec(),
                moment: values,
            },
        };
        history.validate()?;
        history.check_against(&p)?;
        let span = run.span;
        let y_start = state_from(&run.y0.unwrap_or_default(), U2)?;
        let start_hinge = Hinge::new(&p, hinge);
        crate::models::hinge::check_start_state(y_start.as_slice(), 0, Some(&start_hinge))?;
        let traj = py.detach(|| {
            let mut sys = DrivenHinge {
                panel: p,
                model: hinge,
                moment: history,
            };
            run_watched(&mut sys, &m, span, y_start, &out, None, cancel)
        })?;
        let d = run_info(
            py,
            traj.t.clone(),
            &traj.stats,
            traj.y_end.as_slice().to_vec(),
            &traj.method,
        )?;
        d.set_item("theta", array(py, traj.column(0)))?;
        d.set_item("theta_dot", array(py, traj.column(1)))?;
        Ok(d)
    })
}

/// Loads NumPy's array API now, at import. rust-numpy loads it on the first array made, and
/// loading runs Python code, which raises a Ctrl-C pending since the engine call began: rust-numpy
/// then panics, and the call's result became an InternalError instead of KeyboardInterrupt.
fn load_numpy_api(py: Python<'_>) -> PyResult<()> {
    let loaded = std::panic::catch_unwind(|| {
        PyArray1::<f64>::zeros(py, 0, false);
    });
    let Err(payload) = loaded else {
        return Ok(());
    };
    let what = payload
        .downcast_ref::<String>()
        .cloned()
        .unwrap_or_default();
    if what.contains("KeyboardInterrupt") {
        // Ctrl-C during the import itself.
        return Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(""));
    }
    Err(pyo3::exceptions::PyImportError::new_err(format!(
        "thermojitter could not load NumPy's array API: {what}"
    )))
}

#[pymodule]
#[pyo3(name = "_core")]
fn core_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    load_numpy_api(m.py())?;
    m.add("IntegrationError", m.py().get_type::<IntegrationError>())?;
    m.add("ConvergenceError", m.py().get_type::<ConvergenceError>())?;
    m.add("PANEL_FIELDS", crate::Panel::FIELDS.to_vec())?;
    // The valid range of every panel field, name: (low, high, low end open), for the Python
    // layer (truncated distributions) to read rather than restate.
    let ranges = PyDict::new(m.py());
    for (name, low, high, open) in crate::Panel::RANGES {
        ranges.set_item(name, (low, high, open))?;
    }
    m.add("PANEL_RANGES", ranges)?;
    m.add("MAX_NODES", crate::models::conduction::MAX_NODES)?;
    m.add("MAX_SAMPLES", crate::runs::simulate::MAX_SAMPLES)?;
    m.add("PAPER_PANEL", panel_dict(m.py(), &crate::Panel::paper())?)?;
    m.add(
        "SOLVER_DEFAULTS",
        convert::solver_dict(
            m.py(),
            &crate::numerics::integrate::Method::Dopri5(Default::default()),
        )?,
    )?;
    m.add("CASE_A_PANEL", panel_dict(m.py(), &crate::Panel::case_a())?)?;
    m.add("STEFAN_BOLTZMANN", crate::STEFAN_BOLTZMANN)?;
    m.add("MAX_TIME", crate::numerics::integrate::MAX_TIME)?;
    m.add("ENSEMBLE_LANES", crate::runs::lockstep::LANES)?;
    m.add(
        "ENSEMBLE_RUNS_PER_CORE",
        crate::runs::lockstep::RUNS_PER_CORE,
    )?;
    m.add("KERNEL_VARIABLE", crate::numerics::cpu::KERNEL_VARIABLE)?;
    m.add(
        "KERNEL_CHOICES",
        crate::numerics::cpu::KERNEL_CHOICES.to_vec(),
    )?;
    m.add("MAX_THREADS", crate::runs::ensemble::MAX_THREADS)?;
    m.add("VALIDITY_LIMIT", crate::models::hinge::VALIDITY_LIMIT)?;
    m.add("SLOW_RING_LIMIT", crate::runs::hybrid::slow::RING_LIMIT)?;
    m.add("SLOW_ORBIT", crate::runs::hybrid::slow::SHORT_ORBIT)?;
    m.add(
        "SLOW_PIECE_ORBITS",
        crate::runs::hybrid::pieces::PIECE_ORBITS,
    )?;
    m.add_function(wrap_pyfunction!(check_solver, m)?)?;
    m.add_function(wrap_pyfunction!(validate_panel, m)?)?;
    m.add_function(wrap_pyfunction!(validate_orbit, m)?)?;
    m.add_function(wrap_pyfunction!(steady_state, m)?)?;
    m.add_function(wrap_pyfunction!(start_state, m)?)?;
    m.add_function(wrap_pyfunction!(stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(derived, m)?)?;
    m.add_function(wrap_pyfunction!(moment, m)?)?;
    m.add_function(wrap_pyfunction!(energy, m)?)?;
    m.add_function(wrap_pyfunction!(hinge_points, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_thermal, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_hinge, m)?)?;
    flutter::register(m)?;
    orbits::register(m)?;
    beam::register(m)?;
    boom::register(m)?;
    distributed::register(m)?;
    orbit::register(m)?;
    ensemble::register(m)?;
    cancel::register(m)?;
    laminate::register(m)?;
    spacecraft::register(m)?;
    Ok(())
}
