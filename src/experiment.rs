//! The virtual experiment's camera: ballistic tracks sampled at a frame rate with position noise,
//! modelled on the paper's apparatus (Sec. III: 1000 frames/s, 192 x 239 pixels, 4x subpixel
//! expansion, centre accuracy s ~ 2 subpixels, 8 to 12 frames per phase, as few as 2 when fast).
//!
//! No physics of the collision lives here: the caller supplies the states at the collision
//! instant; this module only films them.

use crate::kinematics::Frame;
use nalgebra::Vector2;
use rand::Rng;
use rand_distr::{Distribution, Normal};

/// A high-speed camera and its image processing, as in Sec. III.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub frames_per_s: f64,
    pub pixels_x: u32,
    pub pixels_y: u32,
    /// Width of the field of view, m (the height follows from the pixel aspect).
    pub fov_x_m: f64,
    /// Subpixel expansion factor (4 in the paper).
    pub subpixel_expansion: f64,
    /// Accuracy of a centre, in subpixels (s of Eq. 8; the paper measured s = 1 +- 0.5 and
    /// conservatively quotes 2).
    pub s_subpixels: f64,
    /// Frames per phase are drawn uniformly from this range, then reduced so that the motion
    /// of a phase stays inside half the field of view (never below 2).
    pub frames_min: usize,
    pub frames_max: usize,
}

impl Camera {
    /// The paper's camera with a 48 mm wide field of view (0.25 mm pixels: about 100 pixels per
    /// 25.4 mm diameter, which makes Eq. (8) give the paper's "about 4%" at 1 m/s).
    pub const PAPER: Camera = Camera {
        frames_per_s: 1000.0,
        pixels_x: 192,
        pixels_y: 239,
        fov_x_m: 0.048,
        subpixel_expansion: 4.0,
        s_subpixels: 2.0,
        frames_min: 8,
        frames_max: 12,
    };

    pub fn dt_s(&self) -> f64 {
        1.0 / self.frames_per_s
    }

    pub fn pixel_m(&self) -> f64 {
        self.fov_x_m / self.pixels_x as f64
    }

    pub fn subpixel_m(&self) -> f64 {
        self.pixel_m() / self.subpixel_expansion
    }

    /// Standard deviation of a measured centre coordinate, m.
    pub fn sigma_m(&self) -> f64 {
        self.s_subpixels * self.subpixel_m()
    }

    /// Frames in a phase whose fastest sphere moves at `speed_m_s`.
    pub fn frames_for(&self, speed_m_s: f64, rng: &mut impl Rng) -> usize {
        let drawn = rng.random_range(self.frames_min..=self.frames_max.max(self.frames_min));
        let fit = (0.5 * self.fov_x_m / (speed_m_s * self.dt_s())).floor();
        let fit = if fit.is_finite() { fit as usize } else { drawn };
        drawn.min(fit).max(2)
    }
}

/// The two spheres at the collision instant t = 0 (contact), with velocities just before and
/// just after; y is up, gravity g acts along -y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scene {
    pub r1_m: Vector2<f64>,
    pub r2_m: Vector2<f64>,
    pub v_pre_m_s: [Vector2<f64>; 2],
    pub v_post_m_s: [Vector2<f64>; 2],
    pub g_m_s2: f64,
}

impl Scene {
    fn position(&self, sphere: usize, t_s: f64) -> Vector2<f64> {
        let r0 = if sphere == 0 { self.r1_m } else { self.r2_m };
        let v = if t_s < 0.0 {
            self.v_pre_m_s[sphere]
        } else {
            self.v_post_m_s[sphere]
        };
        r0 + v * t_s - Vector2::new(0.0, 0.5 * self.g_m_s2 * t_s * t_s)
    }

    /// Films the scene: `n_pre` frames before and `n_post` after the collision, at a random phase
    /// of the frame clock, each centre coordinate with Gaussian noise of sd `camera.sigma_m()`.
    /// Returns the frames and the index of the first post-collision frame.
    pub fn film(
        &self,
        camera: &Camera,
        n_pre: usize,
        n_post: usize,
        rng: &mut impl Rng,
    ) -> (Vec<Frame>, usize) {
        let dt = camera.dt_s();
        let offset = rng.random_range(0.0..dt);
        let noise = Normal::new(0.0, camera.sigma_m()).expect("finite sigma");
        let mut frames = Vec::with_capacity(n_pre + n_post);
        for k in -(n_pre as i64)..(n_post as i64) {
            let t = k as f64 * dt + offset;
            let mut sample = |s: usize| {
                let r = self.position(s, t);
                [r.x + noise.sample(rng), r.y + noise.sample(rng)]
            };
            let r1 = sample(0);
            let r2 = sample(1);
            frames.push(Frame {
                t_s: t,
                r1_m: r1,
                r2_m: r2,
            });
        }
        (frames, n_pre)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand::rngs::StdRng;

    #[test]
    fn paper_camera_numbers() {
        let c = Camera::PAPER;
        assert!((c.pixel_m() - 0.25e-3).abs() < 1e-15);
        assert!((c.sigma_m() - 0.125e-3).abs() < 1e-15);
        // Eq. (8) at 1 m/s, N = 10: 0.125 mm / (1 ms sqrt 10) = 0.0395 m/s, the paper's "about 4%".
        let dv = crate::kinematics::eq8_velocity_error_m_s(2.0, c.subpixel_m(), c.dt_s(), 10);
        assert!((dv - 0.0395).abs() < 1e-4, "{dv}");
    }

    #[test]
    fn fast_phases_get_fewer_frames_but_at_least_two() {
        let mut rng = StdRng::seed_from_u64(1);
        let c = Camera::PAPER;
        assert!((8..=12).contains(&c.frames_for(1.0, &mut rng)));
        assert_eq!(c.frames_for(8.0, &mut rng), 3);
        assert_eq!(c.frames_for(100.0, &mut rng), 2);
    }

    #[test]
    fn noise_has_the_camera_sd() {
        let mut rng = StdRng::seed_from_u64(7);
        let scene = Scene {
            r1_m: Vector2::new(0.0, 0.0),
            r2_m: Vector2::new(0.0254, 0.0),
            v_pre_m_s: [Vector2::zeros(); 2],
            v_post_m_s: [Vector2::zeros(); 2],
            g_m_s2: 0.0,
        };
        let (frames, split) = scene.film(&Camera::PAPER, 2000, 2000, &mut rng);
        assert_eq!(split, 2000);
        let var = frames.iter().map(|f| f.r1_m[0].powi(2)).sum::<f64>() / frames.len() as f64;
        // 4000 samples: the sd estimate has relative sd 1/sqrt(2*4000) = 1.1%; 5% is 4.5 sigma.
        assert!((var.sqrt() / Camera::PAPER.sigma_m() - 1.0).abs() < 0.05);
    }
}
