//! Grey-level statistics of the coarse stage ([`super::segment`]; docs/physics.md §8): the
//! pixel noise, block averaging, Otsu's threshold, quantiles, and the quadratic background
//! surface fitted to the background class and subtracted.

use super::GrayImage;
use super::circle::median;
use nalgebra::{SMatrix, SVector};

/// Pixel noise sigma from horizontal neighbour differences: 1.4826 MAD / sqrt 2, robust to the
/// few differences that straddle edges. Uses at most about 5 000 differences (spread rows;
/// the MAD's relative sampling error is then about 1.5%).
pub fn noise_sigma(img: &GrayImage) -> f64 {
    let (w, h) = (img.width, img.height);
    if w < 2 || h == 0 {
        return 0.0;
    }
    let rows_wanted = (5_000 / (w - 1)).clamp(1, h);
    let stride = (h / rows_wanted).max(1);
    let mut d: Vec<f64> = Vec::with_capacity(rows_wanted * (w - 1));
    for r in (0..h).step_by(stride) {
        let row = &img.pixels[r * w..(r + 1) * w];
        d.extend(row.windows(2).map(|p| (p[1] - p[0]) as f64));
    }
    let med = median(&mut d);
    for x in d.iter_mut() {
        *x = (*x - med).abs();
    }
    1.4826 * median(&mut d) / std::f64::consts::SQRT_2
}

/// Block means over factor x factor blocks (the last partial row/column of blocks is dropped),
/// then a 3 x 3 binomial smoothing (edges replicated).
pub(super) fn coarse_image(img: &GrayImage, factor: usize) -> GrayImage {
    let (w, h) = (img.width / factor, img.height / factor);
    let mut out = GrayImage::filled(w, h, 0.0);
    let inv = 1.0 / (factor * factor) as f32;
    // Row by row of the image: each block's sum gains its rows' partial sums in order.
    let mut acc = vec![0.0f32; w];
    for r in 0..h {
        acc.fill(0.0);
        for rr in r * factor..(r + 1) * factor {
            let row = &img.pixels[rr * img.width..rr * img.width + w * factor];
            if factor == 2 {
                // The common case (frames up to ~256 x 256), without the inner loop.
                for (a, pair) in acc.iter_mut().zip(row.chunks_exact(2)) {
                    *a += pair[0] + pair[1];
                }
            } else {
                for (a, block) in acc.iter_mut().zip(row.chunks_exact(factor)) {
                    *a += block.iter().sum::<f32>();
                }
            }
        }
        for (o, a) in out.pixels[r * w..(r + 1) * w].iter_mut().zip(&acc) {
            *o = a * inv;
        }
    }
    // Row slices rather than `get`: the same sums without per-pixel bounds arithmetic.
    let mut tmp = out.clone();
    for (src, dst) in out
        .pixels
        .chunks_exact(w)
        .zip(tmp.pixels.chunks_exact_mut(w))
    {
        for c in 0..w {
            let (a, b, d) = (src[c.saturating_sub(1)], src[c], src[(c + 1).min(w - 1)]);
            dst[c] = 0.25 * a + 0.5 * b + 0.25 * d;
        }
    }
    for r in 0..h {
        let up = &tmp.pixels[r.saturating_sub(1) * w..][..w];
        let mid = &tmp.pixels[r * w..][..w];
        let down = &tmp.pixels[(r + 1).min(h - 1) * w..][..w];
        for (c, o) in out.pixels[r * w..(r + 1) * w].iter_mut().enumerate() {
            *o = 0.25 * up[c] + 0.5 * mid[c] + 0.25 * down[c];
        }
    }
    out
}

/// Otsu's threshold (Otsu 1979): the split of a 256-bin histogram that maximises the
/// between-class variance. Returns a value between the data's minimum and maximum.
pub fn otsu(values: &[f32]) -> f32 {
    let (lo, hi) = values
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi.is_nan() || lo.is_nan() || hi <= lo {
        return lo;
    }
    let mut hist = [0u64; 256];
    let scale = 255.999 / (hi - lo);
    for &v in values {
        hist[((v - lo) * scale) as usize] += 1;
    }
    let total = values.len() as f64;
    let sum_all: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &n)| i as f64 * n as f64)
        .sum();
    let (mut w0, mut sum0, mut best, mut best_i) = (0.0, 0.0, -1.0, 0usize);
    for (i, &n) in hist.iter().enumerate() {
        w0 += n as f64;
        sum0 += i as f64 * n as f64;
        let w1 = total - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let m0 = sum0 / w0;
        let m1 = (sum_all - sum0) / w1;
        let between = w0 * w1 * (m0 - m1) * (m0 - m1);
        if between > best {
            best = between;
            best_i = i;
        }
    }
    lo + (best_i as f32 + 1.0) / scale
}

/// Least-squares quadratic surface a0 + a1 X + a2 Y + a3 X^2 + a4 XY + a5 Y^2 (X, Y scaled to
/// [-1, 1]) through the pixels where `use_px` is true, sampled on a grid of at most ~4 000
/// points (six coefficients need no more). `None` if singular (too few pixels).
pub(super) fn fit_background(img: &GrayImage, use_px: &[bool]) -> Option<[f64; 6]> {
    let (w, h) = (img.width, img.height);
    let stride = (((w * h) as f64 / 4_000.0).sqrt().floor() as usize).max(1);
    let mut ata = SMatrix::<f64, 6, 6>::zeros();
    let mut atb = SVector::<f64, 6>::zeros();
    // Sums of b_i b_j (i <= j; numbered row by row: (0,0) 0, (0,5) 5, (1,1) 6, (2,2) 11,
    // (3,3) 15, (4,4) 18, (5,5) 20) and of b_i v, b = [1, x, y, x^2, x y, y^2]. Every product
    // is x^a y^b, and y is fixed along a row: each row sums the powers of x (and x^a v) over
    // its pixels once, then adds them times the powers of y. Same sums, a third of the work.
    let mut u = [0.0f64; 21];
    let mut rhs = [0.0f64; 6];
    let xs: Vec<[f64; 4]> = (0..w)
        .step_by(stride)
        .map(|c| {
            let x = 2.0 * (c as f64 + 0.5) / w as f64 - 1.0;
            [x, x * x, x * x * x, x * x * x * x]
        })
        .collect();
    for r in (0..h).step_by(stride) {
        let y = 2.0 * (r as f64 + 0.5) / h as f64 - 1.0;
        let (y2, y3, y4) = (y * y, y * y * y, y * y * y * y);
        // Row sums of x^0..x^4 and of x^0..x^2 times the pixel value.
        let mut sx = [0.0f64; 5];
        let mut sv = [0.0f64; 3];
        for (c, p) in (0..w).step_by(stride).zip(&xs) {
            if !use_px[r * w + c] {
                continue;
            }
            let v = img.pixels[r * w + c] as f64;
            sx[0] += 1.0;
            sx[1] += p[0];
            sx[2] += p[1];
            sx[3] += p[2];
            sx[4] += p[3];
            sv[0] += v;
            sv[1] += p[0] * v;
            sv[2] += p[1] * v;
        }
        if sx[0] == 0.0 {
            continue;
        }
        u[0] += sx[0];
        u[1] += sx[1];
        u[2] += y * sx[0];
        u[3] += sx[2];
        u[4] += y * sx[1];
        u[5] += y2 * sx[0];
        u[8] += sx[3];
        u[9] += y * sx[2];
        u[10] += y2 * sx[1];
        u[14] += y3 * sx[0];
        u[15] += sx[4];
        u[16] += y * sx[3];
        u[17] += y2 * sx[2];
        u[19] += y3 * sx[1];
        u[20] += y4 * sx[0];
        rhs[0] += sv[0];
        rhs[1] += sv[1];
        rhs[2] += y * sv[0];
        rhs[3] += sv[2];
        rhs[4] += y * sv[1];
        rhs[5] += y2 * sv[0];
    }
    // (1,1) = (0,3) = x^2, (1,2) = (0,4) = x y, (2,2) = (0,5) = y^2, (2,3) = (1,4) = x^2 y,
    // (2,4) = (1,5) = x y^2, (4,4) = (3,5) = x^2 y^2.
    (u[6], u[7], u[11]) = (u[3], u[4], u[5]);
    (u[12], u[13], u[18]) = (u[9], u[10], u[17]);
    let mut k = 0;
    for i in 0..6 {
        atb[i] = rhs[i];
        for j in i..6 {
            ata[(i, j)] = u[k];
            ata[(j, i)] = u[k];
            k += 1;
        }
    }
    let sol = ata.cholesky()?.solve(&atb);
    sol.iter().all(|v| v.is_finite()).then(|| sol.into())
}

/// The q_lo- and q_hi-quantiles of `v` (nearest rank, q_lo <= q_hi; the ranks
/// floor((n - 1) q) in the order of `total_cmp`). A histogram of the top 12 bits of
/// order-preserving integer keys (sign, exponent, 3 mantissa bits) finds the bin that holds
/// each rank in one pass; the rank is then selected among that bin's values only.
pub(super) fn quantiles(v: &[f32], q_lo: f64, q_hi: f64) -> (f32, f32) {
    let n = v.len();
    let k_lo = ((n - 1) as f64 * q_lo) as usize;
    let k_hi = ((n - 1) as f64 * q_hi) as usize;
    // Unsigned keys in the order of `total_cmp`: negatives (sign bit set) have all bits
    // flipped, the others only the sign bit.
    let key = |x: f32| {
        let b = x.to_bits();
        b ^ (((b as i32 >> 31) as u32) | 0x8000_0000)
    };
    let unkey = |k: u32| {
        f32::from_bits(if k & 0x8000_0000 != 0 {
            k ^ 0x8000_0000
        } else {
            !k
        })
    };
    const SHIFT: u32 = 20;
    let mut hist = vec![0u32; 1 << (32 - SHIFT)];
    for &x in v {
        hist[(key(x) >> SHIFT) as usize] += 1;
    }
    // The bin holding rank k, and how many values lie in lower bins.
    let bin_of = |k: usize| {
        let mut below = 0usize;
        for (b, &c) in hist.iter().enumerate() {
            if below + c as usize > k {
                return (b as u32, below);
            }
            below += c as usize;
        }
        unreachable!("rank {k} of {n} values")
    };
    let (b_lo, below_lo) = bin_of(k_lo);
    let (b_hi, below_hi) = bin_of(k_hi);
    let (mut in_lo, mut in_hi) = (Vec::new(), Vec::new());
    for &x in v {
        let kx = key(x);
        if kx >> SHIFT == b_lo {
            in_lo.push(kx);
        } else if kx >> SHIFT == b_hi {
            in_hi.push(kx);
        }
    }
    let lo = *in_lo.select_nth_unstable(k_lo - below_lo).1;
    // One bin may hold both ranks.
    let hi = if b_hi == b_lo {
        *in_lo.select_nth_unstable(k_hi - below_lo).1
    } else {
        *in_hi.select_nth_unstable(k_hi - below_hi).1
    };
    (unkey(lo), unkey(hi))
}

/// `resid` = `img` minus the quadratic surface `a` (as `fit_background` scales X and Y).
pub(super) fn eval_residual(a: &[f64; 6], img: &GrayImage, resid: &mut [f32]) {
    let (w, h) = (img.width, img.height);
    let xs: Vec<f64> = (0..w)
        .map(|c| 2.0 * (c as f64 + 0.5) / w as f64 - 1.0)
        .collect();
    for r in 0..h {
        let y = 2.0 * (r as f64 + 0.5) / h as f64 - 1.0;
        let (src, dst) = (
            &img.pixels[r * w..(r + 1) * w],
            &mut resid[r * w..(r + 1) * w],
        );
        for ((&x, &p), d) in xs.iter().zip(src).zip(dst) {
            let bg =
                (a[0] + a[1] * x + a[2] * y + a[3] * x * x + a[4] * x * y + a[5] * y * y) as f32;
            *d = p - bg;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Against the nearest ranks of a sorted copy, on values with ties, signs, a -0.0, an
    // infinity and NaNs of both signs (all ordered by `total_cmp`), with both ranks in one
    // histogram bin (0.3, 0.7: most values share few bins) and in different ones.
    #[test]
    fn quantiles_match_sorted_ranks() {
        let mut state = 7u64;
        let mut v: Vec<f32> = (0..20_000)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 40) % 2001) as f32 / 100.0 - 10.0
            })
            .collect();
        v[17] = -0.0;
        v[5] = f32::NAN;
        v[6] = -f32::NAN;
        v[7] = f32::INFINITY;
        let mut sorted = v.clone();
        sorted.sort_by(|a, b| a.total_cmp(b));
        // (0.8, 0.81): about 6.0 and 6.2, one bin [6, 6.5).
        for (lo, hi) in [
            (0.005, 0.995),
            (0.0, 1.0),
            (0.3, 0.7),
            (0.5, 0.5),
            (0.8, 0.81),
        ] {
            let (a, b) = quantiles(&v, lo, hi);
            let rank = |q: f64| sorted[((v.len() - 1) as f64 * q) as usize];
            assert_eq!(
                (a.to_bits(), b.to_bits()),
                (rank(lo).to_bits(), rank(hi).to_bits()),
                "{lo} {hi}"
            );
        }
    }

    #[test]
    fn otsu_splits_two_levels() {
        let mut v = vec![0.2f32; 700];
        v.extend(vec![0.7f32; 300]);
        let t = otsu(&v);
        assert!(t > 0.2 && t <= 0.7, "{t}");
    }

    // A ramp v = col + 10 row: block means are the ramp at the block centres, and the binomial
    // smoothing keeps a linear function except on the border rows and columns, where the
    // replicated edge shifts it by a quarter of a coarse step (2 per coarse column, 20 per
    // coarse row for factor 2). Factor 2 and factor 3 take different summing paths. Tolerance
    // 1e-4: f32 rounding of values below 100 (1/9 is not exact), far below the 0.5 tested.
    #[test]
    fn coarse_image_of_a_ramp() {
        for (factor, w, h) in [(2usize, 10usize, 8usize), (3, 13, 9)] {
            let mut img = GrayImage::filled(w, h, 0.0);
            for r in 0..h {
                for c in 0..w {
                    img.set(c, r, (c + 10 * r) as f32);
                }
            }
            let out = coarse_image(&img, factor);
            let (cw, ch) = (w / factor, h / factor);
            assert_eq!((out.width, out.height), (cw, ch));
            let f = factor as f32;
            for r in 0..ch {
                for c in 0..cw {
                    let mean = (c as f32 + 0.5) * f - 0.5 + 10.0 * ((r as f32 + 0.5) * f - 0.5);
                    let edge = |i: usize, n: usize, step: f32| match i {
                        0 => 0.25 * step,
                        i if i == n - 1 => -0.25 * step,
                        _ => 0.0,
                    };
                    let want = mean + edge(c, cw, f) + edge(r, ch, 10.0 * f);
                    let got = out.get(c, r);
                    assert!(
                        (got - want).abs() < 1e-4,
                        "factor {factor} at ({c}, {r}): {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn noise_sigma_of_a_flat_noisy_frame() {
        // A deterministic pseudo-random sequence with known sigma: uniform on [-a, a] has sigma
        // a/sqrt 3. The MAD estimator is for Gaussians; for a uniform the difference of two is
        // triangular, whose MAD is (1 - 1/sqrt 2) 2a, so the estimate is
        // 1.4826 (2 - sqrt 2) a / sqrt 2 = 0.6141 a, against the true 0.5774 a (6% high).
        let (w, h) = (200, 100);
        let mut state = 12345u64;
        let a = 0.05;
        let mut img = GrayImage::filled(w, h, 0.5);
        for p in img.pixels.iter_mut() {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            *p = (0.5 + a * (2.0 * u - 1.0)) as f32;
        }
        let s = noise_sigma(&img);
        let want = 1.4826 * (2.0 - 2f64.sqrt()) * a / 2f64.sqrt();
        // 5 000 differences: the MAD's sampling error is about 1.5%; 5% allows 3 sigma.
        assert!((s - want).abs() < 0.05 * want, "{s} vs {want}");
    }
}
