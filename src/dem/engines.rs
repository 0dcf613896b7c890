//! Engine parameters from the toolkit's contact quantities (docs/physics.md §9): numbers only;
//! `crate::data::export` writes them into input files.
//!
//! **LAMMPS `pair_style granular`** (as of the 29 Sep 2021 release, read in its source
//! `pair_granular.cpp`): the normal force is F = k_n delta a + damp * D * delta', a = sqrt(R delta),
//! with k_n = (4/3) E* for `hertz/material`, so the elastic part is K delta^(3/2) with the
//! toolkit's K = (4/3) E* R~^(1/2) ([`Contact::hertz_k`]). `damping viscoelastic` has
//! D = m_eff a, so the dashpot is damp m_eff R~^(1/2) delta^(1/2) delta': the paper's
//! C delta^(1/2) delta' (Eq. 9) when damp = C/(m_red R~^(1/2)) = 4 eta/m_red. One eta thus gives a
//! different damp for every pair of sizes: one atom type per size, with every cross pair written
//! out, represents it exactly; a continuous size distribution cannot. `damping tsuji` has
//! D = sqrt(m_eff k_n a) and damp = alpha(e) from a sixth-degree polynomial in the requested e
//! ([`lammps_tsuji_alpha`]); its dashpot is alpha sqrt(m_red K) delta^(1/4) delta', the q = 1/4 case
//! of [`super::damped`]. `limit_damping` drops any attractive normal force: the force rule of
//! [`ContactEnd`](crate::models::viscoelastic::ContactEnd); without it the contact ends when the
//! overlap does (the paper's rule).

use crate::contact::{Contact, Material};
use crate::error::{Error, Result};

/// LAMMPS's `damp` for `damping viscoelastic`: 4 eta/m_red, in 1/(m s) (module note). Uses the
/// toolkit's damping coefficient C = 4 eta R~^(1/2) of Eq. 9.
pub fn lammps_viscoelastic_damp(contact: &Contact, eta: f64) -> f64 {
    contact.damping_c(eta) / (contact.m_red_kg * contact.r_eff_m.sqrt())
}

/// The (Young's modulus, Poisson ratio) to give LAMMPS's `hertz/material` for a pair of spheres,
/// which it turns into E* = E/(2 (1 - nu^2)) as if both spheres were of the one material given.
/// Same material: the material's own values. Two materials: the first's Poisson ratio and the
/// modulus that reproduces the true E* (so the normal force is right; the Mindlin stiffness is set
/// separately by [`mindlin_kt`]).
pub fn lammps_pair_material(m1: &Material, m2: &Material, e_star_pa: f64) -> (f64, f64) {
    if m1 == m2 {
        (m1.youngs_pa, m1.poisson)
    } else {
        let nu = m1.poisson;
        (2.0 * (1.0 - nu * nu) * e_star_pa, nu)
    }
}

/// The Young's modulus to give LAMMPS 29 Sep 2021's `fix wall/gran ... hertz/material E damp nu`
/// for a wall contact with effective modulus `e_star_pa`. That release forms E* = E/(2 (1 - nu))
/// for walls (not E/(2 (1 - nu^2)) as for pairs: given the material's own modulus, a 6.35 mm nylon
/// sphere at 2 m/s rebounds with e = 0.8993 instead of 0.8833, tests/lammps.rs), so the modulus is
/// scaled to give the true E*. tests/lammps.rs checks the result.
pub fn lammps_wall_youngs(e_star_pa: f64, poisson: f64) -> f64 {
    2.0 * (1.0 - poisson) * e_star_pa
}

/// The Mindlin tangential stiffness coefficient k_t = 8 G* (LAMMPS multiplies it by a), with
/// 1/G* = (2 - nu_1)/G_1 + (2 - nu_2)/G_2 and G = Y/(2 (1 + nu)) (Mindlin 1949). Given explicitly
/// so that walls and mixed materials get it right (LAMMPS's NULL derives it from the one
/// modulus given).
pub fn mindlin_kt(m1: &Material, m2: &Material) -> f64 {
    let inv = |m: &Material| (2.0 - m.poisson) * 2.0 * (1.0 + m.poisson) / m.youngs_pa;
    8.0 / (inv(m1) + inv(m2))
}

/// The Hertz contact time scale of a pair at impact speed v: T = (m_red/K)^(2/5) v^(-1/5)
/// ([`Contact::time_scale_s`]); the elastic contact lasts 3.218 T.
pub fn hertz_contact_time_s(contact: &Contact, v_m_s: f64) -> f64 {
    HERTZ_TAU * contact.time_scale_s(v_m_s)
}

/// Duration of an undamped Hertz contact in units of T (docs/physics.md §2).
pub const HERTZ_TAU: f64 = 3.2180654597190430845;

/// The coefficients of LAMMPS's `damping tsuji` polynomial alpha(e) = sum c_k e^k (its source,
/// `pair_granular.cpp`, 29 Sep 2021).
pub const LAMMPS_TSUJI_POLY: [f64; 7] = [1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218];

/// alpha that LAMMPS's `damping tsuji` uses when asked for restitution `cor` (its polynomial).
pub fn lammps_tsuji_alpha(cor: f64) -> f64 {
    LAMMPS_TSUJI_POLY
        .iter()
        .rev()
        .fold(0.0, |acc, &c| acc * cor + c)
}

/// The `cor` to give LAMMPS's `damping tsuji` so that its polynomial yields `alpha`: the inverse
/// of [`lammps_tsuji_alpha`] on [0, 1], where the polynomial falls strictly from 1.2728 to 3e-4
/// (checked on 1e5 points in the tests). `None` outside that interval: such an alpha cannot be
/// asked for through the polynomial. Bisection to 1e-15 (at most 100 steps).
pub fn lammps_tsuji_cor_for_alpha(alpha: f64) -> Option<f64> {
    let (hi_alpha, lo_alpha) = (lammps_tsuji_alpha(0.0), lammps_tsuji_alpha(1.0));
    if !(alpha.is_finite() && alpha >= lo_alpha && alpha <= hi_alpha) {
        return None;
    }
    let (mut a, mut b) = (0.0f64, 1.0f64);
    for _ in 0..100 {
        if b - a <= 1e-15 {
            break;
        }
        let m = 0.5 * (a + b);
        if lammps_tsuji_alpha(m) > alpha {
            a = m;
        } else {
            b = m;
        }
    }
    Some(0.5 * (a + b))
}

/// LIGGGHTS's (and EDEM's Hertz-Mindlin) damping: F_d = -2 sqrt(5/6) beta sqrt(S_n m*) v_n with
/// S_n = 2 Y* sqrt(R* delta) and beta = ln e / sqrt(ln^2 e + pi^2). With S_n = (3/2) K delta^(1/2)
/// this is the Tsuji dashpot with alpha = sqrt(5) (-ln e)/sqrt(ln^2 e + pi^2).
pub fn liggghts_alpha(e: f64) -> f64 {
    let l = e.ln();
    5f64.sqrt() * (-l) / (l * l + std::f64::consts::PI.powi(2)).sqrt()
}

/// The inverse of [`liggghts_alpha`]: e = exp(-pi alpha / sqrt(5 - alpha^2)) for
/// 0 <= alpha < sqrt 5 (the formula cannot ask for more damping).
pub fn liggghts_e_for_alpha(alpha: f64) -> Option<f64> {
    if !(alpha.is_finite() && alpha >= 0.0 && alpha * alpha < 5.0) {
        return None;
    }
    Some((-std::f64::consts::PI * alpha / (5.0 - alpha * alpha).sqrt()).exp())
}

/// Checks 0 < e <= 1 for the constant-e engines.
pub fn check_e(e: f64) -> Result<f64> {
    if e.is_finite() && e > 0.0 && e <= 1.0 {
        Ok(e)
    } else {
        Err(Error::InvalidParameter {
            name: "restitution e",
            value: e,
            expected: "a number in (0, 1]",
        })
    }
}
