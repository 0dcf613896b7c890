//! The geometric fit: Levenberg-Marquardt on the point-to-circle distances, free or fixed
//! radius, with the normal equations it solves and its centre errors.

use super::{Circle, FitError};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::circle::fit_taubin;
    use crate::frames::circle::tests::{TRUE, arc};

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
}
