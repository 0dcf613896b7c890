//! Every way the toolkit computes e, as values the harness can sweep, evaluate and name.

use super::quadrature::WorkQuadrature;
use crate::data::fmt_num;
use crate::error::Result;
use crate::models::plastic::{rebound_u, rebound_u_naive};
use crate::models::viscoelastic::series::{self, Approximation};
use crate::models::viscoelastic::{
    ContactEnd, Integrator, OdeSettings, Restitution, VmMethod, rebound, restitution,
    restitution_ode,
};

/// One viscoelastic evaluation method at one setting of its accuracy knob.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VmSpec {
    /// [`restitution_ode`]: e alone (no extrema located).
    Ode(OdeSettings),
    /// [`rebound`]: e plus contact time, maximum overlap and force (three more events located).
    OdeExtrema(OdeSettings),
    /// [`restitution`] with [`VmMethod::Master`]: the table on [0, 100], the default ODE above.
    Master,
    /// A series or Pade approximant, unchecked (whatever it gives).
    Approx(Approximation),
    /// The same, through [`series::restitution_checked`] at accuracy `tol`.
    Checked(Approximation, f64),
}

impl VmSpec {
    /// The method's name (one line on the work-precision chart).
    pub fn method(&self) -> String {
        let ode = |s: &OdeSettings| {
            let mut n = s.integrator.name().to_string();
            if s.stiffness_check {
                n.push_str("+stiffcheck");
            }
            n
        };
        match self {
            VmSpec::Ode(s) => ode(s),
            VmSpec::OdeExtrema(s) => format!("{}+extrema", ode(s)),
            VmSpec::Master => "master".into(),
            VmSpec::Approx(Approximation::Series(_)) => "series".into(),
            VmSpec::Approx(Approximation::Pade(_)) => "pade".into(),
            VmSpec::Checked(Approximation::Series(_), _) => "series checked".into(),
            VmSpec::Checked(Approximation::Pade(_), _) => "pade checked".into(),
        }
    }

    /// The setting of the knob, as text.
    pub fn setting(&self) -> String {
        let ode = |s: &OdeSettings| match s.integrator {
            Integrator::Rk4 { h } => format!("h={}", fmt_num(h)),
            _ => format!("tol={}", fmt_num(s.rtol)),
        };
        match self {
            VmSpec::Ode(s) | VmSpec::OdeExtrema(s) => ode(s),
            VmSpec::Master => "table".into(),
            VmSpec::Approx(a) => approx_setting(a),
            VmSpec::Checked(a, tol) => format!("{} tol={}", approx_setting(a), fmt_num(*tol)),
        }
    }

    /// The knob as a number (tolerance, step, series order, Pade denominator degree; NaN: none).
    pub fn knob(&self) -> f64 {
        match self {
            VmSpec::Ode(s) | VmSpec::OdeExtrema(s) => match s.integrator {
                Integrator::Rk4 { h } => h,
                _ => s.rtol,
            },
            VmSpec::Master => f64::NAN,
            VmSpec::Approx(a) | VmSpec::Checked(a, _) => match a {
                Approximation::Series(s) => {
                    1.0 + series::Series::ALL.iter().position(|x| x == s).unwrap_or(0) as f64
                }
                Approximation::Pade(series::Pade::Ours15) => 5.0,
                Approximation::Pade(_) => 4.0,
            },
        }
    }

    /// Whether the method is defined for `rule` (the Pade approximants are of the force rule).
    pub fn applies(&self, rule: ContactEnd) -> bool {
        match self {
            VmSpec::Approx(Approximation::Pade(_)) | VmSpec::Checked(Approximation::Pade(_), _) => {
                rule == ContactEnd::Force
            }
            _ => true,
        }
    }

    #[inline]
    pub fn eval(&self, kappa: f64, rule: ContactEnd) -> Result<Restitution> {
        match self {
            VmSpec::Ode(s) => restitution_ode(kappa, rule, s),
            VmSpec::OdeExtrema(s) => rebound(kappa, rule, s).map(|r| Restitution {
                e: r.e,
                one_minus_e: r.one_minus_e,
                rhs_evals: r.rhs_evals,
            }),
            VmSpec::Master => restitution(kappa, rule, &VmMethod::Master),
            VmSpec::Approx(a) => series::restitution_approx(kappa, rule, *a),
            VmSpec::Checked(a, tol) => series::restitution_checked(kappa, rule, *a, *tol),
        }
    }
}

fn approx_setting(a: &Approximation) -> String {
    match a {
        Approximation::Series(s) => s.name().into(),
        Approximation::Pade(p) => p.name().into(),
    }
}

/// One plastic evaluation method.
#[derive(Debug, Clone, PartialEq)]
pub enum PmSpec {
    /// [`rebound_u`]: the closed form without cancellation at yield.
    ClosedForm,
    /// [`rebound_u_naive`]: q = -2/3 + (2/15) sqrt(30 u^2 - 5) and 1 - e taken as 1 - e.
    Naive,
    /// Gauss-Legendre quadrature of the work integrals, Eqs. (16)-(17).
    Quadrature(WorkQuadrature),
}

/// A plastic result with the work it took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PmResult {
    pub e: f64,
    pub one_minus_e: f64,
    /// Integrand evaluations (0 for the closed forms).
    pub evals: u64,
}

impl PmSpec {
    pub fn method(&self) -> String {
        match self {
            PmSpec::ClosedForm => "closed form".into(),
            PmSpec::Naive => "naive q".into(),
            PmSpec::Quadrature(_) => "quadrature".into(),
        }
    }

    pub fn setting(&self) -> String {
        match self {
            PmSpec::Quadrature(q) => format!("n={}", q.nodes()),
            _ => "-".into(),
        }
    }

    pub fn knob(&self) -> f64 {
        match self {
            PmSpec::Quadrature(q) => q.nodes() as f64,
            _ => f64::NAN,
        }
    }

    #[inline]
    pub fn eval(&self, u: f64) -> Result<PmResult> {
        match self {
            PmSpec::ClosedForm => {
                let r = rebound_u(u);
                Ok(PmResult {
                    e: r.e,
                    one_minus_e: r.one_minus_e,
                    evals: 0,
                })
            }
            PmSpec::Naive => {
                let r = rebound_u_naive(u);
                Ok(PmResult {
                    e: r.e,
                    one_minus_e: r.one_minus_e,
                    evals: 0,
                })
            }
            PmSpec::Quadrature(q) => q.rebound_u(u).map(|r| PmResult {
                e: r.e,
                one_minus_e: r.one_minus_e,
                evals: r.integrand_evals,
            }),
        }
    }
}
