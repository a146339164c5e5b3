//! Dormand–Prince 8(5,3) with error control and its seventh-order continuous extension (the
//! method of Hairer, Nørsett & Wanner's DOP853), for a smooth system over one segment.
//!
//! Where each step carries costly work of its own (the slow-time path reads the hinge's ringing
//! over every step), an eighth-order step is worth its twelve stages: at the tolerances that hold
//! θ to a few 1e-8 rad it takes a fraction of Dormand–Prince 5(4)'s steps. The controller is the
//! usual one: the error from the fifth- and third-order estimators combined as Hairer does, scaled
//! by atol + rtol·max(|y_old|, |y_new|), new step h·min(10, 0.9·err^(−1/8)), shrink at most 5×,
//! no growth right after a rejection. A step is accepted only when its continuous extension also
//! holds the tolerance inside it ([`extension_error`]): between the ends of a long step on a
//! settling solution the extension's error can be many times the end's, and callers read there.
//! The first step is Hairer's estimate grown by trial steps not taken ([`first_step`]), so that a
//! segment does not spend its first accepted steps growing it ten-fold at a time.

// The tableau's coefficients as published, to 30 digits: rounding is the compiler's.
#![allow(clippy::excessive_precision)]

use super::dopri5::{initial_step, next_up, shrunk_step, step_too_small};
use super::{rms_scaled, OdeSystem, State, Stats, Tolerances};
use crate::error::{Error, Result};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim};
use std::ops::ControlFlow;

/// Stages of a step; the thirteenth is f(t1, y1), and three more build the continuous extension.
const STAGES: usize = 12;
const EXTENDED: usize = 16;

/// The nodes c of the sixteen stages.
pub(crate) const C: [f64; EXTENDED] = [
    0.0,
    0.526001519587677318785587544488e-1,
    0.789002279381515978178381316732e-1,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    1.0 / 3.0,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
];

/// Row s of the tableau: the weights a_sj of the slopes j < s (row 12 is the solution's weights b).
pub(crate) const A: [&[f64]; EXTENDED] = [
    &[],
    &[5.26001519587677318785587544488e-2],
    &[
        1.97250569845378994544595329183e-2,
        5.91751709536136983633785987549e-2,
    ],
    &[
        2.95875854768068491816892993775e-2,
        0.0,
        8.87627564304205475450678981324e-2,
    ],
    &[
        2.41365134159266685502369798665e-1,
        0.0,
        -8.84549479328286085344864962717e-1,
        9.24834003261792003115737966543e-1,
    ],
    &[
        3.7037037037037037037037037037e-2,
        0.0,
        0.0,
        1.70828608729473871279604482173e-1,
        1.25467687566822425016691814123e-1,
    ],
    &[
        3.7109375e-2,
        0.0,
        0.0,
        1.70252211019544039314978060272e-1,
        6.02165389804559606850219397283e-2,
        -1.7578125e-2,
    ],
    &[
        3.70920001185047927108779319836e-2,
        0.0,
        0.0,
        1.70383925712239993810214054705e-1,
        1.07262030446373284651809199168e-1,
        -1.53194377486244017527936158236e-2,
        8.27378916381402288758473766002e-3,
    ],
    &[
        6.24110958716075717114429577812e-1,
        0.0,
        0.0,
        -3.36089262944694129406857109825,
        -8.68219346841726006818189891453e-1,
        2.75920996994467083049415600797e1,
        2.01540675504778934086186788979e1,
        -4.34898841810699588477366255144e1,
    ],
    &[
        4.77662536438264365890433908527e-1,
        0.0,
        0.0,
        -2.48811461997166764192642586468,
        -5.90290826836842996371446475743e-1,
        2.12300514481811942347288949897e1,
        1.52792336328824235832596922938e1,
        -3.32882109689848629194453265587e1,
        -2.03312017085086261358222928593e-2,
    ],
    &[
        -9.3714243008598732571704021658e-1,
        0.0,
        0.0,
        5.18637242884406370830023853209,
        1.09143734899672957818500254654,
        -8.14978701074692612513997267357,
        -1.85200656599969598641566180701e1,
        2.27394870993505042818970056734e1,
        2.49360555267965238987089396762,
        -3.0467644718982195003823669022,
    ],
    &[
        2.27331014751653820792359768449,
        0.0,
        0.0,
        -1.05344954667372501984066689879e1,
        -2.00087205822486249909675718444,
        -1.79589318631187989172765950534e1,
        2.79488845294199600508499808837e1,
        -2.85899827713502369474065508674,
        -8.87285693353062954433549289258,
        1.23605671757943030647266201528e1,
        6.43392746015763530355970484046e-1,
    ],
    &[
        5.42937341165687622380535766363e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        4.45031289275240888144113950566,
        1.89151789931450038304281599044,
        -5.8012039600105847814672114227,
        3.1116436695781989440891606237e-1,
        -1.52160949662516078556178806805e-1,
        2.01365400804030348374776537501e-1,
        4.47106157277725905176885569043e-2,
    ],
    &[
        5.61675022830479523392909219681e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        2.53500210216624811088794765333e-1,
        -2.46239037470802489917441475441e-1,
        -1.24191423263816360469010140626e-1,
        1.5329179827876569731206322685e-1,
        8.20105229563468988491666602057e-3,
        7.56789766054569976138603589584e-3,
        -8.298e-3,
    ],
    &[
        3.18346481635021405060768473261e-2,
        0.0,
        0.0,
        0.0,
        0.0,
        2.83009096723667755288322961402e-2,
        5.35419883074385676223797384372e-2,
        -5.49237485713909884646569340306e-2,
        0.0,
        0.0,
        -1.08347328697249322858509316994e-4,
        3.82571090835658412954920192323e-4,
        -3.40465008687404560802977114492e-4,
        1.41312443674632500278074618366e-1,
    ],
    &[
        -4.28896301583791923408573538692e-1,
        0.0,
        0.0,
        0.0,
        0.0,
        -4.69762141536116384314449447206,
        7.68342119606259904184240953878,
        4.06898981839711007970213554331,
        3.56727187455281109270669543021e-1,
        0.0,
        0.0,
        0.0,
        -1.39902416515901462129418009734e-3,
        2.9475147891527723389556272149,
        -9.15095847217987001081870187138,
    ],
];

/// The fifth-order error estimator's weights (of slopes 0..12).
const E5: [f64; STAGES] = [
    0.1312004499419488073250102996e-1,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.1225156446376204440720569753e1,
    -0.4957589496572501915214079952,
    0.1664377182454986536961530415e1,
    -0.3503288487499736816886487290,
    0.3341791187130174790297318841,
    0.8192320648511571246570742613e-1,
    -0.2235530786388629525884427845e-1,
];

/// The third-order estimator: b minus these weights, at slopes 0, 8 and 11.
const BHH: [(usize, f64); 3] = [
    (0, 0.244094488188976377952755905512),
    (8, 0.733846688281611857341361741547),
    (11, 0.220588235294117647058823529412e-1),
];

/// The continuous extension's coefficients r4..r7 (of the sixteen slopes, times h).
const DENSE: [[f64; EXTENDED]; 4] = [
    [
        -0.84289382761090128651353491142e1,
        0.0,
        0.0,
        0.0,
        0.0,
        0.56671495351937776962531783590,
        -0.30689499459498916912797304727e1,
        0.23846676565120698287728149680e1,
        0.21170345824450282767155149946e1,
        -0.87139158377797299206789907490,
        0.22404374302607882758541771650e1,
        0.63157877876946881815570249290,
        -0.88990336451333310820698117400e-1,
        0.18148505520854727256656404962e2,
        -0.91946323924783554000451984436e1,
        -0.44360363875948939664310572000e1,
    ],
    [
        0.10427508642579134603413151009e2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.24228349177525818288430175319e3,
        0.16520045171727028198505394887e3,
        -0.37454675472269020279518312152e3,
        -0.22113666853125306036270938578e2,
        0.77334326684722638389603898808e1,
        -0.30674084731089398182061213626e2,
        -0.93321305264302278729567221706e1,
        0.15697238121770843886131091075e2,
        -0.31139403219565177677282850411e2,
        -0.93529243588444783865713862664e1,
        0.35816841486394083752465898540e2,
    ],
    [
        0.19985053242002433820987653617e2,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.38703730874935176555105901742e3,
        -0.18917813819516756882830838328e3,
        0.52780815920542364900561016686e3,
        -0.11573902539959630126141871134e2,
        0.68812326946963000169666922661e1,
        -0.10006050966910838403183860980e1,
        0.77771377980534432092869265740,
        -0.27782057523535084065932004339e1,
        -0.60196695231264120758267380846e2,
        0.84320405506677161018159903784e2,
        0.11992291136182789328035130030e2,
    ],
    [
        -0.25693933462703749003312586129e2,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.15418974869023643374053993627e3,
        -0.23152937917604549567536039109e3,
        0.35763911791061412378285349910e3,
        0.93405324183624310003907691704e2,
        -0.37458323136451633156875139351e2,
        0.10409964950896230045147246184e3,
        0.29840293426660503123344363579e2,
        -0.43533456590011143754432175058e2,
        0.96324553959188282948394950600e2,
        -0.39177261675615439165231486172e2,
        -0.14972683625798562581422125276e3,
    ],
];

const SAFETY: f64 = 0.9;
const MAX_FACTOR: f64 = 10.0;
const ERROR_EXPONENT: f64 = -1.0 / 8.0;
/// A trial first step whose error is below this is grown before any step is taken
/// ([`first_step`]).
const PROBE_ERROR: f64 = 1e-4;
/// The most a first step is grown at one probe, and the number of probes.
const PROBE_FACTOR: f64 = 1e4;
const PROBES: usize = 4;

/// One accepted step [t0, t1] and its continuous extension, of order seven:
/// y(t0 + xh) = y0 + x(r0 + (1−x)(r1 + x(r2 + (1−x)(r3 + x(r4 + (1−x)(r5 + x r6)))))).
#[derive(Debug, Clone)]
pub struct Dop853Step<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub t0: f64,
    pub t1: f64,
    pub y0: State<D>,
    pub y1: State<D>,
    r: [State<D>; 7],
}

impl<D: Dim> Dop853Step<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// The continuous extension's value at t in [t0, t1].
    pub fn eval(&self, t: f64) -> State<D> {
        if t == self.t1 {
            return self.y1.clone();
        }
        let x = (t - self.t0) / (self.t1 - self.t0);
        let x1 = 1.0 - x;
        let [r0, r1, r2, r3, r4, r5, r6] = &self.r;
        let mut acc = r6 * x + r5;
        acc = acc * x1 + r4;
        acc = acc * x + r3;
        acc = acc * x1 + r2;
        acc = acc * x + r1;
        acc = acc * x1 + r0;
        &self.y0 + acc * x
    }

    /// Bounds on component i of the continuous extension over the step: its nested form
    /// evaluated in intervals, x and 1 − x each anywhere in [0, 1] (a level r + f·[lo, hi] with
    /// f ∈ [0, 1] lies in [r + min(0, lo), r + max(0, hi)]), to rounding. About the range of y0
    /// and y1, widened by the higher terms.
    pub fn bounds(&self, i: usize) -> (f64, f64) {
        let [r0, r1, r2, r3, r4, r5, r6] = &self.r;
        let (mut lo, mut hi) = (r6[i], r6[i]);
        for r in [r5, r4, r3, r2, r1, r0] {
            (lo, hi) = (r[i] + lo.min(0.0), r[i] + hi.max(0.0));
        }
        (self.y0[i] + lo.min(0.0), self.y0[i] + hi.max(0.0))
    }

    /// The continuous extension's time derivative at t in [t0, t1].
    pub fn slope(&self, t: f64) -> State<D> {
        let h = self.t1 - self.t0;
        let x = (t - self.t0) / h;
        let x1 = 1.0 - x;
        let [r0, r1, r2, r3, r4, r5, r6] = &self.r;
        // p = r5 + x r6, each level (value, derivative in x) from the one below.
        let (mut p, mut dp) = (r6 * x + r5, r6.clone());
        for (r, by_x) in [
            (r4, false),
            (r3, true),
            (r2, false),
            (r1, true),
            (r0, false),
        ] {
            if by_x {
                dp = &dp * x + &p;
                p = &p * x + r;
            } else {
                dp = &dp * x1 - &p;
                p = &p * x1 + r;
            }
        }
        // y = y0 + x p.
        (p + dp * x) / h
    }
}

/// y0 + h Σ_j a_j k_j over the slopes given so far.
#[inline(always)]
fn stage_state<D: Dim>(y0: &State<D>, h: f64, a: &[f64], k: &[State<D>]) -> State<D>
where
    DefaultAllocator: Allocator<D>,
{
    let mut y = y0.clone();
    for (aj, kj) in a.iter().zip(k) {
        if *aj != 0.0 {
            y.axpy(aj * h, kj, 1.0);
        }
    }
    y
}

/// Σ_j w_j k_j.
#[inline(always)]
fn combination<D: Dim>(w: &[f64], k: &[State<D>]) -> State<D>
where
    DefaultAllocator: Allocator<D>,
{
    let mut out = k[0].map(|_| 0.0);
    for (wj, kj) in w.iter().zip(k) {
        if *wj != 0.0 {
            out.axpy(*wj, kj, 1.0);
        }
    }
    out
}

/// The twelve stages of a trial step of size h from (t, y), f0 = f(t, y): the new state, the
/// slopes and the error norm (< 1 to accept).
#[inline(always)]
fn trial<D: Dim, S: OdeSystem<D>>(
    system: &S,
    t: f64,
    h: f64,
    y: &State<D>,
    f0: &State<D>,
    tol: &Tolerances,
) -> (State<D>, [State<D>; EXTENDED], f64)
where
    DefaultAllocator: Allocator<D>,
{
    // The slopes; those past the twelfth are filled when the step is accepted.
    let mut k: [State<D>; EXTENDED] = std::array::from_fn(|_| f0.clone());
    for s in 1..STAGES {
        let ys = stage_state(y, h, A[s], &k[..s]);
        k[s] = system.rhs(t + C[s] * h, &ys);
    }
    let y_new = stage_state(y, h, A[STAGES], &k[..STAGES]);
    // Hairer's error: the fifth-order estimate, damped where the third-order one is large.
    let weight = y.zip_map(&y_new, |u, v| {
        1.0 / (tol.atol + u.abs().max(v.abs()) * tol.rtol)
    });
    let err5 = combination(&E5, &k[..STAGES]).component_mul(&weight);
    let mut e3 = combination(A[STAGES], &k[..STAGES]);
    for (j, w) in BHH {
        e3.axpy(-w, &k[j], 1.0);
    }
    let err3 = e3.component_mul(&weight);
    let (s5, s3) = (err5.norm_squared(), err3.norm_squared());
    let err = if s5 == 0.0 && s3 == 0.0 {
        0.0
    } else {
        h * s5 / ((s5 + 0.01 * s3) * y.len() as f64).sqrt()
    };
    (y_new, k, err)
}

/// The accepted step from (t, y) to (t_new, y_new), the slopes `k` of its twelve stages: f(t_new,
/// y_new) and the extension's three more stages filled in `k`, and the step with its
/// continuous extension.
#[inline(always)]
fn extend<D: Dim, S: OdeSystem<D>>(
    system: &S,
    t: f64,
    t_new: f64,
    y: &State<D>,
    y_new: State<D>,
    k: &mut [State<D>; EXTENDED],
) -> Dop853Step<D>
where
    DefaultAllocator: Allocator<D>,
{
    let h = t_new - t;
    k[STAGES] = system.rhs(t_new, &y_new);
    for s in STAGES + 1..EXTENDED {
        let ys = stage_state(y, h, A[s], &k[..s]);
        k[s] = system.rhs(t + C[s] * h, &ys);
    }
    let diff = &y_new - y;
    let bspl = &k[0] * h - &diff;
    let r2 = &diff - &k[STAGES] * h - &bspl;
    let [d3, d4, d5, d6] = DENSE.map(|row| combination(&row, &k[..]) * h);
    Dop853Step {
        t0: t,
        t1: t_new,
        y0: y.clone(),
        y1: y_new,
        r: [diff, bspl, r2, d3, d4, d5, d6],
    }
}

/// The extension's error inside `step`, in units of the tolerance: h times its defect
/// y'(t) − f(t, y(t)) at a quarter and half of the step (the error is the defect integrated from
/// the step's start; on decaying and oscillating solutions this is within a few times of the
/// largest error inside the step, above it). Of order h⁸ like the extension's error.
fn extension_error<D: Dim, S: OdeSystem<D>>(
    system: &S,
    step: &Dop853Step<D>,
    tol: &Tolerances,
) -> f64
where
    DefaultAllocator: Allocator<D>,
{
    let h = step.t1 - step.t0;
    let scale = step
        .y0
        .zip_map(&step.y1, |u, v| tol.atol + u.abs().max(v.abs()) * tol.rtol);
    [0.25, 0.5]
        .map(|x| {
            let t = step.t0 + x * h;
            let defect = step.slope(t) - system.rhs(t, &step.eval(t));
            h * rms_scaled(&defect, &scale)
        })
        .into_iter()
        .fold(0.0, f64::max)
}

/// The first step from (t0, y0), f0 = f(t0, y0), towards t1, at most `limit`. Hairer's estimate for the eighth
/// order (the fifth-order estimator's error goes as h⁶ but the steps' as h⁸) is cautious: on a
/// solution smooth over many times that step it is a fraction of a second where tens of seconds
/// hold the tolerance, and the controller then grows it at most [`MAX_FACTOR`] a step, each
/// step carrying its caller's work. So trial steps are tried first, not taken: while one's
/// error is below [`PROBE_ERROR`] the step grows by the controller's own rule, the error going
/// as h⁸ (at most [`PROBE_FACTOR`] a trial, [`PROBES`] trials).
fn first_step<D: Dim, S: OdeSystem<D>>(
    system: &S,
    (t0, t1): (f64, f64),
    y0: &State<D>,
    f0: &State<D>,
    tol: &Tolerances,
    limit: f64,
    stats: &mut Stats,
) -> f64
where
    DefaultAllocator: Allocator<D>,
{
    let longest = (t1 - t0).min(tol.max_step).min(limit);
    let mut h = initial_step(7, system, t0, y0, f0, t1 - t0, tol, stats).min(longest);
    for _ in 0..PROBES {
        if h >= longest {
            break;
        }
        let (_, _, err) = trial(system, t0, h, y0, f0, tol);
        stats.n_rhs += (STAGES - 1) as u64;
        // NaN and a large error alike end the probes: the controller takes it from there.
        if err.is_nan() || err >= PROBE_ERROR {
            break;
        }
        let factor = if err == 0.0 {
            PROBE_FACTOR
        } else {
            PROBE_FACTOR.min(SAFETY * err.powf(ERROR_EXPONENT))
        };
        h = (h * factor).min(longest);
    }
    h
}

/// Integrates `system` over [t0, t1] (one segment: its right-hand side smooth there), telling
/// `on_step` each accepted step; it stops early on `ControlFlow::Break`. Returns the counters and
/// the state at `stats.t_end`.
pub fn solve<D: Dim, S: OdeSystem<D>>(
    system: &S,
    tol: &Tolerances,
    t0: f64,
    y0: State<D>,
    t1: f64,
    on_step: &mut dyn FnMut(&Dop853Step<D>) -> ControlFlow<()>,
) -> Result<(Stats, State<D>)>
where
    DefaultAllocator: Allocator<D>,
{
    solve_from_within(system, tol, t0, y0, t1, f64::INFINITY, on_step)
}

/// [`solve`] with its first step at most `first_limit` long: where the caller's own work over a
/// step needs it shorter than the solution's accuracy does at the start.
pub fn solve_from_within<D: Dim, S: OdeSystem<D>>(
    system: &S,
    tol: &Tolerances,
    t0: f64,
    y0: State<D>,
    t1: f64,
    first_limit: f64,
    on_step: &mut dyn FnMut(&Dop853Step<D>) -> ControlFlow<()>,
) -> Result<(Stats, State<D>)>
where
    DefaultAllocator: Allocator<D>,
{
    super::Method::Dopri5(*tol).validate()?;
    super::check_span(t0, t1)?;
    if let Some(i) = y0.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            "y0",
            y0[i],
            "every component must be finite",
        ));
    }
    let mut stats = Stats {
        t_end: t0,
        ..Stats::default()
    };
    let mut y = y0;
    let mut t = t0;
    let mut f0 = system.rhs(t, &y);
    stats.n_rhs += 1;
    let mut h_abs = first_step(system, (t0, t1), &y, &f0, tol, first_limit, &mut stats);
    while t < t1 {
        let min_step = 10.0 * (next_up(t) - t);
        h_abs = h_abs.max(min_step);
        let mut rejected = false;
        loop {
            if stats.n_steps + stats.n_rejected >= tol.max_steps {
                return Err(Error::Integration {
                    t,
                    reason: format!("max_steps = {} reached", tol.max_steps),
                });
            }
            let t_new = if t + h_abs >= t1 { t1 } else { t + h_abs };
            let h = t_new - t;
            let (y_new, mut k, err) = trial(system, t, h, &y, &f0, tol);
            stats.n_rhs += (STAGES - 1) as u64;
            // The extension is checked too: it is read inside the step, and there its error can
            // be many times the end's.
            let checked = (err < 1.0).then(|| {
                let step = extend(system, t, t_new, &y, y_new, &mut k);
                let dense = extension_error(system, &step, tol);
                (step, dense)
            });
            if checked.is_some() {
                stats.n_rhs += 6;
            }
            let err = checked.as_ref().map_or(err, |(_, dense)| err.max(*dense));
            if let (Some((step, _)), true) = (checked, err < 1.0) {
                // NaN fails this test, so a non-finite state is rejected and shrinks h.
                stats.n_steps += 1;
                y = step.y1.clone();
                f0 = k[STAGES].clone();
                t = t_new;
                stats.t_end = t;
                let mut factor = if err == 0.0 {
                    MAX_FACTOR
                } else {
                    MAX_FACTOR.min(SAFETY * err.powf(ERROR_EXPONENT))
                };
                if rejected {
                    factor = factor.min(1.0);
                }
                h_abs = (h * factor).min(tol.max_step);
                if on_step(&step).is_break() {
                    stats.stopped = t < t1;
                    return Ok((stats, y));
                }
                break;
            }
            stats.n_rejected += 1;
            h_abs = shrunk_step(h, err, ERROR_EXPONENT);
            rejected = true;
            if h_abs < min_step {
                return Err(step_too_small(t, h_abs, y.as_slice()));
            }
        }
    }
    Ok((stats, y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::integrate::dopri5;
    use crate::numerics::integrate::{Method, Observer};
    use nalgebra::{Vector1, Vector2, U1, U2};

    /// y'' = −y.
    struct Oscillator;
    impl OdeSystem<U2> for Oscillator {
        fn rhs(&self, _t: f64, y: &Vector2<f64>) -> Vector2<f64> {
            Vector2::new(y[1], -y[0])
        }
    }

    /// y' = cos t − y³: no closed form, smooth, non-linear, bounded.
    struct Riccati;
    impl OdeSystem<U1> for Riccati {
        fn rhs(&self, t: f64, y: &Vector1<f64>) -> Vector1<f64> {
            Vector1::new(t.cos() - y[0].powi(3))
        }
    }

    #[test]
    fn the_tableau_is_consistent() {
        for s in 1..EXTENDED {
            assert_eq!(A[s].len(), s);
            let sum: f64 = A[s].iter().sum();
            assert!((sum - C[s]).abs() < 1e-13, "row {s}: {sum} vs {}", C[s]);
        }
        let b: f64 = A[STAGES].iter().sum();
        assert!((b - 1.0).abs() < 1e-14);
        // The estimators weigh a constant slope by nothing.
        let e5: f64 = E5.iter().sum();
        let e3: f64 = b - BHH.iter().map(|(_, w)| w).sum::<f64>();
        assert!(e5.abs() < 1e-14 && e3.abs() < 1e-14, "{e5} {e3}");
    }

    /// One step of size h from (0, (1, 0)) on the oscillator: the error of its end and of its
    /// extension at 0.37 h.
    fn one_step(h: f64) -> (f64, f64) {
        let tol = Tolerances::default();
        let y0 = Vector2::new(1.0, 0.0);
        let f0 = Oscillator.rhs(0.0, &y0);
        let (y1, mut k, _) = trial(&Oscillator, 0.0, h, &y0, &f0, &tol);
        let step = extend(&Oscillator, 0.0, h, &y0, y1, &mut k);
        let exact = |t: f64| Vector2::new(t.cos(), -t.sin());
        (
            (step.y1 - exact(h)).norm(),
            (step.eval(0.37 * h) - exact(0.37 * h)).norm(),
        )
    }

    #[test]
    fn a_step_is_of_eighth_order_and_its_extension_of_seventh() {
        // Local errors O(h⁹) and O(h⁸): halving h divides them by 512 and 256.
        let (e1, m1) = one_step(0.4);
        let (e2, m2) = one_step(0.2);
        let (step_ratio, dense_ratio) = (e1 / e2, m1 / m2);
        assert!(
            (350.0..750.0).contains(&step_ratio),
            "{step_ratio} ({e1}, {e2})"
        );
        assert!(
            (170.0..380.0).contains(&dense_ratio),
            "{dense_ratio} ({m1}, {m2})"
        );
    }

    #[test]
    fn the_oscillator_over_many_periods_holds_the_tolerance_everywhere() {
        let tol = Tolerances {
            rtol: 1e-10,
            atol: 1e-10,
            max_step: f64::INFINITY,
            max_steps: 100_000,
        };
        let mut worst: f64 = 0.0;
        let mut steps = 0;
        let (stats, y1) = solve(
            &Oscillator,
            &tol,
            0.0,
            Vector2::new(1.0, 0.0),
            60.0,
            &mut |s| {
                steps += 1;
                for i in 0..=10 {
                    let t = s.t0 + (s.t1 - s.t0) * i as f64 / 10.0;
                    let e = (s.eval(t) - Vector2::new(t.cos(), -t.sin())).norm();
                    worst = worst.max(e);
                }
                ControlFlow::Continue(())
            },
        )
        .unwrap();
        assert_eq!(stats.n_steps, steps);
        assert!((y1 - Vector2::new(60f64.cos(), -60f64.sin())).norm() < 2e-8);
        assert!(worst < 2e-8, "{worst}");
    }

    /// y' = −y/45 + sin(ωt)/100: a thermal transient settling onto a slow drift.
    struct Settling(f64);
    impl OdeSystem<U1> for Settling {
        fn rhs(&self, t: f64, y: &Vector1<f64>) -> Vector1<f64> {
            Vector1::new(-y[0] / 45.0 + (self.0 * t).sin() / 100.0)
        }
    }

    fn settling_exact(w: f64, t: f64) -> f64 {
        // y = A e^{−t/τ} + (a sin ωt − b cos ωt), the forced part of y' = −y/τ + sin(ωt)/100.
        let tau = 45.0f64;
        let d = 1.0 / (tau * tau) + w * w;
        let (a, b) = (1.0 / (100.0 * tau * d), w / (100.0 * d));
        (1.0 + b) * (-t / tau).exp() + a * (w * t).sin() - b * (w * t).cos()
    }

    #[test]
    fn the_extension_holds_the_tolerance_inside_every_step() {
        // Without the extension's own check its error inside long steps of a settling
        // solution was ~20 times the tolerance the steps' ends hold.
        for (w, rtol) in [
            (1.0 / 300.0, 1e-5),
            (1.0 / 300.0, 1e-7),
            (1.0 / 300.0, 1e-9),
            (1e-4, 1e-5),
            (1e-4, 1e-7),
            (1e-4, 1e-9),
        ] {
            let tol = Tolerances {
                rtol,
                atol: 1e-3 * rtol,
                max_step: 600.0,
                max_steps: 100_000,
            };
            let mut worst: f64 = 0.0;
            solve(
                &Settling(w),
                &tol,
                0.0,
                Vector1::new(1.0),
                5000.0,
                &mut |s| {
                    // In the controller's units: each step's scale is that of its ends.
                    let scale = tol.atol + tol.rtol * s.y0[0].abs().max(s.y1[0].abs());
                    for i in 1..40 {
                        let t = s.t0 + (s.t1 - s.t0) * i as f64 / 40.0;
                        worst = worst.max((s.eval(t)[0] - settling_exact(w, t)).abs() / scale);
                    }
                    ControlFlow::Continue(())
                },
            )
            .unwrap();

            assert!(worst < 1.0, "rtol {rtol}: {worst} tolerances");
        }
    }

    /// Counts the steps of Dormand–Prince 5(4).
    struct Count(u64);
    impl<D: Dim> Observer<D> for Count
    where
        DefaultAllocator: Allocator<D>,
    {
        fn on_step(&mut self, _: &super::super::DenseStep<D>) -> ControlFlow<()> {
            self.0 += 1;
            ControlFlow::Continue(())
        }
    }

    #[test]
    fn it_agrees_with_dormand_prince_at_tight_tolerance_in_fewer_steps() {
        let tol = Tolerances {
            rtol: 1e-9,
            atol: 1e-12,
            max_step: f64::INFINITY,
            max_steps: 1_000_000,
        };
        let tight = Tolerances {
            rtol: 1e-13,
            atol: 1e-15,
            ..tol
        };
        let y0 = Vector1::new(0.5);
        let mut count = Count(0);
        let (_, reference) = crate::numerics::integrate::solve(
            &mut Riccati,
            &Method::Dopri5(tight),
            0.0,
            y0,
            30.0,
            &mut count,
        )
        .unwrap();
        let mut dp = Count(0);
        crate::numerics::integrate::solve(
            &mut Riccati,
            &Method::Dopri5(tol),
            0.0,
            y0,
            30.0,
            &mut dp,
        )
        .unwrap();
        let (stats, y1) = solve(&Riccati, &tol, 0.0, y0, 30.0, &mut |_| {
            ControlFlow::Continue(())
        })
        .unwrap();
        assert!(
            (y1[0] - reference[0]).abs() < 1e-8,
            "{} vs {}",
            y1[0],
            reference[0]
        );
        assert!(
            3 * stats.n_steps < dp.0,
            "{} steps against Dormand–Prince's {}",
            stats.n_steps,
            dp.0
        );
        let _ = dopri5::C;
    }

    #[test]
    fn a_non_finite_state_and_a_bad_tolerance_are_refused() {
        let tol = Tolerances {
            rtol: 1e-6,
            atol: 1e-6,
            max_step: 1.0,
            max_steps: 10,
        };
        let bad = Vector1::new(f64::NAN);
        assert!(solve(&Riccati, &tol, 0.0, bad, 1.0, &mut |_| {
            ControlFlow::Continue(())
        })
        .is_err());
        let loose = Tolerances { rtol: 0.5, ..tol };
        let e = solve(&Riccati, &loose, 0.0, Vector1::new(0.5), 1.0, &mut |_| {
            ControlFlow::Continue(())
        })
        .unwrap_err();
        assert!(format!("{e}").contains("rtol"));
        // Too few steps allowed.
        let short = Tolerances {
            max_step: 0.01,
            ..tol
        };
        assert!(
            solve(&Riccati, &short, 0.0, Vector1::new(0.5), 1.0, &mut |_| {
                ControlFlow::Continue(())
            })
            .is_err()
        );
    }

    #[test]
    fn a_steps_bounds_hold_its_extension() {
        let tol = Tolerances {
            rtol: 1e-8,
            atol: 1e-8,
            max_step: 10.0,
            max_steps: 100_000,
        };
        let mut steps = 0;
        solve(&Riccati, &tol, 0.0, Vector1::new(0.5), 30.0, &mut |s| {
            let (lo, hi) = s.bounds(0);
            let values: Vec<f64> = (0..=200)
                .map(|i| s.eval(s.t0 + (s.t1 - s.t0) * i as f64 / 200.0)[0])
                .collect();
            let (min, max) = values
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            // To rounding: y1 is the step's own, not the nested form's sum.
            let ulps = 4.0 * f64::EPSILON * lo.abs().max(hi.abs());
            assert!(
                lo - ulps <= min && max <= hi + ulps,
                "[{lo}, {hi}] vs [{min}, {max}]"
            );
            steps += 1;
            ControlFlow::Continue(())
        })
        .unwrap();
        assert!(steps > 5);
    }

    /// y' = −(y − cos(t/300)): a solution smooth on hundreds of seconds, from a start that
    /// already follows it.
    struct Slow;
    impl OdeSystem<U1> for Slow {
        fn rhs(&self, t: f64, y: &Vector1<f64>) -> Vector1<f64> {
            Vector1::new(-(y[0] - (t / 300.0).cos()) / 50.0)
        }
    }

    #[test]
    fn a_smooth_start_is_probed_to_the_step_the_solution_allows() {
        let tol = Tolerances {
            rtol: 1e-8,
            atol: 1e-8,
            max_step: 1e4,
            max_steps: 100_000,
        };
        let y0 = Vector1::new(1.0);
        let f0 = Slow.rhs(0.0, &y0);
        let mut stats = Stats::default();
        let estimate = initial_step(7, &Slow, 0.0, &y0, &f0, 3000.0, &tol, &mut stats);
        let run = |limit: f64| {
            let mut steps = Vec::new();
            let (st, y1) = solve_from_within(&Slow, &tol, 0.0, y0, 3000.0, limit, &mut |s| {
                steps.push(s.t1 - s.t0);
                ControlFlow::Continue(())
            })
            .unwrap();
            (st, y1, steps)
        };
        let (stats, y1, steps) = run(f64::INFINITY);
        // Far past the estimate, and the whole run as accurate as a tight one's.
        assert!(steps[0] > 100.0 * estimate, "{} vs {estimate}", steps[0]);
        let tight = Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
            ..tol
        };
        let (_, reference) = solve(&Slow, &tight, 0.0, y0, 3000.0, &mut |_| {
            ControlFlow::Continue(())
        })
        .unwrap();
        assert!(
            (y1[0] - reference[0]).abs() < 1e-7,
            "{}",
            y1[0] - reference[0]
        );
        // A first step asked shorter is kept so; the controller grows it from there.
        let (limited, _, short) = run(2.0);
        assert!(short[0] <= 2.0, "{}", short[0]);
        assert!(limited.n_steps > stats.n_steps);
    }
}
