//! Subpixel edge points along radial profiles (docs/physics.md §8).
//!
//! Image coordinates here are continuous with the origin at the top-left corner of the image,
//! u to the right and v down, so pixel (col, row) covers [col, col + 1) x [row, row + 1) and its
//! centre is (col + 0.5, row + 0.5). The detector converts to y-up coordinates at the end.

use super::GrayImage;

/// Bilinear interpolation between pixel centres at (u, v); `None` outside the square spanned by
/// the outermost pixel centres.
#[inline]
pub fn bilinear(img: &GrayImage, u: f64, v: f64) -> Option<f64> {
    let fx = u - 0.5;
    let fy = v - 0.5;
    if !(fx >= 0.0 && fy >= 0.0) {
        return None;
    }
    let (w, h) = (img.width, img.height);
    let x0 = fx as usize;
    let y0 = fy as usize;
    if x0 + 1 >= w || y0 + 1 >= h {
        // On the last row or column exactly: still inside.
        if (x0 + 1 == w && fx == x0 as f64 && y0 < h) || (y0 + 1 == h && fy == y0 as f64 && x0 < w)
        {
            let x1 = (x0 + 1).min(w - 1);
            let y1 = (y0 + 1).min(h - 1);
            let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
            let p = |c: usize, r: usize| img.pixels[r * w + c] as f64;
            let top = p(x0, y0) * (1.0 - tx) + p(x1, y0) * tx;
            let bot = p(x0, y1) * (1.0 - tx) + p(x1, y1) * tx;
            return Some(top * (1.0 - ty) + bot * ty);
        }
        return None;
    }
    let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
    let i = y0 * w + x0;
    let px = &img.pixels;
    let top = px[i] as f64 * (1.0 - tx) + px[i + 1] as f64 * tx;
    let bot = px[i + w] as f64 * (1.0 - tx) + px[i + w + 1] as f64 * tx;
    Some(top * (1.0 - ty) + bot * ty)
}

/// `bilinear` at a point known to be inside (u, v >= 0.5, u < width - 0.5, v < height - 0.5):
/// the same arithmetic without the border tests.
#[inline(always)]
fn bilinear_inside(px: &[f32], w: usize, u: f64, v: f64) -> f64 {
    let (fx, fy) = (u - 0.5, v - 0.5);
    // fx, fy >= 0 here, so truncation is the floor `bilinear` takes.
    let (x0, y0) = (fx as u32 as usize, fy as u32 as usize);
    let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
    let i = y0 * w + x0;
    let top = px[i] as f64 * (1.0 - tx) + px[i + 1] as f64 * tx;
    let bot = px[i + w] as f64 * (1.0 - tx) + px[i + w + 1] as f64 * tx;
    top * (1.0 - ty) + bot * ty
}

/// Subpixel position of a sampled peak: given samples `g[k-1], g[k], g[k+1]` with `g[k]` the
/// largest, the offset of the maximum from k in samples, in [-0.5, 0.5]. Gaussian interpolation
/// (a parabola through the logarithms; exact for a Gaussian peak, which a blurred edge's
/// derivative is) when all three are positive, else a parabola through the values (exact for a
/// quadratic). Fisher & Naidu 1996 compare the two; the Gaussian form has the smaller bias on
/// edge profiles.
pub fn subpixel_peak(gm: f64, g0: f64, gp: f64) -> f64 {
    let off = if gm > 0.0 && g0 > 0.0 && gp > 0.0 {
        let (lm, l0, lp) = (gm.ln(), g0.ln(), gp.ln());
        let den = lm - 2.0 * l0 + lp;
        if den < 0.0 {
            0.5 * (lm - lp) / den
        } else {
            0.0
        }
    } else {
        let den = gm - 2.0 * g0 + gp;
        if den < 0.0 {
            0.5 * (gm - gp) / den
        } else {
            0.0
        }
    };
    if off.is_finite() {
        off.clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// One edge point found on a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgePoint {
    /// Position in image coordinates (u right, v down), pixels.
    pub u: f64,
    pub v: f64,
    /// Peak of the smoothed directional derivative (intensity per pixel, sign made positive for
    /// the expected transition).
    pub strength: f64,
    /// Intensity step across the edge: the profile 2 px inside minus 2 px outside, in the
    /// polarity's sense. A limb as dark as the background has a steep gradient (the shading
    /// falls towards it) but hardly any step.
    pub step: f64,
    /// Angle of the ray, radians (atan2 of dv, du).
    pub angle: f64,
}

/// Settings of the radial profile search.
#[derive(Debug, Clone, Copy)]
pub struct ProfileSettings {
    /// Sample spacing along the ray, pixels.
    pub step: f64,
    /// Gaussian smoothing of the profile, pixels (noise suppression; a symmetric kernel does not
    /// move a symmetric edge).
    pub sigma: f64,
    /// Offsets of parallel rays averaged with the central one (tangential), pixels.
    pub spread: f64,
}

impl Default for ProfileSettings {
    fn default() -> Self {
        // Two samples per pixel so the peak is resolved. sigma trades noise against bias: a
        // front-lit sphere's shading falls as sqrt(R - rho) towards its limb, which pulls the
        // gradient maximum inward by a fraction of the total blur; on synthetic frames sigma
        // 0.7 px halved that bias against 1 px (0.04 against 0.12 px in the centre with a
        // background gradient) at the same noise (tests/frames_detect.rs). Three rays 1 px apart
        // average noise down by about sqrt(3).
        ProfileSettings {
            step: 0.5,
            sigma: 0.7,
            spread: 1.0,
        }
    }
}

/// The derivative kernel: a derivative-of-Gaussian filter of width sigma at spacing `step`,
/// normalised so that sum_j k_j f(s - x_j), x_j = (j - half) step, is -df/ds (exactly -1 on a
/// unit ramp): it measures how fast the profile falls outward.
pub fn derivative_kernel(s: &ProfileSettings) -> Vec<f64> {
    let half = (3.0 * s.sigma / s.step).ceil() as i64;
    let mut k: Vec<f64> = (-half..=half)
        .map(|j| {
            let x = j as f64 * s.step;
            x * (-x * x / (2.0 * s.sigma * s.sigma)).exp()
        })
        .collect();
    // On f(s) = s the response is sum_j k_j (s - x_j) = -sum_j k_j x_j (the k_j sum to 0).
    let norm: f64 = k
        .iter()
        .enumerate()
        .map(|(i, kj)| kj * ((i as i64 - half) as f64 * s.step))
        .sum();
    for kj in &mut k {
        *kj /= norm;
    }
    k
}

/// Searches one ray from `centre` (image coordinates) at `angle` for the strongest edge between
/// radii `r_lo` and `r_hi`: the maximum of `polarity` x (-d/ds) of the smoothed profile (so with
/// polarity +1 a bright-inside, dark-outside transition is positive), with subpixel
/// interpolation. Samples outside the image shorten the ray; a maximum at either end of the
/// usable range (no peak inside it) gives `None`, as does a maximum that is not positive.
#[allow(clippy::too_many_arguments)]
pub fn ray_edge(
    img: &GrayImage,
    centre: [f64; 2],
    angle: f64,
    r_lo: f64,
    r_hi: f64,
    polarity: f64,
    kernel: &[f64],
    s: &ProfileSettings,
    buf: &mut Vec<f64>,
) -> Option<EdgePoint> {
    let dir = [angle.cos(), angle.sin()];
    ray_edge_dir(
        img,
        centre,
        angle,
        dir,
        [r_lo, r_hi],
        polarity,
        kernel,
        s,
        buf,
    )
}

/// `ray_edge` with the ray's direction (cos, sin of `angle`) given, for callers that have it.
#[allow(clippy::too_many_arguments)]
pub(crate) fn ray_edge_dir(
    img: &GrayImage,
    centre: [f64; 2],
    angle: f64,
    dir: [f64; 2],
    [r_lo, r_hi]: [f64; 2],
    polarity: f64,
    kernel: &[f64],
    s: &ProfileSettings,
    buf: &mut Vec<f64>,
) -> Option<EdgePoint> {
    let [dc, ds] = dir;
    let (tc, ts) = (-ds, dc);
    let n = ((r_hi - r_lo) / s.step).floor() as usize + 1;
    let half = kernel.len() / 2;
    if n < kernel.len() + 3 {
        return None;
    }
    buf.clear();
    // The usable part of the ray: the longest run of in-image samples. Rays begin at the centre
    // side, so a run broken by the image border is cut there.
    let mut first_valid: Option<usize> = None;
    // Most rays lie wholly inside the image: then the three parallel rays are sampled without
    // the per-sample border tests (the same arithmetic as `bilinear`, so the same values). The
    // sample positions are linear in i, so the end points of the three rays bound them all;
    // the margin of 1e-6 px covers rounding in r_lo + i step.
    let inside = |u: f64, v: f64| {
        u >= 0.5 + 1e-6
            && v >= 0.5 + 1e-6
            && u < img.width as f64 - 0.5 - 1e-6
            && v < img.height as f64 - 0.5 - 1e-6
    };
    let r_end = r_lo + (n - 1) as f64 * s.step;
    let all_inside = [r_lo, r_end].iter().all(|&r| {
        let (u, v) = (centre[0] + r * dc, centre[1] + r * ds);
        [0.0, s.spread, -s.spread]
            .iter()
            .all(|&o| inside(u + o * tc, v + o * ts))
    });
    if all_inside {
        let (w, px) = (img.width, &img.pixels[..]);
        let sample = |u: f64, v: f64| bilinear_inside(px, w, u, v);
        first_valid = Some(0);
        for i in 0..n {
            let r = r_lo + i as f64 * s.step;
            let (u, v) = (centre[0] + r * dc, centre[1] + r * ds);
            let a = sample(u, v);
            let b = sample(u + s.spread * tc, v + s.spread * ts);
            let c = sample(u - s.spread * tc, v - s.spread * ts);
            // A product, not a division: the divider's latency held up the whole loop.
            buf.push((a + b + c) * (1.0 / 3.0));
        }
    }
    for i in (0..n).filter(|_| !all_inside) {
        let r = r_lo + i as f64 * s.step;
        let (u, v) = (centre[0] + r * dc, centre[1] + r * ds);
        let a = bilinear(img, u, v);
        let b = bilinear(img, u + s.spread * tc, v + s.spread * ts);
        let c = bilinear(img, u - s.spread * tc, v - s.spread * ts);
        match (a, b, c) {
            (Some(a), Some(b), Some(c)) => {
                if first_valid.is_none() {
                    first_valid = Some(i);
                }
                buf.push((a + b + c) * (1.0 / 3.0));
            }
            _ => {
                if first_valid.is_some() {
                    break;
                }
            }
        }
    }
    let start = first_valid?;
    let m = buf.len();
    if m < kernel.len() + 3 {
        return None;
    }
    // g[i] for i in half..m-half: derivative response at sample i.
    let mut best = (usize::MAX, f64::NEG_INFINITY);
    let g = |i: usize| -> f64 {
        let mut acc = 0.0;
        // kernel[j] meets f(s - (j - half) step) = buf[i + half - j].
        for (kj, bj) in kernel.iter().zip(buf[i - half..=i + half].iter().rev()) {
            acc += kj * bj;
        }
        polarity * acc
    };
    for i in half..m - half {
        let gi = g(i);
        if gi > best.1 {
            best = (i, gi);
        }
    }
    let (i, gmax) = best;
    if i <= half || i + 1 >= m - half || gmax.is_nan() || gmax <= 0.0 {
        return None;
    }
    let off = subpixel_peak(g(i - 1), gmax, g(i + 1));
    let r = r_lo + (start + i) as f64 * s.step + off * s.step;
    let d = (2.0 / s.step).round() as usize;
    let step = polarity * (buf[i.saturating_sub(d)] - buf[(i + d).min(m - 1)]);
    Some(EdgePoint {
        u: centre[0] + r * dc,
        v: centre[1] + r * ds,
        strength: gmax,
        step,
        angle,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subpixel_peak_exact_for_gaussian_and_parabola() {
        for x0 in [-0.45, -0.2, 0.0, 0.13, 0.4] {
            let g = |x: f64| (-(x - x0) * (x - x0) / (2.0 * 1.7f64.powi(2))).exp();
            assert!((subpixel_peak(g(-1.0), g(0.0), g(1.0)) - x0).abs() < 1e-12);
            let q = |x: f64| -3.0 - (x - x0) * (x - x0);
            assert!((subpixel_peak(q(-1.0), q(0.0), q(1.0)) - x0).abs() < 1e-12);
        }
    }

    /// The slope at the centre of the edge profile 0.3 (1 - tanh(x/b)) smoothed by a Gaussian
    /// of width sigma: the integral of 0.3/b sech^2(x/b) G_sigma(x) dx by the trapezoid rule on
    /// a fine grid (an independent check of the filter's normalisation).
    fn smoothed_tanh_slope(b: f64, sigma: f64) -> f64 {
        let n = 20000;
        let lim = 12.0 * sigma.max(b);
        let h = 2.0 * lim / n as f64;
        (0..=n)
            .map(|i| {
                let x = -lim + i as f64 * h;
                let w = if i == 0 || i == n { 0.5 } else { 1.0 };
                let g = (-x * x / (2.0 * sigma * sigma)).exp()
                    / (sigma * (2.0 * std::f64::consts::PI).sqrt());
                w * h * 0.3 / b / (x / b).cosh().powi(2) * g
            })
            .sum()
    }

    // An analytic edge: I = 0.2 + 0.3 (1 - tanh((u - e)/b)), odd about e, so any symmetric
    // derivative filter peaks exactly at e on the continuous profile. It is sampled at pixel
    // centres along rows (a vertical straight edge) and read back by bilinear interpolation,
    // which is what breaks the symmetry: with the default sigma 0.7 px the measured peak misses
    // e by up to 0.025 px for b = 1 px (at phases 0.25 and 0.75; 0.006 px with sigma 1 px), an
    // error odd in the subpixel phase, so it averages out round a circle. Bar: 0.03 px; a worse
    // interpolation or kernel fails it.
    #[test]
    fn edge_on_blurred_step_is_found_to_subpixel() {
        let s = ProfileSettings::default();
        let k = derivative_kernel(&s);
        let mut buf = Vec::new();
        let b = 1.0;
        for e in [30.0, 30.1, 30.25, 30.4, 30.5, 30.6, 30.75, 30.9] {
            let (w, h) = (64, 9);
            let mut img = GrayImage::filled(w, h, 0.0);
            for row in 0..h {
                for col in 0..w {
                    let u = col as f64 + 0.5;
                    let val = 0.2 + 0.3 * (1.0 - ((u - e) / b).tanh());
                    img.set(col, row, val as f32);
                }
            }
            // Bright inside (left), dark outside (right): polarity +1, ray to the right.
            let p = ray_edge(&img, [10.0, 4.5], 0.0, 5.0, 35.0, 1.0, &k, &s, &mut buf).unwrap();
            assert!((p.u - e).abs() < 0.03, "edge at {e}: found {}", p.u);
            assert!((p.v - 4.5).abs() < 1e-12);
            // Linear interpolation is an extra blur (a triangle of variance 1/6 px^2) that lowers
            // the peak by 4-7% here: within 10% of the smoothed continuous profile's slope.
            let want = smoothed_tanh_slope(b, s.sigma);
            assert!(
                (p.strength - want).abs() < 0.1 * want,
                "{} vs {want}",
                p.strength
            );
            // Opposite polarity sees no positive peak on this profile.
            assert!(ray_edge(&img, [10.0, 4.5], 0.0, 5.0, 35.0, -1.0, &k, &s, &mut buf).is_none());
        }
    }

    #[test]
    fn bilinear_exact_on_planes_and_none_outside() {
        let mut img = GrayImage::filled(5, 4, 0.0);
        for r in 0..4 {
            for c in 0..5 {
                img.set(c, r, (0.1 * c as f64 + 0.05 * r as f64) as f32);
            }
        }
        let plane = |u: f64, v: f64| 0.1 * (u - 0.5) + 0.05 * (v - 0.5);
        for (u, v) in [(0.5, 0.5), (2.3, 1.7), (4.5, 3.5), (4.5, 1.2), (1.1, 3.5)] {
            assert!((bilinear(&img, u, v).unwrap() - plane(u, v)).abs() < 1e-6);
        }
        assert!(bilinear(&img, 0.4, 1.0).is_none());
        assert!(bilinear(&img, 4.6, 1.0).is_none());
        assert!(bilinear(&img, 1.0, 3.6).is_none());
        assert!(bilinear(&img, f64::NAN, 1.0).is_none());
    }
}
