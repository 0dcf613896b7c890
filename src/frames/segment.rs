//! The coarse stage of detection (docs/physics.md §8): which polarity the spheres have, where
//! the blobs are, and one seed circle per sphere. Only a start for the subpixel edge stage.
//!
//! Steps: block-average to at most ~65 000 pixels (speed; also averages noise), smooth with a
//! 3 x 3 binomial kernel, split by Otsu's threshold, take the class that holds most of the image
//! border as background, fit a quadratic surface to it (uneven lighting) and subtract, decide
//! the polarity by which side of the background has more far-off pixels, threshold halfway to
//! the sphere level, fill holes (markers), label blobs, and find sphere centres as maxima of the
//! Euclidean distance transform; two maxima separated by a dip of the transform are two spheres
//! (touching spheres merge into one blob but keep a narrow neck between their centres).

use super::GrayImage;
use super::circle::{Circle, fit_robust, median};
use super::morphology::{edt, fill_holes, label};
use nalgebra::{SMatrix, SVector};

/// A seed: where a sphere probably is, in full-resolution image coordinates (u right, v down).
#[derive(Debug, Clone, PartialEq)]
pub struct Seed {
    pub circle: Circle,
    /// Index of the blob it came from (two seeds of one blob: touching spheres).
    pub blob: usize,
    /// The blob touches the image border.
    pub touches_border: bool,
}

/// What the coarse stage found.
#[derive(Debug, Clone, PartialEq)]
pub struct Coarse {
    /// +1: spheres brighter than the background; -1: darker.
    pub polarity: f64,
    /// Sphere level minus background level, in the polarity's sense (> 0), intensity units.
    pub contrast: f64,
    /// Pixel noise sigma of the full-resolution frame (from differences of neighbours, MAD).
    pub noise: f64,
    /// Blobs large enough to be considered.
    pub n_blobs: usize,
    pub seeds: Vec<Seed>,
    /// Block size of the coarse grid, pixels.
    pub factor: usize,
}

/// Why the coarse stage found no usable spheres.
#[derive(Debug, Clone, PartialEq)]
pub enum CoarseError {
    /// Nothing stands out from the background by more than the noise allows.
    NoContrast { contrast: f64, noise: f64 },
    /// No blob of sphere size.
    NoBlob,
    /// The frame is too small to analyse.
    TooSmall { width: usize, height: usize },
}

impl std::fmt::Display for CoarseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CoarseError::NoContrast { contrast, noise } => write!(
                f,
                "no sphere: nothing stands out from the background (contrast {contrast:.3}, noise {noise:.3})"
            ),
            CoarseError::NoBlob => write!(f, "no sphere: no blob of sphere size"),
            CoarseError::TooSmall { width, height } => {
                write!(f, "frame of {width} x {height} pixels is too small")
            }
        }
    }
}

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
fn coarse_image(img: &GrayImage, factor: usize) -> GrayImage {
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
fn fit_background(img: &GrayImage, use_px: &[bool]) -> Option<[f64; 6]> {
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
fn quantiles(v: &[f32], q_lo: f64, q_hi: f64) -> (f32, f32) {
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
fn eval_residual(a: &[f64; 6], img: &GrayImage, resid: &mut [f32]) {
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

/// The coarse stage; see the module doc. `max_pixels` bounds the coarse grid (speed).
pub fn coarse(img: &GrayImage, max_pixels: usize) -> Result<Coarse, CoarseError> {
    let (w0, h0) = (img.width, img.height);
    if w0 < 16 || h0 < 16 {
        return Err(CoarseError::TooSmall {
            width: w0,
            height: h0,
        });
    }
    let factor = ((w0 * h0) as f64 / max_pixels as f64)
        .sqrt()
        .ceil()
        .max(1.0) as usize;
    let cimg = coarse_image(img, factor);
    let (w, h) = (cimg.width, cimg.height);
    let noise = noise_sigma(img);
    // Noise of the coarse grid: block mean of factor^2 pixels, then the binomial kernel
    // (sum of squared weights (6/16)^2).
    let noise_c = noise / factor as f64 * 0.375;

    // 1. Otsu split, background = the class holding most of the border.
    let t0 = otsu(&cimg.pixels);
    // The border pixels' indices: top and bottom rows, then the columns between them.
    let border: Vec<usize> = if w >= 2 && h >= 2 {
        (0..w)
            .flat_map(|c| [c, (h - 1) * w + c])
            .chain((1..h - 1).flat_map(|r| [r * w, r * w + w - 1]))
            .collect()
    } else {
        (0..w * h).collect()
    };
    let border_hi = border.iter().filter(|&&i| cimg.pixels[i] > t0).count();
    let border_n = 2 * (w + h) - 4;
    let bg_hi = 2 * border_hi > border_n;
    let mut bg_mask: Vec<bool> = cimg.pixels.iter().map(|&v| (v > t0) == bg_hi).collect();

    // 2. Background surface, twice: the second fit uses the pixels the first one called
    //    background after subtraction.
    let mut resid = vec![0.0f32; w * h];
    let mut polarity = if bg_hi { -1.0 } else { 1.0 };
    let mut level = 0.0;
    for round in 0..2 {
        let Some(a) = fit_background(&cimg, &bg_mask) else {
            return Err(CoarseError::NoBlob);
        };
        eval_residual(&a, &cimg, &mut resid);
        // Polarity: the side with more pixels far from the background. Markers and shaded limbs
        // put some pixels on the other side, but far fewer than the discs.
        let (lo, hi) = quantiles(&resid, 0.005, 0.995);
        let t = 0.25 * hi.max(-lo);
        let (n_pos, n_neg) = resid.iter().fold((0usize, 0usize), |(p, n), &v| {
            (p + (v > t) as usize, n + (v < -t) as usize)
        });
        polarity = if n_pos >= n_neg { 1.0 } else { -1.0 };
        let mut far: Vec<f64> = resid
            .iter()
            .map(|&v| v * polarity as f32)
            .filter(|&v| v > t)
            .map(|v| v as f64)
            .collect();
        if far.is_empty() {
            return Err(CoarseError::NoContrast {
                contrast: 0.0,
                noise,
            });
        }
        level = median(&mut far);
        if round == 0 {
            let half = (0.5 * level) as f32;
            for i in 0..w * h {
                bg_mask[i] = resid[i] * (polarity as f32) < half;
            }
        }
    }
    // A sphere must stand out by many noise sigmas (12: a threshold at half of it is still 6
    // sigma above the background, so noise alone makes no blobs).
    if level.is_nan() || level <= 12.0 * noise_c {
        return Err(CoarseError::NoContrast {
            contrast: level,
            noise,
        });
    }
    let thr = (0.5 * level) as f32;
    let mut mask: Vec<bool> = resid.iter().map(|&v| v * polarity as f32 > thr).collect();
    fill_holes(&mut mask, w, h);
    let (labels, areas) = label(&mask, w, h);
    let largest = areas.iter().copied().max().unwrap_or(0);
    // Blobs under 2% of the largest, or under 12 coarse pixels, are specks (noise, dust).
    let min_area = (largest / 50).max(12);
    let keep: Vec<bool> = areas.iter().map(|&a| a >= min_area).collect();
    if !keep.iter().any(|&k| k) {
        return Err(CoarseError::NoBlob);
    }
    let fg: Vec<bool> = labels
        .iter()
        .map(|&l| l != 0 && keep[l as usize - 1])
        .collect();
    let dist = edt(&fg, w, h);
    let f = factor as f64;
    let candidates = distance_maxima(&labels, &dist, w, h);
    let mut seeds = Vec::new();
    let mut n_blobs = 0;
    for (b, &k) in keep.iter().enumerate() {
        if !k {
            continue;
        }
        n_blobs += 1;
        let lab = b as u32 + 1;
        for (centre, value) in blob_seeds(&candidates, lab, &dist, w) {
            seeds.push((b, [centre[0] * f, centre[1] * f], value * f));
        }
    }
    // Seeds far smaller than the largest are bumps, not spheres (diameter ratios up to 5).
    let vmax = seeds.iter().map(|s| s.2).fold(0.0, f64::max);
    seeds.retain(|s| s.2 >= 0.2 * vmax);
    let mut touches = vec![false; areas.len()];
    for &i in border.iter().filter(|&&i| labels[i] != 0) {
        touches[labels[i] as usize - 1] = true;
    }
    // Boundary points (between a blob pixel and a background pixel inside the image), assigned
    // to the seed they are nearest to in the sense |p - s| - r_s.
    let mut pts: Vec<Vec<[f64; 2]>> = vec![Vec::new(); seeds.len()];
    for r in 0..h {
        for c in 0..w {
            let i = r * w + c;
            if !fg[i] {
                continue;
            }
            let lab = labels[i] as usize - 1;
            for (dc, dr) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
                let (cc, rr) = (c as i64 + dc, r as i64 + dr);
                if cc < 0 || rr < 0 || cc >= w as i64 || rr >= h as i64 {
                    continue;
                }
                if fg[rr as usize * w + cc as usize] {
                    continue;
                }
                let p = [
                    (c as f64 + 0.5 + 0.5 * dc as f64) * f,
                    (r as f64 + 0.5 + 0.5 * dr as f64) * f,
                ];
                let best = seeds
                    .iter()
                    .enumerate()
                    .filter(|(_, s)| s.0 == lab)
                    .min_by(|a, b| {
                        let da = (p[0] - a.1.1[0]).hypot(p[1] - a.1.1[1]) - a.1.2;
                        let db = (p[0] - b.1.1[0]).hypot(p[1] - b.1.1[1]) - b.1.2;
                        da.total_cmp(&db)
                    });
                if let Some((k, _)) = best {
                    pts[k].push(p);
                }
            }
        }
    }
    let seeds = seeds
        .iter()
        .zip(&pts)
        .map(|(&(b, centre, value), p)| {
            let guess = Circle {
                cx: centre[0],
                cy: centre[1],
                r: value,
            };
            // The blob outline is a better start than the distance maximum when a sphere is cut
            // by the image border or shaded at its limb; keep it only when it is plausible.
            let circle = match fit_robust(p, None, 2.5, f, 6) {
                Ok(rf)
                    if rf.fit.circle.r < 2.5 * value + 2.0 * f
                        && rf.fit.circle.r > 0.6 * value
                        && (rf.fit.circle.cx - centre[0]).hypot(rf.fit.circle.cy - centre[1])
                            < value + 2.0 * f =>
                {
                    rf.fit.circle
                }
                _ => guess,
            };
            Seed {
                circle,
                blob: b,
                touches_border: touches[b],
            }
        })
        .collect();
    Ok(Coarse {
        polarity,
        contrast: level,
        noise,
        n_blobs,
        seeds,
        factor,
    })
}

/// Local maxima (8-neighbours) of the distance transform at least 1.5 coarse pixels deep, in
/// raster order, with their blob labels: the candidates for `blob_seeds`, found in one scan.
fn distance_maxima(labels: &[u32], dist: &[f32], w: usize, h: usize) -> Vec<(u32, usize, f32)> {
    let mut maxima = Vec::new();
    for r in 0..h {
        for c in 0..w {
            let i = r * w + c;
            if labels[i] == 0 || dist[i] < 1.5 {
                continue;
            }
            let v = dist[i];
            let mut is_max = true;
            'n: for dr in -1i64..=1 {
                for dc in -1i64..=1 {
                    let (rr, cc) = (r as i64 + dr, c as i64 + dc);
                    if rr < 0 || cc < 0 || rr >= h as i64 || cc >= w as i64 {
                        continue;
                    }
                    if dist[rr as usize * w + cc as usize] > v {
                        is_max = false;
                        break 'n;
                    }
                }
            }
            if is_max {
                maxima.push((labels[i], i, v));
            }
        }
    }
    maxima
}

/// Sphere centres in one blob: maxima of the distance transform, greedily from the largest; a
/// further maximum counts as another sphere only if the transform dips below 60% of the smaller
/// value on the straight line between them (a neck), so a ridge or plateau gives one seed.
/// Returns centres (pixel centres of the coarse grid) and transform values in coarse pixels.
fn blob_seeds(
    candidates: &[(u32, usize, f32)],
    lab: u32,
    dist: &[f32],
    w: usize,
) -> Vec<([f64; 2], f64)> {
    let mut maxima: Vec<(usize, f32)> = candidates
        .iter()
        .filter(|m| m.0 == lab)
        .map(|m| (m.1, m.2))
        .collect();
    maxima.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut accepted: Vec<(usize, f32)> = Vec::new();
    for &(i, v) in &maxima {
        let separate = accepted.iter().all(|&(j, vj)| {
            let (r0, c0) = ((j / w) as f64, (j % w) as f64);
            let (r1, c1) = ((i / w) as f64, (i % w) as f64);
            let len = (r1 - r0).hypot(c1 - c0);
            let n = (len.ceil() as usize).max(1);
            let floor = 0.6 * v.min(vj);
            (0..=n).any(|k| {
                let t = k as f64 / n as f64;
                let (r, c) = (
                    (r0 + t * (r1 - r0)).round() as usize,
                    (c0 + t * (c1 - c0)).round() as usize,
                );
                dist[r * w + c] < floor
            })
        });
        if separate {
            accepted.push((i, v));
        }
    }
    accepted
        .iter()
        .map(|&(i, v)| ([(i % w) as f64 + 0.5, (i / w) as f64 + 0.5], v as f64))
        .collect()
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
