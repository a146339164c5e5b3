//! Bindings of the flutter analysis.

use super::cancel::{cancellable, CancelToken};
use super::convert::{
    coupling, dict_of, hinge_model, panel_from, set_named, FlutterPoint, OrbitPoint,
};
use super::error::shield;
use crate::analysis::flutter::{
    analyse, analyse_system_under, critical_damping, critical_damping_under,
};
use crate::analysis::linear::LinearThermal;
use crate::analysis::stability::Axis;
use crate::models::coupled::Coupled;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Eigen-analysis at the sunlit equilibrium of the flutter `point`, with the critical damping.
#[pyfunction]
fn flutter<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    point: FlutterPoint,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let (p, m, c) = point.inputs(panel)?;
        let a = analyse(&p, m, c, point.flux)?;
        let d = PyDict::new(py);
        let eq = a.equilibrium;
        d.set_item("equilibrium", (eq.t_front, eq.t_back, eq.theta))?;
        let jacobian = a.jacobian;
        let rows = (0..4).map(|i| (0..4).map(|j| jacobian[(i, j)]).collect());
        set_spectrum(&d, rows, &a.eigenvalues, a.growth_rate, a.frequency_hz)?;
        d.set_item("critical_damping", critical_damping(&p, m, c, point.flux)?)?;
        Ok(d)
    })
}

/// Linear stability of the paper's model at the sunlit equilibrium under every load of `orbit`
/// at the `point`'s time t (its Earth heating and attitude there), or with `average` under
/// those loads averaged over the sunlit arc of the orbit that begins at t: the same mapping as
/// [`flutter`], with the loads.
#[pyfunction]
#[pyo3(signature = (panel, orbit, point, with_critical=true))]
fn flutter_at<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    point: OrbitPoint,
    with_critical: bool,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let (p, o, (m, c), loads) = point.inputs(panel, orbit)?;
        let system = Coupled::new(p, o, m, c);
        let (eq, jacobian, spectrum) = analyse_system_under(&system, loads)?;
        let d = PyDict::new(py);
        d.set_item("equilibrium", (eq[0], eq[1], eq[2]))?;
        let rows = (0..4).map(|i| (0..4).map(|j| jacobian[(i, j)]).collect());
        set_spectrum(
            &d,
            rows,
            &spectrum.eigenvalues,
            spectrum.growth_rate,
            spectrum.frequency_hz,
        )?;
        if with_critical {
            d.set_item(
                "critical_damping",
                critical_damping_under(&p, &o, loads, m, c)?,
            )?;
        }
        d.set_item("loads", (loads.sun, loads.front, loads.back))?;
        Ok(d)
    })
}

/// The linear stability of an equilibrium into `d`: its Jacobian (`rows`), eigenvalues (as
/// (re, im) pairs), growth rate and frequency.
pub(super) fn set_spectrum(
    d: &Bound<'_, PyDict>,
    rows: impl Iterator<Item = Vec<f64>>,
    eigenvalues: &[nalgebra::Complex<f64>],
    growth_rate: f64,
    frequency_hz: f64,
) -> PyResult<()> {
    let rows: Vec<Vec<f64>> = rows.collect();
    d.set_item("jacobian", PyArray2::from_vec2(d.py(), &rows)?)?;
    let ev: Vec<(f64, f64)> = eigenvalues.iter().map(|z| (z.re, z.im)).collect();
    d.set_item("eigenvalues", ev)?;
    d.set_item("growth_rate", growth_rate)?;
    d.set_item("frequency_hz", frequency_hz)
}

/// Growth rate and frequency over a grid of two panel parameters (rows: y, columns: x); stops
/// with KeyboardInterrupt within a grid point of `cancel`.
#[pyfunction]
#[pyo3(signature = (panel, x_name, x_values, y_name, y_values, model, coupled, flux, *, cancel=None))]
#[allow(clippy::too_many_arguments)]
fn stability_map<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    x_name: String,
    x_values: Vec<f64>,
    y_name: String,
    y_values: Vec<f64>,
    model: &str,
    coupled: bool,
    flux: f64,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let p = panel_from(panel)?;
        let m = hinge_model(model)?;
        let c = coupling(coupled);
        let x = Axis {
            name: x_name,
            values: x_values,
        };
        let y = Axis {
            name: y_name,
            values: y_values,
        };
        let map = py
            .detach(|| crate::analysis::stability::stability_map(&p, m, c, flux, &x, &y, cancel))?;
        let grid = |v: &[f64]| -> Vec<Vec<f64>> { v.chunks(map.nx).map(|r| r.to_vec()).collect() };
        let d = PyDict::new(py);
        d.set_item(
            "growth_rate",
            PyArray2::from_vec2(py, &grid(&map.growth_rate))?,
        )?;
        d.set_item(
            "frequency_hz",
            PyArray2::from_vec2(py, &grid(&map.frequency_hz))?,
        )?;
        Ok(d)
    })
}

/// The closed-form linear analysis of paper Sec. 4.2: its coefficients and what follows.
#[pyfunction]
#[pyo3(signature = (panel, flux=1.0, omega=None, t_star=None))]
fn linear_thermal<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    flux: f64,
    omega: Option<f64>,
    t_star: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let lt = LinearThermal::new(&panel_from(panel)?, flux, omega, t_star)?;
        let d = dict_of(py, LinearThermal::FIELDS.into_iter().zip(lt.values()))?;
        set_named!(d, lt; amplitude, phase_lag, time_constant, resonant, thermal_damping,
            critical_damping_estimate, growth_rate_estimate);
        Ok(d)
    })
}

/// ΔT(t) of the Sec. 4.2 analysis given by its fields (as [`linear_thermal`] returns them).
#[pyfunction]
#[pyo3(signature = (fields, t, phi, delta_t0))]
fn linear_delta_t<'py>(
    py: Python<'py>,
    fields: &Bound<'py, PyDict>,
    t: PyReadonlyArray1<'py, f64>,
    phi: f64,
    delta_t0: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    shield(|| {
        let mut v = [0.0; 10];
        for (slot, name) in v.iter_mut().zip(LinearThermal::FIELDS) {
            *slot = fields
                .get_item(name)?
                .ok_or_else(|| crate::Error::invalid("fields", name, "is missing"))?
                .extract()?;
        }
        let lt = LinearThermal::from_values(v);
        let out: Vec<f64> = t
            .as_array()
            .iter()
            .map(|&x| lt.delta_t(x, phi, delta_t0))
            .collect();
        Ok(PyArray1::from_vec(py, out))
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("LINEAR_FIELDS", LinearThermal::FIELDS.to_vec())?;
    m.add_function(wrap_pyfunction!(flutter, m)?)?;
    m.add_function(wrap_pyfunction!(flutter_at, m)?)?;
    m.add_function(wrap_pyfunction!(linear_thermal, m)?)?;
    m.add_function(wrap_pyfunction!(linear_delta_t, m)?)?;
    m.add_function(wrap_pyfunction!(stability_map, m)?)?;
    Ok(())
}
