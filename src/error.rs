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

/// How an ODE integration failed, read from an [`Error::Integration`] reason (the reasons are
/// ode_solvers' `IntegrationError` messages or the viscoelastic module's own).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IntegrationFailure {
    /// The step budget ran out: the integration would not have terminated in reasonable time.
    MaxSteps,
    /// The adaptive step shrank below the rounding of the independent variable.
    StepSizeUnderflow,
    /// The adaptive methods' stiffness detector fired (only with `stiffness_check` on).
    Stiffness,
    /// The state became infinite or NaN (fixed-step RK4 with too large a step).
    NonFinite,
    /// The integration finished but gave e outside (0, 1].
    Unphysical,
    /// A phase did not reach its end event (no turning point, no rebound, force never zero).
    PhaseIncomplete,
    /// Any other reason.
    Other,
}

impl IntegrationFailure {
    pub fn name(self) -> &'static str {
        match self {
            IntegrationFailure::MaxSteps => "max_steps",
            IntegrationFailure::StepSizeUnderflow => "step_underflow",
            IntegrationFailure::Stiffness => "stiffness",
            IntegrationFailure::NonFinite => "non_finite",
            IntegrationFailure::Unphysical => "unphysical",
            IntegrationFailure::PhaseIncomplete => "phase_incomplete",
            IntegrationFailure::Other => "other",
        }
    }

    /// Classifies a reason string (case-insensitive).
    pub fn from_reason(reason: &str) -> Self {
        let r = reason.to_ascii_lowercase();
        if r.contains("more than") && r.contains("steps") {
            IntegrationFailure::MaxSteps
        } else if r.contains("step size underflow") {
            IntegrationFailure::StepSizeUnderflow
        } else if r.contains("stiff") {
            IntegrationFailure::Stiffness
        } else if r.contains("non-finite") || r.contains("nan") {
            IntegrationFailure::NonFinite
        } else if r.contains("unphysical") {
            IntegrationFailure::Unphysical
        } else if r.contains("did not slow down")
            || r.contains("no rebound")
            || r.contains("never returned")
        {
            IntegrationFailure::PhaseIncomplete
        } else {
            IntegrationFailure::Other
        }
    }
}

impl Error {
    /// For an integration error, how it failed; `None` for other errors.
    pub fn integration_failure(&self) -> Option<IntegrationFailure> {
        match self {
            Error::Integration { reason, .. } => Some(IntegrationFailure::from_reason(reason)),
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

#[cfg(test)]
mod tests {
    use super::*;
    use ode_solvers::dop_shared::IntegrationError;

    #[test]
    fn classifies_ode_solvers_messages() {
        // The reasons the viscoelastic module passes on are these messages verbatim: if the crate
        // rewords them, this test says so.
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
            assert_eq!(IntegrationFailure::from_reason(&e.to_string()), want, "{e}");
        }
        let own = [
            (
                "stopped at 3: needs more than 200 steps",
                IntegrationFailure::MaxSteps,
            ),
            (
                "non-finite state at 2: step 0.5 too large",
                IntegrationFailure::NonFinite,
            ),
            ("unphysical result e = -0.3", IntegrationFailure::Unphysical),
            (
                "loading phase did not slow down as it must",
                IntegrationFailure::PhaseIncomplete,
            ),
            (
                "no rebound within t = 200 (dimensionless)",
                IntegrationFailure::PhaseIncomplete,
            ),
            (
                "force never returned to zero before separation",
                IntegrationFailure::PhaseIncomplete,
            ),
            ("something else", IntegrationFailure::Other),
        ];
        for (reason, want) in own {
            assert_eq!(IntegrationFailure::from_reason(reason), want, "{reason}");
        }
        let err = Error::Integration {
            method: "rk4",
            kappa: 1.0,
            reason: "unphysical result e = 2".into(),
        };
        assert_eq!(
            err.integration_failure(),
            Some(IntegrationFailure::Unphysical)
        );
        assert_eq!(positive("x", -1.0).unwrap_err().integration_failure(), None);
    }
}
