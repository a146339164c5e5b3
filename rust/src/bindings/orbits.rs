//! Bindings of the long runs (`crate::runs::orbits`, and the hybrid propagator).

use super::cancel::{cancellable, CancelToken};
use super::convert::{
    crossing_tuple, orbit_from, panel_from, set_counters, set_named, solver_dict, OrbitsRun,
};
use crate::runs::layered::LayeredRunRequest;
use crate::runs::orbits::{OrbitRunRequest, OrbitRunSpec, SummaryOptions};
use crate::runs::request::{OrbitsModel, OrbitsRequest};
use crate::runs::simulate::state_from;
use nalgebra::U4;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Integrates whole orbits and returns one summary per orbit (columns as arrays): the two-layer
/// model, or the N-node model (`grid`), or with `hybrid` (its settings) the hybrid propagator,
/// whose fallback is the solver's full integration; a hybrid run adds how the simulated time was
/// split between linear arcs, the exponential integrator and the fallback.
#[pyfunction]
#[pyo3(signature = (panel, orbit, orbits, *, t_start, first_index, y0, theta_limit, stop_at_limit, steps_per_period, cancel=None))]
#[allow(clippy::too_many_arguments)]
fn run_orbits<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    orbits: OrbitsRun<'py>,
    t_start: f64,
    first_index: u64,
    y0: Vec<f64>,
    theta_limit: f64,
    stop_at_limit: bool,
    steps_per_period: f64,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let p = panel_from(panel)?;
        let o = orbit_from(orbit)?;
        let (hinge, coupling, m) = orbits.hinge()?;
        crate::models::hinge::check_hinge_angle("theta_limit", theta_limit)?;
        let spec = OrbitRunSpec {
            panel: p,
            orbit: o,
            model: hinge,
            coupling,
            method: m,
            t_start,
            first_index,
            n_orbits: orbits.n_orbits,
            options: SummaryOptions {
                window: orbits.window,
                theta_limit,
                stop_at_limit,
                steps_per_period,
            },
        };
        let hybrid = orbits.hybrid()?;
        let model = match &orbits.grid {
            // The N-node model: y0 and y_end are (node temperatures, θ, θ̇).
            Some(grid) => OrbitsModel::Laminate(LayeredRunRequest {
                spec,
                conduction: grid.conduction(&p)?,
                y0,
            }),
            None => OrbitsModel::TwoLayer(OrbitRunRequest {
                spec,
                y0: state_from(&y0, U4)?,
            }),
        };
        let req = OrbitsRequest { model, hybrid };
        let out = py.detach(|| crate::runs::request::run_orbits(&req, cancel))?;
        let d = summary_dict(py, &out.summaries, &m)?;
        match out.split {
            Some(split) => hybrid_counters(d, &split),
            None => Ok(d),
        }
    })
}

/// A hybrid run's summary columns with how it split the simulated time.
pub(super) fn hybrid_counters<'py>(
    d: Bound<'py, PyDict>,
    out: &crate::runs::hybrid::HybridRun,
) -> PyResult<Bound<'py, PyDict>> {
    set_named!(d, out; fields t_linear, t_exponential, t_fallback, n_arcs, n_exp_steps,
        n_fallback_steps, n_reread_steps, t_slow, n_slow_steps, n_refused_orbits,
        n_refused_separation, n_refused_ringing, n_refused_split, n_refused_limit, n_refused_gate,
        n_refused_growth, n_refused_windows, n_pieces, n_warmup_orbits, n_pieces_rerun);
    Ok(d)
}

/// The summaries of a run (of either model: a two-layer `OrbitRun` converts) as columns, with
/// its counters and the solver settings it ran with (`method`, as [`solver_dict`] reports them
/// for every run).
pub(super) fn summary_dict<'py>(
    py: Python<'py>,
    out: &crate::runs::layered::LayeredSummaries,
    method: &crate::numerics::integrate::Method,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col = |f: fn(&crate::runs::orbits::OrbitSummary) -> f64| -> Vec<f64> {
        out.summaries.iter().map(f).collect()
    };
    d.set_item(
        "index",
        out.summaries.iter().map(|s| s.index).collect::<Vec<u64>>(),
    )?;
    for (name, values) in [
        ("t_start", col(|s| s.t_start)),
        ("t_end", col(|s| s.t_end)),
        ("theta_eq", col(|s| s.theta_eq)),
        ("theta_max", col(|s| s.theta_max)),
        ("theta_min", col(|s| s.theta_min)),
        ("amplitude", col(|s| s.amplitude)),
        ("jitter_rms", col(|s| s.jitter_rms)),
        ("jitter_peak", col(|s| s.jitter_peak)),
        ("t_entry", col(|s| s.t_entry)),
        ("t_exit", col(|s| s.t_exit)),
        ("entry_theta_min", col(|s| s.entry_theta_min)),
        ("exit_theta_max", col(|s| s.exit_theta_max)),
        ("entry_peak", col(|s| s.entry_peak)),
        ("exit_peak", col(|s| s.exit_peak)),
    ] {
        d.set_item(name, PyArray1::from_vec(py, values))?;
    }
    set_counters(&d, &out.stats)?;
    d.set_item("t_reached", out.stats.t_end)?;
    d.set_item("stopped", out.stats.stopped)?;
    d.set_item("y_end", out.y_end.clone())?;
    d.set_item("crossing", crossing_tuple(out.crossing))?;
    d.set_item("solver", solver_dict(py, method)?)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run_orbits, m)?)?;
    Ok(())
}
