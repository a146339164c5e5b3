//! Stability maps: the flutter growth rate over a grid of two panel parameters, one eigen-analysis
//! per grid point, computed in parallel on rayon. Every point is independent and the result is
//! collected in grid order, so it does not depend on the number of threads.

use crate::analysis::flutter::{analyse, check_flux};
use crate::error::{Error, Result};
use crate::inputs::panel::Panel;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use rayon::prelude::*;

/// One axis of a map: a panel field and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    pub name: String,
    pub values: Vec<f64>,
}

/// Growth rate and frequency on the grid, row-major with y along rows: index `iy * nx + ix`.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityMap {
    pub nx: usize,
    pub ny: usize,
    /// Largest real part of the eigenvalues, 1/s.
    pub growth_rate: Vec<f64>,
    /// Frequency of the oscillatory pair, Hz.
    pub frequency_hz: Vec<f64>,
}

fn check_axis(which: &str, axis: &Axis) -> Result<()> {
    if !Panel::FIELDS.contains(&axis.name.as_str()) {
        return Err(Error::invalid(
            which,
            format!("{:?}", axis.name),
            &format!(
                "is not a panel parameter; one of {}",
                Panel::FIELDS.join(", ")
            ),
        ));
    }
    if axis.values.is_empty() {
        return Err(Error::invalid(
            which,
            &axis.name,
            "needs at least one value",
        ));
    }
    Ok(())
}

/// The flutter growth rate of `panel` with its fields `x.name` and `y.name` set to every pair of
/// values, at the solar flux factor `flux`.
pub fn stability_map(
    panel: &Panel,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
    x: &Axis,
    y: &Axis,
    cancel: &crate::cancel::Cancel,
) -> Result<StabilityMap> {
    check_flux(flux)?;
    check_axis("x", x)?;
    check_axis("y", y)?;
    if x.name == y.name {
        return Err(Error::invalid(
            "y",
            format!("{:?}", y.name),
            "must differ from the x parameter",
        ));
    }
    // Every grid panel is checked before the parallel work, so errors name the bad value.
    let (nx, ny) = (x.values.len(), y.values.len());
    let mut panels = Vec::with_capacity(nx * ny);
    for &yv in &y.values {
        for &xv in &x.values {
            let mut p = *panel;
            p.set(&x.name, xv)?;
            p.set(&y.name, yv)?;
            p.validate()?;
            panels.push(p);
        }
    }
    let results: Vec<(f64, f64)> = panels
        .par_iter()
        .map(|p| {
            // Polled once a grid point (an eigen-analysis, well under a millisecond).
            cancel.check()?;
            analyse(p, model, coupling, flux).map(|a| (a.growth_rate, a.frequency_hz))
        })
        .collect::<Result<_>>()?;
    let (growth_rate, frequency_hz) = results.into_iter().unzip();
    Ok(StabilityMap {
        nx,
        ny,
        growth_rate,
        frequency_hz,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::cancel::Cancel;

    fn axis(name: &str, values: &[f64]) -> Axis {
        Axis {
            name: name.into(),
            values: values.to_vec(),
        }
    }

    /// The map of `p` over `x` and `y` at the full flux, projected area.
    fn map(p: &Panel, model: HingeModel, x: &Axis, y: &Axis) -> Result<StabilityMap> {
        let coupling = Coupling::ProjectedArea;
        stability_map(p, model, coupling, 1.0, x, y, &Cancel::new())
    }

    #[test]
    fn map_matches_point_by_point_analysis() {
        let p = Panel::paper();
        let x = axis("damping", &[0.0, 1.0, 3.0]);
        let y = axis("conductance", &[10.0, 25.0]);
        let m = map(&p, HingeModel::Nonlinear, &x, &y).unwrap();
        assert_eq!((m.nx, m.ny), (3, 2));
        for (iy, &k) in y.values.iter().enumerate() {
            for (ix, &cd) in x.values.iter().enumerate() {
                let q = Panel {
                    damping: cd,
                    conductance: k,
                    ..p
                };
                let a = analyse(&q, HingeModel::Nonlinear, Coupling::ProjectedArea, 1.0).unwrap();
                assert_eq!(m.growth_rate[iy * 3 + ix], a.growth_rate);
                assert_eq!(m.frequency_hz[iy * 3 + ix], a.frequency_hz);
            }
        }
    }

    #[test]
    fn result_does_not_depend_on_the_number_of_threads() {
        let p = Panel::paper();
        let x = axis("damping", &[0.0, 0.7, 1.4, 2.1, 2.8, 3.5]);
        let y = axis("thickness", &[0.02, 0.03, 0.04, 0.05, 0.06]);
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| map(&p, HingeModel::Nonlinear, &x, &y).unwrap())
        };
        assert_eq!(run(1), run(3));
    }

    #[test]
    fn bad_axes_are_refused_by_name() {
        let p = Panel::paper();
        let run = |x: &Axis, y: &Axis| map(&p, HingeModel::Linear, x, y).unwrap_err().to_string();
        let good = axis("damping", &[1.0]);
        assert!(run(&axis("dampng", &[1.0]), &good).contains("dampng"));
        assert!(run(&good, &axis("damping", &[2.0])).starts_with("y"));
        assert!(run(&good, &axis("conductance", &[-1.0])).starts_with("conductance"));
        assert!(run(&good, &axis("conductance", &[])).starts_with("y"));
    }
}
