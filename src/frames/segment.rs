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
use super::levels::{coarse_image, eval_residual, fit_background, noise_sigma, otsu, quantiles};
use super::morphology::{edt, fill_holes, label};

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
