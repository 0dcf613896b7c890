//! Rendered virtual frames: the grey-level images a high-speed camera records of lit spheres
//! (docs/physics.md §8), so that the frame pipeline can be tested against a known truth.
//!
//! **Solves**: given sphere poses (centre, radius, orientation) and the lighting, the image a
//! camera with square pixels records, as pixel averages of the scene's radiance.
//!
//! **Model.** Orthographic projection along -z (the camera is far away and its focal plane is
//! parallel to the plane of motion, as in the paper's Sec. III), object-plane coordinates as
//! documented on [`GrayImage`] (x right, y up, origin at the bottom-left image corner, z towards
//! the camera). Spheres are Lambertian: radiance = albedo (ambient + L_1 max(0, n.l_1) +
//! L_2 max(0, n.l_2)) with two front lamps in the horizontal plane at +-`lamp_angle_deg` from the
//! optical axis (the paper's two lights "symmetrically on both sides of the camera"); unequal
//! L_1, L_2 with little ambient leave the weak lamp's limb as dark as the background. Marker dots
//! are spherical caps fixed in the body frame whose albedo is `marker_albedo` times the sphere's;
//! only caps on the visible hemisphere show, foreshortened by the projection. The background is a
//! plane in intensity (level plus gradient). A nearer sphere (larger z) hides a farther one.
//!
//! **Pixels.** A pixel's value is the mean radiance over its square. Where an edge (a disc's limb
//! or a marker's boundary) can cross the pixel, the mean is taken over an s x s grid of samples
//! (anti-aliasing); elsewhere the radiance is smooth and a single sample at the pixel centre is
//! used (exact for the planar background, off by (P^2/24) times the Laplacian of the shading inside
//! a disc: about 1e-4 of the level for a 50-pixel sphere). Which pixels an edge can cross is
//! decided conservatively: a limb within half a pixel diagonal of the pixel centre, or the pixel
//! inside the exact bounding box of a marker cap's projection.
//!
//! **Motion blur** ([`Renderer::render_exposure`]): the mean of sub-frame renders at equally spaced
//! instants across the exposure (midpoint rule in time).
//!
//! **Needs**: finite poses; lighting whose radiance stays in [0, 1] (checked); sensor noise and
//! quantisation come afterwards ([`expose`]).

use super::GrayImage;
use crate::error::{Error, Result};
use nalgebra::{UnitQuaternion, Vector3};

mod film;
mod sensor;
#[cfg(test)]
mod tests;

pub use film::{FilmSpec, Filmed, FrameTruth, SphereTruth, film_collision};
pub use sensor::{Sensor, expose};

/// Half the diagonal of a unit pixel, with a hair of margin against rounding.
const HALF_DIAGONAL_PX: f64 = std::f64::consts::FRAC_1_SQRT_2 + 1e-9;

/// How the scene is lit; all levels in the image's [0, 1] units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lighting {
    /// Background level at the image centre.
    pub background: f64,
    /// Change of the background level from the left to the right edge, and from the bottom to
    /// the top edge of the image.
    pub background_gradient: [f64; 2],
    /// Sphere albedo (brightness under unit illumination).
    pub albedo: f64,
    /// Ambient illumination (lights every visible point equally).
    pub ambient: f64,
    /// Strengths of the lamp right of the camera (+x) and the lamp left of it (-x).
    pub lamps: [f64; 2],
    /// Angle of each lamp from the optical axis, degrees.
    pub lamp_angle_deg: f64,
    /// Albedo of a marker dot relative to the sphere's (0 = black ink).
    pub marker_albedo: f64,
}

impl Lighting {
    /// Bright spheres on a dark background, two equal lamps: every edge has good contrast
    /// (the limb's shading falls to the ambient 0.28 where the lamps graze it, background 0.1).
    pub const BRIGHT_ON_DARK: Lighting = Lighting {
        background: 0.1,
        background_gradient: [0.03, -0.02],
        albedo: 0.8,
        ambient: 0.35,
        lamps: [0.45, 0.45],
        lamp_angle_deg: 30.0,
        marker_albedo: 0.15,
    };
    /// Dark spheres against a bright screen.
    pub const DARK_ON_BRIGHT: Lighting = Lighting {
        background: 0.85,
        background_gradient: [-0.04, 0.02],
        albedo: 0.25,
        ambient: 0.3,
        lamps: [0.4, 0.4],
        lamp_angle_deg: 30.0,
        marker_albedo: 0.15,
    };
    /// Bright spheres on a dark background lit by one strong and one weak lamp with almost no
    /// ambient light: the limb on the weak lamp's side and at top and bottom is about as dark as
    /// the background, so part of the edge is lost.
    pub const UNEVEN_LAMPS: Lighting = Lighting {
        background: 0.1,
        background_gradient: [0.0, 0.0],
        albedo: 0.85,
        ambient: 0.03,
        lamps: [0.9, 0.12],
        lamp_angle_deg: 35.0,
        marker_albedo: 0.15,
    };

    /// The presets by name: `bright-on-dark`, `dark-on-bright`, `uneven-lamps`.
    pub fn preset(name: &str) -> Option<Lighting> {
        match name {
            "bright-on-dark" => Some(Self::BRIGHT_ON_DARK),
            "dark-on-bright" => Some(Self::DARK_ON_BRIGHT),
            "uneven-lamps" => Some(Self::UNEVEN_LAMPS),
            _ => None,
        }
    }

    /// Checks that every level is finite and that the radiance stays in [0, 1] everywhere.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, value: f64, expected: &'static str| {
            Err(Error::InvalidParameter {
                name,
                value,
                expected,
            })
        };
        let [gx, gy] = self.background_gradient;
        for (name, v) in [
            ("background", self.background),
            ("background gradient x", gx),
            ("background gradient y", gy),
        ] {
            if !v.is_finite() {
                return bad(name, v, "a finite level");
            }
        }
        let lo = self.background - 0.5 * (gx.abs() + gy.abs());
        let hi = self.background + 0.5 * (gx.abs() + gy.abs());
        if lo < 0.0 || hi > 1.0 {
            return bad(
                "background level with gradient",
                if lo < 0.0 { lo } else { hi },
                "a background within [0, 1] over the whole image",
            );
        }
        for (name, v) in [
            ("sphere albedo", self.albedo),
            ("ambient light", self.ambient),
            ("lamp 1 strength", self.lamps[0]),
            ("lamp 2 strength", self.lamps[1]),
            ("marker albedo", self.marker_albedo),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v, "a finite number >= 0");
            }
        }
        if self.marker_albedo > 1.0 {
            return bad(
                "marker albedo",
                self.marker_albedo,
                "<= 1 (markers are darker than the sphere)",
            );
        }
        if !(0.0..90.0).contains(&self.lamp_angle_deg) {
            return bad(
                "lamp angle (deg)",
                self.lamp_angle_deg,
                "an angle in [0, 90) from the optical axis",
            );
        }
        let peak = self.albedo * (self.ambient + self.lamps[0] + self.lamps[1]);
        if peak > 1.0 {
            return bad(
                "sphere brightness albedo*(ambient + lamps)",
                peak,
                "<= 1 (the sensor's full scale)",
            );
        }
        Ok(())
    }

    fn background_at(&self, u_frac: f64, v_frac: f64) -> f64 {
        self.background
            + self.background_gradient[0] * (u_frac - 0.5)
            + self.background_gradient[1] * (v_frac - 0.5)
    }

    fn lamp_dirs(&self) -> [Vector3<f64>; 2] {
        let (s, c) = self.lamp_angle_deg.to_radians().sin_cos();
        [Vector3::new(s, 0.0, c), Vector3::new(-s, 0.0, c)]
    }
}

/// A dark dot on a sphere: a spherical cap around the body-frame direction `dir` (unit) with
/// angular radius `radius_rad`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Marker {
    pub dir: Vector3<f64>,
    pub radius_rad: f64,
}

/// Marker patterns by name: `cube` (8 dots at the cube's vertices, 70.5 degrees apart, 4-5 in
/// view at any orientation), `octahedron` (6 dots on the body axes), `none`.
pub fn marker_pattern(name: &str, radius_rad: f64) -> Option<Vec<Marker>> {
    let dirs: Vec<Vector3<f64>> = match name {
        "cube" => (0..8)
            .map(|i| {
                let s = |b: usize| if i & b == 0 { 1.0 } else { -1.0 };
                Vector3::new(s(1), s(2), s(4)).normalize()
            })
            .collect(),
        "octahedron" => (0..6)
            .map(|i| {
                let mut v = Vector3::zeros();
                v[i / 2] = if i % 2 == 0 { 1.0 } else { -1.0 };
                v
            })
            .collect(),
        "none" => Vec::new(),
        _ => return None,
    };
    Some(
        dirs.into_iter()
            .map(|dir| Marker { dir, radius_rad })
            .collect(),
    )
}

/// A sphere at one instant: centre in object-plane coordinates (m; z towards the camera),
/// radius, and the rotation taking body-frame vectors to camera-frame ones.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpherePose {
    pub centre_m: Vector3<f64>,
    pub radius_m: f64,
    pub orientation: UnitQuaternion<f64>,
}

/// The image grid: `width` x `height` pixels of side `pixel_m`, and the anti-aliasing grid
/// (`supersample` x `supersample` samples in a pixel an edge can cross).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    pub width: usize,
    pub height: usize,
    pub pixel_m: f64,
    pub supersample: usize,
}

/// Renders scenes of lit, marked spheres (see the module documentation for the model).
#[derive(Debug, Clone, PartialEq)]
pub struct Renderer {
    pub view: View,
    pub lighting: Lighting,
    pub markers: Vec<Marker>,
}

/// One sphere prepared for a render, in pixel units (u right, v up).
struct Prepared {
    cu: f64,
    cv: f64,
    r: f64,
    depth: f64,
    /// Camera-frame marker directions and cos of their angular radii.
    markers: Vec<(Vector3<f64>, f64)>,
    /// Bounding boxes (u_min, u_max, v_min, v_max) of the visible markers' projections.
    boxes: Vec<[f64; 4]>,
}

/// Exact bounding box, relative to the disc centre and in units of the radius, of the
/// orthographic projection of the cap around `m` (unit, camera frame) with angular radius alpha:
/// the x extent of a connected cap is reached on its boundary circle (centre cos(alpha) m, radius
/// sin(alpha), normal m: extent +-sin(alpha) sqrt(1 - m_x^2)) or at the axis point +-x if the
/// cap contains it; likewise for y.
fn cap_box(m: &Vector3<f64>, cos_a: f64, sin_a: f64) -> [f64; 4] {
    let axis = |c: f64| {
        let half = sin_a * (1.0 - c * c).max(0.0).sqrt();
        let lo = if -c >= cos_a { -1.0 } else { cos_a * c - half };
        let hi = if c >= cos_a { 1.0 } else { cos_a * c + half };
        (lo, hi)
    };
    let (x0, x1) = axis(m.x);
    let (y0, y1) = axis(m.y);
    [x0, x1, y0, y1]
}

impl Renderer {
    /// Checks the grid, the lighting and the markers.
    pub fn new(view: View, lighting: Lighting, markers: Vec<Marker>) -> Result<Renderer> {
        if view.width == 0 || view.height == 0 || view.width * view.height > 1 << 26 {
            return Err(Error::InvalidParameter {
                name: "image size (pixels)",
                value: (view.width * view.height) as f64,
                expected: "between 1 and 2^26 pixels",
            });
        }
        if !(view.pixel_m.is_finite() && view.pixel_m > 0.0) {
            return Err(Error::InvalidParameter {
                name: "pixel size (m)",
                value: view.pixel_m,
                expected: "a finite size > 0",
            });
        }
        if !(1..=64).contains(&view.supersample) {
            return Err(Error::InvalidParameter {
                name: "supersampling (samples per pixel side)",
                value: view.supersample as f64,
                expected: "1 to 64",
            });
        }
        lighting.validate()?;
        for m in &markers {
            let n = m.dir.norm();
            if !(n.is_finite() && n > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "marker direction length",
                    value: n,
                    expected: "a finite non-zero vector",
                });
            }
            if !(m.radius_rad > 0.0 && m.radius_rad < std::f64::consts::FRAC_PI_2) {
                return Err(Error::InvalidParameter {
                    name: "marker angular radius (rad)",
                    value: m.radius_rad,
                    expected: "in (0, pi/2)",
                });
            }
        }
        Ok(Renderer {
            view,
            lighting,
            markers: markers
                .into_iter()
                .map(|m| Marker {
                    dir: m.dir.normalize(),
                    ..m
                })
                .collect(),
        })
    }

    fn prepare(&self, pose: &SpherePose) -> Result<Prepared> {
        let p = self.view.pixel_m;
        let c = pose.centre_m / p;
        let r = pose.radius_m / p;
        if !(c.iter().all(|x| x.is_finite()) && r.is_finite() && r > 0.0) {
            return Err(Error::InvalidParameter {
                name: "sphere pose (centre or radius, pixels)",
                value: if r.is_finite() { c.norm() } else { r },
                expected: "a finite centre and a radius > 0",
            });
        }
        let mut markers = Vec::with_capacity(self.markers.len());
        let mut boxes = Vec::new();
        for m in &self.markers {
            let dir = pose.orientation * m.dir;
            let (sin_a, cos_a) = m.radius_rad.sin_cos();
            markers.push((dir, cos_a));
            // The cap shows if its nearest point to the viewing direction is in front.
            if dir.z.clamp(-1.0, 1.0).acos() < std::f64::consts::FRAC_PI_2 + m.radius_rad {
                let [x0, x1, y0, y1] = cap_box(&dir, cos_a, sin_a);
                boxes.push([c.x + r * x0, c.x + r * x1, c.y + r * y0, c.y + r * y1]);
            }
        }
        Ok(Prepared {
            cu: c.x,
            cv: c.y,
            r,
            depth: c.z,
            markers,
            boxes,
        })
    }

    /// Radiance at object-plane point (u, v) in pixel units.
    fn radiance(&self, spheres: &[Prepared], lamps: &[Vector3<f64>; 2], u: f64, v: f64) -> f64 {
        let mut front: Option<(&Prepared, f64)> = None;
        for s in spheres {
            let (du, dv) = ((u - s.cu) / s.r, (v - s.cv) / s.r);
            let rho2 = du * du + dv * dv;
            if rho2 < 1.0 {
                let nz = (1.0 - rho2).sqrt();
                let depth = s.depth + s.r * nz;
                if front.is_none_or(|(_, fd)| depth > fd) {
                    front = Some((s, depth));
                }
            }
        }
        let l = &self.lighting;
        let Some((s, _)) = front else {
            return l.background_at(u / self.view.width as f64, v / self.view.height as f64);
        };
        let (du, dv) = ((u - s.cu) / s.r, (v - s.cv) / s.r);
        let n = Vector3::new(du, dv, (1.0 - du * du - dv * dv).max(0.0).sqrt());
        let mut light = l.ambient;
        for (strength, dir) in l.lamps.iter().zip(lamps) {
            light += strength * n.dot(dir).max(0.0);
        }
        let marked = s.markers.iter().any(|(m, cos_a)| n.dot(m) >= *cos_a);
        l.albedo * light * if marked { l.marker_albedo } else { 1.0 }
    }

    /// The noiseless image of spheres at one instant (no blur).
    pub fn render(&self, poses: &[SpherePose]) -> Result<GrayImage> {
        let mut acc = vec![0.0; self.view.width * self.view.height];
        self.accumulate(poses, 1.0, &mut acc)?;
        Ok(self.finish(acc))
    }

    /// The noiseless image over an exposure of `exposure_s` centred on `t_s`: the mean of
    /// `subframes` renders at t_s + exposure_s ((k + 1/2)/subframes - 1/2), k = 0..subframes
    /// (midpoint rule in time; exact for the blur of uniform motion up to the spacing of the
    /// sub-frames). `poses_at` gives the poses at an instant.
    pub fn render_exposure(
        &self,
        poses_at: &dyn Fn(f64) -> Result<Vec<SpherePose>>,
        t_s: f64,
        exposure_s: f64,
        subframes: usize,
    ) -> Result<GrayImage> {
        if !(exposure_s.is_finite() && exposure_s >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "exposure time (s)",
                value: exposure_s,
                expected: "a finite time >= 0",
            });
        }
        let k = if exposure_s == 0.0 { 1 } else { subframes };
        if k == 0 {
            return Err(Error::InvalidParameter {
                name: "sub-frames per exposure",
                value: 0.0,
                expected: ">= 1",
            });
        }
        let mut acc = vec![0.0; self.view.width * self.view.height];
        let w = 1.0 / k as f64;
        for i in 0..k {
            let t = t_s + exposure_s * ((i as f64 + 0.5) * w - 0.5);
            self.accumulate(&poses_at(t)?, w, &mut acc)?;
        }
        Ok(self.finish(acc))
    }

    fn finish(&self, acc: Vec<f64>) -> GrayImage {
        GrayImage {
            width: self.view.width,
            height: self.view.height,
            pixels: acc.into_iter().map(|x| x as f32).collect(),
        }
    }

    /// Adds `weight` times the image of `poses` to `acc` (row-major, row 0 at the top).
    fn accumulate(&self, poses: &[SpherePose], weight: f64, acc: &mut [f64]) -> Result<()> {
        let spheres = poses
            .iter()
            .map(|p| self.prepare(p))
            .collect::<Result<Vec<_>>>()?;
        let lamps = self.lighting.lamp_dirs();
        let (w, h) = (self.view.width, self.view.height);
        let s = self.view.supersample;
        let step = 1.0 / s as f64;
        for row in 0..h {
            let v_c = (h - row) as f64 - 0.5;
            for col in 0..w {
                let u_c = col as f64 + 0.5;
                let edge = spheres.iter().any(|sp| {
                    let d = (u_c - sp.cu).hypot(v_c - sp.cv);
                    (d - sp.r).abs() < HALF_DIAGONAL_PX
                        || (d < sp.r + HALF_DIAGONAL_PX
                            && sp.boxes.iter().any(|b| {
                                u_c > b[0] - 0.5
                                    && u_c < b[1] + 0.5
                                    && v_c > b[2] - 0.5
                                    && v_c < b[3] + 0.5
                            }))
                });
                let value = if edge && s > 1 {
                    let mut sum = 0.0;
                    for i in 0..s {
                        let v = v_c - 0.5 + (i as f64 + 0.5) * step;
                        for j in 0..s {
                            let u = u_c - 0.5 + (j as f64 + 0.5) * step;
                            sum += self.radiance(&spheres, &lamps, u, v);
                        }
                    }
                    sum / (s * s) as f64
                } else {
                    self.radiance(&spheres, &lamps, u_c, v_c)
                };
                acc[row * w + col] += weight * value;
            }
        }
        Ok(())
    }
}
