//! The equations: heat balance (one node, two layers, conduction through N nodes), the hinge,
//! the coupled system, the N-node laminate, the free–free beam and the distributed panel.

pub mod beam;
pub mod conduction;
pub mod coupled;
pub mod distributed;
pub mod hinge;
pub mod layered;
pub mod thermal;
