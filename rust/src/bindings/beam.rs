//! Bindings of the finite-element beam comparator: modes, static deflection, modal transient.

use super::cancel::{cancellable, CancelToken};
use super::convert::{panel_from, set_counters, solver_dict, RunOptions};
use super::error::invalid;
use super::error::shield;
use crate::models::beam::{FreeFreeBeam, BEAM_MODES};
use crate::models::coupled::MomentHistory;
use crate::runs::beam::respond;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::f64::consts::PI;

fn beam_from(panel: &Bound<'_, PyDict>, n_elements: i64) -> PyResult<FreeFreeBeam> {
    let p = panel_from(panel)?;
    let n = usize::try_from(n_elements).map_err(|_| {
        invalid(
            "n_elements",
            n_elements,
            &format!(
                "must be even, between 2 and {}",
                crate::models::beam::MAX_ELEMENTS
            ),
        )
    })?;
    Ok(FreeFreeBeam::new(&p, n)?)
}

/// Modes of the free–free beam: the first `n_modes` elastic frequencies (Hz) and deflection
/// shapes at the nodes, the rigid-body eigenvalues, the total mass and the end-moment data.
#[pyfunction]
fn beam_modes<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    n_elements: i64,
    n_modes: i64,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let beam = beam_from(panel, n_elements)?;
        let (modes, moment_modes) =
            py.detach(|| Ok::<_, crate::Error>((beam.modes()?, beam.end_moment_modes()?)))?;
        let elastic = modes.elastic_count();
        let k = usize::try_from(n_modes)
            .ok()
            .filter(|&k| k >= 1 && k <= elastic)
            .ok_or_else(|| {
                invalid(
                    "n",
                    n_modes,
                    &format!("must be between 1 and {elastic} (elastic modes of the mesh)"),
                )
            })?;
        let freqs: Vec<f64> = modes.elastic_angular_frequencies()[..k]
            .iter()
            .map(|w| w / (2.0 * PI))
            .collect();
        let columns: Vec<Vec<f64>> = (0..k).map(|c| modes.elastic_deflection(c)).collect();
        let shapes: Vec<Vec<f64>> = (0..=beam.n_elements)
            .map(|j| columns.iter().map(|col| col[j]).collect())
            .collect();
        let d = PyDict::new(py);
        d.set_item("frequencies_hz", PyArray1::from_vec(py, freqs))?;
        d.set_item(
            "rigid_eigenvalues",
            PyArray1::from_vec(py, modes.rigid_eigenvalues().to_vec()),
        )?;
        d.set_item("x", PyArray1::from_vec(py, beam.node_positions()))?;
        d.set_item("shapes", PyArray2::from_vec2(py, &shapes)?)?;
        d.set_item("total_mass", beam.total_mass())?;
        d.set_item("flexibility", moment_modes.flexibility)?;
        d.set_item("residual_flexibility", moment_modes.residual_flexibility)?;
        d.set_item(
            "kept_frequencies_hz",
            PyArray1::from_vec(
                py,
                moment_modes
                    .kept
                    .iter()
                    .map(|(w, _, _)| w / (2.0 * PI))
                    .collect(),
            ),
        )?;
        d.set_item("max_kept_modes", BEAM_MODES)?;
        Ok(d)
    })
}

/// Static tip deflection relative to the centre (m) under end moments ±`moment` (N m).
#[pyfunction]
fn beam_static(
    py: Python<'_>,
    panel: &Bound<'_, PyDict>,
    n_elements: i64,
    moment: f64,
) -> PyResult<f64> {
    shield(|| {
        let beam = beam_from(panel, n_elements)?;
        Ok(py.detach(|| beam.static_tip_deflection(moment))?)
    })
}

/// Modal transient response to end moments ±M(t) given as samples (`moment_t`, `moment`);
/// stops with KeyboardInterrupt within a step of `cancel`.
#[pyfunction]
#[pyo3(signature = (panel, n_elements, moment_t, moment, run, *, damping_ratio, residual, cancel=None))]
#[allow(clippy::too_many_arguments)]
fn beam_response<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    n_elements: i64,
    moment_t: PyReadonlyArray1<'py, f64>,
    moment: PyReadonlyArray1<'py, f64>,
    run: RunOptions<'py>,
    damping_ratio: f64,
    residual: bool,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let beam = beam_from(panel, n_elements)?;
        let (m, out) = run.integration()?;
        let span = run.span;
        let history = MomentHistory::Samples {
            t: moment_t.as_array().to_vec(),
            moment: moment.as_array().to_vec(),
        };
        history.validate()?;
        let r = py.detach(|| {
            respond(
                &beam,
                history,
                damping_ratio,
                residual,
                &m,
                span,
                &out,
                cancel,
            )
        })?;
        let d = PyDict::new(py);
        d.set_item("t", PyArray1::from_vec(py, r.t))?;
        d.set_item("eta", PyArray1::from_vec(py, r.eta))?;
        d.set_item("theta_f", PyArray1::from_vec(py, r.theta_f))?;
        set_counters(&d, &r.stats)?;
        d.set_item("solver", solver_dict(py, &m)?)?;
        Ok(d)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("BEAM_MAX_ELEMENTS", crate::models::beam::MAX_ELEMENTS)?;
    m.add_function(wrap_pyfunction!(beam_modes, m)?)?;
    m.add_function(wrap_pyfunction!(beam_static, m)?)?;
    m.add_function(wrap_pyfunction!(beam_response, m)?)?;
    Ok(())
}
