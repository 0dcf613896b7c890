//! Synthetic frames with known truth for the frame tests: spheres lit from the front by two
//! lamps (Lambertian), dark dots on their surfaces, an uneven background, motion blur, sensor
//! noise and 8-bit quantisation. Coordinates as the detector reports them: pixels, x right,
//! y up, origin at the bottom-left corner of the image (a pixel centre is at (col + 0.5,
//! H - row - 0.5)). Independent of the library's detector: only `GrayImage` is shared.
#![allow(dead_code)]

use nalgebra::{Rotation3, Vector3};
use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, Normal};
use restitution::frames::GrayImage;

#[derive(Clone, Debug)]
pub struct Ball {
    /// Centre, pixels (x right, y up), at the middle of the exposure.
    pub centre: [f64; 2],
    pub radius: f64,
    /// Velocity during the exposure, pixels per exposure (motion blur).
    pub blur: [f64; 2],
    /// Marker directions in the sphere's body frame (unit vectors) and their angular radius.
    pub markers: Vec<Vector3<f64>>,
    pub marker_rad: f64,
    /// Orientation: body -> camera (x right, y up, z towards the camera).
    pub attitude: Rotation3<f64>,
    pub albedo: f64,
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub width: usize,
    pub height: usize,
    pub balls: Vec<Ball>,
    /// Background: base + gx x/W + gy y/H + vignette (r/r_max)^2 (vignette usually < 0).
    pub base: f64,
    pub gx: f64,
    pub gy: f64,
    pub vignette: f64,
    /// Lamp strengths (left, right) and their angle from the camera axis in the x-z plane.
    pub lamps: [f64; 2],
    pub lamp_deg: f64,
    pub ambient: f64,
    pub marker_albedo: f64,
    pub noise: f64,
    pub supersample: usize,
    pub blur_steps: usize,
    pub quantise_8bit: bool,
    pub seed: u64,
}

impl Scene {
    /// Bright spheres on a dark, uneven background, unequal lamps, noise: the default test.
    pub fn paper_like(width: usize, height: usize, balls: Vec<Ball>) -> Scene {
        Scene {
            width,
            height,
            balls,
            base: 0.12,
            gx: 0.06,
            gy: -0.04,
            vignette: -0.03,
            lamps: [0.55, 0.35],
            lamp_deg: 35.0,
            ambient: 0.08,
            marker_albedo: 0.12,
            noise: 0.01,
            supersample: 6,
            blur_steps: 1,
            quantise_8bit: true,
            seed: 1,
        }
    }

    fn background(&self, x: f64, y: f64) -> f64 {
        let (w, h) = (self.width as f64, self.height as f64);
        let r2 = ((x - w / 2.0).powi(2) + (y - h / 2.0).powi(2)) / ((w * w + h * h) / 4.0);
        self.base + self.gx * x / w + self.gy * y / h + self.vignette * r2
    }

    /// Scene radiance at (x, y) for the balls displaced by `shift` (fraction of their blur).
    fn radiance(&self, x: f64, y: f64, shift: f64) -> f64 {
        let a = self.lamp_deg.to_radians();
        let lamps = [
            (Vector3::new(-a.sin(), 0.0, a.cos()), self.lamps[0]),
            (Vector3::new(a.sin(), 0.0, a.cos()), self.lamps[1]),
        ];
        // The ball nearest the camera wins; all are at the same depth here, so the first hit.
        for b in &self.balls {
            let cx = b.centre[0] + shift * b.blur[0];
            let cy = b.centre[1] + shift * b.blur[1];
            let (dx, dy) = (x - cx, y - cy);
            let rho2 = dx * dx + dy * dy;
            if rho2 >= b.radius * b.radius {
                continue;
            }
            let n = Vector3::new(dx, dy, (b.radius * b.radius - rho2).sqrt()) / b.radius;
            let mut light = self.ambient;
            for (l, s) in &lamps {
                light += s * n.dot(l).max(0.0);
            }
            let body = b.attitude.inverse() * n;
            let on_marker = b.markers.iter().any(|m| body.dot(m) > b.marker_rad.cos());
            let albedo = if on_marker { self.marker_albedo } else { b.albedo };
            return albedo * light;
        }
        self.background(x, y)
    }

    pub fn render(&self) -> GrayImage {
        let (w, h) = (self.width, self.height);
        let mut img = GrayImage::filled(w, h, 0.0);
        let ss = self.supersample;
        let steps = self.blur_steps.max(1);
        let mut rng = StdRng::seed_from_u64(self.seed);
        let normal = Normal::new(0.0, self.noise.max(1e-300)).unwrap();
        for row in 0..h {
            for col in 0..w {
                let mut acc = 0.0;
                for t in 0..steps {
                    let shift = if steps == 1 {
                        0.0
                    } else {
                        (t as f64 + 0.5) / steps as f64 - 0.5
                    };
                    for j in 0..ss {
                        for i in 0..ss {
                            let x = col as f64 + (i as f64 + 0.5) / ss as f64;
                            let y = (h - 1 - row) as f64 + (j as f64 + 0.5) / ss as f64;
                            acc += self.radiance(x, y, shift);
                        }
                    }
                }
                let mut v = acc / (ss * ss * steps) as f64;
                if self.noise > 0.0 {
                    v += normal.sample(&mut rng);
                }
                v = v.clamp(0.0, 1.0);
                if self.quantise_8bit {
                    v = (v * 255.0).round() / 255.0;
                }
                img.set(col, row, v as f32);
            }
        }
        img
    }
}

/// A ball with `n` markers spread evenly over the sphere (a Fibonacci lattice), at rest.
pub fn ball(centre: [f64; 2], radius: f64, n_markers: usize) -> Ball {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let markers = (0..n_markers)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / n_markers as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * k as f64;
            Vector3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    Ball {
        centre,
        radius,
        blur: [0.0, 0.0],
        markers,
        marker_rad: 0.12,
        attitude: Rotation3::identity(),
        albedo: 1.0,
    }
}
