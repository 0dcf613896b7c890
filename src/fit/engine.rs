//! The fit itself: global search, local polish, uncertainties and profile-likelihood intervals.
//!
//! **Solves** min chi2 = sum_i ((e_i - model_i)/sigma_i)^2 over the model's parameters (sigma_i = 1
//! for data without errors), inside a search box wide enough for any data a user can have:
//! - eta such that the largest kappa in the data lies in [1e-8, 0.999 KAPPA_MAX]: below, 1 - e is
//!   under 1.2e-8 at every point (elastic for any measurement); above, e < 1e-9 and the master
//!   curve would hand over to the ODE;
//! - sigma_y from where every point has V/V_Y >= 1e6 (e_pm < 0.04) up to where no point yields
//!   (V_Y >= 1.5 v for every point: the plateau where sigma_y stops mattering);
//! - powerlaw: A in [1e-9, 1e3], a and b in [-10, 10].
//!
//! **Global minimum.** A local solver started at a fixed guess stalls on the plateaus of the
//! two-parameter models (sigma_y so high that the plastic branch never acts leaves chi2 flat in
//! sigma_y, and the gradient there is exactly zero). So the search starts with a scan: a grid in
//! log eta (spacing 0.5) and log sigma_y (spacing 0.1, i.e. 0.25 in log V_Y); for `min` and
//! `product` the full 2-D grid, made cheap by caching e_vm per eta row and e_pm per sigma column.
//! One-parameter models are then polished by Brent's method (argmin) inside the bracket of the
//! best grid point; two-parameter models by Levenberg-Marquardt ([`super::lsq`]) from the three
//! best separated local minima of the grid. The power law is nearly linear in log(1 - e), so a
//! weighted linear fit of log(1 - e) starts it. While the profile intervals are computed, a
//! profile point below the minimum would reveal a missed minimum: the fit then restarts from it.
//!
//! **Uncertainties** (lmfit / scipy `curve_fit` conventions): with J the Jacobian of the weighted
//! residuals at the minimum, C = (J^T J)^-1; `stderr_abs` = sqrt(C_jj) (error bars taken as exact),
//! `stderr` = sqrt(C_jj chi2/dof). Log-fitted parameters convert by the delta method
//! (stderr of x = x stderr of ln x). The 95% interval is the profile-likelihood interval:
//! the set of values whose profile chi2 (all other parameters re-minimised) stays within
//! Delta = 3.84 s of the minimum, s = max(1, chi2/dof) (errors as given unless the scatter shows
//! them too small, the Particle Data Group's scale-factor rule); unweighted fits use
//! s = chi2/dof, the only scale they have. A parameter whose interval is open on one side (its
//! profile stays below the threshold up to the edge of the search box) is reported as a bound:
//! the data cannot exclude the parameter ceasing to matter, so a value with an error bar would
//! mislead.

use super::dataset::{FitData, pair_contact};
use super::lsq::{self, LmOptions, LmOutcome, Residuals};
use super::models::{Evaluator, ModelKind};
use crate::error::{Error, Result};
use crate::models::viscoelastic::{ContactEnd, VmMethod, master::KAPPA_MAX};
use std::cell::Cell;

/// chi2 quantile of one degree of freedom at 95% (the profile-likelihood interval threshold).
pub const CHI2_1DOF_95: f64 = 3.841458820694124;

/// How to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// End-of-contact rule of the viscoelastic model.
    pub rule: ContactEnd,
    /// How e_vm is evaluated: master curve (default) or the ODE at every point (`--exact`).
    pub vm_method: VmMethod,
    /// Scan the search box before polishing (default). Without it only the local solver runs,
    /// from `start`: kept to show what the scan is for.
    pub scan: bool,
    /// An extra starting point, physical values in the order of [`ModelKind::params`].
    pub start: Option<Vec<f64>>,
    /// Compute the profile-likelihood intervals (default); off, only the covariance is used.
    pub intervals: bool,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            rule: ContactEnd::Overlap,
            vm_method: VmMethod::Master,
            scan: true,
            start: None,
            intervals: true,
        }
    }
}

/// How well the data determine a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamStatus {
    /// A value with an error and a closed 95% interval.
    Estimate,
    /// Only a lower 95% bound: above it the data cannot tell values apart.
    LowerBound,
    /// Only an upper 95% bound.
    UpperBound,
    /// Neither side is bounded inside the search box.
    Unconstrained,
}

impl ParamStatus {
    pub fn name(self) -> &'static str {
        match self {
            ParamStatus::Estimate => "estimate",
            ParamStatus::LowerBound => "lower_bound",
            ParamStatus::UpperBound => "upper_bound",
            ParamStatus::Unconstrained => "unconstrained",
        }
    }
}

/// One fitted (or derived) parameter, in physical units.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamEstimate {
    pub key: &'static str,
    pub unit: &'static str,
    pub status: ParamStatus,
    /// Where the minimiser ended (on a plateau this is arbitrary: see `status`).
    pub best_fit: f64,
    /// The estimate, for [`ParamStatus::Estimate`] only.
    pub value: Option<f64>,
    /// Standard error scaled by sqrt(chi2/dof).
    pub stderr: Option<f64>,
    /// Standard error with the error bars taken as exact (None for unweighted fits).
    pub stderr_abs: Option<f64>,
    /// 95% profile-likelihood interval; `None` on an open side.
    pub ci95: (Option<f64>, Option<f64>),
}

/// The result of fitting one model.
#[derive(Debug, Clone, PartialEq)]
pub struct FitResult {
    pub model: ModelKind,
    pub params: Vec<ParamEstimate>,
    /// Quantities derived from the parameters: `A_s` (Brilliantov's A = 2 eta / E*, s) and
    /// `v_yield_m_s` (V_Y, Eq. 15, of the data's pair geometry when all points share one, as
    /// identical spheres of any sizes do; else of identical spheres).
    pub derived: Vec<ParamEstimate>,
    /// Correlation matrix of the parameters (NaN where undetermined).
    pub correlation: Vec<Vec<f64>>,
    pub n: usize,
    pub dof: usize,
    pub weighted: bool,
    /// chi2 (weighted) or the residual sum of squares (unweighted).
    pub chi2: f64,
    pub reduced_chi2: f64,
    /// chi2 + 2k (weighted), n ln(RSS/n) + 2k (unweighted).
    pub aic: f64,
    /// AIC with the small-sample correction 2k(k+1)/(n-k-1).
    pub aicc: f64,
    /// chi2 + k ln n (weighted), n ln(RSS/n) + k ln n (unweighted).
    pub bic: f64,
    /// The Delta chi2 that defines the 95% intervals (3.84 s, see the module doc).
    pub ci95_delta_chi2: f64,
    pub converged: bool,
    /// Model evaluations (each over all points) for the scan and polish.
    pub evaluations: u64,
    /// Model evaluations for the profile-likelihood intervals.
    pub profile_evaluations: u64,
    /// Internal coordinates at the minimum (logarithms for eta, sigma_y, A).
    pub theta: Vec<f64>,
    /// Model e at each point, and (e - model)/sigma.
    pub predicted: Vec<f64>,
    pub normalized_residuals: Vec<f64>,
    /// Things a user should know: parameters at the edge of the search box, non-convergence.
    pub notes: Vec<String>,
}

impl FitResult {
    pub fn param(&self, key: &str) -> Option<&ParamEstimate> {
        self.params.iter().find(|p| p.key == key)
    }

    pub fn derived(&self, key: &str) -> Option<&ParamEstimate> {
        self.derived.iter().find(|p| p.key == key)
    }

    /// The best-fit parameters in physical units (for drawing the model).
    pub fn best_fit_values(&self) -> Vec<f64> {
        self.model.to_physical(&self.theta)
    }

    pub fn k(&self) -> usize {
        self.params.len()
    }
}

/// The least-squares problem of one model on one data set, counting its evaluations.
struct Objective<'a> {
    ev: &'a Evaluator<'a>,
    kind: ModelKind,
    lower: Vec<f64>,
    upper: Vec<f64>,
    fd_step: f64,
    evals: Cell<u64>,
    inv_sigma: Vec<f64>,
}

impl Residuals for Objective<'_> {
    fn n_params(&self) -> usize {
        self.kind.n_params()
    }
    fn n_residuals(&self) -> usize {
        self.ev.len()
    }
    fn residuals(&self, theta: &[f64], out: &mut [f64]) -> Result<()> {
        self.evals.set(self.evals.get() + 1);
        let p = self.kind.to_physical(theta);
        self.ev.predict(self.kind, &p, out)?;
        for (i, o) in out.iter_mut().enumerate() {
            *o = (*o - self.ev.data.obs[i].e) * self.inv_sigma[i];
        }
        Ok(())
    }
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn fd_step(&self) -> f64 {
        self.fd_step
    }
}

/// The finite-difference step in the log parameters matched to the accuracy of e: the closed
/// forms and the master curve (2.4e-15) give (1e-15)^(1/3) = 1e-5; the ODE its tolerance^(1/3).
fn fd_step_for(kind: ModelKind, method: &VmMethod) -> f64 {
    match (kind, method) {
        (ModelKind::Vm | ModelKind::Min | ModelKind::Product, VmMethod::Ode(s)) => {
            s.rtol.max(s.atol).cbrt().clamp(1e-5, 1e-2)
        }
        _ => 1e-5,
    }
}

/// Search box of log eta (see the module doc).
fn log_eta_range(ev: &Evaluator) -> (f64, f64) {
    let k = ev.max_kappa_per_eta();
    ((1e-8 / k).ln(), (0.999 * KAPPA_MAX / k).ln())
}

/// Search box of log sigma_y (see the module doc).
fn log_sigma_range(ev: &Evaluator) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for (i, o) in ev.data.obs.iter().enumerate() {
        lo = lo.min(ev.sigma_y_for_v_yield(i, o.v_n_m_s * 1e-6).ln());
        hi = hi.max(ev.sigma_y_for_v_yield(i, o.v_n_m_s * 1.5).ln());
    }
    (lo, hi)
}

fn bounds(kind: ModelKind, ev: &Evaluator) -> (Vec<f64>, Vec<f64>) {
    let (el, eh) = log_eta_range(ev);
    let (sl, sh) = log_sigma_range(ev);
    match kind {
        ModelKind::Vm => (vec![el], vec![eh]),
        ModelKind::Pm => (vec![sl], vec![sh]),
        ModelKind::Min | ModelKind::Product => (vec![el, sl], vec![eh, sh]),
        ModelKind::PowerLaw => (
            vec![1e-9f64.ln(), -10.0, -10.0],
            vec![1e3f64.ln(), 10.0, 10.0],
        ),
    }
}

fn grid(lo: f64, hi: f64, spacing: f64) -> Vec<f64> {
    let n = ((hi - lo) / spacing).ceil().max(1.0) as usize;
    (0..=n)
        .map(|k| lo + (hi - lo) * k as f64 / n as f64)
        .collect()
}

/// Fits one model to the data.
pub fn fit(data: &FitData, kind: ModelKind, options: &FitOptions) -> Result<FitResult> {
    let k = kind.n_params();
    if data.len() <= k {
        return Err(Error::InvalidParameter {
            name: "number of data points",
            value: data.len() as f64,
            expected: "more points than the model has parameters",
        });
    }
    if let Some(s) = &options.start
        && (s.len() != k || s.iter().any(|x| !x.is_finite()))
    {
        return Err(Error::InvalidParameter {
            name: "number of start values",
            value: s.len() as f64,
            expected: "one finite value per model parameter",
        });
    }
    let ev = Evaluator::new(data, options.rule, options.vm_method);
    let (lower, upper) = bounds(kind, &ev);
    let obj = Objective {
        ev: &ev,
        kind,
        lower,
        upper,
        fd_step: fd_step_for(kind, &options.vm_method),
        evals: Cell::new(0),
        inv_sigma: (0..data.len()).map(|i| 1.0 / data.sigma(i)).collect(),
    };
    let mut best = global_minimum(&obj, options)?;
    let fit_evals = obj.evals.get();
    let mut notes = Vec::new();
    // Profiles can reveal a lower minimum than the search found; restart from it (twice at most).
    let mut profiles = None;
    if options.intervals {
        for _ in 0..3 {
            let cov = covariance_at(&obj, &best.theta)?;
            match profile_intervals(&obj, &best, &cov)? {
                Ok(p) => {
                    profiles = Some(p);
                    break;
                }
                Err(lower_theta) => {
                    notes.push("a profile found a lower minimum than the search; refitted".into());
                    let all = vec![true; k];
                    let again =
                        lsq::levenberg_marquardt(&obj, &lower_theta, &all, &LmOptions::default())?;
                    if again.chi2 < best.chi2 {
                        best = again;
                    }
                }
            }
        }
    }
    let profile_evals = obj.evals.get() - fit_evals;
    summarise(&obj, best, profiles, fit_evals, profile_evals, notes)
}

/// Scan, then polish the best candidates; the best polished point.
fn global_minimum(obj: &Objective, options: &FitOptions) -> Result<LmOutcome> {
    let kind = obj.kind;
    let k = kind.n_params();
    let all = vec![true; k];
    let lm = LmOptions::default();
    let mut candidates: Vec<LmOutcome> = Vec::new();
    if let Some(s) = &options.start {
        let t0 = kind.to_internal(s);
        candidates.push(lsq::levenberg_marquardt(obj, &t0, &all, &lm)?);
    }
    if options.scan {
        match kind {
            ModelKind::Vm | ModelKind::Pm => candidates.push(scan_1d(obj)?),
            ModelKind::Min | ModelKind::Product => {
                for start in scan_2d(obj)? {
                    candidates.push(lsq::levenberg_marquardt(obj, &start, &all, &lm)?);
                }
            }
            ModelKind::PowerLaw => {
                let mut starts = vec![vec![0.05f64.ln(), 0.5, 0.2], vec![0.05f64.ln(), 1.0, 0.2]];
                if let Some(t) = powerlaw_linear_start(obj) {
                    starts.insert(0, t);
                }
                for start in starts {
                    candidates.push(lsq::levenberg_marquardt(obj, &start, &all, &lm)?);
                }
            }
        }
    } else if options.start.is_none() {
        // No scan and no start: a generic guess in the middle of the box.
        let mid: Vec<f64> = (0..k)
            .map(|j| 0.5 * (obj.lower[j] + obj.upper[j]))
            .collect();
        candidates.push(lsq::levenberg_marquardt(obj, &mid, &all, &lm)?);
    }
    let best = candidates
        .into_iter()
        .min_by(|a, b| a.chi2.total_cmp(&b.chi2))
        .expect("at least one candidate");
    Ok(best)
}

/// Grid in the single parameter, then Brent inside the bracket of the best grid point.
fn scan_1d(obj: &Objective) -> Result<LmOutcome> {
    let spacing = if obj.kind == ModelKind::Vm { 0.5 } else { 0.1 };
    let g = grid(obj.lower[0], obj.upper[0], spacing);
    // A grid point where the model cannot be evaluated (a coarse ODE setting refusing a large
    // kappa far from the data's optimum) is rejected, not fatal; the polish still needs the
    // model where the minimum is.
    let vals: Vec<f64> = g
        .iter()
        .map(|&t| lsq::chi2(obj, &[t]).unwrap_or(f64::INFINITY))
        .collect();
    let kbest = (0..g.len())
        .min_by(|&a, &b| vals[a].total_cmp(&vals[b]))
        .unwrap_or(0);
    let a = g[kbest.saturating_sub(1)];
    let b = g[(kbest + 1).min(g.len() - 1)];
    let (x, fx, converged) = lsq::brent_minimize(|t| lsq::chi2(obj, &[t]), a, b, 1e-10)?;
    // Brent never evaluates the bracket ends; the grid point may be the minimum (box edge).
    let (x, fx) = if vals[kbest] < fx {
        (g[kbest], vals[kbest])
    } else {
        (x, fx)
    };
    Ok(LmOutcome {
        theta: vec![x],
        chi2: fx,
        iterations: 0,
        converged,
        reason: "Brent",
    })
}

/// The profile of chi2 over a grid in log sigma_y for `min` and `product`: for each sigma_y the
/// best log eta, bracketed by a grid in log eta (e_vm cached per row) and refined by Brent.
/// Returns up to three starting points: the best local minima of the profile at least three
/// grid steps apart. A plain 2-D grid is not enough: the eta valley is narrow (a few per cent)
/// and curved, so between eta rows a shallow dip in sigma_y below the plateau is invisible.
fn scan_2d(obj: &Objective) -> Result<Vec<Vec<f64>>> {
    let ev = obj.ev;
    let n = ev.len();
    let ge = grid(obj.lower[0], obj.upper[0], 0.5);
    let gs = grid(obj.lower[1], obj.upper[1], 0.1);
    let min_rule = obj.kind == ModelKind::Min;
    let combine = |x: f64, y: f64| if min_rule { x.min(y) } else { x * y };
    let chi2_with = |vm: &dyn Fn(usize) -> Result<f64>, pm: &[f64]| -> Result<f64> {
        let mut c = 0.0;
        for (i, &p) in pm.iter().enumerate().take(n) {
            let r = (combine(vm(i)?, p) - ev.data.obs[i].e) * obj.inv_sigma[i];
            c += r * r;
        }
        obj.evals.set(obj.evals.get() + 1);
        Ok(c)
    };
    // Rows where e_vm cannot be evaluated (see scan_1d) are marked and rejected below.
    let mut vm_rows = vec![0.0; ge.len() * n];
    let mut row_ok = vec![true; ge.len()];
    for (a, &t) in ge.iter().enumerate() {
        for i in 0..n {
            match ev.e_vm(i, t.exp()) {
                Ok(e) => vm_rows[a * n + i] = e,
                Err(_) => row_ok[a] = false,
            }
        }
    }
    let mut profile = Vec::with_capacity(gs.len());
    let mut pm = vec![0.0; n];
    for &ts in &gs {
        for (i, slot) in pm.iter_mut().enumerate() {
            *slot = ev.e_pm(i, ts.exp());
        }
        let mut coarse = Vec::with_capacity(ge.len());
        for a in 0..ge.len() {
            coarse.push(if row_ok[a] {
                chi2_with(&|i| Ok(vm_rows[a * n + i]), &pm)?
            } else {
                f64::INFINITY
            });
        }
        let abest = (0..ge.len())
            .min_by(|&x, &y| coarse[x].total_cmp(&coarse[y]))
            .unwrap_or(0);
        let lo = ge[abest.saturating_sub(1)];
        let hi = ge[(abest + 1).min(ge.len() - 1)];
        let (te, c, _) = lsq::brent_minimize(
            |te| chi2_with(&|i| ev.e_vm(i, te.exp()), &pm),
            lo,
            hi,
            // Only a starting point for the polish: 1e-3 in log eta changes chi2 by
            // (1e-3 / stderr(log eta))^2, below 0.01 for any eta known to better than 1%.
            1e-3,
        )?;
        let (te, c) = if coarse[abest] < c {
            (ge[abest], coarse[abest])
        } else {
            (te, c)
        };
        profile.push((c, te));
    }
    let mut minima: Vec<usize> = (0..gs.len())
        .filter(|&b| {
            (b == 0 || profile[b - 1].0 >= profile[b].0)
                && (b + 1 == gs.len() || profile[b + 1].0 >= profile[b].0)
        })
        .collect();
    minima.sort_by(|&x, &y| profile[x].0.total_cmp(&profile[y].0));
    let mut chosen: Vec<usize> = Vec::new();
    for b in minima {
        if chosen.iter().all(|&c| c.abs_diff(b) > 2) {
            chosen.push(b);
        }
        if chosen.len() == 3 {
            break;
        }
    }
    Ok(chosen
        .into_iter()
        .map(|b| vec![profile[b].1, gs[b]])
        .collect())
}

/// Weighted linear least squares of ln(1 - e) = ln A - a ln(d/d_ref) + b ln(v/v_ref) over the
/// points with e < 1, weights ((1 - e)/sigma)^2 (the propagated error of ln(1 - e)).
/// With a single size the a column is constant: a is then held at 1/2.
fn powerlaw_linear_start(obj: &Objective) -> Option<Vec<f64>> {
    use super::models::{POWERLAW_D_REF_MM, POWERLAW_V_REF_M_S, powerlaw_d_mm};
    let data = obj.ev.data;
    let mut rows = Vec::new();
    for (i, o) in data.obs.iter().enumerate() {
        let y = 1.0 - o.e;
        if y > 1e-9 {
            let w = (y * obj.inv_sigma[i]).powi(2);
            let x1 = -(powerlaw_d_mm(&data.contacts[i]) / POWERLAW_D_REF_MM).ln();
            let x2 = (o.v_n_m_s / POWERLAW_V_REF_M_S).ln();
            rows.push((w, x1, x2, y.ln()));
        }
    }
    if rows.len() < 3 {
        return None;
    }
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut atb = nalgebra::Vector3::<f64>::zeros();
    for &(w, x1, x2, y) in &rows {
        let x = nalgebra::Vector3::new(1.0, x1, x2);
        ata += w * x * x.transpose();
        atb += w * y * x;
    }
    let sol = ata.cholesky().map(|c| c.solve(&atb)).filter(|s| {
        s.iter().all(|v| v.is_finite()) && ata.determinant().abs() > 1e-12 * ata.norm().powi(3)
    });
    let t = match sol {
        Some(s) => vec![s[0], s[1], s[2]],
        None => {
            let (mut s00, mut s01, mut s11, mut r0, mut r1) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for &(w, x1, x2, y) in &rows {
                let y = y - 0.5 * x1;
                s00 += w;
                s01 += w * x2;
                s11 += w * x2 * x2;
                r0 += w * y;
                r1 += w * x2 * y;
            }
            let det = s00 * s11 - s01 * s01;
            if det.abs() <= 1e-300 {
                return None;
            }
            vec![
                (r0 * s11 - r1 * s01) / det,
                0.5,
                (s00 * r1 - s01 * r0) / det,
            ]
        }
    };
    Some(
        t.iter()
            .enumerate()
            .map(|(j, &x)| x.clamp(obj.lower[j], obj.upper[j]))
            .collect(),
    )
}

/// Per parameter, the 95% profile-likelihood crossings (internal coordinates; `None` = open),
/// or `Err(theta)` when a profile point beat the minimum (the search missed it).
type Crossings = Vec<(Option<f64>, Option<f64>)>;

struct Profiles {
    crossings: Crossings,
    delta: f64,
}

fn scale_of(obj: &Objective, chi2: f64) -> f64 {
    let dof = (obj.ev.len() - obj.kind.n_params()) as f64;
    let red = chi2 / dof;
    if obj.ev.data.weighted {
        red.max(1.0)
    } else {
        red
    }
}

/// The covariance at theta from the Jacobian of the weighted residuals.
fn covariance_at(obj: &Objective, theta: &[f64]) -> Result<lsq::Covariance> {
    let mut f0 = vec![0.0; obj.ev.len()];
    obj.residuals(theta, &mut f0)?;
    let jac = lsq::jacobian(obj, theta, &vec![true; theta.len()], &f0)?;
    Ok(lsq::covariance(&jac))
}

#[allow(clippy::type_complexity)]
fn profile_intervals(
    obj: &Objective,
    best: &LmOutcome,
    cov: &lsq::Covariance,
) -> Result<std::result::Result<Profiles, Vec<f64>>> {
    let k = obj.kind.n_params();
    let theta = &best.theta;
    let delta = CHI2_1DOF_95 * scale_of(obj, best.chi2);
    let threshold = best.chi2 + delta;
    // A profile point this far below the minimum means a missed minimum, not rounding.
    let beaten = best.chi2 - 1e-7 * best.chi2.max(1.0);
    let mut crossings = Vec::with_capacity(k);
    let lm = LmOptions::default();
    for j in 0..k {
        if cov.degenerate[j] {
            // Only a combination with other parameters is determined; a profile would end only
            // at the edges of the other parameters' search ranges.
            crossings.push((None, None));
            continue;
        }
        let step = (delta * cov.matrix[(j, j)]).sqrt();
        let step = if step.is_finite() && step > 0.0 {
            step.min(0.25 * (obj.upper[j] - obj.lower[j]))
        } else {
            0.1
        };
        let mut sides = [None, None];
        for (s, limit) in [obj.lower[j], obj.upper[j]].into_iter().enumerate() {
            // Warm starts: the inner minimum at the nearest profile point already computed, so
            // the profile follows one valley continuously.
            let warm = std::cell::RefCell::new(vec![(theta[j], theta.clone())]);
            let lower_found = std::cell::RefCell::new(None::<Vec<f64>>);
            let profile = |t: f64| -> Result<f64> {
                if k == 1 {
                    let c = lsq::chi2(obj, &[t])?;
                    if c < beaten {
                        *lower_found.borrow_mut() = Some(vec![t]);
                    }
                    return Ok(c);
                }
                let mut start = warm
                    .borrow()
                    .iter()
                    .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
                    .map(|(_, th)| th.clone())
                    .unwrap_or_else(|| theta.clone());
                start[j] = t;
                let mut free = vec![true; k];
                free[j] = false;
                let r = lsq::levenberg_marquardt(obj, &start, &free, &lm)?;
                if r.chi2 < beaten {
                    *lower_found.borrow_mut() = Some(r.theta.clone());
                }
                warm.borrow_mut().push((t, r.theta));
                Ok(r.chi2)
            };
            sides[s] = lsq::profile_crossing(profile, theta[j], limit, step, threshold, 1e-7)?;
            if let Some(t) = lower_found.into_inner() {
                return Ok(Err(t));
            }
        }
        crossings.push((sides[0], sides[1]));
    }
    Ok(Ok(Profiles { crossings, delta }))
}

fn summarise(
    obj: &Objective,
    best: LmOutcome,
    profiles: Option<Profiles>,
    fit_evals: u64,
    profile_evals: u64,
    mut notes: Vec<String>,
) -> Result<FitResult> {
    let kind = obj.kind;
    let data = obj.ev.data;
    let n = data.len();
    let k = kind.n_params();
    let theta = best.theta.clone();
    let chi2 = lsq::chi2(obj, &theta)?;
    let full_cov = covariance_at(obj, &theta)?;
    let cov = &full_cov.matrix;
    let dof = n - k;
    let reduced = chi2 / dof as f64;
    let phys = kind.to_physical(&theta);
    let specs = kind.params();
    let mut params = Vec::with_capacity(k);
    for j in 0..k {
        let spec = specs[j];
        let to_phys = |t: f64| if spec.log { t.exp() } else { t };
        let dscale = if spec.log { phys[j] } else { 1.0 };
        let sd = cov[(j, j)].sqrt();
        let finite = |x: f64| Some(x).filter(|x| x.is_finite());
        let (status, ci) = match &profiles {
            _ if full_cov.degenerate[j] => (ParamStatus::Unconstrained, (None, None)),
            Some(p) => {
                let (lo, hi) = p.crossings[j];
                let status = match (lo, hi) {
                    (Some(_), Some(_)) => ParamStatus::Estimate,
                    (Some(_), None) => ParamStatus::LowerBound,
                    (None, Some(_)) => ParamStatus::UpperBound,
                    (None, None) => ParamStatus::Unconstrained,
                };
                (status, (lo.map(to_phys), hi.map(to_phys)))
            }
            None => {
                let status = if sd.is_finite() {
                    ParamStatus::Estimate
                } else {
                    ParamStatus::Unconstrained
                };
                (status, (None, None))
            }
        };
        let est = status == ParamStatus::Estimate;
        if full_cov.degenerate[j] {
            notes.push(format!(
                "{} is determined only in combination with other parameters (collinear); \
                 reported as unconstrained",
                spec.key
            ));
        }
        params.push(ParamEstimate {
            key: spec.key,
            unit: spec.unit,
            status,
            best_fit: phys[j],
            value: est.then_some(phys[j]),
            stderr: if est {
                finite(sd * dscale * reduced.sqrt())
            } else {
                None
            },
            stderr_abs: if est && data.weighted {
                finite(sd * dscale)
            } else {
                None
            },
            ci95: ci,
        });
        let span = obj.upper[j] - obj.lower[j];
        if (theta[j] - obj.lower[j]).abs() < 1e-6 * span
            || (theta[j] - obj.upper[j]).abs() < 1e-6 * span
        {
            let unit = if spec.unit == "1" {
                String::new()
            } else {
                format!(" {}", spec.unit)
            };
            notes.push(format!(
                "{} ended at the edge of its search range ({}{unit})",
                spec.key,
                crate::data::fmt_num(phys[j]),
            ));
        }
    }
    let correlation = (0..k)
        .map(|i| {
            (0..k)
                .map(|j| cov[(i, j)] / (cov[(i, i)] * cov[(j, j)]).sqrt())
                .collect()
        })
        .collect();
    let mut predicted = vec![0.0; n];
    obj.ev.predict(kind, &phys, &mut predicted)?;
    let normalized_residuals = (0..n)
        .map(|i| (data.obs[i].e - predicted[i]) * obj.inv_sigma[i])
        .collect();
    let (kf, nf) = (k as f64, n as f64);
    let base = if data.weighted {
        chi2
    } else {
        nf * (chi2 / nf).ln()
    };
    let aic = base + 2.0 * kf;
    let aicc = if n > k + 1 {
        aic + 2.0 * kf * (kf + 1.0) / (nf - kf - 1.0)
    } else {
        f64::NAN
    };
    if !best.converged {
        notes.push(format!("the minimiser did not converge ({})", best.reason));
    }
    if !data.weighted {
        notes.push(
            "unweighted (no e_err or v_err_m_s): chi2 is the residual sum of squares, and the \
             errors come from the scatter alone"
                .into(),
        );
    }
    let derived = derive(data, &params);
    Ok(FitResult {
        model: kind,
        params,
        derived,
        correlation,
        n,
        dof,
        weighted: data.weighted,
        chi2,
        reduced_chi2: reduced,
        aic,
        aicc,
        bic: base + kf * nf.ln(),
        ci95_delta_chi2: profiles
            .as_ref()
            .map(|p| p.delta)
            .unwrap_or(CHI2_1DOF_95 * scale_of(obj, chi2)),
        converged: best.converged,
        evaluations: fit_evals,
        profile_evaluations: profile_evals,
        theta,
        predicted,
        normalized_residuals,
        notes,
    })
}

/// A monotone function of a parameter, x -> c x^power, applied to its estimate, error and bounds.
fn map_param(
    p: &ParamEstimate,
    key: &'static str,
    unit: &'static str,
    f: impl Fn(f64) -> f64,
    power: f64,
) -> ParamEstimate {
    let rel = |s: Option<f64>| s.map(|s| (power * s / p.best_fit * f(p.best_fit)).abs());
    let (lo, hi) = (p.ci95.0.map(&f), p.ci95.1.map(&f));
    let (lo, hi) = if power < 0.0 { (hi, lo) } else { (lo, hi) };
    ParamEstimate {
        key,
        unit,
        status: p.status,
        best_fit: f(p.best_fit),
        value: p.value.map(&f),
        stderr: rel(p.stderr),
        stderr_abs: rel(p.stderr_abs),
        ci95: (lo, hi),
    }
}

fn derive(data: &FitData, params: &[ParamEstimate]) -> Vec<ParamEstimate> {
    let mut out = Vec::new();
    if let Some(eta) = params.iter().find(|p| p.key == "eta") {
        // A = 2C/(3K) = 2 eta / E*: the same for every pair of one material (PHYSICS.md §2).
        let c = data.contacts[0];
        out.push(map_param(eta, "A_s", "s", |x| c.brilliantov_a_s(x), 1.0));
    }
    if let Some(sy) = params.iter().find(|p| p.key == "sigma_y")
        && let Ok(identical) = pair_contact(data.material, 10.0, None)
    {
        // V_Y of the data's pairs when they all share one (identical spheres of any size do:
        // Eq. 15 has no size in it); otherwise that of identical spheres. V_Y ~ sigma_y^(5/2).
        let first = data.contacts[0].yield_velocity_m_s(1.0);
        let shared = data
            .contacts
            .iter()
            .all(|c| (c.yield_velocity_m_s(1.0) / first - 1.0).abs() < 1e-9);
        let c = if shared { data.contacts[0] } else { identical };
        out.push(map_param(
            sy,
            "v_yield_m_s",
            "m/s",
            |x| c.yield_velocity_m_s(x),
            2.5,
        ));
    }
    out
}

/// The fits of several models to one data set and, for two or more, their comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSet {
    pub fits: Vec<FitResult>,
    pub comparison: Option<super::compare::Comparison>,
    /// Models not fitted because the data have no more points than the model has parameters.
    pub skipped: Vec<ModelKind>,
}

/// Fits each model in `kinds` (skipping those with as many parameters as points, with an error
/// if none is left), one thread per model, and compares them when there are two or more.
pub fn fit_all(data: &FitData, kinds: &[ModelKind], options: &FitOptions) -> Result<FitSet> {
    let (kinds, skipped): (Vec<ModelKind>, Vec<ModelKind>) =
        kinds.iter().partition(|k| data.len() > k.n_params());
    if kinds.is_empty() {
        return Err(Error::InvalidParameter {
            name: "number of data points",
            value: data.len() as f64,
            expected: "more points than the model has parameters",
        });
    }
    // The models are independent: fit them on separate threads (results do not depend on the
    // number of threads; each fit is deterministic).
    let fits = std::thread::scope(|s| {
        let handles: Vec<_> = kinds
            .iter()
            .map(|&k| s.spawn(move || fit(data, k, options)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a fit thread panicked"))
            .collect::<Result<Vec<_>>>()
    })?;
    let comparison = (fits.len() >= 2).then(|| super::compare::compare(&fits));
    Ok(FitSet {
        fits,
        comparison,
        skipped,
    })
}
