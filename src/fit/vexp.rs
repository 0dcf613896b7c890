//! exp of four numbers at once, for the power law's evaluations on large data (one exp per
//! point per evaluation; the scalar `f64::exp` of the C library was about a fifth of a
//! 100 000-point power-law fit's CPU).
//!
//! **Method**: [`wide::f64x4::exp`], the Cephes / VCL (Agner Fog's vector class library)
//! scheme: r = round(x log2 e), a Cody-Waite reduction x' = (x - r ln2_hi) - r ln2_lo with
//! ln2_hi of 15 significant bits (so r ln2_hi and the first subtraction are exact for
//! |r| < 2^10), |x'| <= ln2 / 2, then exp(x') - 1 by its Taylor polynomial of degree 13 (Estrin
//! scheme; truncation error 0.347^14 / 14! = 4e-18 relative) and exp(x) = (1 + (exp(x') - 1)) 2^r,
//! the power of two built in the exponent bits. Its rounding errors stay within a few units in
//! the last place; the measured maximum is stated and asserted in the tests below.
//!
//! **Range**: wide's exp returns 0 for |x| >= 708.39 and for NaN or infinite x, including
//! large positive x where the answer is an overflow to infinity: a silent wrong number. Here
//! every lane outside |x| < [`VECTOR_LIMIT`] (and every NaN lane) is recomputed by the scalar
//! `f64::exp`, so overflow, results near or below the smallest normal number (x < -708.4), NaN
//! and infinities are exactly std's. Inside the limit the result is a normal number
//! (exp(-708) = 3.3e-307, exp(708) = 3.0e307) and the power-of-two step is exact.
//!
//! **Same bits on every code path**: the `wide` crate chooses its instructions when it is
//! compiled, for the baseline x86-64 the binary targets: two SSE2 halves, and its
//! `mul_add` / `mul_neg_add` are a multiply and a separate add (no fused multiply-add, whose
//! single rounding would change the bits). Compiled inside an AVX2 + FMA function
//! ([`exp_in_place`]'s copy, or [`crate::cpu::fast`]) the same operations may be issued as
//! wider instructions, but Rust never fuses a multiply and an add on its own, so each lane's
//! rounding is the same. A test compares both copies bit for bit. Each value depends on its
//! own argument alone (lanes never mix), so the grouping of points into fours, or a chunk's
//! boundaries, change no number.

use wide::{CmpLt, f64x4};

/// Values per group.
pub const LANES: usize = 4;

/// |x| below which the vector exp is used (wide's own cut-off is 708.39; a round number below
/// it keeps every vector result normal and away from the cut-off's edge).
pub const VECTOR_LIMIT: f64 = 708.0;

/// exp of each lane: the vector method for |x| < [`VECTOR_LIMIT`], `f64::exp` for any other
/// lane (see the module doc).
#[inline(always)]
pub fn exp4(x: f64x4) -> f64x4 {
    let y = x.exp();
    // NaN compares false, so NaN lanes take the scalar path too.
    if x.abs().cmp_lt(f64x4::splat(VECTOR_LIMIT)).all() {
        return y;
    }
    let (xs, mut ys) = (x.to_array(), y.to_array());
    for (y, x) in ys.iter_mut().zip(xs) {
        if !(x.abs() < VECTOR_LIMIT) {
            *y = x.exp();
        }
    }
    f64x4::new(ys)
}

/// `values[i] = exp(values[i])` for every i, four at a time ([`exp4`]; the same bits as
/// [`exp_in_place_baseline`] whichever code runs). Compiled a second time for AVX2 and FMA
/// where the processor has them, as a body called from several places would otherwise run as
/// baseline code inside [`crate::cpu::fast`].
pub fn exp_in_place(values: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::uses_avx2_fma() {
        // SAFETY: the processor has the features the function is compiled for.
        return unsafe { exp_in_place_avx2_fma(values) };
    }
    exp_in_place_baseline(values)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn exp_in_place_avx2_fma(values: &mut [f64]) {
    exp_in_place_baseline(values)
}

/// [`exp_in_place`] on the baseline code (for the tests' comparison of the two copies).
#[inline(always)]
pub fn exp_in_place_baseline(values: &mut [f64]) {
    let mut groups = values.chunks_exact_mut(LANES);
    for g in &mut groups {
        let y = exp4(f64x4::new([g[0], g[1], g[2], g[3]]));
        g.copy_from_slice(&y.to_array());
    }
    let rest = groups.into_remainder();
    if !rest.is_empty() {
        // Padding 0 (exp 0 = 1, dropped): the last values are computed as any others.
        let mut g = [0.0; LANES];
        g[..rest.len()].copy_from_slice(rest);
        let y = exp4(f64x4::new(g)).to_array();
        rest.copy_from_slice(&y[..rest.len()]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng, rngs::StdRng};

    /// Distance in units in the last place between two finite doubles of the same sign.
    fn ulps(a: f64, b: f64) -> u64 {
        assert!(
            a.is_finite() && b.is_finite() && (a >= 0.0) == (b >= 0.0),
            "{a} {b}"
        );
        a.to_bits().abs_diff(b.to_bits())
    }

    fn vexp(x: &[f64]) -> Vec<f64> {
        let mut y = x.to_vec();
        exp_in_place(&mut y);
        y
    }

    /// The largest ulp distance from std's exp over `x`, where the result is a normal number
    /// (elsewhere the scalar path must give std's bits).
    fn max_ulps_from_std(x: &[f64]) -> u64 {
        let y = vexp(x);
        let mut worst = 0;
        for (&x, &y) in x.iter().zip(&y) {
            let s = x.exp();
            if s.is_normal() {
                worst = worst.max(ulps(y, s));
            } else {
                assert!(y.to_bits() == s.to_bits(), "exp({x:e}) = {y:e}, std {s:e}");
            }
        }
        worst
    }

    #[test]
    fn specials_are_std_exp_bit_for_bit() {
        // Lanes outside the vector range, whatever their neighbours: overflow to inf, results
        // that are subnormal or 0, NaN and the infinities, next to lanes inside it.
        let specials = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            708.0,
            -708.0,
            708.39,
            -708.39,
            709.78,
            709.79,
            -709.78,
            710.0,
            1000.0,
            -720.0,
            -740.0,
            -744.4,
            -745.2,
            -746.0,
            -1e300,
            1e300,
            f64::MAX,
            f64::MIN,
        ];
        for (k, &s) in specials.iter().enumerate() {
            for lane in 0..LANES {
                let mut x = [0.5, -1.0 - k as f64, 3.0, 1e-300];
                x[lane] = s;
                let y = vexp(&x);
                let e = x[lane].exp();
                assert!(
                    y[lane].to_bits() == e.to_bits(),
                    "exp({s:e}) = {:e}, std {e:e}",
                    y[lane]
                );
                assert!(e.is_nan() || y[lane] == e);
            }
        }
        assert!(vexp(&[710.0])[0] == f64::INFINITY);
        assert!(vexp(&[f64::NAN])[0].is_nan());
        assert!(vexp(&[-745.0])[0] > 0.0 && !vexp(&[-745.0])[0].is_normal());
        // Inside the range: exact values and the tiny arguments (exp x = 1 + x rounds to 1).
        let y = vexp(&[0.0, -0.0, 1e-300, -1e-300, 1e-17, -1e-17, 5e-324, -5e-324]);
        assert!(y.iter().all(|&y| y == 1.0), "{y:?}");
        // Just inside the cut-off the vector result is normal and close to std's.
        assert!(
            max_ulps_from_std(&[707.999, -707.999, 707.9999999999999, -707.9999999999999]) <= 2
        );
    }

    #[test]
    fn within_two_ulps_of_std_on_a_million_random_arguments() {
        // 1e6 seeded uniform arguments over [-745, 710] (the whole range where exp is neither 0
        // nor inf) and 2e5 over [-1, 1] and log-uniform tiny |x| (1e-300 to 1). Measured maximum
        // distance from glibc's exp (itself within 0.51 ulp of the true value) where the result
        // is normal: 1 ulp. Bound 2: the vector method's own error (the rounding of its
        // polynomial and of 1 + p, under 1 ulp, see the known-answer test below) plus std's;
        // a wrong constant or a fused operation on one path would exceed it.
        let mut rng = StdRng::seed_from_u64(0x5eed_e4b0);
        let mut x: Vec<f64> = (0..1_000_000)
            .map(|_| rng.random_range(-745.0..710.0))
            .collect();
        x.extend((0..100_000).map(|_| rng.random_range(-1.0..1.0)));
        x.extend((0..100_000).map(|_| {
            let m: f64 = rng.random_range(-300.0..0.0);
            let s = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            s * 10f64.powf(m)
        }));
        let worst = max_ulps_from_std(&x);
        assert!(worst <= 2, "max {worst} ulp from std's exp");
    }

    #[test]
    fn matches_high_precision_reference_values() {
        // Known answer: exp at 2000 arguments over [-708, 708] (and a few round ones) by mpmath
        // at 40 digits, tests/fixtures/exp_reference.csv (tools/reference/gen_exp_reference.py).
        // The correctly rounded double of each is its 40-digit decimal parsed. Measured: at most
        // 1 ulp from it; bound 1 (the Taylor polynomial's truncation is 4e-18 relative, its
        // rounding and that of 1 + p stay under 1 ulp).
        let table = include_str!("../../tests/fixtures/exp_reference.csv");
        let (mut x, mut want) = (Vec::new(), Vec::new());
        for line in table.lines().skip(1) {
            let (a, b) = line.split_once(',').unwrap();
            x.push(a.parse::<f64>().unwrap());
            want.push(b.parse::<f64>().unwrap());
        }
        assert!(x.len() >= 2000, "{} rows", x.len());
        let y = vexp(&x);
        let worst = y
            .iter()
            .zip(&want)
            .map(|(&y, &w)| ulps(y, w))
            .max()
            .unwrap();
        assert!(worst <= 1, "max {worst} ulp from the correctly rounded exp");
    }

    #[test]
    fn both_code_paths_give_the_same_bits() {
        // Without AVX2 and FMA both calls take the baseline code and the comparison is void.
        if !crate::cpu::uses_avx2_fma() {
            eprintln!("this processor has no AVX2 and FMA: both calls take the baseline code");
        }
        let mut rng = StdRng::seed_from_u64(7);
        let x: Vec<f64> = (0..100_003)
            .map(|_| rng.random_range(-750.0..750.0))
            .chain([f64::NAN, 0.0, -0.0, 709.78, -708.5])
            .collect();
        let mut base = x.clone();
        exp_in_place_baseline(&mut base);
        let fast = vexp(&x);
        let same = base
            .iter()
            .zip(&fast)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "the AVX2 + FMA copy gives other bits");
    }
}
