//! 95% profile-likelihood intervals.
//!
//! **Solves**, for each parameter j, the ends of {t : P_j(t) <= chi2_min + Delta}, where the
//! profile P_j(t) is chi2 minimised over the other parameters with theta_j = t and
//! Delta = 3.84 s (s the chi2 scale of [`super::objective`]; the same s scales `stderr`, so for a
//! model linear in its parameters the interval is value +- 1.96 stderr). Reference: Venzon &
//! Moolgavkar, Applied Statistics 37, 87 (1988); the PDG's "Statistics" review, section 40.3.2.
//!
//! **Method**: from the minimum, a step of about 1.96 standard errors outwards, then one to just
//! beyond where the parabola through the minimum and that point crosses, then doubling, until the
//! profile passes the threshold or the search box ends (an open side: the parameter is a bound);
//! then the crossing by Brent's root finder ([`super::scalar::profile_crossing`]). The inner
//! minimisation is Levenberg-Marquardt warm-started from the nearest profile point already
//! computed, so a profile follows its valley. Where its value is at or above the threshold, an
//! [`Inner`] given (the fit's, for `min`, `product` and the power law:
//! [`super::slice`]) shows it is the profile's or finds a lower point (a value below the
//! threshold needs no check: the profile is at most that), at the outer end of each crossing's
//! last bracket, the point the end rests on; where it finds that point below the threshold,
//! the crossing is searched again from there (see `profile_end`). [`extend_to_region`] then moves an end past any known point of the 95% region
//! beyond it (the interval is the hull of the region found). A profile point below the minimum
//! reveals a lower minimum: the caller refits from it. Every failure is a value: a side whose crossing could
//! not be found is [`Side::Lost`] with the reason, and inner minimisations that did not converge
//! are counted (their profile values are upper bounds, so the interval could be too short).
//!
//! **Known answer** (test below): a straight line's slope, whose profile interval is exactly
//! the least-squares value +- sqrt(3.84) standard errors.

use super::lsq::{self, Covariance, LmOptions, Residuals};
use super::objective::{CHI2_1DOF_95, Objective};
use super::scalar::{Crossing, profile_crossing};
use super::search::Region;
use super::slice::slice_minimum;
use super::sums;
use crate::error::Result;
use std::cell::{Cell, RefCell};

/// One end of an interval, in internal coordinates.
#[derive(Debug, Clone, PartialEq)]
pub enum Side {
    At(f64),
    /// The profile stays below the threshold up to the edge of the search box.
    Open,
    /// Not found; the reason.
    Lost(String),
}

/// The intervals of every parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Profiles {
    /// Per parameter, the lower and upper end.
    pub sides: Vec<[Side; 2]>,
    /// Per parameter, inner minimisations that did not converge.
    pub unconverged: Vec<u32>,
    pub delta: f64,
}

/// The intervals, or a point whose chi2 beats the minimum (the search missed it).
#[derive(Debug, Clone, PartialEq)]
pub enum ProfileOutcome {
    Done(Profiles),
    Lower(Vec<f64>),
}

/// A global inner minimisation: for parameter j held at t, the local minimisation's point, chi2
/// and whether it converged there, and a target, a point with theta_j = t at least as low, its
/// chi2, and whether it is shown that no point with theta_j = t has chi2 below the lower of that
/// chi2 and the target (by more than the search's tolerance: [`super::slice`]); None for a
/// parameter it does not cover (the local minimisation's result stands).
pub type Inner<'a> = dyn Fn(usize, f64, (&[f64], f64, bool), f64) -> Result<Option<(Vec<f64>, f64, bool)>>
    + Sync
    + 'a;

/// The global inner minimisation of `obj`'s profiles, where it has one: `min` and `product`,
/// whose chi2 over one parameter with the other held can have several minima (a plateau where
/// every point stays elastic, the kinks of `min`), and the power law (whose local minimisation
/// put 5 of 336 ends of its exponents and 1 of 144 of A short on the randomized test's seeds
/// 0-100: `examples/interval_scan --powerlaw`), with the global search's `region`.
pub fn global_inner<'a>(
    obj: &'a Objective<'a>,
    region: Option<&'a Region>,
) -> Option<Box<Inner<'a>>> {
    // The search keeps a region for exactly these models.
    let region = region?;
    Some(Box::new(move |j, t, local, target| {
        Ok(
            slice_minimum(obj, j, t, local, target, region)?
                .map(|m| (m.theta, m.chi2, m.certified)),
        )
    }))
}

/// The profile-likelihood intervals around the minimum `theta` (chi2 `chi2_min`), with the chi2
/// scale given, the inner minimisation completed by `inner` where given (the fit's: [`global_inner`]).
pub fn profile_intervals_of(
    obj: &(impl Residuals + Sync),
    theta: &[f64],
    chi2_min: f64,
    cov: &Covariance,
    scale: f64,
    inner: Option<&Inner>,
) -> Result<ProfileOutcome> {
    let k = obj.n_params();
    let delta = CHI2_1DOF_95 * scale;
    // Degenerate parameters: only a combination with other parameters is determined; a profile
    // would end only at the edges of the other parameters' search ranges.
    let ends: Vec<(usize, usize)> = (0..k)
        .filter(|&j| !cov.degenerate[j])
        .flat_map(|j| [(j, 0), (j, 1)])
        .collect();
    let at = Around {
        chi2_min,
        cov,
        delta,
        inner,
    };
    let end = |&(j, s): &(usize, usize)| profile_end(obj, (theta, chi2_min), &at, j, s);
    // Each end is its own profile (warm-started from its own points only), so large data's
    // ends run side by side (a fit's profiles are a fifth of its time, and the last fit of
    // `--model all` otherwise runs its profiles on one core while the other waits) and give
    // the same numbers as one after another. Small data's stay on this thread.
    let found: Vec<Result<End>> = if sums::is_large(obj.n_residuals()) {
        use rayon::prelude::*;
        ends.par_iter().map(end).collect()
    } else {
        ends.iter().map(end).collect()
    };
    let mut sides = vec![[Side::Open, Side::Open]; k];
    let mut unconverged = vec![0; k];
    // In the ends' order, as one after another would stop: at the first error or lower
    // minimum.
    for (&(j, s), f) in ends.iter().zip(found) {
        match f? {
            End::Lower(t) => return Ok(ProfileOutcome::Lower(t)),
            End::Side(side, failed) => {
                sides[j][s] = side;
                unconverged[j] += failed;
            }
        }
    }
    Ok(ProfileOutcome::Done(Profiles {
        sides,
        unconverged,
        delta,
    }))
}

/// The minimum the profiles are taken around: its chi2, the covariance there, the threshold's
/// Delta, and the global inner minimisation if any.
#[derive(Clone, Copy)]
struct Around<'a> {
    chi2_min: f64,
    cov: &'a Covariance,
    delta: f64,
    inner: Option<&'a Inner<'a>>,
}

/// What the profile of one end of one parameter found.
enum End {
    /// The end, and the inner minimisations that did not converge.
    Side(Side, u32),
    /// A point below the minimum.
    Lower(Vec<f64>),
}

/// Tolerance of the crossings in the internal coordinate (log parameters: 1e-7 relative).
const CROSSING_TOL: f64 = 1e-7;

/// Rounds of a profile end whose crossing's outer point the inner search put below the
/// threshold, with the inner search left to one point per crossing; then it runs at every
/// point at or above the threshold.
const LAZY_ROUNDS: usize = 3;

/// A profile point: t, where the inner minimisation ended, its chi2, and whether the local
/// minimisation converged.
type Point = (f64, Vec<f64>, f64, bool);

/// The end `s` (0 lower, 1 upper) of parameter j's interval (see the module doc), searched
/// outwards from `from` = (theta, chi2), a point below the threshold chi2_min + delta: the
/// minimum, or a point of the 95% region beyond an end already found ([`extend_to_region`]).
///
/// The global inner minimisation (`inner`) runs at one point per crossing: the outer end of the
/// root finder's last bracket, the innermost point whose local value is at or above the
/// threshold, which the end rests on (every point of a crossing's search at or above the
/// threshold lies beyond every point below it: the steps go outwards until one is above, and
/// the brackets shrink). A local value below the threshold shows the profile below it (the
/// profile is at most that), so the bracket's inner end needs no check, and nothing between
/// is claimed. Where the inner search puts the outer end below the threshold after all, the
/// crossing is searched again outwards from there, its first step from the parabola through
/// the end's starting point and the point found ([`restart_step`]), the warm starts beginning
/// at the point it found (a part of the region the local minimisation missed; from the points
/// before, in the valley the local minimisation followed, they led back into it), LAZY_ROUNDS
/// times, then with the inner search at every point at or above the threshold. Why: running it
/// at every such point, as before, cost two to five inner searches per end where one decides
/// (the power law's 100 000 distinct points: four fifths of its profiles' time).
fn profile_end(
    obj: &impl Residuals,
    from: (&[f64], f64),
    at: &Around,
    j: usize,
    s: usize,
) -> Result<End> {
    let Around {
        chi2_min,
        cov,
        delta,
        inner,
    } = *at;
    let (theta, chi2_from) = from;
    let k = obj.n_params();
    let threshold = chi2_min + delta;
    // A profile point this far below the minimum means a missed minimum, not rounding.
    let beaten = chi2_min - 1e-7 * chi2_min.abs().max(1.0);
    let lm = LmOptions::default();
    let (lower, upper) = (obj.lower(), obj.upper());
    let span = upper[j] - lower[j];
    let step = (delta * cov.matrix[(j, j)]).sqrt();
    let step = if step.is_finite() && step > 0.0 {
        step.min(0.25 * span)
    } else {
        0.01 * span
    };
    let limit = [lower[j], upper[j]][s];
    let dir = if s == 0 { -1.0 } else { 1.0 };
    // On large data the inner minimisation stops where the Gauss-Newton step promises a
    // decrease of chi2 below 0.01 CROSSING_TOL 2 Delta / step: a profile quadratic around the
    // minimum crosses at about `step` from it with slope 2 Delta / step, so a value that much
    // too high moves its crossing by a hundredth of the tolerance (a profile a hundred times
    // flatter there, by the tolerance). Levenberg-Marquardt's own stop (a relative reduction
    // below 1e-13) took half as long again on the profiles of `product` on 100 000 points of
    // distinct sizes, zigzagging across the onsets of yield for gains far below what could
    // move an end. Not for `min` ([`Residuals::kinked`]), whose promise is one branch's; not
    // for small data, whose inner fits are cheap and whose profiles' global inner searches
    // (run where the local value is at or above the threshold) cost more when the local values
    // stop that much higher: the 120 shipped points' `--model all` took 1.7% more instructions.
    let promise = 0.01 * CROSSING_TOL * 2.0 * delta / step;
    let enough = |_: f64| promise;
    let enough = (sums::is_large(obj.n_residuals()) && promise.is_finite())
        .then_some(&enough as &dyn Fn(f64) -> f64);
    let failed_inner = Cell::new(0u32);
    let warm = RefCell::new(vec![(theta[j], theta.to_vec())]);
    let lower_found = RefCell::new(None::<Vec<f64>>);
    // Rounds started again from a point the inner search found (its valley, not the local
    // minimisation's: the warm starts begin again there); from LAZY_ROUNDS on, the inner
    // search runs at every point at or above the threshold.
    let rounds = Cell::new(0usize);
    // The points of the current round's crossing whose local value is at or above the
    // threshold, not yet checked by the inner search.
    let unchecked = RefCell::new(Vec::<Point>::new());
    let found = |c: f64, th: &Vec<f64>| {
        if c < beaten && lower_found.borrow().is_none() {
            *lower_found.borrow_mut() = Some(th.clone());
        }
    };
    // The inner search at a point whose local value is at or above the threshold: its value
    // and point (the local ones where it does not cover the parameter).
    let global = |(t, th, c, converged): Point| -> Result<(f64, Vec<f64>)> {
        let g = inner.expect("only called with an inner search");
        Ok(match g(j, t, (&th, c, converged), threshold)? {
            Some((th, c, shown)) => {
                if !shown {
                    failed_inner.set(failed_inner.get() + 1);
                }
                (c, th)
            }
            None => {
                if !converged {
                    failed_inner.set(failed_inner.get() + 1);
                }
                (c, th)
            }
        })
    };
    let mut profile = |t: f64| -> Result<f64> {
        let mut start = match &warm.borrow()[..] {
            // Only the minimum so far: along the covariance's valley (exact for a quadratic).
            [_] if rounds.get() == 0 => along_covariance(theta, cov, j, t, lower, upper),
            // Only the point a new round starts from: from there.
            [(_, th)] => Some(th.clone()),
            w => warm_start(w, t, lower, upper),
        }
        .unwrap_or_else(|| theta.to_vec());
        start[j] = t;
        let (c, th) = if k == 1 {
            (lsq::chi2(obj, &start)?, start)
        } else {
            let mut free = vec![true; k];
            free[j] = false;
            let r = lsq::levenberg_marquardt_to(obj, &start, &free, &lm, enough)?;
            if r.chi2 < threshold || inner.is_none() {
                // Below the threshold the profile is too (it is at most this value), converged
                // or not; without an inner search the local value stands.
                if !r.converged {
                    failed_inner.set(failed_inner.get() + 1);
                }
                (r.chi2, r.theta)
            } else if rounds.get() >= LAZY_ROUNDS {
                global((t, r.theta, r.chi2, r.converged))?
            } else {
                unchecked
                    .borrow_mut()
                    .push((t, r.theta.clone(), r.chi2, r.converged));
                (r.chi2, r.theta)
            }
        };
        found(c, &th);
        warm.borrow_mut().push((t, th));
        Ok(c)
    };
    let (mut t0, mut v0) = (theta[j], chi2_from);
    let mut first_step = step;
    let c = loop {
        let c = profile_crossing(
            &mut profile,
            t0,
            v0,
            limit,
            first_step,
            threshold,
            CROSSING_TOL,
        )?;
        let outer = std::mem::take(&mut *unchecked.borrow_mut())
            .into_iter()
            .min_by(|a, b| ((a.0 - t0) * dir).total_cmp(&((b.0 - t0) * dir)));
        let (Crossing::At(_), Some(outer), false) = (&c, outer, lower_found.borrow().is_some())
        else {
            break c;
        };
        let t = outer.0;
        let (v, th) = global(outer)?;
        found(v, &th);
        if !(v < threshold) || lower_found.borrow().is_some() {
            break c;
        }
        // The outer end is below the threshold: the crossing lies beyond it, and the profile
        // follows the valley the inner search found there (warm starts from the points before,
        // in the valley the local minimisation followed, would lead back into it).
        *warm.borrow_mut() = vec![(t, th)];
        rounds.set(rounds.get() + 1);
        first_step = restart_step((theta[j], chi2_from), (t, v), threshold, step);
        (t0, v0) = (t, v);
    };
    if let Some(t) = lower_found.into_inner() {
        return Ok(End::Lower(t));
    }
    let side = match c {
        Crossing::At(t) => Side::At(t),
        Crossing::Open => Side::Open,
        Crossing::Failed(why) => Side::Lost(why),
    };
    Ok(End::Side(side, failed_inner.get()))
}

/// The first step of a crossing searched again from `restart` = (t0, v0), a point below
/// `threshold` just beyond the last crossing's bracket: to 5% beyond where the parabola through
/// `center` = (t_c, v_c), where this end's search began (the minimum, for the profiles from
/// it), and the restart point reaches the threshold, as [`profile_crossing`]'s second step goes
/// (a profile is close to a parabola about its minimum); at least the crossings' tolerance, at
/// most `step`, and `step` where the parabola says nothing (v0 not above v_c). Why: the restart
/// point lies just below the threshold, so the step from the minimum (about 1.96 standard
/// errors) overshot the crossing far: by 27 in chi2 on `product`'s eta on 100 000 points of
/// distinct sizes, its inner fits then starting far from their valley (9 to 12
/// Levenberg-Marquardt iterations each, against 1 to 3).
fn restart_step(center: (f64, f64), restart: (f64, f64), threshold: f64, step: f64) -> f64 {
    let ((t_c, v_c), (t0, v0)) = (center, restart);
    let ratio = ((threshold - v_c) / (v0 - v_c)).sqrt();
    let to = (t0 - t_c).abs();
    let d = (1.05 * ratio - 1.0) * to;
    if v0 > v_c && d.is_finite() {
        // max then min: never a panic, also where `step` is below the tolerance.
        d.max(CROSSING_TOL).min(step)
    } else {
        step
    }
}

/// An end of an interval moved past a point of the 95% region that the profile from the
/// minimum had not reached ([`extend_to_region`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Moved {
    /// The parameter and the end (0 lower, 1 upper).
    pub j: usize,
    pub s: usize,
    /// The end before, in internal coordinates.
    pub from: f64,
    /// The point passed: its parameters (internal coordinates) and chi2.
    pub point: Vec<f64>,
    pub chi2: f64,
}

/// What [`extend_to_region`] did.
#[derive(Debug, Clone, PartialEq)]
pub enum Extension {
    /// The ends moved (each end of `Profiles` now lies beyond every point given below the
    /// threshold, or is where it was with a side the search could not extend: Lost or Open).
    Done(Vec<Moved>),
    /// A profile point below the minimum: the caller refits from it.
    Lower(Vec<f64>),
}

/// Moves each found end of `p` past the points of `inside` (parameters in internal coordinates,
/// chi2 as the objective's) that lie below the threshold chi2_min + delta but beyond the end
/// (by more than 1e-6, above the crossings' tolerance): the 95% region is
/// {t : P_j(t) <= threshold}, and such a point shows P_j <= its chi2 there, so the interval must
/// reach it. Why it is needed: the profile from the minimum follows one valley (its inner
/// minimisation is local), and the region can have a part it does not reach, beyond a ridge of
/// the profile (a second valley) or where the inner minimisation stopped on a plateau of the
/// other parameter. The interval reported is then the hull of what is known of the region
/// (conservative: the region need not be connected). From the farthest such point, the
/// profile is searched outwards as from the minimum (warm-started there); an
/// end it cannot find stays where it was (the caller's check then warns).
pub fn extend_to_region(
    obj: &(impl Residuals + Sync),
    chi2_min: f64,
    cov: &Covariance,
    p: &mut Profiles,
    inside: &[(Vec<f64>, f64)],
    inner: Option<&Inner>,
) -> Result<Extension> {
    let threshold = chi2_min + p.delta;
    let mut moved = Vec::new();
    for j in 0..p.sides.len() {
        for s in 0..2 {
            let Side::At(end) = p.sides[j][s] else {
                continue;
            };
            let dir = if s == 0 { -1.0 } else { 1.0 };
            let beyond = |th: &Vec<f64>| (th[j] - end) * dir > 1e-6;
            let Some((th, c)) = inside
                .iter()
                .filter(|(th, c)| *c < threshold && th.len() == p.sides.len() && beyond(th))
                .max_by(|a, b| ((a.0[j] - b.0[j]) * dir).total_cmp(&0.0))
            else {
                continue;
            };
            let at = Around {
                chi2_min,
                cov,
                delta: p.delta,
                inner,
            };
            match profile_end(obj, (th, *c), &at, j, s)? {
                End::Lower(t) => return Ok(Extension::Lower(t)),
                End::Side(side, failed) => {
                    p.unconverged[j] += failed;
                    if matches!(side, Side::At(_) | Side::Open) {
                        p.sides[j][s] = side;
                        moved.push(Moved {
                            j,
                            s,
                            from: end,
                            point: th.clone(),
                            chi2: *c,
                        });
                    }
                }
            }
        }
    }
    Ok(Extension::Done(moved))
}

/// The start of the inner minimisation at t when only the minimum is known: the other
/// parameters where the quadratic approximation of chi2 at the minimum has its least value with
/// theta_j = t, theta_k + (C_kj / C_jj)(t - theta_j) (the regression of theta_k on theta_j under
/// the covariance C), kept in the box. From the minimum itself the first profile point took
/// Levenberg-Marquardt four to six iterations on the fits of 100 000 points; the later ones,
/// warm-started along the profile, one. None if C_jj is not a positive number.
fn along_covariance(
    theta: &[f64],
    cov: &Covariance,
    j: usize,
    t: f64,
    lower: &[f64],
    upper: &[f64],
) -> Option<Vec<f64>> {
    let cjj = cov.matrix[(j, j)];
    if !(cjj > 0.0 && cjj.is_finite()) {
        return None;
    }
    Some(
        (0..theta.len())
            .map(|k| {
                let x = theta[k] + cov.matrix[(k, j)] / cjj * (t - theta[j]);
                kept_in_box(x, lower[k], upper[k], theta[k])
            })
            .collect(),
    )
}

/// The start of the inner minimisation at t: the other parameters on the line through the two
/// profile points already computed nearest to t (the valley's direction, so the start is off
/// it only by the valley's curvature), kept in the box; the nearest point's when there is one
/// (or the two share their t).
fn warm_start(warm: &[(f64, Vec<f64>)], t: f64, lower: &[f64], upper: &[f64]) -> Option<Vec<f64>> {
    let by_distance =
        |a: &&(f64, Vec<f64>), b: &&(f64, Vec<f64>)| (a.0 - t).abs().total_cmp(&(b.0 - t).abs());
    let (t1, th1) = warm.iter().min_by(by_distance)?;
    let Some((t2, th2)) = warm.iter().filter(|p| p.0 != *t1).min_by(by_distance) else {
        return Some(th1.clone());
    };
    let s = (t - t1) / (t2 - t1);
    Some(
        (0..th1.len())
            .map(|k| kept_in_box(th1[k] + s * (th2[k] - th1[k]), lower[k], upper[k], th1[k]))
            .collect(),
    )
}

/// x kept in [lo, hi]; `fallback` where x is not a number (a start must be finite).
fn kept_in_box(x: f64, lo: f64, hi: f64, fallback: f64) -> f64 {
    if x.is_finite() {
        x.max(lo).min(hi)
    } else {
        fallback
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::lsq::tests::Line;

    /// chi2(t) = min(t^2, (t - 6)^2 + 1) on [-20, hi]: two valleys, the second's part of the
    /// 95% region (chi2 <= 3.84) is [6 - sqrt(2.84), 6 + sqrt(2.84)], beyond a ridge the
    /// profile from the minimum at t = 0 does not cross.
    struct TwoValleys {
        lo: [f64; 1],
        hi: [f64; 1],
    }

    impl Residuals for TwoValleys {
        fn n_params(&self) -> usize {
            1
        }
        fn n_residuals(&self) -> usize {
            1
        }
        fn residuals(&self, t: &[f64], out: &mut [f64]) -> Result<()> {
            let x = t[0];
            out[0] = (x * x).min((x - 6.0).powi(2) + 1.0).sqrt();
            Ok(())
        }
        fn lower(&self) -> &[f64] {
            &self.lo
        }
        fn upper(&self) -> &[f64] {
            &self.hi
        }
        fn fd_step(&self) -> f64 {
            1e-6
        }
    }

    #[test]
    fn an_end_moves_past_a_part_of_the_region_beyond_a_ridge() {
        // Closed forms: the first valley's ends +-sqrt(3.84), the second's upper end
        // 6 + sqrt(2.84); crossings are found to 1e-7 in t, so 1e-6 covers them.
        let cov = Covariance {
            matrix: nalgebra::DMatrix::from_element(1, 1, 1.0),
            no_effect: vec![false],
            degenerate: vec![false],
        };
        let at = |side: &Side| match side {
            Side::At(t) => *t,
            other => panic!("{other:?}"),
        };
        let intervals = |problem: &TwoValleys| match profile_intervals_of(
            problem,
            &[0.0],
            0.0,
            &cov,
            1.0,
            None,
        )
        .unwrap()
        {
            ProfileOutcome::Done(p) => p,
            other => panic!("no lower minimum here: {other:?}"),
        };
        let problem = TwoValleys {
            lo: [-20.0],
            hi: [20.0],
        };
        let mut p = intervals(&problem);
        let half = CHI2_1DOF_95.sqrt();
        assert!((at(&p.sides[0][0]) + half).abs() < 1e-6, "{:?}", p.sides);
        assert!((at(&p.sides[0][1]) - half).abs() < 1e-6, "{:?}", p.sides);
        // Points inside the interval or above the threshold move nothing; the second valley's
        // minimum (chi2 1 at t = 6) moves the upper end to that valley's far crossing.
        let inside = [
            (vec![-1.0], 1.0),
            (vec![3.0], 9.0),
            (vec![6.0], 1.0),
            (vec![5.0], 2.0),
        ];
        let Extension::Done(moved) =
            extend_to_region(&problem, 0.0, &cov, &mut p, &inside, None).unwrap()
        else {
            panic!("no lower minimum here");
        };
        assert!((at(&p.sides[0][0]) + half).abs() < 1e-6, "{:?}", p.sides);
        let far = 6.0 + (CHI2_1DOF_95 - 1.0).sqrt();
        assert!((at(&p.sides[0][1]) - far).abs() < 1e-6, "{:?}", p.sides);
        assert_eq!(moved.len(), 1);
        let m = &moved[0];
        assert_eq!((m.j, m.s, m.point.clone(), m.chi2), (0, 1, vec![6.0], 1.0));
        assert!((m.from - half).abs() < 1e-6);
        // With the box ending inside the second valley's part the end opens.
        let problem = TwoValleys {
            lo: [-20.0],
            hi: [7.0],
        };
        let mut p = intervals(&problem);
        extend_to_region(&problem, 0.0, &cov, &mut p, &inside, None).unwrap();
        assert_eq!(p.sides[0][1], Side::Open);
    }

    /// chi2(t, x) = min over k < valleys of 0.5 k + (t / (1 + k))^2 + (x - 5 k)^2: valleys in
    /// x five apart (ridges between them), each shallower in t than the one before. The profile
    /// over t is min_k (0.5 k + (t / (1 + k))^2), which reaches 3.84 at the largest of
    /// (1 + k) sqrt(3.84 - 0.5 k); Levenberg-Marquardt over x, started in valley 0, stays there
    /// and crosses at 1.96.
    struct Valleys {
        valleys: usize,
    }

    impl Valleys {
        fn best(&self, t: f64, x: f64) -> (f64, [f64; 3]) {
            (0..self.valleys)
                .map(|k| {
                    let k = k as f64;
                    let r = [(0.5 * k).sqrt(), t / (1.0 + k), x - 5.0 * k];
                    (r.iter().map(|v| v * v).sum::<f64>(), r)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .expect("a valley")
        }

        /// The end of the profile's interval: the largest valley crossing.
        fn end(&self) -> f64 {
            (0..self.valleys)
                .map(|k| (1.0 + k as f64) * (CHI2_1DOF_95 - 0.5 * k as f64).sqrt())
                .fold(f64::NEG_INFINITY, f64::max)
        }
    }

    impl Residuals for Valleys {
        fn n_params(&self) -> usize {
            2
        }
        fn n_residuals(&self) -> usize {
            3
        }
        fn residuals(&self, th: &[f64], out: &mut [f64]) -> Result<()> {
            out.copy_from_slice(&self.best(th[0], th[1]).1);
            Ok(())
        }
        fn lower(&self) -> &[f64] {
            &[-20.0, -50.0]
        }
        fn upper(&self) -> &[f64] {
            &[20.0, 50.0]
        }
        fn fd_step(&self) -> f64 {
            1e-7
        }
    }

    /// Where the local minimisation crosses the threshold in the wrong valley, the inner search
    /// finds the point below it, and the crossing is searched again from there, ending at the
    /// profile's own crossing; the inner search runs once per crossing, not at every point at
    /// or above the threshold (until LAZY_ROUNDS rounds have passed).
    #[test]
    fn the_inner_search_checks_each_crossings_outer_point_and_the_profile_goes_on_from_there() {
        let cov = Covariance {
            matrix: nalgebra::DMatrix::identity(2, 2),
            no_effect: vec![false; 2],
            degenerate: vec![false; 2],
        };
        // The inner search at every point at or above the threshold made 1, 4 and 4 calls;
        // six valleys take LAZY_ROUNDS rounds of one call each, then that (6 calls).
        for (valleys, most_calls) in [(1, 1), (2, 2), (6, usize::MAX)] {
            let problem = Valleys { valleys };
            let calls = std::sync::atomic::AtomicUsize::new(0);
            // The global minimum over x at t (the valleys' floors, x = 5 k), shown.
            let inner = |j: usize, t: f64, _: (&[f64], f64, bool), _: f64| {
                assert_eq!(j, 0, "only t is profiled here");
                calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let (c, k) = (0..problem.valleys)
                    .map(|k| (problem.best(t, 5.0 * k as f64).0, k))
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .expect("a valley");
                Ok(Some((vec![t, 5.0 * k as f64], c, true)))
            };
            let at = Around {
                chi2_min: 0.0,
                cov: &cov,
                delta: CHI2_1DOF_95,
                inner: Some(&inner),
            };
            let End::Side(Side::At(end), failed) =
                profile_end(&problem, (&[0.0, 0.0], 0.0), &at, 0, 1).unwrap()
            else {
                panic!("{valleys} valleys: an end");
            };
            // Crossings are found to 1e-7 in t.
            assert!(
                (end - problem.end()).abs() < 1e-6,
                "{valleys} valleys: {end} against {}",
                problem.end()
            );
            assert_eq!(failed, 0);
            let n = calls.into_inner();
            assert!(n <= most_calls, "{valleys} valleys: {n} inner searches");
        }
    }

    #[test]
    fn a_restart_steps_to_just_beyond_the_parabolas_crossing() {
        // P(t) = 1 + (t - 2)^2 crosses 4.84 at t = 2 + sqrt(3.84) = 3.9596. Restarted at
        // t0 = 3.95 (P = 4.8025), the parabola through (2, 1) and the restart point is the
        // profile itself, so the first step goes to 5% beyond its crossing, measured from the
        // centre: 1.05 sqrt(3.84) - 1.95 = 0.1076; the step from the minimum, 0.5, went to
        // P = 12.9.
        let p = |t: f64| 1.0 + (t - 2.0) * (t - 2.0);
        let root = 2.0 + 3.84f64.sqrt();
        let s = restart_step((2.0, 1.0), (3.95, p(3.95)), 4.84, 0.5);
        assert!((s - (1.05 * 3.84f64.sqrt() - 1.95)).abs() < 1e-12, "{s}");
        // Fewer profile points to the same crossing (to the tolerance asked).
        let count = |step: f64| {
            let n = Cell::new(0);
            let f = |t: f64| {
                n.set(n.get() + 1);
                Ok(p(t))
            };
            let c = profile_crossing(f, 3.95, p(3.95), 100.0, step, 4.84, 1e-10).unwrap();
            let Crossing::At(t) = c else { panic!("{c:?}") };
            assert!((t - root).abs() < 1e-9, "{t}");
            n.get()
        };
        let (restarted, from_minimum) = (count(s), count(0.5));
        assert!(
            restarted < from_minimum,
            "{restarted} against {from_minimum}"
        );
        // Restarted just below the threshold: 5% of the distance from the centre.
        let s = restart_step((2.0, 1.0), (3.96, 4.84 - 1e-12), 4.84, 0.5);
        assert!((s - 0.05 * 1.96).abs() < 1e-9, "{s}");
        // Capped by the step, floored at the tolerance, and the step where the parabola says
        // nothing (the restart point not above the centre).
        assert_eq!(restart_step((2.0, 1.0), (2.1, 1.01), 4.84, 0.5), 0.5);
        assert_eq!(restart_step((2.0, 1.0), (2.5, 0.5), 4.84, 0.5), 0.5);
        assert_eq!(restart_step((2.0, 1.0), (2.5, 1.0), 4.84, 0.5), 0.5);
        assert_eq!(
            restart_step((2.0, 1.0), (2.0, 4.0), 4.84, 0.5),
            CROSSING_TOL
        );
        assert_eq!(restart_step((2.0, 1.0), (3.9, 4.0), 4.84, 1e-9), 1e-9);
    }

    #[test]
    fn warm_starts_follow_the_line_through_the_two_nearest_points() {
        let (lo, hi) = ([-10.0, -10.0], [10.0, 10.0]);
        // Points of the valley x1 = 2 t + 1 (and a far one that must not be used).
        let warm = vec![
            (0.0, vec![0.0, 1.0]),
            (1.0, vec![1.0, 3.0]),
            (-5.0, vec![-5.0, 100.0]),
        ];
        // Between and beyond the two nearest: on their line, exactly (binary fractions).
        assert_eq!(warm_start(&warm, 0.5, &lo, &hi), Some(vec![0.5, 2.0]));
        assert_eq!(warm_start(&warm, 2.0, &lo, &hi), Some(vec![2.0, 5.0]));
        // Kept in the box; one point (or two at the same t) is a start as it is.
        assert_eq!(warm_start(&warm, 6.0, &lo, &hi), Some(vec![6.0, 10.0]));
        assert_eq!(warm_start(&warm[..1], 3.0, &lo, &hi), Some(vec![0.0, 1.0]));
        let twice = vec![(1.0, vec![1.0, 3.0]), (1.0, vec![1.0, 4.0])];
        assert_eq!(warm_start(&twice, 2.0, &lo, &hi), Some(vec![1.0, 3.0]));
        assert_eq!(warm_start(&[], 2.0, &lo, &hi), None);
    }

    #[test]
    fn the_first_start_follows_the_covariance() {
        use nalgebra::DMatrix;
        let cov = |m: [f64; 4]| Covariance {
            matrix: DMatrix::from_row_slice(2, 2, &m),
            no_effect: vec![false; 2],
            degenerate: vec![false; 2],
        };
        let (lo, hi) = ([-10.0, -10.0], [10.0, 10.0]);
        // C_10 / C_00 = 0.5: theta_1 moves half as far as theta_0 (binary fractions: exact).
        let c = cov([4.0, 2.0, 2.0, 3.0]);
        assert_eq!(
            along_covariance(&[1.0, 2.0], &c, 0, 3.0, &lo, &hi),
            Some(vec![3.0, 3.0])
        );
        // Profiling theta_1: C_01 / C_11 = 2/3 of its move.
        assert_eq!(
            along_covariance(&[1.0, 2.0], &c, 1, 5.0, &lo, &hi),
            Some(vec![3.0, 5.0])
        );
        // Kept in the box; no start without a positive variance; NaN entries stay put.
        assert_eq!(
            along_covariance(&[1.0, 2.0], &c, 0, 41.0, &lo, &hi),
            Some(vec![10.0, 10.0])
        );
        assert_eq!(
            along_covariance(&[1.0, 2.0], &cov([0.0, 0.0, 0.0, 1.0]), 0, 3.0, &lo, &hi),
            None
        );
        let nan = cov([4.0, f64::NAN, f64::NAN, 3.0]);
        assert_eq!(
            along_covariance(&[1.0, 2.0], &nan, 0, 3.0, &lo, &hi),
            Some(vec![3.0, 2.0])
        );
    }

    #[test]
    fn a_lines_profile_interval_is_its_closed_form() {
        // 10 points: the ends one after another on this thread.
        line_intervals_are_the_closed_form(10);
    }

    #[test]
    fn a_lines_profile_interval_is_its_closed_form_with_the_ends_side_by_side() {
        // Large data (sums::is_large): the four ends run side by side on the pool.
        let n = sums::PARALLEL_MIN_POINTS + 1000;
        assert!(sums::is_large(n));
        line_intervals_are_the_closed_form(n);
    }

    fn line_intervals_are_the_closed_form(n: usize) {
        let x: Vec<f64> = (0..n).map(|i| (i % 10) as f64).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, &x)| 1.0 + 0.5 * x + [0.3, -0.2, 0.1, -0.4, 0.2][i % 5])
            .collect();
        // Closed-form least squares: slope = Sxy/Sxx, var(slope) = 1/Sxx (sigma = 1).
        let nf = n as f64;
        let (mx, my) = (x.iter().sum::<f64>() / nf, y.iter().sum::<f64>() / nf);
        let sxx: f64 = x.iter().map(|x| (x - mx).powi(2)).sum();
        let sxy: f64 = x.iter().zip(&y).map(|(x, y)| (x - mx) * (y - my)).sum();
        let slope = sxy / sxx;
        let c0 = my - slope * mx;
        let p = Line {
            x,
            y,
            lo: vec![-100.0, -100.0],
            hi: vec![100.0, 100.0],
        };
        let chi2 = lsq::chi2(&p, &[c0, slope]).unwrap();
        let mut f0 = vec![0.0; n];
        p.residuals(&[c0, slope], &mut f0).unwrap();
        let cov = lsq::covariance(&lsq::jacobian(&p, &[c0, slope], &[true, true], &f0).unwrap());
        let out = profile_intervals_of(&p, &[c0, slope], chi2, &cov, 1.0, None).unwrap();
        let ProfileOutcome::Done(pr) = out else {
            panic!("{out:?}")
        };
        let half = (CHI2_1DOF_95 / sxx).sqrt();
        // Crossings are found to 1e-7 in t; the inner LM stops at 1e-10: 1e-6 covers both.
        match &pr.sides[1] {
            [Side::At(a), Side::At(b)] => {
                assert!((a - (slope - half)).abs() < 1e-6, "{a}");
                assert!((b - (slope + half)).abs() < 1e-6, "{b}");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(pr.unconverged, vec![0, 0]);
        // Started two standard errors of c0 from the minimum (chi2 4 above it, for a line
        // exactly), a profile finds a lower point (at one standard error it is 1 above).
        let sd0 = cov.matrix[(0, 0)].sqrt();
        let off = profile_intervals_of(&p, &[c0 + 2.0 * sd0, slope], chi2 + 4.0, &cov, 1.0, None)
            .unwrap();
        assert!(matches!(off, ProfileOutcome::Lower(_)), "{off:?}");
    }
}
