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
            let albedo = if on_marker {
                self.marker_albedo
            } else {
                b.albedo
            };
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

/// A head-on-ish collision filmed at 1000 frames/s: two spheres of radius `r` pixels meet at
/// frame `t_c` (fractional), e = 0.9, with known spins (rad/s, x right, y up, z to the camera)
/// before and after. Frame numbers start at 100; `skip` frame numbers are not rendered.
pub struct Sequence {
    pub fps: f64,
    /// (frame number, scene, centres (x, y) px of sphere 1 and 2).
    pub frames: Vec<(i64, Scene, [[f64; 2]; 2])>,
    /// spins[sphere][phase] (phase 0 before, 1 after), rad/s.
    pub spins: [[Vector3<f64>; 2]; 2],
    pub t_c_frames: f64,
}

pub fn collision_sequence(r: f64, t_c: f64, n: i64, skip: &[i64]) -> Sequence {
    let fps = 1000.0;
    let n_hat = [0.6, -0.8];
    let mid = [96.0, 120.0];
    let c_at = [
        [mid[0] - r * n_hat[0], mid[1] - r * n_hat[1]],
        [mid[0] + r * n_hat[0], mid[1] + r * n_hat[1]],
    ];
    let v = [[3.0, -4.0], [-3.0, 4.0]];
    let e = 0.9;
    let vrel = [v[0][0] - v[1][0], v[0][1] - v[1][1]];
    let vpost = [
        [
            v[0][0] - (1.0 + e) / 2.0 * vrel[0],
            v[0][1] - (1.0 + e) / 2.0 * vrel[1],
        ],
        [
            v[1][0] + (1.0 + e) / 2.0 * vrel[0],
            v[1][1] + (1.0 + e) / 2.0 * vrel[1],
        ],
    ];
    let spins = [
        [
            Vector3::new(10.0, -20.0, 60.0),
            Vector3::new(10.0, -20.0, -40.0),
        ],
        [
            Vector3::new(0.0, 30.0, -50.0),
            Vector3::new(5.0, 25.0, 70.0),
        ],
    ];
    let att0 = [
        Rotation3::from_euler_angles(0.3, -0.2, 0.5),
        Rotation3::from_euler_angles(-0.4, 0.1, 1.1),
    ];
    let mut frames = Vec::new();
    for k in 0..n {
        let number = 100 + k;
        if skip.contains(&number) {
            continue;
        }
        let dt = k as f64 - t_c;
        let phase = usize::from(dt > 0.0);
        let mut balls = Vec::new();
        let mut centres = [[0.0; 2]; 2];
        for s in 0..2 {
            let vel = if phase == 0 { v[s] } else { vpost[s] };
            let c = [c_at[s][0] + vel[0] * dt, c_at[s][1] + vel[1] * dt];
            centres[s] = c;
            let att = Rotation3::from_scaled_axis(spins[s][phase] * (dt / fps)) * att0[s];
            let mut b = ball(c, r, 12);
            b.marker_rad = 0.15;
            b.attitude = att;
            // Half a frame of exposure at this velocity: slight motion blur.
            b.blur = [0.3 * vel[0], 0.3 * vel[1]];
            balls.push(b);
        }
        let mut sc = Scene::paper_like(192, 239, balls);
        sc.blur_steps = 3;
        sc.seed = number as u64;
        frames.push((number, sc, centres));
    }
    Sequence {
        fps,
        frames,
        spins,
        t_c_frames: t_c,
    }
}
