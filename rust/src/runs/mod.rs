//! Runs of the models in time: one transient, runs of many orbits with per-orbit summaries, the
//! hybrid exponential method, the lockstep SIMD lanes, ensembles, the distributed panel's runs.

pub mod beam;
pub mod boom;
pub mod distributed;
pub mod distributed_arc;
pub mod distributed_orbits;
pub(crate) mod distributed_umbra;
pub mod ensemble;
pub mod hybrid;
pub mod layered;
#[cfg(test)]
mod layered_tests;
pub mod lockstep;
pub mod orbits;
pub mod request;
pub mod simulate;
pub mod spacecraft;
