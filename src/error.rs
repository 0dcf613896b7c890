//! The library's error type: every failure a user can provoke is a value, never a panic.
//!
//! Each variant carries what went wrong as typed fields, set where the failure happens (an
//! integration's [`IntegrationFailure`] kind, the derived quantity that left the range of f64, the
//! method that stopped iterating), so callers branch on fields, never on message text. Numbers in
//! the messages are in shortest round-trip form ([`Num`]): `1e300`, not 301 digits.

use std::fmt;

/// An f64 shown in shortest round-trip form: plain (`6.3233`) between 1e-4 and 1e16, with an
/// exponent (`1e300`, `2.5e-130`) outside, so that no message prints hundreds of digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&a) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// Errors raised by the physics and numerics of the library.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A parameter outside its physical domain (non-positive modulus, nu outside (-1, 0.5), NaN, ...).
    #[error("invalid {name} = {}: expected {expected}", Num(*value))]
    InvalidParameter {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    /// The ODE integration gave up; `kind` says how, `reason` gives the details.
    #[error("{method} integration failed at kappa = {}: {reason}", Num(*kappa))]
    Integration {
        method: &'static str,
        kappa: f64,
        kind: IntegrationFailure,
        reason: String,
    },
    /// Valid, finite inputs whose derived quantity is 0, subnormal or infinite in f64 (for
    /// example V_Y of sigma_y = 1e-130 Pa, which is about 1e-345 m/s). `cause` names the inputs.
    #[error("{quantity} = {} is out of the range of f64 ({}): {cause}", Num(*value), if *value == 0.0 || (value.is_finite() && value.abs() < f64::MIN_POSITIVE) { "underflow" } else { "overflow" })]
    OutOfRange {
        quantity: &'static str,
        value: f64,
        cause: String,
    },
    /// An approximation declined: its error bound does not meet the requested accuracy there.
    #[error("{approximation} at kappa = {}: its error bound does not meet the accuracy {} there", Num(*kappa), Num(*tol))]
    BeyondErrorBound {
        approximation: String,
        kappa: f64,
        tol: f64,
    },
    /// An iterative method reached its iteration cap or a NaN without converging.
    #[error("{method} did not converge: {detail}")]
    NoConvergence {
        method: &'static str,
        detail: String,
    },
}

/// How an ODE integration failed (the `kind` of [`Error::Integration`]).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr, strum::EnumIter, strum::Display,
)]
#[strum(serialize_all = "snake_case")]
pub enum IntegrationFailure {
    /// The step budget ran out: the integration would not have terminated in reasonable time.
    MaxSteps,
    /// The adaptive step shrank below the rounding of the independent variable.
    #[strum(serialize = "step_underflow")]
    StepSizeUnderflow,
    /// The adaptive methods' stiffness detector fired (only with `stiffness_check` on).
    Stiffness,
    /// The state became infinite or NaN (fixed-step RK4 with too large a step).
    NonFinite,
    /// The integration finished but gave e outside (0, 1], or violated the energy balance.
    Unphysical,
    /// A phase did not reach its end event (no turning point, no rebound, force never zero).
    PhaseIncomplete,
    /// The event locator reached its iteration cap (or a NaN) without converging on the event.
    EventLocation,
    /// kappa beyond the range where the integrator's accuracy has been checked.
    OutOfRange,
    /// Any other reason.
    Other,
}

impl IntegrationFailure {
    pub fn name(self) -> &'static str {
        self.into()
    }
}

impl From<&ode_solvers::dop_shared::IntegrationError> for IntegrationFailure {
    fn from(e: &ode_solvers::dop_shared::IntegrationError) -> Self {
        use ode_solvers::dop_shared::IntegrationError as E;
        match e {
            E::MaxNumStepReached { .. } => IntegrationFailure::MaxSteps,
            E::StepSizeUnderflow { .. } => IntegrationFailure::StepSizeUnderflow,
            E::StiffnessDetected { .. } => IntegrationFailure::Stiffness,
        }
    }
}

impl Error {
    /// For an integration error, how it failed; `None` for other errors.
    pub fn integration_failure(&self) -> Option<IntegrationFailure> {
        match self {
            Error::Integration { kind, .. } => Some(*kind),
            _ => None,
        }
    }
}

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

/// Checks that a derived quantity is a normal, finite, positive f64; otherwise an
/// [`Error::OutOfRange`] naming it and (lazily) the inputs it came from.
pub fn in_range(quantity: &'static str, value: f64, cause: impl FnOnce() -> String) -> Result<f64> {
    if value.is_finite() && value >= f64::MIN_POSITIVE {
        Ok(value)
    } else {
        Err(Error::OutOfRange {
            quantity,
            value,
            cause: cause(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ode_solvers::dop_shared::IntegrationError;

    #[test]
    fn ode_solvers_errors_map_to_kinds() {
        let cases = [
            (
                IntegrationError::MaxNumStepReached { x: 1.0, n_step: 10 },
                IntegrationFailure::MaxSteps,
            ),
            (
                IntegrationError::StepSizeUnderflow { x: 1.0 },
                IntegrationFailure::StepSizeUnderflow,
            ),
            (
                IntegrationError::StiffnessDetected { x: 1.0 },
                IntegrationFailure::Stiffness,
            ),
        ];
        for (e, want) in cases {
            assert_eq!(IntegrationFailure::from(&e), want, "{e}");
        }
        let err = Error::Integration {
            method: "rk4",
            kappa: 1.0,
            kind: IntegrationFailure::Unphysical,
            reason: "e = 2".into(),
        };
        assert_eq!(
            err.integration_failure(),
            Some(IntegrationFailure::Unphysical)
        );
        assert_eq!(positive("x", -1.0).unwrap_err().integration_failure(), None);
    }

    #[test]
    fn names_are_stable() {
        // Written to stability.csv: renaming one changes the bench's output format.
        assert_eq!(
            IntegrationFailure::StepSizeUnderflow.name(),
            "step_underflow"
        );
        assert_eq!(
            IntegrationFailure::PhaseIncomplete.name(),
            "phase_incomplete"
        );
        assert_eq!(IntegrationFailure::MaxSteps.to_string(), "max_steps");
    }

    #[test]
    fn messages_use_short_numbers() {
        let e = Error::Integration {
            method: "dop853",
            kappa: 1e300,
            kind: IntegrationFailure::OutOfRange,
            reason: "x".into(),
        };
        assert_eq!(
            e.to_string(),
            "dop853 integration failed at kappa = 1e300: x"
        );
        assert_eq!(Num(6.3233).to_string(), "6.3233");
        assert_eq!(Num(1e-130).to_string(), "1e-130");
        assert_eq!(Num(f64::MAX).to_string(), "1.7976931348623157e308");
        let u = in_range("V_Y (m/s)", 0.0, || "sigma_y = 1e-130 Pa".into()).unwrap_err();
        assert_eq!(
            u.to_string(),
            "V_Y (m/s) = 0 is out of the range of f64 (underflow): sigma_y = 1e-130 Pa"
        );
        let o = in_range("E* (Pa)", f64::INFINITY, || "Y".into()).unwrap_err();
        assert!(o.to_string().contains("(overflow)"), "{o}");
    }
}
