//! e of a Hertz contact with a power-law dashpot, the normal force of DEM engines (docs/physics.md §9).
//!
//! **Solves** x'' = -x^(3/2) - alpha x^q x', x(0) = 0, x'(0) = 1, and returns e = -x'(end) for either
//! end-of-contact rule. Two dashpots matter:
//! - q = 1/2 ([`Dashpot::Viscoelastic`]): the paper's Eqs. 9-10 with alpha = kappa (docs/physics.md
//!   §2), which is LAMMPS's `damping viscoelastic`; e depends on the impact speed through kappa.
//! - q = 1/4 ([`Dashpot::Tsuji`]): the damping force alpha sqrt(m_red K) delta^(1/4) delta' of Tsuji
//!   et al., Powder Technol. 71, 239 (1992), used by LAMMPS's `damping tsuji` and by the
//!   Hertz-Mindlin models of LIGGGHTS, EDEM and Yade. Its dimensionless form has no speed in it,
//!   so e depends on alpha alone: a constant e, which is what those engines are built for.
//!
//! Scaling (q = 1/4): with T = (m_red/K)^(1/2) L^(-1/4) and L = V T, the damping term over the
//! Hertz term is alpha exactly, whatever V; so alpha is the engines' dimensionless coefficient.
//!
//! **Method**: the right side has x^q, so the solution is not analytic in t where x = 0 (t^(1+q)
//! terms) and Runge-Kutta in t loses its order there. As in the viscoelastic module, the overlap is
//! replaced by s = x^(1/4) as the independent variable while the spheres approach (until x' = 1/2)
//! and separate (from the turning phase down to s = 0), where
//! dp/ds = -4 s^9/p - 4 alpha s^(4q+3), dt/ds = 4 s^3/p, dJ/ds = 4 s^(4q+3) p
//! are analytic (p = x' is bounded away from 0 there), and time is used around the turning point.
//! Each phase is integrated by classical fourth-order Runge-Kutta at a fixed step, switching at
//! accepted steps (no error from the switch). The force-rule end x^(3/2) + alpha x^q p = 0 is
//! located inside its step by bisection on the length of a partial RK4 step. J = int x^q x'^2 dt
//! gives 1 - e from the energy balance e^2 = 1 - 2 alpha J - (4/5) x_end^(5/2), which keeps the
//! relative accuracy of 1 - e when alpha is small.
//!
//! **Closed form for Tsuji's dashpot, overlap rule** (derived here; docs/physics.md §9): with the
//! time d tau = x^(1/4) dt and y = x^(5/4) the equation becomes y'' + alpha y' + (5/4) y = 0, and
//! dy/dtau = (5/4) dx/dt, so the overlap rule ends after half a damped period and
//! e = exp(-pi alpha / sqrt(5 - alpha^2)) for alpha < sqrt 5: exactly the formula LIGGGHTS and
//! EDEM use. The solver does not use it; tests/export_dem.rs checks the solver against it. The
//! force rule has no such form.
//!
//! This is deliberately a separate implementation from [`crate::models::viscoelastic`]: with
//! q = 1/2 it must reproduce the master curve, which tests both (tests/export_dem.rs).
//!
//! **Needs** 0 <= alpha <= [`ALPHA_MAX`], finite (below sqrt 5 for Tsuji's overlap rule), and
//! leaves e >= [`E_MIN`] / 2 (docs/physics.md §9.4). **Known answers**: alpha = 0 gives e = 1
//! and the Hertz contact time 3.2180654597190430845; for small alpha the dissipated work on the elastic
//! trajectory gives 1 - e = alpha J_0 with J_0 = 2 int_0^x_max x^q p dx, which is
//! 0.8 sqrt(5/4) B(1/2, 3/2) = pi/sqrt(5) for q = 1/4 and C1 = 1.1534488580952888 for q = 1/2.

use crate::error::{Error, IntegrationFailure, Num, Result};
use crate::models::viscoelastic::ContactEnd;

/// The exponent q of the dashpot alpha x^q x'.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr)]
#[strum(serialize_all = "lowercase")]
pub enum Dashpot {
    /// q = 1/2: the viscoelastic model of Eqs. 9-10 (alpha = kappa).
    Viscoelastic,
    /// q = 1/4: Tsuji et al. (1992), velocity-independent e.
    Tsuji,
}

impl Dashpot {
    /// 4q, the power of s = x^(1/4) that x^q becomes.
    fn four_q(self) -> i32 {
        match self {
            Dashpot::Viscoelastic => 2,
            Dashpot::Tsuji => 1,
        }
    }

    /// x^q for x >= 0.
    fn x_pow_q(self, x: f64) -> f64 {
        match self {
            Dashpot::Viscoelastic => x.sqrt(),
            Dashpot::Tsuji => x.sqrt().sqrt(),
        }
    }

    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Largest alpha accepted: the force rule's e is then below 1e-3 (1e-3 at alpha = 35, q = 1/4)
/// and the slow unloading tail needs ever more steps; no DEM parameter of interest lies beyond.
/// Tsuji's dashpot under the overlap rule stops earlier, at [`TSUJI_OVERLAP_CRITICAL`].
pub const ALPHA_MAX: f64 = 50.0;

/// Tsuji's alpha from which the overlap rule has no rebound: y = x^(5/4) obeys
/// y'' + alpha y' + (5/4) y = 0 (module note), critically damped at alpha = sqrt 5, and an
/// overdamped y never returns to 0, so the spheres never part (e = 0).
pub const TSUJI_OVERLAP_CRITICAL: f64 = 2.23606797749979;

/// The smallest e the solver gives or inverts. Its e has an absolute error of about 1e-14 at
/// the default steps (measured against the closed form of Tsuji's overlap rule: 2e-15 at
/// e = 1e-10), so below 1e-6 it would carry more than 1e-8 of relative error, and Tsuji's
/// overlap-rule alpha comes within 3% of critical damping, where e changes faster than a
/// bisection in alpha resolves (e = 1e-20 had been inverted to an alpha that gives 2.8e-16).
/// No DEM scene needs such an e: it is a sticking contact.
pub const E_MIN: f64 = 1e-6;

/// Runge-Kutta steps per phase by default. Measured against the master curve (q = 1/2, kappa up
/// to 10, both rules): |error in e| <= 3e-13 at 2000 steps (tests/export_dem.rs).
pub const DEFAULT_STEPS: usize = 2000;

/// e and 1 - e (with its own relative accuracy) of one collision, and the contact duration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedRebound {
    pub e: f64,
    pub one_minus_e: f64,
    /// Contact duration in units of T (see the module note).
    pub tau_contact: f64,
    /// Overlap at the end of contact in units of L = V T (0 for the overlap rule).
    pub x_end: f64,
}

type Y = [f64; 3];

fn axpy(y: &Y, a: f64, k: &Y) -> Y {
    [y[0] + a * k[0], y[1] + a * k[1], y[2] + a * k[2]]
}

/// One classical RK4 step of y' = f(u, y) from u by h.
fn rk4(f: &impl Fn(f64, &Y) -> Y, u: f64, y: &Y, h: f64) -> Y {
    let k1 = f(u, y);
    let k2 = f(u + 0.5 * h, &axpy(y, 0.5 * h, &k1));
    let k3 = f(u + 0.5 * h, &axpy(y, 0.5 * h, &k2));
    let k4 = f(u + h, &axpy(y, h, &k3));
    let mut out = *y;
    for i in 0..3 {
        out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    out
}

fn finite(y: &Y) -> bool {
    y.iter().all(|v| v.is_finite())
}

fn fail(alpha: f64, kind: IntegrationFailure, reason: impl Into<String>) -> Error {
    Error::Integration {
        method: "rk4 (damped Hertz)",
        kappa: alpha,
        kind,
        reason: reason.into(),
    }
}

/// Bisection for the fraction theta in (0, 1] of a step at which `g(theta, step(theta))` reaches
/// 0, given g > 0 at theta = 0 and g <= 0 at theta = 1. 60 halvings take theta to 1e-18 of the
/// step, below rounding.
fn locate(step: impl Fn(f64) -> Y, g: impl Fn(f64, &Y) -> f64) -> (f64, Y) {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let mut y_hi = step(1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let y = step(mid);
        if g(mid, &y) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
            y_hi = y;
        }
    }
    (hi, y_hi)
}

/// e of x'' = -x^(3/2) - alpha x^q x' (see the module note) with `steps` RK4 steps per phase;
/// an error where e would be below half of [`E_MIN`] (the half: the alpha that
/// [`alpha_for_e`] gives for E_MIN itself lands a bisection's width either side of it).
pub fn rebound(
    alpha: f64,
    dashpot: Dashpot,
    rule: ContactEnd,
    steps: usize,
) -> Result<DampedRebound> {
    let r = solve(alpha, dashpot, rule, steps)?;
    if r.e < 0.5 * E_MIN {
        return Err(Error::InvalidParameter {
            name: "dimensionless damping alpha",
            value: alpha,
            expected: "one that leaves e >= 5e-7 (the solver's resolution; see damped::E_MIN)",
        });
    }
    Ok(r)
}

/// [`rebound`] without the floor on e: [`alpha_for_e`]'s bisection passes below it.
fn solve(alpha: f64, dashpot: Dashpot, rule: ContactEnd, steps: usize) -> Result<DampedRebound> {
    if !(alpha.is_finite() && (0.0..=ALPHA_MAX).contains(&alpha)) {
        return Err(Error::InvalidParameter {
            name: "dimensionless damping alpha",
            value: alpha,
            expected: "a number in [0, 50]",
        });
    }
    if dashpot == Dashpot::Tsuji && rule == ContactEnd::Overlap && alpha >= TSUJI_OVERLAP_CRITICAL {
        return Err(Error::InvalidParameter {
            name: "dimensionless damping alpha (Tsuji's dashpot, overlap rule)",
            value: alpha,
            expected: "below sqrt 5 = 2.2360679...: from there on the contact is overdamped and \
                       the spheres never part (e = 0)",
        });
    }
    let n = steps.max(16);
    let fq = dashpot.four_q();
    // In s = x^(1/4): y = (p, t, J).
    let f_s = |s: f64, y: &Y| -> Y {
        let p = y[0];
        let s3 = s * s * s;
        let s_q3 = s3 * s.powi(fq);
        [
            -4.0 * s3 * s3 * s3 / p - 4.0 * alpha * s_q3,
            4.0 * s3 / p,
            4.0 * s_q3 * p,
        ]
    };
    // In t: y = (x, p, J).
    let f_t = |_t: f64, y: &Y| -> Y {
        let x = y[0].max(0.0);
        let xq = dashpot.x_pow_q(x);
        [y[1], -x * x.sqrt() - alpha * xq * y[1], xq * y[1] * y[1]]
    };
    // Force-rule end: x^(3/2) + alpha x^q p = 0, divided by x^q (> 0): x^(3/2 - q) + alpha p.
    let g_t = |y: &Y| {
        let x = y[0].max(0.0);
        x * x.sqrt() / dashpot.x_pow_q(x) + alpha * y[1]
    };
    let g_s = |s: f64, y: &Y| s.powi(6 - fq) + alpha * y[0];

    // Loading in s from 0 until p <= 1/2 (p falls monotonically here). x never exceeds the
    // undamped maximum (5/4)^(2/5), so s <= 1.0226; a step that would take p below 1/4 (or to a
    // non-finite value near p = 0) is halved, since the switch only needs some p in (1/4, 1/2].
    let mut h = 1.05 / n as f64;
    let (mut s, mut y) = (0.0, [1.0, 0.0, 0.0]);
    let mut count = 0usize;
    loop {
        count += 1;
        if count > 4 * n + 200 {
            return Err(fail(
                alpha,
                IntegrationFailure::PhaseIncomplete,
                "loading phase did not slow down as it must",
            ));
        }
        let trial = rk4(&f_s, s, &y, h);
        if !finite(&trial) || trial[0] < 0.25 {
            h *= 0.5;
            if h < 1e-300 {
                return Err(fail(
                    alpha,
                    IntegrationFailure::StepSizeUnderflow,
                    "loading step size underflow",
                ));
            }
            continue;
        }
        s += h;
        y = trial;
        if y[0] <= 0.5 {
            break;
        }
    }
    let x_switch = s.powi(4);

    // Around the turning point, in t, until the overlap falls back below x_switch.
    let h_t = 3.3 / n as f64;
    let (mut t, mut yt) = (y[1], [x_switch, y[0], y[2]]);
    let mut end: Option<(f64, Y)> = None; // (time, (x, p, J)) at a force-rule end
    let max_t_steps = 400 * n;
    let mut k = 0usize;
    loop {
        k += 1;
        if k > max_t_steps {
            return Err(fail(
                alpha,
                IntegrationFailure::PhaseIncomplete,
                format!(
                    "no rebound within t = {} (dimensionless)",
                    h_t * max_t_steps as f64
                ),
            ));
        }
        let next = rk4(&f_t, t, &yt, h_t);
        if !finite(&next) {
            return Err(fail(
                alpha,
                IntegrationFailure::NonFinite,
                format!("non-finite state at t = {}", Num(t)),
            ));
        }
        if rule == ContactEnd::Force && next[1] < 0.0 && g_t(&next) <= 0.0 {
            let (theta, y_end) = locate(|th| rk4(&f_t, t, &yt, th * h_t), |_, yy| g_t(yy));
            end = Some((t + theta * h_t, y_end));
            break;
        }
        t += h_t;
        yt = next;
        if yt[1] < 0.0 && yt[0] <= x_switch {
            break;
        }
    }

    let (x_end, p_end, j_end, tau) = match end {
        Some((te, ye)) => (ye[0], ye[1], ye[2], te),
        None => {
            // Unloading in s from s_c down to 0 in n equal steps.
            let s_c = yt[0].max(0.0).sqrt().sqrt();
            let h_c = -s_c / n as f64;
            let (mut s, mut y) = (s_c, [yt[1], t, yt[2]]);
            let mut found = None;
            for i in 0..n {
                let next = rk4(&f_s, s, &y, h_c);
                if !finite(&next) || next[0] >= 0.0 {
                    return Err(fail(
                        alpha,
                        IntegrationFailure::Unphysical,
                        format!(
                            "unphysical unloading state at s = {}: p = {}",
                            Num(s),
                            Num(next[0])
                        ),
                    ));
                }
                let s_next = if i + 1 == n { 0.0 } else { s + h_c };
                if rule == ContactEnd::Force && alpha > 0.0 && g_s(s_next, &next) <= 0.0 {
                    let (s0, y0) = (s, y);
                    let (theta, ye) = locate(
                        |th| rk4(&f_s, s0, &y0, th * h_c),
                        |th, yy| g_s(s0 + th * h_c, yy),
                    );
                    let s_e = s0 + theta * h_c;
                    found = Some((s_e.powi(4), ye[0], ye[2], ye[1]));
                    break;
                }
                s = s_next;
                y = next;
            }
            match found {
                Some(f) => f,
                None => (0.0, y[0], y[2], y[1]),
            }
        }
    };
    let e = -p_end;
    let one_minus_e2 = 2.0 * alpha * j_end + 0.8 * x_end.powf(2.5);
    let e_energy = (1.0 - one_minus_e2).max(0.0).sqrt();
    // e from the final speed and e from the energy balance agree to about the truncation error
    // (1e-12 at the default steps); a gross disagreement in e^2 means the integration went wrong
    // (seen at 500 steps and alpha = 10, where e ~ 5e-5), not that e is uncertain.
    if !(e.is_finite() && e > 0.0 && e <= 1.0 + 1e-12) || (e * e - e_energy * e_energy).abs() > 1e-6
    {
        return Err(fail(
            alpha,
            IntegrationFailure::Unphysical,
            format!(
                "unphysical result: e = {} from the speed, {} from the energy",
                Num(e),
                Num(e_energy)
            ),
        ));
    }
    let (e, one_minus_e) = if e_energy > 0.5 {
        (e_energy, one_minus_e2 / (1.0 + e_energy))
    } else {
        (e, 1.0 - e)
    };
    Ok(DampedRebound {
        e,
        one_minus_e,
        tau_contact: tau,
        x_end,
    })
}

/// e alone at the default number of steps; see [`rebound`].
pub fn restitution(alpha: f64, dashpot: Dashpot, rule: ContactEnd) -> Result<f64> {
    Ok(rebound(alpha, dashpot, rule, DEFAULT_STEPS)?.e)
}

/// The alpha at which the dashpot gives restitution `e` in (0, 1]: the inverse of [`restitution`].
///
/// **Method**: e falls monotonically with alpha; the bracket starts at the small-damping estimate
/// alpha_0 = (1 - e)/J_0 (module note) and widens by factors of 2 until it holds the root, then
/// bisection in log alpha to a relative width of 1e-13 (at most 200 steps; e(alpha) itself is good
/// to about 1e-13, so a tighter alpha means nothing).
pub fn alpha_for_e(e: f64, dashpot: Dashpot, rule: ContactEnd) -> Result<f64> {
    if !(e.is_finite() && e > 0.0 && e <= 1.0) {
        return Err(Error::InvalidParameter {
            name: "restitution e",
            value: e,
            expected: "a number in (0, 1]",
        });
    }
    if e < E_MIN {
        return Err(Error::InvalidParameter {
            name: "restitution e",
            value: e,
            expected: "at least 1e-6 (below, the dashpot is all but critically damped and the \
                       solver's e has no relative accuracy left; a DEM contact that sticks)",
        });
    }
    if e == 1.0 {
        return Ok(0.0);
    }
    let j0 = match dashpot {
        Dashpot::Tsuji => std::f64::consts::PI / 5f64.sqrt(),
        Dashpot::Viscoelastic => 1.1534488580952888,
    };
    let target = e;
    // Under the overlap rule Tsuji's e falls to 0 at alpha = sqrt 5 (TSUJI_OVERLAP_CRITICAL),
    // so every e in (0, 1) has its alpha below: the bracket stops there (doubling past it had
    // asked for a rebound that does not exist, and any e below about 0.08 failed).
    let overdamped_from = (dashpot == Dashpot::Tsuji && rule == ContactEnd::Overlap)
        .then_some(TSUJI_OVERLAP_CRITICAL);
    let one_minus = |a: f64| -> Result<f64> {
        if overdamped_from.is_some_and(|c| a >= c) {
            return Ok(0.0 - target);
        }
        Ok(solve(a, dashpot, rule, DEFAULT_STEPS)?.e - target)
    };
    let cap = overdamped_from.unwrap_or(ALPHA_MAX);
    let guess = ((1.0 - e) / j0).min(cap);
    let (mut lo, mut hi) = (guess, guess);
    let mut found = false;
    for _ in 0..200 {
        let f_lo = one_minus(lo)?;
        if f_lo < 0.0 {
            // e(lo) below the target: alpha too large.
            hi = lo;
            lo *= 0.5;
            continue;
        }
        let f_hi = one_minus(hi)?;
        if f_hi > 0.0 {
            lo = hi;
            if hi >= cap {
                return Err(Error::InvalidParameter {
                    name: "restitution e",
                    value: e,
                    expected: "an e reachable with alpha <= 50",
                });
            }
            hi = (hi * 2.0).min(cap);
            continue;
        }
        found = true;
        break;
    }
    if !found {
        return Err(fail(
            f64::NAN,
            IntegrationFailure::Other,
            format!("could not bracket alpha for e = {}", Num(e)),
        ));
    }
    for _ in 0..200 {
        if hi / lo - 1.0 <= 1e-13 {
            return Ok((lo * hi).sqrt());
        }
        let mid = (lo * hi).sqrt();
        let f = one_minus(mid)?;
        if f.is_nan() {
            return Err(fail(mid, IntegrationFailure::NonFinite, "e(alpha) is NaN"));
        }
        if f > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Err(fail(
        lo,
        IntegrationFailure::Other,
        format!("bisection for e = {} did not converge", Num(e)),
    ))
}
