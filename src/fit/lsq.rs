//! Weighted nonlinear least squares for small problems (1-3 parameters, ~100 residuals).
//!
//! **Solves** min over theta in a box [lo, hi] of chi2(theta) = sum_i f_i(theta)^2, where
//! f_i = (model_i - e_i)/sigma_i.
//!
//! **Methods.**
//! - [`levenberg_marquardt`]: Levenberg-Marquardt with Marquardt's diagonal scaling, the gain-ratio
//!   damping update of Nielsen (1999) as given in Madsen, Nielsen & Tingleff, "Methods for
//!   non-linear least squares problems" (2004), Alg. 3.16, and an active set for the box (a
//!   parameter on a bound whose gradient points out of the box is held there for the step).
//!   Why our own: argmin 0.11 has no Levenberg-Marquardt; its Gauss-Newton needs its own
//!   operator types and has no damping, which stalls on the plateaus these models have (a
//!   parameter that stops mattering gives a singular J^T J, which the damping handles); and with
//!   at most 3 parameters the whole method is a dense 3 x 3 solve per step.
//! - [`brent_minimize`]: Brent's bracketed minimisation (argmin's `BrentOpt`) for the
//!   one-parameter models after a grid scan has bracketed the global minimum.
//! - [`profile_crossing`]: where a profile chi2 crosses a threshold, by bracketing outwards and
//!   Brent's root finder (argmin's `BrentRoot`).
//! - [`jacobian`]: central differences with a step matched to the accuracy of the model (see
//!   [`Residuals::fd_step`]); one-sided at a bound.
//! - [`covariance`]: (J^T J)^-1, the covariance of theta when the sigma_i are exact.
//!
//! **Needs** residuals that are finite inside the box; an `Err` from the model aborts the fit.
//!
//! **Known answers**: the tests below fit an exponential decay (closed-form Jacobian not used) and
//! a linear model whose least-squares solution and covariance are known in closed form.

use crate::error::{Error, Result};
use argmin::core::{CostFunction, Executor, State, TerminationReason};
use argmin::solver::brent::{BrentOpt, BrentRoot};
use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;

/// A least-squares problem: residuals f_i(theta) and the box theta must stay in.
pub trait Residuals {
    fn n_params(&self) -> usize;
    fn n_residuals(&self) -> usize;
    /// Writes f_i(theta) = (model_i - e_i)/sigma_i into `out`.
    fn residuals(&self, theta: &[f64], out: &mut [f64]) -> Result<()>;
    /// Lower and upper bounds of each parameter.
    fn lower(&self) -> &[f64];
    fn upper(&self) -> &[f64];
    /// Finite-difference step in theta. For central differences the error is about
    /// eps_f / h + h^2 |f'''| / 6, smallest at h ~ eps_f^(1/3), with eps_f the model's accuracy.
    fn fd_step(&self) -> f64;
}

/// chi2 = sum f_i^2 at theta.
pub fn chi2(p: &impl Residuals, theta: &[f64]) -> Result<f64> {
    let mut f = vec![0.0; p.n_residuals()];
    p.residuals(theta, &mut f)?;
    Ok(f.iter().map(|x| x * x).sum())
}

/// The Jacobian df_i/dtheta_j for the parameters with `free[j]`, in order; `f0` are the
/// residuals at theta (used by one-sided differences at a bound).
pub fn jacobian(
    p: &impl Residuals,
    theta: &[f64],
    free: &[bool],
    f0: &[f64],
) -> Result<DMatrix<f64>> {
    let n = p.n_residuals();
    let cols: Vec<usize> = (0..theta.len()).filter(|&j| free[j]).collect();
    let mut jac = DMatrix::zeros(n, cols.len());
    let h = p.fd_step();
    let (lo, hi) = (p.lower(), p.upper());
    let mut fp = vec![0.0; n];
    let mut fm = vec![0.0; n];
    let mut t = theta.to_vec();
    for (c, &j) in cols.iter().enumerate() {
        let up_ok = theta[j] + h <= hi[j];
        let down_ok = theta[j] - h >= lo[j];
        let (fplus, fminus, width): (&[f64], &[f64], f64) = match (up_ok, down_ok) {
            (true, true) => {
                t[j] = theta[j] + h;
                p.residuals(&t, &mut fp)?;
                t[j] = theta[j] - h;
                p.residuals(&t, &mut fm)?;
                (&fp, &fm, 2.0 * h)
            }
            (true, false) => {
                t[j] = theta[j] + h;
                p.residuals(&t, &mut fp)?;
                (&fp, f0, h)
            }
            (false, true) => {
                t[j] = theta[j] - h;
                p.residuals(&t, &mut fm)?;
                (f0, &fm, h)
            }
            (false, false) => (f0, f0, 1.0),
        };
        for i in 0..n {
            jac[(i, c)] = (fplus[i] - fminus[i]) / width;
        }
        t[j] = theta[j];
    }
    Ok(jac)
}

/// The covariance (J^T J)^-1 of the parameters, with what the data leave undetermined marked.
#[derive(Debug, Clone, PartialEq)]
pub struct Covariance {
    /// NaN in the rows and columns of undetermined parameters.
    pub matrix: DMatrix<f64>,
    /// The parameter does not change the model at all here (a zero Jacobian column: a plateau).
    pub no_effect: Vec<bool>,
    /// The parameter is determined only in combination with others (collinear columns).
    pub degenerate: Vec<bool>,
}

/// (J^T J)^+ with the undetermined parameters marked. Columns are scaled to unit norm first, so
/// the rank test does not depend on units; eigenvalues below 1e-12 of the largest (columns
/// parallel to 1 - 1e-12) are a null space, and a parameter with a share above 1e-6 in it is
/// degenerate. For the others the pseudo-inverse gives their exact variance (they are estimable:
/// orthogonal to the null space).
pub fn covariance(jac: &DMatrix<f64>) -> Covariance {
    let p = jac.ncols();
    let mut out = Covariance {
        matrix: DMatrix::from_element(p, p, f64::NAN),
        no_effect: vec![false; p],
        degenerate: vec![false; p],
    };
    let norms: Vec<f64> = (0..p).map(|j| jac.column(j).norm()).collect();
    let live: Vec<usize> = (0..p).filter(|&j| norms[j] > 0.0).collect();
    for (flag, &norm) in out.no_effect.iter_mut().zip(&norms) {
        // Also true for a NaN norm: such a column carries no usable information either.
        *flag = norm.is_nan() || norm <= 0.0;
    }
    if live.is_empty() {
        return out;
    }
    let m = live.len();
    let mut a = DMatrix::zeros(m, m);
    for (r, &i) in live.iter().enumerate() {
        for (c, &j) in live.iter().enumerate() {
            a[(r, c)] = jac.column(i).dot(&jac.column(j)) / (norms[i] * norms[j]);
        }
    }
    let eig = a.symmetric_eigen();
    let emax = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    let mut pinv = DMatrix::zeros(m, m);
    let mut null_share = vec![0.0; m];
    for (q, &lam) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(q);
        if lam > 1e-12 * emax {
            pinv += v * v.transpose() / lam;
        } else {
            for r in 0..m {
                null_share[r] += v[r] * v[r];
            }
        }
    }
    for (r, &i) in live.iter().enumerate() {
        out.degenerate[i] = null_share[r] > 1e-6;
    }
    for (r, &i) in live.iter().enumerate() {
        for (c, &j) in live.iter().enumerate() {
            if !out.degenerate[i] && !out.degenerate[j] {
                out.matrix[(i, j)] = pinv[(r, c)] / (norms[i] * norms[j]);
            }
        }
    }
    out
}

/// Settings of [`levenberg_marquardt`]; the defaults are MINPACK's tolerances tightened to
/// what a model accurate to ~1e-15 supports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmOptions {
    pub max_iterations: usize,
    /// Orthogonality test: max_j |g_j| / (|J_j| |f|) below this stops (MINPACK gtol).
    pub gtol: f64,
    /// Relative step size below this stops (MINPACK xtol).
    pub xtol: f64,
    /// Actual and predicted relative reduction of chi2 both below this stops (MINPACK ftol).
    pub ftol: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 200,
            gtol: 1e-10,
            xtol: 1e-10,
            ftol: 1e-13,
        }
    }
}

/// What a local minimisation found.
#[derive(Debug, Clone, PartialEq)]
pub struct LmOutcome {
    pub theta: Vec<f64>,
    pub chi2: f64,
    pub iterations: usize,
    pub converged: bool,
    /// Why it stopped.
    pub reason: &'static str,
}

/// Levenberg-Marquardt from `start` over the parameters with `free[j]` (the others stay at their
/// start value, which is how profiles are computed).
pub fn levenberg_marquardt(
    p: &impl Residuals,
    start: &[f64],
    free: &[bool],
    opts: &LmOptions,
) -> Result<LmOutcome> {
    let n = p.n_residuals();
    let (lo, hi) = (p.lower(), p.upper());
    let mut theta: Vec<f64> = start
        .iter()
        .enumerate()
        .map(|(j, &t)| t.clamp(lo[j], hi[j]))
        .collect();
    let mut f = vec![0.0; n];
    p.residuals(&theta, &mut f)?;
    let mut chi2v: f64 = f.iter().map(|x| x * x).sum();
    let mut mu = 1e-3;
    let mut nu = 2.0;
    let mut f_new = vec![0.0; n];
    let outcome = |theta: Vec<f64>, chi2: f64, it: usize, conv: bool, reason| LmOutcome {
        theta,
        chi2,
        iterations: it,
        converged: conv,
        reason,
    };
    if !free.iter().any(|&b| b) {
        return Ok(outcome(theta, chi2v, 0, true, "no free parameters"));
    }
    let mut need_jac = true;
    let mut jac = DMatrix::zeros(0, 0);
    let mut free_now: Vec<bool> = free.to_vec();
    let mut g_full = vec![0.0; theta.len()];
    for it in 1..=opts.max_iterations {
        if need_jac {
            // Active set: a parameter on a bound whose descent direction leaves the box is held.
            let all = jacobian(p, &theta, free, &f)?;
            let fv = DVector::from_column_slice(&f);
            let g_all = all.transpose() * &fv;
            let cols: Vec<usize> = (0..theta.len()).filter(|&j| free[j]).collect();
            let fnorm = fv.norm();
            let mut worst: f64 = 0.0;
            for (c, &j) in cols.iter().enumerate() {
                g_full[j] = g_all[c];
                let cn = all.column(c).norm();
                let at_lo = theta[j] <= lo[j] && g_all[c] > 0.0;
                let at_hi = theta[j] >= hi[j] && g_all[c] < 0.0;
                free_now[j] = !(at_lo || at_hi);
                if free_now[j] && cn > 0.0 && fnorm > 0.0 {
                    worst = worst.max(g_all[c].abs() / (cn * fnorm));
                }
            }
            if worst <= opts.gtol {
                return Ok(outcome(
                    theta,
                    chi2v,
                    it,
                    true,
                    "gradient orthogonal to residuals",
                ));
            }
            let keep: Vec<usize> = cols
                .iter()
                .enumerate()
                .filter(|(_, j)| free_now[**j])
                .map(|(c, _)| c)
                .collect();
            jac = all.select_columns(&keep);
            need_jac = false;
        }
        let idx: Vec<usize> = (0..theta.len()).filter(|&j| free_now[j]).collect();
        let m = idx.len();
        let a = jac.transpose() * &jac;
        let g = DVector::from_iterator(m, idx.iter().map(|&j| g_full[j]));
        let dmax = (0..m).map(|k| a[(k, k)]).fold(0.0, f64::max);
        let mut lhs = a.clone();
        for k in 0..m {
            // Marquardt's scaling; a zero column (no effect on the model) gets a floor so the
            // system stays solvable and its step is zero.
            lhs[(k, k)] += mu * a[(k, k)].max(1e-12 * dmax).max(1e-300);
        }
        let h = match lhs.cholesky() {
            Some(ch) => ch.solve(&(-&g)),
            None => {
                mu *= nu;
                nu *= 2.0;
                continue;
            }
        };
        let mut trial = theta.clone();
        for (k, &j) in idx.iter().enumerate() {
            trial[j] = (theta[j] + h[k]).clamp(lo[j], hi[j]);
        }
        let step = DVector::from_iterator(m, idx.iter().map(|&j| trial[j] - theta[j]));
        let small_step = idx
            .iter()
            .all(|&j| (trial[j] - theta[j]).abs() <= opts.xtol * (theta[j].abs() + opts.xtol));
        // Predicted decrease of chi2 for the (projected) step, from the Gauss-Newton model.
        let pred = -(2.0 * g.dot(&step) + (&a * &step).dot(&step));
        p.residuals(&trial, &mut f_new)?;
        let chi2_new: f64 = f_new.iter().map(|x| x * x).sum();
        let actual = chi2v - chi2_new;
        if chi2_new.is_finite() && actual > 0.0 && pred > 0.0 {
            let rho = actual / pred;
            theta = trial;
            std::mem::swap(&mut f, &mut f_new);
            let done = actual <= opts.ftol * chi2v && pred <= opts.ftol * chi2v;
            chi2v = chi2_new;
            mu *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
            nu = 2.0;
            need_jac = true;
            if done || small_step {
                return Ok(outcome(
                    theta,
                    chi2v,
                    it,
                    true,
                    "relative reduction below ftol",
                ));
            }
        } else {
            if small_step || pred <= opts.ftol * chi2v.max(1e-300) {
                return Ok(outcome(
                    theta,
                    chi2v,
                    it,
                    true,
                    "no further reduction possible",
                ));
            }
            mu *= nu;
            nu *= 2.0;
            if !mu.is_finite() || mu > 1e30 {
                return Ok(outcome(theta, chi2v, it, false, "damping overflow"));
            }
        }
    }
    Ok(outcome(
        theta,
        chi2v,
        opts.max_iterations,
        false,
        "maximum number of iterations",
    ))
}

/// A scalar function for argmin's Brent solvers; model errors are kept aside and re-raised.
struct Scalar<'a, F: FnMut(f64) -> Result<f64>> {
    f: RefCell<F>,
    failure: &'a RefCell<Option<Error>>,
    offset: f64,
}

impl<F: FnMut(f64) -> Result<f64>> CostFunction for Scalar<'_, F> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, x: &f64) -> std::result::Result<f64, argmin::core::Error> {
        match (self.f.borrow_mut())(*x) {
            Ok(v) => Ok(v - self.offset),
            Err(e) => {
                *self.failure.borrow_mut() = Some(e.clone());
                Err(e.into())
            }
        }
    }
}

/// The model's own error if it raised one, else the solver's complaint (a bracket without a sign
/// change, which the callers rule out).
fn solver_failure(what: &'static str, kept: Option<Error>) -> Error {
    kept.unwrap_or(Error::InvalidParameter {
        name: what,
        value: f64::NAN,
        expected: "a bracket with a sign change",
    })
}

/// Minimum of f on [a, b] by Brent's method (argmin `BrentOpt`), to |x| 1.5e-8 + `abs_tol`.
/// Returns (x, f(x), converged). The bracket must contain the minimum the caller wants: Brent
/// finds a local minimum inside it.
pub fn brent_minimize(
    f: impl FnMut(f64) -> Result<f64>,
    a: f64,
    b: f64,
    abs_tol: f64,
) -> Result<(f64, f64, bool)> {
    let failure = RefCell::new(None);
    let problem = Scalar {
        f: RefCell::new(f),
        failure: &failure,
        offset: 0.0,
    };
    let solver = BrentOpt::new(a, b).set_tolerance(f64::EPSILON.sqrt(), abs_tol);
    let res = Executor::new(problem, solver)
        .configure(|s| s.max_iters(200))
        .run();
    match res {
        Ok(r) => {
            let st = r.state();
            let x = *st.get_best_param().unwrap_or(&f64::NAN);
            let converged = matches!(
                st.get_termination_reason(),
                Some(TerminationReason::SolverConverged)
            );
            Ok((x, st.get_best_cost(), converged))
        }
        Err(_) => Err(solver_failure("Brent minimisation", failure.take())),
    }
}

/// The point between `t_hat` and `limit` where `profile(t)` first reaches `threshold`, or `None`
/// when it stays below up to `limit` (the interval is open on that side).
///
/// `profile(t_hat)` must be below `threshold`. Trial points go out from `t_hat` by `step`,
/// doubling, until the profile exceeds the threshold or `limit` is reached; then argmin's
/// `BrentRoot` finds the crossing to `tol` in t.
pub fn profile_crossing(
    mut profile: impl FnMut(f64) -> Result<f64>,
    t_hat: f64,
    limit: f64,
    step: f64,
    threshold: f64,
    tol: f64,
) -> Result<Option<f64>> {
    let dir = (limit - t_hat).signum();
    if dir == 0.0 {
        return Ok(None);
    }
    let mut inner = t_hat;
    let mut dist = step.abs().max(tol);
    let outer = loop {
        let t = if (t_hat + dir * dist - limit) * dir >= 0.0 {
            limit
        } else {
            t_hat + dir * dist
        };
        let v = profile(t)?;
        if v >= threshold {
            break t;
        }
        if t == limit {
            return Ok(None);
        }
        inner = t;
        dist *= 2.0;
    };
    let failure = RefCell::new(None);
    let shared = RefCell::new(&mut profile);
    let problem = Scalar {
        f: RefCell::new(|t: f64| (shared.borrow_mut())(t)),
        failure: &failure,
        offset: threshold,
    };
    let (a, b) = if inner < outer {
        (inner, outer)
    } else {
        (outer, inner)
    };
    let res = Executor::new(problem, BrentRoot::new(a, b, tol))
        .configure(|s| s.max_iters(100))
        .run();
    match res {
        Ok(r) => Ok(r.state().get_best_param().copied().or(Some(outer))),
        Err(_) => {
            if let Some(e) = failure.take() {
                return Err(e);
            }
            // A profile that re-minimises the other parameters need not return the same value
            // when evaluated again at a bracket end (its inner minimisation may settle
            // elsewhere), so Brent can find no sign change. Bisect instead, trusting the
            // classification of each new point.
            let (mut below, mut above) = (inner, outer);
            while (above - below).abs() > tol {
                let mid = 0.5 * (below + above);
                if (shared.borrow_mut())(mid)? >= threshold {
                    above = mid;
                } else {
                    below = mid;
                }
            }
            Ok(Some(0.5 * (below + above)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = A exp(-k x) + noise-free data; residuals f = (model - y)/sigma.
    struct Decay {
        x: Vec<f64>,
        y: Vec<f64>,
        lo: Vec<f64>,
        hi: Vec<f64>,
    }

    impl Residuals for Decay {
        fn n_params(&self) -> usize {
            2
        }
        fn n_residuals(&self) -> usize {
            self.x.len()
        }
        fn residuals(&self, t: &[f64], out: &mut [f64]) -> Result<()> {
            for ((o, x), y) in out.iter_mut().zip(&self.x).zip(&self.y) {
                *o = t[0] * (-t[1] * x).exp() - y;
            }
            Ok(())
        }
        fn lower(&self) -> &[f64] {
            &self.lo
        }
        fn upper(&self) -> &[f64] {
            &self.hi
        }
        fn fd_step(&self) -> f64 {
            1e-5
        }
    }

    #[test]
    fn lm_recovers_exact_parameters() {
        let x: Vec<f64> = (0..20).map(|i| i as f64 * 0.25).collect();
        let y = x.iter().map(|&x| 3.0 * (-0.7 * x).exp()).collect();
        let p = Decay {
            x,
            y,
            lo: vec![-100.0, -100.0],
            hi: vec![100.0, 100.0],
        };
        let r = levenberg_marquardt(&p, &[1.0, 3.0], &[true, true], &LmOptions::default()).unwrap();
        assert!(r.converged, "{r:?}");
        // Noise-free data: the minimum is exact; 1e-9 allows the finite-difference Jacobian's
        // influence on where the iteration stops.
        assert!(
            (r.theta[0] - 3.0).abs() < 1e-9 && (r.theta[1] - 0.7).abs() < 1e-9,
            "{r:?}"
        );
        // Holding one parameter: the other is the 1-D minimiser.
        let r =
            levenberg_marquardt(&p, &[3.0, 0.1], &[false, true], &LmOptions::default()).unwrap();
        assert!((r.theta[1] - 0.7).abs() < 1e-9 && r.theta[0] == 3.0);
    }

    #[test]
    fn lm_stops_at_an_active_bound() {
        let x: Vec<f64> = (0..20).map(|i| i as f64 * 0.25).collect();
        let y = x.iter().map(|&x| 3.0 * (-0.7 * x).exp()).collect();
        let p = Decay {
            x,
            y,
            lo: vec![-100.0, 1.0],
            hi: vec![100.0, 100.0],
        };
        let r = levenberg_marquardt(&p, &[1.0, 3.0], &[true, true], &LmOptions::default()).unwrap();
        assert!(r.converged, "{r:?}");
        assert_eq!(r.theta[1], 1.0);
    }

    /// Straight line y = c0 + c1 x with sigma = 1: the least-squares covariance is (X^T X)^-1
    /// in closed form: var(c1) = n / D, var(c0) = sum x^2 / D, cov = -sum x / D,
    /// D = n sum x^2 - (sum x)^2.
    #[test]
    fn covariance_of_a_line_is_the_closed_form() {
        let x: Vec<f64> = (0..10).map(|i| i as f64).collect();
        let n = x.len() as f64;
        let sx: f64 = x.iter().sum();
        let sxx: f64 = x.iter().map(|x| x * x).sum();
        let d = n * sxx - sx * sx;
        let mut jac = DMatrix::zeros(10, 2);
        for (i, &xi) in x.iter().enumerate() {
            jac[(i, 0)] = 1.0;
            jac[(i, 1)] = xi;
        }
        let c = covariance(&jac).matrix;
        assert!((c[(0, 0)] - sxx / d).abs() < 1e-14);
        assert!((c[(1, 1)] - n / d).abs() < 1e-14);
        assert!((c[(0, 1)] + sx / d).abs() < 1e-14);
        // A zero column is a parameter without effect: the other keeps its variance, 1/n.
        jac.column_mut(1).fill(0.0);
        let c = covariance(&jac);
        assert!(c.no_effect[1] && !c.degenerate[0]);
        assert!(c.matrix[(1, 1)].is_nan() && (c.matrix[(0, 0)] - 0.1).abs() < 1e-14);
        // Parallel columns: both degenerate; a third, orthogonal one stays determined with the
        // variance of its own column, 1/|x|^2.
        jac.column_mut(1).fill(2.0);
        let mut j3 = DMatrix::zeros(10, 3);
        j3.columns_mut(0, 2).copy_from(&jac);
        for i in 0..10 {
            j3[(i, 2)] = if i % 2 == 0 { 1.0 } else { -1.0 };
        }
        let c = covariance(&j3);
        assert!(c.degenerate[0] && c.degenerate[1] && !c.degenerate[2]);
        assert!(c.matrix[(0, 0)].is_nan());
        assert!(
            (c.matrix[(2, 2)] - 0.1).abs() < 1e-14,
            "{}",
            c.matrix[(2, 2)]
        );
    }

    #[test]
    fn brent_minimum_and_profile_crossing() {
        // (x - 2)^2 + 1: minimum 1 at 2; crossing of 1 + 3.84 at 2 +- sqrt(3.84).
        let (x, fx, conv) =
            brent_minimize(|x| Ok((x - 2.0).powi(2) + 1.0), -5.0, 10.0, 1e-12).unwrap();
        assert!(conv && (x - 2.0).abs() < 1e-7 && (fx - 1.0).abs() < 1e-13);
        let f = |x: f64| Ok((x - 2.0f64).powi(2) + 1.0);
        let up = profile_crossing(f, 2.0, 100.0, 0.5, 4.84, 1e-10)
            .unwrap()
            .unwrap();
        assert!((up - (2.0 + 3.84f64.sqrt())).abs() < 1e-9, "{up}");
        let down = profile_crossing(f, 2.0, -100.0, 0.5, 4.84, 1e-10)
            .unwrap()
            .unwrap();
        assert!((down - (2.0 - 3.84f64.sqrt())).abs() < 1e-9, "{down}");
        // A plateau: never reaches the threshold before the limit.
        let flat = |x: f64| Ok(if x < 2.0 { (x - 2.0f64).powi(2) } else { 0.0 });
        assert_eq!(
            profile_crossing(flat, 2.0, 50.0, 0.5, 3.84, 1e-10).unwrap(),
            None
        );
        assert!(
            profile_crossing(flat, 2.0, -50.0, 0.5, 3.84, 1e-10)
                .unwrap()
                .is_some()
        );
    }
}
