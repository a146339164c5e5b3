//! Bindings of the Monte Carlo batches (`crate::runs::ensemble`): a rayon pool of its own
//! (`_core.MonteCarloPool`, named as the engine's module and `montecarlo.py`; `_core.EnsemblePool`
//! is the same class under the name the Python side used before), and the check of a design up
//! front.

use super::cancel::{cancellable, CancelToken};
use super::convert::{laminate_from, orbit_from, solver_dict, solver_from, OrbitsRun};
use super::error::invalid;
use super::error::shield;
use crate::runs::ensemble::{
    pool, run_batch_layered, run_batch_on, EnsembleSettings, Layers, Path, SampleMetrics,
};
use crate::runs::orbits::{resolve_hinge, STEPS_PER_HINGE_PERIOD};
use crate::Panel;
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::ThreadPool;

/// Rows of a (n, len(PANEL_FIELDS)) array, columns in PANEL_FIELDS order, as panels (unchecked).
fn panels_from(rows: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<Panel>> {
    let a = rows.as_array();
    if a.ncols() != Panel::FIELDS.len() {
        return Err(invalid(
            "panels",
            format!("{} columns", a.ncols()),
            &format!("must have {} columns (PANEL_FIELDS)", Panel::FIELDS.len()),
        ));
    }
    a.rows()
        .into_iter()
        .map(|row| {
            let mut p = Panel::paper();
            for (name, &v) in Panel::FIELDS.iter().zip(row.iter()) {
                p.set(name, v)?;
            }
            Ok(p)
        })
        .collect()
}

/// The fewest integrator steps a run of `span` s of each row of `panels` takes, with the step
/// capped at T_n / `steps_per_period` as long runs do (0: no cap; None: the ensembles' cap):
/// known before any work, so that a request beyond its step budget is refused up front.
#[pyfunction]
#[pyo3(signature = (panels, solver, span, steps_per_period=None))]
fn least_steps<'py>(
    py: Python<'py>,
    panels: PyReadonlyArray2<'py, f64>,
    solver: &Bound<'py, PyDict>,
    span: f64,
    steps_per_period: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    shield(|| {
        let method = solver_from(solver)?;
        let cap = steps_per_period.unwrap_or(STEPS_PER_HINGE_PERIOD);
        let least = panels_from(&panels)?
            .iter()
            .map(|p| resolve_hinge(&method, p, cap).least_steps(span))
            .collect();
        Ok(PyArray1::from_vec(py, least))
    })
}

/// Every row that the panel validation refuses, as (row, parameter, message).
#[pyfunction]
fn check_panels(panels: PyReadonlyArray2<'_, f64>) -> PyResult<Vec<(usize, String, String)>> {
    shield(|| {
        Ok(panels_from(&panels)?
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                p.validate().err().map(|e| {
                    let name = match &e {
                        crate::Error::InvalidParameter { name, .. } => name.clone(),
                        _ => String::new(),
                    };
                    (i, name, e.to_string())
                })
            })
            .collect())
    })
}

/// A rayon thread pool of its own; batches run on it with the GIL released. Several Python
/// threads may run batches on one pool at once: they share its threads.
#[pyclass(frozen, module = "thermojitter._core")]
struct MonteCarloPool {
    pool: ThreadPool,
}

#[pymethods]
impl MonteCarloPool {
    #[new]
    #[pyo3(signature = (threads=None))]
    fn new(threads: Option<usize>) -> PyResult<Self> {
        if threads == Some(0) {
            return Err(invalid(
                "threads",
                0,
                "must be >= 1 (or None for one per core)",
            ));
        }
        Ok(MonteCarloPool {
            pool: pool(threads.unwrap_or(0))?,
        })
    }

    #[getter]
    fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// Runs one sample per row of `panels` over the `orbits` run; returns the metrics as
    /// columns. `lockstep`: several samples per thread in SIMD lanes (the same rows, bit for
    /// bit, as one at a time). The `orbits` run's `grid`: the N-node through-thickness model with
    /// that many nodes, on its `layup` (a laminate mapping) or, without one, on each sample's
    /// panel as one homogeneous layer.
    #[pyo3(signature = (panels, orbit, orbits, *, threshold, stop_at_threshold, validity_limit=crate::models::hinge::VALIDITY_LIMIT, cancel=None, lockstep=true))]
    #[allow(clippy::too_many_arguments)]
    fn run<'py>(
        &self,
        py: Python<'py>,
        panels: PyReadonlyArray2<'py, f64>,
        orbit: &Bound<'py, PyDict>,
        orbits: OrbitsRun<'py>,
        threshold: Option<f64>,
        stop_at_threshold: bool,
        validity_limit: f64,
        cancel: Option<&Bound<'py, CancelToken>>,
        lockstep: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let path = if lockstep {
            Path::Lockstep
        } else {
            Path::Scalar
        };
        cancellable(cancel, |cancel| {
            let ps = panels_from(&panels)?;
            let orbit = orbit_from(orbit)?;
            let (model, coupling, method) = orbits.hinge()?;
            let settings = EnsembleSettings {
                orbit,
                model,
                coupling,
                method,
                n_orbits: orbits.n_orbits,
                window: orbits.window,
                threshold,
                stop_at_threshold,
                validity_limit,
                hybrid: orbits.hybrid()?,
            };
            let pool = &self.pool;
            // The N-node model on the grid's layup (None: each sample's panel as one layer).
            let layers = match &orbits.grid {
                Some(grid) => Some(Layers {
                    layup: grid.layup.as_ref().map(laminate_from).transpose()?,
                    nodes: grid.nodes,
                }),
                None => None,
            };
            let out = py.detach(|| match &layers {
                Some(l) => run_batch_layered(pool, &ps, &settings, l, cancel),
                None => run_batch_on(pool, &ps, &settings, cancel, path),
            })?;
            let d = PyDict::new(py);
            let col = |f: fn(&SampleMetrics) -> f64| -> Vec<f64> { out.iter().map(f).collect() };
            for (name, values) in [
                ("theta_eq", col(|m| m.theta_eq)),
                ("growth_rate", col(|m| m.growth_rate)),
                ("frequency_hz", col(|m| m.frequency_hz)),
                ("critical_damping", col(|m| m.critical_damping)),
                ("theta_abs_max", col(|m| m.theta_abs_max)),
                ("amplitude", col(|m| m.amplitude)),
                ("entry_peak", col(|m| m.entry_peak)),
                ("exit_peak", col(|m| m.exit_peak)),
                ("jitter_rms", col(|m| m.jitter_rms)),
                ("jitter_peak", col(|m| m.jitter_peak)),
                ("t_threshold", col(|m| m.t_threshold)),
                ("orbit_threshold", col(|m| m.orbit_threshold)),
                ("orbit_limit", col(|m| m.orbit_limit)),
                ("amplitude_slope", col(|m| m.amplitude_slope)),
                ("t_nonlinear", col(|m| m.t_nonlinear)),
                ("t_reached", col(|m| m.t_reached)),
            ] {
                d.set_item(name, PyArray1::from_vec(py, values))?;
            }
            let stable: Vec<bool> = out.iter().map(|m| m.stable()).collect();
            d.set_item("stable", PyArray1::from_vec(py, stable))?;
            let steps: Vec<u64> = out.iter().map(|m| m.n_steps).collect();
            d.set_item("n_steps", PyArray1::from_vec(py, steps))?;
            let errors: Vec<Option<String>> = out.into_iter().map(|m| m.error).collect();
            d.set_item("error", errors)?;
            // The solver settings the samples ran with (each sample's step capped at its
            // hinge period as the long runs cap it).
            d.set_item("solver", solver_dict(py, &settings.method)?)?;
            Ok(d)
        })
    }
}

/// The processor, the instruction sets it has and the build uses, and the scalar and ensemble
/// kernels chosen on it, for benchmark reports.
#[pyfunction]
fn cpu_info(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("model", crate::numerics::cpu::model_name())?;
    d.set_item("has", crate::numerics::cpu::detected())?;
    d.set_item("build", crate::numerics::cpu::compiled())?;
    d.set_item(
        "scalar_kernel",
        crate::numerics::cpu::ScalarKernel::detect().name(),
    )?;
    d.set_item(
        "ensemble_kernel",
        crate::numerics::cpu::Kernel::detect().name(),
    )?;
    d.set_item("summary", crate::numerics::cpu::describe())?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<MonteCarloPool>()?;
    // The name before MonteCarloPool, kept for the scripts that use it: the same class.
    m.add("EnsemblePool", m.getattr("MonteCarloPool")?)?;
    m.add_function(wrap_pyfunction!(cpu_info, m)?)?;
    m.add_function(wrap_pyfunction!(check_panels, m)?)?;
    m.add_function(wrap_pyfunction!(least_steps, m)?)?;
    Ok(())
}
