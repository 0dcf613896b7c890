//! Cheap approximations of the viscoelastic e(kappa): the small-kappa series and Pade approximants.
//!
//! **What they approximate**: e(kappa) of the dimensionless collision x'' = -x^(3/2) - kappa
//! x^(1/2) x' (docs/physics.md §2). The ODE ([`super::restitution_ode`]) and the master-curve table
//! ([`super::master`]) are the model; these are cross-checks and cheap approximations whose error
//! is stated ([`error_bound`]) and enforced on request ([`restitution_checked`]).
//!
//! **Small-kappa series** (Ramirez, Poeschel, Brilliantov & Schwager, PRE 60, 4465 (1999), whose
//! x^2 = (3/2) A (K/m_red)^(2/5) V^(1/5) is our kappa):
//! - overlap rule: 1 - e = C1 kappa - C2 kappa^2 + C3 kappa^3 - ...
//! - force rule:   1 - e = C1 kappa - C2 kappa^2 - (4/15) kappa^(5/2) + C3 kappa^3 + (2/5) C1 kappa^(7/2) ...
//!
//! with C1 = 2 (5/4)^(3/5) (2/5) B(3/5, 3/2) = 1.1534488580952887991 (closed form), C2 = (3/5) C1^2
//! (Ramirez et al.), C3 = 0.522882565 (numerical, about 9 digits) and the force-rule half-integer
//! terms from tools/reference/README.md (the values are in `tests/fixtures/vm_series.csv`).
//! [`Series::Order1`] .. [`Series::Order3`] keep every term through kappa^1, kappa^2, kappa^3.
//!
//! **Pade approximants** in x = kappa^(1/2), force rule only (the delayed-recovery end of contact
//! of Schwager & Poeschel 2007/2008, for which Mueller & Poeschel, PRE 84, 021302 (2011) give them):
//! - [`Pade::MullerPoeschel14`]: e = (1 + a1 x)/(1 + a1 x + b2 x^2 + b3 x^3 + b4 x^4) with the
//!   coefficients a1 = 0.501086, b2 = 1.15345, b3 = 0.577977, b4 = 0.532178 as printed (6 digits).
//!   We could not read the paper itself; these numbers are as quoted, with that citation and the
//!   name "[1/4] pade approximant", in a script of the MercuryDPM code base (getA.py). We checked
//!   them independently: they are, to their 6 digits, the [1/4] Pade approximant of the force-rule
//!   series through x^5, i.e. b2 = C1, b3 = a1 C1, b4 = C1^2 - C2 = (2/5) C1^2 and
//!   a1 b4 = 4/15 (the kappa^(5/2) coefficient).
//! - [`Pade::Exact14`] (ours): the same approximant with those coefficients to full precision.
//! - [`Pade::Ours15`] (ours): the [1/5] approximant, which also matches the kappa^3 term (C3).
//!   Its denominator has no positive real root (roots near -1.93 and two complex pairs), and it is
//!   about 6 times more accurate than [1/4] over kappa in [0, 100] (measured below).
//!
//! **Error bounds** ([`error_bound`]): for kappa <= [`KAPPA_TRUST`] twice the first omitted term
//! plus the differences of the Taylor coefficients that are matched only approximately; above it,
//! the largest error measured against the mpmath reference (tests/fixtures/vm_reference.csv) over
//! [0, 100] with a margin; none above kappa = 100 or for the series above KAPPA_TRUST.
//! tests/bench_methods.rs checks every bound against the reference values.

use super::{ContactEnd, Restitution};
use crate::error::{Error, Result, non_negative};

/// C1 = 2 (5/4)^(3/5) (2/5) B(3/5, 3/2) (closed form; tools/reference/README.md §1 (c)).
pub const C1: f64 = 1.153_448_858_095_288_8;
/// C2 = (3/5) C1^2 (Ramirez et al. 1999).
pub const C2: f64 = 0.6 * C1 * C1;
/// C3, estimated from the kappa = 1e-8 reference (about 9 digits; `c3_estimate`).
pub const C3: f64 = 0.522_882_565;
/// Uncertainty of [`C3`]: the estimate at kappa = 1e-8 carries a bias of about C4 * 1e-8.
pub const C3_UNCERTAINTY: f64 = 1e-8;
/// |C4|, rough (from the change of the C3 estimate between kappa = 1e-6 and 1e-8); used only in
/// the error bound of the overlap-rule [`Series::Order3`], with the factor 2 of every bound.
pub const C4_ABS_ROUGH: f64 = 0.35;
/// Force rule: coefficient of -kappa^(5/2) in 1 - e (exactly 4/15; tools/reference/README.md).
pub const FORCE_C52: f64 = 4.0 / 15.0;
/// Force rule: coefficient of +kappa^(7/2) in 1 - e (measured 0.461379539, consistent with
/// (2/5) C1 = 0.4613795432; used only as the first omitted term of the force-rule Order3 series).
pub const FORCE_C72: f64 = 0.461_379_539;

/// Where the series and Taylor-coefficient bounds are trusted (they hold with a wide margin up to
/// kappa = 1 at every reference point; 0.1 keeps them far inside that).
pub const KAPPA_TRUST: f64 = 0.1;
/// Largest kappa for which a Pade approximant's global error bound was measured.
pub const PADE_KAPPA_MAX: f64 = 100.0;

/// How many terms of the small-kappa series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr)]
pub enum Series {
    /// 1 - e = C1 kappa.
    #[strum(serialize = "order 1")]
    Order1,
    /// Every term through kappa^2.
    #[strum(serialize = "order 2")]
    Order2,
    /// Every term through kappa^3 (for the force rule including -(4/15) kappa^(5/2)).
    #[strum(serialize = "order 3")]
    Order3,
}

impl Series {
    pub const ALL: [Series; 3] = [Series::Order1, Series::Order2, Series::Order3];

    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Which Pade approximant (force rule).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr)]
pub enum Pade {
    /// [1/4] with Mueller & Poeschel's printed 6-digit coefficients.
    #[strum(serialize = "[1/4] Mueller-Poeschel")]
    MullerPoeschel14,
    /// [1/4] with full-precision coefficients (ours).
    #[strum(serialize = "[1/4] exact coefficients")]
    Exact14,
    /// [1/5] through the kappa^3 term (ours).
    #[strum(serialize = "[1/5] ours")]
    Ours15,
}

impl Pade {
    pub const ALL: [Pade; 3] = [Pade::MullerPoeschel14, Pade::Exact14, Pade::Ours15];

    pub fn name(self) -> &'static str {
        self.into()
    }

    /// Numerator and denominator coefficients in x = kappa^(1/2), lowest power first.
    pub fn coefficients(self) -> (&'static [f64], &'static [f64]) {
        match self {
            Pade::MullerPoeschel14 => (&MP14_NUM, &MP14_DEN),
            Pade::Exact14 => (&EXACT14_NUM, &EXACT14_DEN),
            Pade::Ours15 => (&OURS15_NUM, &OURS15_DEN),
        }
    }

    /// Largest |error in e| over kappa in (KAPPA_TRUST, PADE_KAPPA_MAX]: measured against the
    /// mpmath reference (maxima 8.64e-3 for [1/4] at kappa = 3, 1.33e-3 for [1/5] at kappa = 7),
    /// rounded up by a margin for the error between the reference points (the bench's dense
    /// stability map checks it against the ODE at 4 points per decade).
    pub fn global_bound(self) -> f64 {
        match self {
            Pade::MullerPoeschel14 | Pade::Exact14 => 1e-2,
            Pade::Ours15 => 2e-3,
        }
    }
}

const MP14_NUM: [f64; 2] = [1.0, 0.501086];
const MP14_DEN: [f64; 5] = [1.0, 0.501086, 1.15345, 0.577977, 0.532178];
// a1 = (4/15)/b4 with b4 = (2/5) C1^2; b2 = C1; b3 = a1 C1 (computed in mpmath at 30 digits, and
// re-derived from C1 in the unit test below).
const EXACT14_NUM: [f64; 2] = [1.0, 0.501_085_752_015_688_2];
const EXACT14_DEN: [f64; 5] = [
    1.0,
    0.501_085_752_015_688_2,
    C1,
    0.577_976_788_470_314_6,
    0.532_177_707_296_530_3,
];
// [1/5] of 1 - C1 x^2 + C2 x^4 + (4/15) x^5 - C3 x^6 (mpmath.pade at 40 digits; b2 = C1 and b4
// = (2/5) C1^2 as for [1/4]).
const OURS15_NUM: [f64; 2] = [1.0, 0.809_860_052_278_215_6];
const OURS15_DEN: [f64; 6] = [
    1.0,
    0.809_860_052_278_215_6,
    C1,
    0.934_132_152_517_298_7,
    0.532_177_707_296_530_3,
    0.164_322_799_185_802_3,
];

/// A cheap approximation of e(kappa).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Approximation {
    Series(Series),
    /// Force rule only.
    Pade(Pade),
}

impl Approximation {
    pub fn name(self) -> String {
        match self {
            Approximation::Series(s) => format!("series {}", s.name()),
            Approximation::Pade(p) => format!("pade {}", p.name()),
        }
    }
}

/// 1 - e from the small-kappa series (no checks; see [`restitution_series`]).
#[inline]
pub fn series_one_minus_e(kappa: f64, rule: ContactEnd, order: Series) -> f64 {
    let k = kappa;
    match order {
        Series::Order1 => C1 * k,
        Series::Order2 => k * (C1 - C2 * k),
        Series::Order3 => {
            let poly = k * (C1 + k * (-C2 + C3 * k));
            match rule {
                ContactEnd::Overlap => poly,
                ContactEnd::Force => poly - FORCE_C52 * k * k * k.sqrt(),
            }
        }
    }
}

/// e(kappa) from the small-kappa series; kappa must be finite and >= 0. The result is whatever the
/// truncated series gives (it is not e outside small kappa); see [`restitution_checked`].
pub fn restitution_series(kappa: f64, rule: ContactEnd, order: Series) -> Result<Restitution> {
    non_negative("dimensionless damping kappa", kappa)?;
    let one_minus_e = series_one_minus_e(kappa, rule, order);
    Ok(Restitution {
        e: 1.0 - one_minus_e,
        one_minus_e,
        rhs_evals: 0,
    })
}

#[inline]
fn poly(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ci| acc.mul_add(x, ci))
}

/// e and 1 - e from a Pade approximant (no checks). 1 - e = (den - num)/den keeps its relative
/// accuracy as kappa -> 0 because den - num is summed from its own coefficients.
#[inline]
pub fn pade_restitution_unchecked(kappa: f64, pade: Pade) -> Restitution {
    let x = kappa.sqrt();
    let (num, den) = pade.coefficients();
    let d = poly(den, x);
    let n = poly(num, x);
    // den - num: the constant and linear terms cancel exactly (both approximants have them equal).
    let diff = x * x * poly(&den[2..], x);
    Restitution {
        e: n / d,
        one_minus_e: diff / d,
        rhs_evals: 0,
    }
}

/// e(kappa) from a Pade approximant of the force rule; kappa must be finite and >= 0.
pub fn restitution_pade(kappa: f64, pade: Pade) -> Result<Restitution> {
    non_negative("dimensionless damping kappa", kappa)?;
    Ok(pade_restitution_unchecked(kappa, pade))
}

/// e(kappa) from an approximation, without an accuracy check. Pade approximants exist for the force
/// rule only: asking one for the overlap rule is an error.
pub fn restitution_approx(
    kappa: f64,
    rule: ContactEnd,
    approx: Approximation,
) -> Result<Restitution> {
    match approx {
        Approximation::Series(s) => restitution_series(kappa, rule, s),
        Approximation::Pade(p) => {
            if rule != ContactEnd::Force {
                return Err(Error::InvalidParameter {
                    name: "contact-end rule of a Pade approximant (0 = overlap)",
                    value: 0.0,
                    expected: "the force rule (the approximants are of its series)",
                });
            }
            restitution_pade(kappa, p)
        }
    }
}

/// Taylor coefficients t_0..t_{N-1} of num(x)/den(x) (`den[0] != 0`), by series division.
pub fn taylor_of_ratio<const N: usize>(num: &[f64], den: &[f64]) -> [f64; N] {
    let mut t = [0.0; N];
    for j in 0..N {
        let mut a = num.get(j).copied().unwrap_or(0.0);
        for i in 1..=j.min(den.len() - 1) {
            a -= den[i] * t[j - i];
        }
        t[j] = a / den[0];
    }
    t
}

/// Taylor coefficients of the force-rule e(x), x = kappa^(1/2), through x^7.
fn force_rule_taylor() -> [f64; 8] {
    [1.0, 0.0, -C1, 0.0, C2, FORCE_C52, -C3, -FORCE_C72]
}

/// A bound on |error in e| of `approx` at `kappa`, or `None` where none is known (the series above
/// [`KAPPA_TRUST`], a Pade approximant above [`PADE_KAPPA_MAX`] or for the overlap rule).
/// It includes 2 ulp of double rounding.
pub fn error_bound(kappa: f64, rule: ContactEnd, approx: Approximation) -> Option<f64> {
    if !(kappa.is_finite() && kappa >= 0.0) {
        return None;
    }
    let k = kappa;
    let rounding = 2.0 * f64::EPSILON;
    match approx {
        Approximation::Series(s) => {
            if k > KAPPA_TRUST {
                return None;
            }
            let first_omitted = match (s, rule) {
                (Series::Order1, _) => C2 * k * k,
                (Series::Order2, ContactEnd::Overlap) => C3 * k.powi(3),
                (Series::Order2, ContactEnd::Force) => FORCE_C52 * k * k * k.sqrt(),
                (Series::Order3, ContactEnd::Overlap) => C4_ABS_ROUGH * k.powi(4),
                (Series::Order3, ContactEnd::Force) => FORCE_C72 * k.powi(3) * k.sqrt(),
            };
            let c3_term = if s == Series::Order3 {
                C3_UNCERTAINTY * k.powi(3)
            } else {
                0.0
            };
            Some(2.0 * first_omitted + c3_term + rounding)
        }
        Approximation::Pade(p) => {
            if rule != ContactEnd::Force || k > PADE_KAPPA_MAX {
                return None;
            }
            if k > KAPPA_TRUST {
                return Some(p.global_bound());
            }
            let (num, den) = p.coefficients();
            let t: [f64; 8] = taylor_of_ratio(num, den);
            let s = force_rule_taylor();
            // The approximant matches the series through x^top exactly in exact arithmetic (top = 5
            // for [1/4], 6 for [1/5]); below top only the rounding of printed coefficients differs.
            let top = match p {
                Pade::MullerPoeschel14 | Pade::Exact14 => 6,
                Pade::Ours15 => 7,
            };
            let x = k.sqrt();
            let mut b = 0.0;
            let mut xp = 1.0;
            for j in 0..=top {
                let weight = if j == top { 2.0 } else { 1.0 };
                b += weight * (t[j] - s[j]).abs() * xp;
                xp *= x;
            }
            Some(b + C3_UNCERTAINTY * k.powi(3) + rounding)
        }
    }
}

/// e(kappa) from an approximation, only where its [`error_bound`] guarantees |error in e| <=
/// `tol` * min(1, 1 - e) (so both the absolute error of e and the relative error of 1 - e are at
/// most `tol`); elsewhere an error value saying so.
pub fn restitution_checked(
    kappa: f64,
    rule: ContactEnd,
    approx: Approximation,
    tol: f64,
) -> Result<Restitution> {
    let r = restitution_approx(kappa, rule, approx)?;
    match error_bound(kappa, rule, approx) {
        Some(b) if b <= tol * r.one_minus_e.clamp(0.0, 1.0) || (kappa == 0.0 && b <= tol) => Ok(r),
        _ => Err(Error::BeyondErrorBound {
            approximation: approx.name(),
            kappa,
            tol,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_14_coefficients_follow_from_c1() {
        // [1/4] of the force-rule series through x^5: b2 = C1, b4 = C1^2 - C2, a1 = (4/15)/b4,
        // b3 = a1 C1 (derived in the module docs; 1e-15 relative is a few roundings).
        let b4 = C1 * C1 - C2;
        let a1 = FORCE_C52 / b4;
        let close = |a: f64, b: f64| ((a - b) / b).abs() < 1e-15;
        assert!(close(EXACT14_DEN[4], b4));
        assert!(close(EXACT14_NUM[1], a1) && close(EXACT14_DEN[1], a1));
        assert!(close(EXACT14_DEN[3], a1 * C1));
        // The printed Mueller-Poeschel coefficients are these, rounded to the decimals printed.
        let decimals = [0, 6, 5, 6, 6];
        for ((p, e), d) in MP14_DEN.iter().zip(EXACT14_DEN.iter()).zip(decimals) {
            let scale = 10f64.powi(d);
            assert_eq!((e * scale).round() / scale, *p, "{p} vs {e}");
        }
        assert_eq!(MP14_NUM[1], MP14_DEN[1]);
    }

    #[test]
    fn pade_matches_the_series_through_its_order() {
        let s = force_rule_taylor();
        let t: [f64; 8] = taylor_of_ratio(&EXACT14_NUM, &EXACT14_DEN);
        for j in 0..=5 {
            assert!(
                (t[j] - s[j]).abs() < 1e-15,
                "[1/4] x^{j}: {} vs {}",
                t[j],
                s[j]
            );
        }
        let t: [f64; 8] = taylor_of_ratio(&OURS15_NUM, &OURS15_DEN);
        for j in 0..=6 {
            assert!(
                (t[j] - s[j]).abs() < 1e-15,
                "[1/5] x^{j}: {} vs {}",
                t[j],
                s[j]
            );
        }
    }

    #[test]
    fn one_minus_e_is_consistent_with_e() {
        for p in Pade::ALL {
            for k in [0.0, 1e-6, 0.3, 5.0, 100.0] {
                let r = pade_restitution_unchecked(k, p);
                assert!(
                    (r.e + r.one_minus_e - 1.0).abs() < 4.0 * f64::EPSILON,
                    "{p:?} {k}"
                );
            }
        }
    }

    #[test]
    fn checked_refuses_outside_the_bound() {
        let a = Approximation::Series(Series::Order2);
        assert!(restitution_checked(1e-4, ContactEnd::Overlap, a, 1e-6).is_ok());
        assert!(restitution_checked(0.5, ContactEnd::Overlap, a, 1e-6).is_err());
        assert!(restitution_checked(0.05, ContactEnd::Overlap, a, 1e-6).is_err());
        let p = Approximation::Pade(Pade::Ours15);
        assert!(restitution_checked(1.0, ContactEnd::Force, p, 1e-2).is_ok());
        assert!(restitution_checked(1.0, ContactEnd::Force, p, 1e-4).is_err());
        assert!(restitution_checked(1.0, ContactEnd::Overlap, p, 1.0).is_err());
        assert!(restitution_checked(f64::NAN, ContactEnd::Force, p, 1.0).is_err());
    }
}
