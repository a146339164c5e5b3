//! The N-node laminate on the hinge without a transient: its steady state, the start state of a
//! run, the Jacobian there, flutter growth and critical damping.

use crate::error::{Error, Result};
use crate::inputs::heating::{Loads, Optics};
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::conduction::Conduction;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use nalgebra::{DMatrix, DVector};

/// The steady state of the coupled N-node system under a constant illumination factor: node
/// temperatures (front first) and θ, with θ̇ = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct LayeredEquilibrium {
    pub temperatures: Vec<f64>,
    pub theta: f64,
    pub moment: f64,
}

/// Newton's method on the N heat balances and the static hinge (M_T = K_el θ), with the
/// analytic Jacobian, from the uncoupled steady profile.
pub fn equilibrium(
    panel: &Panel,
    c: &Conduction,
    coupling: Coupling,
    flux: f64,
) -> Result<LayeredEquilibrium> {
    equilibrium_loaded(panel, c, coupling, Loads::sun(flux))
}

/// [`equilibrium`] under constant `loads`: the front's sunlight as a flux factor and the further
/// loads absorbed on each face (W/m², the Earth's and sunlight on the back), all scaled by the
/// projected area with the two-way coupling.
pub fn equilibrium_loaded(
    panel: &Panel,
    c: &Conduction,
    coupling: Coupling,
    loads: Loads,
) -> Result<LayeredEquilibrium> {
    let n = c.nodes();
    let flux = loads.sun;
    // The front's sunlight that heats the plate as much: where Newton starts.
    let start_flux = if loads.has_face_loads() {
        loads.equivalent_flux(&Optics::of(panel))
    } else {
        flux
    };
    if c.two_layer {
        // Two nodes on a plain panel are eq. 2: the same steady state to the bit, so that a run
        // from it is the two-layer run.
        let (t_front, t_back, theta) = if loads.has_face_loads() {
            panel.validate()?;
            let x = crate::analysis::steady::steady_loaded(
                &crate::models::thermal::TwoLayer::new(panel),
                &crate::models::hinge::Hinge::new(panel, HingeModel::Nonlinear),
                coupling,
                loads,
                start_flux,
            )?;
            (x[0], x[1], x[2])
        } else {
            let eq = crate::analysis::steady::equilibrium(panel, coupling, flux)?;
            (eq.t_front, eq.t_back, eq.theta)
        };
        let temperatures = vec![t_front, t_back];
        return Ok(LayeredEquilibrium {
            moment: c.moment(&temperatures),
            temperatures,
            theta,
        });
    }
    let profile = c.steady_profile(start_flux)?;
    let k_el = panel.hinge_stiffness;
    let mut x = DVector::zeros(n + 1);
    for i in 0..n {
        x[i] = profile[i];
    }
    x[n] = c.moment(&profile) / k_el;
    let k = c.conduction_matrix();
    let residual_and_jacobian = |x: &DVector<f64>| {
        let th = x[n];
        let (area, d_area) = match coupling {
            Coupling::ProjectedArea => (th.cos(), -th.sin()),
            Coupling::Frozen => (1.0, 0.0),
        };
        let t: Vec<f64> = x.rows(0, n).iter().copied().collect();
        let (qf, qb) = c.face_inputs(flux * area, t[0], t[n - 1]);
        let mut f = DVector::zeros(n + 1);
        let kt = &k * x.rows(0, n);
        for i in 0..n {
            f[i] = -kt[i];
        }
        f[0] += qf;
        f[n - 1] += qb;
        if loads.has_face_loads() {
            f[0] += loads.front * area;
            f[n - 1] += loads.back * area;
        }
        f[n] = (c.moment(&t) - k_el * th) / k_el;
        let mut jac = DMatrix::zeros(n + 1, n + 1);
        jac.view_mut((0, 0), (n, n)).copy_from(&(-&k));
        jac[(0, 0)] -= 4.0 * c.radiation_front * t[0].powi(3);
        jac[(n - 1, n - 1)] -= 4.0 * c.radiation_back * t[n - 1].powi(3);
        jac[(0, n)] = (c.absorbed * flux + loads.front) * d_area;
        jac[(n - 1, n)] += loads.back * d_area;
        for i in 0..n {
            jac[(n, i)] = c.moment_weight[i] / k_el;
        }
        jac[(n, n)] = -1.0;
        (f, jac)
    };
    let settled = |x: &DVector<f64>, dx: &DVector<f64>| {
        (0..n).all(|i| dx[i].abs() < 1e-12 * x[i]) && dx[n].abs() < 1e-14
    };
    let x = crate::numerics::newton::newton("steady state", x, n, residual_and_jacobian, settled)?;
    if x[n].abs() >= std::f64::consts::FRAC_PI_2 {
        return Err(Error::NoConvergence {
            what: "steady state".into(),
            reason: format!(
                "hinge angle {} rad is beyond 90°: the panel is far too soft",
                x[n]
            ),
        });
    }
    let temperatures: Vec<f64> = x.rows(0, n).iter().copied().collect();
    let moment = c.moment(&temperatures);
    Ok(LayeredEquilibrium {
        temperatures,
        theta: x[n],
        moment,
    })
}

/// The default start of a layered run beginning at `t0`: the sunlit equilibrium at that time's
/// solar flux, at rest, as the state (node temperatures front first, θ, θ̇ = 0).
pub fn start_state(
    panel: &Panel,
    c: &Conduction,
    coupling: Coupling,
    orbit: &Orbit,
    t0: f64,
) -> Result<Vec<f64>> {
    Orbit::check_time(t0)?;
    let eq = equilibrium_loaded(
        panel,
        c,
        coupling,
        orbit.sunlit_loads(t0, &Optics::of(panel)),
    )?;
    let mut y = eq.temperatures;
    y.push(eq.theta);
    y.push(0.0);
    Ok(y)
}

/// Linear stability of the N-node system's sunlit equilibrium (the full nodal Jacobian: an
/// eigen-analysis has no step to protect from fast modes).
#[derive(Debug, Clone, PartialEq)]
pub struct LayeredFlutter {
    pub equilibrium: LayeredEquilibrium,
    /// ∂f/∂y at the equilibrium, state (node temperatures, θ, θ̇).
    pub jacobian: DMatrix<f64>,
    /// Its eigenvalues, 1/s, by decreasing real part.
    pub eigenvalues: Vec<nalgebra::Complex<f64>>,
    /// Largest real part of the eigenvalues, 1/s.
    pub growth_rate: f64,
    /// Frequency of the fastest oscillatory pair, Hz.
    pub frequency_hz: f64,
}

/// One operating point of the N-node laminate on the hinge: the inputs that its Jacobian,
/// flutter analysis and critical damping all read.
#[derive(Debug, Clone, Copy)]
pub struct LayeredPoint<'a> {
    pub panel: &'a Panel,
    pub conduction: &'a Conduction,
    pub model: HingeModel,
    pub coupling: Coupling,
    /// The loads held constant: the front's sunlight as a flux factor (the flux scale), and
    /// the Earth's and the back's sunlight when the orbit has them.
    pub loads: Loads,
}

impl LayeredPoint<'_> {
    /// The steady state at this point.
    pub fn equilibrium(&self) -> Result<LayeredEquilibrium> {
        equilibrium_loaded(self.panel, self.conduction, self.coupling, self.loads)
    }

    /// The analytic Jacobian of the nodal system (N node temperatures, θ, θ̇) at a steady state.
    pub fn jacobian(&self, eq: &LayeredEquilibrium) -> DMatrix<f64> {
        let LayeredPoint {
            panel,
            conduction: c,
            model,
            coupling,
            loads,
        } = *self;
        let n = c.nodes();
        let t = &eq.temperatures;
        let mut j = DMatrix::zeros(n + 2, n + 2);
        let k = c.conduction_matrix();
        for r in 0..n {
            for col in 0..n {
                j[(r, col)] = -k[(r, col)] / c.capacity[r];
            }
        }
        j[(0, 0)] -= 4.0 * c.radiation_front * t[0].powi(3) / c.capacity[0];
        j[(n - 1, n - 1)] -= 4.0 * c.radiation_back * t[n - 1].powi(3) / c.capacity[n - 1];
        let s = eq.theta.sin();
        if coupling == Coupling::ProjectedArea {
            j[(0, n)] = -(c.absorbed * loads.sun + loads.front) * s / c.capacity[0];
            j[(n - 1, n)] -= loads.back * s / c.capacity[n - 1];
        }
        j[(n, n + 1)] = 1.0;
        // The static residual is zero at the equilibrium, so the derivative of the non-linear
        // inertia factor drops out (as in the two-layer Jacobian).
        let inertia = panel.hinge_inertia() * model.inertia_factor(s);
        for col in 0..n {
            j[(n + 1, col)] = c.moment_weight[col] / inertia;
        }
        j[(n + 1, n)] = -panel.hinge_stiffness / inertia;
        j[(n + 1, n + 1)] = -panel.damping / inertia;
        j
    }

    /// The flutter analysis of this point: equilibrium, Jacobian, spectrum.
    pub fn analyse(&self) -> Result<LayeredFlutter> {
        let eq = self.equilibrium()?;
        let jac = self.jacobian(&eq);
        let (growth_rate, frequency_hz, eigenvalues) = growth(self.panel, &jac, &eq)?;
        Ok(LayeredFlutter {
            jacobian: jac,
            equilibrium: eq,
            eigenvalues,
            growth_rate,
            frequency_hz,
        })
    }

    /// The damping c_d (N m s/rad) at which the growth rate crosses zero (bisection); 0 when
    /// the panel is stable without damping.
    pub fn critical_damping(&self) -> Result<f64> {
        // The equilibrium does not depend on c_d.
        let eq = self.equilibrium()?;
        crate::analysis::flutter::critical_hinge_damping(self.panel, |p| {
            let jac = LayeredPoint { panel: p, ..*self }.jacobian(&eq);
            Ok(growth(p, &jac, &eq)?.0)
        })
    }
}

/// (growth rate, frequency, eigenvalues by decreasing real part) of `jac`, the Jacobian of
/// `panel`'s system at `eq`.
fn growth(
    panel: &Panel,
    jac: &DMatrix<f64>,
    eq: &LayeredEquilibrium,
) -> Result<(f64, f64, Vec<nalgebra::Complex<f64>>)> {
    // The state: n node temperatures, θ and θ̇.
    let n = jac.nrows() - 2;
    // Balance kelvin rows against radian rows.
    let tmax = eq.temperatures.iter().fold(1.0_f64, |a, &b| a.max(b));
    let mut scale = vec![1.0; n + 2];
    scale[n] = 1.0 / tmax;
    scale[n + 1] = panel.natural_angular_frequency() / tmax;
    let spectrum = crate::analysis::flutter::Spectrum::of(jac, &scale)?;
    Ok((
        spectrum.growth_rate,
        spectrum.frequency_hz,
        spectrum.eigenvalues,
    ))
}
