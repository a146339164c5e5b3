//! Bindings of the laminate layups and the N-node through-thickness model.

use super::cancel::{cancellable, CancelToken};
use super::convert::{
    coupling, dict_of, laminate_from, layer_from, panel_dict, panel_from, set_named, FlutterPoint,
    Grid, OrbitPoint, RunOptions,
};
use super::error::shield;
use super::flutter::set_spectrum;
use crate::analysis::flutter::check_flux;
use crate::analysis::layered::{LayeredEquilibrium, LayeredPoint};
use crate::inputs::heating::Loads;
use crate::inputs::laminate::{LAYER_FIELDS, MATERIALS};
use crate::inputs::panel::Panel;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use crate::runs::request::ThermalChoice;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Checks one layer mapping (errors name the layer and field).
#[pyfunction]
fn validate_layer(layer: &Bound<'_, PyAny>) -> PyResult<()> {
    shield(|| Ok(layer_from(layer, 0)?.validate()?))
}

/// Checks a laminate mapping.
#[pyfunction]
fn validate_laminate(laminate: &Bound<'_, PyDict>) -> PyResult<()> {
    shield(|| laminate_from(laminate).map(|_| ()))
}

/// Lamination-theory properties of a laminate; with a `panel`, also the `equivalent_panel`: the
/// panel fields equivalent to the laminate, the others taken from `panel`.
#[pyfunction]
#[pyo3(signature = (laminate, panel=None))]
fn laminate_properties<'py>(
    py: Python<'py>,
    laminate: &Bound<'py, PyDict>,
    panel: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let lam = laminate_from(laminate)?;
        let d = PyDict::new(py);
        set_named!(d, lam; thickness, mass_per_area, heat_capacity, thermal_resistance,
            neutral_axis, bending_stiffness, extensional_stiffness);
        if let Some(panel) = panel {
            let base = panel_from(panel)?;
            d.set_item(
                "equivalent_panel",
                panel_dict(py, &lam.equivalent_panel(&base)?)?,
            )?;
        }
        Ok(d)
    })
}

/// The material library: a list of mappings (key, name, properties, source).
#[pyfunction]
fn materials<'py>(py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
    MATERIALS
        .iter()
        .map(|m| {
            let d = dict_of(py, [("key", m.key), ("name", m.name)])?;
            for (name, value) in m.properties() {
                d.set_item(name, value)?;
            }
            d.set_item("source", m.source)?;
            Ok(d)
        })
        .collect()
}

/// The node grid of the N-node model: depth (m), capacity (J/(m² K)), moment weight (N m/K)
/// and the moment offset (N m).
#[pyfunction]
fn conduction_grid<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    grid: Grid<'py>,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let p = panel_from(panel)?;
        let c = grid.conduction(&p)?;
        let d = PyDict::new(py);
        d.set_item("depth", c.depth.clone())?;
        d.set_item("capacity", c.capacity.clone())?;
        d.set_item("moment_weight", c.moment_weight.clone())?;
        d.set_item("moment_offset", c.moment_offset)?;
        d.set_item("element_layer", c.element_layer.clone())?;
        Ok(d)
    })
}

/// An N-node equilibrium as a mapping: node temperatures, θ and M_T.
fn equilibrium_dict<'py>(py: Python<'py>, eq: &LayeredEquilibrium) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("temperatures", eq.temperatures.clone())?;
    d.set_item("theta", eq.theta)?;
    d.set_item("thermal_moment", eq.moment)?;
    Ok(d)
}

/// Sunlit equilibrium of the N-node system: node temperatures, θ and M_T.
#[pyfunction]
#[pyo3(signature = (panel, grid, coupled=true, flux=1.0))]
fn layered_steady_state<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    grid: Grid<'py>,
    coupled: bool,
    flux: f64,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let p = panel_from(panel)?;
        check_flux(flux)?;
        let c = grid.conduction(&p)?;
        let eq = crate::analysis::layered::equilibrium(&p, &c, coupling(coupled), flux)?;
        let d = equilibrium_dict(py, &eq)?;
        d.set_item("depth", c.depth)?;
        Ok(d)
    })
}

/// Flutter analysis of the N-node system at the flutter `point` (full nodal Jacobian), with the
/// critical damping.
#[pyfunction]
fn layered_flutter<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    grid: Grid<'py>,
    point: FlutterPoint,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let (p, m, k) = point.inputs(panel)?;
        layered_analysis(py, &p, &grid, (m, k), Loads::sun(point.flux))
    })
}

/// [`layered_flutter`] at the sunlit equilibrium under every load of `orbit` at the `point`'s
/// time t, or (`average`) under their mean over the sunlit arc of the orbit beginning at t (as
/// `flutter_at` for the two-layer model).
#[pyfunction]
fn layered_flutter_at<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    grid: Grid<'py>,
    orbit: &Bound<'py, PyDict>,
    point: OrbitPoint,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let (p, _, hinge, loads) = point.inputs(panel, orbit)?;
        let d = layered_analysis(py, &p, &grid, hinge, loads)?;
        d.set_item("loads", (loads.sun, loads.front, loads.back))?;
        Ok(d)
    })
}

/// The flutter analysis of the N-node system of `panel` on `grid` with the hinge model and
/// coupling `hinge` under constant `loads`, as a mapping: equilibrium, spectrum, critical
/// damping.
fn layered_analysis<'py>(
    py: Python<'py>,
    panel: &Panel,
    grid: &Grid<'py>,
    hinge: (HingeModel, Coupling),
    loads: Loads,
) -> PyResult<Bound<'py, PyDict>> {
    let conduction = grid.conduction(panel)?;
    let point = LayeredPoint {
        panel,
        conduction: &conduction,
        model: hinge.0,
        coupling: hinge.1,
        loads,
    };
    let a = py.detach(|| point.analyse())?;
    let d = equilibrium_dict(py, &a.equilibrium)?;
    let size = a.jacobian.nrows();
    let rows = (0..size).map(|i| (0..size).map(|j| a.jacobian[(i, j)]).collect());
    set_spectrum(&d, rows, &a.eigenvalues, a.growth_rate, a.frequency_hz)?;
    let cd = py.detach(|| point.critical_damping())?;
    d.set_item("critical_damping", cd)?;
    Ok(d)
}

/// Integrates the N-node laminate coupled to the hinge; node temperatures as a (time × node)
/// array. The validity limit and Ctrl-C as in `simulate`.
#[pyfunction]
#[pyo3(signature = (panel, grid, orbit, run, *, model, coupled, cancel=None))]
#[allow(clippy::too_many_arguments)]
fn simulate_layers<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    grid: Grid<'py>,
    orbit: &Bound<'py, PyDict>,
    run: RunOptions<'py>,
    model: &str,
    coupled: bool,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let mut nodes = None;
        let d = super::coupled_transient(py, panel, orbit, (model, coupled), run, cancel, |p| {
            let c = grid.conduction(p)?;
            nodes = Some((c.depth.clone(), c.node_labels()));
            Ok(ThermalChoice::Laminate(c))
        })?;
        if let Some((depth, labels)) = nodes {
            d.set_item("depth", PyArray1::from_vec(py, depth))?;
            d.set_item("node_labels", labels)?;
        }
        Ok(d)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("LAYER_FIELDS", LAYER_FIELDS.to_vec())?;
    m.add(
        "REFERENCE_TEMPERATURE",
        crate::inputs::laminate::REFERENCE_TEMPERATURE,
    )?;
    m.add_function(wrap_pyfunction!(validate_layer, m)?)?;
    m.add_function(wrap_pyfunction!(validate_laminate, m)?)?;
    m.add_function(wrap_pyfunction!(laminate_properties, m)?)?;
    m.add_function(wrap_pyfunction!(materials, m)?)?;
    m.add_function(wrap_pyfunction!(conduction_grid, m)?)?;
    m.add_function(wrap_pyfunction!(layered_steady_state, m)?)?;
    m.add_function(wrap_pyfunction!(layered_flutter, m)?)?;
    m.add_function(wrap_pyfunction!(layered_flutter_at, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_layers, m)?)?;
    Ok(())
}
