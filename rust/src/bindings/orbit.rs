//! Bindings of the orbit options: eclipses, umbra, the Sun over the year.

use super::convert::{orbit_from, set_named};
use super::error::shield;
use crate::inputs::orbit::Orbit;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The orbit of `orbit`, with [t0, t1] checked as a span of it.
fn spanned(orbit: &Bound<'_, PyDict>, t0: f64, t1: f64) -> PyResult<Orbit> {
    let o = orbit_from(orbit)?;
    o.check_span(t0, t1)?;
    Ok(o)
}

/// (centre, first contact, last contact, umbra entry, umbra exit), s.
type EclipseRow = (f64, f64, f64, f64, f64);

/// Each eclipse overlapping [t0, t1], unclipped: (centre, first contact, last contact, umbra
/// entry, umbra exit), NaN where there is no umbra.
#[pyfunction]
fn eclipses(orbit: &Bound<'_, PyDict>, t0: f64, t1: f64) -> PyResult<Vec<EclipseRow>> {
    shield(|| {
        Ok(spanned(orbit, t0, t1)?
            .eclipses(t0, t1)
            .iter()
            .map(|e| {
                let (c, d) = e.umbra.unwrap_or((f64::NAN, f64::NAN));
                (e.centre, e.outer.0, e.outer.1, c, d)
            })
            .collect())
    })
}

/// Shadow intervals of an orbit within [t0, t1].
#[pyfunction]
fn shadow_intervals(orbit: &Bound<'_, PyDict>, t0: f64, t1: f64) -> PyResult<Vec<(f64, f64)>> {
    shield(|| Ok(spanned(orbit, t0, t1)?.shadow_intervals(t0, t1)))
}

/// Umbra intervals of an orbit within [t0, t1], clipped.
#[pyfunction]
fn umbra_intervals(orbit: &Bound<'_, PyDict>, t0: f64, t1: f64) -> PyResult<Vec<(f64, f64)>> {
    shield(|| Ok(spanned(orbit, t0, t1)?.umbra_intervals(t0, t1)))
}

/// Times in (t0, t1) where s(t) jumps or has a kink.
#[pyfunction]
fn orbit_breakpoints(orbit: &Bound<'_, PyDict>, t0: f64, t1: f64) -> PyResult<Vec<f64>> {
    shield(|| Ok(spanned(orbit, t0, t1)?.breakpoints(t0, t1)))
}

fn map_times<'py>(
    py: Python<'py>,
    orbit: &Bound<'py, PyDict>,
    t: PyReadonlyArray1<'py, f64>,
    f: impl Fn(&Orbit, f64) -> f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let o = orbit_from(orbit)?;
    let t = t.as_array();
    for &x in t.iter() {
        Orbit::check_time(x)?;
    }
    let v: Vec<f64> = t.iter().map(|&x| f(&o, x)).collect();
    Ok(PyArray1::from_vec(py, v))
}

/// A function of the orbit at each time of an array, as a pyfunction named `$name`.
macro_rules! at_times {
    ($(#[$doc:meta])* $name:ident => $f:path) => {
        $(#[$doc])*
        #[pyfunction]
        fn $name<'py>(
            py: Python<'py>,
            orbit: &Bound<'py, PyDict>,
            t: PyReadonlyArray1<'py, f64>,
        ) -> PyResult<Bound<'py, PyArray1<f64>>> {
            shield(|| map_times(py, orbit, t, $f))
        }
    };
}

at_times!(
    /// Illumination s(t) at each time.
    illumination => Orbit::illumination
);
at_times!(
    /// Solar flux relative to 1 au at each time.
    flux_scale => Orbit::flux_scale
);
at_times!(
    /// The Sun's declination at each time, rad.
    declination => Orbit::declination
);
at_times!(
    /// The Sun's angle to the orbit plane at each time, rad.
    beta => Orbit::beta
);

/// Rate of the ascending node, rad/s (0 without j2).
#[pyfunction]
fn nodal_rate(orbit: &Bound<'_, PyDict>) -> PyResult<f64> {
    shield(|| Ok(orbit_from(orbit)?.nodal_rate()))
}

/// Orbit period relative to the Sun (time between eclipses), s.
#[pyfunction]
fn synodic_period(orbit: &Bound<'_, PyDict>) -> PyResult<f64> {
    shield(|| Ok(orbit_from(orbit)?.synodic_period()))
}

/// Eclipse duration per orbit with the cylindrical shadow and the Sun in the orbit plane, s.
#[pyfunction]
fn eclipse_duration(orbit: &Bound<'_, PyDict>) -> PyResult<f64> {
    shield(|| Ok(orbit_from(orbit)?.eclipse_duration()))
}

/// An orbit as the mapping `orbit_from` reads.
fn orbit_dict<'py>(py: Python<'py>, o: &Orbit) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    set_named!(d, o; fields radius, earth_radius, period, phase0);
    d.set_item("shadow", o.shadow.name())?;
    set_named!(d, o; fields season, eccentric_sun, epoch_day, inclination, raan, j2, albedo,
        earth_ir);
    Ok(d)
}

/// The circular low orbit at `altitude` (m): its radius and Keplerian period.
#[pyfunction]
fn leo_orbit(py: Python<'_>, altitude: f64) -> PyResult<Bound<'_, PyDict>> {
    shield(|| {
        crate::error::require_positive("altitude", altitude)?;
        orbit_dict(py, &Orbit::leo(altitude))
    })
}

/// Adds each named constant to the module `m` under its own name.
macro_rules! add_constants {
    ($m:ident: $($name:ident),+) => {
        $($m.add(stringify!($name), $name)?;)+
    };
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    use crate::inputs::attitude::{EARTH_ALBEDO, EARTH_IR};
    use crate::inputs::orbit::{
        DAY, EARTH_RADIUS, EQUINOX_DAY, GEO_RADIUS, J2, LEO_ALTITUDE, MAX_LEO_ALTITUDE,
        MIN_LEO_ALTITUDE, MU_EARTH, OBLIQUITY, PERIHELION_DAY, SIDEREAL_DAY, YEAR_DAYS,
    };
    add_constants!(m: GEO_RADIUS, LEO_ALTITUDE, MIN_LEO_ALTITUDE, MAX_LEO_ALTITUDE,
        EARTH_RADIUS, SIDEREAL_DAY, MU_EARTH, EQUINOX_DAY, PERIHELION_DAY, J2, OBLIQUITY,
        YEAR_DAYS, DAY, EARTH_ALBEDO, EARTH_IR);
    m.add(
        "GEO_EQUINOX_ORBIT",
        orbit_dict(m.py(), &Orbit::geo_equinox())?,
    )?;
    m.add_function(wrap_pyfunction!(eclipse_duration, m)?)?;
    m.add_function(wrap_pyfunction!(leo_orbit, m)?)?;
    m.add_function(wrap_pyfunction!(eclipses, m)?)?;
    m.add_function(wrap_pyfunction!(shadow_intervals, m)?)?;
    m.add_function(wrap_pyfunction!(illumination, m)?)?;
    m.add_function(wrap_pyfunction!(umbra_intervals, m)?)?;
    m.add_function(wrap_pyfunction!(orbit_breakpoints, m)?)?;
    m.add_function(wrap_pyfunction!(flux_scale, m)?)?;
    m.add_function(wrap_pyfunction!(declination, m)?)?;
    m.add_function(wrap_pyfunction!(beta, m)?)?;
    m.add_function(wrap_pyfunction!(nodal_rate, m)?)?;
    m.add_function(wrap_pyfunction!(synodic_period, m)?)?;
    Ok(())
}
