//! Bindings of the distributed panel: its settings, modes, and flutter analysis.

use super::cancel::{cancellable, CancelToken};
use super::convert::{
    coupling, crossing_tuple, orbit_from, panel_from, required_item, set_counters, OrbitsRun,
    RunOptions,
};
use super::error::{invalid, shield};
use crate::analysis::flutter::check_flux;
use crate::models::distributed::{DistributedPanel, Settings, Support};
use crate::runs::orbits::{OrbitRunSpec, SummaryOptions};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::f64::consts::PI;

/// A count setting (`elements`, `modes`) as usize, named in any error.
fn count(name: &str, value: i64) -> PyResult<usize> {
    usize::try_from(value).map_err(|_| invalid(name, value, "must be a positive integer"))
}

/// The model from a panel mapping and a settings mapping {support, elements, modes,
/// damping_ratio (None: hinge-equivalent), sun_angle, coupled}.
pub(super) fn model_from(
    panel: &Bound<'_, PyDict>,
    settings: &Bound<'_, PyDict>,
) -> PyResult<DistributedPanel> {
    let p = panel_from(panel)?;
    let support: String = required_item(settings, "support", "a string")?;
    let elements: i64 = required_item(settings, "elements", "an integer")?;
    let modes: i64 = required_item(settings, "modes", "an integer")?;
    let zeta: Option<f64> = required_item(settings, "damping_ratio", "a number or None")?;
    let sun_angle: f64 = required_item(settings, "sun_angle", "a number")?;
    let coupled: bool = required_item(settings, "coupled", "a bool")?;
    let layers: i64 = required_item(settings, "layers", "an integer")?;
    let layers = u32::try_from(layers)
        .map_err(|_| invalid("layers", layers, "must be a positive integer"))?;
    let defaults = Settings::new(&p);
    let s = Settings {
        layers,
        support: Support::from_name(&support).map_err(PyErr::from)?,
        elements: count("elements", elements)?,
        modes: count("modes", modes)?,
        damping_ratio: zeta.unwrap_or(defaults.damping_ratio),
        sun_angle,
        coupling: coupling(coupled),
    };
    DistributedPanel::new(&p, s).map_err(PyErr::from)
}

/// The kept modes' frequencies (Hz) and the damping ratio in use, into `d`.
fn modal_info<'py>(py: Python<'py>, m: &DistributedPanel, d: &Bound<'py, PyDict>) -> PyResult<()> {
    let hz: Vec<f64> = m.reduction.omega.iter().map(|w| w / (2.0 * PI)).collect();
    d.set_item("frequencies_hz", PyArray1::from_vec(py, hz))?;
    d.set_item("damping_ratio", m.settings.damping_ratio)
}

/// What the model is: node and element positions, kept frequencies, the damping ratio in use,
/// the defaults, and the mesh's first elastic frequency.
#[pyfunction]
fn distributed_info<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    settings: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let m = model_from(panel, settings)?;
        let mesh = &m.reduction.mesh;
        let d = PyDict::new(py);
        d.set_item("x_node", PyArray1::from_vec(py, mesh.node_x()))?;
        d.set_item("x", PyArray1::from_vec(py, mesh.element_x()))?;
        modal_info(py, &m, &d)?;
        d.set_item("arm", mesh.arm())?;
        d.set_item("elastic_modes", mesh.elastic_modes())?;
        Ok(d)
    })
}

/// ζ = c_d/(2 I_B ω₁): the modal damping ratio equivalent to the panel's hinge damping (the beam
/// comparator's and the distributed panel's default).
#[pyfunction]
fn hinge_equivalent_damping_ratio(panel: &Bound<'_, PyDict>) -> PyResult<f64> {
    shield(|| {
        Ok(crate::models::beam::hinge_equivalent_damping_ratio(
            &panel_from(panel)?,
        ))
    })
}

/// The defaults of the distributed model's settings.
#[pyfunction]
fn distributed_defaults(py: Python<'_>, panel: &Bound<'_, PyDict>) -> PyResult<Py<PyDict>> {
    shield(|| {
        let p = panel_from(panel)?;
        let s = Settings::new(&p);
        let d = PyDict::new(py);
        d.set_item("support", s.support.name())?;
        d.set_item("elements", s.elements)?;
        d.set_item("modes", s.modes)?;
        d.set_item("damping_ratio", s.damping_ratio)?;
        d.set_item("sun_angle", s.sun_angle)?;
        Ok(d.unbind())
    })
}

/// Eigen-analysis of the distributed panel at its sunlit equilibrium under flux factor `flux`.
#[pyfunction]
fn distributed_flutter<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    settings: &Bound<'py, PyDict>,
    flux: f64,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let m = model_from(panel, settings)?;
        check_flux(flux).map_err(PyErr::from)?;
        let a = py.detach(|| m.flutter(flux)).map_err(PyErr::from)?;
        let d = PyDict::new(py);
        let temps = PyDict::new(py);
        for (name, row) in m
            .temperature_names()
            .iter()
            .zip(m.temperature_rows(&a.equilibrium))
        {
            temps.set_item(name, PyArray1::from_vec(py, row))?;
        }
        d.set_item("temperatures", temps)?;
        let (w, slope) = m.nodal(&a.equilibrium);
        d.set_item("deflection", PyArray1::from_vec(py, w))?;
        d.set_item("slope", PyArray1::from_vec(py, slope))?;
        d.set_item("theta_f", a.theta_f)?;
        let ev: Vec<(f64, f64)> = a.eigenvalues.iter().map(|z| (z.re, z.im)).collect();
        d.set_item("eigenvalues", ev)?;
        d.set_item("growth_rate", a.growth_rate)?;
        let modes: Vec<(f64, f64, usize)> = a
            .modes
            .iter()
            .map(|o| (o.growth_rate, o.frequency_hz, o.structural_mode))
            .collect();
        d.set_item("modes", modes)?;
        d.set_item("critical_damping_ratio", a.critical_damping_ratio)?;
        d.set_item("critical_damping", a.critical_damping)?;
        d.set_item("damping_ratio", m.settings.damping_ratio)?;
        Ok(d)
    })
}

/// Rows of equal length as a 2-D array.
fn matrix<'py>(
    py: Python<'py>,
    rows: &[Vec<f64>],
    width: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    if rows.is_empty() {
        return Ok(PyArray2::zeros(py, [0, width], false));
    }
    PyArray2::from_vec2(py, rows).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Integrates the distributed panel on an orbit; fields sampled at the requested times. Watches
/// |θ_f| against `theta_limit` as `on_limit` says ("flag", "stop", "ignore") and stops with
/// KeyboardInterrupt within a step of `cancel`.
#[pyfunction]
#[pyo3(signature = (panel, orbit, settings, run, *, cancel=None))]
fn simulate_distributed<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    settings: &Bound<'py, PyDict>,
    run: RunOptions<'py>,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let m = model_from(panel, settings)?;
        let o = orbit_from(orbit)?;
        let settings = run.transient(true)?;
        if let Some(x) = settings.y0.iter().flatten().find(|x| !x.is_finite()) {
            return Err(invalid("y0", x, "every component must be finite"));
        }
        let limit = settings.limit;
        let r = py
            .detach(|| crate::runs::distributed::simulate(&m, o, settings, cancel))
            .map_err(PyErr::from)?;
        let mesh = &m.reduction.mesh;
        let (n, nodes) = (m.n(), m.n() + 1);
        let d = PyDict::new(py);
        d.set_item("t", PyArray1::from_vec(py, r.t))?;
        d.set_item("x", PyArray1::from_vec(py, mesh.element_x()))?;
        d.set_item("x_node", PyArray1::from_vec(py, mesh.node_x()))?;
        // One (time × element) array per temperature name.
        let temps = PyDict::new(py);
        for (i, name) in r.names.iter().enumerate() {
            let rows: Vec<Vec<f64>> = r.temperatures.iter().map(|s| s[i].clone()).collect();
            temps.set_item(name, matrix(py, &rows, n)?)?;
        }
        d.set_item("temperatures", temps)?;
        d.set_item("thermal_moment", matrix(py, &r.moment, n)?)?;
        d.set_item("deflection", matrix(py, &r.deflection, nodes)?)?;
        d.set_item("slope", matrix(py, &r.slope, nodes)?)?;
        d.set_item("theta_f", PyArray1::from_vec(py, r.theta_f))?;
        d.set_item("sunlit", PyArray1::from_vec(py, r.sunlit))?;
        let (front, back) = r.fluxes;
        d.set_item("flux_front", PyArray1::from_vec(py, front))?;
        d.set_item("flux_back", PyArray1::from_vec(py, back))?;
        d.set_item("y_end", PyArray1::from_vec(py, r.y_end))?;
        set_counters(&d, &r.stats)?;
        d.set_item("t_end", r.stats.t_end)?;
        d.set_item("crossing", crossing_tuple(r.crossing))?;
        d.set_item(
            "stopped",
            r.crossing.is_some() && limit.is_some_and(|l| l.stop),
        )?;
        modal_info(py, &m, &d)?;
        Ok(d)
    })
}

/// The default start state of a distributed run on an orbit at t0 (the sunlit equilibrium at
/// rest at that date's flux, or under the orbit's loads there).
#[pyfunction]
fn distributed_start_state(
    py: Python<'_>,
    panel: &Bound<'_, PyDict>,
    settings: &Bound<'_, PyDict>,
    orbit: &Bound<'_, PyDict>,
    t0: f64,
) -> PyResult<Vec<f64>> {
    shield(|| {
        let m = model_from(panel, settings)?;
        let o = orbit_from(orbit)?;
        o.validate().map_err(PyErr::from)?;
        m.check_orbit(&o).map_err(PyErr::from)?;
        py.detach(|| crate::runs::distributed::start_state(&m, &o, t0))
            .map_err(PyErr::from)
    })
}

/// A chunk of a long run as `thermojitter.longrun` passes it, one mapping: its start state, the
/// time and index of its first orbit, and what it watches.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct Chunk {
    y0: Vec<f64>,
    t_start: f64,
    first_index: u64,
    theta_limit: f64,
    stop_at_limit: bool,
    steps_per_period: f64,
}

/// Integrates the distributed panel over whole orbits and returns one summary per orbit (the
/// hinge runs' columns, θ read as θ_f, with `tip_max` and `tip_min`); with `hybrid` (its
/// settings) on linear arcs where their checks hold, adding how the simulated time was split.
#[pyfunction]
#[pyo3(signature = (panel, orbit, settings, orbits, chunk, *, cancel=None))]
fn run_distributed_orbits<'py>(
    py: Python<'py>,
    panel: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    settings: &Bound<'py, PyDict>,
    orbits: OrbitsRun<'py>,
    chunk: Chunk,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let m = model_from(panel, settings)?;
        let (hinge, coupling, method) = orbits.hinge()?;
        crate::models::hinge::check_hinge_angle("theta_limit", chunk.theta_limit)?;
        let options = SummaryOptions {
            window: orbits.window,
            theta_limit: chunk.theta_limit,
            stop_at_limit: chunk.stop_at_limit,
            steps_per_period: chunk.steps_per_period,
        };
        let spec = OrbitRunSpec {
            panel: m.panel,
            orbit: orbit_from(orbit)?,
            model: hinge,
            coupling,
            method,
            t_start: chunk.t_start,
            first_index: chunk.first_index,
            n_orbits: orbits.n_orbits,
            options,
        };
        let hybrid = orbits.hybrid()?;
        let y0 = chunk.y0;
        let out = py.detach(|| {
            crate::runs::distributed_orbits::run_distributed_orbits(
                &m,
                &spec,
                &y0,
                hybrid.as_ref(),
                cancel,
            )
        })?;
        let summaries = crate::runs::layered::LayeredSummaries {
            summaries: out.summaries,
            stats: out.stats,
            y_end: out.y_end,
            crossing: out.crossing,
        };
        let d = super::orbits::summary_dict(py, &summaries, &method)?;
        d.set_item("tip_max", PyArray1::from_vec(py, out.tip_max))?;
        d.set_item("tip_min", PyArray1::from_vec(py, out.tip_min))?;
        if let Some(split) = out.split {
            // Named as the hybrid runs' counters: its full integration is their fallback, the
            // umbra (the temperatures integrated alone, the modes exactly) their exponential
            // steps.
            let counters = crate::runs::hybrid::HybridRun {
                t_linear: split.t_linear,
                t_exponential: split.t_umbra,
                t_fallback: split.t_full,
                n_arcs: split.n_arcs,
                n_exp_steps: split.n_umbra_steps,
                n_fallback_steps: split.n_full_steps,
                ..Default::default()
            };
            super::orbits::hybrid_counters(d.clone(), &counters)?;
            d.set_item("n_refused_arcs", split.n_refused)?;
        }
        modal_info(py, &m, &d)?;
        Ok(d)
    })
}

/// The metrics a study reads off per-orbit summary columns (`thermojitter.longrun`'s, as
/// arrays) of a run that ended at `t_end`: theta_abs_max, amplitude, entry_peak, exit_peak,
/// jitter_rms, jitter_peak, amplitude_slope (`crate::runs::ensemble::summary_metrics`).
#[pyfunction]
fn summary_metrics(columns: &Bound<'_, PyDict>, t_end: f64) -> PyResult<Vec<(String, f64)>> {
    shield(|| {
        let col = |name: &str| -> PyResult<Vec<f64>> {
            required_item(columns, name, "an array of numbers")
        };
        let index: Vec<u64> = required_item(columns, "index", "an array of integers")?;
        let names = [
            "t_start",
            "t_end",
            "theta_eq",
            "theta_max",
            "theta_min",
            "amplitude",
            "jitter_rms",
            "jitter_peak",
            "t_entry",
            "t_exit",
            "entry_theta_min",
            "exit_theta_max",
            "entry_peak",
            "exit_peak",
        ];
        let values = names.iter().map(|n| col(n)).collect::<PyResult<Vec<_>>>()?;
        if let Some(bad) = values.iter().position(|v| v.len() != index.len()) {
            return Err(invalid(
                names[bad],
                values[bad].len(),
                "must hold one value per orbit",
            ));
        }
        let v = |k: usize, i: usize| values[k][i];
        let rows: Vec<crate::runs::orbits::OrbitSummary> = (0..index.len())
            .map(|i| crate::runs::orbits::OrbitSummary {
                index: index[i],
                t_start: v(0, i),
                t_end: v(1, i),
                theta_eq: v(2, i),
                theta_max: v(3, i),
                theta_min: v(4, i),
                amplitude: v(5, i),
                jitter_rms: v(6, i),
                jitter_peak: v(7, i),
                t_entry: v(8, i),
                t_exit: v(9, i),
                entry_theta_min: v(10, i),
                exit_theta_max: v(11, i),
                entry_peak: v(12, i),
                exit_peak: v(13, i),
            })
            .collect();
        let m = crate::runs::ensemble::summary_metrics(&rows, t_end);
        let out = [
            "theta_abs_max",
            "amplitude",
            "entry_peak",
            "exit_peak",
            "jitter_rms",
            "jitter_peak",
            "amplitude_slope",
        ];
        Ok(out.iter().zip(m).map(|(n, x)| (n.to_string(), x)).collect())
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(summary_metrics, m)?)?;
    m.add_function(wrap_pyfunction!(run_distributed_orbits, m)?)?;
    m.add_function(wrap_pyfunction!(distributed_start_state, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_distributed, m)?)?;
    m.add_function(wrap_pyfunction!(distributed_info, m)?)?;
    m.add_function(wrap_pyfunction!(hinge_equivalent_damping_ratio, m)?)?;
    m.add_function(wrap_pyfunction!(distributed_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(distributed_flutter, m)?)?;
    Ok(())
}
