//! What a caller asks of the engine, one request type per kind of run, and the choice of the
//! engine that runs it, made here once: a transient ([`RunRequest`]: the paper's two layers with
//! the state size known at compile time, any registered thermal model, or a laminate's N-node
//! model) and runs of whole orbits with per-orbit summaries ([`OrbitsRequest`]: two layers or a
//! laminate, each by its own request, hinge-resolved or by the hybrid propagator).

use crate::cancel::Cancel;
use crate::error::Result;
use crate::inputs::heating::Optics;
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::conduction::Conduction;
use crate::models::coupled::{Coupled, Coupling};
use crate::models::hinge::{Hinge, HingeModel, StructuralModel};
use crate::models::thermal::ThermalModel;
use crate::numerics::integrate::{Dyn, Method, Stats};
use crate::runs::hybrid::{HybridRun, HybridSettings};
use crate::runs::layered::{LayeredRun, LayeredRunRequest, LayeredSummaries};
use crate::runs::orbits::{LimitCrossing, OrbitRunRequest};
use crate::runs::simulate::{run_watched, state_from, TransientSettings};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim};

/// The through-thickness model of a run.
#[derive(Debug, Clone)]
pub enum ThermalChoice {
    /// The thermal model registered for this number of layers ([`crate::models::thermal_model`]).
    Layers(u32),
    /// A laminate's N-node conduction model ([`crate::runs::layered`]).
    Laminate(Conduction),
}

/// One transient: the panel in its orbit, its thermal model on the hinge, the integrator, where
/// to report, the start (default: the steady state at the start's flux) and the validity limit
/// to watch.
#[derive(Debug, Clone)]
pub struct RunRequest {
    pub panel: Panel,
    pub orbit: Orbit,
    pub thermal: ThermalChoice,
    pub model: HingeModel,
    pub coupling: Coupling,
    pub settings: TransientSettings,
}

/// A sampled run of a coupled system (or of a thermal model alone): every state component by
/// its model's name, the thermal moment and the illumination at each sample.
#[derive(Debug, Clone)]
pub struct CoupledRun {
    pub t: Vec<f64>,
    pub names: Vec<String>,
    /// Component `i` of every sample, in the order of `names`.
    pub columns: Vec<Vec<f64>>,
    pub moment: Vec<f64>,
    pub sunlit: Vec<f64>,
    /// The flux reaching the front and the back face at each sample, W/m² (sunlight, albedo
    /// and Earth infrared on the flat panel in its attitude, the deflection's projected-area
    /// factor not applied); None for a system without the panel's optics.
    pub fluxes: Option<(Vec<f64>, Vec<f64>)>,
    pub stats: Stats,
    /// The state at `stats.t_end`.
    pub y_end: Vec<f64>,
    /// The integrator and the settings the run used.
    pub method: Method,
    /// Where θ first passed the validity limit, when one was watched.
    pub crossing: Option<LimitCrossing>,
    /// Whether the run ended there.
    pub stopped: bool,
}

/// What a transient gives, by the engine that ran it.
#[derive(Debug, Clone)]
pub enum Transient {
    Coupled(CoupledRun),
    /// The N-node run, with its node temperatures sample by sample.
    Layered(LayeredRun),
}

/// Runs `req` on its engine, stopping within a step of `cancel`.
pub fn simulate(req: RunRequest, cancel: &Cancel) -> Result<Transient> {
    let RunRequest {
        panel,
        orbit,
        thermal,
        model,
        coupling,
        settings,
    } = req;
    let layers = match thermal {
        ThermalChoice::Layers(n) => n,
        ThermalChoice::Laminate(c) => {
            let run = crate::runs::layered::simulate(
                &panel,
                c,
                &orbit,
                model,
                coupling,
                &settings.method,
                settings.span,
                settings.y0.as_deref(),
                &settings.output,
                settings.limit,
                cancel,
            )?;
            return Ok(Transient::Layered(run));
        }
    };
    let run = if layers == 2 {
        // The paper's model, its state size known at compile time.
        let sys = Coupled::new(panel, orbit, model, coupling);
        coupled_run(sys, settings, cancel)?
    } else {
        let thermal = crate::models::thermal_model(&panel, layers)?;
        let n = thermal.size() + 2;
        let structure = Hinge::new(&panel, model);
        let sys = Coupled::compose(thermal, structure, orbit, coupling, Dyn(n))?
            .with_optics(Optics::of(&panel));
        coupled_run(sys, settings, cancel)?
    };
    Ok(Transient::Coupled(run))
}

/// Runs a coupled system (or a thermal model alone) as `settings` say, from their `y0` (default:
/// its steady state at the start's flux), watching θ against their `limit` when the system has a
/// θ.
pub fn coupled_run<T, S, D>(
    mut sys: Coupled<T, S, D>,
    settings: TransientSettings,
    cancel: &Cancel,
) -> Result<CoupledRun>
where
    T: ThermalModel,
    S: StructuralModel,
    D: Dim,
    DefaultAllocator: Allocator<D>,
{
    let span = settings.span;
    let orbit = *sys.orbit();
    let y_start = match settings.y0 {
        Some(v) => {
            let y = state_from(&v, sys.dim())?;
            sys.check_start(&y)?;
            y
        }
        None => sys.sunlit_steady_state(span.0)?,
    };
    let names = sys.names();
    // The limit is on θ, the structure's first state (a thermal model alone has none).
    let theta = names.iter().position(|n| n == "theta");
    let watch = settings.limit.zip(theta).map(|(l, i)| l.on_component(i));
    let (method, output) = (&settings.method, &settings.output);
    let traj = run_watched(
        &mut sys,
        method,
        span,
        y_start,
        output,
        watch.as_ref(),
        cancel,
    )?;
    let crossing = traj
        .crossing
        .as_ref()
        .zip(theta)
        .map(|((t, y), i)| LimitCrossing::in_run(&orbit, span.0, *t, y[i]));
    Ok(CoupledRun {
        columns: (0..names.len()).map(|i| traj.column(i)).collect(),
        moment: traj.y.iter().map(|y| sys.moment(y)).collect(),
        sunlit: traj.t.iter().map(|&t| orbit.illumination(t)).collect(),
        fluxes: sys
            .solar_constant()
            .map(|c| orbit.face_flux_samples(&traj.t, c)),
        stopped: crossing.is_some() && watch.is_some_and(|l| l.stop),
        crossing,
        names,
        stats: traj.stats,
        y_end: traj.y_end.as_slice().to_vec(),
        method: traj.method,
        t: traj.t,
    })
}

/// Whole orbits from a start state, summarised orbit by orbit: the model's own request, and
/// the hybrid propagator's settings (None: the hinge-resolved integration, which is also the
/// hybrid's fallback).
pub struct OrbitsRequest {
    pub model: OrbitsModel,
    pub hybrid: Option<HybridSettings>,
}

/// The model a run of orbits integrates.
pub enum OrbitsModel {
    /// The paper's two layers on the hinge.
    TwoLayer(OrbitRunRequest),
    /// A laminate's N-node model on the hinge.
    Laminate(LayeredRunRequest),
}

/// The summaries of a run of orbits and, for a hybrid run, how it split the simulated time.
pub struct OrbitsRun {
    pub summaries: LayeredSummaries,
    pub split: Option<HybridRun>,
}

/// Runs `req` on its engine, stopping within a step of `cancel`.
pub fn run_orbits(req: &OrbitsRequest, cancel: &Cancel) -> Result<OrbitsRun> {
    Ok(match (&req.model, &req.hybrid) {
        (OrbitsModel::Laminate(run), None) => OrbitsRun {
            summaries: crate::runs::layered::run_orbits(run, cancel)?,
            split: None,
        },
        (OrbitsModel::Laminate(run), Some(settings)) => {
            let out = crate::runs::hybrid::layered::run_orbits_hybrid(run, settings, cancel)?;
            OrbitsRun {
                summaries: out.run,
                split: Some(out.split),
            }
        }
        (OrbitsModel::TwoLayer(run), hybrid) => {
            let hinge = Hinge::new(&run.spec.panel, run.spec.model);
            crate::models::hinge::check_start_state(run.y0.as_slice(), 2, Some(&hinge))?;
            match hybrid {
                None => OrbitsRun {
                    summaries: crate::runs::orbits::run_orbits_cancellable(run, cancel)?.into(),
                    split: None,
                },
                Some(settings) => {
                    let out = crate::runs::hybrid::run_orbits_hybrid(run, settings, cancel)?;
                    // The run is copied (one summary per orbit) so that the counters keep theirs.
                    OrbitsRun {
                        summaries: out.run.clone().into(),
                        split: Some(out),
                    }
                }
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::integrate::Tolerances;
    use crate::runs::simulate::{run, Output};

    fn request(thermal: ThermalChoice) -> RunRequest {
        RunRequest {
            panel: Panel::paper(),
            orbit: Orbit::geo_equinox(),
            thermal,
            model: HingeModel::Nonlinear,
            coupling: Coupling::ProjectedArea,
            settings: TransientSettings {
                method: Method::Dopri5(Tolerances::default()),
                span: (0.0, 3000.0),
                output: Output::Every(100.0),
                y0: None,
                limit: None,
            },
        }
    }

    #[test]
    fn a_two_layer_request_is_the_paper_model_run_directly() {
        let req = request(ThermalChoice::Layers(2));
        let Transient::Coupled(got) = simulate(req.clone(), &Cancel::new()).unwrap() else {
            panic!("two layers run on the coupled engine");
        };
        let mut sys = Coupled::new(req.panel, req.orbit, req.model, req.coupling);
        let y0 = sys.steady_state(req.orbit.flux_scale(0.0)).unwrap();
        let s = &req.settings;
        let want = run(&mut sys, &s.method, s.span, y0, &s.output).unwrap();
        assert_eq!(got.t, want.t);
        assert_eq!(got.names, ["T_front", "T_back", "theta", "theta_dot"]);
        for (i, column) in got.columns.iter().enumerate() {
            assert_eq!(*column, want.column(i), "{}", got.names[i]);
        }
        assert_eq!(got.stats, want.stats);
    }

    #[test]
    fn a_laminate_request_runs_the_n_node_engine() {
        let panel = Panel::paper();
        let c = Conduction::homogeneous(&panel, 5).unwrap();
        let req = request(ThermalChoice::Laminate(c.clone()));
        let Transient::Layered(got) = simulate(req.clone(), &Cancel::new()).unwrap() else {
            panic!("a laminate runs on the N-node engine");
        };
        let want = crate::runs::layered::simulate(
            &panel,
            c,
            &req.orbit,
            req.model,
            req.coupling,
            &req.settings.method,
            req.settings.span,
            None,
            &req.settings.output,
            None,
            &Cancel::new(),
        )
        .unwrap();
        assert_eq!((got.nodes, &got.t, &got.theta), (5, &want.t, &want.theta));
        assert_eq!(got.temperatures, want.temperatures);
    }

    #[test]
    fn a_start_of_the_wrong_size_is_refused_by_name() {
        let mut req = request(ThermalChoice::Layers(3));
        req.settings.y0 = Some(vec![300.0; 4]);
        let e = simulate(req, &Cancel::new()).unwrap_err();
        assert!(
            matches!(e, crate::error::Error::InvalidParameter { ref name, .. } if name == "y0"),
            "{e}"
        );
    }
}
