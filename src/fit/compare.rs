//! Model comparison by Akaike's information criterion (Burnham & Anderson, "Model Selection and
//! Multimodel Inference", 2nd ed., 2002, §2.2 and §2.9).
//!
//! Delta AIC_i = AIC_i - min AIC; Akaike weight w_i = exp(-Delta_i/2) / sum_j exp(-Delta_j/2), the
//! relative support of model i within the set. The preferred model follows Burnham & Anderson's
//! rule of thumb that models within Delta AIC <= 2 have substantial support: among the converged
//! fits within 2 of the best, the one with the fewest parameters (then the lower AIC) is named,
//! so that the data are not described with more than they support. Unweighted fits that
//! reproduce the points to rounding leave AIC nothing to rank ([`EXACT_RSS_PER_POINT`];
//! docs/physics.md §7.6): the one of them with the fewest parameters is named if one alone has
//! them, else none, and [`Comparison::unranked`] says why.

use super::models::ModelKind;
use super::result::FitResult;

/// How the preferred model is chosen, for reports.
pub const PREFERENCE_RULE: &str = "lowest AIC; among converged models within delta AIC <= 2 of it, the one with the fewest parameters";

/// One model's line in the comparison table.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonRow {
    pub model: ModelKind,
    pub k: usize,
    pub chi2: f64,
    pub reduced_chi2: f64,
    pub aic: f64,
    pub bic: f64,
    pub delta_aic: f64,
    pub akaike_weight: f64,
    pub converged: bool,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    pub rows: Vec<ComparisonRow>,
    /// `None` when no fit converged, or when AIC cannot rank the fits (see `unranked`).
    pub preferred: Option<ModelKind>,
    /// Why AIC did not choose: no fit converged, or fits that reproduce the points to rounding
    /// (then the one with the fewest parameters, if one alone has them, is `preferred`).
    pub unranked: Option<String>,
}

/// Residual sum of squares per point (unweighted fits) at or below which a model reproduces the
/// points exactly: its residuals of e are then below 1e-12, the rounding of e's evaluation
/// (the master curve's is about 1e-14), far below any measurement's error. There
/// AIC = n ln(RSS/n) + 2k ranks rounding, not fit: on three identical rows at one speed `vm` and
/// `pm` had RSS 9e-29 and 1e-24, `min` and `product` exactly 0 (AIC = -inf), and `min` was named
/// the preferred model of data that no model can tell apart.
pub const EXACT_RSS_PER_POINT: f64 = 1e-24;

/// Compares fitted models of the same data (their AICs are only comparable then).
pub fn compare(fits: &[FitResult]) -> Comparison {
    let min_aic = fits.iter().map(|f| f.aic).fold(f64::INFINITY, f64::min);
    let raw: Vec<f64> = fits
        .iter()
        .map(|f| (-(f.aic - min_aic) / 2.0).exp())
        .collect();
    let total: f64 = raw.iter().sum();
    let rows: Vec<ComparisonRow> = fits
        .iter()
        .zip(&raw)
        .map(|(f, w)| ComparisonRow {
            model: f.model,
            k: f.k(),
            chi2: f.chi2,
            reduced_chi2: f.reduced_chi2,
            aic: f.aic,
            bic: f.bic,
            delta_aic: f.aic - min_aic,
            akaike_weight: w / total,
            converged: f.converged,
        })
        .collect();
    // A fit to rounding (or an AIC that is not a number) leaves AIC nothing to rank: no
    // differences or weights are shown, and a model is named only where one alone has the
    // fewest parameters among the converged fits that reproduce the points (data made by a
    // model: that model; data every model reproduces, as one speed repeated: none).
    let exact: Vec<&FitResult> = fits
        .iter()
        .filter(|f| !f.aic.is_finite() || !f.weighted && f.chi2 <= EXACT_RSS_PER_POINT * f.n as f64)
        .collect();
    if !exact.is_empty() {
        let rows = rows
            .into_iter()
            .map(|r| ComparisonRow {
                delta_aic: f64::NAN,
                akaike_weight: f64::NAN,
                ..r
            })
            .collect();
        let names: Vec<&str> = exact.iter().map(|f| f.model.name()).collect();
        let why = format!(
            "{} {} the points to rounding (residual sum of squares at most {:e} per point), \
             where AIC ranks rounding, not fit",
            names.join(", "),
            if names.len() == 1 {
                "reproduces"
            } else {
                "reproduce"
            },
            EXACT_RSS_PER_POINT
        );
        let converged: Vec<&&FitResult> = exact.iter().filter(|f| f.converged).collect();
        let fewest = converged.iter().map(|f| f.k()).min();
        let alone: Vec<ModelKind> = converged
            .iter()
            .filter(|f| Some(f.k()) == fewest)
            .map(|f| f.model)
            .collect();
        let (preferred, unranked) = match alone[..] {
            [m] => (
                Some(m),
                format!("{why}; {} has the fewest parameters among them", m.name()),
            ),
            _ => (None, why),
        };
        return Comparison {
            rows,
            preferred,
            unranked: Some(unranked),
        };
    }
    let best_conv = rows
        .iter()
        .filter(|r| r.converged)
        .map(|r| r.aic)
        .fold(f64::INFINITY, f64::min);
    let preferred = rows
        .iter()
        .filter(|r| r.converged && r.aic <= best_conv + 2.0)
        .min_by(|a, b| a.k.cmp(&b.k).then(a.aic.total_cmp(&b.aic)))
        .map(|r| r.model);
    let unranked = preferred.is_none().then(|| "no fit converged".to_string());
    Comparison {
        rows,
        preferred,
        unranked,
    }
}
