//! thermojitter: thermally induced vibration ("thermal jitter") and thermal flutter of long, thin
//! spacecraft appendages. A two-layer thermal model of a Sun-pointing plate in orbit, two-way
//! coupled to a one-degree-of-freedom hinge model of its first bending mode (Parisse & Angeletti
//! 2024), integrated through eclipses.
//!
//! The engine is plain Rust; the Python bindings live in `py` behind the `python` feature.

pub mod beam;
pub mod cancel;
pub mod conduction;
pub mod cpu;
pub mod distributed;
pub mod dynamics;
pub mod error;
pub mod flutter;
pub mod hybrid;
pub mod integrate;
pub mod laminate;
pub mod layered;
pub mod linear;
pub mod longrun;
pub mod montecarlo;
mod num;
pub mod orbit;
pub mod params;
pub mod simulate;
pub mod stability;
pub mod steady;
pub mod system;
pub mod thermal;

#[cfg(test)]
mod recorded;

#[cfg(feature = "python")]
mod py;

pub use error::{Error, Result};
pub use orbit::Orbit;
pub use params::Panel;

/// Stefan–Boltzmann constant, W/(m² K⁴) (CODATA 2018, exact).
pub const STEFAN_BOLTZMANN: f64 = 5.670_374_419e-8;
