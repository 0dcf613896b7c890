//! exp of four numbers at once, for the power law's evaluations on large data (one exp per
//! point per evaluation; the scalar `f64::exp` of the C library was about a fifth of a
//! 100 000-point power-law fit's CPU).
//!
//! **Method**: Tang's table-driven exp (P. T. P. Tang, "Table-driven implementation of the
//! exponential function in IEEE floating-point arithmetic", ACM TOMS 15(2), 1989), in the form
//! of the exp of ARM's optimized-routines by Szabolcs Nagy (glibc's since 2.28), with N = 128:
//!
//! - k = round(x N / ln2), by adding and subtracting 1.5 2^52 (the sum's low bits are k);
//! - r = (x - k c_hi) - k c_lo with c_hi + c_lo = ln2 / N, c_hi of 36 significant bits, so
//!   k c_hi is exact for |k| < 2^17 and so is the first subtraction (Sterbenz); |r| <= ln2 / 2N
//!   (0.0027) to within the rounding of x N / ln2;
//! - 2^(k/N) = 2^m 2^(j/N) with k = m N + j: 2^(j/N) = H_j (1 + T_j) from a table of 128
//!   correctly rounded doubles H_j and their rounded relative tails T_j (`vexp_table.rs`,
//!   written by `tools/reference/gen_exp_table.py` with mpmath), 2^m added to H_j's exponent
//!   bits;
//! - exp(x) = s + s (T_j + r + r^2/2 + r^3/6 + r^4/24 + r^5/120), s = 2^m H_j.
//!
//! **Error bound** (in units in the last place of the result): the Taylor polynomial's
//! truncation is below |r|^6 / 720 < 5.5e-19 (0.005 ulp, as the result's ulp is at least 2^-53
//! of it and s is within 0.3 % of it); the roundings of r, of the three additions of T_j, r and
//! the two higher-order groups and of s times the sum each err by at most 2^-53 times a number
//! below 0.0028 (0.003 ulp each, 0.015 in all; the roundings inside the higher-order groups are
//! smaller by a factor r); the table's H_j (1 + T_j) is 2^(j/N) to 2^-104. With the last
//! addition's rounding: within 0.52 ulp of exp(x), so at most 1 ulp from the correctly rounded
//! double, and at most 1 ulp from glibc's exp (within 0.511 ulp by its authors' bound). The
//! tests measure both.
//!
//! **Range**: every lane outside |x| < [`VECTOR_LIMIT`] (and every NaN lane) is recomputed by
//! the scalar `f64::exp`, so overflow, results near or below the smallest normal number
//! (x < -708.4), NaN and infinities are exactly std's. Inside the limit, |m| <= 1022 and s and
//! the result are normal numbers, so adding m to the exponent bits is exact.
//!
//! **Same bits on every code path**: the lanes are plain `[f64; 4]` arithmetic with no
//! `mul_add`; Rust never fuses a multiply and an add on its own, so the AVX2 + FMA copy of
//! [`exp_in_place`] (256-bit instructions) rounds every operation as the baseline code does. A
//! test compares both copies bit for bit. Each value depends on its own argument alone (lanes
//! never mix), so the grouping of points into fours, or a chunk's boundaries, change no number.

#[path = "vexp_table.rs"]
mod table;

/// Values per group.
pub const LANES: usize = 4;

/// |x| below which the table method is used (its result is then a normal number,
/// exp(-708) = 3.3e-307, exp(708) = 3.0e307, and 2^m fits the exponent field).
pub const VECTOR_LIMIT: f64 = 708.0;

const TABLE_BITS: u32 = 7;
const N: u64 = 1 << TABLE_BITS;
/// 1.5 2^52: x N / ln2 + SHIFT rounds x N / ln2 to an integer held in the low bits.
const SHIFT: f64 = 6755399441055744.0;
const C2: f64 = 1.0 / 2.0;
const C3: f64 = 1.0 / 6.0;
const C4: f64 = 1.0 / 24.0;
const C5: f64 = 1.0 / 120.0;

/// exp of each lane: the table method for |x| < [`VECTOR_LIMIT`], `f64::exp` for any other
/// lane (see the module doc). Written step by step over the four lanes, with no branch before
/// the end, so that the compiler issues each step as one vector instruction.
#[inline(always)]
pub fn exp4(x: [f64; LANES]) -> [f64; LANES] {
    let inv_ln2_n = f64::from_bits(table::INV_LN2_N);
    let ln2_hi_n = f64::from_bits(table::LN2_HI_N);
    let ln2_lo_n = f64::from_bits(table::LN2_LO_N);
    let shifted = x.map(|x| x * inv_ln2_n + SHIFT);
    let mut r = [0.0; LANES];
    let mut s = [0.0; LANES];
    let mut tail = [0.0; LANES];
    for i in 0..LANES {
        let ki = shifted[i].to_bits();
        let kd = shifted[i] - SHIFT;
        r[i] = (x[i] - kd * ln2_hi_n) - kd * ln2_lo_n;
        let j = (ki % N) as usize;
        // (ki >> 7) << 52 is m in the exponent field (the shift's own bits fall off the top).
        s[i] = f64::from_bits(table::H_BITS[j].wrapping_add((ki >> TABLE_BITS) << 52));
        tail[i] = f64::from_bits(table::T_BITS[j]);
    }
    let mut y = [0.0; LANES];
    for i in 0..LANES {
        let r2 = r[i] * r[i];
        let p = tail[i] + r[i] + r2 * (C2 + r[i] * C3) + r2 * r2 * (C4 + r[i] * C5);
        y[i] = s[i] + s[i] * p;
    }
    // NaN compares false, so NaN lanes take the scalar path too.
    let inside = x.map(|x| x.abs() < VECTOR_LIMIT);
    if !(inside[0] & inside[1] & inside[2] & inside[3]) {
        outside(x, &mut y);
    }
    y
}

/// `f64::exp` on the lanes outside the table method's range.
#[cold]
#[inline(never)]
fn outside(x: [f64; LANES], y: &mut [f64; LANES]) {
    for (y, x) in y.iter_mut().zip(x) {
        if !(x.abs() < VECTOR_LIMIT) {
            *y = x.exp();
        }
    }
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
        let y = exp4([g[0], g[1], g[2], g[3]]);
        g.copy_from_slice(&y);
    }
    let rest = groups.into_remainder();
    if !rest.is_empty() {
        // Padding 0 (exp 0 = 1, dropped): the last values are computed as any others.
        let mut g = [0.0; LANES];
        g[..rest.len()].copy_from_slice(rest);
        let y = exp4(g);
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
    fn within_one_ulp_of_std_on_a_million_random_arguments() {
        // 1e6 seeded uniform arguments over [-745, 710] (the whole range where exp is neither 0
        // nor inf), 2e5 over [-8, 0] (the power law's) and [-1, 1], and log-uniform tiny |x|
        // (1e-300 to 1). Bound 1 ulp from glibc's exp where the result is normal: both are
        // within 0.52 ulp of exp(x) (the module doc's bound; glibc states 0.511), so they differ
        // by less than 1.04 ulp; a wrong constant, table entry or a fused operation on one path
        // would exceed it.
        let mut rng = StdRng::seed_from_u64(0x5eed_e4b0);
        let mut x: Vec<f64> = (0..1_000_000)
            .map(|_| rng.random_range(-745.0..710.0))
            .collect();
        x.extend((0..100_000).map(|_| rng.random_range(-8.0..0.0)));
        x.extend((0..100_000).map(|_| rng.random_range(-1.0..1.0)));
        x.extend((0..100_000).map(|_| {
            let m: f64 = rng.random_range(-300.0..0.0);
            let s = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            s * 10f64.powf(m)
        }));
        let worst = max_ulps_from_std(&x);
        assert!(worst <= 1, "max {worst} ulp from std's exp");
    }

    #[test]
    fn table_entries_are_powers_of_two() {
        // Against std's exp2 (glibc's, within 1 ulp), not as a reference but to catch a table
        // written for another N or out of order; the exact check is the generator's.
        for j in 0..N as usize {
            let h = f64::from_bits(table::H_BITS[j]);
            let t = f64::from_bits(table::T_BITS[j]);
            let want = (j as f64 / N as f64).exp2();
            assert!(ulps(h, want) <= 1, "H_{j} = {h:e}, exp2 {want:e}");
            assert!(t.abs() <= f64::EPSILON / 2.0, "T_{j} = {t:e}");
        }
    }

    /// Nanoseconds per value of [`exp_in_place`] and of std's exp on 4096 arguments in [-8, 0]
    /// (the power law's), best of 200 passes. `cargo test --release --lib vexp -- --ignored
    /// --nocapture`.
    #[test]
    #[ignore = "timing, not a check"]
    fn time_against_std() {
        let mut rng = StdRng::seed_from_u64(11);
        let x: Vec<f64> = (0..4096).map(|_| rng.random_range(-8.0..0.0)).collect();
        let mut y = x.clone();
        let mut per_value = |f: &mut dyn FnMut(&mut [f64])| {
            let mut best = f64::INFINITY;
            for _ in 0..200 {
                y.copy_from_slice(&x);
                let t = std::time::Instant::now();
                f(std::hint::black_box(&mut y));
                best = best.min(t.elapsed().as_secs_f64());
            }
            best / x.len() as f64 * 1e9
        };
        let ours = per_value(&mut |v| exp_in_place(v));
        let base = per_value(&mut |v| exp_in_place_baseline(v));
        let std = per_value(&mut |v| v.iter_mut().for_each(|v| *v = v.exp()));
        eprintln!("ns per value: table {ours:.2} (baseline copy {base:.2}), std {std:.2}");
    }

    #[test]
    fn matches_high_precision_reference_values() {
        // Known answer: exp at 2000 arguments over [-708, 708], at and next to the ends of the
        // reduction's intervals (where |r| is largest) and a few round ones, by mpmath at 40
        // digits, tests/fixtures/exp_reference.csv (tools/reference/gen_exp_reference.py).
        // The correctly rounded double of each is its 40-digit decimal parsed. Bound 1 ulp from
        // it: the method is within 0.52 ulp of exp(x) (module doc).
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
