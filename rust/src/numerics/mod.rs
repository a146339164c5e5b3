//! Numerical methods that know no physics: SIMD number types, the processor and the kernel
//! chosen on it, the ODE integrators with their output, and interpolation.

pub mod chebyshev;
pub mod cpu;
pub mod integrate;
pub mod newton;
pub mod quadrature;
pub(crate) mod simd;
#[cfg(test)]
pub(crate) mod testing;
pub(crate) mod vector;
