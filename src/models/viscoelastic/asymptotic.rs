//! e(kappa) at large kappa, for both contact-end rules (docs/physics.md §2; the derivations are
//! written out in docs/physics.md §2.7).
//!
//! **Overlap rule: e = A kappa^-5.** The rescaling x = kappa^-4 X, t = kappa T maps
//! x'' = -x^(3/2) - kappa x^(1/2) x' exactly onto the parameter-free X'' = -X^(3/2) - X^(1/2) X'
//! with X'(0) = kappa^5. After the first, damping-dominated instant the trajectory lies on the
//! slow manifold of that equation (P ~ -X - X^(1/2) as X -> infinity), which attracts at the rate
//! X^(1/2); the rebound speed on it is a pure number, A = 5.158381704267685216414305918240...
//! (mpmath: the parameter-free equation started near its slow manifold at X0 = 1e4 and 4e4
//! agree to 4e-51, tests/fixtures/vm_large_kappa_constants.csv). The corrections are
//! exponentially small, about exp(-2 lambda kappa^(5/3)), lambda = (3/2)^(1/3): measured e kappa^5
//! / A - 1 = -4.5e-8 at kappa = 5, -2.6e-17 at 7, -3.5e-36 at 10 (mpmath, 45 digits). So from
//! [`KAPPA_OVERLAP_LAW`] = 10 on, A kappa^-5 *is* e to far below rounding, and
//! [`overlap_e`] returns its correctly rounded value for every kappa up to f64::MAX (0 only when
//! A kappa^-5 < 2^-1075, i.e. kappa > 3.3e64 roughly; subnormal below that, correctly rounded).
//!
//! **Force rule: e ~ xi_m kappa^(-5/3).** With x = kappa^(-2/3) xi, t = kappa^(-2/3) s the
//! equation is xi'' = -xi^(1/2) xi' - eps xi^(3/2), eps = kappa^(-5/3), xi'(0) = 1, and the
//! force-rule end xi' + eps xi = 0 falls at the end of the initial damping transient, where xi
//! has reached the undamped-by-elasticity limit xi_m = (3/2)^(2/3) (from xi' = 1 - (2/3)
//! xi^(3/2)); e = -xi'(end) = eps xi_end. Matching the transient (rate lambda = xi_m^(1/2)) to
//! the slow drift xi' = -eps xi gives
//! e kappa^(5/3) = xi_m (1 - (2/lambda) eps ln(1/eps) + c_f eps + O(eps^2 ln^2 eps)),
//! with the coefficient 2/lambda derived and c_f = 1.654680456256096580225 measured from mpmath
//! at eps = 1e-40 and 1e-50 (agreeing to 6e-37). Checked against the rescaled mpmath integration
//! (28 digits): relative error of the three-term form 4.8e-12 at kappa = 1e4, 2.9e-18 at 1e6,
//! 1.9e-21 at 1e7 (tests/fixtures/vm_large_kappa.csv). Between kappa = 10 and
//! [`KAPPA_FORCE_LAW`] = 1e7 a Chebyshev table of e kappa^(5/3) in ln kappa, made from mpmath
//! values (`force_table.rs`, examples/gen_master_curve.rs), carries it.

use super::force_table as table;
use super::master::clenshaw;
use crate::models::fp::{self, Dd};
pub use table::MAX_REL_ERROR as FORCE_TABLE_MAX_REL_ERROR;

/// From here on the overlap rule's e is A kappa^-5 (relative error below 1e-35).
pub const KAPPA_OVERLAP_LAW: f64 = 10.0;
/// From here on the force rule's e is the three-term law (relative error below 2e-21).
pub const KAPPA_FORCE_LAW: f64 = table::KAPPA_MAX;
/// Where the force rule's large-kappa table starts.
pub const KAPPA_FORCE_TABLE: f64 = table::KAPPA_MIN;

/// A = lim e kappa^5 (overlap rule), as a double-double (mpmath, 45 digits).
pub const OVERLAP_A: Dd = Dd::new(5.158381704267685, -1.6948637100160543e-16);
/// xi_m = (3/2)^(2/3), as a double-double.
pub const FORCE_XI_M: Dd = Dd::new(1.3103706971044482, 1.0253948475159796e-16);
/// 2/lambda, lambda = xi_m^(1/2) = (3/2)^(1/3).
pub const FORCE_TWO_OVER_LAMBDA: f64 = 1.7471609294725978;
/// c_f of the force-rule law (mpmath).
pub const FORCE_C_F: f64 = 1.6546804562560966;

/// A kappa^-5, correctly rounded, for kappa > 0 (every finite kappa; +inf gives 0).
pub fn overlap_e(kappa: f64) -> f64 {
    if kappa == f64::INFINITY {
        return 0.0;
    }
    // kappa = m 2^k with m in [1, 2): A/m^5 in double-double on a normal scale, then 2^(-5k) once.
    let (m, k) = fp::frexp_any(kappa);
    let m2 = Dd::two_prod(m, m);
    let m5 = m2.mul(m2).mul_f64(m);
    fp::round_scaled(OVERLAP_A.div(m5), -5 * k)
}

/// The force rule's three-term law, correctly rounded to about 1e-21 relative (its own error at
/// kappa >= 1e7), for kappa >= 1.
pub fn force_e_law(kappa: f64) -> f64 {
    if kappa == f64::INFINITY {
        return 0.0;
    }
    // kappa = m 2^(3k), m in [1, 8): kappa^(5/3) = m c^2 2^(5k), c = m^(1/3) in double-double.
    let (mm, kk) = fp::frexp(kappa);
    let r = kk.rem_euclid(3);
    let m = mm * f64::from(1u32 << r);
    let k = (kk - r) / 3;
    let c = Dd::cbrt(m);
    let m53 = c.mul(c).mul_f64(m);
    let eps = fp::scale2(1.0 / m53.hi, -5 * k);
    let ln_inv_eps = 5.0 / 3.0 * kappa.ln();
    let delta = eps * (FORCE_C_F - FORCE_TWO_OVER_LAMBDA * ln_inv_eps);
    let h = FORCE_XI_M.add(FORCE_XI_M.mul_f64(delta));
    fp::round_scaled(h.div(m53), -5 * k)
}

/// e kappa^(5/3) of the force rule from the table, for kappa in [KAPPA_FORCE_TABLE, KAPPA_FORCE_LAW].
#[inline]
fn force_h_table(kappa: f64) -> f64 {
    let y = kappa.ln() - table::Y_MIN;
    let u = y / table::PIECE_WIDTH;
    let i = (u as usize).min(table::PIECES - 1);
    clenshaw(&table::FORCE_LARGE[i], 2.0 * (u - i as f64) - 1.0)
}

/// e of the force rule for kappa >= KAPPA_FORCE_TABLE (table, then the law).
#[inline]
pub fn force_e(kappa: f64) -> f64 {
    if kappa >= KAPPA_FORCE_LAW {
        return force_e_law(kappa);
    }
    let c = kappa.cbrt();
    force_h_table(kappa) / (kappa * c * c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_law_known_answers() {
        // e kappa^5 = A at powers of two (exact scaling): kappa = 16 gives A/2^20 exactly rounded.
        let a = OVERLAP_A.hi;
        assert_eq!(overlap_e(1.0), a);
        assert_eq!(overlap_e(16.0), a / 1048576.0);
        // Subnormal results: kappa = 2^215 gives A 2^-1075 = 2.579 units of 2^-1074 -> 3 units;
        // kappa = 2^216 gives A/64 = 0.081 units -> 0 (the true value is below 2^-1075).
        assert_eq!(overlap_e(2f64.powi(215)), f64::from_bits(3));
        assert_eq!(overlap_e(2f64.powi(216)), 0.0);
        assert_eq!(overlap_e(f64::MAX), 0.0);
    }

    #[test]
    fn force_law_matches_the_table_at_the_handover() {
        // The law is good to 1.9e-21 at kappa = 1e7 (mpmath).
        let k = KAPPA_FORCE_LAW;
        let below = force_h_table(k) / (k * k.cbrt() * k.cbrt());
        let law = force_e_law(k);
        // The table is good to 1.9e-15 relative (generator) and its kappa^(-5/3) to ~3 ulp.
        assert!((below / law - 1.0).abs() < 4e-15, "{below} {law}");
    }
}
