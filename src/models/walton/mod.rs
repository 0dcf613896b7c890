//! Walton's collision operator for frictional spheres, Eqs. (1)-(7) of the paper (docs/physics.md §4),
//! in 3-D, for two spheres of any sizes, masses and moments of inertia, or a sphere on a flat wall.
//!
//! A collision is instantaneous and described by three collisional properties ([`WaltonParams`]):
//! the normal restitution `e` (Eq. 4), the friction coefficient `mu0` of the sliding branch (Eq. 6)
//! and the limiting tangential restitution `beta0` of the rolling branch (Eq. 7).
//!
//! * [`collide`] is the forward operator a DEM code calls: pre-collision state in, post-collision
//!   state out, with the contact classed as sliding or rolling.
//! * [`measure`] is the inverse an experimentalist uses: from measured pre- and post-collision
//!   kinematics it returns e (Eq. 4), beta (Eq. 5 projected on v_s), psi = -v_n/|v_s| (the
//!   abscissa of the paper's Figs. 2 and 6) and the impulse ratio |Delta P_t| / |Delta P_n|.
//!
//! Conventions (the paper's): sphere 2 exerts the impulse Delta P on sphere 1; the normal
//! n = (r_1 - r_2)/|r_1 - r_2| points from sphere 2 to sphere 1; the contact velocity is
//! v_c = v_1 - v_2 - (d_1/2 w_1 + d_2/2 w_2) x n (Eq. 3); approaching spheres have v_c . n < 0.
//!
//! Generalisation beyond the paper and docs/physics.md §4 (derived here; the tests check momentum,
//! angular momentum and the energy loss for unequal K): each
//! body carries its own inertia factor K_i = 4 I_i/(m_i d_i^2). A tangential impulse changes the
//! contact velocity by Delta v_s = Delta P_t / m_t with the tangential effective mass
//! 1/m_t = (1 + 1/K_1)/m_1 + (1 + 1/K_2)/m_2 (a wall contributes nothing). With K_1 = K_2 = K this
//! is m_t = m_red K/(1 + K) and every formula below reduces to the paper's; the sliding-branch
//! slope mu_0 (1 + 1/K)(1 + e) of Eq. (7) becomes mu_0 (1 + e) m_red/m_t.

use crate::contact::Sphere;
use crate::error::{Error, Result};
use nalgebra::Vector3;

mod measure;
pub use measure::{Measured, measure};

/// Inertia factor K = 4I/(m d^2) of a homogeneous sphere (I = m d^2/10).
pub const K_HOMOGENEOUS: f64 = 0.4;

/// Whether `k` is an inertia factor a body can have: K = 4I/(m d^2) in (0, 1] (2/3 for a thin
/// spherical shell; 1 would put all the mass on the equator). What the front ends say
/// otherwise: [`INERTIA_K_EXPECTED`].
pub fn inertia_k_ok(k: f64) -> bool {
    k.is_finite() && k > 0.0 && k <= 1.0
}

/// The range of [`inertia_k_ok`], as an error line states it.
pub const INERTIA_K_EXPECTED: &str =
    "a number in (0, 1] (K = 4I/(m d^2); 0.4 for a homogeneous sphere)";

/// A rigid sphere at the instant of contact. SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Centre, m.
    pub position_m: Vector3<f64>,
    /// Centre velocity, m/s.
    pub velocity_m_s: Vector3<f64>,
    /// Angular velocity (rotation vector), rad/s.
    pub spin_rad_s: Vector3<f64>,
    /// Diameter, m.
    pub d_m: f64,
    /// Mass, kg.
    pub mass_kg: f64,
    /// K = 4 I/(m d^2): 2/5 for a homogeneous sphere ([`K_HOMOGENEOUS`]), 2/3 for a thin shell.
    pub inertia_k: f64,
}

impl Body {
    /// A homogeneous sphere (K = 2/5, mass from [`Sphere::mass_kg`]) at rest and not spinning,
    /// centred at `position_m`.
    pub fn homogeneous(position_m: Vector3<f64>, sphere: &Sphere) -> Self {
        Body {
            position_m,
            velocity_m_s: Vector3::zeros(),
            spin_rad_s: Vector3::zeros(),
            d_m: sphere.d_m,
            mass_kg: sphere.mass_kg(),
            inertia_k: K_HOMOGENEOUS,
        }
    }

    /// The same body moving with `velocity_m_s` and spinning with `spin_rad_s`.
    pub fn moving(self, velocity_m_s: Vector3<f64>, spin_rad_s: Vector3<f64>) -> Self {
        Body {
            velocity_m_s,
            spin_rad_s,
            ..self
        }
    }

    /// Moment of inertia about the centre, I = K m d^2/4, kg m^2.
    pub fn inertia_kg_m2(&self) -> f64 {
        0.25 * self.inertia_k * self.mass_kg * self.d_m * self.d_m
    }

    /// Linear momentum m v, kg m/s.
    pub fn momentum(&self) -> Vector3<f64> {
        self.mass_kg * self.velocity_m_s
    }

    /// Angular momentum about `point_m`: m (r - point) x v + I w, kg m^2/s.
    pub fn angular_momentum_about(&self, point_m: &Vector3<f64>) -> Vector3<f64> {
        self.mass_kg * (self.position_m - point_m).cross(&self.velocity_m_s)
            + self.inertia_kg_m2() * self.spin_rad_s
    }

    /// Kinetic energy, translational plus rotational, J.
    pub fn kinetic_energy_j(&self) -> f64 {
        0.5 * self.mass_kg * self.velocity_m_s.norm_squared()
            + 0.5 * self.inertia_kg_m2() * self.spin_rad_s.norm_squared()
    }

    fn validate(&self) -> Result<()> {
        let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
        let bad = |name, value, expected| {
            Err(Error::InvalidParameter {
                name,
                value,
                expected,
            })
        };
        if !(self.d_m.is_finite() && self.d_m > 0.0) {
            return bad("sphere diameter (m)", self.d_m, "a finite number > 0");
        }
        if !(self.mass_kg.is_finite() && self.mass_kg > 0.0) {
            return bad("sphere mass (kg)", self.mass_kg, "a finite number > 0");
        }
        if !inertia_k_ok(self.inertia_k) {
            return bad(
                "inertia factor K = 4I/(m d^2)",
                self.inertia_k,
                "a number in (0, 1] (2/5 for a homogeneous sphere)",
            );
        }
        for (name, v) in [
            ("sphere position (m)", &self.position_m),
            ("sphere velocity (m/s)", &self.velocity_m_s),
            ("sphere spin (rad/s)", &self.spin_rad_s),
        ] {
            if !finite(v) {
                let value = v
                    .iter()
                    .copied()
                    .find(|x| !x.is_finite())
                    .unwrap_or(f64::NAN);
                return bad(name, value, "finite components");
            }
        }
        Ok(())
    }
}

/// What sphere 1 hits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// A second sphere.
    Sphere(Body),
    /// A flat, immovable wall at rest. `contact_point_m` is the point of the wall that sphere 1
    /// touches, so that r_1 - contact_point lies along the wall normal (docs/physics.md §4).
    Wall { contact_point_m: Vector3<f64> },
}

/// The kinematic state of a colliding pair at the instant of contact (before or after).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    pub sphere: Body,
    pub target: Target,
}

/// The pre-collision state [`collide`] takes.
pub type PreCollision = State;

impl State {
    /// Two spheres.
    pub fn pair(sphere1: Body, sphere2: Body) -> Self {
        State {
            sphere: sphere1,
            target: Target::Sphere(sphere2),
        }
    }

    /// A sphere on a wall whose contact point is `contact_point_m`.
    pub fn on_wall(sphere: Body, contact_point_m: Vector3<f64>) -> Self {
        State {
            sphere,
            target: Target::Wall { contact_point_m },
        }
    }

    /// Total linear momentum of the bodies that can move, kg m/s (a wall has none to report).
    pub fn momentum(&self) -> Vector3<f64> {
        match &self.target {
            Target::Sphere(b) => self.sphere.momentum() + b.momentum(),
            Target::Wall { .. } => self.sphere.momentum(),
        }
    }

    /// Total angular momentum of the moving bodies about `point_m`, kg m^2/s.
    pub fn angular_momentum_about(&self, point_m: &Vector3<f64>) -> Vector3<f64> {
        let l1 = self.sphere.angular_momentum_about(point_m);
        match &self.target {
            Target::Sphere(b) => l1 + b.angular_momentum_about(point_m),
            Target::Wall { .. } => l1,
        }
    }

    /// Total kinetic energy, J.
    pub fn kinetic_energy_j(&self) -> f64 {
        let k1 = self.sphere.kinetic_energy_j();
        match &self.target {
            Target::Sphere(b) => k1 + b.kinetic_energy_j(),
            Target::Wall { .. } => k1,
        }
    }

    /// The contact geometry and the contact velocity (Eq. 3) of this state.
    pub fn contact(&self) -> Result<ContactFrame> {
        self.sphere.validate()?;
        let s1 = &self.sphere;
        let (r2, v2_contact, inv_m2, inv_mt2) = match &self.target {
            Target::Sphere(b) => {
                b.validate()?;
                (
                    b.position_m,
                    Some((b.velocity_m_s, 0.5 * b.d_m * b.spin_rad_s)),
                    1.0 / b.mass_kg,
                    (1.0 + 1.0 / b.inertia_k) / b.mass_kg,
                )
            }
            Target::Wall { contact_point_m } => {
                if !contact_point_m.iter().all(|x| x.is_finite()) {
                    return Err(Error::InvalidParameter {
                        name: "wall contact point (m)",
                        value: f64::NAN,
                        expected: "finite components",
                    });
                }
                (*contact_point_m, None, 0.0, 0.0)
            }
        };
        let sep = s1.position_m - r2;
        let dist = length(&sep);
        if !(dist > 0.0 && dist.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "distance between the centres (or centre and wall contact point), m",
                value: dist,
                expected: "> 0 (the normal n = (r1 - r2)/|r1 - r2| must be defined)",
            });
        }
        let n = sep / dist;
        // Eq. (3); a wall has neither velocity nor spin.
        let spin_sum = 0.5 * s1.d_m * s1.spin_rad_s;
        let (v_rel, spin_sum) = match v2_contact {
            Some((v2, half_d2_w2)) => (s1.velocity_m_s - v2, spin_sum + half_d2_w2),
            None => (s1.velocity_m_s, spin_sum),
        };
        let v_c = v_rel - spin_sum.cross(&n);
        let v_n_signed = v_c.dot(&n);
        let v_s = v_c - v_n_signed * n;
        let m_red = 1.0 / (1.0 / s1.mass_kg + inv_m2);
        let m_t = 1.0 / ((1.0 + 1.0 / s1.inertia_k) / s1.mass_kg + inv_mt2);
        Ok(ContactFrame {
            normal: n,
            v_rel_m_s: v_rel,
            v_c_m_s: v_c,
            v_n_signed_m_s: v_n_signed,
            v_s_m_s: v_s,
            m_red_kg: m_red,
            m_t_kg: m_t,
        })
    }
}

/// Contact geometry and kinematics of a [`State`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    /// n = (r_1 - r_2)/|r_1 - r_2|.
    pub normal: Vector3<f64>,
    /// Relative centre velocity v_1 - v_2, m/s.
    pub v_rel_m_s: Vector3<f64>,
    /// Contact velocity v_c (Eq. 3), m/s.
    pub v_c_m_s: Vector3<f64>,
    /// v_c . n, m/s: negative while the surfaces approach.
    pub v_n_signed_m_s: f64,
    /// Tangential part v_s = v_c - (v_c . n) n, m/s.
    pub v_s_m_s: Vector3<f64>,
    /// m_red = m_1 m_2/(m_1 + m_2) (wall: m_1), kg.
    pub m_red_kg: f64,
    /// Tangential effective mass, 1/m_t = (1 + 1/K_1)/m_1 + (1 + 1/K_2)/m_2 (wall: no second
    /// term); m_red K/(1 + K) when both K are equal. kg.
    pub m_t_kg: f64,
}

impl ContactFrame {
    /// psi = -(v_c . n)/|v_s| = -cot(gamma), the abscissa of Figs. 2 and 6 (+inf head-on).
    pub fn psi(&self) -> f64 {
        -self.v_n_signed_m_s / length(&self.v_s_m_s)
    }

    /// The slope s of beta(psi) on the sliding branch, in beta = -1 + s psi (Eq. 7):
    /// s = mu_0 (1 + e) m_red/m_t, which is mu_0 (1 + 1/K)(1 + e) for equal K.
    pub fn sliding_slope(&self, e: f64, mu0: f64) -> f64 {
        mu0 * (1.0 + e) * self.m_red_kg / self.m_t_kg
    }
}

/// The three collisional properties of Walton's operator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaltonParams {
    /// Normal coefficient of restitution, Eq. (4).
    pub e: f64,
    /// Coulomb friction coefficient of the sliding branch, Eq. (6).
    pub mu0: f64,
    /// Tangential restitution of the rolling branch, the upper bound of beta (Eq. 7).
    pub beta0: f64,
}

impl WaltonParams {
    /// Validates 0 <= e <= 1, mu0 >= 0 and -1 <= beta0 <= 1: the domain on which the operator
    /// never creates kinetic energy (docs/physics.md §4).
    pub fn new(e: f64, mu0: f64, beta0: f64) -> Result<Self> {
        let check = |name, v: f64, ok: bool, expected| {
            if v.is_finite() && ok {
                Ok(())
            } else {
                Err(Error::InvalidParameter {
                    name,
                    value: v,
                    expected,
                })
            }
        };
        check("e", e, (0.0..=1.0).contains(&e), "a number in [0, 1]")?;
        check("mu0", mu0, mu0 >= 0.0, "a number >= 0")?;
        check(
            "beta0",
            beta0,
            (-1.0..=1.0).contains(&beta0),
            "a number in [-1, 1]",
        )?;
        Ok(WaltonParams { e, mu0, beta0 })
    }

    /// The paper's values for 25.4 mm nylon spheres (Sec. IV, Fig. 6): e = 0.97, mu_0 = 0.175,
    /// beta_0 = 0.5.
    pub const PAPER_NYLON: WaltonParams = WaltonParams {
        e: 0.97,
        mu0: 0.175,
        beta0: 0.5,
    };
}

/// Which branch of Eq. (7) a collision took.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ContactKind {
    /// Coulomb sliding throughout, Delta P_t = -mu_0 |Delta P_n| t (Eq. 6), beta < beta_0.
    Sliding,
    /// The sliding assumption would give beta >= beta_0: beta = beta_0 (Eq. 7). Head-on
    /// collisions (v_s = 0, psi = +inf) are classed here; their tangential impulse is zero.
    Rolling,
}

impl ContactKind {
    pub fn as_str(&self) -> &'static str {
        match self {
            ContactKind::Sliding => "sliding",
            ContactKind::Rolling => "rolling",
        }
    }
}

/// What [`collide`] returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PostCollision {
    /// The post-collision state (positions unchanged: the collision is instantaneous).
    pub state: State,
    pub kind: ContactKind,
    /// Tangential restitution applied, v_s' = -beta v_s (Eq. 5).
    pub beta: f64,
    /// psi = -v_n/|v_s| before the collision (+inf head-on).
    pub psi: f64,
    /// Impulse exerted by sphere 2 (or the wall) on sphere 1, N s.
    pub impulse_n_s: Vector3<f64>,
    /// Contact normal n.
    pub normal: Vector3<f64>,
}

/// The Euclidean length of `v`, rescaled where its squares overflow or underflow: a heavy
/// body's impulse (density 1e300 kg/m^3: components ~1e294 N s) has a finite length whose squares
/// are not, and `norm()` made the sliding branch's impulse, hence every velocity after it, inf
/// and NaN. Ordinary vectors take `norm()`'s value to the bit.
pub(crate) fn length(v: &Vector3<f64>) -> f64 {
    let n2 = v.norm_squared();
    if n2.is_finite() && n2 >= 1e-290 {
        return n2.sqrt();
    }
    let m = v.amax();
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    m * (v / m).norm()
}

/// Walton's operator, Eqs. (1)-(7): the post-collision state of an approaching pair.
///
/// Delta P_n = -(1 + e) m_red v_n; beta = min(-1 + mu_0 (1 + e) (m_red/m_t) psi, beta_0) (Eq. 7,
/// with m_red/m_t = 1 + 1/K for equal K); Delta P_t = -(1 + beta) m_t v_s, which on the sliding
/// branch equals -mu_0 |Delta P_n| v_s/|v_s| (Eq. 6); then Eq. (1) for the velocities and Eq. (2)
/// for the spins, w_i' = w_i - (d_i/(2 I_i)) n x Delta P for both spheres.
///
/// Errors: invalid parameters or bodies, coincident centres, or surfaces that are not approaching
/// (v_c . n >= 0: there is no collision to resolve).
pub fn collide(pre: &PreCollision, params: &WaltonParams) -> Result<PostCollision> {
    let p = WaltonParams::new(params.e, params.mu0, params.beta0)?;
    let f = pre.contact()?;
    if f.v_n_signed_m_s >= 0.0 {
        return Err(Error::InvalidParameter {
            name: "normal contact velocity v_c . n (m/s)",
            value: f.v_n_signed_m_s,
            expected: "< 0 (approaching surfaces)",
        });
    }
    let v_n = f.v_n_signed_m_s * f.normal;
    let dp_n = -(1.0 + p.e) * f.m_red_kg * v_n;
    let vs_norm = length(&f.v_s_m_s);
    let psi = f.psi();
    let beta_sliding = -1.0 + f.sliding_slope(p.e, p.mu0) * psi;
    let (kind, beta) = if beta_sliding < p.beta0 {
        (ContactKind::Sliding, beta_sliding)
    } else {
        (ContactKind::Rolling, p.beta0)
    };
    let dp_t = if vs_norm > 0.0 {
        match kind {
            // Eq. (6) literally, rather than -(1 + beta) m_t v_s, so that the sliding branch's
            // impulse ratio is mu_0 to rounding.
            ContactKind::Sliding => -p.mu0 * length(&dp_n) / vs_norm * f.v_s_m_s,
            ContactKind::Rolling => -(1.0 + beta) * f.m_t_kg * f.v_s_m_s,
        }
    } else {
        Vector3::zeros()
    };
    let dp = dp_n + dp_t;
    let n = f.normal;
    let kick = |b: &Body, sign: f64| -> Body {
        // Eq. (1) and Eq. (2): both spheres' spins change by -(d_i/(2 I_i)) n x Delta P.
        Body {
            velocity_m_s: b.velocity_m_s + sign * dp / b.mass_kg,
            spin_rad_s: b.spin_rad_s - (0.5 * b.d_m / b.inertia_kg_m2()) * n.cross(&dp),
            ..*b
        }
    };
    let sphere = kick(&pre.sphere, 1.0);
    let target = match &pre.target {
        Target::Sphere(b) => Target::Sphere(kick(b, -1.0)),
        wall @ Target::Wall { .. } => *wall,
    };
    Ok(PostCollision {
        state: State { sphere, target },
        kind,
        beta,
        psi,
        impulse_n_s: dp,
        normal: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Textbook case, independent of Eq. (7)'s algebra: a homogeneous sphere without spin hits a
    /// wall obliquely. Sliding throughout: v_t' = v_t - mu (1 + e) v_n. Ending in pure rolling
    /// (beta_0 = 0, contact velocity zero afterwards): v_t' = (5/7) v_t, w' = 5 v_t/(7 R).
    #[test]
    fn sphere_on_wall_known_answers() {
        let d = 0.02;
        let r = 0.5 * d;
        let nylon = Sphere::new(d, crate::contact::Material::preset("nylon").unwrap()).unwrap();
        let body = Body::homogeneous(Vector3::new(0.0, r, 0.0), &nylon)
            .moving(Vector3::new(1.5, -2.0, 0.0), Vector3::zeros());
        let pre = State::on_wall(body, Vector3::zeros());
        // Sliding: psi = 2/1.5, slope mu (1 + 1/K)(1 + e) = 0.1 * 3.5 * 1.9 -> beta = -0.1133 < 0.9.
        let p = WaltonParams::new(0.9, 0.1, 0.9).unwrap();
        let post = collide(&pre, &p).unwrap();
        assert_eq!(post.kind, ContactKind::Sliding);
        let v = post.state.sphere.velocity_m_s;
        // Tolerances: a handful of roundings of O(1) numbers.
        assert!((v.x - (1.5 - 0.1 * 1.9 * 2.0)).abs() < 1e-14, "{v}");
        assert!((v.y - 0.9 * 2.0).abs() < 1e-14);
        // Rolling with beta_0 = 0: ends rolling without slip.
        let p = WaltonParams::new(0.9, 10.0, 0.0).unwrap();
        let post = collide(&pre, &p).unwrap();
        assert_eq!(post.kind, ContactKind::Rolling);
        let s = post.state.sphere;
        assert!((s.velocity_m_s.x - 5.0 / 7.0 * 1.5).abs() < 1e-14);
        // Spin about -z for motion along +x over a wall below (rolling: v_x = -w_z R).
        assert!((s.spin_rad_s.z + 5.0 * 1.5 / (7.0 * r)).abs() < 1e-11);
    }

    #[test]
    fn rejects_receding_and_bad_params() {
        let s = Sphere::new(0.02, crate::contact::Material::preset("nylon").unwrap()).unwrap();
        let b1 = Body::homogeneous(Vector3::new(0.0, 0.01, 0.0), &s)
            .moving(Vector3::new(0.0, 1.0, 0.0), Vector3::zeros());
        let pre = State::on_wall(b1, Vector3::zeros());
        let p = WaltonParams::PAPER_NYLON;
        assert!(collide(&pre, &p).is_err());
        assert!(WaltonParams::new(1.1, 0.1, 0.5).is_err());
        assert!(WaltonParams::new(0.9, -0.1, 0.5).is_err());
        assert!(WaltonParams::new(0.9, 0.1, f64::NAN).is_err());
        let coincident = State::on_wall(b1, b1.position_m);
        assert!(coincident.contact().is_err());
    }

    /// Known answer: on the sliding branch Eq. (6) makes the impulse ratio |Delta P_t|/|Delta P_n|
    /// exactly mu_0, whatever the masses. Two spheres of one material, one at rest, hit off
    /// centre; collided and measured back at the paper's density and at 1e300 kg/m^3 (where the
    /// impulse's squared length overflowed, so `collide` returned inf and NaN velocities, and the
    /// weights 1/m^2 of the measured impulse's mean underflowed to 0: a NaN ratio).
    #[test]
    fn measure_gives_mu0_on_the_sliding_branch_at_any_mass() {
        for density in [1140.0, 1e300] {
            let m = crate::contact::Material::new(3.5e8, 0.3, density).unwrap();
            let s = Sphere::new(0.02, m).unwrap();
            let b1 = Body::homogeneous(Vector3::new(0.0, 0.0, 0.0), &s)
                .moving(Vector3::new(2.0, 0.0, 0.0), Vector3::zeros());
            let b2 = Body::homogeneous(Vector3::new(0.016, 0.012, 0.0), &s);
            let pre = State::pair(b1, b2);
            let p = WaltonParams::new(0.9, 0.1, 0.9).unwrap();
            let post = collide(&pre, &p).unwrap();
            assert_eq!(post.kind, ContactKind::Sliding);
            let got = measure(&pre, &post.state).unwrap();
            // Tolerance 1e-13: the velocities are rounded once per kick and differenced back.
            assert!(
                (got.impulse_ratio - 0.1).abs() < 1e-13,
                "density {density}: {}",
                got.impulse_ratio
            );
            assert!((got.e - 0.9).abs() < 1e-13, "{}", got.e);
        }
    }

    /// The inverse operator measures only separating surfaces: a sphere that drops onto a wall at
    /// 2 m/s and leaves at rest has e = 0 exactly; one still falling afterwards (at 1 m/s: e = -0.5
    /// by the formula) is an error, not a coefficient of restitution.
    #[test]
    fn measure_refuses_surfaces_still_approaching() {
        let s = Sphere::new(0.02, crate::contact::Material::preset("nylon").unwrap()).unwrap();
        let at = Vector3::new(0.0, 0.01, 0.0);
        let falling = |vy: f64| {
            State::on_wall(
                Body::homogeneous(at, &s).moving(Vector3::new(0.0, vy, 0.0), Vector3::zeros()),
                Vector3::zeros(),
            )
        };
        let pre = falling(-2.0);
        assert_eq!(measure(&pre, &falling(0.0)).unwrap().e, 0.0);
        assert_eq!(measure(&pre, &falling(1.0)).unwrap().e, 0.5);
        let err = measure(&pre, &falling(-1.0)).unwrap_err().to_string();
        assert!(
            err.contains("after the collision") && err.contains("e >= 0"),
            "{err}"
        );
    }
}
