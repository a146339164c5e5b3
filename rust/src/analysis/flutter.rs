//! Thermal flutter without integration: the Jacobian of the coupled system at the sunlit
//! equilibrium, its eigenvalues, the growth rate of the oscillatory mode and the critical damping.
//!
//! With the two-way coupling the absorbed flux depends on cos θ, so a swing of the panel modulates
//! the heating; the temperature gradient answers with a lag, and that lag can feed energy into the
//! oscillation (the paper's "thermal pumping"). Linear stability of the equilibrium decides it.

use crate::analysis::steady::{equilibrium, Equilibrium};
use crate::error::{require_non_negative, Error, Result};
use crate::inputs::heating::Loads;
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::coupled::{jacobian_from_rows, Coupled, Coupling};
use crate::models::hinge::{HingeModel, StructuralModel};
use crate::models::thermal::ThermalModel;
use crate::models::thermal::STEFAN_BOLTZMANN;
use crate::numerics::integrate::State;
use nalgebra::allocator::Allocator;
use nalgebra::{Complex, DMatrix, DVector, DefaultAllocator, Dim, Matrix4, U1, U4};

/// Linear stability of the sunlit equilibrium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlutterAnalysis {
    pub equilibrium: Equilibrium,
    /// ∂f/∂y at the equilibrium, state (T_f, T_b, θ, θ̇).
    pub jacobian: Matrix4<f64>,
    /// Eigenvalues of the Jacobian, 1/s, sorted by decreasing real part.
    pub eigenvalues: [Complex<f64>; 4],
    /// Largest real part of the eigenvalues, 1/s: positive means the equilibrium is unstable
    /// (with the thermal modes strongly damped, this is the oscillatory mode's growth rate).
    pub growth_rate: f64,
    /// Frequency of the oscillatory pair, Hz (0 when the hinge is overdamped).
    pub frequency_hz: f64,
}

impl FlutterAnalysis {
    pub fn stable(&self) -> bool {
        self.growth_rate < 0.0
    }
}

/// The analytic Jacobian of the coupled right-hand side at a steady state (θ̇ = 0, M_T = K_el θ).
pub fn jacobian(
    panel: &Panel,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
    eq: &Equilibrium,
) -> Matrix4<f64> {
    let h = 0.5 * panel.heat_capacity();
    let k = panel.conductance;
    let absorbed = panel.absorptivity * panel.solar_constant * flux;
    let s = eq.theta.sin();
    // d(absorbed · cos θ)/dθ; zero when the projected area is frozen.
    let d_heating = match coupling {
        Coupling::ProjectedArea => -absorbed * s,
        Coupling::Frozen => 0.0,
    };
    let rad_f = 4.0 * STEFAN_BOLTZMANN * panel.emissivity_front * eq.t_front.powi(3);
    let rad_b = 4.0 * STEFAN_BOLTZMANN * panel.emissivity_back * eq.t_back.powi(3);
    // Non-linear inertia factor 1 + 3 sin²θ; its derivative multiplies the static residual,
    // which is zero at the equilibrium, and the θ̇² term vanishes with θ̇.
    let inertia = panel.hinge_inertia() * model.inertia_factor(s);
    let mu = panel.moment_per_kelvin();
    jacobian_from_rows(
        [(-k - rad_f) / h, k / h, d_heating / h],
        [k / h, (-k - rad_b) / h],
        [
            mu / inertia,
            -mu / inertia,
            -panel.hinge_stiffness / inertia,
            -panel.damping / inertia,
        ],
    )
}

/// Eigen-analysis of the coupled system at the sunlit equilibrium under flux factor `flux`.
pub fn analyse(
    panel: &Panel,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
) -> Result<FlutterAnalysis> {
    let eq = equilibrium(panel, coupling, flux)?;
    let jac = jacobian(panel, model, coupling, flux, &eq);
    // Kelvin rows against radian rows: θ scaled by the temperature, θ̇ by ω_n too.
    let scale = [
        1.0,
        1.0,
        1.0 / eq.t_front.max(1.0),
        panel.natural_angular_frequency() / eq.t_front.max(1.0),
    ];
    let spectrum = Spectrum::of(&DMatrix::from_column_slice(4, 4, jac.as_slice()), &scale)?;
    Ok(FlutterAnalysis {
        equilibrium: eq,
        jacobian: jac,
        eigenvalues: [
            spectrum.eigenvalues[0],
            spectrum.eigenvalues[1],
            spectrum.eigenvalues[2],
            spectrum.eigenvalues[3],
        ],
        growth_rate: spectrum.growth_rate,
        frequency_hz: spectrum.frequency_hz,
    })
}

/// Eigenvalues of a linearised system, with its growth rate and oscillation frequency.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    /// 1/s, sorted by decreasing real part (then imaginary part).
    pub eigenvalues: Vec<Complex<f64>>,
    /// Largest real part, 1/s: positive means the equilibrium is unstable.
    pub growth_rate: f64,
    /// Largest |Im λ| / 2π, Hz (0 when nothing oscillates).
    pub frequency_hz: f64,
}

impl Spectrum {
    /// The spectrum of `jac` after the diagonal similarity D⁻¹ J D, D = diag(`scale`), which
    /// leaves the eigenvalues unchanged and evens out the units of the state's components
    /// (kelvin against radians) before the eigen-solve.
    pub fn of(jac: &DMatrix<f64>, scale: &[f64]) -> Result<Spectrum> {
        let n = jac.nrows();
        if jac.ncols() != n || scale.len() != n {
            return Err(Error::invalid(
                "jacobian",
                format!("{}x{}", n, jac.ncols()),
                &format!("must be square and match the {} scales", scale.len()),
            ));
        }
        let balanced = DMatrix::from_fn(n, n, |i, j| jac[(i, j)] * scale[j] / scale[i]);
        let ev = balanced.complex_eigenvalues();
        if ev.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()) {
            return Err(Error::NoConvergence {
                what: "eigenvalues".into(),
                reason: "non-finite result".into(),
            });
        }
        let mut eigenvalues: Vec<Complex<f64>> = ev.iter().copied().collect();
        eigenvalues.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
        let growth_rate = eigenvalues[0].re;
        let omega = eigenvalues.iter().map(|z| z.im.abs()).fold(0.0, f64::max);
        Ok(Spectrum {
            eigenvalues,
            growth_rate,
            frequency_hz: omega / (2.0 * std::f64::consts::PI),
        })
    }
}

/// Scales that balance `jac` (Parlett–Reinsch): powers of two d such that D⁻¹ J D has rows and
/// columns of matching norms, for [`Spectrum::of`]. Being powers of two, they change no digit
/// of the eigenvalues; they even out scales the caller cannot know in advance (kelvin against
/// the coordinates of many modes).
pub fn balancing(jac: &DMatrix<f64>) -> Vec<f64> {
    let n = jac.nrows();
    let mut a = jac.clone();
    let mut d = vec![1.0; n];
    for _ in 0..100 {
        let mut done = true;
        for i in 0..n {
            let c: f64 = (0..n).filter(|&r| r != i).map(|r| a[(r, i)].abs()).sum();
            let r: f64 = (0..n).filter(|&c| c != i).map(|c| a[(i, c)].abs()).sum();
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let mut f = 1.0;
            let (mut cc, mut rr) = (c, r);
            while cc < rr / 2.0 {
                cc *= 2.0;
                rr /= 2.0;
                f *= 2.0;
            }
            while cc > rr * 2.0 {
                cc /= 2.0;
                rr *= 2.0;
                f /= 2.0;
            }
            if (cc + rr) < 0.95 * (c + r) {
                done = false;
                d[i] *= f;
                for k in 0..n {
                    a[(i, k)] /= f;
                    a[(k, i)] *= f;
                }
            }
        }
        if done {
            break;
        }
    }
    d
}

/// ∂f/∂y of `f` at `y` by central differences, step ε^(1/3) · max(|y_j|, `floor[j]`) in
/// component j (`floor`: a magnitude typical of the component where it passes through zero).
pub fn finite_difference_jacobian(
    f: impl Fn(&DVector<f64>) -> DVector<f64>,
    y: &DVector<f64>,
    floor: &[f64],
) -> DMatrix<f64> {
    let n = y.len();
    let mut jac = DMatrix::zeros(n, n);
    for j in 0..n {
        let h = f64::EPSILON.cbrt() * y[j].abs().max(floor[j]);
        let (mut plus, mut minus) = (y.clone(), y.clone());
        plus[j] += h;
        minus[j] -= h;
        // The step actually taken, so that rounding of y ± h does not bias the quotient.
        let step = plus[j] - minus[j];
        jac.set_column(j, &((f(&plus) - f(&minus)) / step));
    }
    jac
}

/// Linear stability of any coupled system at its steady state under flux factor `flux`: its
/// right-hand side differentiated by [`finite_difference_jacobian`], then [`Spectrum::of`]
/// with each component scaled by its magnitude at the equilibrium. Returns the equilibrium and
/// the spectrum.
pub fn analyse_system<T, S, D>(
    system: &Coupled<T, S, D>,
    flux: f64,
) -> Result<(State<D>, DMatrix<f64>, Spectrum)>
where
    T: ThermalModel,
    S: StructuralModel,
    D: Dim,
    DefaultAllocator: Allocator<D>,
{
    check_flux(flux)?;
    let eq = system.steady_state(flux)?;
    spectrum_of(system, eq, Loads::sun(flux))
}

/// Linear stability of any coupled system at its sunlit equilibrium under every load of its
/// orbit at time t (the Sun's distance, the Earth's infrared and albedo and the attitude's
/// incidence there, s = 1), as [`analyse_system`] does under a flux factor.
pub fn analyse_system_at(system: &Coupled, t: f64) -> Result<(State<U4>, DMatrix<f64>, Spectrum)> {
    Orbit::check_time(t)?;
    analyse_system_under(system, system.sunlit_loads(t))
}

/// Linear stability of any coupled system at its equilibrium under constant `loads` (e.g. the
/// sunlit-arc average of [`Orbit::sunlit_average_loads`]), as [`analyse_system_at`].
pub fn analyse_system_under(
    system: &Coupled,
    loads: Loads,
) -> Result<(State<U4>, DMatrix<f64>, Spectrum)> {
    let eq = system.steady_state_under(loads)?;
    spectrum_of(system, eq, loads)
}

/// The Jacobian at the equilibrium `eq` under constant `loads`, and its spectrum.
fn spectrum_of<T: ThermalModel, S: StructuralModel, D: Dim>(
    system: &Coupled<T, S, D>,
    eq: State<D>,
    loads: Loads,
) -> Result<(State<D>, DMatrix<f64>, Spectrum)>
where
    DefaultAllocator: Allocator<D>,
{
    let y = DVector::from_column_slice(eq.as_slice());
    let dim = system.dim();
    let f = |x: &DVector<f64>| {
        let state = State::<D>::from_column_slice_generic(dim, U1, x.as_slice());
        DVector::from_column_slice(system.rhs_at_loads(loads, &state).as_slice())
    };
    // Temperatures and shapes through zero: a kelvin, a milliradian (or its modal equivalent).
    let n_thermal = system.thermal().size();
    let floor: Vec<f64> = (0..y.len())
        .map(|i| if i < n_thermal { 1.0 } else { 1e-3 })
        .collect();
    let jac = finite_difference_jacobian(f, &y, &floor);
    let scale: Vec<f64> = (0..y.len())
        .map(|i| {
            if i < n_thermal {
                1.0
            } else {
                1.0 / y.amax().max(1.0)
            }
        })
        .collect();
    let spectrum = Spectrum::of(&jac, &scale)?;
    Ok((eq, jac, spectrum))
}

/// The value of a stabilising parameter (a damping, a damping ratio) at which `growth` crosses
/// zero, by bracketing from `start` (doubling) and bisection to `rel_tol`. Returns 0 when the
/// system is stable without it.
pub fn critical_value(
    mut growth: impl FnMut(f64) -> Result<f64>,
    start: f64,
    rel_tol: f64,
) -> Result<f64> {
    if growth(0.0)? < 0.0 {
        return Ok(0.0);
    }
    let mut hi = start;
    let mut n = 0;
    while growth(hi)? >= 0.0 {
        hi *= 2.0;
        n += 1;
        if n > 200 {
            return Err(Error::NoConvergence {
                what: "critical damping".into(),
                reason: "no stabilising damping found".into(),
            });
        }
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if growth(mid)? >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= rel_tol * hi {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// The damping c_d (N m s/rad) at which the growth rate crosses zero, by bracketing and bisection.
/// Returns 0 when the panel is stable even without damping.
pub fn critical_damping(
    panel: &Panel,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
) -> Result<f64> {
    critical_hinge_damping(
        panel,
        |p| Ok(analyse(p, model, coupling, flux)?.growth_rate),
    )
}

/// The hinge damping c_d at which `growth_of` (the growth rate of `panel` with a given c_d)
/// crosses zero, by [`critical_value`] from the panel's own c_d (at least 1e-3 √(K_el I_B)); 0
/// when the panel is stable without damping. The equilibrium does not depend on c_d; only the
/// hinge row of the Jacobian does.
pub fn critical_hinge_damping(
    panel: &Panel,
    growth_of: impl Fn(&Panel) -> Result<f64>,
) -> Result<f64> {
    let growth = |cd: f64| {
        growth_of(&Panel {
            damping: cd,
            ..*panel
        })
    };
    let start = panel
        .damping
        .max(1e-3 * (panel.hinge_stiffness * panel.hinge_inertia()).sqrt());
    critical_value(growth, start, 1e-12)
}

/// [`critical_damping`] at the sunlit equilibrium under every load of `orbit` at time t
/// ([`analyse_system_at`]).
pub fn critical_damping_at(
    panel: &Panel,
    orbit: &Orbit,
    t: f64,
    model: HingeModel,
    coupling: Coupling,
) -> Result<f64> {
    Orbit::check_time(t)?;
    let loads = Coupled::new(*panel, *orbit, model, coupling).sunlit_loads(t);
    critical_damping_under(panel, orbit, loads, model, coupling)
}

/// [`critical_damping_at`] about the equilibrium under constant `loads`.
pub fn critical_damping_under(
    panel: &Panel,
    orbit: &Orbit,
    loads: Loads,
    model: HingeModel,
    coupling: Coupling,
) -> Result<f64> {
    let growth = |cd: f64| -> Result<f64> {
        let p = Panel {
            damping: cd,
            ..*panel
        };
        let system = Coupled::new(p, *orbit, model, coupling);
        Ok(analyse_system_under(&system, loads)?.2.growth_rate)
    };
    let start = panel
        .damping
        .max(1e-3 * (panel.hinge_stiffness * panel.hinge_inertia()).sqrt());
    critical_value(growth, start, 1e-12)
}

/// Checks a flux factor argument.
pub fn check_flux(flux: f64) -> Result<()> {
    require_non_negative("flux", flux)?;
    if flux == 0.0 {
        return Err(Error::invalid(
            "flux",
            flux,
            "must be > 0 (the analysis is about the sunlit equilibrium)",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::orbit::Orbit;
    use crate::models::coupled::Coupled;
    use crate::numerics::testing::assert_jacobian;
    use nalgebra::Vector4;

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
                let p = Panel::paper();
                let eq = equilibrium(&p, coupling, 1.0).unwrap();
                let jac = jacobian(&p, model, coupling, 1.0, &eq);
                let sys = Coupled::new(p, Orbit::geo_equinox(), model, coupling);
                let f = |y: &Vector4<f64>| sys.rhs_at_flux(1.0, y);
                let case = format!("{model:?} {coupling:?}");
                assert_jacobian(&jac, f, &eq.state(), 1e-12, &case);
            }
        }
    }

    #[test]
    fn frozen_area_cannot_flutter() {
        // Without the cos θ feedback the mechanical mode only sees its own damping.
        let p = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        let a = analyse(&p, HingeModel::Linear, Coupling::Frozen, 1.0).unwrap();
        assert!(a.growth_rate.abs() < 1e-12, "{}", a.growth_rate);
        assert_eq!(
            critical_damping(&p, HingeModel::Linear, Coupling::Frozen, 1.0).unwrap(),
            0.0
        );
    }

    #[test]
    fn undamped_coupled_panel_flutters_and_damping_cures_it() {
        let p = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        let a = analyse(&p, HingeModel::Nonlinear, Coupling::ProjectedArea, 1.0).unwrap();
        assert!(a.growth_rate > 0.0);
        let f_lin = p.natural_angular_frequency() / (2.0 * std::f64::consts::PI);
        assert!((a.frequency_hz / f_lin - 1.0).abs() < 0.05);
        let cd = critical_damping(&p, HingeModel::Nonlinear, Coupling::ProjectedArea, 1.0).unwrap();
        assert!(cd > 0.0);
        let above = analyse(
            &Panel {
                damping: cd * 1.01,
                ..p
            },
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
            1.0,
        )
        .unwrap();
        let below = analyse(
            &Panel {
                damping: cd * 0.99,
                ..p
            },
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
            1.0,
        )
        .unwrap();
        assert!(above.stable() && !below.stable());
    }

    #[test]
    fn any_system_by_finite_differences_matches_the_analytic_analysis() {
        let orbit = Orbit::geo_equinox();
        for damping in [0.0, 3.0] {
            let p = Panel {
                damping,
                ..Panel::paper()
            };
            for model in [HingeModel::Nonlinear, HingeModel::Linear] {
                let exact = analyse(&p, model, Coupling::ProjectedArea, 1.0).unwrap();
                let sys = Coupled::new(p, orbit, model, Coupling::ProjectedArea);
                let (eq, jac, spectrum) = analyse_system(&sys, 1.0).unwrap();
                assert_eq!(eq, exact.equilibrium.state());
                for i in 0..4 {
                    for j in 0..4 {
                        let tol = 1e-7 * exact.jacobian.column(j).amax();
                        assert!(
                            (jac[(i, j)] - exact.jacobian[(i, j)]).abs() <= tol,
                            "({i},{j})"
                        );
                    }
                }
                // Rounding in the differences moves the eigenvalues by ~1e-10 of their size.
                let size = exact
                    .eigenvalues
                    .iter()
                    .map(|z| z.norm())
                    .fold(0.0, f64::max);
                let err = (spectrum.growth_rate - exact.growth_rate).abs();
                assert!(err < 1e-8 * size, "{model:?} c_d {damping}: {err}");
                assert!((spectrum.frequency_hz / exact.frequency_hz - 1.0).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn critical_damping_of_any_system_by_its_growth_rate() {
        let p = Panel::paper();
        let (model, coupling) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        let growth = |cd: f64| {
            let sys = Coupled::new(
                Panel { damping: cd, ..p },
                Orbit::geo_equinox(),
                model,
                coupling,
            );
            Ok(analyse_system(&sys, 1.0)?.2.growth_rate)
        };
        let generic = critical_value(growth, 1.0, 1e-10).unwrap();
        let exact = critical_damping(&p, model, coupling, 1.0).unwrap();
        assert!((generic / exact - 1.0).abs() < 1e-5, "{generic} vs {exact}");
    }
}
