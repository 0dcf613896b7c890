//! The covariance of fitted parameters from the Jacobian of the weighted residuals, with the
//! parameters the data leave undetermined marked (used by [`super::lsq`] and the fit's errors).
//!
//! **Known answer** (test below): for a straight line the covariance is the closed form of
//! ordinary least squares; a zero column and parallel columns are marked, not inverted.

use nalgebra::DMatrix;

/// The covariance (J^T J)^-1 of the parameters, with what the data leave undetermined marked.
#[derive(Debug, Clone, PartialEq)]
pub struct Covariance {
    /// NaN in the rows and columns of undetermined parameters.
    pub matrix: DMatrix<f64>,
    /// The parameter does not change the model at all here (a zero Jacobian column: a plateau).
    pub no_effect: Vec<bool>,
    /// The parameter is determined only in combination with others (collinear columns).
    pub degenerate: Vec<bool>,
}

/// (J^T J)^+ with the undetermined parameters marked. Columns are scaled to unit norm first, so
/// the rank test does not depend on units; eigenvalues below 1e-12 of the largest (columns
/// parallel to 1 - 1e-12) are a null space, and a parameter with a share above 1e-6 in it is
/// degenerate. For the others the pseudo-inverse gives their exact variance (they are estimable:
/// orthogonal to the null space). A column with a non-finite norm (an overflowing Jacobian)
/// counts as undetermined.
pub fn covariance(jac: &DMatrix<f64>) -> Covariance {
    let p = jac.ncols();
    let mut out = Covariance {
        matrix: DMatrix::from_element(p, p, f64::NAN),
        no_effect: vec![false; p],
        degenerate: vec![false; p],
    };
    let norms: Vec<f64> = (0..p).map(|j| jac.column(j).norm()).collect();
    let live: Vec<usize> = (0..p)
        .filter(|&j| norms[j].is_finite() && norms[j] > 0.0)
        .collect();
    for (j, &norm) in norms.iter().enumerate() {
        out.no_effect[j] = !(norm > 0.0);
        if norm.is_infinite() {
            out.degenerate[j] = true;
        }
    }
    if live.is_empty() {
        return out;
    }
    let m = live.len();
    let mut a = DMatrix::zeros(m, m);
    for (r, &i) in live.iter().enumerate() {
        for (c, &j) in live.iter().enumerate() {
            a[(r, c)] = jac.column(i).dot(&jac.column(j)) / (norms[i] * norms[j]);
        }
    }
    let eig = a.symmetric_eigen();
    let emax = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    let mut pinv = DMatrix::zeros(m, m);
    let mut null_share = vec![0.0; m];
    for (q, &lam) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(q);
        if lam > 1e-12 * emax {
            pinv += v * v.transpose() / lam;
        } else {
            for r in 0..m {
                null_share[r] += v[r] * v[r];
            }
        }
    }
    for (r, &i) in live.iter().enumerate() {
        out.degenerate[i] = null_share[r] > 1e-6;
    }
    for (r, &i) in live.iter().enumerate() {
        for (c, &j) in live.iter().enumerate() {
            if !out.degenerate[i] && !out.degenerate[j] {
                out.matrix[(i, j)] = pinv[(r, c)] / (norms[i] * norms[j]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covariance_of_a_line_is_the_closed_form() {
        let x: Vec<f64> = (0..10).map(|i| i as f64).collect();
        let n = x.len() as f64;
        let sx: f64 = x.iter().sum();
        let sxx: f64 = x.iter().map(|x| x * x).sum();
        let d = n * sxx - sx * sx;
        let mut jac = DMatrix::zeros(10, 2);
        for (i, &xi) in x.iter().enumerate() {
            jac[(i, 0)] = 1.0;
            jac[(i, 1)] = xi;
        }
        let c = covariance(&jac).matrix;
        assert!((c[(0, 0)] - sxx / d).abs() < 1e-14);
        assert!((c[(1, 1)] - n / d).abs() < 1e-14);
        assert!((c[(0, 1)] + sx / d).abs() < 1e-14);
        // A zero column is a parameter without effect: the other keeps its variance, 1/n.
        jac.column_mut(1).fill(0.0);
        let c = covariance(&jac);
        assert!(c.no_effect[1] && !c.degenerate[0]);
        assert!(c.matrix[(1, 1)].is_nan() && (c.matrix[(0, 0)] - 0.1).abs() < 1e-14);
        // Parallel columns: both degenerate; a third, orthogonal one stays determined with the
        // variance of its own column, 1/|x|^2.
        jac.column_mut(1).fill(2.0);
        let mut j3 = DMatrix::zeros(10, 3);
        j3.columns_mut(0, 2).copy_from(&jac);
        for i in 0..10 {
            j3[(i, 2)] = if i % 2 == 0 { 1.0 } else { -1.0 };
        }
        let c = covariance(&j3);
        assert!(c.degenerate[0] && c.degenerate[1] && !c.degenerate[2]);
        assert!(c.matrix[(0, 0)].is_nan());
        assert!(
            (c.matrix[(2, 2)] - 0.1).abs() < 1e-14,
            "{}",
            c.matrix[(2, 2)]
        );
    }
}
