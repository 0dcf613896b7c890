//! Circle fits to edge points (docs/physics.md §8): algebraic starts (Kasa, Taubin), geometric
//! refinement (Levenberg-Marquardt on the point-to-circle distances, free or fixed radius), and
//! a robust wrapper that trims outliers by the median absolute deviation.
//!
//! Coordinates are whatever the caller uses (pixels here); nothing assumes an orientation.

mod geometric;
mod robust;

pub use geometric::{Geometric, fit_geometric};
pub use robust::{RobustFit, fit_robust};

/// A circle: centre (cx, cy) and radius r.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    pub cx: f64,
    pub cy: f64,
    pub r: f64,
}

impl Circle {
    /// Signed distance of a point from the circle (positive outside).
    #[inline]
    pub fn distance(&self, p: [f64; 2]) -> f64 {
        // sqrt rather than hypot (3x faster): pixel coordinates are far from overflow.
        let (dx, dy) = (p[0] - self.cx, p[1] - self.cy);
        (dx * dx + dy * dy).sqrt() - self.r
    }

    fn is_finite(&self) -> bool {
        self.cx.is_finite() && self.cy.is_finite() && self.r.is_finite() && self.r > 0.0
    }
}

/// Why a circle fit failed.
#[derive(Debug, Clone, PartialEq)]
pub enum FitError {
    /// Fewer points than the fit needs.
    TooFewPoints { got: usize, need: usize },
    /// The points are (nearly) collinear or coincident: no finite circle.
    Degenerate,
    /// The iteration hit its cap or produced a non-finite value.
    NotConverged,
}

impl std::fmt::Display for FitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FitError::TooFewPoints { got, need } => {
                write!(f, "{got} edge points, a circle fit needs {need}")
            }
            FitError::Degenerate => write!(f, "edge points are collinear or coincident"),
            FitError::NotConverged => write!(f, "circle fit did not converge"),
        }
    }
}

fn mean(pts: &[[f64; 2]]) -> [f64; 2] {
    let n = pts.len() as f64;
    let (sx, sy) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p[0], b + p[1]));
    [sx / n, sy / n]
}

/// Kasa's algebraic fit: minimises sum (x^2 + y^2 + D x + E y + F)^2, a linear least-squares
/// problem (Kasa 1976, IEEE Trans. Instrum. Meas. 25, 8). Needs 3 non-collinear points; biased
/// towards small radii on short arcs, so it only serves as a start.
pub fn fit_kasa(pts: &[[f64; 2]]) -> Result<Circle, FitError> {
    if pts.len() < 3 {
        return Err(FitError::TooFewPoints {
            got: pts.len(),
            need: 3,
        });
    }
    let m = mean(pts);
    let (mut suu, mut suv, mut svv, mut suuu, mut svvv, mut suvv, mut svuu) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for p in pts {
        let (u, v) = (p[0] - m[0], p[1] - m[1]);
        suu += u * u;
        suv += u * v;
        svv += v * v;
        suuu += u * u * u;
        svvv += v * v * v;
        suvv += u * v * v;
        svuu += v * u * u;
    }
    let det = suu * svv - suv * suv;
    if det.abs() <= 1e-12 * (suu * svv).max(f64::MIN_POSITIVE) || !det.is_finite() {
        return Err(FitError::Degenerate);
    }
    let bu = 0.5 * (suuu + suvv);
    let bv = 0.5 * (svvv + svuu);
    let a = (bu * svv - bv * suv) / det;
    let b = (bv * suu - bu * suv) / det;
    let n = pts.len() as f64;
    let c = Circle {
        cx: a + m[0],
        cy: b + m[1],
        r: (a * a + b * b + (suu + svv) / n).sqrt(),
    };
    if c.is_finite() {
        Ok(c)
    } else {
        Err(FitError::Degenerate)
    }
}

/// Taubin's algebraic fit (Taubin 1991, IEEE PAMI 13, 1115), solved by Newton's method on the
/// characteristic polynomial as in Chernov, *Circular and Linear Regression* (2010), Sec. 5.10.
/// Nearly unbiased even on short arcs; the standard start for a geometric fit. Needs 3
/// non-collinear points.
pub fn fit_taubin(pts: &[[f64; 2]]) -> Result<Circle, FitError> {
    if pts.len() < 3 {
        return Err(FitError::TooFewPoints {
            got: pts.len(),
            need: 3,
        });
    }
    let m = mean(pts);
    let n = pts.len() as f64;
    let (mut mxx, mut myy, mut mxy, mut mxz, mut myz, mut mzz) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for p in pts {
        let (x, y) = (p[0] - m[0], p[1] - m[1]);
        let z = x * x + y * y;
        mxx += x * x;
        myy += y * y;
        mxy += x * y;
        mxz += x * z;
        myz += y * z;
        mzz += z * z;
    }
    let (mxx, myy, mxy, mxz, myz, mzz) = (mxx / n, myy / n, mxy / n, mxz / n, myz / n, mzz / n);
    let mz = mxx + myy;
    let cov_xy = mxx * myy - mxy * mxy;
    let var_z = mzz - mz * mz;
    let a3 = 4.0 * mz;
    let a2 = -3.0 * mz * mz - mzz;
    let a1 = var_z * mz + 4.0 * cov_xy * mz - mxz * mxz - myz * myz;
    let a0 = mxz * (mxz * myy - myz * mxy) + myz * (myz * mxx - mxz * mxy) - var_z * cov_xy;
    let (mut x, mut y) = (0.0f64, a0);
    // Newton from x = 0 descends monotonically to the smallest root (Chernov); 100 steps is far
    // more than the few it takes.
    for _ in 0..100 {
        let dy = a1 + x * (2.0 * a2 + 3.0 * a3 * x);
        let x_new = x - y / dy;
        if x_new == x || !x_new.is_finite() {
            break;
        }
        let y_new = a0 + x_new * (a1 + x_new * (a2 + x_new * a3));
        if y_new.abs() >= y.abs() {
            break;
        }
        x = x_new;
        y = y_new;
    }
    let det = x * x - x * mz + cov_xy;
    if det.abs() <= 1e-14 * mz * mz || !det.is_finite() {
        return Err(FitError::Degenerate);
    }
    let xc = (mxz * (myy - x) - myz * mxy) / det / 2.0;
    let yc = (myz * (mxx - x) - mxz * mxy) / det / 2.0;
    let c = Circle {
        cx: xc + m[0],
        cy: yc + m[1],
        r: (xc * xc + yc * yc + mz).sqrt(),
    };
    if c.is_finite() {
        Ok(c)
    } else {
        Err(FitError::Degenerate)
    }
}

/// Median of a slice (reorders it). NaN-free input assumed; an empty slice gives NaN.
pub(crate) fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    let m = *m;
    if v.len() % 2 == 1 {
        m
    } else {
        let lo = v[..mid].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lo + m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn arc(c: Circle, from_deg: f64, to_deg: f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let t = (from_deg + (to_deg - from_deg) * i as f64 / (n - 1) as f64).to_radians();
                [c.cx + c.r * t.cos(), c.cy + c.r * t.sin()]
            })
            .collect()
    }

    pub(super) const TRUE: Circle = Circle {
        cx: 103.25,
        cy: -47.5,
        r: 38.125,
    };

    // Exact points: every method must return the circle to rounding. 1e-9 px on a 100 px scale
    // leaves room for the conditioning of a 60-degree arc (about 1e3) times f64 rounding.
    #[test]
    fn exact_points_full_and_short_arcs() {
        for (from, to) in [(0.0, 360.0), (10.0, 70.0), (-30.0, 200.0)] {
            let p = arc(TRUE, from, to, 25);
            for c in [fit_kasa(&p).unwrap(), fit_taubin(&p).unwrap()] {
                assert!((c.cx - TRUE.cx).abs() < 1e-9, "{c:?} on {from}..{to}");
                assert!((c.cy - TRUE.cy).abs() < 1e-9);
                assert!((c.r - TRUE.r).abs() < 1e-9);
            }
            let start = Circle {
                cx: TRUE.cx + 3.0,
                cy: TRUE.cy - 2.0,
                r: 30.0,
            };
            let g = fit_geometric(&p, start, None).unwrap();
            assert!((g.circle.cx - TRUE.cx).abs() < 1e-9, "{g:?}");
            assert!((g.circle.r - TRUE.r).abs() < 1e-9);
            assert!(g.rms < 1e-9);
            let g = fit_geometric(&p, start, Some(TRUE.r)).unwrap();
            assert!((g.circle.cy - TRUE.cy).abs() < 1e-9, "{g:?}");
        }
    }

    #[test]
    fn degenerate_inputs_are_errors() {
        let line: Vec<[f64; 2]> = (0..10).map(|i| [i as f64, 2.0 * i as f64]).collect();
        assert!(fit_kasa(&line).is_err());
        assert!(fit_taubin(&line).is_err());
        assert!(fit_taubin(&[[0.0, 0.0], [1.0, 1.0]]).is_err());
        let same = vec![[1.0, 1.0]; 8];
        assert!(fit_taubin(&same).is_err());
        assert!(fit_robust(&same, None, 3.0, 0.05, 6).is_err());
    }

    #[test]
    fn median_even_and_odd() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }
}
