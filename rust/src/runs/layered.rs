//! Runs of the N-node laminate on the hinge: its ODE systems in orbit, one transient, runs of
//! many orbits with their per-orbit summaries.

use crate::analysis::layered::{equilibrium, equilibrium_loaded, start_state};
use crate::error::{Error, Result};
use crate::inputs::heating::{Loads, Optics};
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::conduction::Conduction;
use crate::models::coupled::{Coupling, Sunlight};
use crate::models::hinge::{Hinge, HingeModel};
use crate::models::layered::{Layered, Thermal, FAST_MODE_FACTOR};
use crate::numerics::integrate::{Dyn, OdeSystem, State};
use nalgebra::allocator::Allocator;
use nalgebra::{Const, DVector, DefaultAllocator, Dim, SVector};

/// The N-node system in orbit: the illumination of the current segment drives it, with the
/// orbit's Earth heating and the attitude's incidence on the outer nodes when it has them.
#[derive(Debug, Clone)]
pub struct LayeredOrbit {
    pub system: Layered,
    pub(crate) sun: Sunlight,
}

impl LayeredOrbit {
    /// The system on `orbit`, its outer nodes absorbing every load of the orbit with `panel`'s
    /// optics.
    pub fn new(system: Layered, panel: &Panel, orbit: Orbit) -> Self {
        LayeredOrbit {
            system,
            sun: Sunlight::with_optics(orbit, Optics::of(panel)),
        }
    }

    /// dy/dt at time t inside the current segment (written into `dy`): the front's sunlight
    /// alone on the paper's orbits (their arithmetic kept), else every load.
    #[inline]
    fn rhs_into(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        if self.sun.face_loads {
            self.system.rhs_at_loads(self.sun.loads(t), y, dy);
        } else {
            self.system.rhs_at_flux(self.sun.flux(t), y, dy);
        }
    }
}

impl OdeSystem<Dyn> for LayeredOrbit {
    #[inline]
    fn rhs(&self, t: f64, y: &State<Dyn>) -> State<Dyn> {
        let mut dy = DVector::zeros(y.len());
        self.rhs_into(t, y.as_slice(), dy.as_mut_slice());
        dy
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.sun.orbit.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.sun.enter(a, b);
    }
    fn check_span(&self, t0: f64, t1: f64) -> Result<()> {
        self.sun.check("the laminate's N-node model")?;
        crate::numerics::integrate::check_span(t0, t1)
    }
}

/// The N-node system on a state whose size S is known at compile time: the integrator's
/// vectors then live on the stack, with no allocation per evaluation (the run-time size `Dyn`
/// allocates every intermediate vector, which costs more than the physics of a small state).
struct Fixed<const S: usize>(LayeredOrbit);

impl<const S: usize> OdeSystem<Const<S>> for Fixed<S> {
    #[inline]
    fn rhs(&self, t: f64, y: &State<Const<S>>) -> State<Const<S>> {
        let mut dy = SVector::<f64, S>::zeros();
        self.0.rhs_into(t, y.as_slice(), dy.as_mut_slice());
        dy
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.0.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.0.enter_segment(a, b);
    }
    fn check_span(&self, t0: f64, t1: f64) -> Result<()> {
        self.0.check_span(t0, t1)
    }
}

/// A state vector of dimension `D` from its components.
fn state_of<D: Dim>(v: &[f64]) -> State<D>
where
    DefaultAllocator: Allocator<D>,
{
    State::<D>::from_column_slice_generic(D::from_usize(v.len()), Const::<1>, v)
}

/// Calls `$run(system, state)` with the N-node system `$orb` on a compile-time state size when
/// its size is one of the common ones (slow-mode models keep a few modes; nodal models have a
/// few nodes), else on the run-time size.
macro_rules! on_fastest_state {
    ($orb:expr, $size:expr, $run:ident ( $($arg:expr),* )) => {
        match $size {
            3 => $run(&mut Fixed::<3>($orb), $($arg),*),
            4 => $run(&mut Fixed::<4>($orb), $($arg),*),
            5 => $run(&mut Fixed::<5>($orb), $($arg),*),
            6 => $run(&mut Fixed::<6>($orb), $($arg),*),
            7 => $run(&mut Fixed::<7>($orb), $($arg),*),
            8 => $run(&mut Fixed::<8>($orb), $($arg),*),
            9 => $run(&mut Fixed::<9>($orb), $($arg),*),
            10 => $run(&mut Fixed::<10>($orb), $($arg),*),
            11 => $run(&mut Fixed::<11>($orb), $($arg),*),
            12 => $run(&mut Fixed::<12>($orb), $($arg),*),
            13 => $run(&mut Fixed::<13>($orb), $($arg),*),
            14 => $run(&mut Fixed::<14>($orb), $($arg),*),
            16 => $run(&mut Fixed::<16>($orb), $($arg),*),
            18 => $run(&mut Fixed::<18>($orb), $($arg),*),
            22 => $run(&mut Fixed::<22>($orb), $($arg),*),
            _ => { let mut dynamic = $orb; $run(&mut dynamic, $($arg),*) }
        }
    };
}

/// A sampled run of the N-node system, with the temperature of every node.
#[derive(Debug, Clone)]
pub struct LayeredRun {
    pub t: Vec<f64>,
    /// Number of nodes.
    pub nodes: usize,
    /// Node temperatures at each sample (sample-major: t.len() × nodes).
    pub temperatures: Vec<f64>,
    pub theta: Vec<f64>,
    pub theta_dot: Vec<f64>,
    pub moment: Vec<f64>,
    /// The illumination at each sample.
    pub sunlit: Vec<f64>,
    /// The flux reaching the front and the back face at each sample, W/m² (as
    /// [`crate::runs::request::CoupledRun::fluxes`]).
    pub fluxes: (Vec<f64>, Vec<f64>),
    pub stats: crate::numerics::integrate::Stats,
    /// The end state as node temperatures, θ, θ̇ (a run can resume from it).
    pub y_end: Vec<f64>,
    /// The integrator settings the run used.
    pub method: crate::numerics::integrate::Method,
    /// Where |θ| first passed the validity limit, when one was watched.
    pub crossing: Option<crate::runs::orbits::LimitCrossing>,
    /// Whether the run ended there.
    pub stopped: bool,
}

/// Integrates the N-node system over `t_span` from `y0` (node temperatures, θ, θ̇; default the
/// sunlit equilibrium at the start's solar flux) and samples it as `output` asks, watching
/// `limit` (see [`crate::runs::simulate::run_watched`]) and stopping within a step of `cancel`.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    panel: &Panel,
    conduction: Conduction,
    orbit: &Orbit,
    model: HingeModel,
    coupling: Coupling,
    method: &crate::numerics::integrate::Method,
    t_span: (f64, f64),
    y0: Option<&[f64]>,
    output: &crate::runs::simulate::Output,
    limit: Option<crate::runs::simulate::OnLimit>,
    cancel: &crate::cancel::Cancel,
) -> Result<LayeredRun> {
    let n = conduction.nodes();
    let start: Vec<f64> = match y0 {
        Some(v) => {
            check_start(panel, v, n)?;
            v.to_vec()
        }
        None => start_state(panel, &conduction, coupling, orbit, t_span.0)?,
    };
    let system = Layered::new(panel, conduction, model, coupling, FAST_MODE_FACTOR)?;
    let y_start = system.state_from_nodes(&start[..n], start[n], start[n + 1]);
    let size = y_start.len();
    let orb = LayeredOrbit::new(system.clone(), panel, *orbit);
    let m = system.thermal_size();
    // θ is the state's component m in every form of the system.
    let watch = limit.map(|l| l.on_component(m));
    let (t, y, stats, y_end, used, crossing) = on_fastest_state!(
        orb,
        size,
        sample_run(method, t_span, &y_start, output, watch.as_ref(), cancel)
    )?;
    let optics = Optics::of(panel);
    let loads = |t: f64| orbit.loads_at(t, &optics);
    let stopped = crossing.is_some() && watch.is_some_and(|l| l.stop);
    let mut run = LayeredRun {
        nodes: n,
        sunlit: t.iter().map(|&t| orbit.illumination(t)).collect(),
        fluxes: orbit.face_flux_samples(&t, optics.solar_constant),
        stopped,
        theta: y.iter().map(|v| v[m]).collect(),
        theta_dot: y.iter().map(|v| v[m + 1]).collect(),
        temperatures: Vec::with_capacity(t.len() * n),
        moment: Vec::with_capacity(t.len()),
        t,
        stats,
        y_end: Vec::new(),
        method: used,
        crossing: crossing
            .map(|(t, y)| crate::runs::orbits::LimitCrossing::in_run(orbit, t_span.0, t, y[m])),
    };
    for (t, y) in run.t.iter().zip(&y) {
        let temps = system.node_temperatures(loads(*t), y);
        run.moment.push(system.conduction.moment(&temps));
        run.temperatures.extend(temps);
    }
    let mut end = system.node_temperatures(loads(stats.t_end), &y_end);
    end.push(y_end[m]);
    end.push(y_end[m + 1]);
    run.y_end = end;
    Ok(run)
}

/// Samples of one run of `system`: times, states, counters, the end state, the settings used
/// and where the limit was first passed (t, state).
type Samples = (
    Vec<f64>,
    Vec<Vec<f64>>,
    crate::numerics::integrate::Stats,
    Vec<f64>,
    crate::numerics::integrate::Method,
    Option<(f64, Vec<f64>)>,
);

fn sample_run<D: Dim, S: OdeSystem<D>>(
    system: &mut S,
    method: &crate::numerics::integrate::Method,
    t_span: (f64, f64),
    y0: &[f64],
    output: &crate::runs::simulate::Output,
    limit: Option<&crate::runs::simulate::Limit>,
    cancel: &crate::cancel::Cancel,
) -> Result<Samples>
where
    DefaultAllocator: Allocator<D>,
{
    let traj = crate::runs::simulate::run_watched(
        system,
        method,
        t_span,
        state_of::<D>(y0),
        output,
        limit,
        cancel,
    )?;
    let y = traj.y.iter().map(|v| v.as_slice().to_vec()).collect();
    Ok((
        traj.t,
        y,
        traj.stats,
        traj.y_end.as_slice().to_vec(),
        traj.method,
        traj.crossing.map(|(t, y)| (t, y.as_slice().to_vec())),
    ))
}

/// The summaries' view of the N-node system.
pub(crate) struct LayeredView {
    system: Layered,
    panel: Panel,
    orbit: Orbit,
    coupling: Coupling,
    /// (from, to, s): the illumination s holds on [from, to) (between two breakpoints of a
    /// shadow without penumbra), so the reads of a step need not recompute the geometry.
    sunlit: std::cell::Cell<(f64, f64, f64)>,
    /// Whether the slow-mode model's points inside a step read M_T off the interpolant's slope
    /// (true but in the test that compares the two reads).
    slope_reads: bool,
}

impl LayeredView {
    pub(crate) fn new(system: Layered, panel: Panel, orbit: Orbit, coupling: Coupling) -> Self {
        LayeredView {
            system,
            panel,
            orbit,
            coupling,
            sunlit: std::cell::Cell::new((0.0, 0.0, 0.0)),
            slope_reads: true,
        }
    }

    /// Illumination s(t). Without a penumbra s is constant between breakpoints: it is taken at
    /// the middle of the interval that starts at t (a read exactly on a shadow boundary takes
    /// the side after it) and kept for the reads that follow inside that interval.
    fn illumination(&self, t: f64) -> f64 {
        let (from, to, s) = self.sunlit.get();
        if t >= from && t < to {
            return s;
        }
        if matches!(self.orbit.shadow, crate::inputs::orbit::Shadow::Penumbra) {
            return self.orbit.illumination(t);
        }
        let next = self.orbit.breakpoints(t, t + self.orbit.period);
        let to = next
            .into_iter()
            .find(|&b| b > t)
            .unwrap_or(t + self.orbit.period);
        let s = self.orbit.illumination(0.5 * (t + to));
        self.sunlit.set((t, to, s));
        s
    }
}

impl crate::runs::orbits::SummaryView for LayeredView {
    fn theta_eq(&self, flux: f64) -> Result<f64> {
        Ok(equilibrium(&self.panel, &self.system.conduction, self.coupling, flux)?.theta)
    }
    fn theta_eq_loaded(&self, orbit: &Orbit, t: f64) -> Result<f64> {
        let loads = orbit.sunlit_loads(t, &Optics::of(&self.panel));
        Ok(equilibrium_loaded(&self.panel, &self.system.conduction, self.coupling, loads)?.theta)
    }
    fn angles(&self, t: f64, y: &[f64]) -> (f64, f64) {
        let s = self.illumination(t);
        let loads = if self.orbit.has_face_loads() {
            self.orbit.loads(t, s, &Optics::of(&self.panel))
        } else {
            Loads::sun(s * self.orbit.flux_scale(t))
        };
        let theta = y[self.system.thermal_size()];
        (
            theta,
            self.system.moment_of(loads, y) / self.panel.hinge_stiffness,
        )
    }
    fn rate(&self, y: &[f64]) -> f64 {
        y[self.system.thermal_size() + 1]
    }
    /// With the fast modes quasi-static, M_T costs a solve of the faces: read it off the
    /// step's end slope instead, except where t is a breakpoint of a shadow without penumbra
    /// (the slope there saw the illumination before it, the summaries read the one after).
    fn angles_at_end(&self, t: f64, y: &[f64], dy: &[f64]) -> (f64, f64) {
        if let Thermal::Modal(_) = self.system.thermal {
            self.illumination(t);
            let penumbra = matches!(self.orbit.shadow, crate::inputs::orbit::Shadow::Penumbra);
            if penumbra || self.sunlit.get().0 != t {
                let theta = y[self.system.thermal_size()];
                return (theta, self.system.quasi_static_from_rate(y, dy));
            }
        }
        self.angles(t, y)
    }
    /// With the fast modes quasi-static, inside a step too: M_T off the equation of motion with
    /// the interpolant's slope, which is within a relative (ωh)⁴/1920 of the system's (at the
    /// middle; 4e-7 at the default 40 steps per hinge period) — against a solve of the faces.
    fn reads_slopes(&self) -> bool {
        self.slope_reads && matches!(self.system.thermal, Thermal::Modal(_))
    }
    fn angles_inside(&self, _t: f64, y: &[f64], dy: &[f64]) -> (f64, f64) {
        let theta = y[self.system.thermal_size()];
        (theta, self.system.quasi_static_from_rate(y, dy))
    }
}

/// A run of the N-node system over whole orbits, as [`crate::runs::orbits::OrbitRunRequest`] is
/// for the two-layer model: `spec` with its conduction model, from `y0` = (node temperatures, θ,
/// θ̇).
#[derive(Debug, Clone)]
pub struct LayeredRunRequest {
    pub spec: crate::runs::orbits::OrbitRunSpec,
    pub conduction: Conduction,
    pub y0: Vec<f64>,
}

/// Per-orbit summaries of the N-node system (as [`crate::runs::orbits::run_orbits`]); the end state
/// is returned as (node temperatures, θ, θ̇).
pub fn run_orbits(
    req: &LayeredRunRequest,
    cancel: &crate::cancel::Cancel,
) -> Result<LayeredSummaries> {
    run_orbits_reading(req, cancel, true)
}

/// [`run_orbits`], the points inside a step read off the interpolant's slope or not.
pub(crate) fn run_orbits_reading(
    req: &LayeredRunRequest,
    cancel: &crate::cancel::Cancel,
    slope_reads: bool,
) -> Result<LayeredSummaries> {
    let s = &req.spec;
    check_start(&s.panel, &req.y0, req.conduction.nodes())?;
    let (system, start) = req.system()?;
    let mut view = LayeredView::new(system.clone(), s.panel, s.orbit, s.coupling);
    view.slope_reads = slope_reads;
    let orb = LayeredOrbit::new(system.clone(), &s.panel, s.orbit);
    let size = start.len();
    let theta_index = system.thermal_size();
    let mut run = on_fastest_state!(
        orb,
        size,
        summarised_run(&start, theta_index, req, view, cancel)
    )?;
    run.y_end = req.nodal(&system, run.stats.t_end, &run.y_end);
    Ok(run)
}

impl LayeredRunRequest {
    /// The system of the request (its slow conduction modes) and y0 in its coordinates.
    pub(crate) fn system(&self) -> Result<(Layered, Vec<f64>)> {
        let n = self.conduction.nodes();
        let system = Layered::new(
            &self.spec.panel,
            self.conduction.clone(),
            self.spec.model,
            self.spec.coupling,
            FAST_MODE_FACTOR,
        )?;
        let start = system.state_from_nodes(&self.y0[..n], self.y0[n], self.y0[n + 1]);
        Ok((system, start))
    }

    /// The same request of the two-layer model (whose state is that of two nodes on a plain
    /// panel: `y0` = (T_front, T_back, θ, θ̇), checked by the caller).
    pub fn two_layer(&self) -> crate::runs::orbits::OrbitRunRequest {
        crate::runs::orbits::OrbitRunRequest {
            spec: self.spec,
            y0: nalgebra::Vector4::from_column_slice(&self.y0),
        }
    }

    /// A state `y` of `system` at time t as (node temperatures, θ, θ̇).
    pub(crate) fn nodal(&self, system: &Layered, t: f64, y: &[f64]) -> Vec<f64> {
        let m = system.thermal_size();
        let loads = self.spec.orbit.loads_at(t, &Optics::of(&self.spec.panel));
        let mut out = system.node_temperatures(loads, y);
        out.extend([y[m], y[m + 1]]);
        out
    }
}

/// Per-orbit summaries of the N-node system, the end state as a plain vector.
pub struct LayeredSummaries {
    pub summaries: Vec<crate::runs::orbits::OrbitSummary>,
    pub stats: crate::numerics::integrate::Stats,
    /// Node temperatures, θ, θ̇.
    pub y_end: Vec<f64>,
    pub crossing: Option<crate::runs::orbits::LimitCrossing>,
}

/// The summaries of any model's run (a two-layer [`crate::runs::orbits::OrbitRun`] among them), the
/// end state as a plain vector.
impl<D: Dim> From<crate::runs::orbits::Summarised<D>> for LayeredSummaries
where
    DefaultAllocator: Allocator<D>,
{
    fn from(run: crate::runs::orbits::Summarised<D>) -> Self {
        LayeredSummaries {
            summaries: run.summaries,
            stats: run.stats,
            y_end: run.y_end.as_slice().to_vec(),
            crossing: run.crossing,
        }
    }
}

/// The summarised run of `req` on `system` (one of [`on_fastest_state`]'s) from `y0`.
fn summarised_run<D: Dim, S: OdeSystem<D>>(
    system: &mut S,
    y0: &[f64],
    theta_index: usize,
    req: &LayeredRunRequest,
    view: LayeredView,
    cancel: &crate::cancel::Cancel,
) -> Result<LayeredSummaries>
where
    DefaultAllocator: Allocator<D>,
{
    let y0 = state_of::<D>(y0);
    let run =
        crate::runs::orbits::run_summarised(system, view, &req.spec, y0, theta_index, cancel)?;
    Ok(run.into())
}

/// Checks a start state of node temperatures, θ and θ̇: its size here, its values as every
/// start state's ([`crate::models::hinge::check_start_state`]).
pub(crate) fn check_start(panel: &Panel, v: &[f64], n: usize) -> Result<()> {
    if v.len() != n + 2 {
        return Err(Error::invalid(
            "y0",
            format!("{} components", v.len()),
            &format!(
                "must hold the {n} node temperatures, θ and θ̇ ({} values)",
                n + 2
            ),
        ));
    }
    // The bound on θ̇ is the same for both hinge models: the linear one stands for either.
    let hinge = Hinge::new(panel, HingeModel::Linear);
    crate::models::hinge::check_start_state(v, n, Some(&hinge))
}
