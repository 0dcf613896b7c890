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
//! converge, a profile that found a lower minimum (the fit refits from it, three times at most,
//! with Levenberg-Marquardt finished by damped Newton where it runs out of iterations),
//! an interval end not found, or a second region inside the 95% threshold that the interval
//! does not cover: each is a line in the result's `warnings`, and `converged` is false whenever
//! the reported minimum itself is in doubt.

mod summary;

use super::beyond::{Certified, Unshown, certify_ends};
use super::compare::{Comparison, compare};
use super::dataset::{FitData, Merged};
use super::lsq;
use super::models::{Evaluator, ModelKind};
use super::objective::{Objective, check_size};
use super::polish::{polish_lm, polish_newton};
use super::profile::{
    Extension, Moved, ProfileOutcome, Profiles, Side, extend_to_region, global_inner,
    profile_intervals_of,
};
use super::result::FitResult;
use super::search::{SearchOutcome, global_minimum, share_starting_rows};
use super::sums;
use crate::error::{Error, Num, Result};
use crate::models::viscoelastic::{ContactEnd, VmMethod};
use rayon::prelude::*;
use summary::{Rows, summarise};

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
    let merged = data.merge_repeats();
    let points = merged.as_ref().map_or(data, |m| &m.data);
    let ev = Evaluator::new(points, options.rule, options.vm_method);
    fit_alone(data, merged.as_ref(), &ev, kind, options)
}

/// [`fit_points`] for one model alone: large data on the thread pool, as a task of its own.
/// Called from a thread outside the pool, each parallel sum would be handed to a worker and
/// waited for (a sleep and a wake of this thread per sum: a tenth of the power law's CPU on
/// 100 000 points of distinct sizes, in the scheduler); small data never wake the pool.
fn fit_alone(
    data: &FitData,
    merged: Option<&Merged>,
    ev: &Evaluator,
    kind: ModelKind,
    options: &FitOptions,
) -> Result<FitResult> {
    if sums::is_large(ev.len()) {
        rayon::scope(|_| fit_points(data, merged, ev, kind, options))
    } else {
        fit_points(data, merged, ev, kind, options)
    }
}

/// Fits one model to the data through `ev`, the evaluator of its points (the rows with repeats
/// merged, `merged`, if any): built once for every model of [`fit_all`].
fn fit_points(
    data: &FitData,
    merged: Option<&Merged>,
    ev: &Evaluator,
    kind: ModelKind,
    options: &FitOptions,
) -> Result<FitResult> {
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
    let mut obj = Objective::new(ev, kind)?;
    if let Some(m) = merged {
        obj = obj.with_merged(m);
    }
    let search = global_minimum(&obj, options)?;
    let fit_evals = obj.evaluations();
    let SearchOutcome {
        mut best,
        global,
        mut warnings,
        near_nodes,
        region,
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
    let mut moved: Vec<Moved> = Vec::new();
    let mut unshown: Vec<Unshown> = Vec::new();
    if options.intervals {
        let mut refits = 0;
        loop {
            let cov = covariance_at(&obj, &best.theta)?;
            // The ends, moved past the grid nodes of the 95% region the profiles did not reach.
            let inner = global_inner(&obj, region.as_ref());
            let inner = inner.as_deref();
            let scale = obj.scale(best.chi2);
            let outcome =
                match profile_intervals_of(&obj, &best.theta, best.chi2, &cov, scale, inner)? {
                    ProfileOutcome::Done(mut p) => {
                        match extend_to_region(&obj, best.chi2, &cov, &mut p, &near_nodes, inner)? {
                            Extension::Done(m) => {
                                moved = m;
                                // Then past the parts between the grid's nodes.
                                match region.as_ref() {
                                    Some(region) => match certify_ends(
                                        &obj,
                                        (&best.theta, best.chi2),
                                        &cov,
                                        &mut p,
                                        region,
                                        inner,
                                        &mut moved,
                                    )? {
                                        Certified::Done(u) => {
                                            unshown = u;
                                            ProfileOutcome::Done(p)
                                        }
                                        Certified::Lower(t) => ProfileOutcome::Lower(t),
                                    },
                                    None => ProfileOutcome::Done(p),
                                }
                            }
                            Extension::Lower(t) => ProfileOutcome::Lower(t),
                        }
                    }
                    lower => lower,
                };
            match outcome {
                ProfileOutcome::Done(p) => {
                    profiles = Some(p);
                    break;
                }
                ProfileOutcome::Lower(t) if refits < MAX_REFITS => {
                    refits += 1;
                    let mut again = polish_lm(&obj, &t)?;
                    // Both in full (shortest round-trip): 1e-7 below prints alike in 4 digits.
                    warnings.push(format!(
                        "a profile found chi2 {} below the minimum {}; refitted from it",
                        Num(again.chi2 + obj.chi2_offset),
                        Num(best.chi2 + obj.chi2_offset)
                    ));
                    if !again.converged {
                        // Levenberg-Marquardt creeping along a narrow curved valley (where a
                        // point starts to yield) hands over to Newton, as in the search.
                        again = polish_newton(&obj, again)?;
                    }
                    if again.chi2 < best.chi2 {
                        best = again;
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
    let profile_evals = obj.evaluations() - fit_evals;
    let rows = Rows { data, merged };
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
        for m in &moved {
            notes.push(moved_note(&obj, p, m));
        }
        for u in &unshown {
            warnings.push(unshown_warning(&obj, u));
        }
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

/// The note of an end moved past a point of the 95% region (both values in full, shortest
/// round-trip; the points' chi2 plus the rows' offset, as the fit's chi2 is printed).
fn moved_note(obj: &Objective, p: &Profiles, m: &Moved) -> String {
    let spec = &obj.kind.params()[m.j];
    let show = |t: f64| Num(if spec.log { t.exp() } else { t });
    let end = match &p.sides[m.j][m.s] {
        Side::At(t) => format!("moved to {}", show(*t)),
        _ => "opened (the profile stays below the threshold to the search box's edge)".into(),
    };
    format!(
        "the {} end of the 95% interval of {} {end}, from {}: the profile from the minimum had \
         not reached a point of the 95% region there (chi2 = {} at {} = {}); the interval is \
         the hull of the region found",
        ["lower", "upper"][m.s],
        spec.key,
        show(m.from),
        Num(m.chi2 + obj.chi2_offset),
        spec.key,
        show(m.point[m.j]),
    )
}

/// The warning for an end whose far side could not be cleared of the 95% region.
fn unshown_warning(obj: &Objective, u: &Unshown) -> String {
    let spec = &obj.kind.params()[u.j];
    let show = |t: f64| Num(if spec.log { t.exp() } else { t });
    format!(
        "{}: not shown that the 95% region has no part beyond the {} end of its interval ({}): \
         {}; the interval may be too short",
        spec.key,
        ["lower", "upper"][u.s],
        show(u.end),
        u.why
    )
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
                crate::error::Num(threshold + obj.chi2_offset),
                spec.key,
                crate::error::Num(v)
            ));
        }
    }
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
/// if none is left), side by side through one evaluator of the points, and compares them when
/// there are two or more. Each fit is the one [`fit`] gives alone, to the last bit.
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
    // Repeated (d, d2, v) rows cost the search their count but change chi2 only by a constant:
    // merged once, and the points' evaluator built once, for every model.
    let merged = data.merge_repeats();
    let points = merged.as_ref().map_or(data, |m| &m.data);
    let ev = Evaluator::new(points, options.rule, options.vm_method);
    if kinds.len() >= 2 {
        share_starting_rows(&ev, &kinds, options);
    }
    let (merged, ev) = (merged.as_ref(), &ev);
    // The models are independent: fit them side by side (results do not depend on the number
    // of threads; each fit is deterministic). One model runs here: a thread would only add its
    // start-up to the main job's whole-process time. Large data's fits sum on the rayon pool
    // ([`sums`]), so they run as its tasks: on threads of their own, five fits and the pool's
    // workers took turns on the cores, every sum a hand-over between threads (a tenth more CPU,
    // a fifth more wall time on two cores). Small data never wake the pool (its idle workers'
    // spinning cost more than the fits' threads).
    let fits = if let [k] = kinds[..] {
        vec![fit_alone(data, merged, ev, k, options)?]
    } else if sums::is_large(points.len()) {
        // Every fit's outcome first, then the first error in the models' order (rayon's own
        // collect into a Result returns whichever error it meets first: not reproducible).
        kinds
            .par_iter()
            .map(|&k| fit_points(data, merged, ev, k, options))
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<Vec<_>>>()?
    } else {
        std::thread::scope(|s| {
            let handles: Vec<_> = kinds
                .iter()
                .map(|&k| s.spawn(move || fit_points(data, merged, ev, k, options)))
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
