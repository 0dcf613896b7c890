//! The result at the minimum, for the rows as given: estimates or bounds with their errors and
//! 95% intervals, correlations, residuals, information criteria, and the derived parameters.

use super::covariance_at;
use crate::error::{Error, Result};
use crate::fit::dataset::{FitData, Merged, pair_contact};
use crate::fit::lsq;
use crate::fit::objective::{CHI2_1DOF_95, Objective};
use crate::fit::polish::Found;
use crate::fit::profile::{Profiles, Side};
use crate::fit::result::{FitResult, GlobalSearch, ParamEstimate, ParamStatus};

/// The rows as given and, when repeats were merged, the points the objective sees.
pub(super) struct Rows<'a> {
    pub(super) data: &'a FitData,
    pub(super) merged: Option<&'a Merged>,
}

/// The result at `best`, for the rows as given.
pub(super) fn summarise(
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
            name: "chi2 at the best fit (the squares overflow: e far from the model, or e_err too small?)",
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
                        "{}: {} inner minimisations of its profile did not converge or were not \
                         shown global; the interval may be too short",
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
            let unit = crate::fit::models::unit_after(spec.unit);
            notes.push(format!(
                "{} ended at the edge of its search range ({}{unit})",
                spec.key,
                crate::error::Num(phys[j]),
            ));
        }
    }
    // Only between parameters that carry an error: for a bound or an unconstrained parameter
    // the curvature at the search box's edge or on a plateau says nothing about how the two
    // vary together (with both of `product`'s parameters bounds, 0.518 had been printed).
    let has_error = |j: usize| params[j].stderr.is_some();
    let correlation = (0..k)
        .map(|i| {
            (0..k)
                .map(|j| {
                    if has_error(i) && has_error(j) {
                        cov[(i, j)] / (cov[(i, i)] * cov[(j, j)]).sqrt()
                    } else {
                        f64::NAN
                    }
                })
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
        global: GlobalSearch {
            certified: false,
            gap_chi2: f64::INFINITY,
            tolerance_chi2: 0.0,
            cells: 0,
            polishes: 0,
            fine_cells: 0,
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
