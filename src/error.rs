//! The library's error type: every failure a user can provoke is a value, never a panic.

use std::fmt;

/// Errors raised by the physics and numerics of the library.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A parameter outside its physical domain (non-positive modulus, nu outside (-1, 0.5), NaN, ...).
    InvalidParameter {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// The ODE integration gave up; `reason` says how (step-size underflow, too many steps, ...).
    Integration {
        method: &'static str,
        kappa: f64,
        reason: String,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidParameter {
                name,
                value,
                expected,
            } => write!(f, "invalid {name} = {value}: expected {expected}"),
            Error::Integration {
                method,
                kappa,
                reason,
            } => write!(
                f,
                "{method} integration failed at kappa = {kappa}: {reason}"
            ),
        }
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;

/// Checks that `value` is finite and strictly positive.
pub fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name,
            value,
            expected: "a finite number > 0",
        })
    }
}

/// Checks that `value` is finite and not negative.
pub fn non_negative(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name,
            value,
            expected: "a finite number >= 0",
        })
    }
}
