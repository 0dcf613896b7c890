//! Markers: dark dots printed on a sphere (the paper's Fig. 2), found inside a fitted disc
//! (docs/physics.md §8).
//!
//! A pixel is a marker candidate when it is darker than the mean of the disc pixels around it
//! (a box of half the radius, restricted to the disc so the background beyond the limb does
//! not count) by more than `max(5 sigma_noise, 0.1 contrast)`. Connected candidates form a dot
//! if on average they are 30% darker than the surface around them; its position is the centroid
//! on the sphere (subpixel; see `find_markers`). Only the inner 80% of the radius
//! is searched: towards the limb the shading falls steeply and would mimic dots, and a dot seen
//! edge-on is too foreshortened to place well.

use super::GrayImage;
use super::circle::Circle;

/// One marker seen in a frame, image coordinates (u right, v down), pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Marker {
    pub u: f64,
    pub v: f64,
    /// Pixels in the dot.
    pub area_px: usize,
    /// Mean darkness against the surrounding disc, intensity units.
    pub depth: f64,
}

/// A dot must be at least this much darker than the surface around it, relative to that
/// surface's brightness.
pub const MIN_RELATIVE_DEPTH: f64 = 0.3;

/// Fraction of the radius searched for markers.
pub const SEARCH_FRACTION: f64 = 0.8;

/// Finds the markers inside `disc`; see the module doc. `noise` is the pixel noise sigma and
/// `contrast` the sphere-background contrast, both in intensity units.
///
/// Discs over 48 px in radius are searched on block means (blocks of r/32 pixels): a dot
/// spans tens of pixels there, and the cost falls with the square of the block (a 200 px disc
/// took 8 ms a pass at full resolution).
pub fn find_markers(img: &GrayImage, disc: &Circle, noise: f64, contrast: f64) -> Vec<Marker> {
    let b = (disc.r / 32.0).floor() as usize;
    if b < 2 || !disc.r.is_finite() {
        return find_markers_at(img, disc, noise, contrast);
    }
    // The disc's bounding box in blocks, clipped to the image.
    let c0 = ((disc.cx - disc.r).floor().max(0.0) as usize).min(img.width);
    let r0 = ((disc.cy - disc.r).floor().max(0.0) as usize).min(img.height);
    let bw = ((disc.cx + disc.r).ceil().max(0.0) as usize)
        .min(img.width)
        .saturating_sub(c0)
        / b;
    let bh = ((disc.cy + disc.r).ceil().max(0.0) as usize)
        .min(img.height)
        .saturating_sub(r0)
        / b;
    if bw < 3 || bh < 3 {
        return Vec::new();
    }
    let mut small = GrayImage::filled(bw, bh, 0.0);
    let inv = 1.0 / (b * b) as f32;
    for rr in 0..bh {
        for cc in 0..bw {
            let mut acc = 0.0f32;
            for y in r0 + rr * b..r0 + (rr + 1) * b {
                let row =
                    &img.pixels[y * img.width + c0 + cc * b..y * img.width + c0 + (cc + 1) * b];
                acc += row.iter().sum::<f32>();
            }
            small.pixels[rr * bw + cc] = acc * inv;
        }
    }
    let bf = b as f64;
    let sd = Circle {
        cx: (disc.cx - c0 as f64) / bf,
        cy: (disc.cy - r0 as f64) / bf,
        r: disc.r / bf,
    };
    find_markers_at(&small, &sd, noise / bf, contrast)
        .into_iter()
        .map(|m| Marker {
            u: c0 as f64 + m.u * bf,
            v: r0 as f64 + m.v * bf,
            area_px: m.area_px * b * b,
            depth: m.depth,
        })
        .collect()
}

fn find_markers_at(img: &GrayImage, disc: &Circle, noise: f64, contrast: f64) -> Vec<Marker> {
    let (w, h) = (img.width as i64, img.height as i64);
    let r = disc.r;
    if r.is_nan() || r < 4.0 {
        return Vec::new();
    }
    // Bounding box of the disc (pixel indices), clipped to the image.
    let c0 = ((disc.cx - r).floor() as i64).clamp(0, w);
    let c1 = ((disc.cx + r).ceil() as i64).clamp(0, w);
    let r0 = ((disc.cy - r).floor() as i64).clamp(0, h);
    let r1 = ((disc.cy + r).ceil() as i64).clamp(0, h);
    let (bw, bh) = ((c1 - c0) as usize, (r1 - r0) as usize);
    if bw < 3 || bh < 3 {
        return Vec::new();
    }
    // Disc membership (pixel centre within 0.95 r: keeps the blurred limb out of the means).
    let inside = |c: usize, rr: usize, frac: f64| {
        let du = (c0 as usize + c) as f64 + 0.5 - disc.cx;
        let dv = (r0 as usize + rr) as f64 + 0.5 - disc.cy;
        du * du + dv * dv < frac * frac * r * r
    };
    let half = ((0.25 * r).round() as usize).max(2);
    let thr = (5.0 * noise).max(0.1 * contrast);
    let pix = |c: usize, rr: usize| img.get(c0 as usize + c, r0 as usize + rr) as f64;
    // Darkness against the local mean of the disc pixels in `use_px`, by integral images.
    // Disc membership of each pixel of the box, computed once for both passes.
    let member = |frac: f64| -> Vec<bool> {
        let mut m = Vec::with_capacity(bw * bh);
        for rr in 0..bh {
            m.extend((0..bw).map(|c| inside(c, rr, frac)));
        }
        m
    };
    let (in95, in_search) = (member(0.95), member(SEARCH_FRACTION));
    let darkness = |use_px: &[bool]| -> (Vec<f64>, Vec<f64>) {
        let stride = bw + 1;
        let mut si = vec![0.0f64; stride * (bh + 1)];
        let mut sm = vec![0.0f64; stride * (bh + 1)];
        for rr in 0..bh {
            let (mut ri, mut rm) = (0.0, 0.0);
            for c in 0..bw {
                if use_px[rr * bw + c] {
                    ri += pix(c, rr);
                    rm += 1.0;
                }
                si[(rr + 1) * stride + c + 1] = si[rr * stride + c + 1] + ri;
                sm[(rr + 1) * stride + c + 1] = sm[rr * stride + c + 1] + rm;
            }
        }
        let box_sum = |s: &[f64], c: usize, rr: usize| {
            let (a0, a1) = (c.saturating_sub(half), (c + half + 1).min(bw));
            let (b0, b1) = (rr.saturating_sub(half), (rr + half + 1).min(bh));
            s[b1 * stride + a1] - s[b0 * stride + a1] - s[b1 * stride + a0] + s[b0 * stride + a0]
        };
        let mut dark = vec![0.0f64; bw * bh];
        let mut level = vec![0.0f64; bw * bh];
        for rr in 0..bh {
            for c in 0..bw {
                if !in_search[rr * bw + c] {
                    continue;
                }
                let n = box_sum(&sm, c, rr);
                if n >= 1.0 {
                    let mean = box_sum(&si, c, rr) / n;
                    level[rr * bw + c] = mean;
                    dark[rr * bw + c] = (mean - pix(c, rr)).max(0.0);
                }
            }
        }
        (dark, level)
    };
    // Pass 1 finds the dots against a mean that they darken themselves; pass 2 takes the mean
    // without them (and their one-pixel rim), so the weights of partly covered rim pixels are
    // their true darkness and the centroid is not pulled.
    let (first, _) = darkness(&in95);
    let mut dotted = vec![false; bw * bh];
    for i in (0..bw * bh).filter(|&i| first[i] > thr) {
        dotted[i] = true;
        for j in neighbours8(i, bw, bh) {
            dotted[j] = true;
        }
    }
    let use2: Vec<bool> = in95.iter().zip(&dotted).map(|(&a, &d)| a && !d).collect();
    let (dark, level) = darkness(&use2);
    // Connected dots (8-neighbours: a small dot drawn at an angle may touch only diagonally).
    let max_area = (0.1 * std::f64::consts::PI * r * r) as usize;
    let above = |i: usize| dark[i] > thr;
    let mut seen = vec![false; bw * bh];
    // Pixels already counted in some dot's centroid (its pixels and their rim).
    let mut weighed = vec![usize::MAX; bw * bh];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    let mut members = Vec::new();
    for start in 0..bw * bh {
        if !above(start) || seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        members.clear();
        while let Some(i) = stack.pop() {
            members.push(i);
            for j in neighbours8(i, bw, bh) {
                if above(j) && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
        let n = members.len();
        // The dot's centre is the centroid on the sphere, not in the image: each pixel (the
        // dot's and its one-pixel rim, which holds the partly covered pixels below the
        // threshold) is lifted to the sphere and weighted by its covered fraction (darkness over
        // the local surface brightness: shading cancels) times the surface area it spans (R/z:
        // foreshortening). An image centroid would sit nearer the disc centre than the dot
        // (its limb side is foreshortened and less lit) and shrink every turn about x or y.
        let mut acc = [0.0f64; 3];
        let mut frac_sum = 0.0;
        for &i in &members {
            frac_sum += if level[i] > 1e-6 {
                dark[i] / level[i]
            } else {
                1.0
            };
        }
        for &i in &members {
            for j in std::iter::once(i).chain(neighbours8(i, bw, bh)) {
                if weighed[j] == start {
                    continue;
                }
                weighed[j] = start;
                let frac = if level[j] > 1e-6 {
                    dark[j] / level[j]
                } else {
                    dark[j]
                };
                let dx = (c0 as usize + j % bw) as f64 + 0.5 - disc.cx;
                let dy = (r0 as usize + j / bw) as f64 + 0.5 - disc.cy;
                // Pixels are inside 95% of the radius, so z >= 0.31 R: no blow-up.
                let z = (r * r - dx * dx - dy * dy).max(0.01 * r * r).sqrt();
                let w = frac * r / z;
                acc[0] += w * dx / r;
                acc[1] += w * dy / r;
                acc[2] += w * z / r;
            }
        }
        let norm = (acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2]).sqrt();
        // One pixel is noise; more than a tenth of the disc is shading or a shadow, not a dot;
        // a printed dot is much darker than the surface around it (the paper's are black), while
        // the curvature of the shading towards a dim limb makes shallow dips of 10-20%.
        if n >= 2 && n <= max_area && norm > 0.0 && frac_sum / n as f64 >= MIN_RELATIVE_DEPTH {
            out.push(Marker {
                u: disc.cx + r * acc[0] / norm,
                v: disc.cy + r * acc[1] / norm,
                area_px: n,
                depth: members.iter().map(|&i| dark[i]).sum::<f64>() / n as f64,
            });
        }
    }
    out
}

fn neighbours8(i: usize, w: usize, h: usize) -> impl Iterator<Item = usize> {
    let (r, c) = ((i / w) as i64, (i % w) as i64);
    (-1i64..=1)
        .flat_map(move |dr| (-1i64..=1).map(move |dc| (r + dr, c + dc)))
        .filter(move |&(rr, cc)| {
            (rr, cc) != (r, c) && rr >= 0 && cc >= 0 && rr < h as i64 && cc < w as i64
        })
        .map(move |(rr, cc)| rr as usize * w + cc as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    // Two dots drawn as spherical caps (angular radius 0.1 rad) on a Lambertian-shaded sphere
    // (light from the camera: brightness z/R), 16 x 16 supersampled. The known answer is the
    // projection of each cap's centre, (cx + R n_x, cy + R n_y): a cap is symmetric on the
    // sphere, which the spherical centroid exploits. Measured 0.011 px (pixel-centre weighting
    // of partly covered pixels, supersampling); bar 0.04 px.
    #[test]
    fn dots_found_at_their_centres() {
        let (w, h) = (80, 80);
        let disc = Circle {
            cx: 40.0,
            cy: 40.0,
            r: 30.0,
        };
        let dirs: [[f64; 3]; 2] = [[-0.25, 0.15, 0.0], [0.55, -0.3, 0.0]].map(|d| {
            let z = (1.0f64 - d[0] * d[0] - d[1] * d[1]).sqrt();
            [d[0], d[1], z]
        });
        let cos_a = 0.1f64.cos();
        let mut img = GrayImage::filled(w, h, 0.1);
        for r in 0..h {
            for c in 0..w {
                let mut acc = 0.0;
                for sy in 0..16 {
                    for sx in 0..16 {
                        let u = c as f64 + (sx as f64 + 0.5) / 16.0;
                        let v = r as f64 + (sy as f64 + 0.5) / 16.0;
                        let (dx, dy) = ((u - disc.cx) / disc.r, (v - disc.cy) / disc.r);
                        let rho2 = dx * dx + dy * dy;
                        acc += if rho2 >= 1.0 {
                            0.1
                        } else {
                            let z = (1.0 - rho2).sqrt();
                            let on_dot = dirs
                                .iter()
                                .any(|n| n[0] * dx + n[1] * dy + n[2] * z > cos_a);
                            (if on_dot { 0.15 } else { 0.9 }) * (0.2 + 0.8 * z)
                        };
                    }
                }
                img.set(c, r, (acc / 256.0) as f32);
            }
        }
        let m = find_markers(&img, &disc, 0.0, 0.7);
        assert_eq!(m.len(), 2, "{m:?}");
        for n in dirs {
            let want = (disc.cx + disc.r * n[0], disc.cy + disc.r * n[1]);
            let best = m
                .iter()
                .map(|k| (k.u - want.0).hypot(k.v - want.1))
                .fold(f64::INFINITY, f64::min);
            assert!(
                best < 0.04,
                "dot at {want:?}: nearest marker {best} px away"
            );
        }
    }

    #[test]
    fn plain_disc_has_no_markers() {
        let mut img = GrayImage::filled(60, 60, 0.2);
        for r in 0..60 {
            for c in 0..60 {
                if ((c as f64 + 0.5) - 30.0).hypot((r as f64 + 0.5) - 30.0) < 20.0 {
                    img.set(c, r, 0.9);
                }
            }
        }
        let disc = Circle {
            cx: 30.0,
            cy: 30.0,
            r: 20.0,
        };
        assert!(find_markers(&img, &disc, 0.01, 0.7).is_empty());
    }
}
