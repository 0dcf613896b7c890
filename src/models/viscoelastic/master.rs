//! Master curve: e(kappa) for each end-of-contact rule as a fast piecewise Chebyshev table.
//!
//! **What**: e depends on the dimensionless damping kappa alone (docs/physics.md §2), so one function
//! per rule serves every material, size and speed. We tabulate h(s) = (1 - e)/kappa as a function
//! of s = kappa^(1/2) on [0, `S_MAX`]: h is analytic in s down to s = 0 (h(0) = C1 = 1.1534...),
//! including the half-integer powers of kappa that the force rule's expansion has, and
//! 1 - e = kappa h keeps its relative accuracy as kappa -> 0.
//!
//! **How**: `PIECES` equal intervals in s, each a Chebyshev interpolant of degree `DEGREE` through
//! the ODE at its tightest setting ([`super::OdeSettings::REFERENCE`]) at Chebyshev nodes, made by
//! `examples/gen_master_curve.rs` (committed) and checked by it at points between the nodes. The
//! generator's measured maximum errors are [`MAX_ABS_ERROR_E`] and [`MAX_REL_ERROR_ONE_MINUS_E`]
//! (2.4e-15 and 4.9e-15 for the committed 40 pieces of degree 16, over kappa in (0, 100] and both
//! rules); tests/viscoelastic.rs checks the table against the independent mpmath reference values
//! (bar: 1e-12 in e, 1e-11 relative in 1 - e). The committed table was made before the ODE's
//! events were located by Newton steps, which moved the reference ODE's e at rounding level: the
//! generator run today writes coefficients whose e differs from the committed table's by at most
//! 3.7e-15, with errors 2.4e-15 and 4.6e-15. The table is kept so that every shipped result stays
//! bit for bit.
//!
//! **Large kappa.** The table's e = 1 - kappa h loses the relative accuracy of a small e (at
//! kappa = 100 the overlap rule's e = 5.2e-10 would carry 2.4e-15 absolute, 5e-6 relative), so
//! [`restitution_master`] hands over to the large-kappa laws of [`super::asymptotic`] at kappa =
//! 10 for both rules, where their errors are far below the table's (3.5e-36 relative for the
//! overlap rule; the force rule's large-kappa table, 1e-16). Every finite kappa >= 0 gets a
//! number; only NaN, infinite or negative kappa gets `None`.

use super::asymptotic::{self, KAPPA_FORCE_TABLE, KAPPA_OVERLAP_LAW};
use super::master_table as table;
use super::{ContactEnd, Restitution};

pub use table::{MAX_ABS_ERROR_E, MAX_REL_ERROR_ONE_MINUS_E};

/// Largest kappa the small-kappa table covers (the master curve itself covers every kappa; from
/// kappa = 10 on it uses the large-kappa laws).
pub const KAPPA_MAX: f64 = table::S_MAX * table::S_MAX;
/// Width of one piece in s = kappa^(1/2).
pub const PIECE_WIDTH: f64 = table::S_MAX / table::PIECES as f64;

/// Clenshaw summation of sum_j c_j T_j(x), x in [-1, 1].
#[inline]
pub fn clenshaw(c: &[f64], x: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    let x2 = 2.0 * x;
    for &cj in c.iter().skip(1).rev() {
        let b0 = cj + x2 * b1 - b2;
        b2 = b1;
        b1 = b0;
    }
    c[0] + x * b1 - b2
}

/// Piece index and local coordinate in [-1, 1] of s.
#[inline]
pub fn locate(s: f64) -> (usize, f64) {
    let u = s / PIECE_WIDTH;
    let i = (u as usize).min(table::PIECES - 1);
    (i, 2.0 * (u - i as f64) - 1.0)
}

/// e(kappa) for every finite kappa >= 0: the table below kappa = 10, the large-kappa laws from
/// there on; `None` for NaN, infinite or negative kappa.
#[inline]
pub fn restitution_master(kappa: f64, rule: ContactEnd) -> Option<Restitution> {
    if !(0.0..f64::INFINITY).contains(&kappa) {
        return None;
    }
    let (coeffs, large) = match rule {
        ContactEnd::Overlap => (&table::OVERLAP, kappa >= KAPPA_OVERLAP_LAW),
        ContactEnd::Force => (&table::FORCE, kappa >= KAPPA_FORCE_TABLE),
    };
    if large {
        let e = match rule {
            ContactEnd::Overlap => asymptotic::overlap_e(kappa),
            ContactEnd::Force => asymptotic::force_e(kappa),
        };
        return Some(Restitution {
            e,
            one_minus_e: 1.0 - e,
            rhs_evals: 0,
        });
    }
    let (i, x) = locate(kappa.sqrt());
    let one_minus_e = kappa * clenshaw(&coeffs[i], x);
    Some(Restitution {
        e: 1.0 - one_minus_e,
        one_minus_e,
        rhs_evals: 0,
    })
}
