//! Heat from the Earth and the panel's attitude: where the panel's front face points, the view
//! factor of each face to the Earth, and the loads each face absorbs.
//!
//! The panel's front normal n is set by its [`Attitude`] (inputs/attitude.rs); the back face's normal is −n. Each face
//! receives, per unit area:
//!
//! - direct sunlight C · scale · s · max(±n·Ŝ, 0) (Ŝ the unit vector to the Sun, s the
//!   illuminated fraction of the Sun, scale the 1/r² of the Sun's distance), absorbed with that
//!   face's solar absorptivity;
//! - Earth infrared E_IR · F, absorbed with that face's emissivity;
//! - albedo a · C · scale · max(cos Z, 0) · F, absorbed with that face's solar absorptivity.
//!
//! F is the view factor of a flat plate to a sphere ([`earth_view_factor`]), with H = r/R_E and λ
//! the angle between the face's normal and the direction to the Earth's centre. The albedo is
//! approximated by the sunlight reflected at the sub-satellite point: Z is the Sun's zenith
//! angle there (cos Z = r̂·Ŝ), so the albedo is zero while the point below the panel is on the
//! Earth's night side and the Earth is taken as a Lambertian reflector lit uniformly as that
//! point is. This is the usual engineering estimate; it is exact for a nadir face far from the
//! terminator and overstates the albedo near it (parts of the visible Earth are darker).
//!
//! The structure's deflection scales every load by its projected-area factor (cos θ for the
//! hinge: the two halves tilt by ±θ about the hinge line, so the mean of their projected areas
//! along any direction d is cos θ times the flat panel's, exactly for the Sun's parallel rays;
//! for the Earth's diffuse loads this is exact while the Earth is in full view and an
//! approximation beyond).

use crate::inputs::attitude::Attitude;
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::numerics::vector::{cross, dot, norm};
use std::f64::consts::PI;

/// View factor from a flat plate to a sphere: `cos_lambda` the cosine of the angle between the
/// plate's normal and the direction to the sphere's centre, `h` = distance / sphere radius > 1.
///
/// Full view (λ ≤ acos(1/H)): F = cos λ / H². No view (λ ≥ π/2 + asin(1/H)): F = 0. In between
/// (the plate's plane cuts the sphere), with x = sqrt(H² − 1):
/// F = 1/2 − asin(x / (H sin λ))/π + [cos λ acos(−x cot λ) − x sqrt(1 − H² cos²λ)] / (π H²).
pub fn earth_view_factor(cos_lambda: f64, h: f64) -> f64 {
    let c = cos_lambda.clamp(-1.0, 1.0);
    let h2 = h * h;
    if c * h >= 1.0 {
        return c / h2;
    }
    if c * h <= -1.0 {
        return 0.0;
    }
    let x = (h2 - 1.0).sqrt();
    let s = (1.0 - c * c).sqrt();
    // s > 0 here: |c| < 1/H < 1.
    let first = 0.5 - (x / (h * s)).min(1.0).asin() / PI;
    let cot = c / s;
    let second = (c * (-x * cot).clamp(-1.0, 1.0).acos() - x * (1.0 - h2 * c * c).max(0.0).sqrt())
        / (PI * h2);
    (first + second).max(0.0)
}

/// The panel's optical properties that turn incident fluxes into absorbed ones.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Optics {
    pub absorptivity_front: f64,
    pub absorptivity_back: f64,
    pub emissivity_front: f64,
    pub emissivity_back: f64,
    /// C, W/m².
    pub solar_constant: f64,
}

impl Optics {
    pub fn of(panel: &Panel) -> Self {
        Optics {
            absorptivity_front: panel.absorptivity,
            absorptivity_back: panel.absorptivity_back,
            emissivity_front: panel.emissivity_front,
            emissivity_back: panel.emissivity_back,
            solar_constant: panel.solar_constant,
        }
    }
}

/// What the thermal models absorb at one time, before the structure's area factor: `sun` the
/// front's solar flux factor (the absorbed power is α C · sun, the paper's form), `front` and
/// `back` the further absorbed loads on each face, W/m² (the Earth's loads, and sunlight on the
/// back face).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Loads {
    pub sun: f64,
    pub front: f64,
    pub back: f64,
}

impl Loads {
    /// Sunlight on the front only: the paper's load.
    pub fn sun(flux: f64) -> Self {
        Loads {
            sun: flux,
            front: 0.0,
            back: 0.0,
        }
    }

    /// Whether a face holds more than the front's sunlight.
    #[inline]
    pub fn has_face_loads(&self) -> bool {
        self.front != 0.0 || self.back != 0.0
    }

    /// Every load times `factor` (the structure's projected-area factor).
    #[inline]
    pub fn scaled(&self, factor: f64) -> Self {
        Loads {
            sun: self.sun * factor,
            front: self.front * factor,
            back: self.back * factor,
        }
    }

    /// The solar flux factor that would heat the front by as much as all the loads together:
    /// where the steady-state search starts.
    pub fn equivalent_flux(&self, optics: &Optics) -> f64 {
        self.sun + (self.front + self.back) / (optics.absorptivity_front * optics.solar_constant)
    }
}

/// The incident fluxes on each face at one time, by source, W/m².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceFluxes {
    /// Direct sunlight on the front and on the back.
    pub sun_front: f64,
    pub sun_back: f64,
    /// Albedo on the front and on the back.
    pub albedo_front: f64,
    pub albedo_back: f64,
    /// Earth infrared on the front and on the back.
    pub ir_front: f64,
    pub ir_back: f64,
}

impl FaceFluxes {
    /// Everything reaching the front face, W/m².
    pub fn front(&self) -> f64 {
        self.sun_front + self.albedo_front + self.ir_front
    }

    /// Everything reaching the back face, W/m².
    pub fn back(&self) -> f64 {
        self.sun_back + self.albedo_back + self.ir_back
    }
}

/// The geometry of one time: the unit vectors to the Sun and to the satellite (from the Earth's
/// centre) and the front normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    pub sun: [f64; 3],
    pub position: [f64; 3],
    pub normal: [f64; 3],
}

impl Orbit {
    /// Whether the panel is heated by more than sunlight on a Sun-pointing front: Earth
    /// infrared, albedo, or an attitude other than Sun-pointing. False on the paper's presets,
    /// whose runs keep their own arithmetic.
    #[inline]
    pub fn has_face_loads(&self) -> bool {
        self.albedo != 0.0 || self.earth_ir != 0.0 || self.attitude != Attitude::SunPointing
    }

    /// The front normal at time t, with the Sun's and the satellite's directions.
    pub fn geometry(&self, t: f64) -> Geometry {
        let sun = self.sun_direction(t);
        let position = self.position(t);
        let normal = match self.attitude {
            Attitude::SunPointing => sun,
            Attitude::Nadir => position.map(|c| -c),
            Attitude::Inertial { normal } => normal,
            Attitude::SunTracking { offset } => {
                let h = self.normal(t);
                let along = dot(sun, h);
                let projected = [0, 1, 2].map(|k| sun[k] - along * h[k]);
                let length = norm(projected);
                // With the Sun on the orbit normal (|β| = 90°) every direction of the plane is
                // as good: the one a quarter orbit past the node.
                let p = if length > 1e-12 {
                    projected.map(|c| c / length)
                } else {
                    cross(h, self.node_direction(t))
                };
                let (so, co) = offset.sin_cos();
                [0, 1, 2].map(|k| co * p[k] + so * h[k])
            }
        };
        Geometry {
            sun,
            position,
            normal,
        }
    }

    /// Incident fluxes on each face at time t for the illuminated fraction `s` of the Sun and a
    /// solar constant C (W/m²), before the structure's area factor.
    pub fn face_fluxes(&self, t: f64, s: f64, solar_constant: f64) -> FaceFluxes {
        let g = self.geometry(t);
        let cos_sun = match self.attitude {
            // Exactly 1: the paper's plate.
            Attitude::SunPointing => 1.0,
            _ => dot(g.normal, g.sun).clamp(-1.0, 1.0),
        };
        let sunlight = solar_constant * self.flux_scale(t);
        let direct = sunlight * s;
        let h = self.radius / self.earth_radius;
        // The direction to the Earth's centre is −position.
        let cos_front = -dot(g.normal, g.position);
        let (view_front, view_back) = (
            earth_view_factor(cos_front, h),
            earth_view_factor(-cos_front, h),
        );
        let lit = self.albedo * sunlight * dot(g.position, g.sun).max(0.0);
        FaceFluxes {
            sun_front: direct * cos_sun.max(0.0),
            sun_back: direct * (-cos_sun).max(0.0),
            albedo_front: lit * view_front,
            albedo_back: lit * view_back,
            ir_front: self.earth_ir * view_front,
            ir_back: self.earth_ir * view_back,
        }
    }

    /// The loads the thermal models absorb at time t for the illuminated fraction `s`: the
    /// front's sunlight as a flux factor (the paper's form) and the rest absorbed, W/m².
    pub fn loads(&self, t: f64, s: f64, optics: &Optics) -> Loads {
        let f = self.face_fluxes(t, s, optics.solar_constant);
        Loads {
            sun: f.sun_front / optics.solar_constant,
            front: optics.absorptivity_front * f.albedo_front
                + optics.emissivity_front * f.ir_front,
            back: optics.absorptivity_back * (f.sun_back + f.albedo_back)
                + optics.emissivity_back * f.ir_back,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::orbit::{Shadow, EARTH_RADIUS};

    /// The view factor by integrating cos over the Earth's disk of directions (midpoint rule in
    /// polar angles about the nadir): an independent check of the closed forms.
    fn view_factor_by_quadrature(lambda: f64, h: f64) -> f64 {
        let rho = (1.0 / h).asin();
        let (na, nb) = (400, 800);
        let mut sum = 0.0;
        for i in 0..na {
            let a = (i as f64 + 0.5) * rho / na as f64;
            for j in 0..nb {
                let b = (j as f64 + 0.5) * 2.0 * PI / nb as f64;
                // Direction at angle a from the nadir (z), azimuth b; the normal is tilted λ
                // from z towards x.
                let d = [a.sin() * b.cos(), a.sin() * b.sin(), a.cos()];
                let c = d[0] * lambda.sin() + d[2] * lambda.cos();
                sum += c.max(0.0) * a.sin();
            }
        }
        sum * (rho / na as f64) * (2.0 * PI / nb as f64) / PI
    }

    #[test]
    fn the_view_factor_is_the_integral_over_the_earth() {
        for h in [1.08, 1.5, 6.61] {
            for deg in [0.0_f64, 20.0, 60.0, 80.0, 90.0, 100.0, 110.0, 130.0, 180.0] {
                let lambda = deg.to_radians();
                let closed = earth_view_factor(lambda.cos(), h);
                let numeric = view_factor_by_quadrature(lambda, h);
                assert!(
                    (closed - numeric).abs() < 2e-5,
                    "H {h} λ {deg}°: {closed} vs {numeric}"
                );
            }
            // Continuous where the full view ends.
            let edge = 1.0 / h;
            let (a, b) = (
                earth_view_factor(edge + 1e-12, h),
                earth_view_factor(edge - 1e-12, h),
            );
            assert!((a - b).abs() < 1e-9, "{a} {b}");
        }
    }

    #[test]
    fn a_nadir_face_sees_the_earth_and_the_other_face_does_not() {
        let o = Orbit {
            albedo: 0.3,
            earth_ir: 237.0,
            attitude: Attitude::Nadir,
            shadow: Shadow::None,
            ..Orbit::leo(540e3)
        };
        let h = o.radius / EARTH_RADIUS;
        // t = 0 at the subsolar point: the front sees the lit Earth, the back the Sun.
        let f = o.face_fluxes(0.0, 1.0, 1361.0);
        assert!((f.ir_front - 237.0 / (h * h)).abs() < 1e-12);
        assert!((f.albedo_front - 0.3 * 1361.0 / (h * h)).abs() < 1e-9);
        assert_eq!((f.ir_back, f.albedo_back, f.sun_front), (0.0, 0.0, 0.0));
        assert!((f.sun_back - 1361.0).abs() < 1e-9);
        // Half an orbit on: over the night side, infrared and no albedo.
        let night = o.face_fluxes(0.5 * o.period, 0.0, 1361.0);
        assert!(night.ir_front > 200.0 / (h * h) && night.albedo_front == 0.0);
    }
}
