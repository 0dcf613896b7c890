//! The robust wrapper: geometric fits that drop outliers by the median absolute deviation.

use super::{FitError, Geometric, fit_geometric, fit_taubin, median};

/// Result of [`fit_robust`].
#[derive(Debug, Clone, PartialEq)]
pub struct RobustFit {
    pub fit: Geometric,
    /// Which input points the final fit used.
    pub inliers: Vec<bool>,
    pub n_used: usize,
}

/// A geometric fit that rejects outliers: Taubin start, Levenberg-Marquardt, then points whose
/// distance from the circle differs from the median by more than `k_mad` x 1.4826 MAD (a
/// Gaussian sigma estimate; never below `floor`) are dropped and the fit repeated, until the
/// inlier set stops changing (at most 10 rounds; the last fit is returned then, it is already
/// a fit to its own inliers). Rejected points may come back in later rounds. `fixed_r` fixes
/// the radius. Needs `min_points` inliers (at least 3).
pub fn fit_robust(
    pts: &[[f64; 2]],
    fixed_r: Option<f64>,
    k_mad: f64,
    floor: f64,
    min_points: usize,
) -> Result<RobustFit, FitError> {
    let need = min_points.max(3);
    if pts.len() < need {
        return Err(FitError::TooFewPoints {
            got: pts.len(),
            need,
        });
    }
    let mut inliers = vec![true; pts.len()];
    let mut used: Vec<[f64; 2]> = pts.to_vec();
    let mut start = fit_taubin(&used)?;
    let mut best = fit_geometric(&used, start, fixed_r)?;
    let mut scratch = Vec::with_capacity(pts.len());
    for _ in 0..10 {
        let c = best.circle;
        scratch.clear();
        scratch.extend(pts.iter().map(|&p| c.distance(p)));
        let med = median(&mut scratch.clone());
        let mut dev: Vec<f64> = scratch.iter().map(|d| (d - med).abs()).collect();
        let mad = median(&mut dev);
        let thr = (k_mad * 1.4826 * mad).max(floor);
        let next: Vec<bool> = scratch.iter().map(|d| (d - med).abs() <= thr).collect();
        if next == inliers {
            break;
        }
        let n_in = next.iter().filter(|&&b| b).count();
        if n_in < need {
            return Err(FitError::TooFewPoints { got: n_in, need });
        }
        inliers = next;
        used = pts
            .iter()
            .zip(&inliers)
            .filter(|(_, k)| **k)
            .map(|(p, _)| *p)
            .collect();
        start = best.circle;
        best = fit_geometric(&used, start, fixed_r)?;
    }
    let n_used = inliers.iter().filter(|&&b| b).count();
    Ok(RobustFit {
        fit: best,
        inliers,
        n_used,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::circle::tests::{TRUE, arc};

    #[test]
    fn robust_fit_drops_outliers() {
        let mut p = arc(TRUE, 0.0, 360.0, 90);
        // Markers and shading put edge points inside the disc: 20% outliers 5-15 px inside.
        for (i, q) in p.iter_mut().enumerate().filter(|(i, _)| i % 5 == 0) {
            let t = (q[1] - TRUE.cy).atan2(q[0] - TRUE.cx);
            let depth = 5.0 + (i % 11) as f64;
            q[0] -= depth * t.cos();
            q[1] -= depth * t.sin();
        }
        let rf = fit_robust(&p, None, 3.0, 0.05, 6).unwrap();
        // The clean points are exact, so after trimming the fit is exact to rounding.
        assert!((rf.fit.circle.cx - TRUE.cx).abs() < 1e-9, "{rf:?}");
        assert!((rf.fit.circle.r - TRUE.r).abs() < 1e-9);
        assert_eq!(rf.n_used, 72);
    }
}
