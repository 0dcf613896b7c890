//! Detection in one frame (docs/physics.md §8): seeds from the coarse stage, then subpixel edge
//! points on radial profiles and robust circle fits, three passes, then the markers.
//!
//! Pass 1 searches each ray over a wide band (0.5 r .. 1.5 r) around the seed circle; passes 2
//! and 3 search a narrow band around the previous fit, so dots and shading inside the disc are
//! no longer in reach. Rays whose edge would lie on the other sphere (touching spheres) are
//! skipped, as are rays leaving the image. Edge points weaker than 30% of the circle's typical
//! (75th percentile) strength, or within 5 sigma of the noise, are dropped: a limb as dark as
//! the background (lamps of unequal strength) has no edge, and the fit uses the visible arcs.

use super::GrayImage;
use super::circle::{Circle, FitError, fit_robust};
use super::edges::{EdgePoint, ProfileSettings, derivative_kernel, ray_edge_dir};
use super::markers::{Marker, find_markers};
use super::segment::{Coarse, CoarseError, coarse};

/// How a sphere's radius was treated in its fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub enum RadiusMode {
    /// Fitted with the centre.
    Free,
    /// Held at a known value (short visible arc).
    #[strum(serialize = "fixed_radius")]
    Fixed,
}

impl RadiusMode {
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// One sphere fitted in one frame. Image coordinates: u right, v down, pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereFit {
    pub circle: Circle,
    /// Rms distance of the used edge points from the circle, pixels.
    pub rms_px: f64,
    /// Standard errors of the centre from the fit's covariance (a lower bound), pixels.
    pub centre_err_px: [f64; 2],
    /// Edge points used by the fit.
    pub n_edge: usize,
    /// Angle of the circle covered by the used edge points: 360 minus the largest gap, degrees.
    pub coverage_deg: f64,
    pub radius_mode: RadiusMode,
    /// The circle extends beyond the image.
    pub clipped: bool,
    /// Every edge point of the last pass, and whether the fit used it.
    pub edges: Vec<EdgePoint>,
    pub inliers: Vec<bool>,
}

/// What one frame gave.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameDetection {
    pub width: usize,
    pub height: usize,
    /// One or two spheres (in no particular order; identities are assigned across frames).
    pub spheres: Vec<SphereFit>,
    /// Markers inside each sphere, same order as `spheres`.
    pub markers: Vec<Vec<Marker>>,
    pub polarity: f64,
    pub contrast: f64,
    pub noise: f64,
    /// Spheres seen but not fitted, with the reason (e.g. mostly outside the image).
    pub left_out: Vec<String>,
}

/// Why a frame gave nothing usable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DetectError {
    #[error("{0}")]
    Coarse(CoarseError),
    /// More than two sphere-sized blobs (or maxima): not a two-sphere frame. `at_edge` of them
    /// touch the image border, where a sphere leaving the view can be cut into two by a marker.
    #[error(
        "{n} sphere-sized blobs where at most 2 spheres were expected{}",
        if *at_edge > 0 {
            format!(" ({at_edge} of them cut by the frame's edge, where a sphere leaving the view can split in two)")
        } else {
            String::new()
        }
    )]
    TooManyBlobs { n: usize, at_edge: usize },
    /// Seeds were found but no circle could be fitted to any.
    #[error("no sphere could be fitted: {}", reasons.join("; "))]
    NoFit { reasons: Vec<String> },
}

/// Settings of the detector.
#[derive(Debug, Clone)]
pub struct DetectSettings {
    /// Largest coarse grid for the seed stage, pixels.
    pub max_coarse_pixels: usize,
    /// Radii known in advance (pixels), e.g. from the diameters and the pixel size. A fit whose
    /// visible arc is short holds its radius at the nearest of these.
    pub known_radii_px: Vec<f64>,
    /// Below this coverage (degrees) a known radius is held fixed.
    pub free_coverage_deg: f64,
    /// Below this coverage (degrees), or with fewer than `min_edge_points`, a sphere is left out.
    pub min_coverage_deg: f64,
    pub min_edge_points: usize,
    pub profile: ProfileSettings,
    /// Edge points whose intensity step is below this fraction of the circle's typical step
    /// are dropped (dark limbs).
    pub step_fraction: f64,
    /// Look for markers.
    pub markers: bool,
}

impl Default for DetectSettings {
    fn default() -> Self {
        DetectSettings {
            // ~128 x 128: seeds need no more (the first edge pass searches 0.5-1.5 radii), and
            // the coarse stage stays cheap even for megapixel frames. A sphere needs a radius of
            // a few coarse pixels: 3 px at 192 x 239 (block 2), 24 px at 1024 x 1024 (block 8).
            max_coarse_pixels: 16_384,
            known_radii_px: Vec::new(),
            // With 240 degrees of arc a free fit's radius is as good as a full circle's to
            // within a factor ~2 in variance (Chernov 2010, Ch. 6); shorter arcs need the radius.
            free_coverage_deg: 240.0,
            // A 90-degree arc still fixes a centre with a known radius; less is guesswork.
            min_coverage_deg: 90.0,
            min_edge_points: 8,
            profile: ProfileSettings::default(),
            step_fraction: 0.4,
            markers: true,
        }
    }
}

/// Angle covered by points seen from the centre: 360 minus the largest angular gap, degrees.
pub fn coverage_deg(c: &Circle, pts: impl Iterator<Item = [f64; 2]>) -> f64 {
    let mut a: Vec<f64> = pts.map(|p| (p[1] - c.cy).atan2(p[0] - c.cx)).collect();
    if a.len() < 2 {
        return 0.0;
    }
    // Values equal under total_cmp are the same bits: an unstable sort gives the same order.
    a.sort_unstable_by(|x, y| x.total_cmp(y));
    let mut gap = a[0] + std::f64::consts::TAU - a[a.len() - 1];
    for w in a.windows(2) {
        gap = gap.max(w[1] - w[0]);
    }
    (360.0 - gap.to_degrees()).max(0.0)
}

struct Pass<'a> {
    img: &'a GrayImage,
    polarity: f64,
    noise_floor: f64,
    kernel: Vec<f64>,
    profile: ProfileSettings,
    step_fraction: f64,
}

impl Pass<'_> {
    /// Edge points of circle `c` searched between `lo` and `hi` (pixels from the centre), on
    /// `n_rays` rays; rays whose edge would lie within `others` (+ margin) are skipped.
    fn edges(
        &self,
        c: &Circle,
        lo: f64,
        hi: f64,
        n_rays: usize,
        others: &[Circle],
        margin: f64,
    ) -> Vec<EdgePoint> {
        let mut buf = Vec::new();
        let mut out = Vec::with_capacity(n_rays);
        for k in 0..n_rays {
            let a = std::f64::consts::TAU * k as f64 / n_rays as f64;
            let dir = [a.cos(), a.sin()];
            let e = [c.cx + c.r * dir[0], c.cy + c.r * dir[1]];
            if others.iter().any(|o| {
                let (dx, dy) = (e[0] - o.cx, e[1] - o.cy);
                dx * dx + dy * dy < (o.r + margin) * (o.r + margin)
            }) {
                continue;
            }
            if let Some(p) = ray_edge_dir(
                self.img,
                [c.cx, c.cy],
                a,
                dir,
                [lo, hi],
                self.polarity,
                &self.kernel,
                &self.profile,
                &mut buf,
            ) {
                out.push(p);
            }
        }
        // Keep the clear edges: gradient and step against the circle's typical ones (75th
        // percentiles) and the gradient against the noise.
        if out.is_empty() {
            return out;
        }
        let typical = |f: fn(&EdgePoint) -> f64| {
            let mut s: Vec<f64> = out.iter().map(f).collect();
            let k = (s.len() - 1) * 3 / 4;
            *s.select_nth_unstable_by(k, |a, b| a.total_cmp(b)).1
        };
        let strength_floor = (0.3 * typical(|p| p.strength)).max(self.noise_floor);
        let step_floor = self.step_fraction * typical(|p| p.step);
        out.retain(|p| p.strength >= strength_floor && p.step >= step_floor);
        out
    }
}

fn fit_points(
    edges: &[EdgePoint],
    fixed_r: Option<f64>,
    min_points: usize,
) -> Result<(super::circle::RobustFit, Vec<[f64; 2]>), FitError> {
    let pts: Vec<[f64; 2]> = edges.iter().map(|e| [e.u, e.v]).collect();
    // Outliers beyond 3 MAD-sigmas; never tighter than 0.1 px (clean synthetic edges have a
    // spread of a few hundredths and must not be trimmed to a handful).
    let rf = fit_robust(&pts, fixed_r, 3.0, 0.1, min_points)?;
    Ok((rf, pts))
}

/// Detects the spheres and markers in one frame. See the module doc.
pub fn detect_frame(img: &GrayImage, s: &DetectSettings) -> Result<FrameDetection, DetectError> {
    let co: Coarse = coarse(img, s.max_coarse_pixels).map_err(DetectError::Coarse)?;
    if co.seeds.len() > 2 {
        return Err(DetectError::TooManyBlobs {
            n: co.seeds.len(),
            at_edge: co.seeds.iter().filter(|s| s.touches_border).count(),
        });
    }
    let kernel = derivative_kernel(&s.profile);
    // Gradient noise: the profile averages 3 rays (sigma/sqrt 3); the kernel's noise gain is
    // sqrt(sum k^2), doubled in variance because samples half a pixel apart are correlated.
    let gain = (2.0 * kernel.iter().map(|k| k * k).sum::<f64>()).sqrt();
    let pass = Pass {
        img,
        polarity: co.polarity,
        noise_floor: 5.0 * co.noise / 3f64.sqrt() * gain,
        kernel,
        profile: s.profile,
        step_fraction: s.step_fraction,
    };
    let half_kernel = (pass.kernel.len() / 2) as f64 * s.profile.step;
    let mut circles: Vec<Circle> = co.seeds.iter().map(|sd| sd.circle).collect();
    let n = circles.len();
    let mut last: Vec<Result<(super::circle::RobustFit, Vec<EdgePoint>), String>> =
        vec![Err("not fitted".into()); n];
    // A sphere whose narrow-band fit lands within 0.05 px of the circle its rays were placed
    // on has settled: a third pass would search the same band again.
    let mut settled = vec![false; n];
    for round in 0..3 {
        let mut next = circles.clone();
        for i in 0..n {
            if settled[i] {
                continue;
            }
            let c = circles[i];
            let others: Vec<Circle> = (0..n).filter(|&j| j != i).map(|j| circles[j]).collect();
            let (lo, hi, n_rays, margin) = if round == 0 {
                let rays = ((std::f64::consts::TAU * c.r / 4.0) as usize).clamp(16, 64);
                (0.5 * c.r, 1.5 * c.r + 4.0, rays, 0.1 * c.r + 2.0)
            } else {
                let band = (0.06 * c.r).max(3.0);
                let rays = ((std::f64::consts::TAU * c.r / 1.5) as usize).clamp(48, 360);
                (
                    (c.r - band - half_kernel).max(0.0),
                    c.r + band + half_kernel,
                    rays,
                    band + 2.0,
                )
            };
            let edges = pass.edges(&c, lo, hi, n_rays, &others, margin);
            let mut fit = fit_points(&edges, None, s.min_edge_points);
            // A short arc holds a known radius (the nearest known one).
            if let Ok((rf, pts)) = &fit {
                let cov = coverage_deg(
                    &rf.fit.circle,
                    pts.iter().zip(&rf.inliers).filter(|x| *x.1).map(|x| *x.0),
                );
                let known = s.known_radii_px.iter().copied().min_by(|a, b| {
                    (a - rf.fit.circle.r)
                        .abs()
                        .total_cmp(&(b - rf.fit.circle.r).abs())
                });
                if let (true, Some(r)) = (cov < s.free_coverage_deg, known) {
                    fit = fit_points(&edges, Some(r), s.min_edge_points);
                }
            }
            match fit {
                Ok((rf, _)) => {
                    let f = rf.fit.circle;
                    settled[i] = round > 0
                        && (f.cx - c.cx)
                            .abs()
                            .max((f.cy - c.cy).abs())
                            .max((f.r - c.r).abs())
                            < 0.05;
                    next[i] = f;
                    last[i] = Ok((rf, edges));
                }
                Err(e) => last[i] = Err(e.to_string()),
            }
        }
        circles = next;
    }

    let (w, h) = (img.width as f64, img.height as f64);
    let mut spheres = Vec::new();
    let mut left_out = Vec::new();
    for (i, res) in last.into_iter().enumerate() {
        let place = format!(
            "sphere near pixel ({:.0}, {:.0})",
            circles[i].cx,
            h - circles[i].cy
        );
        let (rf, edges) = match res {
            Ok(x) => x,
            Err(e) => {
                left_out.push(format!("{place}: {e}"));
                continue;
            }
        };
        let c = rf.fit.circle;
        // The passes may walk off (a short arc, a wrong edge): a circle far from its seed is
        // not this sphere.
        let seed = co.seeds[i].circle;
        if (c.cx - seed.cx).hypot(c.cy - seed.cy) > 0.5 * seed.r + 3.0
            || !(c.r > 0.5 * seed.r && c.r < 1.5 * seed.r + 3.0)
        {
            left_out.push(format!(
                "{place}: the edge fit ({:.1}, {:.1}, r {:.1}) strayed from the blob ({:.1}, {:.1}, r {:.1})",
                c.cx,
                h - c.cy,
                c.r,
                seed.cx,
                h - seed.cy,
                seed.r
            ));
            continue;
        }
        let cov = coverage_deg(
            &c,
            edges
                .iter()
                .zip(&rf.inliers)
                .filter(|x| *x.1)
                .map(|x| [x.0.u, x.0.v]),
        );
        if cov < s.min_coverage_deg || rf.n_used < s.min_edge_points {
            left_out.push(format!(
                "{place}: visible edge covers {cov:.0} degrees with {} points (need {} degrees and {} points)",
                rf.n_used, s.min_coverage_deg, s.min_edge_points
            ));
            continue;
        }
        let fixed = cov < s.free_coverage_deg && !s.known_radii_px.is_empty();
        spheres.push(SphereFit {
            circle: c,
            rms_px: rf.fit.rms,
            centre_err_px: rf.fit.centre_err,
            n_edge: rf.n_used,
            coverage_deg: cov,
            radius_mode: if fixed {
                RadiusMode::Fixed
            } else {
                RadiusMode::Free
            },
            clipped: c.cx - c.r < 0.0 || c.cy - c.r < 0.0 || c.cx + c.r > w || c.cy + c.r > h,
            edges,
            inliers: rf.inliers,
        });
    }
    if spheres.is_empty() {
        return Err(DetectError::NoFit { reasons: left_out });
    }
    let markers = spheres
        .iter()
        .map(|sp| {
            if s.markers {
                find_markers(img, &sp.circle, co.noise, co.contrast)
            } else {
                Vec::new()
            }
        })
        .collect();
    Ok(FrameDetection {
        width: img.width,
        height: img.height,
        spheres,
        markers,
        polarity: co.polarity,
        contrast: co.contrast,
        noise: co.noise,
        left_out,
    })
}
