//! The equations: heat balance (one node, two layers, conduction through N nodes), the hinge,
//! the coupled system, the N-node laminate, the free–free beam and the distributed panel.

pub mod beam;
pub mod conduction;
pub mod coupled;
pub mod distributed;
pub mod hinge;
pub mod layered;
pub mod spacecraft;
pub mod thermal;
pub mod tube;

use crate::error::{Error, Result};
use crate::inputs::panel::Panel;
use thermal::ThermalModel;

/// The thermal models by their number of layers (the `layers=` of the Python API). This is the
/// one place a new model is registered: the runs, steady states and bindings that take a
/// `layers` go through it.
pub fn thermal_model(panel: &Panel, layers: u32) -> Result<Box<dyn ThermalModel + Send + Sync>> {
    match layers {
        1 => Ok(Box::new(thermal::OneNode::new(panel))),
        2 => Ok(Box::new(thermal::TwoLayer::new(panel))),
        // N nodes through one homogeneous layer (the N-node conduction model).
        n if n >= 3 && (n as usize) <= conduction::MAX_NODES => Ok(Box::new(
            conduction::Conduction::homogeneous(panel, n as usize)?,
        )),
        other => Err(Error::invalid(
            "layers",
            other,
            &format!("must be between 1 and {}", conduction::MAX_NODES),
        )),
    }
}
