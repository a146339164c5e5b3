//! Bindings of the Monte Carlo batches (`crate::runs::ensemble`): a rayon pool of its own
//! (`_core.MonteCarloPool`, named as the engine's module and `montecarlo.py`; `_core.EnsemblePool`
//! is the same class under the name the Python side used before), and the check of a design up
//! front.

use super::cancel::{cancellable, CancelToken};
use super::convert::{laminate_from, orbit_from, solver_dict, solver_from, OrbitsRun};
use super::error::invalid;
use super::error::shield;
use crate::inputs::boom::Boom;
use crate::runs::ensemble::{
    orbit_with, pool, run_batch_layered, run_boom_batch, run_samples, EnsembleSettings, Layers,
    Path, Sample, SampleMetrics, ORBIT_INPUTS, ORBIT_INPUT_RANGES,
};
use crate::runs::orbits::{resolve_hinge, STEPS_PER_HINGE_PERIOD};
use crate::{Orbit, Panel};
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::ThreadPool;

/// Rows of a (n, len(fields)) array, columns in `fields` order, each set on a copy of `base`
/// with `set` (unchecked); `what` names the array and its columns in an error.
fn rows_from<T: Copy>(
    rows: &PyReadonlyArray2<'_, f64>,
    base: T,
    fields: &[&str],
    set: fn(&mut T, &str, f64) -> crate::Result<()>,
    what: (&str, &str),
) -> PyResult<Vec<T>> {
    let a = rows.as_array();
    if a.ncols() != fields.len() {
        return Err(invalid(
            what.0,
            format!("{} columns", a.ncols()),
            &format!("must have {} columns ({})", fields.len(), what.1),
        ));
    }
    a.rows()
        .into_iter()
        .map(|row| {
            let mut x = base;
            for (name, &v) in fields.iter().zip(row.iter()) {
                set(&mut x, name, v)?;
            }
            Ok(x)
        })
        .collect()
}

/// Rows of a (n, len(PANEL_FIELDS)) array, columns in PANEL_FIELDS order, as panels (unchecked).
fn panels_from(rows: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<Panel>> {
    rows_from(
        rows,
        Panel::paper(),
        &Panel::FIELDS,
        Panel::set,
        ("panels", "PANEL_FIELDS"),
    )
}

/// Rows of a (n, len(BOOM_FIELDS)) array, columns in BOOM_FIELDS order, as booms (unchecked).
fn booms_from(rows: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<Boom>> {
    rows_from(
        rows,
        Boom::example(),
        &Boom::FIELDS,
        Boom::set,
        ("booms", "BOOM_FIELDS"),
    )
}

/// The rows of a design as panels, or as the booms' equivalent hinges (whose period caps a
/// boom's step as a panel's does).
fn hinges_from(rows: &PyReadonlyArray2<'_, f64>, boom: bool) -> PyResult<Vec<Panel>> {
    if boom {
        Ok(booms_from(rows)?.iter().map(Boom::hinge_panel).collect())
    } else {
        panels_from(rows)
    }
}

/// Each sample's orbit: `base` with the sample's orbit inputs (a mapping of ORBIT_INPUTS names
/// to arrays of `n` values; None: `base` for all), unchecked.
fn orbits_from(base: Orbit, inputs: Option<&Bound<'_, PyDict>>, n: usize) -> PyResult<Vec<Orbit>> {
    let mut orbits = vec![base; n];
    let Some(inputs) = inputs else {
        return Ok(orbits);
    };
    for (key, values) in inputs.iter() {
        let name: String = key.extract()?;
        if !ORBIT_INPUTS.contains(&name.as_str()) {
            return Err(invalid(
                "orbit_inputs",
                format!("{name:?}"),
                &format!("must name orbit inputs: {}", ORBIT_INPUTS.join(", ")),
            ));
        }
        let values: PyReadonlyArray1<'_, f64> = values.extract()?;
        let values = values.as_array();
        if values.len() != n {
            return Err(invalid(
                "orbit_inputs",
                format!("{} values of {name}", values.len()),
                &format!("must hold one value a sample ({n})"),
            ));
        }
        for (o, &v) in orbits.iter_mut().zip(values.iter()) {
            *o = orbit_with(*o, &name, v)?;
        }
    }
    Ok(orbits)
}

/// The (row, parameter, message) of an error of row `i`.
fn refusal(i: usize, e: crate::Error) -> (usize, String, String) {
    let name = match &e {
        crate::Error::InvalidParameter { name, .. } => name.clone(),
        _ => String::new(),
    };
    (i, name, e.to_string())
}

/// The fewest integrator steps a run of `span` s of each row of `panels` takes, with the step
/// capped at T_n / `steps_per_period` as long runs do (0: no cap; None: the ensembles' cap):
/// known before any work, so that a request beyond its step budget is refused up front.
/// With `boom`, the rows are booms (BOOM_FIELDS), each capped by its equivalent hinge.
#[pyfunction]
#[pyo3(signature = (panels, solver, span, steps_per_period=None, *, boom=false))]
fn least_steps<'py>(
    py: Python<'py>,
    panels: PyReadonlyArray2<'py, f64>,
    solver: &Bound<'py, PyDict>,
    span: f64,
    steps_per_period: Option<f64>,
    boom: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    shield(|| {
        let method = solver_from(solver)?;
        let cap = steps_per_period.unwrap_or(STEPS_PER_HINGE_PERIOD);
        let least = hinges_from(&panels, boom)?
            .iter()
            .map(|p| resolve_hinge(&method, p, cap).least_steps(span))
            .collect();
        Ok(PyArray1::from_vec(py, least))
    })
}

/// Every row that the panel validation (with `boom`, the boom's: rows of BOOM_FIELDS) refuses,
/// as (row, parameter, message).
#[pyfunction]
#[pyo3(signature = (panels, *, boom=false))]
fn check_panels(
    panels: PyReadonlyArray2<'_, f64>,
    boom: bool,
) -> PyResult<Vec<(usize, String, String)>> {
    shield(|| {
        let checks: Vec<crate::Result<()>> = if boom {
            booms_from(&panels)?.iter().map(Boom::validate).collect()
        } else {
            panels_from(&panels)?.iter().map(Panel::validate).collect()
        };
        Ok(checks
            .into_iter()
            .enumerate()
            .filter_map(|(i, r)| r.err().map(|e| refusal(i, e)))
            .collect())
    })
}

/// Every sample whose orbit (`orbit` with the sample's `orbit_inputs`, as `MonteCarloPool.run`
/// builds it) the orbit validation refuses, as (row, parameter, message).
#[pyfunction]
fn check_orbits(
    orbit: &Bound<'_, PyDict>,
    orbit_inputs: &Bound<'_, PyDict>,
    n: usize,
) -> PyResult<Vec<(usize, String, String)>> {
    shield(|| {
        let base = orbit_from(orbit)?;
        Ok(orbits_from(base, Some(orbit_inputs), n)?
            .iter()
            .enumerate()
            .filter_map(|(i, o)| o.validate().err().map(|e| refusal(i, e)))
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
    /// panel as one homogeneous layer. `orbit_inputs`: each sample's orbit inputs (a mapping of
    /// ORBIT_INPUTS names to one value a sample) set on `orbit`. `boom`: the rows are booms
    /// (BOOM_FIELDS), one at a time per thread.
    #[pyo3(signature = (panels, orbit, orbits, *, threshold, stop_at_threshold, validity_limit=crate::models::hinge::VALIDITY_LIMIT, cancel=None, lockstep=true, orbit_inputs=None, boom=false))]
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
        orbit_inputs: Option<&Bound<'py, PyDict>>,
        boom: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let path = if lockstep {
            Path::Lockstep
        } else {
            Path::Scalar
        };
        cancellable(cancel, |cancel| {
            let orbit = orbit_from(orbit)?;
            let n = panels.as_array().nrows();
            let sample_orbits = orbits_from(orbit, orbit_inputs, n)?;
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
            if boom && layers.is_some() {
                return Err(invalid("grid", "given", "a boom has its own thermal model"));
            }
            let out = if boom {
                let booms: Vec<(Boom, Orbit)> = booms_from(&panels)?
                    .into_iter()
                    .zip(sample_orbits)
                    .collect();
                py.detach(|| run_boom_batch(pool, &booms, &settings, cancel))?
            } else {
                let samples: Vec<Sample> = panels_from(&panels)?
                    .into_iter()
                    .zip(sample_orbits)
                    .map(|(panel, orbit)| Sample { panel, orbit })
                    .collect();
                py.detach(|| match &layers {
                    Some(l) => run_batch_layered(pool, &samples, &settings, l, cancel),
                    None => run_samples(pool, &samples, &settings, cancel, path),
                })?
            };
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
    m.add_function(wrap_pyfunction!(check_orbits, m)?)?;
    m.add("ORBIT_INPUTS", ORBIT_INPUTS.to_vec())?;
    let ranges = PyDict::new(m.py());
    for (name, range) in ORBIT_INPUTS.iter().zip(ORBIT_INPUT_RANGES) {
        ranges.set_item(name, range)?;
    }
    m.add("ORBIT_INPUT_RANGES", ranges)?;
    m.add_function(wrap_pyfunction!(least_steps, m)?)?;
    Ok(())
}
