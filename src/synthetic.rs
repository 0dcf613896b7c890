//! Synthetic oblique-collision data sets like the paper's Fig. 6 series (Sec. IV): the known
//! truth behind `data/oblique_collisions.csv`, the Walton-fit tests and the coverage study.

use crate::contact::{Material, Sphere};
use crate::error::{Error, Result};
use crate::fit::walton::CollisionRecord;
use crate::models::walton::{self, Body, State, Target};
use nalgebra::Vector3;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// A synthetic oblique-collision experiment like the paper's Fig. 6 series: two equal spheres
/// launched towards each other at about the same speed, the impact parameter varied so that the
/// angle of incidence covers a range, collided with Walton's operator, and the kinematics blurred
/// by Gaussian measurement noise. Used by `examples/gen_oblique_collisions.rs` and the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyntheticSpec {
    pub n: usize,
    pub d_m: f64,
    pub material: Material,
    pub inertia_k: f64,
    pub params: walton::WaltonParams,
    /// Mean launch speed of each sphere and its standard deviation, m/s.
    pub speed_m_s: f64,
    pub speed_sd_m_s: f64,
    /// Angle between -n and the relative velocity, drawn uniformly in this range, degrees.
    pub incidence_deg: (f64, f64),
    /// Standard deviation of the pre-collision spins (each component in the plane's normal), rad/s.
    pub spin_sd_rad_s: f64,
    /// Measurement noise, one standard deviation per component: centre velocity (m/s), spin
    /// (rad/s), centre position at contact (m).
    pub noise_v_m_s: f64,
    pub noise_w_rad_s: f64,
    pub noise_r_m: f64,
}

impl SyntheticSpec {
    /// The paper's experiment (Sec. IV): 25.4 mm nylon, about 2 m/s per sphere, e = 0.97,
    /// mu_0 = 0.175, beta_0 = 0.5, 60 collisions with incidence 10 to 80 degrees (psi about
    /// 0.18 to 5.7). Noise: 0.04 m/s per velocity component, the paper's "about a 4% uncertainty
    /// for velocities of the order of 1 m/s" (Sec. III); spins 3 rad/s, which gives the surface
    /// speed (d/2) w the same error as the centre speed; positions 0.2 mm, two subpixels (half a
    /// pixel) for a 25.4 mm sphere imaged over about 60 pixels (a 100 mm field of view on the
    /// camera's 239 pixels).
    pub fn paper() -> Self {
        SyntheticSpec {
            n: 60,
            d_m: 0.0254,
            material: Material::preset("nylon").expect("a preset"),
            inertia_k: walton::K_HOMOGENEOUS,
            params: walton::WaltonParams::PAPER_NYLON,
            speed_m_s: 2.0,
            speed_sd_m_s: 0.05,
            incidence_deg: (10.0, 80.0),
            spin_sd_rad_s: 3.0,
            noise_v_m_s: 0.04,
            noise_w_rad_s: 3.0,
            noise_r_m: 2e-4,
        }
    }
}

/// Draws the collisions of `spec` (true and measured), reproducibly from `seed`. In 2-D (the x-y
/// plane, spins about z), as in the paper's camera plane. Returns (true, measured) records.
pub fn synthetic_collisions(
    spec: &SyntheticSpec,
    seed: u64,
) -> Result<(Vec<CollisionRecord>, Vec<CollisionRecord>)> {
    use rand_distr::{Distribution, Normal};
    let normal = |sd: f64| {
        Normal::new(0.0, sd).map_err(|_| Error::InvalidParameter {
            name: "noise standard deviation",
            value: sd,
            expected: "a finite number >= 0",
        })
    };
    let (speed_noise, spin0, nv, nw, nr) = (
        normal(spec.speed_sd_m_s)?,
        normal(spec.spin_sd_rad_s)?,
        normal(spec.noise_v_m_s)?,
        normal(spec.noise_w_rad_s)?,
        normal(spec.noise_r_m)?,
    );
    let sphere = Sphere::new(spec.d_m, spec.material)?;
    let mut rng = StdRng::seed_from_u64(seed);
    let mut truth = Vec::with_capacity(spec.n);
    let mut measured = Vec::with_capacity(spec.n);
    let (lo, hi) = spec.incidence_deg;
    for i in 0..spec.n {
        let speed1 = spec.speed_m_s + speed_noise.sample(&mut rng);
        let speed2 = spec.speed_m_s + speed_noise.sample(&mut rng);
        // Launch directions within a few degrees of +x and -x.
        let a1 = rng.random_range(-3f64..3.0).to_radians();
        let a2 = std::f64::consts::PI + rng.random_range(-3f64..3.0).to_radians();
        let v1 = speed1 * Vector3::new(a1.cos(), a1.sin(), 0.0);
        let v2 = speed2 * Vector3::new(a2.cos(), a2.sin(), 0.0);
        let u = (v1 - v2).normalize();
        let theta = rng.random_range(lo..=hi).to_radians();
        let theta = if rng.random_bool(0.5) { theta } else { -theta };
        // n = -u rotated by theta about z.
        let n = Vector3::new(
            -(u.x * theta.cos() - u.y * theta.sin()),
            -(u.x * theta.sin() + u.y * theta.cos()),
            0.0,
        );
        let r1 = Vector3::new(
            0.05 + rng.random_range(-0.01..0.01),
            0.10 + rng.random_range(-0.01..0.01),
            0.0,
        );
        let r2 = r1 - spec.d_m * n;
        let body = |r: Vector3<f64>, v: Vector3<f64>, w: f64| Body {
            inertia_k: spec.inertia_k,
            ..Body::homogeneous(r, &sphere).moving(v, Vector3::new(0.0, 0.0, w))
        };
        let pre = State::pair(
            body(r1, v1, spin0.sample(&mut rng)),
            body(r2, v2, spin0.sample(&mut rng)),
        );
        let post = walton::collide(&pre, &spec.params)?.state;
        let mut blur = |b: &Body, position: bool| -> Body {
            let dr = if position {
                Vector3::new(nr.sample(&mut rng), nr.sample(&mut rng), 0.0)
            } else {
                Vector3::zeros()
            };
            Body {
                position_m: b.position_m + dr,
                velocity_m_s: b.velocity_m_s
                    + Vector3::new(nv.sample(&mut rng), nv.sample(&mut rng), 0.0),
                spin_rad_s: b.spin_rad_s + Vector3::new(0.0, 0.0, nw.sample(&mut rng)),
                ..*b
            }
        };
        let sphere2 = |s: &State| match s.target {
            Target::Sphere(b) => b,
            Target::Wall { .. } => unreachable!("synthetic collisions are sphere pairs"),
        };
        let pre_m = State::pair(blur(&pre.sphere, true), blur(&sphere2(&pre), true));
        // The collision is instantaneous: measured post positions are the measured contact ones.
        let mut post_m = State::pair(blur(&post.sphere, false), blur(&sphere2(&post), false));
        post_m.sphere.position_m = pre_m.sphere.position_m;
        if let (Target::Sphere(b), Target::Sphere(a)) = (&mut post_m.target, &pre_m.target) {
            b.position_m = a.position_m;
        }
        let id = Some(format!("{}", i + 1));
        truth.push(CollisionRecord {
            line: 0,
            id: id.clone(),
            pre,
            post,
        });
        measured.push(CollisionRecord {
            line: 0,
            id,
            pre: pre_m,
            post: post_m,
        });
    }
    Ok((truth, measured))
}
