//! The Fig. 6 fit itself: e, beta_0 and mu_0 with standard errors, bootstrap intervals, the
//! classification of the collisions and the cross-checks.

use super::bootstrap::{Point, Replicates, pairs_bootstrap, percentile_interval};
use super::hinge::{HingeFit, HingeShape, fit_hinge};
use crate::error::{Error, Result};
use crate::models::walton::{self, ContactKind, Measured};

/// How collisions are weighted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weights {
    /// Every velocity component measured with the same error, as for a camera (Eq. 8 depends on
    /// the optics and frame rate, not on the speed). Then var(beta_i) ~ 1/|v_s,i|^2 and
    /// var(e_i) ~ 1/v_n,i^2, and each collision is weighted by the inverse: w = |v_s|^2 for beta,
    /// v_n^2 for e and for the impulse ratio. Near-head-on collisions, whose beta is poorly
    /// measured, and grazing ones, whose e is, count for less.
    Camera,
    /// Every collision counts the same (what a by-eye reading of Fig. 6 does).
    Equal,
}

impl Weights {
    pub fn as_str(&self) -> &'static str {
        match self {
            Weights::Camera => "camera",
            Weights::Equal => "equal",
        }
    }
}

/// Settings of [`fit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// K = 4I/(m d^2) of the spheres, used in mu_0 = s/((1 + 1/K)(1 + e)).
    pub inertia_k: f64,
    pub weights: Weights,
    /// Bootstrap resamples for the 95% intervals (0: no intervals).
    pub bootstrap: usize,
    pub seed: u64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            inertia_k: walton::K_HOMOGENEOUS,
            weights: Weights::Camera,
            bootstrap: 2000,
            seed: 1,
        }
    }
}

/// Which side a parameter's only bound is on, when the data do not determine it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    Lower,
}

/// A fitted number with its standard error and 95% interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    pub value: f64,
    /// Standard error from the least-squares covariance, scaled by the residual variance
    /// (the lmfit / curve_fit default); `None` when the data do not determine the parameter.
    pub stderr: Option<f64>,
    /// Bootstrap percentile 95% interval; `None` without bootstrap or when undetermined.
    pub ci95: Option<(f64, f64)>,
    /// `Some` when `value` is only a bound.
    pub bound: Option<Bound>,
}

/// Summary of the measured normal restitution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EStats {
    /// Weighted mean (see [`Weights`]).
    pub value: f64,
    pub stderr: f64,
    pub ci95: Option<(f64, f64)>,
    /// Plain standard deviation of the e_i: the collision-to-collision spread, as in the
    /// paper's e = 0.97 +- 0.07.
    pub spread: f64,
    pub min: f64,
    pub max: f64,
}

/// Per-collision result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Classified {
    pub measured: Measured,
    /// `None` for a head-on collision (no beta).
    pub kind: Option<ContactKind>,
    /// beta_i - hinge(psi_i).
    pub residual: Option<f64>,
}

/// Bootstrap bookkeeping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BootstrapInfo {
    pub resamples: usize,
    pub seed: u64,
    /// Resamples without collisions on both sides of the kink (or with fewer than 3 oblique
    /// collisions); left out of the intervals.
    pub failed: usize,
}

/// What [`fit`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct WaltonFit {
    pub e: EStats,
    pub beta0: Estimate,
    pub mu0: Estimate,
    /// s = mu_0 (1 + 1/K)(1 + e).
    pub slope: Estimate,
    /// psi* = (1 + beta_0)/s.
    pub kink_psi: Estimate,
    pub hinge: HingeFit,
    /// All collisions, in input order.
    pub collisions: Vec<Classified>,
    pub n: usize,
    pub n_sliding: usize,
    pub n_rolling: usize,
    pub n_head_on: usize,
    /// Weighted mean impulse ratio |Delta P_t|/|Delta P_n| of the sliding collisions: a second,
    /// independent estimate of mu_0 (Sec. II), with its standard error. `None` with < 2 sliding.
    pub impulse_ratio_sliding: Option<(f64, f64)>,
    /// Root mean square of the centre-of-mass velocity change over sphere pairs (m/s): the
    /// paper's momentum check of the measurement (zero for exact data). `None` for walls only.
    pub com_dv_rms_m_s: Option<f64>,
    /// Unweighted root mean square of the beta residuals.
    pub residual_rms: f64,
    /// Degrees of freedom of the hinge fit, n_oblique - 2.
    pub dof: usize,
    pub bootstrap: BootstrapInfo,
    /// Whether both slope and plateau are determined (false: see `message`).
    pub converged: bool,
    pub message: String,
    pub options: FitOptions,
}

fn weighted_mean(values: &[f64], w: &[f64]) -> f64 {
    let sw: f64 = w.iter().sum();
    values.iter().zip(w).map(|(v, w)| v * w).sum::<f64>() / sw
}

/// Fits Walton's e, beta_0 and mu_0 to measured collisions (the paper's Fig. 6 analysis).
///
/// e is the weighted mean of the e_i; the hinge beta(psi) = min(-1 + s psi, beta_0) is fitted
/// globally by [`fit_hinge`] to the collisions that have a beta (not head-on);
/// mu_0 = s/((1 + 1/K)(1 + e)) (Eq. 7). Standard errors: var(s) = sigma_sl^2/sum_sliding w psi^2,
/// var(beta_0) = sigma_rol^2/sum_rolling w, with sigma_sl^2 and sigma_rol^2 the weighted residual
/// variances of the two branches (the Gauss-Newton covariance, which is diagonal because s and
/// beta_0 act on disjoint points; valid for a kink strictly between data points); mu_0's adds
/// the error of e in quadrature (delta method). The 95% intervals are
/// percentile intervals of a pairs bootstrap (collisions resampled with replacement, the whole
/// fit redone; seeded, so reproducible), which needs no assumption about the error distribution
/// and carries the kink's nonlinearity and e's correlation into mu_0.
///
/// Errors: fewer than 3 oblique collisions, an invalid K, or invalid measured numbers.
pub fn fit(measured: &[Measured], options: &FitOptions) -> Result<WaltonFit> {
    let k = options.inertia_k;
    if !(k.is_finite() && k > 0.0 && k <= 1.0) {
        return Err(Error::InvalidParameter {
            name: "inertia factor K = 4I/(m d^2)",
            value: k,
            expected: "a number in (0, 1] (2/5 for a homogeneous sphere)",
        });
    }
    let n = measured.len();
    let e: Vec<f64> = measured.iter().map(|m| m.e).collect();
    if let Some(bad) = e.iter().find(|x| !x.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "measured e",
            value: *bad,
            expected: "a finite number",
        });
    }
    let we: Vec<f64> = measured
        .iter()
        .map(|m| match options.weights {
            Weights::Camera => m.v_n_m_s * m.v_n_m_s,
            Weights::Equal => 1.0,
        })
        .collect();
    let oblique: Vec<usize> = (0..n).filter(|&i| measured[i].beta.is_some()).collect();
    let psi: Vec<f64> = oblique.iter().map(|&i| measured[i].psi).collect();
    let beta: Vec<f64> = oblique.iter().map(|&i| measured[i].beta.unwrap()).collect();
    let wb: Vec<f64> = oblique
        .iter()
        .map(|&i| match options.weights {
            Weights::Camera => measured[i].v_s_m_s * measured[i].v_s_m_s,
            Weights::Equal => 1.0,
        })
        .collect();
    let hinge = fit_hinge(&psi, &beta, &wb)?;
    let factor = 1.0 + 1.0 / k;

    // e.
    let e_mean = weighted_mean(&e, &we);
    let mean_plain = e.iter().sum::<f64>() / n as f64;
    let spread = if n > 1 {
        (e.iter().map(|x| (x - mean_plain).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
    } else {
        f64::NAN
    };
    let e_stderr = if n > 1 {
        let sw: f64 = we.iter().sum();
        let s2 = e
            .iter()
            .zip(&we)
            .map(|(x, w)| w * (x - e_mean).powi(2))
            .sum::<f64>()
            / (n - 1) as f64;
        (s2 / sw).sqrt()
    } else {
        f64::NAN
    };

    // Hinge parameters and their standard errors.
    let dof = psi.len() - 2;
    // Each parameter acts on its own points only, so each branch's residual variance scales its
    // parameter's error: the sliding points carry the extra scatter of psi (errors in the
    // abscissa times the slope), the plateau does not. A branch of fewer than 5 points gives too
    // unsteady a variance (under 4 degrees of freedom); the pooled one is used instead.
    let pooled = hinge.sse / dof as f64;
    let branch = |sse: f64, m: usize| if m >= 5 { sse / (m - 1) as f64 } else { pooled };
    let both = hinge.shape == HingeShape::Both;
    let slope_se = (hinge.shape != HingeShape::NoSliding && hinge.info_slope > 0.0)
        .then(|| (branch(hinge.sse_sliding, hinge.n_sliding) / hinge.info_slope).sqrt());
    let beta0_se = (hinge.shape != HingeShape::NoRolling && hinge.info_beta0 > 0.0)
        .then(|| (branch(hinge.sse_rolling, hinge.n_rolling) / hinge.info_beta0).sqrt());
    let mu0 = hinge.slope / (factor * (1.0 + e_mean));
    let mu0_se = slope_se
        .map(|se| mu0 * ((se / hinge.slope).powi(2) + (e_stderr / (1.0 + e_mean)).powi(2)).sqrt());
    let kink_se = match (slope_se, beta0_se) {
        // psi* = (1 + beta_0)/s with independent s and beta_0.
        (Some(ss), Some(sb)) if both => Some(
            hinge.kink_psi
                * ((sb / (1.0 + hinge.beta0)).powi(2) + (ss / hinge.slope).powi(2)).sqrt(),
        ),
        _ => None,
    };

    // Bootstrap.
    let points: Vec<Point> = (0..n)
        .map(|i| Point {
            e: e[i],
            we: we[i],
            hinge: measured[i].beta.map(|b| {
                let w = match options.weights {
                    Weights::Camera => measured[i].v_s_m_s * measured[i].v_s_m_s,
                    Weights::Equal => 1.0,
                };
                (measured[i].psi, b, w)
            }),
        })
        .collect();
    let Replicates {
        e: mut bs_e,
        beta0: mut bs_b0,
        mu0: mut bs_mu,
        slope: mut bs_s,
        kink: mut bs_k,
        failed,
    } = pairs_bootstrap(&points, factor, options.bootstrap, options.seed);
    let ci = |v: &mut Vec<f64>, ok: bool| if ok { percentile_interval(v) } else { None };

    let estimate = |value, stderr: Option<f64>, ci95, bound| Estimate {
        value,
        stderr,
        ci95,
        bound,
    };
    let slope_det = hinge.shape != HingeShape::NoSliding;
    let beta0_det = hinge.shape != HingeShape::NoRolling;
    let beta0 = estimate(
        hinge.beta0,
        beta0_se,
        ci(&mut bs_b0, beta0_det),
        (!beta0_det).then_some(Bound::Lower),
    );
    let slope = estimate(
        hinge.slope,
        slope_se,
        ci(&mut bs_s, slope_det),
        (!slope_det).then_some(Bound::Lower),
    );
    let mu0 = estimate(
        mu0,
        mu0_se,
        ci(&mut bs_mu, slope_det),
        (!slope_det).then_some(Bound::Lower),
    );
    let kink_psi = estimate(hinge.kink_psi, kink_se, ci(&mut bs_k, both), None);
    let e_stats = EStats {
        value: e_mean,
        stderr: e_stderr,
        ci95: percentile_interval(&mut bs_e),
        spread,
        min: e.iter().copied().fold(f64::INFINITY, f64::min),
        max: e.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    };

    // Classification and cross-checks.
    let collisions: Vec<Classified> = measured
        .iter()
        .map(|m| match m.beta {
            None => Classified {
                measured: *m,
                kind: None,
                residual: None,
            },
            Some(b) => Classified {
                measured: *m,
                kind: Some(match hinge.shape {
                    HingeShape::NoRolling => ContactKind::Sliding,
                    HingeShape::NoSliding => ContactKind::Rolling,
                    HingeShape::Both if m.psi < hinge.kink_psi => ContactKind::Sliding,
                    HingeShape::Both => ContactKind::Rolling,
                }),
                residual: Some(b - hinge.beta_at(m.psi)),
            },
        })
        .collect();
    let count = |kind| collisions.iter().filter(|c| c.kind == Some(kind)).count();
    let (n_sliding, n_rolling) = (count(ContactKind::Sliding), count(ContactKind::Rolling));
    let sliding: Vec<&Classified> = collisions
        .iter()
        .filter(|c| c.kind == Some(ContactKind::Sliding))
        .collect();
    let impulse_ratio_sliding = (sliding.len() >= 2).then(|| {
        let r: Vec<f64> = sliding.iter().map(|c| c.measured.impulse_ratio).collect();
        let w: Vec<f64> = sliding
            .iter()
            .map(|c| match options.weights {
                Weights::Camera => c.measured.v_n_m_s.powi(2),
                Weights::Equal => 1.0,
            })
            .collect();
        let m = weighted_mean(&r, &w);
        let sw: f64 = w.iter().sum();
        let s2 = r
            .iter()
            .zip(&w)
            .map(|(x, w)| w * (x - m).powi(2))
            .sum::<f64>()
            / (r.len() - 1) as f64;
        (m, (s2 / sw).sqrt())
    });
    let com: Vec<f64> = measured
        .iter()
        .filter_map(|m| m.com_velocity_change_m_s.map(|v| v.norm_squared()))
        .collect();
    let com_dv_rms_m_s =
        (!com.is_empty()).then(|| (com.iter().sum::<f64>() / com.len() as f64).sqrt());
    let residual_rms = {
        let r: Vec<f64> = collisions.iter().filter_map(|c| c.residual).collect();
        (r.iter().map(|x| x * x).sum::<f64>() / r.len() as f64).sqrt()
    };

    let thin = |m: usize, what: &str, param: &str| {
        (m < 3).then(|| {
            format!(
                "; only {m} collision(s) on the {what}, so {param} rests on them: the bootstrap interval is the more honest error"
            )
        })
    };
    let thin_note = [
        thin(hinge.n_sliding, "sliding line", "mu0"),
        thin(hinge.n_rolling, "rolling plateau", "beta0"),
    ]
    .into_iter()
    .flatten()
    .collect::<String>();
    let failed_note = if failed * 100 > options.bootstrap {
        format!(
            "; {failed} of {} bootstrap resamples had no collisions on one side of the kink and were left out of the intervals, which may therefore be too narrow",
            options.bootstrap
        )
    } else {
        String::new()
    };
    // Walton's operator takes beta_0 in [-1, 1] (above 1 a collision gains energy, docs/physics.md
    // §4.4). A plateau level outside it is the noise of tangential velocities too small to
    // measure (nearly head-on collisions: 10 of them at incidence 0 gave beta0 = 1.11 +- 0.55,
    // "converged"), not a property of the spheres.
    let outside = plateau_outside(&hinge);
    let message = match hinge.shape {
        _ if outside => format!(
            "not determined: the rolling plateau's level, beta0 = {}, lies outside Walton's range [-1, 1] (above 1 a collision gains energy); its betas scatter by {} (rms residual): the tangential velocities are mostly noise at these angles of incidence",
            crate::error::Num(hinge.beta0),
            crate::error::Num(residual_rms)
        ),
        HingeShape::Both => format!("converged{thin_note}{failed_note}"),
        HingeShape::NoRolling => format!(
            "not determined: no collision reached the rolling plateau, so beta0 >= {} is only a lower bound (mu0 is determined); add collisions closer to head-on (larger psi)",
            hinge.beta0
        ),
        HingeShape::NoSliding => format!(
            "not determined: every collision is on the rolling plateau, so mu0 >= {} is only a lower bound (beta0 is determined); add more grazing collisions (smaller psi)",
            mu0.value
        ),
    };
    // Every reported number must be finite: data near the edge of f64 can overflow a sum of
    // squares even when each collision is finite.
    let reported = [
        ("e", e_stats.value),
        ("standard error of e", e_stats.stderr),
        ("spread of e", e_stats.spread),
        ("beta0", beta0.value),
        ("mu0", mu0.value),
        ("slope", slope.value),
        ("psi*", kink_psi.value),
        ("residual rms", residual_rms),
    ];
    let optional = [
        ("standard error of beta0", beta0.stderr),
        ("standard error of mu0", mu0.stderr),
        ("standard error of the slope", slope.stderr),
        ("standard error of psi*", kink_psi.stderr),
        ("rms centre-of-mass velocity change", com_dv_rms_m_s),
        ("impulse ratio", impulse_ratio_sliding.map(|r| r.0)),
        (
            "standard error of the impulse ratio",
            impulse_ratio_sliding.map(|r| r.1),
        ),
    ];
    let intervals = [
        e_stats.ci95,
        beta0.ci95,
        mu0.ci95,
        slope.ci95,
        kink_psi.ci95,
    ];
    let bad = reported
        .into_iter()
        .chain(optional.into_iter().filter_map(|(n, v)| v.map(|v| (n, v))))
        .chain(
            intervals
                .into_iter()
                .flatten()
                .flat_map(|(lo, hi)| [("95% interval", lo), ("95% interval", hi)]),
        )
        .find(|(_, v)| !v.is_finite());
    if let Some((name, value)) = bad {
        return Err(Error::InvalidParameter {
            name,
            value,
            expected: "a finite number (the data's magnitudes overflow the fit's sums)",
        });
    }
    Ok(WaltonFit {
        e: e_stats,
        beta0,
        mu0,
        slope,
        kink_psi,
        hinge,
        collisions,
        n,
        n_sliding,
        n_rolling,
        n_head_on: n - oblique.len(),
        impulse_ratio_sliding,
        com_dv_rms_m_s,
        residual_rms,
        dof,
        bootstrap: BootstrapInfo {
            resamples: options.bootstrap,
            seed: options.seed,
            failed,
        },
        converged: both && !outside,
        message,
        options: *options,
    })
}

/// Whether the hinge's plateau (determined: some collision reaches it) lies outside Walton's
/// range [-1, 1] of beta_0.
fn plateau_outside(h: &HingeFit) -> bool {
    h.shape != HingeShape::NoRolling && !(-1.0..=1.0).contains(&h.beta0)
}

impl WaltonFit {
    /// Whether beta_0 is not determined because the plateau's level lies outside [-1, 1] (see
    /// `message`), rather than because a branch has no collisions.
    pub fn plateau_outside(&self) -> bool {
        plateau_outside(&self.hinge)
    }

    /// The paper's critical angle of incidence gamma_0 in degrees (Fig. 1: cot gamma = v_n/v_s,
    /// 180 degrees head-on): cot gamma_0 = -psi*.
    pub fn gamma0_deg(&self) -> f64 {
        (1.0f64).atan2(-self.kink_psi.value).to_degrees()
    }
}
