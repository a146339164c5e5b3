//! The validated inputs of every run: the panel, its laminate, the orbit.

pub mod attitude;
pub mod boom;
pub mod heating;
pub mod laminate;
pub mod orbit;
pub mod panel;
