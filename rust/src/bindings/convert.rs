//! Python values to engine types, with errors that name the parameter.

use super::error::invalid;
use crate::inputs::attitude::Attitude;
use crate::inputs::heating::{Loads, Optics};
use crate::inputs::laminate::{Laminate, Layer, LAYER_FIELDS};
use crate::inputs::orbit::Shadow;
use crate::models::conduction::Conduction;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use crate::numerics::integrate::{Method, Stats, Tolerances};
use crate::runs::hybrid::HybridSettings;
use crate::runs::simulate::{Output, TransientSettings};
use crate::{Orbit, Panel};
use numpy::PyReadonlyArray1;
use pyo3::exceptions::PyTypeError;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyBool, PyDict, PyList, PyString};

/// A float entry of a mapping, named in any error. The key may be an interned Python string, so
/// that the lookup neither builds nor hashes a new string.
pub(super) fn float_item<'py, K>(d: &Bound<'py, PyDict>, key: K) -> PyResult<f64>
where
    K: IntoPyObject<'py> + std::fmt::Display + Copy,
{
    let v = d
        .get_item(key)?
        .ok_or_else(|| invalid(&key.to_string(), "missing", "is required"))?;
    // A bool is not a number (Python would read True as 1.0).
    if v.is_instance_of::<PyBool>() {
        return Err(type_error(&key.to_string(), "a number", &v));
    }
    v.extract::<f64>()
        .map_err(|_| type_error(&key.to_string(), "a number", &v))
}

/// A TypeError naming the parameter, the type expected and the type given.
pub fn type_error(name: &str, expected: &str, given: &Bound<'_, PyAny>) -> PyErr {
    let kind = given
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default();
    PyTypeError::new_err(format!("{name} must be {expected}, not {kind}"))
}

/// The panel's field names as interned Python strings, built once.
static PANEL_KEYS: PyOnceLock<Vec<Py<PyString>>> = PyOnceLock::new();

pub fn panel_from(d: &Bound<'_, PyDict>) -> PyResult<Panel> {
    let py = d.py();
    let keys = PANEL_KEYS.get_or_init(py, || {
        Panel::FIELDS
            .iter()
            .map(|name| PyString::intern(py, name).unbind())
            .collect()
    });
    let mut p = Panel::paper();
    for (name, key) in Panel::FIELDS.iter().zip(keys) {
        p.set(name, float_item(d, key.bind(py))?)?;
    }
    p.validate()?;
    Ok(p)
}

/// A panel as the mapping [`panel_from`] reads.
pub fn panel_dict<'py>(py: Python<'py>, p: &Panel) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for name in Panel::FIELDS {
        d.set_item(name, p.get(name)?)?;
    }
    Ok(d)
}

/// A result mapping of `(name, value)` pairs, in order: the engine lists a type's named values
/// where they are defined (`LinearThermal::FIELDS` with `values()`, `Material::properties`), and
/// every binding turns them into a dict here.
pub fn dict_of<'py, V: IntoPyObject<'py>>(
    py: Python<'py>,
    pairs: impl IntoIterator<Item = (&'static str, V)>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, value) in pairs {
        d.set_item(name, value)?;
    }
    Ok(d)
}

/// Sets into the dict `$d` each named quantity of `$of`, read by the method of that name and
/// stored under it: `set_named!(d, laminate; thickness, mass_per_area)`. The names of a result's
/// derived quantities are written once, in that list, never as a key and again as a call.
/// `set_named!(d, run; fields a, b)` reads the fields of those names instead.
macro_rules! set_named {
    ($d:expr, $of:expr; fields $($name:ident),+ $(,)?) => {{
        let (d, of) = (&$d, &$of);
        $(d.set_item(stringify!($name), of.$name)?;)+
    }};
    ($d:expr, $of:expr; $($name:ident),+ $(,)?) => {{
        let (d, of) = (&$d, &$of);
        $(d.set_item(stringify!($name), of.$name())?;)+
    }};
}
pub(super) use set_named;

/// An optional entry of a mapping of type T, named in any error.
pub(super) fn optional_item<'py, T: FromPyObjectOwned<'py>>(
    d: &Bound<'py, PyDict>,
    key: &str,
    kind: &str,
) -> PyResult<Option<T>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(v) => v
            .extract::<T>()
            .map(Some)
            .map_err(|_| type_error(key, kind, &v)),
    }
}

/// A required entry of a mapping, of type `T` (`kind` says which in the error).
pub(super) fn required_item<'py, T: FromPyObjectOwned<'py>>(
    d: &Bound<'py, PyDict>,
    key: &str,
    kind: &str,
) -> PyResult<T> {
    optional_item(d, key, kind)?.ok_or_else(|| invalid(key, "missing", "is required"))
}

/// An optional number of a mapping (checked as [`float_item`] checks it), or `default`.
fn float_or(d: &Bound<'_, PyDict>, key: &str, default: f64) -> PyResult<f64> {
    match d.get_item(key)? {
        Some(_) => float_item(d, key),
        None => Ok(default),
    }
}

/// An orbit from a mapping: radius, earth_radius, period and phase0 are required; shadow
/// ('none' | 'cylindrical' | 'conical' | 'penumbra'), season, eccentric_sun, epoch_day,
/// inclination, raan and j2 are optional and default to the paper's equinox.
pub fn orbit_from(d: &Bound<'_, PyDict>) -> PyResult<Orbit> {
    let base = Orbit::geo_equinox();
    let shadow = match optional_item::<String>(d, "shadow", "a string")? {
        Some(name) => Shadow::from_name(&name)?,
        None => base.shadow,
    };
    let o = Orbit {
        radius: float_item(d, "radius")?,
        earth_radius: float_item(d, "earth_radius")?,
        period: float_item(d, "period")?,
        phase0: float_item(d, "phase0")?,
        shadow,
        season: optional_item(d, "season", "a bool")?.unwrap_or(base.season),
        eccentric_sun: optional_item(d, "eccentric_sun", "a bool")?.unwrap_or(base.eccentric_sun),
        epoch_day: float_or(d, "epoch_day", base.epoch_day)?,
        inclination: float_or(d, "inclination", base.inclination)?,
        raan: float_or(d, "raan", base.raan)?,
        j2: optional_item(d, "j2", "a bool")?.unwrap_or(base.j2),
        albedo: float_or(d, "albedo", base.albedo)?,
        earth_ir: float_or(d, "earth_ir", base.earth_ir)?,
        attitude: match d.get_item("attitude")? {
            Some(a) => attitude_from(&a)?,
            None => base.attitude,
        },
    };
    o.validate()?;
    Ok(o)
}

/// An attitude from a mapping: `kind` ('sun_pointing' | 'sun_tracking' | 'nadir' |
/// 'inertial'), with `offset` (rad) for Sun tracking and `normal` (three numbers) for inertial.
pub fn attitude_from(value: &Bound<'_, PyAny>) -> PyResult<Attitude> {
    let d = value
        .cast::<PyDict>()
        .map_err(|_| type_error("attitude", "a mapping", value))?;
    let kind: String = required_item(d, "kind", "a string")?;
    let attitude = match kind.as_str() {
        "sun_pointing" => Attitude::SunPointing,
        "nadir" => Attitude::Nadir,
        "sun_tracking" => Attitude::SunTracking {
            offset: float_item(d, "offset")?,
        },
        "inertial" => {
            let normal: Vec<f64> = required_item(d, "normal", "three numbers")?;
            let normal: [f64; 3] = normal.try_into().map_err(|v: Vec<f64>| {
                invalid(
                    "attitude.normal",
                    format!("{v:?}"),
                    "must hold three numbers",
                )
            })?;
            Attitude::inertial(normal)?
        }
        other => {
            return Err(invalid(
                "attitude",
                format!("{other:?}"),
                "must be 'sun_pointing', 'sun_tracking', 'nadir' or 'inertial'",
            ))
        }
    };
    attitude.validate()?;
    Ok(attitude)
}

/// The coupling of a `coupled` flag: the projected area follows θ (two-way), or is frozen.
pub fn coupling(coupled: bool) -> Coupling {
    if coupled {
        Coupling::ProjectedArea
    } else {
        Coupling::Frozen
    }
}

pub fn hinge_model(name: &str) -> PyResult<HingeModel> {
    match name {
        "nonlinear" => Ok(HingeModel::Nonlinear),
        "linear" => Ok(HingeModel::Linear),
        other => Err(invalid(
            "model",
            format!("{other:?}"),
            "must be 'nonlinear' or 'linear'",
        )),
    }
}

/// The validity limit a run watches: `theta_limit` (rad, checked whatever `on_limit`) with
/// `on_limit` "flag" (record the first crossing), "stop" (end the run there) or "ignore" (None).
pub fn on_limit(
    theta_limit: f64,
    on_limit: &str,
) -> PyResult<Option<crate::runs::simulate::OnLimit>> {
    let stop = match on_limit {
        "flag" => false,
        "stop" => true,
        "ignore" => {
            crate::runs::simulate::check_theta_limit(theta_limit)?;
            return Ok(None);
        }
        other => {
            return Err(invalid(
                "on_limit",
                format!("{other:?}"),
                "must be 'flag', 'stop' or 'ignore'",
            ))
        }
    };
    Ok(Some(crate::runs::simulate::OnLimit::new(
        theta_limit,
        stop,
    )?))
}

/// A limit crossing as the long runs report theirs: (t s, orbit index, θ rad).
pub fn crossing_tuple(c: Option<crate::runs::orbits::LimitCrossing>) -> Option<(f64, u64, f64)> {
    c.map(|c| (c.t, c.orbit, c.theta))
}

/// The integrator from a solver mapping {method, rtol, atol, dt, max_step, max_steps}, as every
/// run function receives it, converted only: its settings are checked once, by the integrator
/// ([`Method::validate`], at the start of every solve).
pub fn solver_from(d: &Bound<'_, PyDict>) -> PyResult<Method> {
    let name: String = required_item(d, "method", "a string")?;
    let dt = match d.get_item("dt")? {
        Some(v) if !v.is_none() => Some(float_item(d, "dt")?),
        _ => None,
    };
    let max_steps: u64 = required_item(d, "max_steps", "an integer >= 1")?;
    let (rtol, atol) = (float_item(d, "rtol")?, float_item(d, "atol")?);
    let max_step = float_item(d, "max_step")?;
    // rk45 does not use dt, but a dt no method could use is a mistake all the same.
    if let Some(dt) = dt {
        crate::error::require_positive("dt", dt)?;
    }
    match name.as_str() {
        "rk45" => Ok(Method::Dopri5(Tolerances {
            rtol,
            atol,
            max_step,
            max_steps,
        })),
        "rk4" => match dt {
            Some(dt) => Ok(Method::Rk4 { dt }),
            None => Err(invalid(
                "dt",
                "None",
                "is required with method='rk4' (the fixed step, s)",
            )),
        },
        other => Err(invalid(
            "method",
            format!("{other:?}"),
            "must be 'rk45' or 'rk4'",
        )),
    }
}

/// A layer from a mapping of its fields and a name.
pub(super) fn layer_from(d: &Bound<'_, PyAny>, index: usize) -> PyResult<Layer> {
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
pub(super) fn laminate_from(d: &Bound<'_, PyDict>) -> PyResult<Laminate> {
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
pub(super) fn conduction_from(
    panel: &Panel,
    layup: Option<&Bound<'_, PyDict>>,
    nodes: usize,
) -> PyResult<Conduction> {
    Ok(match layup {
        Some(d) => Conduction::new(panel, &laminate_from(d)?, nodes)?,
        None => Conduction::homogeneous(panel, nodes)?,
    })
}

/// Hybrid settings from a mapping of optional keys (missing ones keep the engine's defaults).
pub(super) fn hybrid_from(d: &Bound<'_, PyDict>) -> PyResult<HybridSettings> {
    let mut s = HybridSettings::default();
    for (key, value) in d.iter() {
        let key: String = key.extract()?;
        let v: f64 = value.extract()?;
        match key.as_str() {
            "rtol" => s.tolerances.rtol = v,
            "atol_temperature" => s.tolerances.atol_temperature = v,
            "atol_angle" => s.tolerances.atol_angle = v,
            "max_step" => s.tolerances.max_step = v,
            "linear_tolerance" => s.linear_tolerance = v,
            "linear_amplitude" => s.linear_amplitude = v,
            "resolved_amplitude" => s.resolved_amplitude = v,
            other => return Err(invalid("hybrid", other, "not a hybrid setting")),
        }
    }
    s.validate()?;
    Ok(s)
}

// The groups of parameters that several pyfunctions take: each group is ONE struct read from ONE
// Python mapping (pyo3's `FromPyObject`, `from_item_all`: a key per field), converted here, once,
// with the errors every function gives. The Python side builds each mapping in one place too
// (`thermojitter.simulate`: `run_settings` and `limit_args` for [`RunOptions`], `grid_args` for
// [`Grid`]); `_core.pyi` declares each as one TypedDict. A new binding (a new model's run, a new
// analysis of the N-node model) takes these structs rather than restating their parameters.

/// The N-node through-thickness model's grid, as the functions of that model receive it: the
/// mapping `grid` = {layup (a laminate mapping, or None: the panel as one homogeneous layer),
/// nodes}.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct Grid<'py> {
    pub layup: Option<Bound<'py, PyDict>>,
    pub nodes: usize,
}

impl Grid<'_> {
    /// The conduction model of `panel` on this grid ([`conduction_from`]).
    pub fn conduction(&self, panel: &Panel) -> PyResult<Conduction> {
        conduction_from(panel, self.layup.as_ref(), self.nodes)
    }
}

/// The point a flutter analysis linearises about, as both flutter analyses (`flutter` of the
/// two-layer model, `layered_flutter` of the N-node model) receive it: the mapping `point` =
/// {model, coupled, flux}, converted by [`FlutterPoint::inputs`] in the same order with the same
/// errors for both.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct FlutterPoint {
    pub model: String,
    pub coupled: bool,
    pub flux: f64,
}

impl FlutterPoint {
    /// The panel, the hinge model and the coupling of the analysis, its flux factor checked.
    pub fn inputs(&self, panel: &Bound<'_, PyDict>) -> PyResult<(Panel, HingeModel, Coupling)> {
        let p = panel_from(panel)?;
        let m = hinge_model(&self.model)?;
        crate::analysis::flutter::check_flux(self.flux)?;
        Ok((p, m, coupling(self.coupled)))
    }
}

/// A flutter analysis on an orbit, as both analyses (`flutter_at`, `layered_flutter_at`)
/// receive it: the mapping `point` = {t, model, coupled, average}. [`OrbitPoint::inputs`] gives
/// the panel, the orbit and the constant loads it is about: every load of the orbit at time t in
/// full sunlight, or (`average`) their mean over the sunlit arc of the orbit beginning at t.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct OrbitPoint {
    pub t: f64,
    pub model: String,
    pub coupled: bool,
    pub average: bool,
}

impl OrbitPoint {
    /// The panel, the orbit, the hinge (model, coupling) and the loads of the analysis.
    pub fn inputs(
        &self,
        panel: &Bound<'_, PyDict>,
        orbit: &Bound<'_, PyDict>,
    ) -> PyResult<(Panel, Orbit, (HingeModel, Coupling), Loads)> {
        let p = panel_from(panel)?;
        p.validate()?;
        let o = orbit_from(orbit)?;
        let optics = Optics::of(&p);
        let loads = if self.average {
            o.sunlit_average_loads(self.t, &optics)?
        } else {
            Orbit::check_time(self.t)?;
            o.sunlit_loads(self.t, &optics)
        };
        let hinge = (hinge_model(&self.model)?, coupling(self.coupled));
        Ok((p, o, hinge, loads))
    }
}

/// One run over whole orbits, as both the long run (`run_orbits`, one call a chunk of orbits)
/// and the Monte Carlo batches (`MonteCarloPool.run`, one sample a row) receive it: the mapping
/// `orbits` = {model, coupled, solver, n_orbits, window[, hybrid][, grid]}, built in one place on
/// the Python side (`thermojitter.simulate.orbits_args`). `hybrid` (its settings; None: the
/// solver alone) runs the hybrid propagator; `grid` (None: the two-layer model) the N-node model.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct OrbitsRun<'py> {
    pub model: String,
    pub coupled: bool,
    pub solver: Bound<'py, PyDict>,
    pub n_orbits: u64,
    pub window: f64,
    #[pyo3(default)]
    pub hybrid: Option<Bound<'py, PyDict>>,
    #[pyo3(default)]
    pub grid: Option<Grid<'py>>,
}

impl OrbitsRun<'_> {
    /// The hinge model, the coupling and the integrator of the run, converted in that order.
    pub fn hinge(&self) -> PyResult<(HingeModel, Coupling, Method)> {
        let m = hinge_model(&self.model)?;
        Ok((m, coupling(self.coupled), solver_from(&self.solver)?))
    }

    /// The hybrid propagator's settings (None: the solver alone).
    pub fn hybrid(&self) -> PyResult<Option<HybridSettings>> {
        self.hybrid.as_ref().map(hybrid_from).transpose()
    }
}

/// The validity limit a run watches, as the `limit` entry of a [`RunOptions`] mapping
/// {theta_limit, on_limit}: converted by [`on_limit`].
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct Limit {
    pub theta_limit: f64,
    pub on_limit: String,
}

/// How one transient is run, as every transient run function (`simulate`, `simulate_thermal`,
/// `simulate_hinge`, `simulate_layers`, `simulate_distributed`, `beam_response`) receives it:
/// ONE mapping `run` = {span: (t0, t1), solver, t_eval, dt_out[, y0][, limit]}, built in one place
/// on the Python side (`thermojitter.simulate.run_settings`, with `limit_args` for the limit).
///
/// This is the group a new run function takes, rather than its own list of `solver`, `t_eval`,
/// `dt_out`, `y0`, `theta_limit`, `on_limit` parameters: it is converted here once, in the same
/// order with the same errors for every run ([`RunOptions::integration`], [`RunOptions::watch`]).
/// `y0` (the start state, None: the model's default) and `limit` (None: nothing watched) may be
/// left out of the mapping by runs that take no start state or watch no angle.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct RunOptions<'py> {
    pub span: (f64, f64),
    pub solver: Bound<'py, PyDict>,
    pub t_eval: Option<PyReadonlyArray1<'py, f64>>,
    pub dt_out: Option<f64>,
    #[pyo3(default)]
    pub y0: Option<Vec<f64>>,
    #[pyo3(default)]
    pub limit: Option<Limit>,
}

impl RunOptions<'_> {
    /// The integrator of the `solver` mapping ([`solver_from`]), then the span and the output
    /// times (`t_eval` or every `dt_out`), converted in that order.
    pub fn integration(&self) -> PyResult<(Method, Output)> {
        let method = solver_from(&self.solver)?;
        let (t0, t1) = self.span;
        crate::numerics::integrate::check_span(t0, t1)?;
        let out = match (&self.t_eval, self.dt_out) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "dt_out",
                    "given",
                    "give t_eval or dt_out, not both",
                ))
            }
            (Some(ts), None) => Output::Times(ts.as_array().to_vec()),
            (None, Some(dt)) => Output::Every(dt),
            (None, None) => return Err(invalid("dt_out", "None", "t_eval or dt_out is required")),
        };
        out.sample_times(t0, t1)?;
        Ok((method, out))
    }

    /// The transient's settings: [`RunOptions::integration`], then with `watch` the limit
    /// ([`RunOptions::watch`]; without, none: a system with no θ), converted in that order.
    pub fn transient(&self, watch: bool) -> PyResult<TransientSettings> {
        let (method, output) = self.integration()?;
        let limit = if watch { self.watch()? } else { None };
        Ok(TransientSettings {
            method,
            span: self.span,
            output,
            y0: self.y0.clone(),
            limit,
        })
    }

    /// The validity limit the run watches (None without a `limit` entry, or with "ignore").
    pub fn watch(&self) -> PyResult<Option<crate::runs::simulate::OnLimit>> {
        match &self.limit {
            Some(l) => on_limit(l.theta_limit, &l.on_limit),
            None => Ok(None),
        }
    }
}

/// A run's step counters into `d`, under the names every run's result uses.
pub fn set_counters(d: &Bound<'_, PyDict>, stats: &Stats) -> PyResult<()> {
    d.set_item(intern!(d.py(), "n_steps"), stats.n_steps)?;
    d.set_item(intern!(d.py(), "n_rejected"), stats.n_rejected)?;
    d.set_item(intern!(d.py(), "n_rhs"), stats.n_rhs)
}

/// The integrator settings as a solver mapping (what [`solver_from`] reads): the engine's
/// defaults, and the settings a run used.
pub fn solver_dict<'py>(py: Python<'py>, method: &Method) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let tol = match method {
        Method::Rk4 { dt } => {
            d.set_item("method", "rk4")?;
            d.set_item("dt", *dt)?;
            Tolerances::default()
        }
        Method::Dopri5(tol) => {
            d.set_item("method", "rk45")?;
            d.set_item("dt", py.None())?;
            *tol
        }
    };
    d.set_item("rtol", tol.rtol)?;
    d.set_item("atol", tol.atol)?;
    d.set_item("max_step", tol.max_step)?;
    d.set_item("max_steps", tol.max_steps)?;
    Ok(d)
}
