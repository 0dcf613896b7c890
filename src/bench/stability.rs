//! The stability map: where each method fails over kappa (and u), and how.
//!
//! Each cell evaluates one method at one point and compares with the reference. Its outcome is one
//! of: `ok` (error <= [`MAP_TOL`]); a silent failure, i.e. a number returned that is wrong
//! (`inaccurate`: error above MAP_TOL; `nan`: not finite); or an error value, classified as the
//! integrators report it (`max_steps`: no termination within the step budget, `step_underflow`,
//! `stiffness`, `non_finite`, `unphysical`, `phase_incomplete`) or `refused` (an approximation
//! outside the range where its error bound meets MAP_TOL). The error of a cell is
//! |e - e_ref| / min(1, (1 - e)_ref): at once the absolute error of e and the relative error of
//! 1 - e, which is what matters as kappa -> 0 or u -> 1. Rows of [`Role::Loose`] settings (shown
//! for their breakdowns) are held to LOOSE_FACTOR x their tolerance instead.

use super::methods::{PmSpec, VmSpec};
use super::reference::{PmRef, vm_dense_reference};
use crate::error::{Error, IntegrationFailure};
use crate::models::viscoelastic::ContactEnd;

/// The accuracy a cell must reach to count as `ok`.
pub const MAP_TOL: f64 = 1e-6;

/// What happened in one cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Outcome {
    Ok,
    /// A finite number with error above [`MAP_TOL`], returned as if it were right.
    Inaccurate,
    /// NaN or infinity returned as if it were right.
    NotFinite,
    /// An approximation declined: its error bound does not meet the requested accuracy.
    Refused,
    /// The integration gave up with an error value.
    Failed(IntegrationFailure),
    /// Any other error value.
    OtherError,
}

impl Outcome {
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Ok => "ok",
            Outcome::Inaccurate => "inaccurate",
            Outcome::NotFinite => "nan",
            Outcome::Refused => "refused",
            Outcome::Failed(f) => f.name(),
            Outcome::OtherError => "error",
        }
    }

    /// A wrong number returned without an error value.
    pub fn is_silent_failure(self) -> bool {
        matches!(self, Outcome::Inaccurate | Outcome::NotFinite)
    }

    /// Every outcome, in the order of the figure's legend.
    pub const ALL: [Outcome; 13] = [
        Outcome::Ok,
        Outcome::Inaccurate,
        Outcome::NotFinite,
        Outcome::Refused,
        Outcome::Failed(IntegrationFailure::MaxSteps),
        Outcome::Failed(IntegrationFailure::StepSizeUnderflow),
        Outcome::Failed(IntegrationFailure::Stiffness),
        Outcome::Failed(IntegrationFailure::NonFinite),
        Outcome::Failed(IntegrationFailure::Unphysical),
        Outcome::Failed(IntegrationFailure::PhaseIncomplete),
        Outcome::Failed(IntegrationFailure::EventLocation),
        Outcome::Failed(IntegrationFailure::OutOfRange),
        Outcome::OtherError,
    ];
}

/// Whether a method is one a user computes e with, or a comparator kept to show a failure mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "lowercase")]
pub enum Role {
    /// A way to compute e that the library offers: it must never return a wrong number silently.
    Production,
    /// A second method for comparison (quadrature) or the demonstration of a failure (naive q).
    Comparator,
    /// An ODE setting too loose for MAP_TOL, shown for its breakdowns: its cells count as
    /// inaccurate only above [`LOOSE_FACTOR`] x its tolerance.
    Loose,
}

/// A loose setting's cell is inaccurate when its error exceeds this multiple of its tolerance
/// (global errors of the adaptive methods run up to ~10x their local tolerance on the chart).
pub const LOOSE_FACTOR: f64 = 100.0;

/// One cell of the map.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    pub model: &'static str,
    pub method: String,
    pub setting: String,
    pub role: Role,
    /// `overlap`, `force` or `-`.
    pub rule: String,
    /// kappa (vm) or u (pm).
    pub x: f64,
    pub outcome: Outcome,
    /// See the module docs; NaN when the method gave an error value.
    pub error: f64,
    /// The error value's message, or why a number is wrong.
    pub detail: String,
}

fn classify_error(err: &Error) -> Outcome {
    match err {
        Error::Integration { kind, .. } => Outcome::Failed(*kind),
        Error::BeyondErrorBound { .. } => Outcome::Refused,
        _ => Outcome::OtherError,
    }
}

fn classify_number(
    e: f64,
    one_minus_e: f64,
    e_ref: f64,
    ome_ref: f64,
    tol: f64,
) -> (Outcome, f64, String) {
    if !(e.is_finite() && one_minus_e.is_finite()) {
        return (
            Outcome::NotFinite,
            f64::NAN,
            format!("e = {e}, 1 - e = {one_minus_e}"),
        );
    }
    // The worse of the relative errors of e and of 1 - e (computed separately by some methods):
    // the absolute error of e near e = 1, and its relative error where e is tiny (kappa -> inf,
    // u -> inf), where an absolute 1e-6 would pass any number at all. e itself is not held to
    // the relative accuracy of 1 - e: next to 1 a double cannot resolve 1 - e = 1e-10 to 1e-6 of
    // itself; that is 1 - e's job. Below 1e-290 (down to the subnormals, where neither the
    // reference nor the method can keep relative digits) the error is taken relative to 1e-290.
    let err_ome = if ome_ref > 0.0 {
        (one_minus_e - ome_ref).abs() / ome_ref
    } else {
        (one_minus_e - ome_ref).abs()
    };
    let err_e = (e - e_ref).abs() / e_ref.clamp(1e-290, 1.0);
    let err = err_e.max(err_ome);
    if err <= tol {
        (Outcome::Ok, err, String::new())
    } else {
        (
            Outcome::Inaccurate,
            err,
            format!(
                "e = {e} (reference {e_ref}), 1 - e = {one_minus_e} (reference {ome_ref}); allowed {tol:e}"
            ),
        )
    }
}

/// `per_decade` log-spaced kappa values from 1e-8 to 10^`max_decade` inclusive.
pub fn kappa_grid(per_decade: usize, max_decade: i32) -> Vec<f64> {
    let n = (max_decade + 8) as usize * per_decade;
    (0..=n)
        .map(|i| {
            let d = -8.0 + i as f64 / per_decade as f64;
            // Exact powers of ten where the grid hits a decade.
            if i % per_decade == 0 {
                format!("1e{}", d.round() as i32)
                    .parse()
                    .unwrap_or(10f64.powf(d))
            } else {
                10f64.powf(d)
            }
        })
        .collect()
}

/// The map's kappa: `per_decade` per decade from 1e-8 to 1e4 ([`kappa_grid`]), then every
/// second decade to 1e300, and f64::MAX: the whole range a user can give.
pub fn kappa_grid_wide(per_decade: usize) -> Vec<f64> {
    let mut g = kappa_grid(per_decade, 4);
    for d in (6..=300).step_by(2) {
        g.push(format!("1e{d}").parse().expect("a literal"));
    }
    g.push(f64::MAX);
    g
}

/// The viscoelastic map: every spec, both rules (where it applies), every kappa.
/// Fails only if the reference itself cannot be computed.
pub fn vm_map(specs: &[(VmSpec, Role)], kappas: &[f64]) -> crate::error::Result<Vec<Cell>> {
    let mut refs = Vec::new();
    for rule in ContactEnd::ALL {
        for &kappa in kappas {
            let (e_ref, ome_ref, _) = vm_dense_reference(kappa, rule)?;
            refs.push((rule, kappa, e_ref, ome_ref));
        }
    }
    let mut cells = Vec::new();
    for (spec, role) in specs {
        for rule in ContactEnd::ALL {
            if !spec.applies(rule) {
                continue;
            }
            let tol = match (role, spec) {
                (Role::Loose, VmSpec::Ode(s)) => MAP_TOL.max(LOOSE_FACTOR * s.rtol),
                _ => MAP_TOL,
            };
            for &(_, kappa, e_ref, ome_ref) in refs.iter().filter(|r| r.0 == rule) {
                let (outcome, error, detail) = match spec.eval(kappa, rule) {
                    Ok(r) => classify_number(r.e, r.one_minus_e, e_ref, ome_ref, tol),
                    Err(err) => (classify_error(&err), f64::NAN, err.to_string()),
                };
                cells.push(Cell {
                    model: "vm",
                    method: spec.method(),
                    setting: spec.setting(),
                    role: *role,
                    rule: rule.name().into(),
                    x: kappa,
                    outcome,
                    error,
                    detail,
                });
            }
        }
    }
    Ok(cells)
}

/// The plastic map over the reference points with u > 1.
pub fn pm_map(specs: &[(PmSpec, Role)], refs: &[PmRef]) -> Vec<Cell> {
    let mut cells = Vec::new();
    for r in refs.iter().filter(|r| r.u > 1.0) {
        for (spec, role) in specs {
            let (outcome, error, detail) = match spec.eval(r.u) {
                Ok(got) => classify_number(got.e, got.one_minus_e, r.e, r.one_minus_e, MAP_TOL),
                Err(err) => (classify_error(&err), f64::NAN, err.to_string()),
            };
            cells.push(Cell {
                model: "pm",
                method: spec.method(),
                setting: spec.setting(),
                role: *role,
                rule: "-".into(),
                x: r.u,
                outcome,
                error,
                detail,
            });
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_has_exact_decades() {
        let g = kappa_grid(4, 2);
        assert_eq!(g.len(), 41);
        assert_eq!(g[0], 1e-8);
        assert_eq!(g[40], 100.0);
        assert_eq!(g[32], 1.0);
    }

    #[test]
    fn numbers_are_classified_by_the_combined_error() {
        // 1 - e = 1e-8 known to 1e-15 absolute: relative 1e-7, ok.
        assert_eq!(
            classify_number(1.0 - 1e-8, 1e-8 + 1e-15, 1.0 - 1e-8, 1e-8, MAP_TOL).0,
            Outcome::Ok
        );
        // 1 - e off by 1e-13 at 1 - e = 1e-8: relative 1e-5, inaccurate.
        assert_eq!(
            classify_number(1.0 - 1e-8, 1e-8 + 1e-13, 1.0 - 1e-8, 1e-8, MAP_TOL).0,
            Outcome::Inaccurate
        );
        assert_eq!(
            classify_number(f64::NAN, 0.5, 0.5, 0.5, MAP_TOL).0,
            Outcome::NotFinite
        );
    }
}
