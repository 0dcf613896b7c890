//! The least-squares polynomials of the kinematics: one coordinate of one sphere over one phase,
//! a free quadratic or a straight line with known gravity, evaluated with its covariance at the
//! collision time (docs/physics.md §5.1, §5.3).

use super::{FitKind, Frame};
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector, Vector2};

/// A least-squares polynomial in tau = t - t_ref: value = c0 + c1 tau + c2 tau^2. With fixed
/// gravity c2 is the known -g/2 (or 0) and only c0, c1 are fitted.
#[derive(Debug, Clone, PartialEq)]
pub struct PolyFit {
    pub t_ref_s: f64,
    pub coef: [f64; 3],
    /// (X^T X)^-1 of the fitted parameters: times the noise variance it is their covariance.
    pub xtx_inv: DMatrix<f64>,
    pub rss: f64,
    pub n: usize,
}

impl PolyFit {
    fn fit(t: &[f64], y: &[f64], fixed_c2: Option<f64>) -> Result<PolyFit> {
        let n = t.len();
        let p = if fixed_c2.is_some() { 2 } else { 3 };
        let t_ref = t.iter().sum::<f64>() / n as f64;
        let x = DMatrix::from_fn(n, p, |i, j| (t[i] - t_ref).powi(j as i32));
        let c2 = fixed_c2.unwrap_or(0.0);
        let rhs = DVector::from_fn(n, |i, _| y[i] - c2 * (t[i] - t_ref).powi(2));
        let xtx = x.transpose() * &x;
        let xtx_inv = xtx.try_inverse().ok_or(Error::InvalidParameter {
            name: "frame times",
            value: t_ref,
            expected: "distinct times in each phase",
        })?;
        let beta = &xtx_inv * (x.transpose() * &rhs);
        let resid = &rhs - &x * &beta;
        let coef = [beta[0], beta[1], if p == 3 { beta[2] } else { c2 }];
        Ok(PolyFit {
            t_ref_s: t_ref,
            coef,
            xtx_inv,
            rss: resid.norm_squared(),
            n,
        })
    }

    pub fn value(&self, t_s: f64) -> f64 {
        let tau = t_s - self.t_ref_s;
        self.coef[0] + tau * (self.coef[1] + tau * self.coef[2])
    }

    pub fn slope(&self, t_s: f64) -> f64 {
        let tau = t_s - self.t_ref_s;
        self.coef[1] + 2.0 * tau * self.coef[2]
    }

    /// Variance of the slope at `t_s` per unit noise variance: J (X^T X)^-1 J^T, J = (0, 1, 2 tau).
    pub fn slope_variance_factor(&self, t_s: f64) -> f64 {
        let tau = t_s - self.t_ref_s;
        self.variance_factor([0.0, 1.0, 2.0 * tau])
    }

    /// Variance of the value at `t_s` per unit noise variance: J = (1, tau, tau^2).
    pub fn value_variance_factor(&self, t_s: f64) -> f64 {
        let tau = t_s - self.t_ref_s;
        self.variance_factor([1.0, tau, tau * tau])
    }

    fn variance_factor(&self, j: [f64; 3]) -> f64 {
        let p = self.xtx_inv.nrows();
        let mut v = 0.0;
        for a in 0..p {
            for b in 0..p {
                v += j[a] * self.xtx_inv[(a, b)] * j[b];
            }
        }
        v
    }
}

/// The four fits (x, y of sphere 1 and 2) of one phase.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseFit {
    pub fits: [PolyFit; 4],
    pub t_first_s: f64,
    pub t_last_s: f64,
}

impl PhaseFit {
    pub(super) fn new(frames: &[Frame], kind: FitKind) -> Result<PhaseFit> {
        let t: Vec<f64> = frames.iter().map(|f| f.t_s).collect();
        let coord = |k: usize| -> Vec<f64> {
            frames
                .iter()
                .map(|f| if k < 2 { f.r1_m[k] } else { f.r2_m[k - 2] })
                .collect()
        };
        let fixed = |k: usize| match kind {
            FitKind::Free => None,
            FitKind::FixedGravity { g_m_s2 } => Some(if k % 2 == 1 { -0.5 * g_m_s2 } else { 0.0 }),
        };
        let fit = |k: usize| PolyFit::fit(&t, &coord(k), fixed(k));
        Ok(PhaseFit {
            fits: [fit(0)?, fit(1)?, fit(2)?, fit(3)?],
            t_first_s: t.iter().cloned().fold(f64::INFINITY, f64::min),
            t_last_s: t.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
        })
    }

    pub(super) fn position(&self, sphere: usize, t_s: f64) -> Vector2<f64> {
        Vector2::new(
            self.fits[2 * sphere].value(t_s),
            self.fits[2 * sphere + 1].value(t_s),
        )
    }

    pub(super) fn velocity(&self, sphere: usize, t_s: f64) -> Vector2<f64> {
        Vector2::new(
            self.fits[2 * sphere].slope(t_s),
            self.fits[2 * sphere + 1].slope(t_s),
        )
    }

    pub(super) fn velocity_var_factor(&self, sphere: usize, t_s: f64) -> Vector2<f64> {
        Vector2::new(
            self.fits[2 * sphere].slope_variance_factor(t_s),
            self.fits[2 * sphere + 1].slope_variance_factor(t_s),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::eq8_velocity_error_m_s;

    #[test]
    fn slope_variance_at_the_window_end_exceeds_eq8() {
        // docs/physics.md §5: a quadratic's slope half a frame past the end of a 10-frame window has
        // sd 0.4489 sigma/dt (normal equations solved by hand, independently), not Eq. (8)'s
        // sigma/(dt sqrt 10) = 0.3162 sigma/dt; at the last frame itself it is 0.4069.
        let t: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let y = vec![0.0; 10];
        let f = PolyFit::fit(&t, &y, None).unwrap();
        let end = f.slope_variance_factor(9.5).sqrt();
        assert!((end - 0.4489043901713944).abs() < 1e-12, "{end}");
        assert!((f.slope_variance_factor(9.0).sqrt() - 0.4068541544955674).abs() < 1e-12);
        assert!((eq8_velocity_error_m_s(1.0, 1.0, 1.0, 10.0) - 0.316227766).abs() < 1e-9);
    }
}
