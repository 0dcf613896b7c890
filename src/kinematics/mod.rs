//! Kinematics from tracked sphere centres: Sec. III of Labous et al. (1997), docs/physics.md §5.
//!
//! **Solves**: given the centres of two spheres in a sequence of video frames before and after a
//! collision, the velocities of both spheres just before and just after it, with uncertainties.
//!
//! **Method** (the paper's): per sphere, per phase (pre/post) and per coordinate, a least-squares
//! polynomial of degree two in time (`FitKind::Free`), or, with the acceleration known, a straight
//! line plus the fixed gravitational term (`FitKind::FixedGravity`: x'' = 0, y'' = -g, y up).
//! Fixing the acceleration removes the parameter most correlated with the end-point slope, and with
//! the same noise the velocities come out several times more precise (see the virtual experiment).
//!
//! **Collision time.** Primary: the first instant, at or after the last pre-collision frame minus
//! one frame interval, at which the centre distance on the pre-collision fits reaches
//! (d1 + d2)/2, i.e. the spheres touch. It is defined by the approach alone, so it does not depend
//! on the outcome being measured, and the distance changes at the normal speed, which pins the
//! instant to about sigma/v_n. Fallback, flagged: when noise keeps the fitted centres from ever
//! touching within the window, the instant where pre- and post-collision fits come closest (the
//! centres are continuous through an instantaneous collision).
//!
//! **Uncertainties**: the covariance of each fit from the residual variance pooled over all the
//! collision's fits (a fit of 10 frames alone estimates its own noise poorly), propagated to the
//! velocities at the collision time. Eq. (8)'s Delta v = s d/(n_s dt sqrt N) is reported next to it:
//! it ignores that the slope is taken at the end of the window, where a quadratic fit's slope has
//! a larger spread (1.3-1.6 times at N = 10 frames, 1.6-2.0 at 8, less beyond 12: the table in
//! docs/physics.md §5.4).
//!
//! **Needs**: at least 3 frames per phase (free fits) or 2 (fixed gravity), distinct times.

use crate::contact::{Material, Sphere};
use crate::error::{Error, Result};
use crate::models::walton::{self, Body, Measured, State};
use nalgebra::{Vector2, Vector3};

pub mod batch;
mod instant;
mod polyfit;
use instant::{collision_time, normal_restitution, propagate};
pub use polyfit::{PhaseFit, PolyFit};

/// Standard gravity, m/s^2.
pub const G_STANDARD_M_S2: f64 = 9.80665;

/// The largest gravity a fixed-gravity fit is given by the front ends, m/s^2 (1e5 g, a
/// centrifuge's): at 1e300 every collision's fit overflowed and was skipped, and the error
/// named the first collision's own reason instead of the gravity.
pub const G_MAX_M_S2: f64 = 1e6;

/// The range of gravities a fixed-gravity fit takes, as an error line states it.
pub const G_EXPECTED: &str = "a number > 0, at most 1e6 m/s^2 (1e5 g, a centrifuge's)";

/// Whether `g` is a gravity the front ends give a fixed-gravity fit ([`G_EXPECTED`]).
pub fn g_ok(g: f64) -> bool {
    g.is_finite() && g > 0.0 && g <= G_MAX_M_S2
}

/// How each coordinate is fitted in time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FitKind {
    /// x(t) = a + b t + c t^2 for every coordinate (the paper's).
    Free,
    /// x(t) = a + b t, y(t) = a + b t - g t^2/2 (y up).
    FixedGravity { g_m_s2: f64 },
}

impl FitKind {
    fn params(self) -> usize {
        match self {
            FitKind::Free => 3,
            FitKind::FixedGravity { .. } => 2,
        }
    }
}

/// One video frame: time and the two centres (x, y), metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub t_s: f64,
    pub r1_m: [f64; 2],
    pub r2_m: [f64; 2],
}

/// How the collision time was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub enum TimeRule {
    /// Centre distance on the pre-collision fits reaches (d1 + d2)/2.
    ContactDistance,
    /// Fallback: where the pre- and post-collision fits come closest.
    FitsMeet,
}

impl TimeRule {
    /// `contact_distance` or `fits_meet` (written to kinematics.csv).
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Velocities of both spheres before and after, at the collision time, with standard errors.
#[derive(Debug, Clone, PartialEq)]
pub struct Kinematics {
    /// Where the collision time is searched: last pre frame - dt .. first post frame + dt.
    pub window_s: (f64, f64),
    /// Centre distance at contact, (d1 + d2)/2, m.
    pub contact_m: f64,
    pub t_c_s: f64,
    pub time_rule: TimeRule,
    /// Centres at t_c from the pre-collision fits.
    pub r1_m: Vector2<f64>,
    pub r2_m: Vector2<f64>,
    /// Velocities: [sphere 1 pre, sphere 2 pre, sphere 1 post, sphere 2 post].
    pub v_m_s: [Vector2<f64>; 4],
    /// Variance of each velocity component per unit position-noise variance, same order.
    pub v_var_factor_per_m2: [Vector2<f64>; 4],
    /// Sum of squared residuals over the eight fits, m^2, and its degrees of freedom.
    pub rss_m2: f64,
    pub dof: usize,
    pub n_pre: usize,
    pub n_post: usize,
    pub pre: PhaseFit,
    pub post: PhaseFit,
}

/// Splits frames into pre and post phases when the tracks carry no phase label: frames up to the
/// closest approach are "pre", the rest "post"; the closest frame itself goes to whichever side
/// leaves the smaller total residual (it may be the last frame before contact or the first after).
pub fn split_at_contact(frames: &[Frame], kind: FitKind) -> Result<usize> {
    let need = kind.params();
    let dist =
        |f: &Frame| ((f.r1_m[0] - f.r2_m[0]).powi(2) + (f.r1_m[1] - f.r2_m[1]).powi(2)).sqrt();
    let k_min = (0..frames.len())
        .min_by(|&a, &b| dist(&frames[a]).total_cmp(&dist(&frames[b])))
        .ok_or(Error::InvalidParameter {
            name: "frames",
            value: 0.0,
            expected: "at least one frame",
        })?;
    let rss = |split: usize| -> Option<f64> {
        if split < need || frames.len() - split < need {
            return None;
        }
        let a = PhaseFit::new(&frames[..split], kind).ok()?;
        let b = PhaseFit::new(&frames[split..], kind).ok()?;
        Some(a.fits.iter().chain(b.fits.iter()).map(|f| f.rss).sum())
    };
    match (rss(k_min + 1), rss(k_min)) {
        (Some(a), Some(b)) => Ok(if a <= b { k_min + 1 } else { k_min }),
        (Some(_), None) => Ok(k_min + 1),
        (None, Some(_)) => Ok(k_min),
        (None, None) => Err(Error::InvalidParameter {
            name: "frames per phase",
            value: frames.len() as f64,
            expected: "enough frames on both sides of the closest approach",
        }),
    }
}

/// Fits both phases and extracts the velocities at the collision time. `frames` must be sorted by
/// time; `split` is the index of the first post-collision frame.
pub fn analyse(
    frames: &[Frame],
    split: usize,
    d1_m: f64,
    d2_m: f64,
    kind: FitKind,
) -> Result<Kinematics> {
    let need = kind.params();
    let (pre_frames, post_frames) = frames.split_at(split.min(frames.len()));
    if pre_frames.len() < need || post_frames.len() < need {
        return Err(Error::InvalidParameter {
            name: "frames per phase",
            value: pre_frames.len().min(post_frames.len()) as f64,
            expected: if need == 3 {
                "at least 3 frames before and after the collision (2 with fixed gravity)"
            } else {
                "at least 2 frames before and after the collision"
            },
        });
    }
    let pre = PhaseFit::new(pre_frames, kind)?;
    let post = PhaseFit::new(post_frames, kind)?;
    let dt = if frames.len() > 1 {
        (frames[frames.len() - 1].t_s - frames[0].t_s) / (frames.len() - 1) as f64
    } else {
        0.0
    };
    let window = (pre.t_last_s - dt, post.t_first_s + dt);
    let contact = 0.5 * (d1_m + d2_m);
    let (t_c, rule) = collision_time(&pre, &post, contact, window, None)?;
    let all = pre.fits.iter().chain(post.fits.iter());
    let (rss, dof) = all.fold((0.0, 0usize), |(r, d), f| (r + f.rss, d + f.n - need));
    let v = [
        pre.velocity(0, t_c),
        pre.velocity(1, t_c),
        post.velocity(0, t_c),
        post.velocity(1, t_c),
    ];
    let factor = [
        pre.velocity_var_factor(0, t_c),
        pre.velocity_var_factor(1, t_c),
        post.velocity_var_factor(0, t_c),
        post.velocity_var_factor(1, t_c),
    ];
    Ok(Kinematics {
        window_s: window,
        contact_m: contact,
        t_c_s: t_c,
        time_rule: rule,
        r1_m: pre.position(0, t_c),
        r2_m: pre.position(1, t_c),
        v_m_s: v,
        v_var_factor_per_m2: factor,
        rss_m2: rss,
        dof,
        n_pre: pre_frames.len(),
        n_post: post_frames.len(),
        pre,
        post,
    })
}

/// Eq. (8): Delta v = s d/(n_s dt sqrt N) = s * (subpixel size)/(dt sqrt N), with s the position
/// accuracy in subpixels, the subpixel size in metres, dt the frame interval and N the frames in
/// the fit. Optimistic for a slope at the end of the frame window (docs/physics.md §5).
pub fn eq8_velocity_error_m_s(s_subpixels: f64, subpixel_m: f64, dt_s: f64, n_frames: f64) -> f64 {
    s_subpixels * subpixel_m / (dt_s * n_frames.sqrt())
}

/// e and v_n of one collision from its tracks, without error propagation (for Monte Carlo
/// studies, where the scatter over repetitions is the error).
pub fn measure_e(
    frames: &[Frame],
    split: usize,
    d1_m: f64,
    d2_m: f64,
    kind: FitKind,
) -> Result<(f64, f64)> {
    let k = analyse(frames, split, d1_m, d2_m, kind)?;
    Ok(normal_restitution(&k.pre, &k.post, k.t_c_s))
}

/// The camera numbers Eq. (8) needs besides the frame interval and count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eq8Inputs {
    /// Accuracy of a centre, subpixels (the paper: s = 1 +- 0.5 measured, 2 quoted).
    pub s_subpixels: f64,
    /// Size of a subpixel in the object plane, m.
    pub subpixel_m: f64,
}

/// One collision measured from its tracks: the velocities, Walton's e, beta and psi from them
/// ([`walton::measure`]), and two error estimates of e.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    pub kinematics: Kinematics,
    pub pre: State,
    pub post: State,
    pub measured: Measured,
    /// The position noise the errors below assume, m.
    pub sigma_pos_m: f64,
    /// Standard errors of each velocity component: [1 pre, 2 pre, 1 post, 2 post], m/s.
    pub v_err_m_s: [Vector2<f64>; 4],
    /// Standard error of e from the fits' covariance, propagated through the whole chain: the
    /// velocities, and the normal's direction through the centres and the collision time (a
    /// position error along n shifts t_c by delta/v_n, while r1 - r2 turns at v_t/|r1 - r2|:
    /// for grazing impacts this dominates).
    pub e_err: f64,
    /// Standard error of v_n from the fits' covariance, m/s.
    pub v_n_err_m_s: f64,
    /// Eq. (8): the error of one sphere's velocity component (docs/physics.md §5.4-5.5), with N
    /// the mean number of frames of the pre- and post-collision fits, m/s.
    pub eq8_dv_m_s: f64,
    /// The paper's error of e from Eq. (8): Delta e = 2 e Delta v / v_n.
    pub e_err_eq8: f64,
}

/// Runs the whole chain for one collision: fits, collision time, velocities, then Walton's
/// measurement. `spins_rad_s` are the z spins [1 pre, 2 pre, 1 post, 2 post] from markers.
///
/// `sigma_pos_m` is the position noise behind the error estimates. `None` estimates it from this
/// collision's residuals, or, without residual degrees of freedom (3 frames a phase with free
/// fits), takes the camera's stated accuracy s x subpixel. A caller with many collisions from one
/// camera does better to pool the residuals over all of them ([`Kinematics::rss_m2`], `dof`).
#[allow(clippy::too_many_arguments)]
pub fn measure_collision(
    frames: &[Frame],
    split: usize,
    d1_m: f64,
    d2_m: f64,
    material: &Material,
    inertia_k: f64,
    spins_rad_s: [f64; 4],
    kind: FitKind,
    eq8: &Eq8Inputs,
    sigma_pos_m: Option<f64>,
) -> Result<Measurement> {
    let k = analyse(frames, split, d1_m, d2_m, kind)?;
    let sigma = match sigma_pos_m {
        Some(s) => s,
        None if k.dof > 0 => (k.rss_m2 / k.dof as f64).sqrt(),
        None => eq8.s_subpixels * eq8.subpixel_m,
    };
    let v_err = k
        .v_var_factor_per_m2
        .map(|f| f.map(|x| (x * sigma * sigma).sqrt()));
    let body = |d: f64, r: Vector2<f64>, v: Vector2<f64>, w: f64| -> Result<Body> {
        let mut b = Body::homogeneous(Vector3::new(r.x, r.y, 0.0), &Sphere::new(d, *material)?);
        b.inertia_k = inertia_k;
        Ok(b.moving(Vector3::new(v.x, v.y, 0.0), Vector3::new(0.0, 0.0, w)))
    };
    let pre = State::pair(
        body(d1_m, k.r1_m, k.v_m_s[0], spins_rad_s[0])?,
        body(d2_m, k.r2_m, k.v_m_s[1], spins_rad_s[1])?,
    );
    let post = State::pair(
        body(d1_m, k.r1_m, k.v_m_s[2], spins_rad_s[2])?,
        body(d2_m, k.r2_m, k.v_m_s[3], spins_rad_s[3])?,
    );
    let measured = walton::measure(&pre, &post)?;
    let (e_err, v_n_err) = propagate(&k, sigma)?;
    let e = measured.e;
    let dt = frames
        .windows(2)
        .map(|w| w[1].t_s - w[0].t_s)
        .fold(f64::INFINITY, f64::min);
    // The mean, not its integer part: 9 and 10 frames are N = 9.5, not 9.
    let n_mean = (k.n_pre + k.n_post) as f64 / 2.0;
    let eq8_dv = eq8_velocity_error_m_s(eq8.s_subpixels, eq8.subpixel_m, dt, n_mean);
    Ok(Measurement {
        sigma_pos_m: sigma,
        v_err_m_s: v_err,
        e_err,
        v_n_err_m_s: v_n_err,
        eq8_dv_m_s: eq8_dv,
        e_err_eq8: 2.0 * e * eq8_dv / measured.v_n_m_s,
        kinematics: k,
        pre,
        post,
        measured,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ballistic(t: f64, r0: [f64; 2], v0: [f64; 2], g: f64) -> [f64; 2] {
        [r0[0] + v0[0] * t, r0[1] + v0[1] * t - 0.5 * g * t * t]
    }

    /// Head-on collision at t = 0 of two 10 mm spheres with exact (noise-free) tracks.
    fn frames(e: f64) -> Vec<Frame> {
        let g = G_STANDARD_M_S2;
        let d = 0.01;
        let (u1, u2) = (1.0, -1.0);
        let (w1, w2) = (-e, e); // equal masses, head-on: velocities swap sign times e
        let mut out = Vec::new();
        for k in -10..=10 {
            if k == 0 {
                continue;
            }
            let t = k as f64 * 1e-3 + 0.3e-3;
            let (v1, v2) = if t < 0.0 { (u1, u2) } else { (w1, w2) };
            let r1 = ballistic(t, [-d / 2.0, 0.0], [v1, 0.0], g);
            let r2 = ballistic(t, [d / 2.0, 0.0], [v2, 0.0], g);
            out.push(Frame {
                t_s: t,
                r1_m: r1,
                r2_m: r2,
            });
        }
        out
    }

    #[test]
    fn exact_tracks_give_exact_velocities() {
        let f = frames(0.8);
        let split = split_at_contact(&f, FitKind::Free).unwrap();
        assert_eq!(split, 10);
        for kind in [
            FitKind::Free,
            FitKind::FixedGravity {
                g_m_s2: G_STANDARD_M_S2,
            },
        ] {
            let k = analyse(&f, split, 0.01, 0.01, kind).unwrap();
            assert_eq!(k.time_rule, TimeRule::ContactDistance);
            // Contact at t = 0: the centres are 10 mm apart then (closed form of the tracks).
            assert!(k.t_c_s.abs() < 1e-12, "{}", k.t_c_s);
            // Quadratic fits are exact on ballistic tracks: slopes to rounding.
            let want = [[1.0, 0.0], [-1.0, 0.0], [-0.8, 0.0], [0.8, 0.0]];
            for (v, w) in k.v_m_s.iter().zip(want) {
                assert!(
                    (v.x - w[0]).abs() < 1e-9 && (v.y - w[1]).abs() < 1e-9,
                    "{v:?} {w:?}"
                );
            }
        }
    }

    #[test]
    fn too_few_frames_is_an_error() {
        let f = frames(0.8);
        assert!(analyse(&f[8..12], 2, 0.01, 0.01, FitKind::Free).is_err());
        assert!(
            analyse(
                &f[8..12],
                2,
                0.01,
                0.01,
                FitKind::FixedGravity { g_m_s2: 9.8 }
            )
            .is_ok()
        );
    }
}
