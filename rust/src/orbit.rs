//! Orbit geometry: orbit phase, the Earth's shadow, the illumination s(t) and the exact shadow
//! entry and exit times.
//!
//! The plate is Sun-pointing, so only the illuminated fraction of the Sun changes along the orbit.
//! Phase β = 2π t / T + β₀, with β = 0 at the subsolar point and the shadow centred on β = π.

use crate::error::{require_finite, require_positive, Error, Result};
use std::f64::consts::PI;

/// GEO radius, m.
pub const GEO_RADIUS: f64 = 42_164_170.0;
/// Equatorial Earth radius, m.
pub const EARTH_RADIUS: f64 = 6_378_137.0;
/// One sidereal day, s.
pub const SIDEREAL_DAY: f64 = 86_164.090_5;

/// A circular orbit with a cylindrical Earth shadow, the Sun in the orbit plane (equinox).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// Orbit radius, m.
    pub radius: f64,
    /// Radius of the shadowing Earth, m.
    pub earth_radius: f64,
    /// Orbit period, s.
    pub period: f64,
    /// Orbit phase at t = 0, rad (0: at the subsolar point).
    pub phase0: f64,
}

impl Orbit {
    /// The paper's scenario: GEO at equinox, cylindrical shadow, t = 0 at the subsolar point.
    pub fn geo_equinox() -> Self {
        Orbit {
            radius: GEO_RADIUS,
            earth_radius: EARTH_RADIUS,
            period: SIDEREAL_DAY,
            phase0: 0.0,
        }
    }

    pub fn validate(&self) -> Result<()> {
        require_positive("radius", self.radius)?;
        require_positive("earth_radius", self.earth_radius)?;
        require_positive("period", self.period)?;
        require_finite("phase0", self.phase0)?;
        if self.earth_radius >= self.radius {
            return Err(Error::invalid(
                "earth_radius",
                self.earth_radius,
                "must be smaller than the orbit radius",
            ));
        }
        Ok(())
    }

    /// Half the orbit arc spent in shadow, asin(R_E / r), rad.
    pub fn shadow_half_angle(&self) -> f64 {
        (self.earth_radius / self.radius).asin()
    }

    /// Eclipse duration per orbit, s.
    pub fn eclipse_duration(&self) -> f64 {
        self.period * self.shadow_half_angle() / PI
    }

    /// Time of the k-th shadow centre (β = π + 2πk), s.
    fn shadow_centre(&self, k: f64) -> f64 {
        (PI + 2.0 * PI * k - self.phase0) * self.period / (2.0 * PI)
    }

    /// Every eclipse (t_enter, t_exit) overlapping [t0, t1], clipped to it, in time order.
    pub fn shadow_intervals(&self, t0: f64, t1: f64) -> Vec<(f64, f64)> {
        let half = 0.5 * self.eclipse_duration();
        let k_first = ((t0 + half) * 2.0 * PI / self.period + self.phase0 - PI) / (2.0 * PI);
        let mut k = k_first.floor() - 1.0;
        let mut out = Vec::new();
        loop {
            let c = self.shadow_centre(k);
            let (enter, exit) = (c - half, c + half);
            if enter >= t1 {
                break;
            }
            if exit > t0 {
                out.push((enter.max(t0), exit.min(t1)));
            }
            k += 1.0;
        }
        out
    }

    /// Times in (t0, t1) where s(t) jumps: the shadow entries and exits, sorted.
    pub fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        let mut out = Vec::new();
        for (enter, exit) in self.shadow_intervals(t0, t1) {
            for t in [enter, exit] {
                if t > t0 && t < t1 {
                    out.push(t);
                }
            }
        }
        out
    }

    /// Illuminated fraction of the Sun seen from the plate at time t: 1 in sunlight, 0 in umbra.
    pub fn illumination(&self, t: f64) -> f64 {
        let beta = 2.0 * PI * t / self.period + self.phase0;
        let from_anti_sun = (beta - PI).rem_euclid(2.0 * PI);
        let dist = from_anti_sun.min(2.0 * PI - from_anti_sun);
        if dist < self.shadow_half_angle() {
            0.0
        } else {
            1.0
        }
    }

    /// Illumination to use inside the segment [a, b] between two breakpoints. s(t) is constant
    /// there, so it is taken at the midpoint: this gives the right one-sided value at the ends,
    /// where the integrator evaluates the right-hand side exactly on a discontinuity.
    pub fn illumination_on(&self, _t: f64, a: f64, b: f64) -> f64 {
        self.illumination(0.5 * (a + b))
    }

    /// Solar flux relative to the nominal solar constant at time t (1 at 1 au).
    pub fn flux_scale(&self, _t: f64) -> f64 {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geo_eclipse_is_about_seventy_minutes() {
        let o = Orbit::geo_equinox();
        let minutes = o.eclipse_duration() / 60.0;
        assert!((minutes - 69.4).abs() < 0.1, "{minutes}");
    }

    #[test]
    fn shadow_intervals_are_centred_on_half_orbits_with_analytic_length() {
        let o = Orbit::geo_equinox();
        let iv = o.shadow_intervals(0.0, 3.0 * o.period);
        assert_eq!(iv.len(), 3);
        for (k, (a, b)) in iv.iter().enumerate() {
            let centre = (k as f64 + 0.5) * o.period;
            assert!(((a + b) / 2.0 - centre).abs() < 1e-6);
            assert!((b - a - o.eclipse_duration()).abs() < 1e-6);
            assert_eq!(o.illumination(centre), 0.0);
            assert_eq!(o.illumination(a - 1e-3), 1.0);
            assert_eq!(o.illumination(b + 1e-3), 1.0);
            assert_eq!(o.illumination(a + 1e-3), 0.0);
        }
    }

    #[test]
    fn intervals_are_clipped_to_the_span() {
        let o = Orbit::geo_equinox();
        let mid = 0.5 * o.period;
        let iv = o.shadow_intervals(mid, mid + 10.0);
        assert_eq!(iv, vec![(mid, mid + 10.0)]);
        assert!(o.breakpoints(mid, mid + 10.0).is_empty());
        assert!(o.shadow_intervals(0.0, 1000.0).is_empty());
        // negative times and a phase offset
        let shifted = Orbit { phase0: PI, ..o };
        let iv = shifted.shadow_intervals(-10.0, 10.0);
        assert_eq!(iv.len(), 1);
        assert!(iv[0].0 == -10.0 && iv[0].1 == 10.0);
    }

    #[test]
    fn validation_names_the_parameter() {
        let mut o = Orbit::geo_equinox();
        o.radius = 1.0;
        assert!(o
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("earth_radius"));
        o.period = f64::NAN;
        assert!(o.validate().unwrap_err().to_string().starts_with("period"));
    }
}
