//! The hinge of Walton's Eq. (7), beta(psi) = min(-1 + s psi, beta_0), fitted globally by least
//! squares (docs/physics.md §4).

use crate::error::{Error, Result};

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
    let b: Vec<f64> = order.iter().map(|&i| beta[i]).collect();
    let w: Vec<f64> = order.iter().map(|&i| weight[i]).collect();
    Ok(hinge_sorted(&x, &b, &w))
}

/// [`fit_hinge`] on points that are valid (as it checks) and sorted by psi, at least 3 of them.
/// The bootstrap calls it directly: a resample of presorted points is presorted.
pub(super) fn hinge_sorted(x: &[f64], beta: &[f64], w: &[f64]) -> HingeFit {
    let n = x.len();
    let y: Vec<f64> = beta.iter().map(|b| b + 1.0).collect();
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
    // Candidates (sse, s, c, shape); s = NaN when the slope is not determined. The first is
    // all points on the plateau.
    let mut best = (
        syy - sy[n] * sy[n] / sw[n],
        f64::NAN,
        sy[n] / sw[n],
        HingeShape::NoSliding,
    );
    let mut offer = |sse: f64, s: f64, c: f64, shape: HingeShape| {
        if sse < best.0 {
            best = (sse, s, c, shape);
        }
    };
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
    let (_, s, c, shape) = best;
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
        let r = beta[i] - fit.beta_at(x[i]);
        fit.sse += w[i] * r * r;
        let on_line = match shape {
            HingeShape::NoRolling => true,
            HingeShape::NoSliding => false,
            HingeShape::Both => x[i] < kink,
        };
        if on_line {
            fit.n_sliding += 1;
            fit.info_slope += w[i] * x[i] * x[i];
            fit.sse_sliding += w[i] * r * r;
        } else {
            fit.n_rolling += 1;
            fit.info_beta0 += w[i];
            fit.sse_rolling += w[i] * r * r;
        }
    }
    fit
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};
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
}
