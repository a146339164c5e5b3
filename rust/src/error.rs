//! One error type for the whole engine; the Python layer maps each kind to an exception.

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum Error {
    /// A user-supplied value is outside its allowed range.
    #[error("{name} = {value} is invalid: {reason}")]
    InvalidParameter {
        name: String,
        value: String,
        reason: String,
    },
    /// The integrator could not make progress (step size underflow, step guard, NaN state).
    #[error("integration failed at t = {t} s: {reason}")]
    Integration { t: f64, reason: String },
    /// A non-linear solve (equilibrium, root-finding) did not converge.
    #[error("{what} did not converge: {reason}")]
    NoConvergence { what: String, reason: String },
    /// The caller cancelled the work (see `crate::cancel::Cancel`).
    #[error("cancelled")]
    Cancelled,
}

pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub fn invalid(name: &str, value: impl std::fmt::Display, reason: &str) -> Self {
        Error::InvalidParameter {
            name: name.to_string(),
            value: readable(value.to_string()),
            reason: reason.to_string(),
        }
    }
}

/// A number as a person writes it: Rust prints 1e300 with all its 301 digits, so long numbers
/// are shown in exponent form (the value itself is unchanged).
fn readable(text: String) -> String {
    match text.parse::<f64>() {
        Ok(x) if text.len() > 16 => format!("{x:e}"),
        _ => text,
    }
}

/// A bound as a person writes it: plain between 1e-3 and 1e5, else in exponent form.
pub fn short(x: f64) -> String {
    if x == 0.0 || (1e-3..1e5).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Checks that `value` is finite and strictly positive.
pub fn require_positive(name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(name, value, "must be finite and > 0"))
    }
}

/// Checks that `value` is finite and not negative.
pub fn require_non_negative(name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(name, value, "must be finite and >= 0"))
    }
}

/// Checks that `value` is finite.
pub fn require_finite(name: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(name, value, "must be finite"))
    }
}
