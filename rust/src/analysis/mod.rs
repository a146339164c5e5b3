//! What the models say without a transient: the steady state, flutter (eigen-analysis and
//! critical damping), stability maps and the linear thermal response.

pub mod distributed;
pub mod flutter;
pub mod layered;
pub mod linear;
pub mod stability;
pub mod steady;
pub mod tube;
