//! Bindings of the flutter analysis.

use super::convert::{hinge_model, panel_from};
use super::error::shield;
use crate::flutter::{analyse, check_flux, critical_damping};
use crate::stability::Axis;
use crate::system::Coupling;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn coupling(coupled: bool) -> Coupling {
    if coupled {
        Coupling::ProjectedArea
    } else {
        Coupling::Frozen
    }
}

/// Eigen-analysis at the sunlit equilibrium; with `with_critical`, also the critical damping.
#[pyfunction]
#[pyo3(signature = (panel, model, coupled, flux, with_critical=true))]
fn flutter<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    model: &str,
    coupled: bool,
    flux: f64,
    with_critical: bool,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let p = panel_from(panel)?;
        let m = hinge_model(model)?;
        check_flux(flux)?;
        let c = coupling(coupled);
        let a = analyse(&p, m, c, flux)?;
        let d = PyDict::new(py);
        let eq = a.equilibrium;
        d.set_item("equilibrium", (eq.t_front, eq.t_back, eq.theta))?;
        let rows: Vec<Vec<f64>> = (0..4)
            .map(|i| (0..4).map(|j| a.jacobian[(i, j)]).collect())
            .collect();
        d.set_item("jacobian", PyArray2::from_vec2(py, &rows)?)?;
        let ev: Vec<(f64, f64)> = a.eigenvalues.iter().map(|z| (z.re, z.im)).collect();
        d.set_item("eigenvalues", ev)?;
        d.set_item("growth_rate", a.growth_rate)?;
        d.set_item("frequency_hz", a.frequency_hz)?;
        if with_critical {
            d.set_item("critical_damping", critical_damping(&p, m, c, flux)?)?;
        }
        Ok(d)
    })
}

/// Growth rate and frequency over a grid of two panel parameters (rows: y, columns: x).
#[pyfunction]
#[pyo3(signature = (panel, x_name, x_values, y_name, y_values, model, coupled, flux))]
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
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
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
        let map = py.detach(|| crate::stability::stability_map(&p, m, c, flux, &x, &y))?;
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

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(flutter, m)?)?;
    m.add_function(wrap_pyfunction!(stability_map, m)?)?;
    Ok(())
}
