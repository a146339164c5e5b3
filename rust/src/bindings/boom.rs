//! Bindings of the boom (`inputs::boom`, `models::tube`): its checks and derived values, its
//! transient, its runs of whole orbits and its flutter analysis.

use super::cancel::{cancellable, CancelToken};
use super::convert::{coupling, float_item, orbit_from, solver_from, RunOptions};
use super::error::shield;
use super::flutter::set_spectrum;
use super::orbits::{hybrid_counters, summary_dict};
use super::transient_dict;
use crate::analysis::flutter::check_flux;
use crate::inputs::boom::{Boom, BOOM_TABLE};
use crate::models::hinge::check_hinge_angle;
use crate::models::tube::boom_system;
use crate::runs::orbits::SummaryOptions;
use crate::runs::request::Transient;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A boom from a mapping of every one of its parameters, validated.
fn boom_from(d: &Bound<'_, PyDict>) -> PyResult<Boom> {
    let mut b = Boom::example();
    for name in Boom::FIELDS {
        b.set(name, float_item(d, name)?)?;
    }
    b.validate()?;
    Ok(b)
}

/// Validates a boom given as a mapping and returns what the model derives from it: the tube's
/// mass, bending stiffness and thermal time constant, and its equivalent hinge.
#[pyfunction]
fn boom_derived<'py>(py: Python<'py>, boom: &Bound<'py, PyDict>) -> PyResult<Bound<'py, PyDict>> {
    let b = boom_from(boom)?;
    let d = PyDict::new(py);
    for (name, value) in [
        ("mass_per_length", b.mass_per_length()),
        ("bending_inertia", b.bending_inertia()),
        ("heat_capacity", b.heat_capacity()),
        ("conduction_relaxation", b.conduction_relaxation()),
        ("radiation_relaxation", b.radiation_relaxation()),
        ("time_constant", b.time_constant()),
        ("sunlit_mean_temperature", b.sunlit_mean_temperature()),
        ("physical_moment_per_kelvin", b.physical_moment_per_kelvin()),
        ("beta1_l", b.beta1_l()),
        ("first_angular_frequency", b.first_angular_frequency()),
        ("hinge_inertia", b.hinge_inertia()),
        ("hinge_stiffness", b.hinge_stiffness()),
        ("hinge_damping", b.hinge_damping()),
        ("hinge_moment_scale", b.hinge_moment_scale()),
        ("moment_per_kelvin", b.moment_per_kelvin()),
    ] {
        d.set_item(name, value)?;
    }
    let panel = b.hinge_panel();
    let p = PyDict::new(py);
    for name in crate::Panel::FIELDS {
        p.set_item(name, panel.get(name)?)?;
    }
    d.set_item("hinge_panel", p)?;
    Ok(d)
}

/// The boom's steady state (T̄, T_m, θ, θ̇) under the flux factor `flux`.
#[pyfunction]
#[pyo3(signature = (boom, coupled=true, flux=1.0))]
fn boom_steady_state(boom: &Bound<'_, PyDict>, coupled: bool, flux: f64) -> PyResult<Vec<f64>> {
    shield(|| {
        let b = boom_from(boom)?;
        check_flux(flux)?;
        let sys = boom_system(&b, crate::Orbit::geo_equinox(), coupling(coupled))?;
        Ok(sys.steady_state(flux)?.as_slice().to_vec())
    })
}

/// The default start of a boom's run at `t0`: its steady state at that time's solar flux.
#[pyfunction]
fn boom_start_state(
    boom: &Bound<'_, PyDict>,
    orbit: &Bound<'_, PyDict>,
    t0: f64,
    coupled: bool,
) -> PyResult<Vec<f64>> {
    shield(|| {
        let b = boom_from(boom)?;
        let o = orbit_from(orbit)?;
        crate::Orbit::check_time(t0)?;
        let sys = boom_system(&b, o, coupling(coupled))?;
        Ok(sys.steady_state(o.flux_scale(t0))?.as_slice().to_vec())
    })
}

/// A transient of the boom: the columns T_mean, T_circ, theta, theta_dot, thermal_moment and
/// sunlit, with the counters, the end state and the limit's crossing (as `simulate`'s).
#[pyfunction]
#[pyo3(signature = (boom, orbit, run, *, coupled, cancel=None))]
fn simulate_boom<'py>(
    py: Python<'py>,
    boom: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    run: RunOptions<'py>,
    coupled: bool,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let b = boom_from(boom)?;
        let o = orbit_from(orbit)?;
        let settings = run.transient(true)?;
        let c = coupling(coupled);
        let run = py.detach(|| crate::runs::boom::simulate(&b, o, c, settings, cancel))?;
        transient_dict(py, Transient::Coupled(run))
    })
}

/// How a run of a boom's orbits is asked for: one mapping with the keys `run_orbits` takes one
/// by one (the same names and meanings), converted here once.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct OrbitsSpec<'py> {
    model: String,
    coupled: bool,
    solver: Bound<'py, PyDict>,
    t_start: f64,
    first_index: u64,
    n_orbits: u64,
    window: f64,
    theta_limit: f64,
    stop_at_limit: bool,
    steps_per_period: f64,
}

/// Whole orbits of the boom from `y0`, summarised as `run_orbits`'s, asked for by `spec`. With
/// `hybrid` the run is the full integration (the hybrid propagator's modal form is the plate's,
/// not the tube's), and says so: all its time in `t_fallback`, with `fallback` the reason.
#[pyfunction]
#[pyo3(signature = (boom, orbit, spec, y0, *, hybrid=None, cancel=None))]
fn run_boom_orbits<'py>(
    py: Python<'py>,
    boom: &Bound<'py, PyDict>,
    orbit: &Bound<'py, PyDict>,
    spec: OrbitsSpec<'py>,
    y0: Vec<f64>,
    hybrid: Option<&Bound<'py, PyDict>>,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    let OrbitsSpec {
        model,
        coupled,
        solver,
        t_start,
        first_index,
        n_orbits,
        window,
        theta_limit,
        stop_at_limit,
        steps_per_period,
    } = spec;
    cancellable(cancel, |cancel| {
        let b = boom_from(boom)?;
        let o = orbit_from(orbit)?;
        // The rigid link has no (1 + 3 sin²θ): both hinge models are the same equation.
        super::convert::hinge_model(&model)?;
        let method = solver_from(&solver)?;
        check_hinge_angle("theta_limit", theta_limit)?;
        if let Some(h) = hybrid {
            super::convert::hybrid_from(h)?;
        }
        let options = SummaryOptions {
            window,
            theta_limit,
            stop_at_limit,
            steps_per_period,
        };
        let c = coupling(coupled);
        let span = (t_start, first_index, n_orbits);
        let out = py.detach(|| {
            crate::runs::boom::run_orbits(&b, o, c, &method, span, &y0, options, cancel)
        })?;
        let d = summary_dict(py, &out, &method)?;
        if hybrid.is_some() {
            // All of it the fallback's: the tube has no hybrid regime.
            let all_full = crate::runs::hybrid::HybridRun {
                t_fallback: out.stats.t_end - t_start,
                n_fallback_steps: out.stats.n_steps,
                ..Default::default()
            };
            hybrid_counters(d.clone(), &all_full)?;
            d.set_item(
                "fallback",
                "the hybrid propagator's linear arcs are the plate's modal form; the tube ran \
                 the full integration (rk45 resolving the hinge period)",
            )?;
        }
        Ok(d)
    })
}

/// The boom's flutter analysis at its steady state under `flux`: the Jacobian over
/// (T̄, T_m, θ, θ̇), its eigenvalues, growth rate and frequency, and the critical damping ratio.
#[pyfunction]
#[pyo3(signature = (boom, coupled, flux, with_critical=true))]
fn boom_flutter<'py>(
    py: Python<'py>,
    boom: &Bound<'py, PyDict>,
    coupled: bool,
    flux: f64,
    with_critical: bool,
) -> PyResult<Bound<'py, PyDict>> {
    shield(|| {
        let b = boom_from(boom)?;
        check_flux(flux)?;
        let c = coupling(coupled);
        let (eq, jac, s) = crate::analysis::tube::spectrum(&b, c, flux)?;
        let d = PyDict::new(py);
        d.set_item("equilibrium", eq.to_vec())?;
        let rows = jac.row_iter().map(|row| row.iter().copied().collect());
        set_spectrum(&d, rows, &s.eigenvalues, s.growth_rate, s.frequency_hz)?;
        if with_critical {
            let f = crate::analysis::tube::flutter(&b, c, flux)?;
            d.set_item("critical_damping", f.critical_damping_ratio)?;
        }
        Ok(d)
    })
}

/// The boom's growth rate and critical damping ratio over solar inclinations (rows) and ratios
/// B = ω₁ τ (columns), each as a flat row-major list.
#[pyfunction]
#[pyo3(signature = (boom, inclinations, ratios, coupled, flux, *, cancel=None))]
fn boom_stability_map<'py>(
    py: Python<'py>,
    boom: &Bound<'py, PyDict>,
    inclinations: Vec<f64>,
    ratios: Vec<f64>,
    coupled: bool,
    flux: f64,
    cancel: Option<&Bound<'py, CancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    cancellable(cancel, |cancel| {
        let b = boom_from(boom)?;
        check_flux(flux)?;
        let c = coupling(coupled);
        let map = py.detach(|| {
            crate::analysis::tube::stability_map(&b, &inclinations, &ratios, c, flux, cancel)
        })?;
        let d = PyDict::new(py);
        d.set_item("growth_rate", map.growth_rate)?;
        d.set_item("critical_damping", map.critical_damping_ratio)?;
        Ok(d)
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(boom_stability_map, m)?)?;
    m.add("BOOM_FIELDS", Boom::FIELDS.to_vec())?;
    let ranges = PyDict::new(m.py());
    let example = PyDict::new(m.py());
    for (name, value, range) in BOOM_TABLE {
        ranges.set_item(name, range)?;
        example.set_item(name, value)?;
    }
    m.add("BOOM_RANGES", ranges)?;
    m.add("BOOM_EXAMPLE", example)?;
    m.add_function(wrap_pyfunction!(boom_derived, m)?)?;
    m.add_function(wrap_pyfunction!(boom_steady_state, m)?)?;
    m.add_function(wrap_pyfunction!(boom_start_state, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_boom, m)?)?;
    m.add_function(wrap_pyfunction!(run_boom_orbits, m)?)?;
    m.add_function(wrap_pyfunction!(boom_flutter, m)?)?;
    Ok(())
}
