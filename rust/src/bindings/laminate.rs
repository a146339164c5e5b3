//! Bindings of the laminate layups and the N-node through-thickness model.

use super::cancel::{cancellable, CancelToken};
use super::convert::{
    coupling, float_item, orbit_from, panel_dict, panel_from, type_error, Grid, RunOptions,
};
use super::error::{invalid, shield};
use super::flutter::{flutter_inputs, set_spectrum};
use crate::analysis::flutter::check_flux;
use crate::analysis::layered::LayeredEquilibrium;
use crate::inputs::laminate::{Laminate, Layer, LAYER_FIELDS, MATERIALS};
use crate::inputs::panel::Panel;
use crate::models::conduction::Conduction;
use crate::runs::request::ThermalChoice;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// A layer from a mapping of its fields and a name.
fn layer_from(d: &Bound<'_, PyAny>, index: usize) -> PyResult<Layer> {
    let d = d
        .cast::<PyDict>()
        .map_err(|_| type_error(&format!("layers[{index}]"), "a mapping", d))?;
    let name: String = match d.get_item("name")? {
        Some(v) => v
            .extract()
            .map_err(|_| type_error(&format!("layers[{index}].name"), "a string", &v))?,
        None => format!("layer {index}"),
    };
    // Errors name the layer and the field: "layer 'core': density".
    let value = |field: &str| -> PyResult<f64> {
        let label = format!("layer '{name}': {field}");
        let v = d
            .get_item(field)?
            .ok_or_else(|| invalid(&label, "missing", "is required"))?;
        if v.is_instance_of::<pyo3::types::PyBool>() {
            return Err(type_error(&label, "a number", &v));
        }
        v.extract::<f64>()
            .map_err(|_| type_error(&label, "a number", &v))
    };
    let [thickness, conductivity, density, specific_heat, youngs_modulus, expansion_coeff] =
        LAYER_FIELDS;
    Ok(Layer {
        thickness: value(thickness)?,
        conductivity: value(conductivity)?,
        density: value(density)?,
        specific_heat: value(specific_heat)?,
        youngs_modulus: value(youngs_modulus)?,
        expansion_coeff: value(expansion_coeff)?,
        name,
    })
}

/// A laminate from a mapping {layers: [mapping…], emissivity_front, emissivity_back,
/// absorptivity, reference_temperature}, validated.
pub fn laminate_from(d: &Bound<'_, PyDict>) -> PyResult<Laminate> {
    let items = d
        .get_item("layers")?
        .ok_or_else(|| invalid("layers", "missing", "is required"))?;
    let list = items
        .cast::<PyList>()
        .map_err(|_| type_error("layers", "a list of layers", &items))?;
    let layers = list
        .iter()
        .enumerate()
        .map(|(i, item)| layer_from(&item, i))
        .collect::<PyResult<Vec<_>>>()?;
    let lam = Laminate {
        layers,
        emissivity_front: float_item(d, "emissivity_front")?,
        emissivity_back: float_item(d, "emissivity_back")?,
        absorptivity: float_item(d, "absorptivity")?,
        reference_temperature: float_item(d, "reference_temperature")?,
    };
    lam.validate()?;
    Ok(lam)
}

/// The conduction model of `panel` with `nodes` nodes through its layup, or through one
/// homogeneous layer for a plain panel.
pub fn conduction_from(
    panel: &Panel,
    layup: Option<&Bound<'_, PyDict>>,
    nodes: usize,
) -> PyResult<Conduction> {
    Ok(match layup {
        Some(d) => Conduction::new(panel, &laminate_from(d)?, nodes)?,
        None => Conduction::homogeneous(panel, nodes)?,
    })
}

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

/// Lamination-theory properties of a laminate.
#[pyfunction]
fn laminate_properties<'py>(
    py: Python<'py>,
    laminate: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let lam = laminate_from(laminate)?;
        let d = PyDict::new(py);
        d.set_item("thickness", lam.thickness())?;
        d.set_item("mass_per_area", lam.mass_per_area())?;
        d.set_item("heat_capacity", lam.heat_capacity())?;
        d.set_item("thermal_resistance", lam.thermal_resistance())?;
        d.set_item("neutral_axis", lam.neutral_axis())?;
        d.set_item("bending_stiffness", lam.bending_stiffness())?;
        d.set_item("extensional_stiffness", lam.extensional_stiffness())?;
        Ok(d)
    })
}

/// The panel fields equivalent to a laminate, the others taken from `panel`.
#[pyfunction]
fn equivalent_panel<'py>(
    py: Python<'py>,
    laminate: &Bound<'py, PyDict>,
    panel: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let lam = laminate_from(laminate)?;
        let base = panel_from(panel)?;
        panel_dict(py, &lam.equivalent_panel(&base)?)
    })
}

/// The material library: a list of mappings (key, name, properties, source).
#[pyfunction]
fn materials<'py>(py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
    MATERIALS
        .iter()
        .map(|m| {
            let d = PyDict::new(py);
            d.set_item("key", m.key)?;
            d.set_item("name", m.name)?;
            d.set_item("conductivity", m.conductivity)?;
            d.set_item("density", m.density)?;
            d.set_item("specific_heat", m.specific_heat)?;
            d.set_item("youngs_modulus", m.youngs_modulus)?;
            d.set_item("expansion_coeff", m.expansion_coeff)?;
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

/// The default start of an N-node run beginning at `t0`: the sunlit equilibrium at that time's
/// solar flux, at rest (node temperatures, θ, θ̇).
#[pyfunction]
fn layered_start_state(
    panel: &Bound<'_, PyDict>,
    grid: Grid<'_>,
    orbit: &Bound<'_, PyDict>,
    t0: f64,
    coupled: bool,
) -> PyResult<Vec<f64>> {
    shield(|| {
        let p = panel_from(panel)?;
        let o = orbit_from(orbit)?;
        let c = grid.conduction(&p)?;
        Ok(crate::analysis::layered::start_state(
            &p,
            &c,
            coupling(coupled),
            &o,
            t0,
        )?)
    })
}

/// Flutter analysis of the N-node system (full nodal Jacobian).
#[pyfunction]
#[pyo3(signature = (panel, grid, model, coupled, flux, with_critical=true))]
fn layered_flutter<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    grid: Grid<'py>,
    model: &str,
    coupled: bool,
    flux: f64,
    with_critical: bool,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let (p, m) = flutter_inputs(panel, model, flux)?;
        let c = grid.conduction(&p)?;
        let k = coupling(coupled);
        let a = py.detach(|| crate::analysis::layered::analyse(&p, &c, m, k, flux))?;
        let d = equilibrium_dict(py, &a.equilibrium)?;
        let size = a.jacobian.nrows();
        let rows = (0..size).map(|i| (0..size).map(|j| a.jacobian[(i, j)]).collect());
        set_spectrum(&d, rows, &a.eigenvalues, a.growth_rate, a.frequency_hz)?;
        if with_critical {
            let cd =
                py.detach(|| crate::analysis::layered::critical_damping(&p, &c, m, k, flux))?;
            d.set_item("critical_damping", cd)?;
        }
        Ok(d)
    })
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
    m.add_function(wrap_pyfunction!(equivalent_panel, m)?)?;
    m.add_function(wrap_pyfunction!(materials, m)?)?;
    m.add_function(wrap_pyfunction!(conduction_grid, m)?)?;
    m.add_function(wrap_pyfunction!(layered_steady_state, m)?)?;
    m.add_function(wrap_pyfunction!(layered_start_state, m)?)?;
    m.add_function(wrap_pyfunction!(layered_flutter, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_layers, m)?)?;
    Ok(())
}
