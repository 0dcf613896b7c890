//! The fit of one model (and of several, compared): global search, intervals, summary.
//!
//! **Solves** min chi2 = sum_i ((e_i - model_i)/sigma_i)^2 over the model's parameters
//! (sigma_i = 1 for data without errors) inside the search box of [`super::objective`], by the
//! certified global search of [`super::search`], then the uncertainties:
//!
//! - **Covariance** (lmfit / scipy `curve_fit` conventions for J): with J the Jacobian of the
//!   weighted residuals at the minimum, C = (J^T J)^-1; `stderr_abs` = sqrt(C_jj) (error bars
//!   taken as exact) and `stderr` = sqrt(s C_jj) with the chi2 scale s of [`super::objective`]:
//!   max(1, chi2/dof) weighted (the PDG scale factor: errors as given unless the scatter shows
//!   them too small), chi2/dof unweighted. Log-fitted parameters convert by the delta method
//!   (stderr of x = x stderr of ln x).
//! - **95% intervals**: profile likelihood with Delta chi2 = 3.84 s, the same s
//!   ([`super::profile`]); so for a model linear in its parameters the interval is exactly
//!   value +- 1.96 stderr. A parameter whose interval is open on one side (its profile stays
//!   below the threshold up to the edge of the search box) is reported as a bound: the data
//!   cannot exclude the parameter ceasing to matter, so a value with an error bar would mislead.
//!
//! Nothing is lost silently: a search that could not be certified, a polish that did not
//! converge, a profile that found a lower minimum (the fit refits from it, three times at most),
//! an interval end not found, or a second region inside the 95% threshold that the interval
//! does not cover: each is a line in the result's `warnings`, and `converged` is false whenever
//! the reported minimum itself is in doubt.

use super::compare::{Comparison, compare};
use super::dataset::{FitData, Merged, pair_contact};
use super::lsq::{self, LmOptions};
use super::models::{Evaluator, ModelKind};
use super::objective::{CHI2_1DOF_95, Objective, check_size};
use super::polish::Found;
use super::profile::{ProfileOutcome, Profiles, Side, profile_intervals};
use super::result::{FitResult, ParamEstimate, ParamStatus, show};
use super::search::{SearchOutcome, global_minimum};
use crate::error::{Error, Result};
use crate::models::viscoelastic::{ContactEnd, VmMethod};

/// How to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// End-of-contact rule of the viscoelastic model.
    pub rule: ContactEnd,
    /// How e_vm is evaluated: master curve (default) or the ODE at every point (`--exact`).
    pub vm_method: VmMethod,
    /// Run the global search (default). Without it only the local solver runs, from `start`
    /// (or the middle of the box), and the result says it is not shown global: kept to show what
    /// the search is for.
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

/// Profile refits allowed when a profile finds a lower minimum.
const MAX_REFITS: usize = 3;

/// Fits one model to the data.
pub fn fit(data: &FitData, kind: ModelKind, options: &FitOptions) -> Result<FitResult> {
    let k = kind.n_params();
    check_size(data, kind)?;
    if let Some(s) = &options.start
        && (s.len() != k
            || s.iter()
                .zip(kind.params())
                .any(|(x, p)| !(x.is_finite() && (*x > 0.0 || !p.log))))
    {
        return Err(Error::InvalidParameter {
            name: "number of start values",
            value: s.len() as f64,
            expected: "one finite value per model parameter (positive where fitted as a log)",
        });
    }
    // Repeated (d, d2, v) rows cost the search their count but change chi2 only by a constant.
    let merged = data.merge_repeats();
    let points = merged.as_ref().map_or(data, |m| &m.data);
    let ev = Evaluator::new(points, options.rule, options.vm_method);
    let mut obj = Objective::new(&ev, kind)?;
    if let Some(m) = &merged {
        obj = obj.with_merged(m);
    }
    let search = global_minimum(&obj, options)?;
    let fit_evals = obj.evals.get();
    let SearchOutcome {
        mut best,
        global,
        mut warnings,
        near_nodes,
    } = search;
    warnings.splice(0..0, obj.warnings.iter().cloned());
    let mut notes = Vec::new();
    let mut converged = best.converged && global.certified;
    if !best.converged {
        warnings.push(format!(
            "the local polish did not converge ({})",
            best.reason
        ));
    }
    let mut profiles = None;
    if options.intervals {
        let mut refits = 0;
        loop {
            let cov = covariance_at(&obj, &best.theta)?;
            match profile_intervals(&obj, &best.theta, best.chi2, &cov)? {
                ProfileOutcome::Done(p) => {
                    profiles = Some(p);
                    break;
                }
                ProfileOutcome::Lower(t) if refits < MAX_REFITS => {
                    refits += 1;
                    let all = vec![true; k];
                    let again = lsq::levenberg_marquardt(&obj, &t, &all, &LmOptions::default())?;
                    warnings.push(format!(
                        "a profile found chi2 {} below the minimum {}; refitted from it",
                        show(again.chi2 + obj.chi2_offset),
                        show(best.chi2 + obj.chi2_offset)
                    ));
                    if again.chi2 < best.chi2 {
                        best = Found {
                            theta: again.theta,
                            chi2: again.chi2,
                            converged: again.converged,
                            reason: again.reason.to_string(),
                        };
                        converged = converged && best.converged;
                    }
                }
                ProfileOutcome::Lower(_) => {
                    warnings.push(format!(
                        "95% intervals lost: the profiles kept finding lower minima after \
                         {MAX_REFITS} refits"
                    ));
                    converged = false;
                    break;
                }
            }
        }
    }
    let lost_intervals = options.intervals && profiles.is_none();
    let profile_evals = obj.evals.get() - fit_evals;
    let rows = Rows {
        data,
        merged: merged.as_ref(),
    };
    let mut r = summarise(
        &obj,
        &rows,
        &best,
        profiles.as_ref(),
        lost_intervals,
        &mut notes,
        &mut warnings,
    )?;
    if let Some(p) = &profiles {
        check_disjoint(&obj, &r, p, &near_nodes, &mut warnings);
    }
    r.converged = converged;
    r.global = global;
    r.evaluations = fit_evals;
    r.profile_evaluations = profile_evals;
    r.warnings = warnings;
    r.notes = notes;
    Ok(r)
}

/// The covariance at theta from the Jacobian of the weighted residuals.
fn covariance_at(obj: &Objective, theta: &[f64]) -> Result<lsq::Covariance> {
    let mut f0 = vec![0.0; obj.ev.len()];
    lsq::residuals_checked(obj, theta, &mut f0)?;
    let jac = lsq::jacobian(obj, theta, &vec![true; theta.len()], &f0)?;
    Ok(lsq::covariance(&jac))
}

/// Warns when a grid node inside the 95% threshold lies outside a parameter's interval: the 95%
/// region then has a part the interval does not show.
fn check_disjoint(
    obj: &Objective,
    r: &FitResult,
    p: &Profiles,
    nodes: &[(Vec<f64>, f64)],
    warnings: &mut Vec<String>,
) {
    // The nodes' chi2 is that of the points (see Objective::chi2_offset).
    let threshold = r.chi2 - obj.chi2_offset + p.delta;
    for (j, spec) in obj.kind.params().iter().enumerate() {
        let lo = match p.sides[j][0] {
            Side::At(t) => t,
            _ => f64::NEG_INFINITY,
        };
        let hi = match p.sides[j][1] {
            Side::At(t) => t,
            _ => f64::INFINITY,
        };
        // Beyond the crossing by more than its tolerance (1e-7) and a margin for rounding.
        let outside = nodes
            .iter()
            .filter(|(th, c)| *c < threshold && (th[j] < lo - 1e-6 || th[j] > hi + 1e-6))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((th, c)) = outside {
            let v = if spec.log { th[j].exp() } else { th[j] };
            warnings.push(format!(
                "the 95% region of {} has a part outside the interval: chi2 = {} (within the \
                 threshold {}) at {} = {}",
                spec.key,
                crate::error::Num(*c + obj.chi2_offset),
                crate::error::Num(threshold),
                spec.key,
                crate::error::Num(v)
            ));
        }
    }
}

/// The rows as given and, when repeats were merged, the points the objective sees.
struct Rows<'a> {
    data: &'a FitData,
    merged: Option<&'a Merged>,
}

/// The result at `best`, for the rows as given.
fn summarise(
    obj: &Objective,
    rows: &Rows,
    best: &Found,
    profiles: Option<&Profiles>,
    lost_intervals: bool,
    notes: &mut Vec<String>,
    warnings: &mut Vec<String>,
) -> Result<FitResult> {
    let kind = obj.kind;
    let (data, merged) = (rows.data, rows.merged);
    let n = data.len();
    let k = kind.n_params();
    let theta = best.theta.clone();
    let chi2_points = lsq::chi2(obj, &theta)?;
    let chi2 = chi2_points + obj.chi2_offset;
    if !chi2.is_finite() {
        return Err(Error::InvalidParameter {
            name: "chi2 at the best fit (the squares overflow: e_err too small?)",
            value: chi2,
            expected: "a finite number",
        });
    }
    let full_cov = covariance_at(obj, &theta)?;
    let cov = &full_cov.matrix;
    let dof = n - k;
    let reduced = chi2 / dof as f64;
    let scale = obj.scale(chi2_points);
    let phys = kind.to_physical(&theta);
    let specs = kind.params();
    let mut params = Vec::with_capacity(k);
    for j in 0..k {
        let spec = specs[j];
        let to_phys = |t: f64| if spec.log { t.exp() } else { t };
        let dscale = if spec.log { phys[j] } else { 1.0 };
        let sd = cov[(j, j)].sqrt();
        let finite = |x: f64| Some(x).filter(|x| x.is_finite());
        let at = |s: &Side| match s {
            Side::At(t) => Some(to_phys(*t)),
            _ => None,
        };
        let (status, ci) = match profiles {
            _ if full_cov.degenerate[j] => (ParamStatus::Unconstrained, (None, None)),
            Some(p) => {
                let [lo, hi] = &p.sides[j];
                let status = match (lo, hi) {
                    (Side::At(_), Side::At(_)) => ParamStatus::Estimate,
                    (Side::At(_), Side::Open) => ParamStatus::LowerBound,
                    (Side::Open, Side::At(_)) => ParamStatus::UpperBound,
                    (Side::Open, Side::Open) => ParamStatus::Unconstrained,
                    _ => ParamStatus::IntervalLost,
                };
                for (s, end) in [(lo, "lower"), (hi, "upper")] {
                    if let Side::Lost(why) = s {
                        warnings.push(format!(
                            "{}: {end} end of the 95% interval not found: {why}",
                            spec.key
                        ));
                    }
                }
                if p.unconverged[j] > 0 {
                    warnings.push(format!(
                        "{}: {} inner minimisations of its profile did not converge; the interval \
                         may be too short",
                        spec.key, p.unconverged[j]
                    ));
                }
                (status, (at(lo), at(hi)))
            }
            None if lost_intervals && sd.is_finite() => (ParamStatus::IntervalLost, (None, None)),
            None if sd.is_finite() => (ParamStatus::Estimate, (None, None)),
            None => (ParamStatus::Unconstrained, (None, None)),
        };
        let has_value = status.has_value();
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
            value: has_value.then_some(phys[j]),
            stderr: if has_value {
                finite(sd * dscale * scale.sqrt())
            } else {
                None
            },
            stderr_abs: if has_value && data.weighted {
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
                crate::error::Num(phys[j]),
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
    let mut at_points = vec![0.0; obj.ev.len()];
    obj.ev.predict(kind, &phys, &mut at_points)?;
    let predicted: Vec<f64> = match merged {
        Some(m) => m.point_of_row.iter().map(|&p| at_points[p]).collect(),
        None => at_points,
    };
    let normalized_residuals = (0..n)
        .map(|i| (data.obs[i].e - predicted[i]) / data.sigma(i))
        .collect();
    if let Some(m) = merged {
        notes.push(format!(
            "{} rows share {} distinct (d, d2, v_n) points: fitted as those points with their weighted mean e (exact: chi2 differs by the constant {})",
            n,
            m.data.len(),
            crate::error::Num(m.chi2_offset)
        ));
    }
    let (kf, nf) = (k as f64, n as f64);
    let base = if data.weighted {
        chi2
    } else {
        nf * (chi2 / nf).ln()
    };
    let aic = base + 2.0 * kf;
    let aicc = (n > k + 1).then(|| aic + 2.0 * kf * (kf + 1.0) / (nf - kf - 1.0));
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
        scale,
        aic,
        aicc,
        bic: base + kf * nf.ln(),
        ci95_delta_chi2: CHI2_1DOF_95 * scale,
        converged: best.converged,
        global: super::result::GlobalSearch {
            certified: false,
            gap_chi2: f64::INFINITY,
            tolerance_chi2: 0.0,
            cells: 0,
            polishes: 0,
        },
        evaluations: 0,
        profile_evaluations: 0,
        theta,
        predicted,
        normalized_residuals,
        warnings: Vec::new(),
        notes: Vec::new(),
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
        // A = 2C/(3K) = 2 eta / E*: the same for every pair of one material (physics.md §2).
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
    pub comparison: Option<Comparison>,
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
    // number of threads; each fit is deterministic). One model runs here: a thread would only
    // add its start-up to the main job's whole-process time.
    let fits = if let [k] = kinds[..] {
        vec![fit(data, k, options)?]
    } else {
        std::thread::scope(|s| {
            let handles: Vec<_> = kinds
                .iter()
                .map(|&k| s.spawn(move || fit(data, k, options)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("a fit thread panicked"))
                .collect::<Result<Vec<_>>>()
        })?
    };
    let comparison = (fits.len() >= 2).then(|| compare(&fits));
    Ok(FitSet {
        fits,
        comparison,
        skipped,
    })
}
