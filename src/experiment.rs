//! The virtual experiment's camera: ballistic tracks sampled at a frame rate with position noise,
//! modelled on the paper's apparatus (Sec. III: 1000 frames/s, 192 x 239 pixels, 4x subpixel
//! expansion, centre accuracy s ~ 2 subpixels, 8 to 12 frames per phase, as few as 2 when fast).
//!
//! The collision itself is Walton's operator ([`crate::models::walton::collide`]) with e(v_n)
//! supplied by the caller (any model of `fit::models`); this module draws the geometry, collides,
//! and films the result.

use crate::contact::{Material, Sphere};
use crate::error::{Error, Num, Result};
use crate::kinematics::{FitKind, Frame, measure_e};
use crate::models::walton::{self, Body, ContactKind, State, WaltonParams};
use nalgebra::{Vector2, Vector3};
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
    /// True centre of sphere `sphere` (0 or 1) at time `t_s` (t = 0 is the contact): ballistic
    /// flight on the pre-collision velocity before it and the post-collision one after.
    pub fn position(&self, sphere: usize, t_s: f64) -> Vector2<f64> {
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

/// What the virtual experiment draws and how it collides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExperimentSpec {
    pub n: usize,
    pub d1_m: f64,
    pub d2_m: f64,
    pub material: Material,
    pub inertia_k: f64,
    /// Normal approach speed, drawn log-uniformly in this range, m/s.
    pub v_n_range_m_s: (f64, f64),
    /// Angle of incidence between -n and the relative velocity, uniform in this range, degrees.
    pub incidence_deg: (f64, f64),
    pub mu0: f64,
    pub beta0: f64,
    /// Spread of each component of the centre-of-mass velocity, m/s.
    pub cm_speed_sd_m_s: f64,
    /// Spread of the pre-collision spins, rad/s.
    pub spin_sd_rad_s: f64,
    /// Error of a spin measured from markers, rad/s.
    pub spin_noise_rad_s: f64,
    pub g_m_s2: f64,
    pub camera: Camera,
}

impl ExperimentSpec {
    /// The paper's set-up: 25.4 mm nylon spheres, Walton's mu_0 = 0.175 and beta_0 = 0.5,
    /// impact speeds 0.5 to 5 m/s at incidences 0 to 80 degrees, the paper's camera.
    pub fn paper() -> Self {
        ExperimentSpec {
            n: 60,
            d1_m: 0.0254,
            d2_m: 0.0254,
            material: Material::preset("nylon").expect("a preset"),
            inertia_k: walton::K_HOMOGENEOUS,
            v_n_range_m_s: (0.5, 5.0),
            incidence_deg: (0.0, 80.0),
            mu0: 0.175,
            beta0: 0.5,
            cm_speed_sd_m_s: 0.3,
            spin_sd_rad_s: 3.0,
            spin_noise_rad_s: 3.0,
            g_m_s2: crate::kinematics::G_STANDARD_M_S2,
            camera: Camera::PAPER,
        }
    }
}

/// One simulated collision: the truth and what the camera saw.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulated {
    pub id: String,
    pub pre: State,
    pub post: State,
    pub e: f64,
    pub v_n_m_s: f64,
    pub beta: f64,
    pub psi: f64,
    pub kind: ContactKind,
    pub frames: Vec<Frame>,
    /// Index of the first post-collision frame.
    pub split: usize,
    /// Spins measured from markers: [1 pre, 2 pre, 1 post, 2 post], rad/s.
    pub spins_measured_rad_s: [f64; 4],
    /// The true flight, for rendering the frames (`frames::render`).
    pub scene: Scene,
}

/// Runs the virtual experiment: draws `spec.n` collisions, resolves each with Walton's operator
/// and e = `e_of_v_n(v_n)`, and films them. Collision ids are `c1`, `c2`, ...
pub fn simulate(
    spec: &ExperimentSpec,
    e_of_v_n: &dyn Fn(f64) -> Result<f64>,
    rng: &mut impl Rng,
) -> Result<Vec<Simulated>> {
    let (lo, hi) = spec.v_n_range_m_s;
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "v_n range (m/s)",
            value: lo,
            expected: "0 < min <= max",
        });
    }
    let (g_lo, g_hi) = spec.incidence_deg;
    if !(0.0..90.0).contains(&g_lo) || !(g_lo..90.0).contains(&g_hi) {
        return Err(Error::InvalidParameter {
            name: "incidence range (deg)",
            value: g_hi,
            expected: "0 <= min <= max < 90",
        });
    }
    let s1 = Sphere::new(spec.d1_m, spec.material)?;
    let s2 = Sphere::new(spec.d2_m, spec.material)?;
    let (m1, m2) = (s1.mass_kg(), s2.mass_kg());
    let cm = Normal::new(0.0, spec.cm_speed_sd_m_s).map_err(|_| Error::InvalidParameter {
        name: "centre-of-mass speed spread (m/s)",
        value: spec.cm_speed_sd_m_s,
        expected: ">= 0",
    })?;
    let spin = Normal::new(0.0, spec.spin_sd_rad_s).map_err(|_| Error::InvalidParameter {
        name: "spin spread (rad/s)",
        value: spec.spin_sd_rad_s,
        expected: ">= 0",
    })?;
    let spin_noise =
        Normal::new(0.0, spec.spin_noise_rad_s).map_err(|_| Error::InvalidParameter {
            name: "spin noise (rad/s)",
            value: spec.spin_noise_rad_s,
            expected: ">= 0",
        })?;
    let mut out = Vec::with_capacity(spec.n);
    for i in 0..spec.n {
        let v_n = lo * (hi / lo).powf(rng.random_range(0.0..=1.0));
        let gamma = rng.random_range(g_lo..=g_hi).to_radians();
        let phi = rng.random_range(0.0..std::f64::consts::TAU);
        let n = Vector2::new(phi.cos(), phi.sin());
        let t = Vector2::new(-n.y, n.x) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let v_rel = -n * v_n + t * (v_n * gamma.tan());
        let v_cm = Vector2::new(cm.sample(rng), cm.sample(rng));
        let v1 = v_cm + v_rel * (m2 / (m1 + m2));
        let v2 = v_cm - v_rel * (m1 / (m1 + m2));
        let r1 = Vector2::zeros();
        let r2 = r1 - n * (0.5 * (spec.d1_m + spec.d2_m));
        let w = [spin.sample(rng), spin.sample(rng)];
        let body = |s: &Sphere, r: Vector2<f64>, v: Vector2<f64>, w: f64| {
            let mut b = Body::homogeneous(Vector3::new(r.x, r.y, 0.0), s);
            b.inertia_k = spec.inertia_k;
            b.moving(Vector3::new(v.x, v.y, 0.0), Vector3::new(0.0, 0.0, w))
        };
        let pre = State::pair(body(&s1, r1, v1, w[0]), body(&s2, r2, v2, w[1]));
        // v_n of the contact point equals that of the centres: spins do not change it.
        let e = e_of_v_n(v_n)?;
        let post = walton::collide(&pre, &WaltonParams::new(e, spec.mu0, spec.beta0)?)?;
        let walton::Target::Sphere(b2) = post.state.target else {
            unreachable!("a pair stays a pair");
        };
        let vpost = [post.state.sphere.velocity_m_s.xy(), b2.velocity_m_s.xy()];
        let scene = Scene {
            r1_m: r1,
            r2_m: r2,
            v_pre_m_s: [v1, v2],
            v_post_m_s: vpost,
            g_m_s2: spec.g_m_s2,
        };
        let n_pre = spec.camera.frames_for(v1.norm().max(v2.norm()), rng);
        let n_post = spec
            .camera
            .frames_for(vpost[0].norm().max(vpost[1].norm()), rng);
        let (frames, split) = scene.film(&spec.camera, n_pre, n_post, rng);
        let wpost = [post.state.sphere.spin_rad_s.z, b2.spin_rad_s.z];
        // At absurd speeds (1e300 m/s) the filmed positions overflow, and an absurdly small
        // sphere (1e-80 mm) spins infinitely fast after an oblique impact: an error naming the
        // collision's speed, not NaN or inf in the tracks.
        if frames
            .iter()
            .any(|f| !f.r1_m.iter().chain(&f.r2_m).all(|x| x.is_finite()))
            || !wpost.iter().all(|w| w.is_finite())
        {
            return Err(Error::InvalidParameter {
                name: "normal speed (m/s) of a collision whose positions or spins overflow",
                value: v_n,
                expected: "a collision whose filmed positions and spins stay finite",
            });
        }
        let spins = [w[0], w[1], wpost[0], wpost[1]].map(|x| x + spin_noise.sample(rng));
        // A spread near f64::MAX draws noise that overflows (fuzzed `simulate`, seed 639, case
        // 976, wrote inf into tracks.csv): an error naming the spread.
        if !spins.iter().all(|x| x.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "spin noise (rad/s): a measured spin overflows",
                value: spec.spin_noise_rad_s,
                expected: "a spread whose measured spins stay finite",
            });
        }
        out.push(Simulated {
            id: format!("c{}", i + 1),
            pre,
            post: post.state,
            e,
            v_n_m_s: v_n,
            beta: post.beta,
            psi: post.psi,
            kind: post.kind,
            frames,
            split,
            spins_measured_rad_s: spins,
            scene,
        });
    }
    Ok(out)
}

/// One point of a camera study: how well a camera measures e at one normal speed.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyPoint {
    pub camera: String,
    pub fit: &'static str,
    pub v_n_m_s: f64,
    /// Collisions simulated and measured (the rest had too few frames for the fit).
    pub simulated: usize,
    pub measured: usize,
    /// Mean and standard deviation of e_measured/e_true - 1 over the measured collisions.
    pub bias: f64,
    pub scatter: f64,
}

/// The normal speeds of the camera study, m/s: the paper's range and beyond.
pub const STUDY_SPEEDS_M_S: [f64; 7] = [0.3, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0];

/// The cameras of the study: `base`, twice its frame rate, four times its pixels, and both (five
/// times the rate), each named "F fps / N px". A faster camera films the same time window in
/// more frames (the field of view, not the frame count, limits a phase); with the frame count
/// fixed it would see a shorter window and measure slopes worse, not better.
pub fn study_cameras(base: Camera) -> Vec<(String, Camera)> {
    let fps = |k: f64| Camera {
        frames_per_s: base.frames_per_s * k,
        frames_min: (base.frames_min as f64 * k).round() as usize,
        frames_max: (base.frames_max as f64 * k).round() as usize,
        ..base
    };
    let px = |k: u32, cam: Camera| Camera {
        pixels_x: cam.pixels_x * k,
        pixels_y: cam.pixels_y * k,
        ..cam
    };
    let name = |cam: &Camera| format!("{} fps / {} px", Num(cam.frames_per_s), cam.pixels_x);
    [base, fps(2.0), px(4, base), px(4, fps(5.0))]
        .into_iter()
        .map(|cam| (name(&cam), cam))
        .collect()
}

/// Monte Carlo of the measurement chain: for each camera and normal speed, simulate
/// `per_point` collisions of `base` (the speed range collapsed to that speed), measure e from the
/// tracks with free and fixed-gravity fits, and report the relative bias and scatter of e.
pub fn camera_study(
    base: &ExperimentSpec,
    cameras: &[(String, Camera)],
    v_n_m_s: &[f64],
    per_point: usize,
    e_of_v_n: &dyn Fn(f64) -> Result<f64>,
    rng: &mut impl Rng,
) -> Result<Vec<StudyPoint>> {
    let kinds = [
        ("free", FitKind::Free),
        (
            "fixed_gravity",
            FitKind::FixedGravity {
                g_m_s2: base.g_m_s2,
            },
        ),
    ];
    let mut out = Vec::new();
    for (label, camera) in cameras {
        for &v in v_n_m_s {
            let spec = ExperimentSpec {
                n: per_point,
                v_n_range_m_s: (v, v),
                camera: *camera,
                ..*base
            };
            let sims = simulate(&spec, e_of_v_n, rng)?;
            for (fit, kind) in kinds {
                let rel: Vec<f64> = sims
                    .iter()
                    .filter_map(|s| {
                        measure_e(&s.frames, s.split, spec.d1_m, spec.d2_m, kind)
                            .ok()
                            .map(|(e, _)| e / s.e - 1.0)
                    })
                    .filter(|x| x.is_finite())
                    .collect();
                let m = rel.len() as f64;
                let bias = rel.iter().sum::<f64>() / m;
                let scatter =
                    (rel.iter().map(|x| (x - bias).powi(2)).sum::<f64>() / (m - 1.0)).sqrt();
                out.push(StudyPoint {
                    camera: label.clone(),
                    fit,
                    v_n_m_s: v,
                    simulated: sims.len(),
                    measured: rel.len(),
                    bias: if rel.len() >= 2 { bias } else { f64::NAN },
                    scatter: if rel.len() >= 2 { scatter } else { f64::NAN },
                });
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand::rngs::StdRng;

    #[test]
    fn spin_noise_that_overflows_is_an_error_naming_it() {
        let spec = ExperimentSpec {
            n: 10,
            spin_noise_rad_s: f64::MAX,
            ..ExperimentSpec::paper()
        };
        let mut rng = StdRng::seed_from_u64(535684499);
        let e = |_: f64| Ok(0.9);
        match simulate(&spec, &e, &mut rng) {
            Err(Error::InvalidParameter { name, value, .. }) => {
                assert!(name.starts_with("spin noise"), "{name}");
                assert_eq!(value, f64::MAX);
            }
            other => panic!("{:?}", other.map(|v| v.len())),
        }
        // The paper's spread: every measured spin a number.
        let mut rng = StdRng::seed_from_u64(1);
        let ok = simulate(&ExperimentSpec::paper(), &e, &mut rng).unwrap();
        assert!(
            ok.iter()
                .all(|c| c.spins_measured_rad_s.iter().all(|w| w.is_finite()))
        );
    }

    #[test]
    fn paper_camera_numbers() {
        let c = Camera::PAPER;
        assert!((c.pixel_m() - 0.25e-3).abs() < 1e-15);
        assert!((c.sigma_m() - 0.125e-3).abs() < 1e-15);
        // Eq. (8) at 1 m/s, N = 10: 0.125 mm / (1 ms sqrt 10) = 0.0395 m/s, the paper's "about 4%".
        let dv = crate::kinematics::eq8_velocity_error_m_s(2.0, c.subpixel_m(), c.dt_s(), 10.0);
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
