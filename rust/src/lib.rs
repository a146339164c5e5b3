//! thermojitter: thermally induced vibration ("thermal jitter") and thermal flutter of long, thin
//! spacecraft appendages. A two-layer thermal model of a Sun-pointing plate in orbit, two-way
//! coupled to a one-degree-of-freedom hinge model of its first bending mode (Parisse & Angeletti
//! 2024), integrated through eclipses.
//!
//! The engine is plain Rust; the Python bindings live in `bindings` behind the `python` feature.

pub mod analysis;
pub mod cancel;
pub mod error;
pub mod inputs;
pub mod models;
pub mod numerics;
pub mod runs;

#[cfg(test)]
mod recorded;

#[cfg(feature = "python")]
mod bindings;

pub use error::{Error, Result};
pub use inputs::orbit::Orbit;
pub use inputs::panel::Panel;
pub use models::thermal::STEFAN_BOLTZMANN;
