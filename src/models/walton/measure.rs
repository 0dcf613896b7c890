//! The inverse of Walton's operator: e, beta, psi and the impulse from measured pre- and
//! post-collision kinematics (docs/physics.md §4); the round trip with [`super::collide`] is
//! tested in the parent module.

use super::{State, Target, length};
use crate::error::{Error, Result};
use nalgebra::Vector3;

/// Collision properties measured from pre- and post-collision kinematics ([`measure`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Normal restitution, Eq. (4): (v_1' - v_2') . n = -e (v_1 - v_2) . n.
    pub e: f64,
    /// Tangential restitution, Eq. (5) projected on v_s: beta = -(v_s' . v_s)/|v_s|^2. `None`
    /// for a head-on collision (|v_s| <= 1e-12 |v_n|), where v_s has no direction.
    pub beta: Option<f64>,
    /// psi = v_n/|v_s| = -(v_c . n)/|v_s| >= 0 (+inf head-on).
    pub psi: f64,
    /// Normal approach speed -(v_c . n) before the collision, m/s (> 0): the `v_n_m_s` of `fit`.
    pub v_n_m_s: f64,
    /// Tangential contact speed |v_s| before the collision, m/s.
    pub v_s_m_s: f64,
    /// The impulse on sphere 1, N s: m_1 (v_1' - v_1) for a wall; for two spheres the
    /// inverse-variance mean of m_1 (v_1' - v_1) and -m_2 (v_2' - v_2), assuming both spheres'
    /// velocities are measured with the same error (equal masses: the plain mean).
    pub impulse_n_s: Vector3<f64>,
    /// |Delta P . n|, N s.
    pub impulse_normal_n_s: f64,
    /// |Delta P - (Delta P . n) n|, N s.
    pub impulse_tangential_n_s: f64,
    /// |Delta P_t|/|Delta P_n|: mu_0 on the sliding branch (Sec. II).
    pub impulse_ratio: f64,
    /// Change of the centre-of-mass velocity, (m_1 Delta v_1 + m_2 Delta v_2)/(m_1 + m_2), m/s:
    /// zero for exact data; the paper's momentum check Delta v = (v_1' + v_2' - v_1 - v_2)/2 for
    /// equal masses (Sec. III). `None` for a wall.
    pub com_velocity_change_m_s: Option<Vector3<f64>>,
}

/// The inverse of [`super::collide`]: e (Eq. 4), beta (Eq. 5), psi and the impulse from measured pre- and
/// post-collision kinematics. The contact geometry (n, and the contact velocity's lever arms) is
/// taken from `pre`; the post-collision positions are not used.
///
/// Errors: invalid bodies, coincident centres, a wall in one state and a sphere in the other,
/// surfaces that were not approaching before (e would be meaningless), or that still approach
/// after (e < 0).
pub fn measure(pre: &State, post: &State) -> Result<Measured> {
    let f = pre.contact()?;
    let n = f.normal;
    post.sphere.validate()?;
    let (v_rel_post, half_d_w_post) = match (&pre.target, &post.target) {
        (Target::Sphere(_), Target::Sphere(b)) => {
            b.validate()?;
            (
                post.sphere.velocity_m_s - b.velocity_m_s,
                0.5 * post.sphere.d_m * post.sphere.spin_rad_s + 0.5 * b.d_m * b.spin_rad_s,
            )
        }
        (Target::Wall { .. }, Target::Wall { .. }) => (
            post.sphere.velocity_m_s,
            0.5 * post.sphere.d_m * post.sphere.spin_rad_s,
        ),
        _ => {
            return Err(Error::InvalidParameter {
                name: "post-collision target",
                value: f64::NAN,
                expected: "the same kind (sphere or wall) as before the collision",
            });
        }
    };
    let approach = f.v_rel_m_s.dot(&n);
    if approach.is_nan() || approach >= 0.0 {
        return Err(Error::InvalidParameter {
            name: "normal relative velocity (v_1 - v_2) . n before the collision (m/s)",
            value: approach,
            expected: "< 0 (approaching spheres)",
        });
    }
    // Still approaching after the collision, the surfaces would interpenetrate: no e < 0 is a
    // measurement (`fit` refuses one as data). A mistyped post-collision velocity had given
    // e = -2.5e39, and the Walton fit averaged it into e = -7e37 with a 95% interval of [1, 1].
    let separation = v_rel_post.dot(&n);
    if separation.is_nan() || separation < 0.0 {
        return Err(Error::InvalidParameter {
            name: "normal relative velocity (v_1' - v_2') . n after the collision (m/s)",
            value: separation,
            expected: ">= 0 (separating spheres: e >= 0)",
        });
    }
    let e = -separation / approach;
    let v_c_post = v_rel_post - half_d_w_post.cross(&n);
    let v_s_post = v_c_post - v_c_post.dot(&n) * n;
    let vs2 = f.v_s_m_s.norm_squared();
    let v_n = -f.v_n_signed_m_s;
    let head_on = length(&f.v_s_m_s) <= 1e-12 * v_n.abs();
    let beta = if head_on {
        None
    } else {
        Some(-v_s_post.dot(&f.v_s_m_s) / vs2)
    };
    let psi = if head_on { f64::INFINITY } else { f.psi() };

    let m1 = pre.sphere.mass_kg;
    let dp1 = m1 * (post.sphere.velocity_m_s - pre.sphere.velocity_m_s);
    let (impulse, com_dv) = match (&pre.target, &post.target) {
        (Target::Sphere(a), Target::Sphere(b)) => {
            let m2 = a.mass_kg;
            let dp2 = -m2 * (b.velocity_m_s - a.velocity_m_s);
            // Var(m_i Delta v_i) ~ m_i^2 when both spheres' velocities carry the same error: weights
            // 1/m_i^2. Where those underflow (heavy bodies, density 1e300 kg/m^3: the mean was
            // 0/0) or overflow, the same mean with the mass ratio alone.
            let (w1, w2) = (1.0 / (m1 * m1), 1.0 / (m2 * m2));
            let dp = if w1.is_normal() && w2.is_normal() {
                (w1 * dp1 + w2 * dp2) / (w1 + w2)
            } else {
                let r2 = (m1 / m2).powi(2);
                (dp1 + r2 * dp2) / (1.0 + r2)
            };
            (dp, Some((dp1 - dp2) / (m1 + m2)))
        }
        _ => (dp1, None),
    };
    let dp_n = impulse.dot(&n);
    let dp_t = length(&(impulse - dp_n * n));
    Ok(Measured {
        e,
        beta,
        psi,
        v_n_m_s: v_n,
        v_s_m_s: length(&f.v_s_m_s),
        impulse_n_s: impulse,
        impulse_normal_n_s: dp_n.abs(),
        impulse_tangential_n_s: dp_t,
        impulse_ratio: dp_t / dp_n.abs(),
        com_velocity_change_m_s: com_dv,
    })
}
