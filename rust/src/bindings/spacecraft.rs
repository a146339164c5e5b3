//! Bindings of the spacecraft run (`crate::runs::spacecraft`).

use super::cancel::{cancellable, CancelToken};
use super::convert::{orbit_from, panel_from, RunOptions};
use crate::error::Error;
use crate::models::spacecraft::{Appendage, Pd, Spacecraft, ARCSEC_PER_RADIAN, MAX_APPENDAGES};
use crate::runs::spacecraft::{
    simulate_spacecraft as simulate, AppendageColumns, SpacecraftRequest,
};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Where one sampled column of an appendage is.
type Column = fn(&AppendageColumns) -> &Vec<f64>;

/// A (time × appendage) array from per-appendage columns.
fn per_appendage<'py>(
    py: Python<'py>,
    n_t: usize,
    columns: impl Iterator<Item = &'py Vec<f64>> + Clone,
) -> Bound<'py, PyArray2<f64>> {
    let n = columns.clone().count();
    let mut flat = vec![0.0; n_t * n];
    for (j, col) in columns.enumerate() {
        for (k, v) in col.iter().enumerate() {
            flat[k * n + j] = *v;
        }
    }
    PyArray1::from_vec(py, flat)
        .reshape([n_t, n])
        .expect("n_t × n values")
}

/// Integrates a spacecraft: a bus of inertia `bus_inertia` (kg m², inf for one that does not
/// turn), one appendage per panel with its hinge's distance from the bus axis (`offsets`, m) and
/// sense (`senses`, ±1), an optional PD controller (bandwidth rad/s, damping ratio), a constant
/// `disturbance` torque (N m) on the bus.
#[pyfunction]
#[pyo3(signature = (bus_inertia, panels, offsets, senses, controller, orbit, run, *, disturbance=0.0, bus_rate=0.0, cancel=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_spacecraft<'py>(
    py: Python<'py>,
    bus_inertia: f64,
    panels: Vec<Bound<'py, PyDict>>,
    offsets: Vec<f64>,
    senses: Vec<f64>,
    controller: Option<(f64, f64)>,
    orbit: &Bound<'py, PyDict>,
    run: RunOptions<'py>,
    disturbance: f64,
    bus_rate: f64,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        if panels.len() != offsets.len() || panels.len() != senses.len() {
            return Err(Error::invalid(
                "appendages",
                format!("{}, {}, {}", panels.len(), offsets.len(), senses.len()),
                "needs one offset and one sense per panel",
            )
            .into());
        }
        if panels.len() > MAX_APPENDAGES {
            return Err(Error::invalid(
                "appendages",
                panels.len(),
                &format!("must hold at most {MAX_APPENDAGES} appendages"),
            )
            .into());
        }
        let mut appendages = Vec::with_capacity(panels.len());
        for ((p, offset), sense) in panels.iter().zip(offsets).zip(senses) {
            appendages.push(Appendage {
                panel: panel_from(p)?,
                offset,
                sense,
            });
        }
        let (method, output) = run.integration()?;
        let req = SpacecraftRequest {
            craft: Spacecraft {
                bus_inertia,
                appendages,
                controller: controller.map(|(bandwidth, damping)| Pd { bandwidth, damping }),
            },
            orbit: orbit_from(orbit)?,
            disturbance,
            method,
            span: run.span,
            y0: run.y0,
            bus_rate,
            output,
        };
        let r = py.detach(|| simulate(&req, cancel))?;
        let n_t = r.t.len();
        let d = super::run_info(py, r.t, &r.stats, r.y_end, &r.method)?;
        d.set_item("phi", PyArray1::from_vec(py, r.phi))?;
        d.set_item("phi_dot", PyArray1::from_vec(py, r.phi_dot))?;
        d.set_item("bus_torque", PyArray1::from_vec(py, r.bus_torque))?;
        d.set_item(
            "angular_momentum",
            r.angular_momentum.map(|h| PyArray1::from_vec(py, h)),
        )?;
        let a = &r.appendages;
        let columns: [(&str, Column); 6] = [
            ("T_front", |c| &c.t_front),
            ("T_back", |c| &c.t_back),
            ("theta", |c| &c.theta),
            ("theta_dot", |c| &c.theta_dot),
            ("thermal_moment", |c| &c.thermal_moment),
            ("reaction_torque", |c| &c.reaction_torque),
        ];
        for (name, column) in columns {
            d.set_item(name, per_appendage(py, n_t, a.iter().map(column)))?;
        }
        d.set_item("gains", r.gains)?;
        d.set_item("inertia_at_rest", r.inertia_at_rest)?;
        Ok(d)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("ARCSEC_PER_RADIAN", ARCSEC_PER_RADIAN)?;
    m.add_function(wrap_pyfunction!(simulate_spacecraft, m)?)?;
    Ok(())
}
