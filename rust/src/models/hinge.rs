//! Thermal bending moment and the one-degree-of-freedom hinge model (paper Sec. 3, eqs. 20, 28).

use crate::error::{Error, Result};
use crate::inputs::panel::Panel;
use crate::numerics::simd::{Fused, Num};

/// Structural model of the hinge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HingeModel {
    /// Eq. 20: the exact kinematics of two rigid halves, with the (1 + 3 sin²θ) inertia.
    Nonlinear,
    /// Eq. 28: I_B θ̈ + c_d θ̇ + K_el θ = M_T.
    Linear,
}

impl HingeModel {
    /// The factor on I_B θ̈ at sin θ = `sin`: 1 + 3 sin²θ (eq. 20), 1 for the linear model.
    #[inline(always)]
    pub fn inertia_factor(self, sin: f64) -> f64 {
        match self {
            HingeModel::Nonlinear => 1.0 + 3.0 * sin * sin,
            HingeModel::Linear => 1.0,
        }
    }
}

/// |θ| the hinge model describes, rad: its two rigid halves fold by θ each, so beyond π/2 they
/// would pass through each other (and the paper's use is for a few degrees).
pub const MAX_HINGE_ANGLE: f64 = std::f64::consts::FRAC_PI_2;

/// |θ| up to which the hinge model is trusted by default, rad (20°): its rigid halves and the
/// cos θ coupling are meant for modest angles. Long runs and Monte Carlo samples stop or flag
/// the first orbit beyond it.
pub const VALIDITY_LIMIT: f64 = 20.0 * (std::f64::consts::PI / 180.0);

/// Checks an angle given to the hinge model (a start state, a limit): within ±π/2 rad. The
/// message says what a value in degrees would have been, the likely slip.
pub fn check_hinge_angle(name: &str, theta: f64) -> crate::error::Result<()> {
    if theta.is_finite() && theta.abs() <= MAX_HINGE_ANGLE {
        return Ok(());
    }
    let mut reason = "must be within ±π/2 rad (the hinge model's range)".to_string();
    if theta.is_finite() && theta.abs() <= 360.0 {
        reason += &format!(
            "; if degrees were meant, {theta}° = {:.6} rad",
            theta.to_radians()
        );
    }
    Err(crate::error::Error::invalid(name, theta, &reason))
}

/// Checks a start state `y0` of (temperatures…, then, with `hinge`, θ and θ̇): the one check
/// of every run that takes a start state. A temperature is absolute: finite and > 0 K (the
/// radiation T⁴ and every material value assume a body above absolute zero). θ is within
/// ±π/2 ([`check_hinge_angle`]) and θ̇ within the hinge's fastest rate
/// ([`Hinge::max_start_rate`]). Components are named by their index, `y0[i]`.
pub fn check_start_state(y0: &[f64], temperatures: usize, hinge: Option<&Hinge>) -> Result<()> {
    for (i, &t) in y0.iter().enumerate().take(temperatures) {
        if !(t.is_finite() && t > 0.0) {
            return Err(Error::invalid(
                &format!("y0[{i}]"),
                t,
                "must be a temperature, finite and > 0 K",
            ));
        }
    }
    if let Some(hinge) = hinge {
        hinge.check_start(temperatures, &y0[temperatures..])?;
    }
    Ok(())
}

/// The static angle M/K_el of a moment on the hinge, checked against the hinge model's range:
/// a larger moment would fold the panel beyond what the model describes.
pub fn check_moment(panel: &Panel, moment: f64) -> crate::error::Result<()> {
    let angle = moment / panel.hinge_stiffness;
    if angle.is_finite() && angle.abs() <= MAX_HINGE_ANGLE {
        return Ok(());
    }
    Err(crate::error::Error::invalid(
        "moment",
        moment,
        &format!(
            "gives a static angle M/K_el = {angle:.3e} rad, beyond the hinge model's range \
             (|M| <= {:.4e} N m with this hinge_stiffness)",
            MAX_HINGE_ANGLE * panel.hinge_stiffness
        ),
    ))
}

/// Refuses a start (θ, θ̇) = `states`, the components `offset` and `offset + 1` of the full
/// state: θ within ±π/2 ([`check_hinge_angle`]), θ̇ within ±`most` rad/s, (π/2) max(ω_n, c_d/I_B)
/// of a hinge, beyond which the start alone would swing it past its range.
pub(crate) fn check_angle_and_rate(offset: usize, states: &[f64], most: f64) -> Result<()> {
    let &[theta, rate, ..] = states else {
        return Err(Error::invalid(
            "y0",
            format!("{} components", offset + states.len()),
            &format!("must hold θ and θ̇ after its {offset} temperatures"),
        ));
    };
    check_hinge_angle(&format!("y0[{offset}]"), theta)?;
    if !(rate.is_finite() && rate.abs() <= most) {
        return Err(Error::invalid(
            &format!("y0[{}]", offset + 1),
            rate,
            &format!(
                "θ̇ must be within ±{most:.4e} rad/s: (π/2) max(ω_n, c_d/I_B), beyond which \
                 the start alone would swing the hinge past its range of ±π/2"
            ),
        ));
    }
    Ok(())
}

/// A structural model of the plate: its states (positions, then velocities), their rates under
/// the thermal moment, and the projected-area factor its shape imposes on the absorbed flux.
///
/// The coupled system ([`crate::models::coupled::Coupled`]) puts these states after the temperatures.
pub trait StructuralModel {
    /// Number of states.
    fn size(&self) -> usize;

    /// Name of each state, as results label it ("theta", "theta_dot").
    fn names(&self) -> Vec<String>;

    /// The inertia the thermal moment is divided by in [`StructuralModel::rates`], kg m² (I_B
    /// for the hinge): the coupled system folds M_T / inertia into one coefficient.
    fn inertia(&self) -> f64;

    /// Factor of the absorbed flux for the plate's shape `q` (cos θ for the hinge).
    fn area_factor(&self, q: &[f64]) -> f64;

    /// Rates of the states under the load `moment / inertia()`, into `out`; returns
    /// [`StructuralModel::area_factor`] of `q`, so that what both need is computed once.
    fn rates(&self, load: f64, q: &[f64], out: &mut [f64]) -> f64;

    /// [`StructuralModel::rates`] with its multiply-adds fused where the model has a fused form
    /// (the hinge does), else `rates` itself. Only code compiled for FMA calls it
    /// (`numerics::cpu::ScalarKernel::Fma`).
    #[inline(always)]
    fn rates_fused(&self, load: f64, q: &[f64], out: &mut [f64]) -> f64 {
        self.rates(load, q, out)
    }

    /// Number of position states (the first ones); the velocities that follow are zero at rest.
    fn positions(&self) -> usize;

    /// Static balance of the positions under the thermal moment `moment` (N m), in balanced
    /// units (for the hinge (M_T − K_el θ)/K_el, rad): zero at rest.
    fn static_residual(&self, moment: f64, positions: &[f64], out: &mut [f64]);

    /// Refuses a rest shape outside the model's range (the hinge beyond 90°).
    fn check_static(&self, _positions: &[f64]) -> Result<()> {
        Ok(())
    }

    /// Refuses a start state outside the model's range; `offset` is the index of the first of
    /// `states` in the full state, to name it.
    fn check_start(&self, _offset: usize, _states: &[f64]) -> Result<()> {
        Ok(())
    }
}

/// Where the point at ζ ∈ [0, 2l] along one rigid half of the hinge model is when the panel
/// is folded by θ (paper Sec. 3.1, Fig. 12), m: x = (l − ζ) sin θ normal to the undeformed
/// panel, y = ζ cos θ along it. As θ varies each point runs on an ellipse of semi-axes |l − ζ|
/// and ζ (the half slides like a trammel, its ends on the two axes).
pub fn hinge_point(panel: &Panel, zeta: f64, theta: f64) -> (f64, f64) {
    let arm = panel.half_arm();
    ((arm - zeta) * theta.sin(), zeta * theta.cos())
}

/// The quasi-static angle M_T/K_el of the two-layer panel, M_T = (M_T per kelvin)(T_f − T_b)
/// ([`thermal_moment`]), for one value or for lanes (the lockstep lanes read their steps with it).
#[inline(always)]
pub(crate) fn quasi_static<T: Num>(moment_per_kelvin: T, stiffness: T, t_front: T, t_back: T) -> T {
    moment_per_kelvin * (t_front - t_back) / stiffness
}

/// M_T = χ a E I (T_f − T_b) / d, N m.
#[inline]
pub fn thermal_moment(panel: &Panel, t_front: f64, t_back: f64) -> f64 {
    panel.moment_per_kelvin() * (t_front - t_back)
}

/// The generalised moment on the hinge, M − c_d θ̇ − K_el θ, in the unit of its coefficients
/// (N m, or per I_B when all three are divided by it).
#[inline(always)]
pub(crate) fn generalised_moment<T: Num>(
    moment: T,
    damping: T,
    stiffness: T,
    theta: T,
    theta_dot: T,
) -> T {
    // (M − c θ̇) − k θ.
    stiffness.neg_mul_add(theta, damping.neg_mul_add(theta_dot, moment))
}

/// θ̈ from the generalised moment over I_B, `forced`: eq. 28, or eq. 20 with 3/(2 m l³) = 1/I_B
/// factored out. `sin`, `cos` are those of θ (unused by the linear model).
#[inline(always)]
pub(crate) fn angular_acceleration<T: Num>(
    model: HingeModel,
    forced: T,
    theta_dot: T,
    sin: T,
    cos: T,
) -> T {
    let three = T::from(3.0);
    match model {
        HingeModel::Linear => forced,
        HingeModel::Nonlinear => {
            // (forced − 3 θ̇² sin cos) / (1 + 3 sin²), the products taken left to right.
            let coriolis = three * theta_dot * theta_dot * sin;
            coriolis.neg_mul_add(cos, forced) / (three * sin).mul_add(sin, T::from(1.0))
        }
    }
}

/// The same equation of motion as (1 + 3 sin² θ, load), (1 + 3 sin² θ) θ̈ = M_T/I_B − load with
/// load = c_d θ̇/I_B + K_el θ/I_B + 3 θ̇² sin θ cos θ (the non-linear model; 1 and no θ̇² term for
/// the linear one), for models that divide by the factor once and reuse it (the N-node slow-mode
/// model). `damping`, `stiffness` are per I_B.
#[inline(always)]
pub(crate) fn hinge_load(
    model: HingeModel,
    damping: f64,
    stiffness: f64,
    theta: f64,
    theta_dot: f64,
    sin: f64,
    cos: f64,
) -> (f64, f64) {
    let restoring = damping * theta_dot + stiffness * theta;
    let load = match model {
        HingeModel::Linear => restoring,
        HingeModel::Nonlinear => restoring + 3.0 * theta_dot * theta_dot * sin * cos,
    };
    (model.inertia_factor(sin), load)
}

/// θ̈ of the hinge under the thermal moment `moment`, rad/s².
#[inline]
pub fn hinge_acceleration(
    panel: &Panel,
    model: HingeModel,
    moment: f64,
    theta: f64,
    theta_dot: f64,
) -> f64 {
    let generalised = generalised_moment(
        moment,
        panel.damping,
        panel.hinge_stiffness,
        theta,
        theta_dot,
    );
    let (s, c) = match model {
        HingeModel::Linear => (0.0, 1.0),
        HingeModel::Nonlinear => sin_cos(theta),
    };
    angular_acceleration(model, generalised / panel.hinge_inertia(), theta_dot, s, c)
}

/// The one-degree-of-freedom hinge model (paper Sec. 3): states (θ, θ̇), the projected area
/// cos θ. Its coefficients are divided by I_B once, here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hinge {
    model: HingeModel,
    /// I_B, kg m².
    inertia: f64,
    /// c_d / I_B, 1/s.
    damping: f64,
    /// K_el / I_B, 1/s².
    stiffness: f64,
    /// K_el, N m/rad.
    hinge_stiffness: f64,
}

impl Hinge {
    pub fn new(panel: &Panel, model: HingeModel) -> Self {
        Hinge {
            model,
            inertia: panel.hinge_inertia(),
            damping: panel.damping_rate(),
            stiffness: panel.stiffness_rate(),
            hinge_stiffness: panel.hinge_stiffness,
        }
    }
}

impl Hinge {
    /// The largest |θ̇| a start state may have, rad/s: (π/2) · max(ω_n, c_d/I_B). From θ̇ alone
    /// the hinge travels at most θ̇/ω_n (the undamped swing; damping only shortens it) and at
    /// most θ̇ I_B/c_d (the pure drag; the spring only shortens it): beyond this bound it would
    /// cross the model's whole range (π/2) within the time of its fastest structural motion, a
    /// start the hinge model does not describe (a unit slip, deg/s or rpm for rad/s). The
    /// non-linear hinge's inertia I_B (1 + 3 sin²θ) is never smaller, so the bound holds for it.
    pub fn max_start_rate(&self) -> f64 {
        std::f64::consts::FRAC_PI_2 * self.stiffness.sqrt().max(self.damping)
    }

    /// (model, c_d / I_B, K_el / I_B): what [`StructuralModel::rates`] uses of the hinge.
    pub(crate) fn rate_form(&self) -> (HingeModel, f64, f64) {
        (self.model, self.damping, self.stiffness)
    }

    /// [`StructuralModel::rates`] in the arithmetic of `T` (`f64`, or [`Fused`]).
    #[inline(always)]
    fn rates_as<T: Num + Into<f64>>(&self, load: f64, q: &[f64], out: &mut [f64]) -> f64 {
        let (theta, theta_dot) = (T::from(q[0]), T::from(q[1]));
        let (damping, stiffness) = (T::from(self.damping), T::from(self.stiffness));
        let forced = generalised_moment(T::from(load), damping, stiffness, theta, theta_dot);
        let (s, c) = sin_cos_as::<T>(q[0]);
        out[0] = q[1];
        out[1] = angular_acceleration(self.model, forced, theta_dot, s, c).into();
        c.into()
    }
}

impl StructuralModel for Hinge {
    fn size(&self) -> usize {
        2
    }
    fn names(&self) -> Vec<String> {
        vec!["theta".into(), "theta_dot".into()]
    }
    fn inertia(&self) -> f64 {
        self.inertia
    }
    /// cos θ.
    #[inline(always)]
    fn area_factor(&self, q: &[f64]) -> f64 {
        sin_cos(q[0]).1
    }
    #[inline(always)]
    fn rates(&self, load: f64, q: &[f64], out: &mut [f64]) -> f64 {
        self.rates_as::<f64>(load, q, out)
    }
    #[inline(always)]
    fn rates_fused(&self, load: f64, q: &[f64], out: &mut [f64]) -> f64 {
        self.rates_as::<Fused>(load, q, out)
    }
    fn positions(&self) -> usize {
        1
    }
    /// M_T − K_el θ = 0, the same for the linear and the non-linear hinge, whose static terms
    /// coincide.
    fn static_residual(&self, moment: f64, positions: &[f64], out: &mut [f64]) {
        out[0] = (moment - self.hinge_stiffness * positions[0]) / self.hinge_stiffness;
    }
    fn check_start(&self, offset: usize, states: &[f64]) -> Result<()> {
        check_angle_and_rate(offset, states, self.max_start_rate())
    }
    fn check_static(&self, positions: &[f64]) -> Result<()> {
        let theta = positions[0];
        if theta.abs() >= std::f64::consts::FRAC_PI_2 {
            return Err(Error::NoConvergence {
                what: "steady state".into(),
                reason: format!("hinge angle {theta} rad is beyond 90°: the panel is far too soft"),
            });
        }
        Ok(())
    }
}

/// No structure: a plate that does not move (θ = 0), for the thermal models alone.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rigid;

impl StructuralModel for Rigid {
    fn size(&self) -> usize {
        0
    }
    fn names(&self) -> Vec<String> {
        Vec::new()
    }
    fn inertia(&self) -> f64 {
        1.0
    }
    #[inline]
    fn area_factor(&self, _q: &[f64]) -> f64 {
        1.0
    }
    #[inline]
    fn rates(&self, _load: f64, _q: &[f64], _out: &mut [f64]) -> f64 {
        1.0
    }
    fn positions(&self) -> usize {
        0
    }
    fn static_residual(&self, _moment: f64, _positions: &[f64], _out: &mut [f64]) {}
}

/// (sin θ, cos θ), the right-hand side's only transcendental functions.
///
/// For |θ| ≤ π/4, where the hinge lives, the minimax polynomials of fdlibm's sine and cosine
/// kernels (degrees 13 and 14, within an ulp or so of the library), evaluated with short
/// dependency chains; further out the library's `sin_cos`. Inline arithmetic keeps the hot path
/// free of calls into libm, which make every caller spill its registers.
#[inline]
pub fn sin_cos(theta: f64) -> (f64, f64) {
    sin_cos_as(theta)
}

/// [`sin_cos`] in the arithmetic of `T` (beyond π/4 the library's values, whatever `T`).
#[inline(always)]
pub(crate) fn sin_cos_as<T: Num>(theta: f64) -> (T, T) {
    if theta.abs() > std::f64::consts::FRAC_PI_4 {
        let (s, c) = theta.sin_cos();
        return (T::from(s), T::from(c));
    }
    sin_cos_kernel(T::from(theta))
}

/// The polynomials of [`sin_cos`] alone, for |θ| ≤ π/4 (no branch, so that a loop over SIMD
/// lanes vectorises; the caller handles the lanes beyond π/4).
#[inline(always)]
pub(crate) fn sin_cos_kernel<T: Num>(theta: T) -> (T, T) {
    const S: [f64; 6] = [
        -0.16666666666666632,
        0.00833333333332249,
        -0.0001984126982985795,
        2.7557313707070068e-06,
        -2.5050760253406863e-08,
        1.58969099521155e-10,
    ];
    const C: [f64; 6] = [
        0.0416666666666666,
        -0.001388888888887411,
        2.480158728947673e-05,
        -2.7557314351390663e-07,
        2.087572321298175e-09,
        -1.1359647557788195e-11,
    ];
    let z = theta * theta;
    let w = z * z;
    let w2 = w * w;
    // Estrin's scheme: three independent pairs, then two levels,
    // ((k0 + z k1) + w (k2 + z k3)) + w² (k4 + z k5), in that order. (A function, not a
    // closure: a closure is not always inlined, and out of line the lanes' intrinsics are calls.)
    #[inline(always)]
    fn estrin<T: Num>(z: T, w: T, w2: T, [k0, k1, k2, k3, k4, k5]: [T; 6]) -> T {
        let low = z.mul_add(k1, k0);
        let low = w.mul_add(z.mul_add(k3, k2), low);
        w2.mul_add(z.mul_add(k5, k4), low)
    }
    let ps = estrin(z, w, w2, S.map(T::from));
    let pc = estrin(z, w, w2, C.map(T::from));
    (
        (theta * z).mul_add(ps, theta),
        T::from(1.0) - w.neg_mul_add(pc, T::from(0.5) * z),
    )
}

/// Mechanical energy of the hinge in a constant moment field, J: kinetic + spring − work of M.
/// Conserved when c_d = 0 and M constant.
pub fn hinge_energy(
    panel: &Panel,
    model: HingeModel,
    theta: f64,
    theta_dot: f64,
    moment: f64,
) -> f64 {
    let kinetic = match model {
        HingeModel::Linear => 0.5 * panel.hinge_inertia() * theta_dot * theta_dot,
        HingeModel::Nonlinear => {
            let l = panel.half_arm();
            let s = theta.sin();
            panel.mass_per_length * l * l * l / 3.0 * theta_dot * theta_dot * (1.0 + 3.0 * s * s)
        }
    };
    kinetic + 0.5 * panel.hinge_stiffness * theta * theta - moment * theta
}

/// [`hinge_energy`] of a state given by a caller: θ within the hinge model's range, a moment
/// whose static angle is too, and a rate whose kinetic energy is a number (a rate of 1e160
/// rad/s would give inf).
pub fn checked_hinge_energy(
    panel: &Panel,
    model: HingeModel,
    theta: f64,
    theta_dot: f64,
    moment: f64,
) -> Result<f64> {
    check_hinge_angle("theta", theta)?;
    check_moment(panel, moment)?;
    let energy = hinge_energy(panel, model, theta, theta_dot, moment);
    if energy.is_finite() {
        Ok(energy)
    } else {
        Err(Error::invalid(
            "theta_dot",
            theta_dot,
            "must be finite, with a kinetic energy within a float's range",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_states_out_of_the_model_are_refused_by_component() {
        let p = Panel::paper();
        let hinge = Hinge::new(&p, HingeModel::Nonlinear);
        let most = hinge.max_start_rate();
        let w = p.natural_angular_frequency().max(p.damping_rate());
        assert_eq!(most, std::f64::consts::FRAC_PI_2 * w);
        let ok = [360.0, 350.0, 0.1, 0.99 * most];
        check_start_state(&ok, 2, Some(&hinge)).unwrap();
        for (bad, name) in [
            ([0.0, 350.0, 0.0, 0.0], "y0[0]"),
            ([360.0, -4.0, 0.0, 0.0], "y0[1]"),
            ([360.0, f64::NAN, 0.0, 0.0], "y0[1]"),
            ([360.0, 350.0, 2.0, 0.0], "y0[2]"),
            ([360.0, 350.0, 0.0, 1.01 * most], "y0[3]"),
            ([360.0, 350.0, 0.0, -1e6], "y0[3]"),
        ] {
            let err = check_start_state(&bad, 2, Some(&hinge)).unwrap_err();
            assert!(err.to_string().starts_with(name), "{err}");
        }
        // Temperatures alone (a thermal model): no hinge to check.
        check_start_state(&[300.0, 290.0], 2, None).unwrap();
        // A hinge asked for but missing is an error, not a panic.
        assert!(check_start_state(&[300.0, 290.0, 0.0], 2, Some(&hinge)).is_err());
    }

    #[test]
    fn a_half_of_the_hinge_model_stays_rigid() {
        // Its ends (ζ = 0 and 2l) stay 2l apart at every fold, and the point at ζ = l (the
        // middle) stays on the panel's axis at distance l cos θ.
        let p = Panel::paper();
        let arm = p.half_arm();
        for deg in [-90.0, -30.0, 0.0, 5.0, 45.0, 90.0] {
            let th = f64::to_radians(deg);
            let (x0, y0) = hinge_point(&p, 0.0, th);
            let (x1, y1) = hinge_point(&p, 2.0 * arm, th);
            let length = (x1 - x0).hypot(y1 - y0);
            assert!((length - 2.0 * arm).abs() < 1e-12 * arm, "{deg}: {length}");
            let (xm, ym) = hinge_point(&p, arm, th);
            assert!(xm.abs() < 1e-15 && (ym - arm * th.cos()).abs() < 1e-12 * arm);
        }
    }

    /// Units in the last place between a and b.
    fn ulps(a: f64, b: f64) -> f64 {
        (a - b).abs() / (f64::EPSILON * b.abs().max(f64::MIN_POSITIVE))
    }

    #[test]
    fn sin_cos_agrees_with_the_library_to_an_ulp() {
        let n = 200_001;
        let mut worst: f64 = 0.0;
        for i in 0..n {
            // 1.2·[−π/4, π/4] also crosses into the library branch on both sides.
            let x = (2.0 * i as f64 / (n - 1) as f64 - 1.0) * 1.2 * std::f64::consts::FRAC_PI_4;
            let (s, c) = sin_cos(x);
            if x != 0.0 {
                worst = worst.max(ulps(s, x.sin()));
            } else {
                assert_eq!(s, 0.0);
            }
            worst = worst.max(ulps(c, x.cos()));
        }
        for x in [
            1e-300,
            -1e-8,
            1e-3,
            0.085,
            0.5,
            -std::f64::consts::FRAC_PI_4,
            3.0,
            -40.0,
        ] {
            let (s, c) = sin_cos(x);
            worst = worst.max(ulps(s, x.sin())).max(ulps(c, x.cos()));
        }
        assert!(worst <= 1.0, "worst difference {worst} ulp");
    }

    #[test]
    fn models_agree_for_small_angles() {
        let p = Panel::paper();
        let a = hinge_acceleration(&p, HingeModel::Nonlinear, 10.0, 1e-6, 1e-6);
        let b = hinge_acceleration(&p, HingeModel::Linear, 10.0, 1e-6, 1e-6);
        assert!((a - b).abs() < 1e-9 * b.abs());
    }

    #[test]
    fn static_equilibrium_is_moment_over_stiffness() {
        let p = Panel::paper();
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            let th = 400.0 / p.hinge_stiffness;
            assert!(hinge_acceleration(&p, model, 400.0, th, 0.0).abs() < 1e-15);
        }
    }

    #[test]
    fn energy_rate_is_zero_along_undamped_motion() {
        // dE/dt = ∂E/∂θ θ̇ + ∂E/∂θ̇ θ̈ must vanish for c_d = 0 (checks eq. 20 against its Lagrangian).
        let p = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            let (th, om, m) = (0.4, 0.3, 250.0);
            let acc = hinge_acceleration(&p, model, m, th, om);
            let eps = 1e-6;
            let de_dth = (hinge_energy(&p, model, th + eps, om, m)
                - hinge_energy(&p, model, th - eps, om, m))
                / (2.0 * eps);
            let de_dom = (hinge_energy(&p, model, th, om + eps, m)
                - hinge_energy(&p, model, th, om - eps, m))
                / (2.0 * eps);
            let rate = de_dth * om + de_dom * acc;
            assert!(rate.abs() < 1e-5 * (de_dth * om).abs(), "{model:?}: {rate}");
        }
    }

    #[test]
    fn checked_hinge_energy_refuses_states_beyond_the_model_and_agrees_within() {
        let p = Panel::paper();
        let m = HingeModel::Nonlinear;
        let name = |r: Result<f64>| match r {
            Err(Error::InvalidParameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(
            name(checked_hinge_energy(&p, m, 1e300, 0.0, 400.0)),
            "theta"
        );
        assert_eq!(
            name(checked_hinge_energy(&p, m, 0.1, 1e200, 400.0)),
            "theta_dot"
        );
        assert_eq!(name(checked_hinge_energy(&p, m, 0.1, 0.0, 1e300)), "moment");
        let e = checked_hinge_energy(&p, m, 0.1, 0.02, 400.0).unwrap();
        assert_eq!(e, hinge_energy(&p, m, 0.1, 0.02, 400.0));
    }
}
