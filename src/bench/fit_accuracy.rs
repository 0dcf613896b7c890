//! What accuracy a fit needs: the fitted eta of the viscoelastic model (`fit`, model `vm`) on a
//! data set, per evaluation method of e(kappa), against the fit with the most accurate method,
//! and the fit's wall time.
//!
//! **The rule** ("model no more than a scene needs"): a method is good enough when its model error,
//! the largest |e_method - e_reference| over the data's kappa at the reference fit's eta, stays
//! below [`SIGMA_FRACTION`] of the smallest error bar in the data; the default is the cheapest
//! such method (by fit wall time). The fitted eta's own standard error is reported beside it: a
//! method's eta error far below it is accuracy the data cannot use.
//!
//! **Reference**: the fit with the ODE at [`OdeSettings::REFERENCE`] (Dop853, tol 1e-15), whose
//! e(kappa) is checked against the mpmath fixture in the bench's summary.

use super::VmSpec;
use super::timing::TimingPlan;
use crate::error::Result;
use crate::fit::{FitData, FitOptions, ModelKind, fit};
use crate::models::viscoelastic::{ContactEnd, OdeSettings, VmMethod, restitution};
use std::time::Instant;

/// The default method's model error must stay below this fraction of the smallest error bar.
pub const SIGMA_FRACTION: f64 = 0.01;

/// One evaluation method's fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitMethodRow {
    pub method: String,
    pub setting: String,
    /// Tolerance, RK4 step or NaN (master curve).
    pub knob: f64,
    /// Fitted eta, kg/(s m) (NaN if the fit failed).
    pub eta: f64,
    /// |eta - eta_ref| / eta_ref.
    pub eta_rel_error: f64,
    /// Wall time of one fit (scan, polish, covariance; no profile intervals), minimum over repeats.
    pub fit_ms: f64,
    /// Model evaluations of the fit (each over all points).
    pub evaluations: u64,
    /// max |e_method - e_ref| over the data's kappa at the reference eta.
    pub model_error: f64,
    /// model_error <= SIGMA_FRACTION * (smallest error bar).
    pub meets: bool,
    pub converged: bool,
    /// The error value's message if the fit (or the model-error evaluation) failed.
    pub failure: Option<String>,
}

/// The whole comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct FitAccuracy {
    pub rows: Vec<FitMethodRow>,
    /// The reference fit's eta and its standard error (`stderr`: scaled by sqrt(s),
    /// s = max(1, chi2/dof), docs/physics.md §7.5), kg/(s m).
    pub eta_ref: f64,
    pub eta_ref_stderr: f64,
    pub reference_fit_ms: f64,
    pub min_sigma: f64,
    /// SIGMA_FRACTION * min_sigma.
    pub threshold: f64,
    /// Index into `rows` of the cheapest method that meets the threshold.
    pub default_row: Option<usize>,
    pub n_points: usize,
    pub kappa_range: (f64, f64),
}

fn options(method: VmMethod, rule: ContactEnd) -> FitOptions {
    FitOptions {
        rule,
        vm_method: method,
        intervals: false,
        ..FitOptions::default()
    }
}

fn spec_of(method: &VmMethod) -> VmSpec {
    match method {
        VmMethod::Master => VmSpec::Master,
        VmMethod::Ode(s) => VmSpec::Ode(*s),
    }
}

/// Fits model `vm` with each method and compares with the reference fit. Fails only if the
/// reference fit or its e(kappa) fails.
pub fn fit_accuracy(
    data: &FitData,
    rule: ContactEnd,
    methods: &[VmMethod],
    plan: &TimingPlan,
) -> Result<FitAccuracy> {
    let reference = VmMethod::Ode(OdeSettings::REFERENCE);
    let t0 = Instant::now();
    let ref_fit = fit(data, ModelKind::Vm, &options(reference, rule))?;
    let reference_fit_ms = t0.elapsed().as_secs_f64() * 1e3;
    let eta_p = ref_fit.param("eta").expect("model vm has eta");
    let eta_ref = eta_p.best_fit;
    let eta_ref_stderr = eta_p.stderr.unwrap_or(f64::NAN);
    let kappas: Vec<f64> = data
        .obs
        .iter()
        .zip(&data.contacts)
        .map(|(o, c)| c.kappa(eta_ref, o.v_n_m_s))
        .collect();
    let e_ref: Vec<f64> = kappas
        .iter()
        .map(|&k| restitution(k, rule, &reference).map(|r| r.e))
        .collect::<Result<_>>()?;
    let min_sigma = (0..data.len())
        .map(|i| data.sigma(i))
        .fold(f64::INFINITY, f64::min);
    let threshold = SIGMA_FRACTION * min_sigma;

    let mut rows = Vec::new();
    for m in methods {
        let spec = spec_of(m);
        let model_error: std::result::Result<f64, String> = kappas
            .iter()
            .zip(&e_ref)
            .map(|(&k, &e)| {
                restitution(k, rule, m)
                    .map(|r| (r.e - e).abs())
                    .map_err(|err| err.to_string())
            })
            .try_fold(0.0f64, |acc, x| x.map(|x| acc.max(x)));
        let mut best_ms = f64::INFINITY;
        let mut result = None;
        for _ in 0..plan.repeats.max(1) {
            let t = Instant::now();
            let r = fit(data, ModelKind::Vm, &options(*m, rule));
            best_ms = best_ms.min(t.elapsed().as_secs_f64() * 1e3);
            let failed = r.is_err();
            result = Some(r);
            if failed {
                break;
            }
        }
        let knob = spec.knob();
        let row = match (result.expect("at least one repeat"), model_error) {
            (Ok(r), Ok(me)) => {
                let eta = r.param("eta").expect("model vm has eta").best_fit;
                FitMethodRow {
                    method: spec.method(),
                    setting: spec.setting(),
                    knob,
                    eta,
                    eta_rel_error: ((eta - eta_ref) / eta_ref).abs(),
                    fit_ms: best_ms,
                    evaluations: r.evaluations,
                    model_error: me,
                    meets: me <= threshold && r.converged,
                    converged: r.converged,
                    failure: None,
                }
            }
            (fit_result, me) => FitMethodRow {
                method: spec.method(),
                setting: spec.setting(),
                knob,
                eta: f64::NAN,
                eta_rel_error: f64::NAN,
                fit_ms: best_ms,
                evaluations: 0,
                model_error: me.clone().unwrap_or(f64::NAN),
                meets: false,
                converged: false,
                failure: Some(match (fit_result, me) {
                    (Err(e), _) => format!("fit: {e}"),
                    (_, Err(e)) => format!("model error: {e}"),
                    _ => unreachable!("handled above"),
                }),
            },
        };
        rows.push(row);
    }
    let default_row = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.meets)
        .min_by(|a, b| a.1.fit_ms.total_cmp(&b.1.fit_ms))
        .map(|(i, _)| i);
    let kappa_range = kappas.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &k| {
        (lo.min(k), hi.max(k))
    });
    Ok(FitAccuracy {
        rows,
        eta_ref,
        eta_ref_stderr,
        reference_fit_ms,
        min_sigma,
        threshold,
        default_row,
        n_points: data.len(),
        kappa_range,
    })
}
