//! Bindings of the flutter analysis.

use super::convert::{hinge_model, panel_from};
use super::to_py;
use crate::flutter::{analyse, check_flux, critical_damping};
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
    let p = panel_from(panel)?;
    let m = hinge_model(model)?;
    check_flux(flux).map_err(to_py)?;
    let c = coupling(coupled);
    let a = analyse(&p, m, c, flux).map_err(to_py)?;
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
        d.set_item(
            "critical_damping",
            critical_damping(&p, m, c, flux).map_err(to_py)?,
        )?;
    }
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(flutter, m)?)?;
    Ok(())
}
