//! The collision instant on the fitted tracks (first contact, or where the fits meet) and the
//! propagation of the fits' covariance through it to e and v_n (docs/physics.md §5).

use super::{Kinematics, PhaseFit, TimeRule};
use crate::error::{Error, Num, Result};

/// The collision time on `window` by `rule` (or the primary rule with its fallback when `None`).
pub(super) fn collision_time(
    pre: &PhaseFit,
    post: &PhaseFit,
    contact_m: f64,
    window: (f64, f64),
    rule: Option<TimeRule>,
) -> Result<(f64, TimeRule)> {
    let (lo, hi) = window;
    let gap = |t: f64| (pre.position(0, t) - pre.position(1, t)).norm() - contact_m;
    let mismatch = |t: f64| {
        (0..2)
            .map(|s| (pre.position(s, t) - post.position(s, t)).norm_squared())
            .sum::<f64>()
    };
    let crossing = match rule {
        Some(TimeRule::FitsMeet) => None,
        _ => first_crossing(&gap, lo, hi)?,
    };
    Ok(match crossing {
        Some(t) => (t, TimeRule::ContactDistance),
        None => (argmin_scan(&mismatch, lo, hi)?, TimeRule::FitsMeet),
    })
}

/// (e, v_n) of the fits: the normal from the pre-collision centres at t_c, e = -(v1' - v2').n /
/// (v1 - v2).n, v_n = -(v1 - v2).n. The same numbers [`walton::measure`] gives (spins do not
/// enter the normal components); used here to propagate the fits' covariance.
pub(super) fn normal_restitution(pre: &PhaseFit, post: &PhaseFit, t_c: f64) -> (f64, f64) {
    let n = (pre.position(0, t_c) - pre.position(1, t_c)).normalize();
    let b = (pre.velocity(0, t_c) - pre.velocity(1, t_c)).dot(&n);
    let a = (post.velocity(0, t_c) - post.velocity(1, t_c)).dot(&n);
    (-a / b, -b)
}

/// Standard errors of (e, v_n) by linear propagation of every fit parameter's covariance
/// (sigma^2 (X^T X)^-1 per fit; fits independent) through the whole chain, collision time and
/// normal included, with central differences of step 1e-4 standard deviations.
pub(super) fn propagate(k: &Kinematics, sigma: f64) -> Result<(f64, f64)> {
    let eval = |pre: &PhaseFit, post: &PhaseFit| -> Result<(f64, f64)> {
        let (t_c, _) = collision_time(pre, post, k.contact_m, k.window_s, Some(k.time_rule))?;
        Ok(normal_restitution(pre, post, t_c))
    };
    let (mut var_e, mut var_vn) = (0.0, 0.0);
    for phase in 0..2 {
        for f in 0..4 {
            let fit = if phase == 0 {
                &k.pre.fits[f]
            } else {
                &k.post.fits[f]
            };
            let p = fit.xtx_inv.nrows();
            let mut grad = vec![(0.0, 0.0); p];
            for (j, g) in grad.iter_mut().enumerate() {
                let h = 1e-4 * sigma * fit.xtx_inv[(j, j)].sqrt();
                let shifted = |delta: f64| {
                    let (mut pre, mut post) = (k.pre.clone(), k.post.clone());
                    let target = if phase == 0 {
                        &mut pre.fits[f]
                    } else {
                        &mut post.fits[f]
                    };
                    target.coef[j] += delta;
                    eval(&pre, &post)
                };
                let (plus, minus) = (shifted(h)?, shifted(-h)?);
                *g = (
                    (plus.0 - minus.0) / (2.0 * h),
                    (plus.1 - minus.1) / (2.0 * h),
                );
            }
            for a in 0..p {
                for b in 0..p {
                    let c = sigma * sigma * fit.xtx_inv[(a, b)];
                    var_e += grad[a].0 * c * grad[b].0;
                    var_vn += grad[a].1 * c * grad[b].1;
                }
            }
        }
    }
    Ok((var_e.sqrt(), var_vn.sqrt()))
}

/// Iteration cap of the bisection and golden-section refinements below. Both stop when the
/// bracket is down to 1e-15 of the window or of the time (whichever is larger): bisection needs
/// about 43 halvings from a scan cell (1/200 of the window), golden section about 75 steps from
/// two cells; 200 leaves a margin, and reaching it is an error.
const REFINE_MAX_ITERATIONS: usize = 200;

fn refine_error(what: &str, detail: String) -> Error {
    Error::NoConvergence {
        method: if what == "crossing" {
            "bisection for the contact instant"
        } else {
            "golden-section search for the instant the fits meet"
        },
        detail,
    }
}

/// Whether [x0, x1] is down to rounding: 1e-15 of |x| or of the window.
fn narrow(x0: f64, x1: f64, window: f64) -> bool {
    x1 - x0 <= 1e-15 * (x0.abs().max(x1.abs()) + window)
}

/// First crossing of f from > 0 to <= 0 on [lo, hi], by a scan and bisection to rounding; `None`
/// if f does not cross, an error if f is NaN where it is evaluated or the bisection stalls.
fn first_crossing(f: &impl Fn(f64) -> f64, lo: f64, hi: f64) -> Result<Option<f64>> {
    const N: usize = 200;
    let nan = |t: f64| {
        refine_error(
            "crossing",
            format!("the centre distance is NaN at t = {} s", Num(t)),
        )
    };
    let mut a = lo;
    let mut fa = f(a);
    if fa.is_nan() {
        return Err(nan(a));
    }
    for i in 1..=N {
        let b = lo + (hi - lo) * i as f64 / N as f64;
        let fb = f(b);
        if fb.is_nan() {
            return Err(nan(b));
        }
        if fa > 0.0 && fb <= 0.0 {
            let (mut x0, mut x1) = (a, b);
            for _ in 0..REFINE_MAX_ITERATIONS {
                let m = 0.5 * (x0 + x1);
                if narrow(x0, x1, hi - lo) || m <= x0 || m >= x1 {
                    return Ok(Some(0.5 * (x0 + x1)));
                }
                let fm = f(m);
                if fm.is_nan() {
                    return Err(nan(m));
                }
                if fm > 0.0 { x0 = m } else { x1 = m }
            }
            return Err(refine_error(
                "crossing",
                format!(
                    "{REFINE_MAX_ITERATIONS} halvings left [{}, {}] s",
                    Num(x0),
                    Num(x1)
                ),
            ));
        }
        a = b;
        fa = fb;
    }
    Ok(None)
}

/// Minimiser of f on [lo, hi]: a scan, then golden-section refinement around the best point; an
/// error if f is NaN where it is evaluated or the refinement does not narrow to rounding.
fn argmin_scan(f: &impl Fn(f64) -> f64, lo: f64, hi: f64) -> Result<f64> {
    const N: usize = 200;
    let nan = |t: f64| {
        refine_error(
            "meet",
            format!("the fits' mismatch is NaN at t = {} s", Num(t)),
        )
    };
    let h = (hi - lo) / N as f64;
    let mut best = (lo, f(lo));
    for i in 0..=N {
        let t = lo + h * i as f64;
        let v = f(t);
        if v.is_nan() {
            return Err(nan(t));
        }
        if v < best.1 {
            best = (t, v);
        }
    }
    let (mut a, mut b) = ((best.0 - h).max(lo), (best.0 + h).min(hi));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..REFINE_MAX_ITERATIONS {
        if narrow(a, b, hi - lo) {
            return Ok(0.5 * (a + b));
        }
        let c = b - g * (b - a);
        let d = a + g * (b - a);
        let (fc, fd) = (f(c), f(d));
        if fc.is_nan() || fd.is_nan() {
            return Err(nan(if fc.is_nan() { c } else { d }));
        }
        if fc < fd { b = d } else { a = c }
    }
    Err(refine_error(
        "meet",
        format!(
            "{REFINE_MAX_ITERATIONS} steps left [{}, {}] s",
            Num(a),
            Num(b)
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossing_and_minimum_known_answers() {
        // f(t) = 0.3 - t crosses at 0.3; (t - 0.7)^2 has its minimum at 0.7. Both to rounding
        // (1e-15 of the window, the documented stopping rule).
        let c = first_crossing(&|t: f64| 0.3 - t, 0.0, 1.0)
            .unwrap()
            .unwrap();
        assert!((c - 0.3).abs() < 2e-15, "{c}");
        let m = argmin_scan(&|t: f64| (t - 0.7) * (t - 0.7), 0.0, 1.0).unwrap();
        // Golden section on a quadratic: the minimiser to about sqrt(eps) of the function's
        // flatness, but the bracket is narrowed to 1e-15 of the window in t.
        assert!((m - 0.7).abs() < 1e-7, "{m}");
        assert_eq!(first_crossing(&|t: f64| 1.0 + t, 0.0, 1.0).unwrap(), None);
    }

    #[test]
    fn nan_is_an_error_not_a_time() {
        let e = first_crossing(&|t: f64| if t > 0.5 { f64::NAN } else { 1.0 }, 0.0, 1.0);
        assert!(matches!(e, Err(Error::NoConvergence { .. })), "{e:?}");
        let e = argmin_scan(&|_t: f64| f64::NAN, 0.0, 1.0);
        assert!(matches!(e, Err(Error::NoConvergence { .. })), "{e:?}");
    }
}
