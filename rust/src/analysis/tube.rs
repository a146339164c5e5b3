//! The boom's thermal flutter: the linear stability of its sunlit steady state (`models::tube`)
//! and the damping ratio of the first mode at which it is neutral.

use crate::analysis::flutter::{analyse_system, critical_value, Spectrum};
use crate::error::Result;
use crate::inputs::boom::Boom;
use crate::inputs::orbit::Orbit;
use crate::models::coupled::Coupling;
use crate::models::tube::boom_system;
use nalgebra::DMatrix;

/// The boom's linear stability at its steady state under `flux`.
#[derive(Debug, Clone, PartialEq)]
pub struct BoomFlutter {
    /// (T̄, T_m, θ, θ̇) at the steady state.
    pub equilibrium: [f64; 4],
    /// ∂f/∂y there (central differences).
    pub jacobian: DMatrix<f64>,
    pub spectrum: Spectrum,
    /// The damping ratio ζ at which the growth rate crosses zero (0: stable undamped).
    pub critical_damping_ratio: f64,
}

/// Growth rate and spectrum of `boom` at its steady state under `flux`.
pub fn spectrum(
    boom: &Boom,
    coupling: Coupling,
    flux: f64,
) -> Result<([f64; 4], DMatrix<f64>, Spectrum)> {
    let sys = boom_system(boom, Orbit::geo_equinox(), coupling)?;
    let (eq, jac, spectrum) = analyse_system(&sys, flux)?;
    Ok(([eq[0], eq[1], eq[2], eq[3]], jac, spectrum))
}

/// [`spectrum`] and the critical damping ratio, by bisection on ζ to 1e-12 (relative).
pub fn flutter(boom: &Boom, coupling: Coupling, flux: f64) -> Result<BoomFlutter> {
    let (equilibrium, jacobian, spectrum) = spectrum(boom, coupling, flux)?;
    let growth = |zeta: f64| -> Result<f64> {
        let b = Boom {
            damping: zeta,
            ..*boom
        };
        Ok(self::spectrum(&b, coupling, flux)?.2.growth_rate)
    };
    let critical_damping_ratio = critical_value(growth, boom.damping.max(1e-6), 1e-12)?;
    Ok(BoomFlutter {
        equilibrium,
        jacobian,
        spectrum,
        critical_damping_ratio,
    })
}

/// The growth rate and the critical damping ratio over solar inclinations ψ (rows) and ratios
/// B = ω₁ τ of the thermal to the structural response time (columns, set through the
/// conductivity, [`Boom::with_response_time_ratio`]), row-major.
pub struct TubeStabilityMap {
    pub growth_rate: Vec<f64>,
    pub critical_damping_ratio: Vec<f64>,
}

/// [`TubeStabilityMap`] of `boom` under `flux`, stopping within a point of `cancel`.
pub fn stability_map(
    boom: &Boom,
    inclinations: &[f64],
    ratios: &[f64],
    coupling: Coupling,
    flux: f64,
    cancel: &crate::cancel::Cancel,
) -> Result<TubeStabilityMap> {
    let mut map = TubeStabilityMap {
        growth_rate: Vec::with_capacity(inclinations.len() * ratios.len()),
        critical_damping_ratio: Vec::with_capacity(inclinations.len() * ratios.len()),
    };
    for &psi in inclinations {
        let tilted = Boom {
            solar_inclination: psi,
            ..*boom
        };
        for &ratio in ratios {
            cancel.check()?;
            let point = tilted.with_response_time_ratio(ratio)?;
            let f = flutter(&point, coupling, flux)?;
            map.growth_rate.push(f.spectrum.growth_rate);
            map.critical_damping_ratio.push(f.critical_damping_ratio);
        }
    }
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cubic of the single-mode model from the Jacobian's own entries (state T̄, T_m, θ,
    /// θ̇; T̄ does not feed back, so the rest is closed): λ³ + (a + r) λ² + (ω² + a r) λ +
    /// a ω² − G, with a = −J₁₁, r = −J₃₃, ω² = −J₃₂, G = J₁₂ J₃₁.
    fn routh_critical_ratio(jac: &DMatrix<f64>) -> f64 {
        let a = -jac[(1, 1)];
        let w2 = -jac[(3, 2)];
        let g = jac[(1, 2)] * jac[(3, 1)];
        // (a + r)(ω² + a r) > a ω² − G  ⟺  a r² + (ω² + a²) r + G > 0.
        let (qa, qb, qc) = (a, w2 + a * a, g);
        let r = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
        r / (2.0 * w2.sqrt())
    }

    #[test]
    fn the_flutter_boundary_is_the_routh_hurwitz_boundary_of_its_cubic() {
        for psi in [1.9, 2.3, 2.8] {
            let boom = Boom {
                solar_inclination: psi,
                ..Boom::example()
            };
            let f = flutter(&boom, Coupling::ProjectedArea, 1.0).unwrap();
            let want = routh_critical_ratio(&f.jacobian);
            let got = f.critical_damping_ratio;
            assert!(want > 0.0);
            assert!((got / want - 1.0).abs() < 1e-6, "ψ {psi}: {got} vs {want}");
        }
    }

    #[test]
    fn the_response_time_ratio_is_set_by_the_conductivity() {
        let boom = Boom {
            length: 10.0,
            ..Boom::example()
        };
        for ratio in [0.1, 1.0, 20.0] {
            let b = boom.with_response_time_ratio(ratio).unwrap();
            let got = b.first_angular_frequency() * b.time_constant();
            assert!((got / ratio - 1.0).abs() < 1e-12, "{got}");
        }
        assert!(boom.with_response_time_ratio(1e6).is_err());
    }

    #[test]
    fn leaning_away_from_the_sun_flutters_and_toward_it_does_not() {
        for (psi, flutters) in [(0.6, false), (1.2, false), (1.95, true), (2.6, true)] {
            let boom = Boom {
                solar_inclination: psi,
                ..Boom::example()
            };
            let (_, _, s) = spectrum(&boom, Coupling::ProjectedArea, 1.0).unwrap();
            assert_eq!(s.growth_rate > 0.0, flutters, "ψ {psi}: {}", s.growth_rate);
        }
    }
}
