//! What a fit returns: per-parameter estimates, the fit's statistics, and what was lost on the
//! way (`warnings`). Plain data, shared by the engine, the comparison and the reports (so that
//! neither of those imports the other).

use super::models::ModelKind;

/// How well the data determine a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub enum ParamStatus {
    /// A value with an error and a closed 95% interval.
    Estimate,
    /// Only a lower 95% bound: above it the data cannot tell values apart.
    LowerBound,
    /// Only an upper 95% bound.
    UpperBound,
    /// Neither side is bounded inside the search box.
    Unconstrained,
    /// A value and an error, but an end of the 95% interval could not be computed (the fit's
    /// `warnings` say which and why); the ends that were found are kept.
    IntervalLost,
}

impl ParamStatus {
    pub fn name(self) -> &'static str {
        self.into()
    }

    /// Whether the parameter has a value (with errors) rather than a bound or nothing.
    pub fn has_value(self) -> bool {
        matches!(self, ParamStatus::Estimate | ParamStatus::IntervalLost)
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
    /// The estimate, when [`ParamStatus::has_value`].
    pub value: Option<f64>,
    /// Standard error, scaled by sqrt(s) with the fit's chi2 scale s (see [`FitResult::scale`]).
    pub stderr: Option<f64>,
    /// Standard error with the error bars taken as exact (None for unweighted fits).
    pub stderr_abs: Option<f64>,
    /// 95% profile-likelihood interval; `None` on an open (or lost) side.
    pub ci95: (Option<f64>, Option<f64>),
}

/// What the global search established (see [`super::search`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalSearch {
    /// True when the lower bounds exclude, everywhere in the search box outside `fine_cells`
    /// cells at the search's resolution around the minima, any chi2 more than `gap_chi2` below
    /// the reported minimum, and every local minimum of the grid that could beat it was
    /// polished ([`super::search`]).
    pub certified: bool,
    /// How far below the reported chi2 the global minimum could lie at most (certified only).
    pub gap_chi2: f64,
    /// The tolerance the search worked to (the gap is at most this when certified).
    pub tolerance_chi2: f64,
    /// Cells of the branch and bound that were examined.
    pub cells: u64,
    /// Local minimisations run (one per candidate minimum that could beat the best).
    pub polishes: u64,
    /// Cells left at the search's resolution (a fraction of a standard error) whose bound lies
    /// below the reported minimum minus the tolerance: inside them the answer rests on the
    /// local polishes and line scans, not on the bounds (0: the bounds alone certify it).
    pub fine_cells: u64,
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
    /// Correlation matrix of the parameters: NaN (reported as null) where undetermined or where
    /// either parameter has no error (a bound or unconstrained).
    pub correlation: Vec<Vec<f64>>,
    pub n: usize,
    pub dof: usize,
    pub weighted: bool,
    /// chi2 (weighted) or the residual sum of squares (unweighted).
    pub chi2: f64,
    pub reduced_chi2: f64,
    /// The chi2 scale s that both `stderr` (sqrt(s) stderr_abs) and the 95% intervals
    /// (Delta chi2 = 3.84 s) use: max(1, chi2/dof) weighted, chi2/dof unweighted.
    pub scale: f64,
    /// chi2 + 2k (weighted), n ln(RSS/n) + 2k (unweighted).
    pub aic: f64,
    /// AIC with the small-sample correction 2k(k+1)/(n-k-1) (None when n <= k + 1).
    pub aicc: Option<f64>,
    /// chi2 + k ln n (weighted), n ln(RSS/n) + k ln n (unweighted).
    pub bic: f64,
    /// The Delta chi2 that defines the 95% intervals (3.84 s).
    pub ci95_delta_chi2: f64,
    /// The minimiser converged and the minimum is shown global (`global.certified`); false
    /// whenever a warning says the optimum may be wrong.
    pub converged: bool,
    pub global: GlobalSearch,
    /// Model evaluations (each over all points) for the search and polish.
    pub evaluations: u64,
    /// Model evaluations for the profile-likelihood intervals.
    pub profile_evaluations: u64,
    /// Internal coordinates at the minimum (logarithms for eta, sigma_y, A).
    pub theta: Vec<f64>,
    /// Model e at each point, and (e - model)/sigma.
    pub predicted: Vec<f64>,
    pub normalized_residuals: Vec<f64>,
    /// What was lost or could not be shown: a polish or search that did not finish, an interval
    /// end not found, a second region inside the 95% threshold. Empty for a clean fit.
    pub warnings: Vec<String>,
    /// Things a user should know that are not failures: parameters at the edge of the search
    /// box, parameters determined only in combination, an unweighted fit.
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

/// A number for a message: four significant digits, exponent form outside [1e-3, 1e5).
pub fn show(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e5).contains(&a) {
        let dec = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.dec$}")
    } else {
        format!("{x:.3e}")
    }
}
