//! Walton's collision operator (Eqs. 1-7) and its inverse (the fit and the command:
//! tests/walton_fit.rs).

use nalgebra::Vector3;
use proptest::prelude::*;
use restitution::contact::{Material, Sphere};
use restitution::models::walton::{
    Body, ContactKind, State, Target, WaltonParams, collide, measure,
};

const EPS: f64 = f64::EPSILON;

/// A homogeneous sphere of diameter `d_m` and density `rho` (the elastic constants do not enter
/// Walton's operator).
fn sphere(d_m: f64, rho: f64) -> Sphere {
    Sphere::new(d_m, Material::new(1e9, 0.3, rho).unwrap()).unwrap()
}

// ---------------------------------------------------------------------------------------------
// Random states.

fn vec3(r: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

fn unit() -> impl Strategy<Value = Vector3<f64>> {
    vec3(1.0)
        .prop_filter("not too short to normalise", |v| v.norm() > 0.1)
        .prop_map(|v| v.normalize())
}

/// A body with diameter 1-50 mm, density 500-8000 kg/m^3, its own K in [0.1, 2/3], speeds up to
/// 5 m/s per component and spins up to 300 rad/s.
fn body() -> impl Strategy<Value = Body> {
    (
        1e-3..0.05f64,
        500.0..8000.0f64,
        0.1..(2.0 / 3.0),
        vec3(5.0),
        vec3(300.0),
    )
        .prop_map(|(d, rho, k, v, w)| {
            let mut b = Body::homogeneous(Vector3::zeros(), &sphere(d, rho)).moving(v, w);
            b.inertia_k = k;
            b
        })
}

/// Makes the surfaces approach: reversing every velocity and spin reverses v_c.
fn approaching(mut s: State) -> State {
    let f = s.contact().unwrap();
    if f.v_n_signed_m_s >= 0.0 {
        s.sphere.velocity_m_s = -s.sphere.velocity_m_s;
        s.sphere.spin_rad_s = -s.sphere.spin_rad_s;
        if let Target::Sphere(b) = &mut s.target {
            b.velocity_m_s = -b.velocity_m_s;
            b.spin_rad_s = -b.spin_rad_s;
        }
    }
    s
}

/// Two touching spheres anywhere within 1 m of the origin.
fn pair_state() -> impl Strategy<Value = State> {
    (body(), body(), unit(), vec3(1.0)).prop_map(|(mut b1, mut b2, n, c)| {
        b1.position_m = c + 0.5 * b1.d_m * n;
        b2.position_m = c - 0.5 * b2.d_m * n;
        approaching(State::pair(b1, b2))
    })
}

/// A sphere touching a wall whose contact point is within 1 m of the origin.
fn wall_state() -> impl Strategy<Value = State> {
    (body(), unit(), vec3(1.0)).prop_map(|(mut b, n, c)| {
        b.position_m = c + 0.5 * b.d_m * n;
        approaching(State::on_wall(b, c))
    })
}

/// (e, mu0, beta0) over the whole domain where the operator must not create energy.
fn params() -> impl Strategy<Value = WaltonParams> {
    (0.0..=1.0f64, 0.0..2.0f64, -1.0..=1.0f64)
        .prop_map(|(e, mu0, beta0)| WaltonParams::new(e, mu0, beta0).unwrap())
}

fn contact_point(s: &State) -> Vector3<f64> {
    let n = s.contact().unwrap().normal;
    match s.target {
        Target::Sphere(b) => b.position_m + 0.5 * b.d_m * n,
        Target::Wall { contact_point_m } => contact_point_m,
    }
}

fn bodies(s: &State) -> Vec<Body> {
    match s.target {
        Target::Sphere(b) => vec![s.sphere, b],
        Target::Wall { .. } => vec![s.sphere],
    }
}

/// The scale of the momenta and angular momenta in a state and its impulse, for rounding bounds.
fn momentum_scale(s: &State, impulse: f64) -> f64 {
    bodies(s)
        .iter()
        .map(|b| b.mass_kg * b.velocity_m_s.norm())
        .sum::<f64>()
        + impulse
}

fn angular_scale(s: &State, about: &Vector3<f64>, impulse: f64) -> f64 {
    bodies(s)
        .iter()
        .map(|b| {
            // r - about carries the absolute rounding of the positions themselves.
            let lever = (b.position_m - about).norm() + b.position_m.norm() + about.norm();
            b.mass_kg * lever * b.velocity_m_s.norm()
                + b.inertia_kg_m2() * b.spin_rad_s.norm()
                + impulse * (lever + b.d_m)
        })
        .sum()
}

fn energy_scale(s: &State) -> f64 {
    s.kinetic_energy_j()
}

/// Rounding bound for a quantity computed from numbers of size `scale` by a few dozen
/// floating-point operations: 64 ulp of the scale.
fn rounding(scale: f64) -> f64 {
    64.0 * EPS * scale
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn linear_momentum_is_conserved(pre in pair_state(), p in params()) {
        let post = collide(&pre, &p).unwrap();
        let scale = momentum_scale(&pre, post.impulse_n_s.norm());
        let change = (post.state.momentum() - pre.momentum()).norm();
        prop_assert!(change <= rounding(scale), "{change} > {}", rounding(scale));
    }

    #[test]
    fn angular_momentum_about_the_contact_point_is_conserved(
        pre in pair_state(), p in params(), elsewhere in vec3(1.0)
    ) {
        let post = collide(&pre, &p).unwrap();
        let dp = post.impulse_n_s.norm();
        // About the contact point and, since the impulses are equal and opposite and act on the
        // line of centres' contact point, about any other point too.
        for about in [contact_point(&pre), elsewhere] {
            let change = (post.state.angular_momentum_about(&about)
                - pre.angular_momentum_about(&about)).norm();
            let tol = rounding(angular_scale(&pre, &about, dp));
            prop_assert!(change <= tol, "{change} > {tol}");
        }
    }

    #[test]
    fn wall_conserves_angular_momentum_about_its_contact_point(pre in wall_state(), p in params()) {
        let post = collide(&pre, &p).unwrap();
        let c = contact_point(&pre);
        let change = (post.state.angular_momentum_about(&c) - pre.angular_momentum_about(&c)).norm();
        let tol = rounding(angular_scale(&pre, &c, post.impulse_n_s.norm()));
        prop_assert!(change <= tol, "{change} > {tol}");
    }

    /// KE' <= KE for 0 <= e <= 1, beta <= beta0 <= 1, and the loss equals docs/physics.md §4's
    /// (1/2) [m_red (1 - e^2) v_n^2 + m_t (1 - beta^2) |v_s|^2].
    #[test]
    fn kinetic_energy_never_increases(
        pre in prop_oneof![pair_state(), wall_state()], p in params()
    ) {
        let post = collide(&pre, &p).unwrap();
        let (k0, k1) = (pre.kinetic_energy_j(), post.state.kinetic_energy_j());
        let tol = rounding(energy_scale(&pre));
        prop_assert!(k1 <= k0 + tol, "energy grew: {k0} -> {k1}");
        prop_assert!(post.beta <= p.beta0 && post.beta >= -1.0);
        let f = pre.contact().unwrap();
        let loss = 0.5 * (f.m_red_kg * (1.0 - p.e * p.e) * f.v_n_signed_m_s.powi(2)
            + f.m_t_kg * (1.0 - post.beta * post.beta) * f.v_s_m_s.norm_squared());
        prop_assert!(((k0 - k1) - loss).abs() <= tol, "loss {} vs formula {loss}", k0 - k1);
    }

    /// measure(pre, collide(pre)) gives back e, beta, psi, and mu0 as the sliding impulse ratio.
    #[test]
    fn operator_then_inverse_recovers_e_and_beta(
        pre in prop_oneof![pair_state(), wall_state()], p in params()
    ) {
        let post = collide(&pre, &p).unwrap();
        let m = measure(&pre, &post.state).unwrap();
        let f = pre.contact().unwrap();
        // e and beta are ratios of a post-collision component to a pre-collision one; the
        // numerator carries rounding of the order of the largest velocity in the state, so the
        // relative error grows as |v_n| (for e) or |v_s| (for beta) shrink against it.
        let v_scale: f64 = bodies(&pre).iter()
            .map(|b| b.velocity_m_s.norm() + b.d_m * b.spin_rad_s.norm())
            .sum::<f64>() * (1.0 + p.e);
        let tol_e = rounding(v_scale) / f.v_n_signed_m_s.abs();
        prop_assert!((m.e - p.e).abs() <= tol_e, "e {} vs {}", m.e, p.e);
        let vs = f.v_s_m_s.norm();
        if let Some(beta) = m.beta {
            let tol_b = rounding(v_scale) / vs;
            prop_assert!((beta - post.beta).abs() <= tol_b, "beta {beta} vs {}", post.beta);
            prop_assert!((m.psi - post.psi).abs() <= 1e-12 * post.psi.max(1.0));
            if post.kind == ContactKind::Sliding && p.mu0 > 0.0 {
                // Eq. (6): |Delta P_t| = mu0 |Delta P_n|.
                prop_assert!((m.impulse_ratio - p.mu0).abs() <= 1e-9 * p.mu0.max(1.0),
                    "ratio {} vs {}", m.impulse_ratio, p.mu0);
            }
        }
    }

    /// The sliding branch reproduces Eq. (7) for equal K (the paper's case):
    /// beta = -1 - mu0 (1 + 1/K)(1 + e) v_n/v_s, with v_n = v_c . n < 0 and v_s = |v_s|.
    #[test]
    fn sliding_branch_is_equation_7(
        pre in pair_state(), k in 0.1..(2.0 / 3.0), e in 0.0..=1.0f64, mu0 in 0.0..1.0f64
    ) {
        let mut pre = pre;
        pre.sphere.inertia_k = k;
        if let Target::Sphere(b) = &mut pre.target { b.inertia_k = k; }
        // beta0 = 1 is as permissive as energy allows; keep the cases that slide.
        let p = WaltonParams::new(e, mu0, 1.0).unwrap();
        let post = collide(&pre, &p).unwrap();
        let f = pre.contact().unwrap();
        let eq7 = -1.0 - mu0 * (1.0 + 1.0 / k) * (1.0 + e) * f.v_n_signed_m_s / f.v_s_m_s.norm();
        if eq7 < 1.0 {
            prop_assert_eq!(post.kind, ContactKind::Sliding);
            // Same formula evaluated in a different order: a few ulp of the terms' size.
            prop_assert!((post.beta - eq7).abs() <= 1e-12 * (1.0 + eq7.abs()), "{} vs {eq7}", post.beta);
            // and the post-collision tangential contact velocity is -beta v_s (Eq. 5).
            let g = post.state.contact().unwrap();
            let target = -eq7 * f.v_s_m_s;
            // n is the same (positions unchanged); tolerance from the velocity scale.
            let scale = f.v_c_m_s.norm() + g.v_c_m_s.norm();
            prop_assert!((g.v_s_m_s - target).norm() <= 1e-12 * scale.max(1e-300));
        } else {
            prop_assert_eq!(post.kind, ContactKind::Rolling);
        }
    }
}

#[test]
fn rolling_branch_returns_beta0() {
    let d = 0.0254;
    let b1 = Body::homogeneous(Vector3::new(0.0, 0.0, 0.0), &sphere(d, 1140.0))
        .moving(Vector3::new(-2.0, 0.3, 0.0), Vector3::new(0.0, 0.0, 5.0));
    let b2 = Body::homogeneous(Vector3::new(-d, 0.0, 0.0), &sphere(d, 1140.0))
        .moving(Vector3::new(2.0, -0.2, 0.0), Vector3::zeros());
    let pre = State::pair(b1, b2);
    let post = collide(&pre, &WaltonParams::PAPER_NYLON).unwrap();
    // psi = 4 / |0.5 - 0.0127 * 5| = 9.2 > psi* = 1.24: rolling.
    assert_eq!(post.kind, ContactKind::Rolling);
    assert_eq!(post.beta, 0.5);
    let m = measure(&pre, &post.state).unwrap();
    // Rounding of O(1) velocities over |v_s| ~ 0.44.
    assert!((m.beta.unwrap() - 0.5).abs() < 1e-14);
    assert!((m.e - 0.97).abs() < 1e-15);
    // The impulse ratio on the rolling branch is below mu0 (the friction limit is not reached).
    assert!(m.impulse_ratio < 0.175);
}

#[test]
fn head_on_collision_has_no_beta() {
    let d = 0.0254;
    let b1 = Body::homogeneous(Vector3::zeros(), &sphere(d, 1140.0))
        .moving(Vector3::new(-1.0, 0.0, 0.0), Vector3::zeros());
    let b2 = Body::homogeneous(Vector3::new(-d, 0.0, 0.0), &sphere(d, 1140.0))
        .moving(Vector3::new(1.0, 0.0, 0.0), Vector3::zeros());
    let pre = State::pair(b1, b2);
    let post = collide(&pre, &WaltonParams::PAPER_NYLON).unwrap();
    assert_eq!(post.kind, ContactKind::Rolling);
    assert!(post.psi.is_infinite());
    let m = measure(&pre, &post.state).unwrap();
    assert_eq!(m.beta, None);
    assert!((m.e - 0.97).abs() < 1e-15);
    // Velocities: 1 -> -0.97 along the line of centres, exactly symmetric.
    assert!((post.state.sphere.velocity_m_s.x - 0.97).abs() < 1e-15);
}
