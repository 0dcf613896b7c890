//! The Fig. 6 fit: e, beta_0 and mu_0 of Walton's operator from measured oblique collisions.
//!
//! Each collision, measured by [`walton::measure`], gives e_i (Eq. 4), beta_i (Eq. 5) and
//! psi_i = -v_n/|v_s|. Walton's Eq. (7) says beta(psi) = min(-1 + s psi, beta_0) with
//! s = mu_0 (1 + 1/K)(1 + e): a hinge through (0, -1) whose kink psi* = (1 + beta_0)/s separates
//! sliding (psi < psi*) from rolling (psi >= psi*) collisions. [`fit_hinge`] finds the global
//! least-squares hinge exactly (no starting guess: see its doc); [`fit`] adds e, mu_0 =
//! s/((1 + 1/K)(1 + e)), standard errors, seeded bootstrap 95% intervals and the classification.
//!
//! Also here: the CSV schema of `restitution walton fit` ([`read_collisions`], [`write_collisions`]),
//! so that every producer of oblique-collision data (the generator, the kinematics command) writes
//! exactly what the fit reads.

use crate::contact::{Material, Sphere};
use crate::data::{DataError, Table, fmt_num};
use crate::error::{Error, Result};
use crate::models::walton::{self, Body, ContactKind, Measured, State, Target};
use nalgebra::Vector3;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

// ---------------------------------------------------------------------------------------------
// The hinge.

/// Which segments of the hinge the data reach.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HingeShape {
    /// Collisions on both sides of the kink: slope and plateau are both determined.
    Both,
    /// Every collision is on the sliding line: beta_0 has only a lower bound, -1 + s psi_max.
    NoRolling,
    /// Every collision is on the plateau: the slope has only a lower bound, (1 + beta_0)/psi_min.
    NoSliding,
}

/// The least-squares hinge beta = min(-1 + s psi, beta_0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HingeFit {
    /// s; for [`HingeShape::NoSliding`] the lower bound (1 + beta_0)/psi_min.
    pub slope: f64,
    /// beta_0; for [`HingeShape::NoRolling`] the lower bound -1 + s psi_max.
    pub beta0: f64,
    /// psi* = (1 + beta_0)/s.
    pub kink_psi: f64,
    /// Weighted sum of squared residuals, sum w_i (beta_i - hinge(psi_i))^2.
    pub sse: f64,
    pub shape: HingeShape,
    /// Points with psi < psi* (the sliding line) and psi >= psi* (the plateau).
    pub n_sliding: usize,
    pub n_rolling: usize,
    /// sum over sliding points of w psi^2, and over rolling points of w: the diagonal of the
    /// Gauss-Newton normal matrix (the two parameters act on disjoint points, so it is diagonal).
    pub info_slope: f64,
    pub info_beta0: f64,
    /// The part of `sse` from the sliding points and from the rolling points.
    pub sse_sliding: f64,
    pub sse_rolling: f64,
}

impl HingeFit {
    /// The hinge at `psi`.
    pub fn beta_at(&self, psi: f64) -> f64 {
        (-1.0 + self.slope * psi).min(self.beta0)
    }
}

/// Global weighted least-squares fit of beta = min(-1 + s psi, beta_0), s > 0.
///
/// Solves: minimise S(s, c) = sum w_i (y_i - min(s psi_i, c))^2 with y = beta + 1, c = 1 + beta_0.
/// Needs: at least 3 points, psi_i >= 0, finite beta_i, weights w_i > 0.
/// Method (exact segmented regression, Hudson, J. Am. Stat. Assoc. 61, 1097 (1966), for a kink
/// whose position is itself a parameter): S is continuous and piecewise quadratic in (s, c); the
/// pieces are the orderings of the kink relative to the sorted psi_i. Its global minimum is either
/// the unconstrained least-squares point of a piece that lies inside that piece (the first k
/// points on the line s psi, the rest on the plateau c: two independent linear fits), or lies on
/// a piece boundary, where the kink sits at a data point psi_j and the model is s min(psi, psi_j),
/// linear in s. All n + 1 partitions and n boundaries are evaluated in O(n) with prefix sums
/// after an O(n log n) sort; the smallest valid candidate is the global minimum, with no starting
/// guess. Known-answer tests: exact recovery of noise-free hinges, and no point of a dense
/// (s, beta_0) grid below the returned minimum (tests below).
pub fn fit_hinge(psi: &[f64], beta: &[f64], weight: &[f64]) -> Result<HingeFit> {
    let n = psi.len();
    if beta.len() != n || weight.len() != n {
        return Err(Error::InvalidParameter {
            name: "hinge fit input lengths",
            value: n as f64,
            expected: "psi, beta and weights of equal length",
        });
    }
    if n < 3 {
        return Err(Error::InvalidParameter {
            name: "number of oblique collisions",
            value: n as f64,
            expected: ">= 3 (two parameters and a residual)",
        });
    }
    for i in 0..n {
        let bad = |name, value, expected| {
            Err(Error::InvalidParameter {
                name,
                value,
                expected,
            })
        };
        if !(psi[i].is_finite() && psi[i] >= 0.0) {
            return bad("psi", psi[i], "a finite number >= 0");
        }
        if !beta[i].is_finite() {
            return bad("beta", beta[i], "a finite number");
        }
        if !(weight[i].is_finite() && weight[i] > 0.0) {
            return bad("weight", weight[i], "a finite number > 0");
        }
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| psi[a].total_cmp(&psi[b]));
    let x: Vec<f64> = order.iter().map(|&i| psi[i]).collect();
    let y: Vec<f64> = order.iter().map(|&i| beta[i] + 1.0).collect();
    let w: Vec<f64> = order.iter().map(|&i| weight[i]).collect();
    // Prefix sums over the first k sorted points.
    let mut a = vec![0.0; n + 1]; // w x^2
    let mut b = vec![0.0; n + 1]; // w x y
    let mut sw = vec![0.0; n + 1]; // w
    let mut sy = vec![0.0; n + 1]; // w y
    for i in 0..n {
        a[i + 1] = a[i] + w[i] * x[i] * x[i];
        b[i + 1] = b[i] + w[i] * x[i] * y[i];
        sw[i + 1] = sw[i] + w[i];
        sy[i + 1] = sy[i] + w[i] * y[i];
    }
    let syy: f64 = (0..n).map(|i| w[i] * y[i] * y[i]).sum();
    // Candidates (sse, s, c, shape); s = NaN when the slope is not determined.
    let mut best: Option<(f64, f64, f64, HingeShape)> = None;
    let mut offer = |sse: f64, s: f64, c: f64, shape: HingeShape| {
        if best.is_none_or(|(b, ..)| sse < b) {
            best = Some((sse, s, c, shape));
        }
    };
    // All points on the plateau.
    offer(
        syy - sy[n] * sy[n] / sw[n],
        f64::NAN,
        sy[n] / sw[n],
        HingeShape::NoSliding,
    );
    // All points on the line.
    if a[n] > 0.0 && b[n] > 0.0 {
        let s = b[n] / a[n];
        offer(
            syy - b[n] * b[n] / a[n],
            s,
            s * x[n - 1],
            HingeShape::NoRolling,
        );
    }
    for k in 1..n {
        // Interior of a piece: first k on the line, the rest on the plateau.
        if a[k] > 0.0 && b[k] > 0.0 {
            let s = b[k] / a[k];
            let (wr, yr) = (sw[n] - sw[k], sy[n] - sy[k]);
            let c = yr / wr;
            let kink = c / s;
            if x[k - 1] <= kink && kink <= x[k] {
                offer(
                    syy - b[k] * b[k] / a[k] - yr * yr / wr,
                    s,
                    c,
                    HingeShape::Both,
                );
            }
        }
    }
    for j in 0..n {
        // Boundary: kink at x_j, model s min(x, x_j).
        let sxy = b[j + 1] + x[j] * (sy[n] - sy[j + 1]);
        let sxx = a[j + 1] + x[j] * x[j] * (sw[n] - sw[j + 1]);
        if sxx > 0.0 && sxy > 0.0 {
            let s = sxy / sxx;
            // A kink at the first point is the all-plateau model, at the last the all-line one.
            let shape = if j + 1 == n {
                HingeShape::NoRolling
            } else if j == 0 {
                HingeShape::NoSliding
            } else {
                HingeShape::Both
            };
            offer(syy - sxy * sxy / sxx, s, s * x[j], shape);
        }
    }
    let (_, s, c, shape) = best.expect("the all-plateau candidate always exists");
    let (slope, kink) = match shape {
        HingeShape::NoSliding => {
            // Any s >= c/psi_min fits equally; report that bound.
            let kink = x[0];
            (if kink > 0.0 { c / kink } else { f64::INFINITY }, kink)
        }
        _ => (s, c / s),
    };
    let mut fit = HingeFit {
        slope,
        beta0: c - 1.0,
        kink_psi: kink,
        sse: 0.0,
        shape,
        n_sliding: 0,
        n_rolling: 0,
        info_slope: 0.0,
        info_beta0: 0.0,
        sse_sliding: 0.0,
        sse_rolling: 0.0,
    };
    // The reported SSE is summed directly (the prefix-sum form cancels when the fit is close).
    for i in 0..n {
        let r = beta[i] - fit.beta_at(psi[i]);
        fit.sse += weight[i] * r * r;
        let on_line = match shape {
            HingeShape::NoRolling => true,
            HingeShape::NoSliding => false,
            HingeShape::Both => psi[i] < kink,
        };
        if on_line {
            fit.n_sliding += 1;
            fit.info_slope += weight[i] * psi[i] * psi[i];
            fit.sse_sliding += weight[i] * r * r;
        } else {
            fit.n_rolling += 1;
            fit.info_beta0 += weight[i];
            fit.sse_rolling += weight[i] * r * r;
        }
    }
    Ok(fit)
}

// ---------------------------------------------------------------------------------------------
// The full fit.

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

/// Core of [`fit`] on one sample: (e_mean, hinge) or None when the hinge is degenerate.
fn fit_once(
    e: &[f64],
    we: &[f64],
    psi: &[f64],
    beta: &[f64],
    wb: &[f64],
) -> Option<(f64, HingeFit)> {
    let e_mean = weighted_mean(e, we);
    let h = fit_hinge(psi, beta, wb).ok()?;
    (h.shape == HingeShape::Both).then_some((e_mean, h))
}

/// The 2.5% and 97.5% points of `v` (sorted in place), by linear interpolation between order
/// statistics (Hyndman & Fan type 7, numpy's default).
fn percentile_interval(v: &mut [f64]) -> Option<(f64, f64)> {
    if v.len() < 2 {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let h = (v.len() - 1) as f64 * p;
        let lo = h.floor() as usize;
        let hi = (lo + 1).min(v.len() - 1);
        v[lo] + (h - lo as f64) * (v[hi] - v[lo])
    };
    Some((q(0.025), q(0.975)))
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
    let mut rng = StdRng::seed_from_u64(options.seed);
    let (mut bs_e, mut bs_b0, mut bs_mu, mut bs_s, mut bs_k) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut failed = 0;
    let (mut re, mut rwe, mut rp, mut rb, mut rwb) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for _ in 0..options.bootstrap {
        re.clear();
        rwe.clear();
        rp.clear();
        rb.clear();
        rwb.clear();
        for _ in 0..n {
            let i = rng.random_range(0..n);
            re.push(e[i]);
            rwe.push(we[i]);
            if let Some(b) = measured[i].beta {
                rp.push(measured[i].psi);
                rb.push(b);
                rwb.push(match options.weights {
                    Weights::Camera => measured[i].v_s_m_s.powi(2),
                    Weights::Equal => 1.0,
                });
            }
        }
        match fit_once(&re, &rwe, &rp, &rb, &rwb) {
            Some((em, h)) => {
                bs_e.push(em);
                bs_b0.push(h.beta0);
                bs_s.push(h.slope);
                bs_mu.push(h.slope / (factor * (1.0 + em)));
                bs_k.push(h.kink_psi);
            }
            None => failed += 1,
        }
    }
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
    let message = match hinge.shape {
        HingeShape::Both => format!("converged{thin_note}{failed_note}"),
        HingeShape::NoRolling => format!(
            "not determined: no collision reached the rolling plateau, so beta0 >= {} is only a lower bound (mu0 is determined); add collisions closer to head-on (larger psi)",
            fmt_num(hinge.beta0)
        ),
        HingeShape::NoSliding => format!(
            "not determined: every collision is on the rolling plateau, so mu0 >= {} is only a lower bound (beta0 is determined); add more grazing collisions (smaller psi)",
            fmt_num(mu0.value)
        ),
    };
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
        converged: both,
        message,
        options: *options,
    })
}

impl WaltonFit {
    /// The paper's critical angle of incidence gamma_0 in degrees (Fig. 1: cot gamma = v_n/v_s,
    /// 180 degrees head-on): cot gamma_0 = -psi*.
    pub fn gamma0_deg(&self) -> f64 {
        (1.0f64).atan2(-self.kink_psi.value).to_degrees()
    }
}

// ---------------------------------------------------------------------------------------------
// Synthetic data.

/// A synthetic oblique-collision experiment like the paper's Fig. 6 series: two equal spheres
/// launched towards each other at about the same speed, the impact parameter varied so that the
/// angle of incidence covers a range, collided with Walton's operator, and the kinematics blurred
/// by Gaussian measurement noise. Used by `examples/gen_oblique_collisions.rs` and the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyntheticSpec {
    pub n: usize,
    pub d_m: f64,
    pub material: Material,
    pub inertia_k: f64,
    pub params: walton::WaltonParams,
    /// Mean launch speed of each sphere and its standard deviation, m/s.
    pub speed_m_s: f64,
    pub speed_sd_m_s: f64,
    /// Angle between -n and the relative velocity, drawn uniformly in this range, degrees.
    pub incidence_deg: (f64, f64),
    /// Standard deviation of the pre-collision spins (each component in the plane's normal), rad/s.
    pub spin_sd_rad_s: f64,
    /// Measurement noise, one standard deviation per component: centre velocity (m/s), spin
    /// (rad/s), centre position at contact (m).
    pub noise_v_m_s: f64,
    pub noise_w_rad_s: f64,
    pub noise_r_m: f64,
}

impl SyntheticSpec {
    /// The paper's experiment (Sec. IV): 25.4 mm nylon, about 2 m/s per sphere, e = 0.97,
    /// mu_0 = 0.175, beta_0 = 0.5, 60 collisions with incidence 10 to 80 degrees (psi about
    /// 0.18 to 5.7). Noise: 0.04 m/s per velocity component, the paper's "about a 4% uncertainty
    /// for velocities of the order of 1 m/s" (Sec. III); spins 3 rad/s, which gives the surface
    /// speed (d/2) w the same error as the centre speed; positions 0.2 mm, two subpixels (half a
    /// pixel) for a 25.4 mm sphere imaged over about 60 pixels (a 100 mm field of view on the
    /// camera's 239 pixels).
    pub fn paper() -> Self {
        SyntheticSpec {
            n: 60,
            d_m: 0.0254,
            material: Material::preset("nylon").expect("a preset"),
            inertia_k: walton::K_HOMOGENEOUS,
            params: walton::WaltonParams::PAPER_NYLON,
            speed_m_s: 2.0,
            speed_sd_m_s: 0.05,
            incidence_deg: (10.0, 80.0),
            spin_sd_rad_s: 3.0,
            noise_v_m_s: 0.04,
            noise_w_rad_s: 3.0,
            noise_r_m: 2e-4,
        }
    }
}

/// Draws the collisions of `spec` (true and measured), reproducibly from `seed`. In 2-D (the x-y
/// plane, spins about z), as in the paper's camera plane. Returns (true, measured) records.
pub fn synthetic_collisions(
    spec: &SyntheticSpec,
    seed: u64,
) -> Result<(Vec<CollisionRecord>, Vec<CollisionRecord>)> {
    use rand_distr::{Distribution, Normal};
    let normal = |sd: f64| {
        Normal::new(0.0, sd).map_err(|_| Error::InvalidParameter {
            name: "noise standard deviation",
            value: sd,
            expected: "a finite number >= 0",
        })
    };
    let (speed_noise, spin0, nv, nw, nr) = (
        normal(spec.speed_sd_m_s)?,
        normal(spec.spin_sd_rad_s)?,
        normal(spec.noise_v_m_s)?,
        normal(spec.noise_w_rad_s)?,
        normal(spec.noise_r_m)?,
    );
    let sphere = Sphere::new(spec.d_m, spec.material)?;
    let mut rng = StdRng::seed_from_u64(seed);
    let mut truth = Vec::with_capacity(spec.n);
    let mut measured = Vec::with_capacity(spec.n);
    let (lo, hi) = spec.incidence_deg;
    for i in 0..spec.n {
        let speed1 = spec.speed_m_s + speed_noise.sample(&mut rng);
        let speed2 = spec.speed_m_s + speed_noise.sample(&mut rng);
        // Launch directions within a few degrees of +x and -x.
        let a1 = rng.random_range(-3f64..3.0).to_radians();
        let a2 = std::f64::consts::PI + rng.random_range(-3f64..3.0).to_radians();
        let v1 = speed1 * Vector3::new(a1.cos(), a1.sin(), 0.0);
        let v2 = speed2 * Vector3::new(a2.cos(), a2.sin(), 0.0);
        let u = (v1 - v2).normalize();
        let theta = rng.random_range(lo..=hi).to_radians();
        let theta = if rng.random_bool(0.5) { theta } else { -theta };
        // n = -u rotated by theta about z.
        let n = Vector3::new(
            -(u.x * theta.cos() - u.y * theta.sin()),
            -(u.x * theta.sin() + u.y * theta.cos()),
            0.0,
        );
        let r1 = Vector3::new(
            0.05 + rng.random_range(-0.01..0.01),
            0.10 + rng.random_range(-0.01..0.01),
            0.0,
        );
        let r2 = r1 - spec.d_m * n;
        let body = |r: Vector3<f64>, v: Vector3<f64>, w: f64| Body {
            inertia_k: spec.inertia_k,
            ..Body::homogeneous(r, &sphere).moving(v, Vector3::new(0.0, 0.0, w))
        };
        let pre = State::pair(
            body(r1, v1, spin0.sample(&mut rng)),
            body(r2, v2, spin0.sample(&mut rng)),
        );
        let post = walton::collide(&pre, &spec.params)?.state;
        let mut blur = |b: &Body, position: bool| -> Body {
            let dr = if position {
                Vector3::new(nr.sample(&mut rng), nr.sample(&mut rng), 0.0)
            } else {
                Vector3::zeros()
            };
            Body {
                position_m: b.position_m + dr,
                velocity_m_s: b.velocity_m_s
                    + Vector3::new(nv.sample(&mut rng), nv.sample(&mut rng), 0.0),
                spin_rad_s: b.spin_rad_s + Vector3::new(0.0, 0.0, nw.sample(&mut rng)),
                ..*b
            }
        };
        let sphere2 = |s: &State| match s.target {
            Target::Sphere(b) => b,
            Target::Wall { .. } => unreachable!("synthetic collisions are sphere pairs"),
        };
        let pre_m = State::pair(blur(&pre.sphere, true), blur(&sphere2(&pre), true));
        // The collision is instantaneous: measured post positions are the measured contact ones.
        let mut post_m = State::pair(blur(&post.sphere, false), blur(&sphere2(&post), false));
        post_m.sphere.position_m = pre_m.sphere.position_m;
        if let (Target::Sphere(b), Target::Sphere(a)) = (&mut post_m.target, &pre_m.target) {
            b.position_m = a.position_m;
        }
        let id = Some(format!("{}", i + 1));
        truth.push(CollisionRecord {
            line: 0,
            id: id.clone(),
            pre,
            post,
        });
        measured.push(CollisionRecord {
            line: 0,
            id,
            pre: pre_m,
            post: post_m,
        });
    }
    Ok((truth, measured))
}

// ---------------------------------------------------------------------------------------------
// The CSV schema.

/// One collision read from a `walton fit` CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionRecord {
    /// 1-based line in the file (0 for records not read from a file).
    pub line: usize,
    /// The `collision` column, if any.
    pub id: Option<String>,
    pub pre: State,
    pub post: State,
}

/// Columns of one sphere: position (3), velocity (3), spin (3) before; velocity and spin after.
fn sphere_columns(i: u8) -> [String; 15] {
    [
        format!("x{i}_m"),
        format!("y{i}_m"),
        format!("z{i}_m"),
        format!("v{i}x_m_s"),
        format!("v{i}y_m_s"),
        format!("v{i}z_m_s"),
        format!("w{i}x_rad_s"),
        format!("w{i}y_rad_s"),
        format!("w{i}z_rad_s"),
        format!("v{i}x_post_m_s"),
        format!("v{i}y_post_m_s"),
        format!("v{i}z_post_m_s"),
        format!("w{i}x_post_rad_s"),
        format!("w{i}y_post_rad_s"),
        format!("w{i}z_post_rad_s"),
    ]
}

/// Indices into [`sphere_columns`] that are required (the in-plane set of the issue); the others
/// (z, v_z, w_x, w_y) are optional and default to 0.
const REQUIRED: [usize; 8] = [0, 1, 3, 4, 8, 9, 10, 14];

/// A centre distance is accepted when within this factor of the touching distance: it catches
/// positions in millimetres or centres not at contact, while allowing tracking noise (a pixel
/// is a few per cent of a diameter in the paper's images).
const CONTACT_DISTANCE_TOLERANCE: f64 = 0.25;

/// Reads the collisions of a `walton fit` CSV (schema: `restitution walton fit --help`).
/// Masses come from the diameters and `material` ([`Sphere::mass_kg`]); both spheres get inertia factor
/// `inertia_k`. Returns the records and warnings (unknown columns, 3-D columns without their
/// pre/post partner). Errors name the file, line, column and value.
pub fn read_collisions(
    table: &Table,
    material: &Material,
    inertia_k: f64,
) -> std::result::Result<(Vec<CollisionRecord>, Vec<String>), DataError> {
    let d1c = table.require("d1_mm")?;
    let d2c = table.require("d2_mm")?;
    let c1 = sphere_columns(1);
    let c2 = sphere_columns(2);
    let idx1: Vec<Option<usize>> = c1.iter().map(|c| table.column(c)).collect();
    let idx2: Vec<Option<usize>> = c2.iter().map(|c| table.column(c)).collect();
    for &j in &REQUIRED {
        table.require(&c1[j])?;
    }
    // Sphere 2's position is needed for walls too (the contact point).
    table.require(&c2[0])?;
    table.require(&c2[1])?;
    let id_col = table.column("collision");
    let mut warnings = Vec::new();
    for h in &table.headers {
        let known =
            h == "d1_mm" || h == "d2_mm" || h == "collision" || c1.contains(h) || c2.contains(h);
        if !known {
            warnings.push(format!(
                "{}:{}: ignoring unknown column '{h}'",
                table.path, table.header_line
            ));
        }
    }
    for (cols, idx) in [(&c1, &idx1), (&c2, &idx2)] {
        // Pre velocity/spin j (3..9) pairs with post j + 6.
        for j in [5, 6, 7] {
            if idx[j].is_some() != idx[j + 6].is_some() {
                let (have, missing) = if idx[j].is_some() {
                    (&cols[j], &cols[j + 6])
                } else {
                    (&cols[j + 6], &cols[j])
                };
                warnings.push(format!(
                    "{}:{}: column '{have}' without '{missing}': the missing one is taken as 0",
                    table.path, table.header_line
                ));
            }
        }
    }
    let mut records = Vec::with_capacity(table.rows.len());
    for row in &table.rows {
        let d1_mm = table.number_where(row, d1c, |v| v > 0.0, "a diameter > 0 (mm)")?;
        let d2_mm = table.positive_or_inf(row, d2c)?;
        let wall = d2_mm.is_infinite();
        let read = |idx: &[Option<usize>], names: &[String; 15], j: usize, zero_ok: bool| match idx
            [j]
        {
            None if REQUIRED.contains(&j) && !zero_ok => Err(DataError {
                path: table.path.clone(),
                line: Some(row.line),
                column: Some(names[j].clone()),
                message: format!(
                    "required column is missing (needed for a sphere-sphere collision, d2_mm = {})",
                    row.fields[d2c]
                ),
            }),
            None => Ok(0.0),
            Some(c) if zero_ok && row.fields[c].is_empty() => Ok(0.0),
            Some(c) => table.number(row, c),
        };
        let mut v1 = [0.0; 15];
        let mut v2 = [0.0; 15];
        for j in 0..15 {
            v1[j] = read(&idx1, &c1, j, false)?;
            // For a wall, only the contact point (positions) is read; motion must be absent or 0.
            let position = j < 3;
            v2[j] = read(&idx2, &c2, j, wall && !position)?;
            if wall && !position && v2[j] != 0.0 {
                let c = idx2[j].expect("a nonzero value came from a column");
                return Err(table.cell_error(
                    row,
                    c,
                    format!(
                        "'{}': a wall (d2_mm = inf) is at rest; leave its velocity and spin columns empty or 0",
                        row.fields[c]
                    ),
                ));
            }
        }
        let vec3 = |v: &[f64; 15], j: usize| Vector3::new(v[j], v[j + 1], v[j + 2]);
        let d1 = d1_mm * 1e-3;
        // Diameters were checked > 0 above, so the sphere is valid.
        let mass = |d: f64| {
            Sphere::new(d, *material)
                .map(|s| s.mass_kg())
                .unwrap_or(f64::NAN)
        };
        let body = |v: &[f64; 15], d: f64, post: bool| Body {
            position_m: vec3(v, 0),
            velocity_m_s: vec3(v, if post { 9 } else { 3 }),
            spin_rad_s: vec3(v, if post { 12 } else { 6 }),
            d_m: d,
            mass_kg: mass(d),
            inertia_k,
        };
        let (pre, post) = if wall {
            let p = vec3(&v2, 0);
            (
                State::on_wall(body(&v1, d1, false), p),
                State::on_wall(body(&v1, d1, true), p),
            )
        } else {
            let d2 = d2_mm * 1e-3;
            (
                State::pair(body(&v1, d1, false), body(&v2, d2, false)),
                State::pair(body(&v1, d1, true), body(&v2, d2, true)),
            )
        };
        let touching = if wall {
            0.5 * d1
        } else {
            0.5 * (d1 + d2_mm * 1e-3)
        };
        let other = match pre.target {
            Target::Sphere(b) => b.position_m,
            Target::Wall { contact_point_m } => contact_point_m,
        };
        let dist = (pre.sphere.position_m - other).norm();
        let off = (dist / touching - 1.0).abs();
        if off.is_nan() || off > CONTACT_DISTANCE_TOLERANCE {
            let what = if wall {
                "centre to wall contact point (x2_m, y2_m) is"
            } else {
                "centres are"
            };
            return Err(DataError {
                path: table.path.clone(),
                line: Some(row.line),
                column: Some("x1_m".into()),
                message: format!(
                    "{what} {} m apart, but touching needs {} m from the diameters (within {}%): positions must be in metres, at contact",
                    fmt_num(dist),
                    fmt_num(touching),
                    CONTACT_DISTANCE_TOLERANCE * 100.0
                ),
            });
        }
        records.push(CollisionRecord {
            line: row.line,
            id: id_col.map(|c| row.fields[c].clone()),
            pre,
            post,
        });
    }
    Ok((records, warnings))
}

/// Measures every record ([`walton::measure`]); an error names the record's line.
pub fn measure_records(
    path: &str,
    records: &[CollisionRecord],
) -> std::result::Result<Vec<Measured>, DataError> {
    records
        .iter()
        .map(|r| {
            let err = |message: String| DataError {
                path: path.to_string(),
                line: Some(r.line),
                column: None,
                message,
            };
            let frame = r.pre.contact().map_err(|e| err(e.to_string()))?;
            let approach = frame.v_rel_m_s.dot(&frame.normal);
            if approach.is_nan() || approach >= 0.0 {
                return Err(err(format!(
                    "the spheres are not approaching before the collision: (v1 - v2) . n = {} m/s, expected < 0 (n points from sphere 2 to sphere 1; check the velocity signs and the pre/post columns)",
                    fmt_num(approach)
                )));
            }
            walton::measure(&r.pre, &r.post).map_err(|e| err(e.to_string()))
        })
        .collect()
}

/// Writes records in the `walton fit` CSV schema: the in-plane columns, plus the out-of-plane
/// ones when any record has a nonzero z component, position or in-plane spin. A `collision` id
/// column is written when any record has an id. Numbers in shortest round-trip form.
pub fn write_collisions(records: &[CollisionRecord]) -> String {
    let flat = |r: &CollisionRecord| -> ([f64; 15], [f64; 15], f64, f64) {
        let pack = |pre: &Body, post: &Body| {
            let mut v = [0.0; 15];
            for (j, x) in pre
                .position_m
                .iter()
                .chain(pre.velocity_m_s.iter())
                .chain(pre.spin_rad_s.iter())
                .chain(post.velocity_m_s.iter())
                .chain(post.spin_rad_s.iter())
                .enumerate()
            {
                v[j] = *x;
            }
            v
        };
        let v1 = pack(&r.pre.sphere, &r.post.sphere);
        match (&r.pre.target, &r.post.target) {
            (Target::Sphere(a), Target::Sphere(b)) => (v1, pack(a, b), r.pre.sphere.d_m, a.d_m),
            (Target::Wall { contact_point_m }, _) | (_, Target::Wall { contact_point_m }) => {
                let mut v2 = [0.0; 15];
                v2[..3].copy_from_slice(contact_point_m.as_slice());
                (v1, v2, r.pre.sphere.d_m, f64::INFINITY)
            }
        }
    };
    let rows: Vec<_> = records.iter().map(flat).collect();
    let three_d = rows.iter().any(|(a, b, ..)| {
        (0..15)
            .filter(|j| !REQUIRED.contains(j))
            .any(|j| a[j] != 0.0 || b[j] != 0.0)
    });
    let cols: Vec<usize> = (0..15)
        .filter(|j| three_d || REQUIRED.contains(j))
        .collect();
    let with_id = records.iter().any(|r| r.id.is_some());
    let (c1, c2) = (sphere_columns(1), sphere_columns(2));
    let mut header: Vec<String> = Vec::new();
    if with_id {
        header.push("collision".into());
    }
    header.push("d1_mm".into());
    header.push("d2_mm".into());
    // The order: positions (sphere 1, sphere 2), motion before (1, 2), after (1, 2).
    let groups: [(bool, std::ops::Range<usize>); 6] = [
        (true, 0..3),
        (false, 0..3),
        (true, 3..9),
        (false, 3..9),
        (true, 9..15),
        (false, 9..15),
    ];
    for (first, range) in &groups {
        let c = if *first { &c1 } else { &c2 };
        for &j in cols.iter().filter(|j| range.contains(j)) {
            header.push(c[j].clone());
        }
    }
    let mut out = header.join(",") + "\n";
    for (r, (a, b, d1, d2)) in records.iter().zip(&rows) {
        let mut cells: Vec<String> = Vec::new();
        if with_id {
            cells.push(r.id.clone().unwrap_or_default());
        }
        cells.push(fmt_num(d1 * 1e3));
        cells.push(if d2.is_infinite() {
            "inf".into()
        } else {
            fmt_num(d2 * 1e3)
        });
        for (first, range) in &groups {
            let v = if *first { a } else { b };
            for &j in cols.iter().filter(|j| range.contains(j)) {
                cells.push(fmt_num(v[j]));
            }
        }
        out += &(cells.join(",") + "\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::{Distribution, Normal};

    fn hinge_sse(psi: &[f64], beta: &[f64], w: &[f64], s: f64, b0: f64) -> f64 {
        (0..psi.len())
            .map(|i| w[i] * (beta[i] - (-1.0 + s * psi[i]).min(b0)).powi(2))
            .sum()
    }

    #[test]
    fn noise_free_hinge_is_recovered_exactly() {
        let psi: Vec<f64> = (0..20).map(|i| 0.1 + 0.3 * i as f64).collect();
        let (s, b0) = (1.2, 0.5);
        let beta: Vec<f64> = psi.iter().map(|p| (-1.0 + s * p).min(b0)).collect();
        let w = vec![1.0; psi.len()];
        let h = fit_hinge(&psi, &beta, &w).unwrap();
        // Rounding of sums of ~20 O(1) terms.
        assert!((h.slope - s).abs() < 1e-13, "{h:?}");
        assert!((h.beta0 - b0).abs() < 1e-13);
        assert!((h.kink_psi - 1.25).abs() < 1e-12);
        assert_eq!(h.shape, HingeShape::Both);
        assert_eq!(h.n_sliding, 4); // psi = 0.1, 0.4, 0.7, 1.0 < 1.25
    }

    /// Globality: no point of a dense (s, beta_0) grid beats the returned minimum, for noisy data
    /// with outliers where a local solver started at the wrong kink would stop early.
    #[test]
    fn global_minimum_beats_a_dense_grid() {
        let mut rng = StdRng::seed_from_u64(7);
        let noise = Normal::new(0.0, 0.25).unwrap();
        for _ in 0..5 {
            let psi: Vec<f64> = (0..25).map(|_| rng.random_range(0.0..5.0)).collect();
            let beta: Vec<f64> = psi
                .iter()
                .map(|p| (-1.0 + 1.2 * p).min(0.5) + noise.sample(&mut rng))
                .collect();
            let w: Vec<f64> = (0..25).map(|_| rng.random_range(0.2..2.0)).collect();
            let h = fit_hinge(&psi, &beta, &w).unwrap();
            let direct = hinge_sse(&psi, &beta, &w, h.slope, h.beta0);
            assert!((direct - h.sse).abs() <= 1e-12 * direct);
            let mut grid_min = f64::INFINITY;
            for i in 0..=400 {
                let s = 0.01 + 6.0 * i as f64 / 400.0;
                for j in 0..=400 {
                    let b0 = -1.0 + 2.5 * j as f64 / 400.0;
                    grid_min = grid_min.min(hinge_sse(&psi, &beta, &w, s, b0));
                }
            }
            // The exact minimum can only be below a grid point's value (up to rounding).
            assert!(h.sse <= grid_min * (1.0 + 1e-12), "{} > {grid_min}", h.sse);
        }
    }

    #[test]
    fn degenerate_shapes_are_reported() {
        // All on the line.
        let psi = [0.1, 0.3, 0.5, 0.7];
        let beta: Vec<f64> = psi.iter().map(|p| -1.0 + 1.0 * p).collect();
        let h = fit_hinge(&psi, &beta, &[1.0; 4]).unwrap();
        assert_eq!(h.shape, HingeShape::NoRolling);
        assert!((h.slope - 1.0).abs() < 1e-14);
        // All on the plateau.
        let psi = [2.0, 3.0, 4.0, 5.0];
        let beta = [0.5, 0.52, 0.48, 0.5];
        let h = fit_hinge(&psi, &beta, &[1.0; 4]).unwrap();
        assert_eq!(h.shape, HingeShape::NoSliding);
        assert!((h.beta0 - 0.5).abs() < 1e-14);
        assert!((h.slope - 1.5 / 2.0).abs() < 1e-14);
        // Too few points, bad values.
        assert!(fit_hinge(&[1.0, 2.0], &[0.0, 0.0], &[1.0, 1.0]).is_err());
        assert!(fit_hinge(&[1.0, 2.0, f64::NAN], &[0.0; 3], &[1.0; 3]).is_err());
        assert!(fit_hinge(&[1.0, 2.0, 3.0], &[0.0; 3], &[1.0, 0.0, 1.0]).is_err());
    }

    #[test]
    fn percentiles_match_numpy_type_7() {
        // numpy.percentile(range(11), [2.5, 97.5]) = [0.25, 9.75].
        let mut v: Vec<f64> = (0..11).rev().map(f64::from).collect();
        let (lo, hi) = percentile_interval(&mut v).unwrap();
        assert!((lo - 0.25).abs() < 1e-15 && (hi - 9.75).abs() < 1e-15);
    }
}
