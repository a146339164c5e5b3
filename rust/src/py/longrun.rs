//! Bindings of summarised long runs.

use super::cancel::{token, CancelToken};
use super::convert::{hinge_model, orbit_from, panel_from, solver_from, state};
use super::error::shield;
use crate::summary::{run_orbits_cancellable as run, SummaryOptions};
use crate::system::Coupling;
use nalgebra::U4;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Integrates whole orbits and returns one summary per orbit (columns as arrays).
#[pyfunction]
#[pyo3(signature = (panel, orbit, *, model, coupled, solver, t_start, first_index, n_orbits, y0, window, theta_limit, stop_at_limit, steps_per_period, cancel=None))]
#[allow(clippy::too_many_arguments)]
fn run_orbits<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    model: &str,
    coupled: bool,
    solver: &Bound<'py, PyDict>,
    t_start: f64,
    first_index: u64,
    n_orbits: u64,
    y0: Vec<f64>,
    window: f64,
    theta_limit: f64,
    stop_at_limit: bool,
    steps_per_period: f64,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    let cancel = token(cancel);
    shield(|| {
        let p = panel_from(panel)?;
        let o = orbit_from(orbit)?;
        let hinge = hinge_model(model)?;
        let coupling = if coupled {
            Coupling::ProjectedArea
        } else {
            Coupling::Frozen
        };
        let m = solver_from(solver)?;
        let y = state(&y0, U4)?;
        let options = SummaryOptions {
            window,
            theta_limit,
            stop_at_limit,
            steps_per_period,
        };
        let out = py.detach(|| {
            run(
                &p,
                &o,
                hinge,
                coupling,
                &m,
                t_start,
                first_index,
                n_orbits,
                y,
                options,
                &cancel,
            )
        })?;
        let d = PyDict::new(py);
        let col = |f: fn(&crate::summary::OrbitSummary) -> f64| -> Vec<f64> {
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
        d.set_item("n_steps", out.stats.n_steps)?;
        d.set_item("n_rejected", out.stats.n_rejected)?;
        d.set_item("n_rhs", out.stats.n_rhs)?;
        d.set_item("t_reached", out.stats.t_end)?;
        d.set_item("stopped", out.stats.stopped)?;
        d.set_item("y_end", out.y_end.as_slice().to_vec())?;
        d.set_item("crossing", out.crossing.map(|c| (c.t, c.orbit, c.theta)))?;
        Ok(d)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run_orbits, m)?)?;
    Ok(())
}
