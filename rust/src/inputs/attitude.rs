//! Where the panel's front face points ([`Attitude`]) and the Earth's heat constants (mean
//! albedo, mean infrared flux and the largest infrared flux accepted). The orbit holds an
//! attitude and checks its Earth infrared against the bound; heating.rs turns both into the
//! front normal and the loads on each face.

use crate::error::{require_finite, Error, Result};
use crate::numerics::vector::norm;
use std::f64::consts::PI;

/// The Earth's mean albedo, the default of `tj.Orbit.circular`.
pub const EARTH_ALBEDO: f64 = 0.30;
/// The Earth's mean infrared flux at its surface, W/m², the default of `tj.Orbit.circular`.
pub const EARTH_IR: f64 = 237.0;

/// Largest Earth infrared flux accepted, W/m² (the Earth emits about 237; a hot planet a few
/// thousand).
pub const MAX_EARTH_IR: f64 = 1e4;

/// Where the panel's front face points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Attitude {
    /// The front normal on the Sun (the paper's plate): the incidence is 0 at all times.
    SunPointing,
    /// A one-axis tracking array: the rotation axis is the orbit normal h and the front normal
    /// lies in the plane of h and the Sun, tilted `offset` (rad) from the orbit plane towards h:
    /// n = cos(offset) Ŝ_p + sin(offset) h, Ŝ_p the Sun's direction projected on the orbit plane.
    /// The incidence is β − offset.
    SunTracking { offset: f64 },
    /// The front normal on the Earth's centre (a boom or antenna held towards the Earth).
    Nadir,
    /// A fixed front normal in the equatorial frame (x: March equinox, z: north pole), unit.
    Inertial { normal: [f64; 3] },
}

impl Attitude {
    /// The attitude's name, as the Python layer and scenario files spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Attitude::SunPointing => "sun_pointing",
            Attitude::SunTracking { .. } => "sun_tracking",
            Attitude::Nadir => "nadir",
            Attitude::Inertial { .. } => "inertial",
        }
    }

    /// An inertial attitude from any non-zero finite vector (normalised here).
    pub fn inertial(normal: [f64; 3]) -> Result<Attitude> {
        let length = norm(normal);
        if !(length.is_finite() && length > 0.0) {
            return Err(Error::invalid(
                "attitude.normal",
                format!("{normal:?}"),
                "must be a finite, non-zero vector",
            ));
        }
        Ok(Attitude::Inertial {
            normal: normal.map(|c| c / length),
        })
    }

    pub fn validate(&self) -> Result<()> {
        match *self {
            Attitude::SunTracking { offset } => {
                require_finite("attitude.offset", offset)?;
                if offset.abs() > 0.5 * PI {
                    return Err(Error::invalid(
                        "attitude.offset",
                        offset,
                        "must be in [-π/2, π/2] rad",
                    ));
                }
                Ok(())
            }
            Attitude::Inertial { normal } => {
                let length = norm(normal);
                if (length - 1.0).abs() > 1e-9 || !length.is_finite() {
                    return Err(Error::invalid(
                        "attitude.normal",
                        format!("{normal:?}"),
                        "must be a unit vector",
                    ));
                }
                Ok(())
            }
            Attitude::SunPointing | Attitude::Nadir => Ok(()),
        }
    }
}
