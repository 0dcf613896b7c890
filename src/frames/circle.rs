//! Circle fits to edge points (docs/physics.md §8): algebraic starts (Kasa, Taubin), geometric
//! refinement (Levenberg-Marquardt on the point-to-circle distances, free or fixed radius), and
//! a robust wrapper that trims outliers by the median absolute deviation.
//!
//! Coordinates are whatever the caller uses (pixels here); nothing assumes an orientation.

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

/// Result of a geometric fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometric {
    pub circle: Circle,
    /// Root mean square of the distances, same unit as the points.
    pub rms: f64,
    /// Standard errors of cx, cy from the Gauss-Newton covariance, rms^2 (J^T J)^-1 (edge errors
    /// taken as independent; they are not quite, so this is a lower bound).
    pub centre_err: [f64; 2],
    pub iterations: usize,
}

/// Geometric circle fit: minimises sum (|p_i - c| - r)^2 by Levenberg-Marquardt from `start`
/// (Chernov 2010, Ch. 4). With `fixed_r` only the centre is fitted (a known diameter: short arcs
/// then still fix the centre). Needs 3 points (2 with a fixed radius) not all on a line through
/// the centre. Stops when a step moves the circle by less than 1e-10 of its radius or lowers
/// the sum of squares by less than 1e-13 of itself (rounding), or when no damping gives a
/// downhill step (a minimum to rounding); at most 100 iterations, else `NotConverged`.
pub fn fit_geometric(
    pts: &[[f64; 2]],
    start: Circle,
    fixed_r: Option<f64>,
) -> Result<Geometric, FitError> {
    let np = if fixed_r.is_some() { 2 } else { 3 };
    if pts.len() < np {
        return Err(FitError::TooFewPoints {
            got: pts.len(),
            need: np,
        });
    }
    let mut c = start;
    if let Some(r) = fixed_r {
        c.r = r;
    }
    if !c.is_finite() {
        return Err(FitError::Degenerate);
    }
    let mut ne = normal_equations(pts, &c);
    let mut lambda = 1e-3;
    for it in 0..100 {
        let (f, jtj, jtr) = ne;
        let mut accepted = false;
        for _ in 0..20 {
            let mut m = jtj;
            for (a, row) in m.iter_mut().enumerate().take(np) {
                row[a] *= 1.0 + lambda;
            }
            let Some(step) = solve(&m, &jtr, np) else {
                lambda *= 10.0;
                continue;
            };
            let trial = Circle {
                cx: c.cx - step[0],
                cy: c.cy - step[1],
                r: if np == 3 { c.r - step[2] } else { c.r },
            };
            // The trial's cost comes with its normal equations, which the next iteration
            // needs if the step is taken.
            let nt = normal_equations(pts, &trial);
            let ft = nt.0;
            if trial.is_finite() && ft.is_finite() && ft <= f {
                let moved = step[0].hypot(step[1]).max(step[2].abs());
                let gain = f - ft;
                c = trial;
                ne = nt;
                lambda = (lambda * 0.1).max(1e-12);
                accepted = true;
                if moved <= 1e-10 * c.r.max(1.0) || gain <= 1e-13 * ft {
                    return finish(pts.len(), c, ft, &jtj, np, it + 1);
                }
                break;
            }
            lambda *= 10.0;
        }
        if !accepted {
            // No downhill step at any damping: a minimum to rounding.
            return finish(pts.len(), c, f, &jtj, np, it + 1);
        }
    }
    Err(FitError::NotConverged)
}

/// At circle `c`: the sum of squared distances of `pts`, and the normal equations J^T J and
/// J^T res of the distances in (cx, cy, r) (all three; a fixed-radius fit uses the leading
/// 2 x 2 block). One pass, one square root per point. Points at the centre have no gradient
/// and are left out of the normal equations.
fn normal_equations(pts: &[[f64; 2]], c: &Circle) -> (f64, [[f64; 3]; 3], [f64; 3]) {
    let mut f = 0.0;
    let (mut sxx, mut sxy, mut syy, mut sx, mut sy, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut rx, mut ry, mut rr) = (0.0, 0.0, 0.0);
    for &p in pts {
        let (dx, dy) = (p[0] - c.cx, p[1] - c.cy);
        let d = (dx * dx + dy * dy).sqrt();
        let res = d - c.r;
        f += res * res;
        if d == 0.0 {
            continue;
        }
        // One division per point, not two.
        let inv = 1.0 / d;
        let (jx, jy) = (-dx * inv, -dy * inv);
        rx += jx * res;
        ry += jy * res;
        rr += -res;
        sxx += jx * jx;
        sxy += jx * jy;
        syy += jy * jy;
        sx += -jx;
        sy += -jy;
        n += 1.0;
    }
    (
        f,
        [[sxx, sxy, sx], [sxy, syy, sy], [sx, sy, n]],
        [rx, ry, rr],
    )
}

fn finish(
    n: usize,
    c: Circle,
    ss: f64,
    jtj: &[[f64; 3]; 3],
    np: usize,
    iterations: usize,
) -> Result<Geometric, FitError> {
    let rms = (ss / n as f64).sqrt();
    let dof = n.saturating_sub(np).max(1) as f64;
    let s2 = ss / dof;
    let mut centre_err = [f64::NAN; 2];
    for (k, e) in centre_err.iter_mut().enumerate() {
        let mut unit = [0.0; 3];
        unit[k] = 1.0;
        if let Some(col) = solve(jtj, &unit, np) {
            *e = (col[k] * s2).max(0.0).sqrt();
        }
    }
    if !rms.is_finite() || !c.is_finite() {
        return Err(FitError::NotConverged);
    }
    Ok(Geometric {
        circle: c,
        rms,
        centre_err,
        iterations,
    })
}

/// Solves the leading np x np block of m x = b by Gaussian elimination with partial pivoting.
fn solve(m: &[[f64; 3]; 3], b: &[f64; 3], np: usize) -> Option<[f64; 3]> {
    let mut a = *m;
    let mut x = *b;
    for col in 0..np {
        let piv = (col..np).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 || !a[piv][col].is_finite() {
            return None;
        }
        a.swap(col, piv);
        x.swap(col, piv);
        for row in col + 1..np {
            let f = a[row][col] / a[col][col];
            let pivot = a[col];
            for (k, x) in a[row].iter_mut().enumerate().take(np).skip(col) {
                *x -= f * pivot[k];
            }
            x[row] -= f * x[col];
        }
    }
    let mut out = [0.0; 3];
    for row in (0..np).rev() {
        let s: f64 = (row + 1..np).map(|k| a[row][k] * out[k]).sum();
        out[row] = (x[row] - s) / a[row][row];
    }
    out[..np].iter().all(|v| v.is_finite()).then_some(out)
}

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

    fn arc(c: Circle, from_deg: f64, to_deg: f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let t = (from_deg + (to_deg - from_deg) * i as f64 / (n - 1) as f64).to_radians();
                [c.cx + c.r * t.cos(), c.cy + c.r * t.sin()]
            })
            .collect()
    }

    const TRUE: Circle = Circle {
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

    // A known-answer case with noise where the geometric optimum is known in closed form: points
    // at alternating radii r +- a around the full circle (even count, symmetric) have their
    // least-squares circle at the true centre with radius exactly r, residual rms exactly a.
    #[test]
    fn alternating_radii_known_optimum() {
        let a = 0.3;
        let p: Vec<[f64; 2]> = (0..64)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / 64.0;
                let r = TRUE.r + if i % 2 == 0 { a } else { -a };
                [TRUE.cx + r * t.cos(), TRUE.cy + r * t.sin()]
            })
            .collect();
        let g = fit_geometric(&p, fit_taubin(&p).unwrap(), None).unwrap();
        assert!((g.circle.r - TRUE.r).abs() < 1e-9);
        assert!((g.circle.cx - TRUE.cx).abs() < 1e-9);
        assert!((g.rms - a).abs() < 1e-9);
    }

    // The sums by hand for 8 points spaced 45 degrees round a circle of radius R, evaluated at
    // the same centre and radius R + d: every residual is -d, every gradient row is
    // (-cos t, -sin t, -1). Sums of cos^2 and sin^2 over the 8 angles are 4 each, of cos,
    // sin and cos sin 0. So f = 8 d^2, J^T J = [[4, 0, 0], [0, 4, 0], [0, 0, 8]],
    // J^T res = [0, 0, 8 d]. 1e-12: rounding of sums of 8 terms of order 1.
    #[test]
    fn normal_equations_known_sums() {
        let d = 0.25;
        let p = arc(TRUE, 0.0, 315.0, 8);
        let at = Circle {
            r: TRUE.r + d,
            ..TRUE
        };
        let (f, jtj, jtr) = normal_equations(&p, &at);
        assert!((f - 8.0 * d * d).abs() < 1e-12, "{f}");
        let want = [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 8.0]];
        for a in 0..3 {
            for b in 0..3 {
                assert!((jtj[a][b] - want[a][b]).abs() < 1e-12, "{jtj:?}");
            }
        }
        assert!(jtr[0].abs() < 1e-12 && jtr[1].abs() < 1e-12, "{jtr:?}");
        assert!((jtr[2] - 8.0 * d).abs() < 1e-12, "{jtr:?}");
    }

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
