//! One-dimensional methods of the fit: a minimum inside a bracket, and where a profile crosses a
//! threshold.
//!
//! - [`brent_minimize`]: **solves** min f(x) on [a, b] by Brent's method (golden sections and
//!   parabolic steps; Brent, "Algorithms for Minimization without Derivatives", 1973, ch. 5;
//!   argmin's `BrentOpt`). **Needs** a bracket holding the minimum wanted (it finds a local one).
//! - [`profile_crossing`]: **solves** profile(t) = threshold between a minimum t_hat and a search
//!   limit: steps out from t_hat (the second step to just beyond the parabola's crossing, then
//!   doubling) until the profile reaches the threshold, then Brent's root finder (Brent 1973,
//!   ch. 4; argmin's `BrentRoot`) inside the bracket, from the values the steps found, with
//!   bisection as the fallback when Brent stops for any reason other than convergence.
//!
//! Every loop is capped; a NaN value, an exhausted cap or a solver that stopped for any reason
//! other than convergence is reported in the result (`converged: false`, [`Crossing::Failed`]),
//! never passed on as a number. An `Err` raised by the function itself is returned as it is.
//!
//! **Known answers** (tests below): a parabola's minimum and its crossings at 2 +- sqrt(3.84); a
//! skewed profile's crossing, found with no point evaluated twice.

use crate::error::{Error, Result};
use argmin::core::{CostFunction, Executor, State, TerminationReason};
use argmin::solver::brent::{BrentOpt, BrentRoot};
use std::cell::RefCell;

/// Iteration cap of Brent's minimisation (it converges linearly at worst, by golden sections:
/// 0.618^200 of any bracket is below the resolution of a double).
const BRENT_MIN_ITERS: u64 = 200;
/// Iteration cap of Brent's root finder (same argument, with bisection steps).
const BRENT_ROOT_ITERS: u64 = 200;
/// Doublings of the outward step of [`profile_crossing`]: 2^80 steps of at least `tol` reach any
/// finite limit.
const MAX_DOUBLINGS: usize = 80;
/// Bisections of the fallback: 200 halvings reach the resolution of a double from any interval.
const MAX_BISECTIONS: usize = 200;

/// A scalar function for argmin's Brent solvers; the function's own errors and NaN values are
/// kept aside (argmin's error type would lose them) and reported by the caller.
struct Scalar<'a, F: FnMut(f64) -> Result<f64>> {
    f: RefCell<F>,
    failure: &'a RefCell<Option<Failure>>,
    offset: f64,
}

enum Failure {
    Model(Error),
    NotANumber(f64),
}

impl<F: FnMut(f64) -> Result<f64>> CostFunction for Scalar<'_, F> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, x: &f64) -> std::result::Result<f64, argmin::core::Error> {
        match (self.f.borrow_mut())(*x) {
            Ok(v) if v.is_nan() => {
                *self.failure.borrow_mut() = Some(Failure::NotANumber(*x));
                Err(argmin::core::Error::msg("NaN"))
            }
            Ok(v) => Ok(v - self.offset),
            Err(e) => {
                *self.failure.borrow_mut() = Some(Failure::Model(e.clone()));
                Err(e.into())
            }
        }
    }
}

/// A one-dimensional minimum.
#[derive(Debug, Clone, PartialEq)]
pub struct Minimum1d {
    pub x: f64,
    pub fx: f64,
    pub converged: bool,
    /// Why it stopped.
    pub reason: String,
}

/// Minimum of f on [a, b] by Brent's method, to |x - m| 1.5e-8 + `abs_tol`, m the middle of the
/// bracket where it lies at least two half-widths from 0, else m = 0 (the relative part is
/// sqrt(machine epsilon), the most function values can resolve relative to the scale of x). The
/// bracket ends themselves are never evaluated.
///
/// Why from the middle: argmin's tolerance is relative to |x|, and the fit's coordinates are
/// logarithms with arbitrary offsets (ln sigma_y ~ 16 for sigma_y in Pa), so 1.5e-8 |x| was
/// 2.4e-7 in ln sigma_y: 0.8 of a standard error for ten rows with one e_err of 1e-7 (fuzzed
/// `fit`, seed 607, case 777: the 1-D polish stopped 6.2e-5 above the minimum in chi2).
pub fn brent_minimize(
    f: impl FnMut(f64) -> Result<f64>,
    a: f64,
    b: f64,
    abs_tol: f64,
) -> Result<Minimum1d> {
    if !(a.is_finite() && b.is_finite() && a < b) {
        return Err(Error::InvalidParameter {
            name: "Brent bracket",
            value: b - a,
            expected: "finite ends a < b",
        });
    }
    let failure = RefCell::new(None);
    // Counted from the middle only where that is nearer than 0 for every point of the bracket
    // (the middle at least two half-widths from 0): never a looser tolerance than from 0.
    let half = 0.5 * b - 0.5 * a;
    let mid = if (0.5 * a + 0.5 * b).abs() >= 2.0 * half {
        0.5 * a + 0.5 * b
    } else {
        0.0
    };
    let mut f = f;
    let problem = Scalar {
        f: RefCell::new(move |y: f64| f(mid + y)),
        failure: &failure,
        offset: 0.0,
    };
    let solver = BrentOpt::new(a - mid, b - mid).set_tolerance(f64::EPSILON.sqrt(), abs_tol);
    let res = Executor::new(problem, solver)
        .configure(|s| s.max_iters(BRENT_MIN_ITERS))
        .run();
    match res {
        Ok(r) => {
            let st = r.state();
            let x = mid + st.get_best_param().copied().unwrap_or(f64::NAN);
            let fx = st.get_best_cost();
            let reason = st.get_termination_reason();
            let converged = matches!(reason, Some(TerminationReason::SolverConverged));
            if !x.is_finite() || fx.is_nan() {
                return Ok(Minimum1d {
                    x: 0.5 * (a + b),
                    fx: f64::NAN,
                    converged: false,
                    reason: "Brent returned no point".into(),
                });
            }
            Ok(Minimum1d {
                x,
                fx,
                converged,
                reason: match reason {
                    Some(r) => r.text().to_string(),
                    None => "not terminated".into(),
                },
            })
        }
        Err(e) => match failure.take() {
            Some(Failure::Model(err)) => Err(err),
            Some(Failure::NotANumber(y)) => Ok(Minimum1d {
                x: mid + y,
                fx: f64::NAN,
                converged: false,
                reason: format!("the function is NaN at {}", mid + y),
            }),
            None => Ok(Minimum1d {
                x: 0.5 * (a + b),
                fx: f64::NAN,
                converged: false,
                reason: format!("Brent failed: {e}"),
            }),
        },
    }
}

/// Where a profile reaches its threshold, seen from the minimum.
#[derive(Debug, Clone, PartialEq)]
pub enum Crossing {
    /// It crosses here (to the tolerance asked).
    At(f64),
    /// It stays below the threshold up to the search limit: the interval is open on this side.
    Open,
    /// The crossing could not be found; the reason says why.
    Failed(String),
}

/// The point between `t_hat` and `limit` where `profile(t)` first reaches `threshold` (see the
/// module doc). `v_hat = profile(t_hat)` (the minimum, known to the caller) must be below
/// `threshold`; trial points go out from `t_hat` by `step`, then once to 5% beyond where the
/// parabola through (t_hat, v_hat) and the first point reaches the threshold (at most twice the
/// distance: a profile is close to a parabola near its minimum, so the bracket handed to Brent
/// is tight), then doubling. No point is evaluated twice: the root
/// finder starts from the bracket's values as the steps found them.
pub fn profile_crossing(
    profile: impl FnMut(f64) -> Result<f64>,
    t_hat: f64,
    v_hat: f64,
    limit: f64,
    step: f64,
    threshold: f64,
    tol: f64,
) -> Result<Crossing> {
    // Values already computed, by their exact argument (the bracket's ends are handed to the
    // root finder as they are, so it finds them here).
    let mut seen: Vec<(f64, f64)> = vec![(t_hat, v_hat)];
    let mut profile = profile;
    let mut profile = move |t: f64| -> Result<f64> {
        if let Some(&(_, v)) = seen.iter().find(|p| p.0 == t) {
            return Ok(v);
        }
        let v = profile(t)?;
        seen.push((t, v));
        Ok(v)
    };
    if ![t_hat, v_hat, limit, step, threshold, tol]
        .iter()
        .all(|x| x.is_finite())
        || !(tol > 0.0)
    {
        return Ok(Crossing::Failed(format!(
            "non-finite search settings (t = {t_hat}, limit = {limit}, step = {step}, \
             threshold = {threshold})"
        )));
    }
    if limit == t_hat {
        return Ok(Crossing::Open);
    }
    let dir = (limit - t_hat).signum();
    let mut inner = t_hat;
    let mut dist = step.abs().max(tol);
    let mut outer = None;
    for k in 0..MAX_DOUBLINGS + 1 {
        let t = if (t_hat + dir * dist - limit) * dir >= 0.0 {
            limit
        } else {
            t_hat + dir * dist
        };
        let v = profile(t)?;
        if v.is_nan() {
            return Ok(Crossing::Failed(format!("the profile is NaN at {t}")));
        }
        if v >= threshold {
            outer = Some(t);
            break;
        }
        if t == limit {
            return Ok(Crossing::Open);
        }
        inner = t;
        // After the first step, 5% beyond the parabola's crossing (see the doc): a factor above
        // 1.05 (v is below the threshold) and at most 2; the one guided step comes on top of
        // the doublings, so their reach is kept. NaN (v below v_hat: a lower minimum, which the
        // caller handles) or inf (a flat start): doubling.
        let ratio = ((threshold - v_hat) / (v - v_hat)).sqrt();
        dist *= if k == 0 && ratio.is_finite() {
            (1.05 * ratio).min(2.0)
        } else {
            2.0
        };
    }
    let Some(outer) = outer else {
        return Ok(Crossing::Failed(format!(
            "no crossing within {MAX_DOUBLINGS} doublings of the step"
        )));
    };
    let failure = RefCell::new(None);
    let shared = RefCell::new(&mut profile);
    // The root finder sees the signed root sqrt(profile - v_hat) - sqrt(threshold - v_hat),
    // which has the profile's sign against the threshold and the same root, but is close to a
    // straight line in t where the profile is close to a parabola (the signed likelihood root:
    // (t - t_hat)/stderr for a quadratic chi2), so the secant and inverse quadratic steps of
    // Brent's method land near the root at once. On the profile itself they crept in from the
    // end whose value is far above the threshold (a steep side: 12 profile points for one end of
    // `product` on 100 000 points of distinct sizes). A value below v_hat (a lower minimum,
    // which the caller handles) counts as v_hat; NaN stays NaN. A start not below the
    // threshold (outside this function's contract) keeps the plain difference.
    let signed = threshold > v_hat;
    let root = |v: f64| {
        if v.is_nan() || !signed {
            v - threshold
        } else {
            (v - v_hat).max(0.0).sqrt() - (threshold - v_hat).sqrt()
        }
    };
    let problem = Scalar {
        f: RefCell::new(|t: f64| (shared.borrow_mut())(t).map(root)),
        failure: &failure,
        offset: 0.0,
    };
    let (a, b) = if inner < outer {
        (inner, outer)
    } else {
        (outer, inner)
    };
    let res = Executor::new(problem, BrentRoot::new(a, b, tol))
        .configure(|s| s.max_iters(BRENT_ROOT_ITERS))
        .run();
    match (res, failure.take()) {
        (_, Some(Failure::Model(e))) => return Err(e),
        (_, Some(Failure::NotANumber(t))) => {
            return Ok(Crossing::Failed(format!("the profile is NaN at {t}")));
        }
        (Ok(r), None) => {
            let st = r.state();
            let converged = matches!(
                st.get_termination_reason(),
                Some(TerminationReason::SolverConverged)
            );
            // The last iterate b, not argmin's "best" (the smallest |f| seen, which for a
            // profile that is not reproducible can lie on the wrong side of the crossing).
            if let (true, Some(&x)) = (converged, st.get_param())
                && x.is_finite()
            {
                return Ok(Crossing::At(x));
            }
            // Any other stop (the iteration cap): fall through to bisection.
        }
        (Err(_), None) => {
            // argmin refused the bracket (the ends' values are the steps' own, so their signs
            // differ; kept as a fall-through all the same). Bisection below trusts the
            // classification of each new point.
        }
    }
    let (mut below, mut above) = (inner, outer);
    for _ in 0..MAX_BISECTIONS {
        if (above - below).abs() <= tol {
            return Ok(Crossing::At(0.5 * (below + above)));
        }
        let mid = 0.5 * (below + above);
        if mid == below || mid == above {
            // The resolution of a double: as close as the crossing can be located.
            return Ok(Crossing::At(mid));
        }
        let v = (shared.borrow_mut())(mid)?;
        if v.is_nan() {
            return Ok(Crossing::Failed(format!("the profile is NaN at {mid}")));
        }
        if v >= threshold {
            above = mid;
        } else {
            below = mid;
        }
    }
    Ok(Crossing::Failed(format!(
        "bisection did not reach the tolerance in {MAX_BISECTIONS} steps"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_resolves_a_narrow_minimum_far_from_zero() {
        // A parabola of width 1e-8 at x = 16.4 (ln sigma_y in Pa, say), bracketed to +-1e-6:
        // the tolerance counts from the bracket's middle (1.5e-8 x 1e-6 + 1e-13), not from 0
        // (1.5e-8 x 16.4 = 2.5e-7, 25 widths), so x comes to within 1e-11, and f within
        // (1e-11 / 1e-8)^2 = 1e-6 of its minimum.
        let f = |x: f64| Ok(((x - 16.4) / 1e-8).powi(2) + 10.0);
        let m = brent_minimize(f, 16.4 - 1e-6, 16.4 + 2e-6, 1e-13).unwrap();
        assert!(
            m.converged && (m.x - 16.4).abs() < 1e-11 && m.fx - 10.0 < 1e-6,
            "{m:?}"
        );
    }

    #[test]
    fn brent_minimum_and_profile_crossing() {
        // (x - 2)^2 + 1: minimum 1 at 2; crossing of 1 + 3.84 at 2 +- sqrt(3.84). Tolerances:
        // Brent's x to sqrt(eps) relative (1e-7 allows it), f(x) then to (1e-7)^2; the
        // crossings to the 1e-10 asked (1e-9 allows the last step).
        let m = brent_minimize(|x| Ok((x - 2.0).powi(2) + 1.0), -5.0, 10.0, 1e-12).unwrap();
        assert!(
            m.converged && (m.x - 2.0).abs() < 1e-7 && (m.fx - 1.0).abs() < 1e-13,
            "{m:?}"
        );
        let f = |x: f64| Ok((x - 2.0f64).powi(2) + 1.0);
        let at = |c: Crossing| match c {
            Crossing::At(x) => x,
            other => panic!("{other:?}"),
        };
        let up = at(profile_crossing(f, 2.0, 1.0, 100.0, 0.5, 4.84, 1e-10).unwrap());
        assert!((up - (2.0 + 3.84f64.sqrt())).abs() < 1e-9, "{up}");
        let down = at(profile_crossing(f, 2.0, 1.0, -100.0, 0.5, 4.84, 1e-10).unwrap());
        assert!((down - (2.0 - 3.84f64.sqrt())).abs() < 1e-9, "{down}");
        // A plateau: never reaches the threshold before the limit.
        let flat = |x: f64| Ok(if x < 2.0 { (x - 2.0f64).powi(2) } else { 0.0 });
        assert_eq!(
            profile_crossing(flat, 2.0, 0.0, 50.0, 0.5, 3.84, 1e-10).unwrap(),
            Crossing::Open
        );
        let down = at(profile_crossing(flat, 2.0, 0.0, -50.0, 0.5, 3.84, 1e-10).unwrap());
        assert!((down - (2.0 - 3.84f64.sqrt())).abs() < 1e-9, "{down}");
    }

    #[test]
    fn steep_profiles_are_crossed_in_few_points() {
        // chi2 = 1 + (exp(k (x - 2)) - 1)^2 / k^2: a parabola near its minimum, steep beyond
        // (k = 3: the crossing of 1 + 3.84 at 2 + ln(1 + k sqrt(3.84))/k, closed form). A first
        // step of 1 lands 3e4 above the threshold; on the signed root sqrt(chi2 - 1) - sqrt(3.84)
        // = (exp(k d) - 1)/k - sqrt(3.84), nearly linear, Brent reaches the root to 1e-10 in
        // 8 points in all (on chi2 itself it took 11: its interpolations crept in from the
        // steep end).
        let k = 3.0;
        let mut calls = 0;
        let f = |x: f64| {
            calls += 1;
            let z = ((k * (x - 2.0)).exp() - 1.0) / k;
            Ok(1.0 + z * z)
        };
        let c = profile_crossing(f, 2.0, 1.0, 100.0, 1.0, 4.84, 1e-10).unwrap();
        let root = 2.0 + (1.0 + k * 3.84f64.sqrt()).ln() / k;
        assert!(
            matches!(c, Crossing::At(x) if (x - root).abs() < 1e-9),
            "{c:?} {root}"
        );
        assert!(calls <= 8, "{calls} points");
    }

    #[test]
    fn a_crossing_evaluates_no_point_twice() {
        // A skewed profile, (x - 2)^2 (1 - 0.1 (x - 2)) + 1, whose upper crossing of 1 + 3.84 lies
        // at 2 + r with r^2 - 0.1 r^3 = 3.84 (r = 2.22...); the first step, 0.9 sqrt(3.84), falls
        // short, the parabola's step brackets the root. The old doubling re-evaluated both ends
        // of the bracket in Brent's start: every argument here is new, and the minimum's value
        // is never asked for.
        let mut calls: Vec<f64> = Vec::new();
        let f = |x: f64| {
            calls.push(x);
            let d = x - 2.0;
            Ok(d * d * (1.0 - 0.1 * d) + 1.0)
        };
        let step = 0.9 * 3.84f64.sqrt();
        let c = profile_crossing(f, 2.0, 1.0, 100.0, step, 4.84, 1e-10).unwrap();
        // The root by Newton's method in the test (independent of the code under test).
        let mut r = 2.2f64;
        for _ in 0..50 {
            r -= (r * r - 0.1 * r * r * r - 3.84) / (2.0 * r - 0.3 * r * r);
        }
        assert!(
            matches!(c, Crossing::At(x) if (x - (2.0 + r)).abs() < 1e-9),
            "{c:?} {r}"
        );
        assert!(!calls.contains(&2.0), "{calls:?}");
        for (k, x) in calls.iter().enumerate() {
            assert!(!calls[..k].contains(x), "{x} evaluated twice: {calls:?}");
        }
        // The parabola's step lands just beyond the root (within 5%: the skew's error plus the
        // 5% margin); doubling alone put it at 2 x 1.76, 59% beyond.
        let second = calls[1] - 2.0;
        assert!(second > r && second < 1.05 * r, "{calls:?} {r}");
    }

    #[test]
    fn failures_are_reported_not_hidden() {
        // NaN inputs or values: a failure with the reason, no hang (the old code looped forever
        // on a NaN start).
        let f = |x: f64| Ok((x - 2.0f64).powi(2));
        assert!(matches!(
            profile_crossing(f, f64::NAN, 0.0, 10.0, 0.5, 3.84, 1e-10).unwrap(),
            Crossing::Failed(_)
        ));
        let nan_beyond = |x: f64| Ok(if x > 3.0 { f64::NAN } else { 0.0 });
        assert!(matches!(
            profile_crossing(nan_beyond, 2.0, 0.0, 10.0, 0.5, 3.84, 1e-10).unwrap(),
            Crossing::Failed(_)
        ));
        let m = brent_minimize(|x| Ok(if x > 1.0 { f64::NAN } else { x }), 0.0, 3.0, 1e-9).unwrap();
        assert!(!m.converged, "{m:?}");
        // A model error is passed on as it is.
        let err = |_: f64| -> Result<f64> {
            Err(Error::InvalidParameter {
                name: "x",
                value: 1.0,
                expected: "y",
            })
        };
        assert!(profile_crossing(err, 2.0, 0.0, 10.0, 0.5, 3.84, 1e-10).is_err());
        // A profile that gives different values at the same point (re-minimisation settling
        // elsewhere) still ends, by bisection: a step function with a threshold at 3.
        let mut calls = 0;
        let flaky = |x: f64| {
            calls += 1;
            Ok(if x >= 3.0 { 10.0 } else { (calls % 2) as f64 })
        };
        let c = profile_crossing(flaky, 2.0, 0.0, 10.0, 0.5, 5.0, 1e-10).unwrap();
        assert!(
            matches!(c, Crossing::At(x) if (x - 3.0).abs() < 1e-9),
            "{c:?}"
        );
    }
}
