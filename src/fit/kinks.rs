//! Polishes across the kinks of `min` ([`super::search`]): where its two branches meet at a point,
//! chi2 has a kink, and Levenberg-Marquardt (whose Gauss-Newton model sees one branch) can stop
//! on it. [`kink_starts`] proposes starts mirrored across the kinks near a minimum;
//! [`polish_profiles`] minimises the profile along each parameter (Levenberg-Marquardt then
//! Brent for the other parameter at each point), which follows a kink's valley to its bottom.
//!
//! **Known answer** (test below): noise-free `min` data give back their planted parameters.

use super::lsq::{self, LmOptions};
use super::models::ModelKind;
use super::objective::Objective;
use super::polish::{Found, KINK_REACH, VALLEY_REACH, VALLEY_ROUNDS, polish_lm};
use super::scalar;
use crate::error::Result;

/// The standard errors of the landscape's axes at theta (internal units, scaled by sqrt(s): so
/// the number of cells at this resolution around a minimum depends on the number of points, not
/// on how badly the model fits), for the resolution of the branch and bound; a parameter the
/// data do not determine gets 1/4096 of its box (a plateau may end in a dip narrower than any
/// standard error: where a point starts to yield), and none more than 1/256.
pub fn axis_stderr(obj: &Objective, theta: &[f64]) -> Result<[f64; 2]> {
    let mut f0 = vec![0.0; obj.ev.len()];
    lsq::residuals_checked(obj, theta, &mut f0)?;
    let jac = lsq::jacobian(obj, theta, &vec![true; theta.len()], &f0)?;
    let cov = lsq::covariance(&jac);
    let s = obj.scale(lsq::chi2(obj, theta)?);
    let sd = |j: usize| {
        let v = (cov.matrix[(j, j)] * s).sqrt();
        let span = obj.upper[j] - obj.lower[j];
        if !(v.is_finite() && v > 0.0) {
            span / 4096.0
        } else if v < span / 256.0 {
            v
        } else {
            span / 256.0
        }
    };
    Ok(match obj.kind {
        ModelKind::Vm => [sd(0), 0.0],
        ModelKind::Pm => [0.0, sd(0)],
        ModelKind::Min | ModelKind::Product => [sd(0), sd(1)],
        ModelKind::PowerLaw => [sd(1), sd(2)],
    })
}

/// Starts across the kinks of `min` near theta: for each point whose two branches meet within
/// [`KINK_REACH`] standard errors and whose residual is positive there (chi2 then has a ridge
/// along the kink, so a second minimum may sit just across it), theta mirrored across the kink
/// (linearised), with the ridge's strength: the jump of chi2's slope across it, per standard
/// error (2 |r_i| |grad(e_vm - e_pm)| / sigma_i^2, the gradient in standard errors). Convex kinks
/// (negative residual) cannot hide a second minimum. Also returned: whether theta is within 1%
/// of a standard error of some point's kink.
pub fn kink_starts(obj: &Objective, theta: &[f64], sd: [f64; 2]) -> Result<(Vec<KinkStart>, bool)> {
    let ev = obj.ev;
    let (t0, t1) = (theta[0], theta[1]);
    // Central differences in the log parameters, step matched to the model (see fd_step).
    let h = obj.fd_step;
    let mut out = Vec::new();
    let mut on_kink = false;
    // Each factor at its three values for every point as rows (the evaluations' vectorised
    // path, the same doubles as point by point: on 100 000 points the scalar calls were 3% of
    // a `min` fit). A NaN of e_vm's row is evaluated again alone, for its error.
    let n = ev.len();
    let eta = [t0.exp(), (t0 + h).exp(), (t0 - h).exp()];
    let sigma = [t1.exp(), (t1 + h).exp(), (t1 - h).exp()];
    let rows = |axis: usize, x: f64| {
        let mut row = vec![0.0; n];
        if axis == 0 {
            ev.e_vm_row(x, &mut row);
        } else {
            ev.e_pm_row(x, &mut row);
        }
        row
    };
    let vm_rows = eta.map(|x| rows(0, x));
    let pm_rows = sigma.map(|x| rows(1, x));
    let vm = |k: usize, i: usize| -> Result<f64> {
        match vm_rows[k][i] {
            v if v.is_nan() => ev.e_vm(i, eta[k]),
            v => Ok(v),
        }
    };
    let [g_at, g_hi, g_lo] = &pm_rows;
    for (i, ((&g, g_hi), g_lo)) in g_at.iter().zip(g_hi).zip(g_lo).enumerate() {
        let f = vm(0, i)?;
        let convex = f.min(g) <= ev.data.obs[i].e;
        let df = (vm(1, i)? - vm(2, i)?) / (2.0 * h);
        let dg = (g_hi - g_lo) / (2.0 * h);
        let (gx, gy) = (df, -dg);
        let norm2 = gx * gx + gy * gy;
        let reach = ((gx * sd[0]).powi(2) + (gy * sd[1]).powi(2)).sqrt();
        let gap = f - g;
        // Within 1% of a standard error of its kink: the polish may have stopped there.
        on_kink |= norm2 > 0.0 && gap.abs() <= 0.01 * reach;
        if convex || !(norm2 > 0.0) || !(gap.abs() <= KINK_REACH * reach) {
            continue;
        }
        let k = -2.0 * gap / norm2;
        let start = vec![
            (t0 + k * gx).clamp(obj.lower[0], obj.upper[0]),
            (t1 + k * gy).clamp(obj.lower[1], obj.upper[1]),
        ];
        if start.iter().all(|x| x.is_finite()) {
            let w = obj.inv_sigma[i];
            out.push(KinkStart {
                theta: start,
                ridge: 2.0 * (f.min(g) - ev.data.obs[i].e).abs() * w * w * reach,
            });
        }
    }
    Ok((out, on_kink))
}

/// A start of [`kink_starts`].
#[derive(Debug, Clone, PartialEq)]
pub struct KinkStart {
    pub theta: Vec<f64>,
    /// The jump of chi2's slope across the kink, per standard error.
    pub ridge: f64,
}

/// The profile of a two-parameter model along axis `outer` at `u`: the other parameter
/// minimised by Levenberg-Marquardt from `centre` (the last profile point's minimum, so the
/// profile follows its valley, however narrow). Returns chi2 and the minimising inner value.
fn profile_point(
    obj: &Objective,
    outer: usize,
    u: f64,
    centre: f64,
    width: f64,
) -> Result<(f64, f64)> {
    let inner = 1 - outer;
    let mut th = vec![0.0; 2];
    th[outer] = u;
    th[inner] = centre;
    let mut free = vec![true; 2];
    free[outer] = false;
    let r = lsq::levenberg_marquardt(obj, &th, &free, &LmOptions::default())?;
    // Then Brent within `width` of where it ended: at a kink of `min` (a V in the inner
    // parameter) Levenberg-Marquardt stops near, not at, the bottom.
    let (mut v, mut at) = (r.chi2, r.theta[inner]);
    let (lo, hi) = (
        (at - width).max(obj.lower[inner]),
        (at + width).min(obj.upper[inner]),
    );
    if lo < hi {
        let m = scalar::brent_minimize(
            |x| {
                th[inner] = x;
                lsq::chi2(obj, &th)
            },
            lo,
            hi,
            width * 1e-5,
        )?;
        if m.fx < v {
            (v, at) = (m.fx, m.x);
        }
    }
    Ok((v, at))
}

/// Brent's method on the profile along each axis of a two-parameter model in turn (see
/// `profile_point`), over +-[`VALLEY_REACH`] standard errors, then Levenberg-Marquardt; repeated
/// while a round gains at least `min_gain` (the search passes its tolerance tau: a round that
/// gained less has reached the minimum within the accuracy the search states, and each costs
/// about a hundred profile points).
pub fn polish_profiles(obj: &Objective, start: Found, min_gain: f64) -> Result<Found> {
    let mut best = start;
    for _ in 0..VALLEY_ROUNDS {
        let before = best.chi2;
        let sd = axis_stderr(obj, &best.theta)?;
        for outer in 0..2 {
            let inner = 1 - outer;
            let base = best.theta.clone();
            let centre = std::cell::Cell::new(base[inner]);
            let p = |u: f64| -> Result<f64> {
                let (v, at) = profile_point(obj, outer, u, centre.get(), sd[inner] / 8.0)?;
                centre.set(at);
                Ok(v)
            };
            let (a, b) = (
                (base[outer] - VALLEY_REACH * sd[outer]).max(obj.lower[outer]),
                (base[outer] + VALLEY_REACH * sd[outer]).min(obj.upper[outer]),
            );
            if !(a < b) {
                continue;
            }
            // Zooming grids (9 points, then 9 across the best one's neighbours, three times):
            // the profile of `min` has a kink wherever another point changes branch, so it can
            // have minima closer together than one grid step; then Brent in the last bracket.
            let n = 9;
            let (mut a, mut b) = (a, b);
            let (mut u, mut fu) = (base[outer], f64::INFINITY);
            let (mut lo, mut hi) = (a, b);
            for _ in 0..3 {
                let grid: Vec<f64> = (0..n)
                    .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
                    .collect();
                // From the middle outwards, each point warm-started from its neighbour.
                let mut vals = vec![f64::INFINITY; n];
                for half in [(n / 2..n).collect::<Vec<_>>(), (0..n / 2).rev().collect()] {
                    centre.set(base[inner]);
                    for i in half {
                        vals[i] = p(grid[i])?;
                    }
                }
                let i = (0..n)
                    .min_by(|&x, &y| vals[x].total_cmp(&vals[y]))
                    .unwrap_or(0);
                if vals[i] < fu {
                    (u, fu) = (grid[i], vals[i]);
                }
                (lo, hi) = (grid[i.saturating_sub(1)], grid[(i + 1).min(n - 1)]);
                (a, b) = (lo, hi);
            }
            centre.set(base[inner]);
            let m = scalar::brent_minimize(p, lo, hi, 1e-6 * sd[outer])?;
            if m.fx < fu {
                (u, fu) = (m.x, m.fx);
            }
            if fu < best.chi2 {
                let (v, at) = profile_point(obj, outer, u, centre.get(), sd[inner] / 8.0)?;
                let mut th = vec![0.0; 2];
                th[outer] = u;
                th[inner] = at;
                if v < best.chi2 {
                    best = Found {
                        theta: th,
                        chi2: v,
                        converged: best.converged,
                        reason: best.reason.clone(),
                    };
                }
            }
        }
        let again = polish_lm(obj, &best.theta)?;
        if again.chi2 <= best.chi2 {
            best = again;
        }
        if !(best.chi2 < before - min_gain.max(1e-12 * before.abs())) {
            break;
        }
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::fit::dataset::{FitData, Observation};
    use crate::fit::models::{Evaluator, predict_e};
    use crate::fit::polish::polish_valleys;
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
    fn profiles_recover_noise_free_parameters() {
        // As in polish.rs: chi2 = 0 at the planted parameters, found to 1e-7 (stopping
        // tolerances 1e-10; the slack covers the flat direction).
        let p = [190.0, 4.0e7];
        let d = data(ModelKind::Min, &p);
        let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
        let obj = Objective::new(&ev, ModelKind::Min).unwrap();
        let truth = ModelKind::Min.to_internal(&p);
        let start = [truth[0] + 0.3, truth[1] - 0.05];
        let f = polish_lm(&obj, &start).unwrap();
        let f = polish_valleys(&obj, f, &|_| true).unwrap();
        let f = polish_profiles(&obj, f, 0.0).unwrap();
        let close = f
            .theta
            .iter()
            .zip(&truth)
            .all(|(x, y)| (x - y).abs() < 1e-7);
        assert!(close && f.chi2 < 1e-12, "{f:?}");
        // At the exact minimum no kink is near enough to be mirrored across with a positive
        // residual (every residual is zero).
        let sd = axis_stderr(&obj, &truth).unwrap();
        assert!(kink_starts(&obj, &truth, sd).unwrap().0.is_empty());
    }
}
