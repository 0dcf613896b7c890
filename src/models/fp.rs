//! Floating-point helpers for results that must be right to the last bit across the whole range
//! of f64: exact scaling by powers of two, and double-double ("dd") products and quotients.
//!
//! **What for.** The large-kappa laws e = A kappa^-5 and e ~ xi_m kappa^(-5/3) (docs/physics.md
//! §2) underflow for kappa above ~1e62 and ~1e194, and V_Y ~ sigma_y^(5/2) underflows for tiny
//! sigma_y; evaluated naively, intermediate powers under- or overflow long before the result does,
//! and a result in the subnormal range is rounded twice. Here the significand is computed in
//! double-double (about 106 bits: error-free transformations with FMA, Dekker 1971; Knuth TAOCP
//! vol. 2, 4.2.2) on a normal-range scale, and the power of two is applied once at the end with a
//! single rounding ([`round_scaled`]), so the result is the correctly rounded value of the dd
//! number (a subnormal or 0 only when the true value is).

/// A double-double number hi + lo with |lo| <= ulp(hi)/2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dd {
    pub hi: f64,
    pub lo: f64,
}

// Named methods rather than operator traits: every dd operation stays visible at the call site.
#[allow(clippy::should_implement_trait)]
impl Dd {
    pub const fn new(hi: f64, lo: f64) -> Self {
        Dd { hi, lo }
    }

    pub fn from_f64(x: f64) -> Self {
        Dd { hi: x, lo: 0.0 }
    }

    /// Error-free sum of two doubles (Knuth's two-sum).
    pub fn two_sum(a: f64, b: f64) -> Self {
        let s = a + b;
        let bb = s - a;
        let err = (a - (s - bb)) + (b - bb);
        Dd { hi: s, lo: err }
    }

    /// Error-free product of two doubles (FMA).
    pub fn two_prod(a: f64, b: f64) -> Self {
        let p = a * b;
        Dd {
            hi: p,
            lo: a.mul_add(b, -p),
        }
    }

    fn renorm(hi: f64, lo: f64) -> Self {
        let s = hi + lo;
        Dd {
            hi: s,
            lo: lo - (s - hi),
        }
    }

    pub fn add(self, o: Dd) -> Dd {
        let s = Dd::two_sum(self.hi, o.hi);
        Dd::renorm(s.hi, s.lo + self.lo + o.lo)
    }

    pub fn mul(self, o: Dd) -> Dd {
        let p = Dd::two_prod(self.hi, o.hi);
        Dd::renorm(p.hi, p.lo + (self.hi * o.lo + self.lo * o.hi))
    }

    pub fn mul_f64(self, b: f64) -> Dd {
        let p = Dd::two_prod(self.hi, b);
        Dd::renorm(p.hi, p.lo + self.lo * b)
    }

    /// self / o, to about 2^-104 relative.
    pub fn div(self, o: Dd) -> Dd {
        let q1 = self.hi / o.hi;
        // r = self - q1 o, exactly enough: two_prod keeps the leading product exact.
        let p = o.mul_f64(q1);
        let r = self.add(Dd::new(-p.hi, -p.lo));
        let q2 = r.hi / o.hi;
        let p2 = o.mul_f64(q2);
        let r2 = r.add(Dd::new(-p2.hi, -p2.lo));
        let q3 = r2.hi / o.hi;
        Dd::renorm(q1, q2).add(Dd::from_f64(q3))
    }

    /// The cube root of a positive double, to about 2^-104 relative (one Newton step in dd from
    /// the libm value).
    pub fn cbrt(x: f64) -> Dd {
        let c = x.cbrt();
        // c3 = c^3 exactly enough in dd; c_new = c - (c^3 - x)/(3 c^2).
        let c2 = Dd::two_prod(c, c);
        let c3 = c2.mul_f64(c);
        let resid = c3.add(Dd::from_f64(-x));
        let corr = resid.hi / (3.0 * c * c);
        Dd::renorm(c, -corr)
    }
}

/// x * 2^n, exact while the result is normal and rounded once when it is not (so a subnormal or
/// 0 result is the correctly rounded one). `x` must be normal or zero.
pub fn scale2(x: f64, n: i32) -> f64 {
    let mut x = x;
    let mut n = n;
    // Steps of 2^+-600 keep every intermediate normal (x starts near 1 in every caller), so only
    // the last multiplication can round.
    while n > 1000 {
        x *= pow2(600);
        n -= 600;
    }
    while n < -1000 {
        if x == 0.0 {
            return x;
        }
        x *= pow2(-600);
        n += 600;
    }
    if n >= -1022 {
        x * pow2(n)
    } else {
        // 2^n itself is subnormal: split so that the final product rounds once.
        (x * pow2(n + 600)) * pow2(-600)
    }
}

/// 2^n for -1022 <= n <= 1023, exactly.
fn pow2(n: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&n));
    f64::from_bits(((n + 1023) as u64) << 52)
}

/// The double nearest to (d.hi + d.lo) * 2^n (ties to even), for a positive normal dd d: one
/// rounding, also when the result is subnormal (where plain `scale2(d.hi, n)` would round the
/// already rounded d.hi a second time).
pub fn round_scaled(d: Dd, n: i32) -> f64 {
    let hi = scale2(d.hi, n);
    if !(hi.is_finite()) || hi >= f64::MIN_POSITIVE {
        // Normal result: scaling is exact, so hi + lo*2^n rounds once (lo is below half an ulp
        // of hi, so adding it can only matter at a tie, and renorm has already resolved that).
        return hi;
    }
    // Subnormal (or zero) result: count in units of the smallest subnormal, 2^-1074.
    let m = 1074 + n;
    // d * 2^m is below 2^53 here: exact scaling of both parts (they are normal or zero).
    let a = d.hi * 2f64.powi(m.clamp(-1000, 1000)) * 2f64.powi(m - m.clamp(-1000, 1000));
    let b = d.lo * 2f64.powi(m.clamp(-1000, 1000)) * 2f64.powi(m - m.clamp(-1000, 1000));
    let f = a.floor();
    // r is exact; b is far below ulp(a), so it matters only when r is exactly one half.
    let r = a - f;
    let up = r > 0.5 || (r == 0.5 && (b > 0.0 || (b == 0.0 && f % 2.0 == 1.0)));
    let k = if up { f + 1.0 } else { f };
    k * f64::from_bits(1)
}

/// Splits a positive normal x into (m, k) with x = m 2^k, m in [1, 2), exactly.
pub fn frexp(x: f64) -> (f64, i32) {
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    debug_assert!(
        exp != 0 && exp != 0x7ff,
        "frexp of a subnormal, zero or non-finite {x}"
    );
    let m = f64::from_bits((bits & !(0x7ffu64 << 52)) | (1023u64 << 52));
    (m, exp - 1023)
}

/// Splits any positive finite x (subnormals included) into (m, k) with x = m 2^k, m in [1, 2).
pub fn frexp_any(x: f64) -> (f64, i32) {
    if x >= f64::MIN_POSITIVE {
        frexp(x)
    } else {
        let (m, k) = frexp(x * pow2(64));
        (m, k - 64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_is_exact_and_rounds_once() {
        assert_eq!(scale2(1.5, 10), 1536.0);
        assert_eq!(scale2(1.0, -1074), f64::from_bits(1));
        // 1.5 * 2^-1075 lies between 2^-1075 (half the smallest subnormal) and 2^-1074: the
        // correctly rounded value is 2^-1074, and 0.5 * 2^-1074 exactly is a tie to even (0).
        assert_eq!(scale2(1.5, -1075), f64::from_bits(1));
        assert_eq!(scale2(1.0, -1075), 0.0);
        assert_eq!(scale2(1.0, 1023), 2f64.powi(1023));
        assert!(scale2(1.0, 1024).is_infinite());
        assert_eq!(scale2(1.0, -2000), 0.0);
        assert_eq!(scale2(2f64.powi(-500), 1500), 2f64.powi(1000));
    }

    #[test]
    fn dd_arithmetic_is_twice_as_precise() {
        // 1/3 in dd times 3 is 1 to 2^-104.
        let third = Dd::from_f64(1.0).div(Dd::from_f64(3.0));
        let one = third.mul_f64(3.0);
        assert!((one.hi - 1.0 + one.lo).abs() < 1e-31, "{one:?}");
        // cbrt(2)^3 = 2 to 2^-104.
        let c = Dd::cbrt(2.0);
        let c3 = c.mul(c).mul(c);
        assert!((c3.hi - 2.0 + c3.lo).abs() < 1e-30, "{c3:?}");
    }

    #[test]
    fn round_scaled_decides_subnormal_ties_with_the_low_part() {
        // 1.5 * 2^-1075 + a hair: rounds up to 2^-1074 either way; 0.5 ulp - a hair rounds down.
        let up = Dd::new(1.0, 1e-20);
        assert_eq!(round_scaled(up, -1075), f64::from_bits(1));
        let down = Dd::new(1.0, -1e-20);
        assert_eq!(round_scaled(down, -1075), 0.0);
        // 3 * 2^-1075 = 1.5 smallest subnormals: a tie, to even (2 units).
        assert_eq!(round_scaled(Dd::new(1.5, 0.0), -1074), f64::from_bits(2));
        assert_eq!(round_scaled(Dd::new(1.5, 1e-30), -1075), f64::from_bits(1));
        assert_eq!(round_scaled(Dd::new(1.25, 0.0), 3), 10.0);
    }

    #[test]
    fn frexp_splits_exactly() {
        assert_eq!(frexp(12.0), (1.5, 3));
        assert_eq!(frexp(f64::MAX).1, 1023);
        assert_eq!(frexp_any(f64::from_bits(1)), (1.0, -1074));
    }
}
