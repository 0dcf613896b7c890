//! Local polishes of the global search ([`super::search`]): each starts at a candidate the
//! branch and bound proposes and ends at a local minimum of chi2.
//!
//! - one parameter: Brent's method inside the candidate's bracket ([`polish_brent`]);
//! - more: Levenberg-Marquardt ([`polish_lm`]); for the minima closest to the best, line searches
//!   along the principal axes of the covariance ([`polish_valleys`]: Levenberg-Marquardt can stop
//!   in a long flat valley with shallow wiggles) and, where Levenberg-Marquardt ran out of
//!   iterations, damped Newton on chi2 ([`polish_newton`]). The kinks of `min` are handled in
//!   [`super::kinks`], the power law's collinear A and a in [`super::powerlaw`].
//!
//! **Known answers** (test below): noise-free data give back their planted parameters.

use super::lsq::{self, LmOptions};
use super::objective::Objective;
use super::scalar;
use super::search::tolerance;
use crate::error::Result;

/// A local minimum (or the best point) found by the search.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    pub theta: Vec<f64>,
    pub chi2: f64,
    pub converged: bool,
    pub reason: String,
}

/// Levenberg-Marquardt over every parameter from `start`, stopped where the Gauss-Newton step
/// promises less than a hundredth of the search's tolerance ([`lsq::levenberg_marquardt_to`]).
pub fn polish_lm(obj: &Objective, start: &[f64]) -> Result<Found> {
    let all = vec![true; start.len()];
    // A hundredth of the search's tolerance: the minimum to far better than the search states
    // (not for `min`, whose kinks make the promise one branch's: [`lsq::Residuals::kinked`]).
    let enough = |chi2: f64| 0.01 * tolerance(obj, chi2);
    let r = lsq::levenberg_marquardt_to(obj, start, &all, &LmOptions::default(), Some(&enough))?;
    Ok(Found {
        theta: r.theta,
        chi2: r.chi2,
        converged: r.converged,
        reason: r.reason.to_string(),
    })
}

/// Brent's method inside the bracket of a grid minimum (value `at_node` at `t`); the node itself
/// is kept when Brent ends higher (a minimum on the edge of the box).
pub fn polish_brent(obj: &Objective, t: f64, lo: f64, hi: f64, at_node: f64) -> Result<Found> {
    if !(lo < hi) {
        return Ok(Found {
            theta: vec![t],
            chi2: at_node,
            converged: false,
            reason: "empty bracket".into(),
        });
    }
    // 1e-10 in the log parameter: far below any standard error a fit can have.
    let m = scalar::brent_minimize(|x| lsq::chi2(obj, &[x]), lo, hi, 1e-10)?;
    if m.fx.is_nan() || at_node < m.fx {
        return Ok(Found {
            theta: vec![t],
            chi2: at_node,
            converged: m.converged,
            reason: m.reason,
        });
    }
    Ok(Found {
        theta: vec![m.x],
        chi2: m.fx,
        converged: m.converged,
        reason: m.reason,
    })
}

/// Line searches from a local minimum along the principal axes of its covariance (the valley
/// first), each a grid of `VALLEY_POINTS` over +-[`VALLEY_REACH`] standard errors then Brent's
/// method around the best grid point, followed by Levenberg-Marquardt from the lowest point;
/// repeated while a round gains more than a hundredth of the search's tolerance.
/// Levenberg-Marquardt can stop on a kink of `min` (its Gauss-Newton model sees one branch) or
/// in a long flat valley with shallow wiggles; a derivative-free line search along the valley
/// does not.
///
/// `may_beat(theta)`: false where the global search has proved chi2 no lower than its
/// tolerance below the best minimum known ([`super::bnb::Bnb::may_hold_below`]); the scan's
/// grid points there are not evaluated (nothing they could show would change the answer by more
/// than the tolerance). `|_| true` scans every point.
pub fn polish_valleys(
    obj: &Objective,
    start: Found,
    may_beat: &dyn Fn(&[f64]) -> bool,
) -> Result<Found> {
    let k = start.theta.len();
    let mut best = start;
    for _ in 0..VALLEY_ROUNDS {
        let before = best.chi2;
        for (dir, sd) in principal_axes(obj, &best.theta)? {
            // The part of the line within reach that stays inside the box.
            let (mut amin, mut amax) = (-VALLEY_REACH * sd, VALLEY_REACH * sd);
            for (j, &dj) in dir.iter().enumerate().take(k) {
                if dj != 0.0 {
                    let a = (obj.lower[j] - best.theta[j]) / dj;
                    let b = (obj.upper[j] - best.theta[j]) / dj;
                    amin = amin.max(a.min(b));
                    amax = amax.min(a.max(b));
                }
            }
            if !(amax > amin) {
                continue;
            }
            let base = best.theta.clone();
            let at = |a: f64| -> Vec<f64> {
                (0..k)
                    .map(|j| (base[j] + a * dir[j]).clamp(obj.lower[j], obj.upper[j]))
                    .collect()
            };
            let grid: Vec<f64> = (0..VALLEY_POINTS)
                .map(|i| amin + (amax - amin) * i as f64 / (VALLEY_POINTS - 1) as f64)
                .collect();
            let vals = grid
                .iter()
                .map(|&a| {
                    let t = at(a);
                    // A point the bounds exclude is left out as NaN is (never the best).
                    if may_beat(&t) {
                        lsq::chi2(obj, &t)
                    } else {
                        Ok(f64::NAN)
                    }
                })
                .collect::<Result<Vec<f64>>>()?;
            let Some(i) = (0..grid.len())
                .filter(|&i| !vals[i].is_nan())
                .min_by(|&x, &y| vals[x].total_cmp(&vals[y]))
            else {
                continue;
            };
            let (mut x, mut fx) = (grid[i], vals[i]);
            let (lo, hi) = (grid[i.saturating_sub(1)], grid[(i + 1).min(grid.len() - 1)]);
            if lo < hi {
                // Along a principal axis chi2 ~ chi2_min + (a/sd)^2 (sd from the error bars as
                // given), so missing the line's minimum by 1e-4 sqrt(min(s, 1)) sd costs at most
                // 1e-8 s (s the chi2 scale, below 1 only without error bars), a hundredth of the
                // search's tolerance (1e-6 s and more); not below the 1e-12 it was before (a
                // NaN scale gives that).
                let s = obj.scale(best.chi2).min(1.0);
                let tol = (1e-4 * sd * s.sqrt()).max(1e-12);
                let m = scalar::brent_minimize(|a| lsq::chi2(obj, &at(a)), lo, hi, tol)?;
                if m.fx < fx {
                    (x, fx) = (m.x, m.fx);
                }
            }
            if fx < best.chi2 {
                best = Found {
                    theta: at(x),
                    chi2: fx,
                    converged: best.converged,
                    reason: best.reason.clone(),
                };
            }
        }
        if best.chi2 < before {
            let again = polish_lm(obj, &best.theta)?;
            if again.chi2 <= best.chi2 {
                best = again;
            }
        }
        // A round that gained less than a hundredth of the search's tolerance (where
        // [`polish_lm`] stops, but for `min`) found what Levenberg-Marquardt had left, not a
        // valley.
        if !(best.chi2 < before - 0.01 * tolerance(obj, before)) {
            break;
        }
    }
    Ok(best)
}

/// Parameters within this fraction of their box's width from an end are tried at that end
/// ([`polish_at_bounds`]).
const BOUND_NEAR: f64 = 0.01;

/// A minimum on the box's boundary: where some parameters end close to an end of their box, they
/// are pinned at that end and Levenberg-Marquardt polishes the others, then all of them from
/// there (so a parameter can leave the end again); the lowest of the three points is kept.
/// Levenberg-Marquardt with its steps clamped to the box creeps along a valley that runs into a
/// corner: the power law on two nearly equal sizes (ln A and a nearly collinear) with A already
/// at its lower end and a 0.0325 from its own stopped 2.5 above the corner's chi2 (955.66
/// against 958.21, seed 3386 of the randomized test), and the profiles' refits crept after it.
pub fn polish_at_bounds(obj: &Objective, start: Found) -> Result<Found> {
    let k = start.theta.len();
    let mut pinned = start.theta.clone();
    let mut free = vec![true; k];
    for j in 0..k {
        let (lo, hi) = (obj.lower[j], obj.upper[j]);
        let near = BOUND_NEAR * (hi - lo);
        if start.theta[j] - lo <= near {
            (pinned[j], free[j]) = (lo, false);
        } else if hi - start.theta[j] <= near {
            (pinned[j], free[j]) = (hi, false);
        }
    }
    if free.iter().all(|&f| f) {
        return Ok(start);
    }
    let at_ends = if free.iter().any(|&f| f) {
        let r = lsq::levenberg_marquardt(obj, &pinned, &free, &LmOptions::default())?;
        Found {
            theta: r.theta,
            chi2: r.chi2,
            converged: r.converged,
            reason: r.reason.to_string(),
        }
    } else {
        Found {
            chi2: lsq::chi2(obj, &pinned)?,
            theta: pinned,
            converged: true,
            reason: "every parameter at an end of its box".into(),
        }
    };
    if !(at_ends.chi2 < start.chi2) {
        return Ok(start);
    }
    let all = polish_lm(obj, &at_ends.theta)?;
    Ok(if all.chi2 <= at_ends.chi2 {
        all
    } else {
        at_ends
    })
}

/// Unit directions of the principal axes of (J^T J)^-1 at theta and the standard error along
/// each (error bars as given); a direction the data do not determine gets 1/256 of the box.
fn principal_axes(obj: &Objective, theta: &[f64]) -> Result<Vec<(Vec<f64>, f64)>> {
    let k = theta.len();
    let mut f0 = vec![0.0; obj.ev.len()];
    lsq::residuals_checked(obj, theta, &mut f0)?;
    let jac = lsq::jacobian(obj, theta, &vec![true; k], &f0)?;
    let jtj = jac.transpose() * &jac;
    let diag = (0..k)
        .map(|j| (obj.upper[j] - obj.lower[j]).powi(2))
        .sum::<f64>()
        .sqrt();
    if jtj.iter().any(|x| !x.is_finite()) {
        return Ok((0..k)
            .map(|j| {
                let mut d = vec![0.0; k];
                d[j] = 1.0;
                (d, diag / 256.0)
            })
            .collect());
    }
    let eig = jtj.symmetric_eigen();
    let lmax = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    let mut out: Vec<(Vec<f64>, f64)> = (0..k)
        .map(|q| {
            let lam = eig.eigenvalues[q];
            let sd = if lam > 1e-12 * lmax {
                (1.0 / lam).sqrt().min(diag / 256.0)
            } else {
                diag / 256.0
            };
            (eig.eigenvectors.column(q).iter().copied().collect(), sd)
        })
        .collect();
    out.sort_by(|a, b| b.1.total_cmp(&a.1));
    Ok(out)
}

/// Damped Newton on chi2 itself, gradient and Hessian by central differences: for the narrow
/// curved valleys where a point starts to yield, whose curvature comes from the model's second
/// derivative (the Gauss-Newton matrix of Levenberg-Marquardt omits it, so Levenberg-Marquardt
/// creeps there). Steps (H + lambda I) d = -g with lambda raised until chi2 falls (Nocedal &
/// Wright, "Numerical Optimization", 2nd ed., 2006, sec. 3.4); projected onto the box; at most
/// NEWTON_ITERS iterations; stops when a step no longer lowers chi2.
pub fn polish_newton(obj: &Objective, start: Found) -> Result<Found> {
    let k = start.theta.len();
    let mut best = start;
    // Difference step: chi2 is accurate to ~1e-14 relative, so the Hessian's rounding error is
    // ~1e-14 chi2 / h^2 = 1e-6 chi2 at h = 1e-4, below the curvature of any valley that matters.
    let h = 1e-4;
    let f = |t: &[f64]| -> Result<f64> {
        let c: Vec<f64> = (0..k)
            .map(|j| t[j].clamp(obj.lower[j], obj.upper[j]))
            .collect();
        lsq::chi2(obj, &c)
    };
    let mut lambda = 0.0;
    for _ in 0..NEWTON_ITERS {
        let x = best.theta.clone();
        let f0 = best.chi2;
        let mut g = nalgebra::DVector::zeros(k);
        let mut hm = nalgebra::DMatrix::zeros(k, k);
        for i in 0..k {
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[i] += h;
            xm[i] -= h;
            let (fp, fm) = (f(&xp)?, f(&xm)?);
            g[i] = (fp - fm) / (2.0 * h);
            hm[(i, i)] = (fp - 2.0 * f0 + fm) / (h * h);
            for j in 0..i {
                let mut a = x.clone();
                a[i] += h;
                a[j] += h;
                let mut b = x.clone();
                b[i] += h;
                b[j] -= h;
                let mut c = x.clone();
                c[i] -= h;
                c[j] += h;
                let mut d = x.clone();
                d[i] -= h;
                d[j] -= h;
                let v = (f(&a)? - f(&b)? - f(&c)? + f(&d)?) / (4.0 * h * h);
                hm[(i, j)] = v;
                hm[(j, i)] = v;
            }
        }
        if g.iter().chain(hm.iter()).any(|v| !v.is_finite()) {
            break;
        }
        let scale = (0..k)
            .map(|i| hm[(i, i)].abs())
            .fold(0.0, f64::max)
            .max(1e-300);
        let mut improved = false;
        for _ in 0..30 {
            let mut m = hm.clone();
            for i in 0..k {
                m[(i, i)] += lambda * scale;
            }
            if let Some(ch) = m.cholesky() {
                let d = ch.solve(&(-&g));
                let t: Vec<f64> = (0..k)
                    .map(|j| (x[j] + d[j]).clamp(obj.lower[j], obj.upper[j]))
                    .collect();
                let ft = lsq::chi2(obj, &t)?;
                if ft < f0 {
                    best = Found {
                        theta: t,
                        chi2: ft,
                        converged: true,
                        reason: "Newton".into(),
                    };
                    lambda *= 0.1;
                    improved = true;
                    break;
                }
            }
            lambda = if lambda == 0.0 { 1e-6 } else { lambda * 10.0 };
        }
        if !improved || !(best.chi2 < f0 - 1e-15 * f0.abs()) {
            break;
        }
    }
    Ok(best)
}

const NEWTON_ITERS: usize = 50;

pub const VALLEY_ROUNDS: usize = 3;
const VALLEY_POINTS: usize = 25;
pub const VALLEY_REACH: f64 = 4.0;

/// How far (in standard errors) from a minimum a kink of `min` is looked across.
pub const KINK_REACH: f64 = 3.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::fit::dataset::{FitData, Observation};
    use crate::fit::models::{Evaluator, ModelKind, predict_e};
    use crate::models::viscoelastic::{ContactEnd, VmMethod};

    /// Noise-free data of `kind` with parameters `p` (physical) on two sizes.
    fn data(kind: ModelKind, p: &[f64]) -> FitData {
        let m = Material::preset("nylon").unwrap();
        let mut obs = Vec::new();
        for d in [6.35, 25.4] {
            let c = crate::fit::dataset::pair_contact(m, d, None).unwrap();
            for k in 0..15 {
                let v = 0.5 * 1.3f64.powi(k);
                let e = predict_e(kind, &c, v, p, ContactEnd::Overlap, &VmMethod::Master).unwrap();
                obs.push(Observation {
                    d_mm: d,
                    d2_mm: None,
                    v_n_m_s: v,
                    e,
                    e_err: Some(0.01),
                });
            }
        }
        FitData::new(m, obs).unwrap()
    }

    #[test]
    fn one_parameter_and_valley_polishes_recover_noise_free_parameters() {
        // The planted parameters are the exact minimum (chi2 = 0); Brent and Newton, started a
        // standard error or more away, must return them to their stopping tolerance (1e-10 in
        // the log parameters; 1e-7 allows for the flat directions).
        let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-7);
        let d = data(ModelKind::Vm, &[190.0]);
        let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
        let obj = Objective::new(&ev, ModelKind::Vm).unwrap();
        let t = 190f64.ln();
        let f = polish_brent(&obj, t + 0.1, t - 0.5, t + 0.5, f64::INFINITY).unwrap();
        assert!(f.converged && close(&f.theta, &[t]), "{f:?}");
        let p = [190.0, 4.0e7];
        let d = data(ModelKind::Product, &p);
        let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
        let obj = Objective::new(&ev, ModelKind::Product).unwrap();
        let truth = ModelKind::Product.to_internal(&p);
        // Newton and the line searches from a point off the minimum (not polished first).
        let off = vec![truth[0] + 0.02, truth[1] - 0.005];
        let start = Found {
            chi2: lsq::chi2(&obj, &off).unwrap(),
            theta: off,
            converged: false,
            reason: String::new(),
        };
        let f = polish_newton(&obj, start.clone()).unwrap();
        assert!(close(&f.theta, &truth) && f.chi2 < 1e-12, "{f:?}");
        // The line searches end with Levenberg-Marquardt stopped where the Gauss-Newton step
        // promises less than a hundredth of the search's tolerance (1e-6 here, chi2 = 0 with
        // a scale of 1): chi2 at most 1e-8 above the minimum, so each parameter within
        // sqrt(1e-8) = 1e-4 standard errors of it (2e-4 allows for the model's curvature).
        let f = polish_valleys(&obj, start, &|_| true).unwrap();
        let sd = crate::fit::kinks::axis_stderr(&obj, &truth).unwrap();
        assert!(f.chi2 <= 1e-8, "{f:?}");
        for k in 0..2 {
            assert!(
                (f.theta[k] - truth[k]).abs() <= 2e-4 * sd[k],
                "{k}: {f:?} sd {sd:?}"
            );
        }
    }
}
