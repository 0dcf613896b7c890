//! Viscoelastic model (VM): Eqs. (9)-(10) of Labous, Rosato & Dave (1997), docs/physics.md §2.
//!
//! **Solves** m_red delta'' = -(K delta^(3/2) + C delta^(1/2) delta'), delta(0) = 0, delta'(0) = V,
//! in the dimensionless form x'' = -x^(3/2) - kappa x^(1/2) x', x(0) = 0, x'(0) = 1 (docs/physics.md §2:
//! the paper's Eq. 10 omits the sign of the force), and returns e = -x'(end) for either end-of-contact
//! rule ([`ContactEnd`]).
//!//! **Method** ([`ode`]): the ODE in phases, with the independent variable r = x^(1/2) where x
//! is near 0, so that Runge-Kutta methods keep their order; events located by safeguarded Newton
//! steps ([`events`]).
//!
//! **Every kappa >= 0** ([`restitution`] with [`VmMethod::Master`]): the master-curve table for
//! kappa <= 10, then the large-kappa laws (docs/physics.md §2, derived in
//! docs/physics.md §2.7): for the overlap rule e = A kappa^-5 exactly up to
//! exponentially small terms; for the force rule a table of e kappa^(5/3) in ln kappa up to
//! kappa = 1e7 and e = xi_m kappa^(-5/3) (1 - (2/lambda) eps ln(1/eps) + c_f eps) beyond, eps =
//! kappa^(-5/3) ([`asymptotic`]). The small-kappa end is the table's h(0) = C1: 1 - e = C1 kappa
//! keeps its relative accuracy down to the smallest kappa.
//!
//! **Needs** kappa >= 0 finite. Integrators: Dop853 and Dopri5 from `ode_solvers` (adaptive,
//! sparse output), and classical RK4 at a fixed step (our own loop: `ode_solvers::Rk4` overshoots
//! the end point and cannot run backwards, which the unloading phase does).
//!
//! **Reference values**: `tests/fixtures/vm_reference.csv` (mpmath Taylor integration at 30-40
//! digits, `tools/reference/`); the tests there bound the error of every setting.

pub mod asymptotic;
pub mod events;
mod force_table;
pub mod master;
mod master_table;
pub mod ode;
pub mod series;
pub mod settings;
pub mod si;
mod stepper;

pub use ode::{rebound, restitution_ode};
pub use settings::{
    Integrator, ODE_KAPPA_MAX_FORCE, ODE_KAPPA_MAX_OVERLAP, OdeSettings, Rebound, ode_kappa_max,
};
pub use si::{Impact, Viscoelastic};

use crate::error::Result;
use std::fmt;
use std::str::FromStr;

/// When the contact ends (docs/physics.md §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr, strum::VariantArray)]
#[strum(serialize_all = "lowercase")]
pub enum ContactEnd {
    /// The paper's rule: the first t > 0 with delta = 0.
    Overlap,
    /// Schwager & Poeschel, PRE 78, 051304 (2008): the first t > 0 where the contact force returns to zero.
    Force,
}

impl ContactEnd {
    pub const ALL: [ContactEnd; 2] = [ContactEnd::Overlap, ContactEnd::Force];

    pub fn name(self) -> &'static str {
        self.into()
    }
}

impl fmt::Display for ContactEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ContactEnd {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        use strum::VariantArray;
        ContactEnd::VARIANTS
            .iter()
            .find(|r| r.name() == s)
            .copied()
            .ok_or_else(|| {
                let names: Vec<&str> = ContactEnd::VARIANTS.iter().map(|r| r.name()).collect();
                format!(
                    "'{s}' is not a contact-end rule: expected {}",
                    names.join(" or ")
                )
            })
    }
}

/// e and 1 - e from any of the evaluation methods, with the work it took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Restitution {
    pub e: f64,
    /// 1 - e with its own relative accuracy.
    pub one_minus_e: f64,
    /// Right-hand-side evaluations (0 for closed forms and tables).
    pub rhs_evals: u64,
}

/// How e(kappa) is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum VmMethod {
    /// The master curve: table and large-kappa laws, every finite kappa >= 0.
    #[default]
    Master,
    /// The ODE at the given setting, for every point.
    Ode(OdeSettings),
}

/// e(kappa) by the chosen method. [`VmMethod::Master`] covers every finite kappa >= 0 (table and
/// large-kappa laws, [`master::restitution_master`]); NaN, infinite or negative kappa is an error.
pub fn restitution(kappa: f64, rule: ContactEnd, method: &VmMethod) -> Result<Restitution> {
    match method {
        VmMethod::Master => {
            crate::error::non_negative("dimensionless damping kappa", kappa)?;
            master::restitution_master(kappa, rule).ok_or(crate::error::Error::InvalidParameter {
                name: "dimensionless damping kappa",
                value: kappa,
                expected: "a finite number >= 0",
            })
        }
        VmMethod::Ode(settings) => restitution_ode(kappa, rule, settings),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rule_names_round_trip() {
        for r in ContactEnd::ALL {
            assert_eq!(r.name().parse::<ContactEnd>().unwrap(), r);
            assert_eq!(r.to_string(), r.name());
        }
        let err = "elastic".parse::<ContactEnd>().unwrap_err();
        assert_eq!(
            err,
            "'elastic' is not a contact-end rule: expected overlap or force"
        );
    }
}
