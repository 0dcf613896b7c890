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
//!   at most 3 parameters the whole method is a dense 3 x 3 solve per step. It is a local
//!   method: the global search ([`super::search`]) decides where it starts.
//! - [`jacobian`]: the problem's exact Jacobian where it has one ([`Residuals::jacobian_exact`]),
//!   else central differences with a step matched to the accuracy of the model (see
//!   [`Residuals::fd_step`]); one-sided at a bound.
//! - [`covariance`] (in [`super::covariance`]): (J^T J)^-1, the covariance of theta when the
//!   sigma_i are exact.
//!
//! **Needs** a finite start inside the box. A NaN residual is an error value (a model that
//! returns NaN is broken); an infinite chi2 (errors so small that the squares overflow) makes a
//! trial step fail, and at the start it ends the run unconverged. The iteration count is capped
//! ([`LmOptions::max_iterations`]) and so is the damping (1e30): both end unconverged, with the
//! reason.
//!
//! **Known answers**: the tests below fit an exponential decay (closed-form Jacobian not used) and
//! a linear model whose least-squares solution and covariance are known in closed form.

pub use super::covariance::{Covariance, covariance};
use super::sums;
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

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
    /// The exact Jacobian df_i/dtheta_j at `theta` for the parameters with `free[j]`, in order:
    /// `out` arrives as zeros of n_residuals x (number of free parameters) and column c gets the
    /// c-th free parameter's derivatives. `None` (the default) when the problem has no closed
    /// form: [`jacobian`] then uses central differences. An implementation must agree with
    /// those to their accuracy (about eps_f^(2/3), see [`Residuals::fd_step`]) and has a
    /// known-answer test comparing the two; unlike them it is exact on a bound as well.
    fn jacobian_exact(
        &self,
        _theta: &[f64],
        _free: &[bool],
        _out: &mut DMatrix<f64>,
    ) -> Option<Result<()>> {
        None
    }
    /// The residuals into `out` and, in the same pass, the exact Jacobian at the same `theta`
    /// into `jac` (as [`Residuals::jacobian_exact`] gives it, to the last bit), where together
    /// they cost little more than the residuals alone: Levenberg-Marquardt asks for this at
    /// trial points, where it needs the Jacobian whenever it accepts the step. `jac` comes with
    /// stale values, and with its shape (n x free parameters) or none (0 x 0: the implementation
    /// then makes it, so that a problem that declines costs no matrix); `Some(Ok(()))` promises
    /// that every entry was written. `None` (the default): nothing was written,
    /// [`Residuals::residuals`] serves.
    fn residuals_and_jacobian(
        &self,
        _theta: &[f64],
        _out: &mut [f64],
        _free: &[bool],
        _jac: &mut DMatrix<f64>,
    ) -> Option<Result<()>> {
        None
    }
    /// Whether chi2 has kinks (the models' e is the smaller of two branches): the Gauss-Newton
    /// step then sees the active branch only, and its promised decrease
    /// ([`gauss_newton_decrease`]) is no estimate of what crossing a kink gains, so callers do
    /// not stop on it ([`levenberg_marquardt_to`]). False by default.
    fn kinked(&self) -> bool {
        false
    }
}

fn nan_residual(theta: &[f64]) -> Error {
    Error::InvalidParameter {
        name: "model residual (NaN) at parameter",
        value: theta.first().copied().unwrap_or(f64::NAN),
        expected: "a model that evaluates to a number everywhere in the search box",
    }
}

/// Residuals at theta, with NaN turned into an error value.
pub fn residuals_checked(p: &impl Residuals, theta: &[f64], out: &mut [f64]) -> Result<()> {
    p.residuals(theta, out)?;
    if out.iter().any(|x| x.is_nan()) {
        return Err(nan_residual(theta));
    }
    Ok(())
}

/// chi2 = sum f_i^2 at theta (+inf when the squares overflow; NaN residuals are an error).
pub fn chi2(p: &impl Residuals, theta: &[f64]) -> Result<f64> {
    let mut f = vec![0.0; p.n_residuals()];
    residuals_checked(p, theta, &mut f)?;
    Ok(sum_squares(&f))
}

/// sum f_i^2: in order for small data (as it always was), by chunks for large data
/// ([`sums::sum`]: the serial sums of Levenberg-Marquardt were about a twentieth of
/// `fit --model all` on 100 000 points, and the whole of its tail while its last fit ran
/// alone).
fn sum_squares(f: &[f64]) -> f64 {
    if !sums::is_large(f.len()) {
        return f.iter().map(|x| x * x).sum();
    }
    sums::sum(f.len(), |r| [f[r].iter().map(|x| x * x).sum()])[0]
}

/// What a Levenberg-Marquardt step needs of the Jacobian J (n x k, k <= 3) and the residuals
/// f: J^T f, the norms of J's columns and of f, and J^T J. Small data as nalgebra forms them
/// (as they always were); large data in one pass over the points by chunks ([`sums::sum`]),
/// the norms the square roots of J^T J's diagonal and of f.f.
fn normal_parts(all: &DMatrix<f64>, f: &[f64]) -> (DVector<f64>, Vec<f64>, f64, DMatrix<f64>) {
    let (n, k) = all.shape();
    if !sums::is_large(n) || k > 3 {
        let fv = DVector::from_column_slice(f);
        let cn = (0..k).map(|c| all.column(c).norm()).collect();
        return (all.tr_mul(&fv), cn, fv.norm(), all.tr_mul(all));
    }
    let cols: Vec<&[f64]> = (0..k)
        .map(|c| &all.as_slice()[c * n..(c + 1) * n])
        .collect();
    // [J^T J row-major (9), J^T f (3), f.f]
    let t = sums::sum(n, |r| {
        let mut t = [0.0; 13];
        for i in r {
            let fi = f[i];
            for a in 0..k {
                let ja = cols[a][i];
                t[9 + a] += ja * fi;
                for b in a..k {
                    t[3 * a + b] += ja * cols[b][i];
                }
            }
            t[12] += fi * fi;
        }
        t
    });
    let jtj = DMatrix::from_fn(k, k, |a, b| t[3 * a.min(b) + a.max(b)]);
    let g = DVector::from_fn(k, |a, _| t[9 + a]);
    let cn = (0..k).map(|c| jtj[(c, c)].sqrt()).collect();
    (g, cn, t[12].sqrt(), jtj)
}

/// The Jacobian df_i/dtheta_j for the parameters with `free[j]`, in order: the problem's exact
/// one ([`Residuals::jacobian_exact`]) where it has one, else central differences; `f0` are the
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
    if let Some(done) = p.jacobian_exact(theta, free, &mut jac) {
        done?;
        return Ok(jac);
    }
    jacobian_fd(p, theta, free, f0)
}

/// The Jacobian by central differences alone (one-sided at a bound), whether or not the problem
/// has an exact one: what [`jacobian`] falls back to, and the reference an exact Jacobian's
/// test compares with.
pub fn jacobian_fd(
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
                residuals_checked(p, &t, &mut fp)?;
                t[j] = theta[j] - h;
                residuals_checked(p, &t, &mut fm)?;
                (&fp, &fm, 2.0 * h)
            }
            (true, false) => {
                t[j] = theta[j] + h;
                residuals_checked(p, &t, &mut fp)?;
                (&fp, f0, h)
            }
            (false, true) => {
                t[j] = theta[j] - h;
                residuals_checked(p, &t, &mut fm)?;
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

/// The decrease of chi2 that one undamped Gauss-Newton step from theta predicts:
/// g^T (J^T J)^+ g with g = J^T f (the squared length of f's projection on J's columns).
///
/// Zero at a stationary point of a smooth chi2, and the exact distance to the minimum for a
/// model linear in theta. Where Levenberg-Marquardt ends with the damping driven up rather than
/// at a stationary point (on a kink of `min`, whose exact Jacobian is the active branch's), it
/// stays as large as the gain one branch still promises: the search's test of whether a
/// minimum needs a costlier polish. Columns are scaled to unit norm, and eigenvalues of J^T J
/// below 1e-12 of the largest dropped, as in [`covariance`]; a zero column (a parameter on a
/// plateau) promises nothing. +inf where the Jacobian or the sums are not finite.
pub fn gauss_newton_decrease(p: &impl Residuals, theta: &[f64]) -> Result<f64> {
    let mut f = vec![0.0; p.n_residuals()];
    residuals_checked(p, theta, &mut f)?;
    let jac = jacobian(p, theta, &vec![true; theta.len()], &f)?;
    if jac.iter().any(|x| !x.is_finite()) {
        return Ok(f64::INFINITY);
    }
    let (g, norms, _, jtj) = normal_parts(&jac, &f);
    Ok(decrease_of(&g, &norms, &jtj))
}

/// [`gauss_newton_decrease`] from the normal equations' parts: g = J^T f, the columns' norms and
/// J^T J.
fn decrease_of(g: &DVector<f64>, norms: &[f64], jtj: &DMatrix<f64>) -> f64 {
    let live: Vec<usize> = (0..norms.len()).filter(|&j| norms[j] > 0.0).collect();
    let m = live.len();
    if m == 0 {
        return 0.0;
    }
    let a = DMatrix::from_fn(m, m, |r, c| {
        jtj[(live[r], live[c])] / (norms[live[r]] * norms[live[c]])
    });
    let gs = DVector::from_fn(m, |r, _| g[live[r]] / norms[live[r]]);
    let eig = a.symmetric_eigen();
    let emax = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    let mut out = 0.0;
    for (q, &lam) in eig.eigenvalues.iter().enumerate() {
        if lam > 1e-12 * emax {
            out += eig.eigenvectors.column(q).dot(&gs).powi(2) / lam;
        }
    }
    // Residuals whose sums overflow promise nothing a caller can compare: +inf, as for a
    // Jacobian that is not finite (a caller then takes the costlier path).
    if out.is_nan() { f64::INFINITY } else { out }
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
    levenberg_marquardt_to(p, start, free, opts, None)
}

/// [`levenberg_marquardt`] that also stops, converged, where the undamped Gauss-Newton step
/// over the free parameters promises a decrease of chi2 ([`gauss_newton_decrease`]) of at most
/// `enough(chi2)`: a caller that needs the minimum only to a stated accuracy in chi2 (the global
/// search's, [`super::search::tolerance`]). Why: on data of many sizes the onsets of yield make
/// chi2's curvature jump at many places, and the damped steps then zigzag across them for tens
/// of iterations, each gaining a millionth of that accuracy (`product` on 100 000 points of
/// distinct sizes: 65 iterations for a gain of 0.02, the search's tolerance 0.027). Not for a
/// problem with kinks ([`Residuals::kinked`]: `enough` is ignored), where the promise is one
/// branch's: stopping on it left `min` 7 tolerances above its minimum (tests/fit_large.rs,
/// seed 22).
pub fn levenberg_marquardt_to(
    p: &impl Residuals,
    start: &[f64],
    free: &[bool],
    opts: &LmOptions,
    enough: Option<&dyn Fn(f64) -> f64>,
) -> Result<LmOutcome> {
    let n = p.n_residuals();
    let (lo, hi) = (p.lower(), p.upper());
    if let Some(j) = (0..start.len()).find(|&j| !start[j].is_finite()) {
        return Err(Error::InvalidParameter {
            name: "Levenberg-Marquardt start value",
            value: start[j],
            expected: "a finite number",
        });
    }
    let mut theta: Vec<f64> = start
        .iter()
        .enumerate()
        .map(|(j, &t)| t.clamp(lo[j], hi[j]))
        .collect();
    let mut f = vec![0.0; n];
    // The first Jacobian in the same pass as the residuals where the problem fuses them (one
    // evaluation of the model where the residuals and then the Jacobian took two; the same
    // numbers, see [`Residuals::residuals_and_jacobian`]).
    let n_free = free.iter().filter(|&&b| b).count();
    let mut jac_next: Option<DMatrix<f64>> = None;
    let mut fuses = true;
    let mut jac = DMatrix::zeros(0, 0);
    match p.residuals_and_jacobian(&theta, &mut f, free, &mut jac) {
        Some(done) => {
            done?;
            if f.iter().any(|x| x.is_nan()) {
                return Err(nan_residual(&theta));
            }
            jac_next = Some(jac);
        }
        None => {
            fuses = false;
            residuals_checked(p, &theta, &mut f)?;
        }
    }
    let mut chi2v: f64 = sum_squares(&f);
    let outcome = |theta: Vec<f64>, chi2: f64, it: usize, conv: bool, reason| LmOutcome {
        theta,
        chi2,
        iterations: it,
        converged: conv,
        reason,
    };
    if !chi2v.is_finite() {
        return Ok(outcome(
            theta,
            chi2v,
            0,
            false,
            "chi2 not finite at the start",
        ));
    }
    if !free.iter().any(|&b| b) {
        return Ok(outcome(theta, chi2v, 0, true, "no free parameters"));
    }
    let mut mu = 1e-3;
    let mut nu = 2.0;
    let mut f_new = vec![0.0; n];
    let mut need_jac = true;
    // The Jacobian at the last trial point, when the problem gave it with the residuals.
    let mut jac_trial = DMatrix::zeros(0, 0);
    // The last Jacobian used, its storage lent to the next trial point's (a matrix of n rows
    // allocated and zeroed at every trial cost a tenth of the iteration on 100 000 points).
    let mut spare = DMatrix::zeros(0, 0);
    // J^T J over the parameters free for the step (computed once per Jacobian).
    let mut a = DMatrix::zeros(0, 0);
    let mut free_now: Vec<bool> = free.to_vec();
    let mut g_full = vec![0.0; theta.len()];
    for it in 1..=opts.max_iterations {
        if need_jac {
            // Active set: a parameter on a bound whose descent direction leaves the box is held.
            let all = match jac_next.take() {
                Some(j) => j,
                None => jacobian(p, &theta, free, &f)?,
            };
            if !crate::cpu::fast(|| all.as_slice().iter().all(|x| x.is_finite())) {
                return Ok(outcome(theta, chi2v, it, false, "Jacobian not finite"));
            }
            let (g_all, norms, fnorm, jtj) = normal_parts(&all, &f);
            spare = all;
            let cols: Vec<usize> = (0..theta.len()).filter(|&j| free[j]).collect();
            let mut worst: f64 = 0.0;
            for (c, &j) in cols.iter().enumerate() {
                g_full[j] = g_all[c];
                let cn = norms[c];
                let at_lo = theta[j] <= lo[j] && g_all[c] > 0.0;
                let at_hi = theta[j] >= hi[j] && g_all[c] < 0.0;
                free_now[j] = !(at_lo || at_hi);
                if free_now[j] && cn > 0.0 && fnorm > 0.0 {
                    worst = worst.max(g_all[c].abs() / (cn * fnorm));
                }
            }
            if !worst.is_finite() {
                return Ok(outcome(theta, chi2v, it, false, "gradient not finite"));
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
            if let Some(enough) = enough
                && !p.kinked()
                && decrease_of(&g_all, &norms, &jtj) <= enough(chi2v)
            {
                return Ok(outcome(
                    theta,
                    chi2v,
                    it,
                    true,
                    "the Gauss-Newton step promises less than the tolerance",
                ));
            }
            let keep: Vec<usize> = cols
                .iter()
                .enumerate()
                .filter(|(_, j)| free_now[**j])
                .map(|(c, _)| c)
                .collect();
            a = jtj.select_rows(&keep).select_columns(&keep);
            need_jac = false;
        }
        let idx: Vec<usize> = (0..theta.len()).filter(|&j| free_now[j]).collect();
        let m = idx.len();
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
            None => DVector::from_element(m, f64::NAN),
        };
        if h.iter().any(|x| !x.is_finite()) {
            mu *= nu;
            nu *= 2.0;
            if !(mu <= 1e30) {
                return Ok(outcome(theta, chi2v, it, false, "damping overflow"));
            }
            continue;
        }
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
        // A step that will end the iteration if it is accepted (too small, or too little
        // decrease predicted) needs no Jacobian after it; a problem that declined once is not
        // asked again (nor is a matrix prepared for it).
        let last = small_step || pred <= opts.ftol * chi2v;
        let spec = if last || !fuses {
            None
        } else {
            // The spare is this fit's last Jacobian (the same shape) or none, which the problem
            // then makes ([`Residuals::residuals_and_jacobian`]).
            if jac_trial.shape() != (n, n_free) {
                jac_trial = std::mem::replace(&mut spare, DMatrix::zeros(0, 0));
            }
            let spec = p.residuals_and_jacobian(&trial, &mut f_new, free, &mut jac_trial);
            fuses = spec.is_some();
            spec
        };
        let with_jac = match spec {
            Some(done) => {
                done?;
                if f_new.iter().any(|x| x.is_nan()) {
                    return Err(nan_residual(&trial));
                }
                true
            }
            None => {
                residuals_checked(p, &trial, &mut f_new)?;
                false
            }
        };
        let chi2_new: f64 = sum_squares(&f_new);
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
            if with_jac {
                jac_next = Some(std::mem::replace(&mut jac_trial, DMatrix::zeros(0, 0)));
            }
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
            // `pred` is finite here: the step h and the matrix a are.
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
            if !(mu <= 1e30) {
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

#[cfg(test)]
pub(crate) mod tests {
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
    fn large_datas_normal_parts_are_nalgebras_to_rounding() {
        // 3 columns of 20 000 rows (the chunked path) against nalgebra's products (the small
        // path's): equal to the rounding of sums of 20 000 terms (1e-12 relative).
        let n = sums::PARALLEL_MIN_POINTS + 3616;
        assert!(sums::is_large(n));
        let x = |i: usize| (i as f64 * 0.37).sin();
        let all = DMatrix::from_fn(n, 3, |i, c| x(i + 7 * c) * (c + 1) as f64);
        let f: Vec<f64> = (0..n).map(|i| x(3 * i) - 0.2).collect();
        let (g, cn, fnorm, jtj) = normal_parts(&all, &f);
        let fv = DVector::from_column_slice(&f);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        let want_g = all.tr_mul(&fv);
        let want_jtj = all.tr_mul(&all);
        for a in 0..3 {
            assert!(close(g[a], want_g[a]), "{a}: {} {}", g[a], want_g[a]);
            assert!(close(cn[a], all.column(a).norm()), "{a}");
            for b in 0..3 {
                assert!(close(jtj[(a, b)], want_jtj[(a, b)]), "{a} {b}");
            }
        }
        assert!(close(fnorm, fv.norm()));
        assert!(close(sum_squares(&f), fv.norm_squared()));
        // Small data: nalgebra's own, bit for bit.
        let small = all.rows(0, 100).into_owned();
        let (g, _, _, jtj) = normal_parts(&small, &f[..100]);
        assert_eq!(g, small.tr_mul(&DVector::from_column_slice(&f[..100])));
        assert_eq!(jtj, small.tr_mul(&small));
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
    fn lm_stops_where_the_gauss_newton_step_promises_less_than_asked() {
        // Noisy decay data (min chi2 > 0): the tight run's minimum is the reference.
        let x: Vec<f64> = (0..20).map(|i| i as f64 * 0.25).collect();
        let y = (0..20)
            .map(|i| 3.0 * (-0.7 * x[i]).exp() + 0.01 * (3.0 * i as f64).sin())
            .collect();
        let p = Decay {
            x,
            y,
            lo: vec![-100.0, -100.0],
            hi: vec![100.0, 100.0],
        };
        let opts = LmOptions::default();
        let start = [1.0, 3.0];
        let tight = levenberg_marquardt(&p, &start, &[true, true], &opts).unwrap();
        assert!(tight.converged, "{tight:?}");
        // Stopped where the promise is below 1e-6: chi2 within it of the minimum (this problem
        // is nearly linear near its minimum, so the promise is the remaining decrease to within
        // a factor 2), in fewer iterations.
        let enough = |_: f64| 1e-6;
        let r = levenberg_marquardt_to(&p, &start, &[true, true], &opts, Some(&enough)).unwrap();
        assert!(r.converged && r.reason.contains("Gauss-Newton"), "{r:?}");
        assert!(r.chi2 - tight.chi2 <= 2e-6, "{} vs {}", r.chi2, tight.chi2);
        assert!(r.iterations < tight.iterations, "{r:?} {tight:?}");
        // A promise below anything: the first Jacobian already satisfies it.
        let all = |_: f64| f64::MAX;
        let r = levenberg_marquardt_to(&p, &start, &[true, true], &opts, Some(&all)).unwrap();
        assert_eq!((r.iterations, r.theta.as_slice()), (1, &start[..]));
        // A problem with kinks ignores the promise: the tight run, to the last bit.
        struct Kinked(Decay);
        impl Residuals for Kinked {
            fn n_params(&self) -> usize {
                2
            }
            fn n_residuals(&self) -> usize {
                self.0.n_residuals()
            }
            fn residuals(&self, t: &[f64], out: &mut [f64]) -> Result<()> {
                self.0.residuals(t, out)
            }
            fn lower(&self) -> &[f64] {
                self.0.lower()
            }
            fn upper(&self) -> &[f64] {
                self.0.upper()
            }
            fn fd_step(&self) -> f64 {
                self.0.fd_step()
            }
            fn kinked(&self) -> bool {
                true
            }
        }
        let k = Kinked(p);
        let r = levenberg_marquardt_to(&k, &start, &[true, true], &opts, Some(&all)).unwrap();
        assert_eq!(r, tight);
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

    /// y = c0 + c1 x, sigma = 1: a model linear in its parameters (closed-form answers), shared
    /// with the profile intervals' tests. It has as many parameters as `lo` has entries; those
    /// beyond c0 and c1 have no effect (a plateau).
    pub(crate) struct Line {
        pub x: Vec<f64>,
        pub y: Vec<f64>,
        pub lo: Vec<f64>,
        pub hi: Vec<f64>,
    }

    impl Residuals for Line {
        fn n_params(&self) -> usize {
            self.lo.len()
        }
        fn n_residuals(&self) -> usize {
            self.x.len()
        }
        fn residuals(&self, t: &[f64], out: &mut [f64]) -> Result<()> {
            for (o, (&x, &y)) in out.iter_mut().zip(self.x.iter().zip(&self.y)) {
                *o = t[0] + t[1] * x - y;
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
    fn gauss_newton_decrease_of_a_line_is_the_distance_to_its_minimum() {
        // For a model linear in theta chi2 is quadratic, so one Gauss-Newton step lands on the
        // minimum: the predicted decrease is chi2(theta) - chi2_min, chi2_min from the closed
        // form of ordinary least squares. Central differences of a linear model are exact to
        // rounding: 1e-9 relative covers the sums. The parameter without effect adds nothing.
        let x: Vec<f64> = (0..30).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, &x)| 1.5 - 0.8 * x + 0.05 * (i as f64 * 1.7).sin())
            .collect();
        let n = x.len() as f64;
        let (sx, sy) = (x.iter().sum::<f64>(), y.iter().sum::<f64>());
        let sxx: f64 = x.iter().map(|x| x * x).sum();
        let sxy: f64 = x.iter().zip(&y).map(|(x, y)| x * y).sum();
        let c1 = (n * sxy - sx * sy) / (n * sxx - sx * sx);
        let c0 = (sy - c1 * sx) / n;
        let p = Line {
            x,
            y,
            lo: vec![-10.0; 3],
            hi: vec![10.0; 3],
        };
        let at_min = chi2(&p, &[c0, c1, 0.0]).unwrap();
        for t in [[0.0, 0.0, 0.0], [c0 + 0.3, c1 - 0.2, 5.0], [c0, c1, -2.0]] {
            let want = chi2(&p, &t).unwrap() - at_min;
            let got = gauss_newton_decrease(&p, &t).unwrap();
            assert!(
                (got - want).abs() <= 1e-9 * want.max(at_min),
                "{t:?}: {got} {want}"
            );
        }
        // Residuals that overflow (a difference of -inf and -inf in the Jacobian): +inf, never
        // NaN (which compares as below every threshold).
        let mut q = p;
        q.y[0] = f64::MAX;
        let got = gauss_newton_decrease(&q, &[-f64::MAX, 0.0, 0.0]).unwrap();
        assert_eq!(got, f64::INFINITY);
    }

    #[test]
    fn lm_failures_are_values_not_hangs() {
        let x: Vec<f64> = (0..20).map(|i| i as f64 * 0.25).collect();
        let y: Vec<f64> = x.iter().map(|&x| 3.0 * (-0.7 * x).exp()).collect();
        let p = Decay {
            x: x.clone(),
            y: y.clone(),
            lo: vec![-100.0, -100.0],
            hi: vec![100.0, 100.0],
        };
        // The iteration cap ends the run unconverged, with the reason.
        let one = LmOptions {
            max_iterations: 1,
            ..LmOptions::default()
        };
        let r = levenberg_marquardt(&p, &[1.0, 3.0], &[true, true], &one).unwrap();
        assert!(
            !r.converged && r.reason == "maximum number of iterations",
            "{r:?}"
        );
        // A non-finite start is an error; so is a model returning NaN.
        assert!(levenberg_marquardt(&p, &[f64::NAN, 3.0], &[true, true], &one).is_err());
        let mut bad = Decay {
            x,
            y,
            lo: vec![-100.0, -100.0],
            hi: vec![100.0, 100.0],
        };
        bad.y[3] = f64::NAN;
        let opts = LmOptions::default();
        assert!(levenberg_marquardt(&bad, &[1.0, 3.0], &[true, true], &opts).is_err());
        // Residuals whose squares overflow: unconverged at the start, not a wrong minimum.
        bad.y[3] = 1e200;
        let r = levenberg_marquardt(&bad, &[1.0, 3.0], &[true, true], &opts).unwrap();
        assert!(!r.converged && r.chi2.is_infinite(), "{r:?}");
    }
}
