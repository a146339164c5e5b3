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

use crate::error::{Error, Result};
use crate::inputs::attitude::Attitude;
use crate::inputs::orbit::sign_change_bracket;
use crate::inputs::orbit::{Frame, Orbit};
use crate::inputs::panel::Panel;
use crate::numerics::vector::{cross, dot, norm};
use std::f64::consts::{FRAC_1_PI, PI};

/// View factor from a flat plate to a sphere: `cos_lambda` the cosine of the angle between the
/// plate's normal and the direction to the sphere's centre, `h` = distance / sphere radius > 1.
///
/// Full view (λ ≤ acos(1/H)): F = cos λ / H². No view (λ ≥ π/2 + asin(1/H)): F = 0. In between
/// (the plate's plane cuts the sphere), with x = sqrt(H² − 1):
/// F = 1/2 − asin(x / (H sin λ))/π + [cos λ acos(−x cot λ) − x sqrt(1 − H² cos²λ)] / (π H²).
pub fn earth_view_factor(cos_lambda: f64, h: f64) -> f64 {
    EarthView::new(h).factors(cos_lambda).0
}

/// The sphere seen from H = distance / radius: the constants of [`earth_view_factor`] that do
/// not depend on the plate's angle, computed once for an orbit's many loads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EarthView {
    h: f64,
    h2: f64,
    /// x = sqrt(H² − 1), x / H and 1/(π H²).
    x: f64,
    x_over_h: f64,
    per_pi_h2: f64,
}

impl EarthView {
    pub fn new(h: f64) -> Self {
        let h2 = h * h;
        let x = (h2 - 1.0).sqrt();
        EarthView {
            h,
            h2,
            x,
            x_over_h: x / h,
            per_pi_h2: 1.0 / (PI * h2),
        }
    }

    /// The view factors of a plate's two faces, the front's normal at `cos_lambda` to the
    /// direction of the sphere: (front, back). Where the plate's plane cuts the sphere both
    /// faces share the arcsine, and the back's arccosine is π less the front's.
    pub fn factors(&self, cos_lambda: f64) -> (f64, f64) {
        let c = cos_lambda.clamp(-1.0, 1.0);
        let (h, h2, x) = (self.h, self.h2, self.x);
        if c * h >= 1.0 {
            return (c / h2, 0.0);
        }
        if c * h <= -1.0 {
            return (0.0, -c / h2);
        }
        // sin λ > 0 here: |cos λ| < 1/H < 1.
        let per_sin = 1.0 / (1.0 - c * c).sqrt();
        let first = 0.5 - (self.x_over_h * per_sin).min(1.0).asin() * FRAC_1_PI;
        let arc = (-x * c * per_sin).clamp(-1.0, 1.0).acos();
        let chord = x * (1.0 - h2 * c * c).max(0.0).sqrt();
        let front = first + (c * arc - chord) * self.per_pi_h2;
        let back = first + (-c * (PI - arc) - chord) * self.per_pi_h2;
        (front.max(0.0), back.max(0.0))
    }
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

impl FaceFluxes {
    /// What the faces absorb of these fluxes with `optics`: the front's sunlight as a flux factor
    /// (the paper's form), the rest in W/m².
    pub fn absorbed(&self, optics: &Optics) -> Loads {
        Loads {
            sun: self.sun_front / optics.solar_constant,
            front: optics.absorptivity_front * self.albedo_front
                + optics.emissivity_front * self.ir_front,
            back: optics.absorptivity_back * (self.sun_back + self.albedo_back)
                + optics.emissivity_back * self.ir_back,
        }
    }
}

/// What heats a flat face at one time, before its orientation (see [`Orbit::sources`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sources {
    /// Unit vectors to the Sun and to the satellite from the Earth's centre.
    pub sun: [f64; 3],
    pub position: [f64; 3],
    /// C · scale · s, W/m².
    pub direct: f64,
    /// a · C · scale · max(cos Z, 0), W/m² (times a face's view factor: its albedo).
    pub albedo: f64,
    /// E_IR, W/m².
    pub earth_ir: f64,
    /// The Earth seen from the orbit (H = r/R_E).
    pub earth: EarthView,
}

impl Sources {
    /// The incident fluxes on the faces of a plate whose front normal is `normal` (unit); the
    /// front exactly on the Sun when `on_sun` (the paper's plate, its incidence exactly 0).
    pub fn fluxes(&self, normal: [f64; 3], on_sun: bool) -> FaceFluxes {
        let cos_sun = if on_sun {
            1.0
        } else {
            dot(normal, self.sun).clamp(-1.0, 1.0)
        };
        // The direction to the Earth's centre is −position.
        let cos_front = -dot(normal, self.position);
        let (view_front, view_back) = self.earth.factors(cos_front);
        FaceFluxes {
            sun_front: self.direct * cos_sun.max(0.0),
            sun_back: self.direct * (-cos_sun).max(0.0),
            albedo_front: self.albedo * view_front,
            albedo_back: self.albedo * view_back,
            ir_front: self.earth_ir * view_front,
            ir_back: self.earth_ir * view_back,
        }
    }
}

/// The geometry of one time: the unit vectors to the Sun and to the satellite (from the Earth's
/// centre) and the front normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    pub sun: [f64; 3],
    pub position: [f64; 3],
    pub normal: [f64; 3],
    /// The Sun's flux there relative to 1 au ([`Orbit::flux_scale`]).
    pub flux_scale: f64,
}

impl Orbit {
    /// Whether the panel is heated by more than sunlight on a Sun-pointing front: Earth
    /// infrared, albedo, or an attitude other than Sun-pointing. False on the paper's presets,
    /// whose runs keep their own arithmetic.
    #[inline]
    pub fn has_face_loads(&self) -> bool {
        self.albedo != 0.0 || self.earth_ir != 0.0 || self.attitude != Attitude::SunPointing
    }

    /// The Earth seen from the orbit: the view factors' constants at H = r/R_E, computed once
    /// for a run's many loads.
    pub fn earth_view(&self) -> EarthView {
        EarthView::new(self.radius / self.earth_radius)
    }

    /// The front normal at time t, with the Sun's and the satellite's directions.
    pub fn geometry(&self, t: f64) -> Geometry {
        self.geometry_in(&self.frame(), t)
    }

    /// [`Orbit::geometry`] with the orbit's constants from `frame`.
    pub fn geometry_in(&self, frame: &Frame, t: f64) -> Geometry {
        let sun = self.sun_direction_in(frame, t);
        let position = self.position_in(frame, t);
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
            flux_scale: self.flux_scale_in(frame, t),
        }
    }

    /// Incident fluxes on each face at time t for the illuminated fraction `s` of the Sun and a
    /// solar constant C (W/m²), before the structure's area factor.
    pub fn face_fluxes(&self, t: f64, s: f64, solar_constant: f64) -> FaceFluxes {
        self.face_fluxes_of(&self.geometry(t), s, solar_constant, &self.earth_view())
    }

    /// [`Orbit::face_fluxes`] of the geometry `g` of a time ([`Orbit::geometry_in`]).
    pub fn face_fluxes_of(
        &self,
        g: &Geometry,
        s: f64,
        solar_constant: f64,
        earth: &EarthView,
    ) -> FaceFluxes {
        self.sources(g, s, solar_constant, earth)
            .fluxes(g.normal, self.attitude == Attitude::SunPointing)
    }

    /// What heats a flat face at the time of the geometry `g`, whatever its normal: the Sun's
    /// and the satellite's directions, the direct sunlight C · scale · s, the albedo's
    /// sunlit-Earth factor a · C · scale · max(cos Z, 0), the Earth's infrared and the Earth
    /// seen from the orbit (`earth`, [`Orbit::earth_view`]).
    pub fn sources(&self, g: &Geometry, s: f64, solar_constant: f64, earth: &EarthView) -> Sources {
        let sunlight = solar_constant * g.flux_scale;
        Sources {
            sun: g.sun,
            position: g.position,
            direct: sunlight * s,
            albedo: self.albedo * sunlight * dot(g.position, g.sun).max(0.0),
            earth_ir: self.earth_ir,
            earth: *earth,
        }
    }

    /// The loads the thermal models absorb at time t for the illuminated fraction `s`: the
    /// front's sunlight as a flux factor (the paper's form) and the rest absorbed, W/m².
    pub fn loads(&self, t: f64, s: f64, optics: &Optics) -> Loads {
        self.face_fluxes(t, s, optics.solar_constant)
            .absorbed(optics)
    }

    /// The loads at the time of the geometry `g` ([`Orbit::geometry_in`]) for the
    /// illuminated fraction `s`: [`Orbit::loads`] without computing the geometry again.
    pub fn loads_of(&self, g: &Geometry, s: f64, optics: &Optics, earth: &EarthView) -> Loads {
        self.face_fluxes_of(g, s, optics.solar_constant, earth)
            .absorbed(optics)
    }

    /// The direction of the panel's length at time t (unit, in the plane of its faces): about
    /// which a bent panel's elements turn. Taken in the plane of the front normal and the orbit
    /// normal h, as the wing of an array that tracks the Sun about h lies along its drive axis
    /// (there the Sun stays in the plane of the normal and the length); with the normal on h,
    /// the direction a quarter orbit past the node.
    pub fn length_direction(&self, t: f64, normal: [f64; 3]) -> [f64; 3] {
        let along_plane = |d: [f64; 3]| {
            let c = dot(d, normal);
            let p = [0, 1, 2].map(|k| d[k] - c * normal[k]);
            let l = norm(p);
            (l > 1e-9).then(|| p.map(|x| x / l))
        };
        let h = self.normal(t);
        // With the normal on h, h × (the node) is a unit vector in the faces' plane.
        along_plane(h).unwrap_or_else(|| cross(h, self.node_direction(t)))
    }

    /// Every load at time t in full sunlight (s = 1), absorbed with `optics`: the front's
    /// sunlight alone, at the Sun's distance there, on an orbit without Earth heating or
    /// attitude (the paper's arithmetic).
    pub fn sunlit_loads(&self, t: f64, optics: &Optics) -> Loads {
        if self.has_face_loads() {
            self.loads(t, 1.0, optics)
        } else {
            Loads::sun(self.flux_scale(t))
        }
    }

    /// Every load at time t in the Sun's illuminated fraction there, as a run's samples read
    /// the state: on an orbit without Earth heating or attitude, the front's sunlight alone,
    /// s × flux scale.
    pub fn loads_at(&self, t: f64, optics: &Optics) -> Loads {
        let s = self.illumination(t);
        if self.has_face_loads() {
            self.loads(t, s, optics)
        } else {
            Loads::sun(s * self.flux_scale(t))
        }
    }

    /// The flux reaching the front and the back face at each of the times `t`, W/m² (in the
    /// Sun's illuminated fraction there, the structure's area factor not applied).
    pub fn face_flux_samples(&self, t: &[f64], solar_constant: f64) -> (Vec<f64>, Vec<f64>) {
        t.iter()
            .map(|&t| {
                let f = self.face_fluxes(t, self.illumination(t), solar_constant);
                (f.front(), f.back())
            })
            .unzip()
    }
}

/// Where `f` changes sign in (lo, hi), `low` whether f(lo) > 0 (f(hi) on the other side): bisection
/// until the bracket is at most `rel` max(|hi|, 1) wide (0: two adjacent floats), its middle.
///
/// Those bits at a fraction of the evaluations: the sign change is first bracketed tightly by
/// regula falsi ([`sign_change_bracket`]), and a bisection point outside that bracket takes
/// the sign of its side (f changes sign once in (lo, hi)), one inside evaluates f.
fn sign_change(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, low: bool, rel: f64) -> f64 {
    // Negative exactly where the bisection keeps lo: f > 0 when `low`, else f ≤ 0.
    let on_lo = |t: f64| {
        let v = f(t);
        if low {
            -v
        } else if v <= 0.0 {
            v.min(-f64::MIN_POSITIVE)
        } else {
            v
        }
    };
    // Half the bisection's last width: the bisection then evaluates once or twice inside.
    let (neg, pos) = sign_change_bracket(&on_lo, lo, hi, 0.5 * rel * hi.abs().max(1.0));
    while hi - lo > rel * hi.abs().max(1.0) {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let keeps_lo = if mid < neg {
            true
        } else if mid > pos {
            false
        } else {
            on_lo(mid) < 0.0
        };
        if keeps_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Subintervals of the sunlit-arc average per orbit period. The loads are smooth on each piece
/// between their kinks — where the Sun crosses a face's plane (max(±n·Ŝ, 0)) and where the
/// sub-satellite point crosses the terminator (the albedo's max(cos Z, 0)), which are found and
/// split at — but for the view factor's edges of full view, where its second derivative jumps
/// (an O(h³) error of the subinterval there: a relative ~1e-10 of the average).
const AVERAGE_SUBINTERVALS: f64 = 2000.0;

impl Orbit {
    /// The times in (x0, x1) where a load has a kink — the Sun crossing the faces' plane, the
    /// sub-satellite point crossing the terminator — each where its cosine changes sign between
    /// the ends (the interval is short against the orbit: at most one crossing of each), found
    /// by bisection to 1e-12 of t; sorted.
    fn kinks(&self, x0: f64, x1: f64) -> Vec<f64> {
        self.crossings(&self.kink_functions(false), x0, x1, 1, 1e-12)
    }

    /// The times in (x0, x1) where a load is not smooth: its kinks ([`Orbit::kinks`]) and where a
    /// face's view of the Earth becomes full (cos λ H = ±1, λ the front normal's angle to the
    /// nadir: the view factor's partial branch starts there like a power 3/2). Each is searched
    /// on pieces of at most `span` s, found where its function changes sign between a piece's
    /// ends (two crossings inside one piece are not found: a table fitted across them refuses
    /// that part), to the rounding of t; sorted.
    pub(crate) fn load_kinks(&self, x0: f64, x1: f64, span: f64) -> Vec<f64> {
        let pieces = ((x1 - x0) / span).ceil().max(1.0) as usize;
        self.crossings(&self.kink_functions(true), x0, x1, pieces, 0.0)
    }

    /// The functions of the geometry (and H = r/R_E) whose sign changes are the loads' kinks:
    /// the Sun crossing a face's plane (an attitude other than Sun-pointing), the sub-satellite
    /// point crossing the terminator (albedo) and, with `edges`, a face's view of the Earth
    /// becoming full.
    fn kink_functions(&self, edges: bool) -> Vec<fn(&Geometry, f64) -> f64> {
        let mut out: Vec<fn(&Geometry, f64) -> f64> = Vec::new();
        if edges {
            out.push(|g, h| -dot(g.normal, g.position) * h - 1.0);
            out.push(|g, h| -dot(g.normal, g.position) * h + 1.0);
        }
        if self.attitude != Attitude::SunPointing {
            out.push(|g, _| dot(g.normal, g.sun));
        }
        if self.albedo != 0.0 {
            out.push(|g, _| dot(g.position, g.sun));
        }
        out
    }

    /// Where each of `functions` changes sign between the ends of one of `pieces` equal pieces
    /// of (x0, x1), bisected to `rel` of t ([`sign_change`]); sorted.
    fn crossings(
        &self,
        functions: &[fn(&Geometry, f64) -> f64],
        x0: f64,
        x1: f64,
        pieces: usize,
        rel: f64,
    ) -> Vec<f64> {
        if functions.is_empty() {
            return Vec::new();
        }
        let h = self.radius / self.earth_radius;
        let ends: Vec<f64> = (0..=pieces)
            .map(|k| {
                if k == pieces {
                    x1
                } else {
                    x0 + (x1 - x0) * k as f64 / pieces as f64
                }
            })
            .collect();
        let at_ends: Vec<Geometry> = ends.iter().map(|&t| self.geometry(t)).collect();
        let mut out = Vec::new();
        for f in functions {
            for k in 0..pieces {
                let low = f(&at_ends[k], h) > 0.0;
                if low != (f(&at_ends[k + 1], h) > 0.0) {
                    let at = |t: f64| f(&self.geometry(t), h);
                    out.push(sign_change(at, ends[k], ends[k + 1], low, rel));
                }
            }
        }
        out.retain(|&t| t > x0 && t < x1);
        out.sort_by(f64::total_cmp);
        out
    }

    /// The loads averaged over the sunlit arc of the orbit that begins at `t0` (one period):
    /// (1/τ) ∫ loads(t, s(t)) dt over the times with s(t) > 0 (the penumbra's partial Sun
    /// included), τ their total length. On an orbit without Earth heating or attitude, the
    /// front's sunlight alone: the mean of s × flux scale. Composite Gauss–Legendre between the
    /// shadow's breakpoints, split at the loads' kinks ([`AVERAGE_SUBINTERVALS`]).
    pub fn sunlit_average_loads(&self, t0: f64, optics: &Optics) -> Result<Loads> {
        Orbit::check_time(t0)?;
        let t1 = t0 + self.period;
        let mut edges = vec![t0];
        edges.extend(self.breakpoints(t0, t1));
        edges.push(t1);
        let (mut sum, mut duration) = (Loads::sun(0.0), 0.0);
        for w in edges.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b <= a || self.illumination(0.5 * (a + b)) <= 0.0 {
                continue;
            }
            let pieces = ((b - a) / self.period * AVERAGE_SUBINTERVALS)
                .ceil()
                .max(1.0);
            let h = (b - a) / pieces;
            for i in 0..pieces as usize {
                let (x0, x1) = (a + i as f64 * h, a + (i + 1) as f64 * h);
                let mut cuts = vec![x0];
                cuts.extend(self.kinks(x0, x1));
                cuts.push(x1);
                for piece in cuts.windows(2) {
                    let (mid, half) = (0.5 * (piece[0] + piece[1]), 0.5 * (piece[1] - piece[0]));
                    for (x, weight) in crate::numerics::quadrature::GAUSS_5 {
                        let l = self.loads_at(mid + half * x, optics).scaled(half * weight);
                        sum = Loads {
                            sun: sum.sun + l.sun,
                            front: sum.front + l.front,
                            back: sum.back + l.back,
                        };
                    }
                }
            }
            duration += b - a;
        }
        if duration <= 0.0 {
            return Err(Error::invalid(
                "t",
                t0,
                "begins an orbit with no sunlit arc: there is no sunlit forcing to average",
            ));
        }
        Ok(sum.scaled(1.0 / duration))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::orbit::{Shadow, EARTH_RADIUS};
    use std::cell::Cell;

    /// The search for a load's kink gives plain bisection's bits (to adjacent floats, and to
    /// 1e-12 of t) on drawn functions with one sign change, either sign first, flat or steep or
    /// kinked at it, at times up to ten years; and on the kinks of drawn heated inclined orbits
    /// with under a third of its evaluations.
    #[test]
    fn a_kinks_search_is_plain_bisection_to_the_bit() {
        fn plain(f: &dyn Fn(f64) -> f64, mut lo: f64, mut hi: f64, low: bool, rel: f64) -> f64 {
            while hi - lo > rel * f64::abs(hi).max(1.0) {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if (f(mid) > 0.0) == low {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            0.5 * (lo + hi)
        }
        let mut draw = crate::numerics::testing::uniform_draws(7);
        for _ in 0..3000 {
            let c = crate::numerics::testing::DrawnCrossing::draw(&mut draw, 1.0, 60.0);
            let low = draw() < 0.5;
            let f = |t: f64| if low { -c.at(t) } else { c.at(t) };
            let (t0, t1) = (c.t0, c.t0 + c.span);
            for rel in [0.0, 1e-12] {
                let got = sign_change(f, t0, t1, low, rel);
                assert_eq!(got, plain(&f, t0, t1, low, rel), "{t0} {} {rel}", c.root);
            }
        }
        // The kinks of drawn orbits (the faces' edges of full view, the terminator, the Sun on
        // a tracking face's plane) over an orbit, found on the pieces of the tables' search.
        let (calls, plain_calls) = (Cell::new(0_u64), Cell::new(0_u64));
        let mut found = 0;
        for _ in 0..20 {
            let o = Orbit {
                inclination: PI * draw(),
                raan: 2.0 * PI * draw(),
                season: true,
                epoch_day: 365.0 * draw(),
                albedo: 0.3,
                earth_ir: 237.0,
                attitude: if draw() < 0.5 {
                    Attitude::SunPointing
                } else {
                    Attitude::SunTracking {
                        offset: draw() - 0.5,
                    }
                },
                ..Orbit::leo(400e3 + 1000e3 * draw())
            };
            let h = o.radius / o.earth_radius;
            let t0 = 3e8 * draw();
            let span = 60.0;
            for f in o.kink_functions(true) {
                for k in 0..(o.period / span) as usize {
                    let (lo, hi) = (t0 + k as f64 * span, t0 + (k + 1) as f64 * span);
                    let low = f(&o.geometry(lo), h) > 0.0;
                    if low == (f(&o.geometry(hi), h) > 0.0) {
                        continue;
                    }
                    found += 1;
                    let counted = |t: f64| {
                        calls.set(calls.get() + 1);
                        f(&o.geometry(t), h)
                    };
                    let plain_counted = |t: f64| {
                        plain_calls.set(plain_calls.get() + 1);
                        f(&o.geometry(t), h)
                    };
                    let got = sign_change(counted, lo, hi, low, 0.0);
                    assert_eq!(got, plain(&plain_counted, lo, hi, low, 0.0));
                }
            }
        }
        assert!(found > 60, "{found}");
        assert!(
            3 * calls.get() < plain_calls.get(),
            "{} against {}",
            calls.get(),
            plain_calls.get()
        );
    }

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

    /// The two faces' view factors at once are each face's alone: the back's is the front's
    /// formula at the opposite normal (the arcsine shared, the arccosine π less the front's),
    /// on drawn heights and angles, the edges of full view and of no view included.
    #[test]
    fn both_faces_view_factors_are_each_faces_own() {
        let mut draw = crate::numerics::testing::uniform_draws(77);
        for _ in 0..20_000 {
            let h = 1.0 + 1e-3 + 8.0 * draw() * draw();
            let c = match (draw() * 4.0) as u32 {
                0 => 1.0 / h * (1.0 + 1e-9 * (draw() - 0.5)),
                1 => -1.0 / h * (1.0 + 1e-9 * (draw() - 0.5)),
                _ => 2.0 * draw() - 1.0,
            };
            let (front, back) = EarthView::new(h).factors(c);
            assert_eq!(front, earth_view_factor(c, h));
            let alone = earth_view_factor(-c, h);
            assert!(
                (back - alone).abs() <= 1e-15,
                "H {h} cos {c}: {back} vs {alone}"
            );
        }
        for deg in [0.0_f64, 60.0, 95.0, 120.0, 180.0] {
            let lambda = deg.to_radians();
            let back = EarthView::new(1.2).factors(lambda.cos()).1;
            let numeric = view_factor_by_quadrature(PI - lambda, 1.2);
            assert!(
                (back - numeric).abs() < 2e-5,
                "λ {deg}°: {back} vs {numeric}"
            );
        }
    }

    /// The sunlit-arc average against a plain midpoint sum over a fine grid (the sunlit samples
    /// only), on an inclined orbit with its eclipse, Earth heating and a tracking attitude; and
    /// the full Sun alone (the mean of 1) on the paper's orbit with its eclipse.
    #[test]
    fn the_sunlit_average_is_the_mean_over_the_lit_samples() {
        let optics = Optics::of(&Panel::paper());
        let o = Orbit {
            albedo: 0.3,
            earth_ir: 237.0,
            attitude: Attitude::SunTracking { offset: 0.2 },
            shadow: Shadow::Cylindrical,
            ..Orbit::leo(540e3)
        };
        let t0 = 123.0;
        let avg = o.sunlit_average_loads(t0, &optics).unwrap();
        let n = 2_000_000;
        let h = o.period / n as f64;
        let (mut sum, mut lit) = ([0.0; 3], 0usize);
        for i in 0..n {
            let t = t0 + (i as f64 + 0.5) * h;
            if o.illumination(t) > 0.0 {
                let l = o.loads_at(t, &optics);
                sum = [sum[0] + l.sun, sum[1] + l.front, sum[2] + l.back];
                lit += 1;
            }
        }
        let want = sum.map(|x| x / lit as f64);
        // The midpoint sum's error at the two shadow edges: about h/τ.
        for (got, want) in [avg.sun, avg.front, avg.back].iter().zip(want) {
            assert!((got / want - 1.0).abs() < 2e-6, "{got} vs {want}");
        }
        let bare = Orbit {
            shadow: Shadow::Cylindrical,
            ..Orbit::geo_equinox()
        };
        let mean = bare.sunlit_average_loads(0.0, &optics).unwrap();
        assert_eq!((mean.front, mean.back), (0.0, 0.0));
        assert!((mean.sun - 1.0).abs() < 1e-12, "{}", mean.sun);
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
