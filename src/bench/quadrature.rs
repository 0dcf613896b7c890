//! The plastic model's e by numerical quadrature of its work integrals: a deliberately generic
//! second method to set against the closed form of [`crate::models::plastic::rebound_u`].
//!
//! **Solves** (docs/physics.md §3, in units of delta_y for the overlap, P_y for the force and P_y delta_y
//! for work, so that W_y = 2/5 and the impact energy is (2/5) u^2):
//! - Eq. (16): (2/5) u^2 = int_0^(1+q) p(xi) dxi with the loading law of Eq. (12): p = xi^(3/2)
//!   (Hertz) for xi <= 1, p = 1 + (3/2)(xi - 1) (perfectly plastic, slope continuous) above;
//!   solved for q = xi* - 1 by Newton's method on the quadrature (dW/dq = p(1 + q));
//! - Eq. (17): W_r = int_xi0^xi* p* ((xi - xi0)/(xi* - xi0))^(3/2) dxi, the Hertzian unloading of
//!   Eq. (14), whose width follows from the continuity of P* and a*: xi* - xi0 = p*/sqrt(xi*);
//! - e = (W_r / ((2/5) u^2))^(1/2).
//!
//! **Method**: n-point Gauss-Legendre on each integral (nodes and weights by Golub & Welsch, Math.
//! Comp. 23, 221 (1969): eigenvalues and first eigenvector components of the Jacobi matrix, by
//! nalgebra's symmetric eigensolver). The (xi - xi0)^(3/2) end points are not smooth, so the error
//! falls only algebraically with n (about n^-5); that is the knob of the work-precision chart.
//!
//! **Needs** u finite and >= 0. 1 - e comes from (W_i - W_r)/W_i and cancels as u -> 1 (where
//! 1 - e ~ (3/8) q^2): this method is a comparator for the chart, not a way to compute 1 - e there.

use crate::error::{Error, Num, Result, non_negative};
use nalgebra::{DMatrix, SymmetricEigen};

/// Cap of the Newton iteration for q: monotone Newton on a convex function, started within a
/// factor of about 1.2 of the root, converges in about 6 steps (quadratically); 200 leaves a wide
/// margin and still bounds the cost.
const NEWTON_MAX_ITERATIONS: usize = 200;

/// An n-point Gauss-Legendre rule on [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct GaussLegendre {
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
}

impl GaussLegendre {
    /// The rule with `n` >= 1 nodes (Golub-Welsch; exact for polynomials of degree 2n - 1).
    pub fn new(n: usize) -> Self {
        assert!(n >= 1, "a quadrature rule needs at least one node");
        let mut j = DMatrix::<f64>::zeros(n, n);
        for k in 1..n {
            let kf = k as f64;
            let b = kf / (4.0 * kf * kf - 1.0).sqrt();
            j[(k, k - 1)] = b;
            j[(k - 1, k)] = b;
        }
        let eig = SymmetricEigen::new(j);
        let mut pairs: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let v0 = eig.eigenvectors[(0, i)];
                // On [-1, 1] the weight is 2 v0^2; mapped to [0, 1] it halves.
                (0.5 * (eig.eigenvalues[i] + 1.0), v0 * v0)
            })
            .collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        GaussLegendre {
            nodes: pairs.iter().map(|p| p.0).collect(),
            weights: pairs.iter().map(|p| p.1).collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// int_a^b f.
    #[inline]
    pub fn integrate(&self, a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
        let w = b - a;
        let mut s = 0.0;
        for (t, wt) in self.nodes.iter().zip(&self.weights) {
            s += wt * f(a + w * t);
        }
        w * s
    }
}

/// e and 1 - e by quadrature, with the integrand evaluations spent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadratureRebound {
    pub e: f64,
    pub one_minus_e: f64,
    pub integrand_evals: u64,
}

/// The plastic work integrals by an n-point Gauss-Legendre rule.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkQuadrature {
    rule: GaussLegendre,
}

impl WorkQuadrature {
    pub fn new(nodes: usize) -> Self {
        WorkQuadrature {
            rule: GaussLegendre::new(nodes),
        }
    }

    pub fn nodes(&self) -> usize {
        self.rule.len()
    }

    /// e(u), u = V/V_Y, from Eqs. (16)-(17) by quadrature (see the module docs).
    pub fn rebound_u(&self, u: f64) -> Result<QuadratureRebound> {
        non_negative("u = V/V_Y", u)?;
        let n = self.rule.len() as u64;
        if u <= 1.0 {
            // Below yield the contact is Hertzian both ways: W_r = W_i exactly.
            return Ok(QuadratureRebound {
                e: 1.0,
                one_minus_e: 0.0,
                integrand_evals: 0,
            });
        }
        let w_in = 0.4 * u * u;
        let hertz = self.rule.integrate(0.0, 1.0, |xi| xi * xi.sqrt());
        let mut evals = n;
        let plastic = |q: f64| {
            self.rule
                .integrate(1.0, 1.0 + q, |xi| 1.0 + 1.5 * (xi - 1.0))
        };
        // F(q) = hertz + plastic(q) - w_in is convex and increasing; Newton from q0 >= root
        // (F(q0) >= hertz + q0 > 0 since (3/4) q0^2 = w_in) descends monotonically onto it, so
        // the first step that does not descend is rounding noise: stop there.
        let mut q = u * (8.0f64 / 15.0).sqrt();
        let mut converged = false;
        for _ in 0..NEWTON_MAX_ITERATIONS {
            let f = hertz + plastic(q) - w_in;
            evals += n;
            let dq = f / (1.0 + 1.5 * q);
            if !dq.is_finite() {
                return Err(Error::NoConvergence {
                    method: "quadrature Newton iteration for q",
                    detail: format!("step {} at u = {}, q = {}", Num(dq), Num(u), Num(q)),
                });
            }
            if dq <= 0.0 {
                converged = true;
                break;
            }
            q -= dq;
            if dq <= 4.0 * f64::EPSILON * q.abs() {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(Error::NoConvergence {
                method: "quadrature Newton iteration for q",
                detail: format!(
                    "{NEWTON_MAX_ITERATIONS} iterations at u = {} (q = {})",
                    Num(u),
                    Num(q)
                ),
            });
        }
        let p_star = 1.0 + 1.5 * q;
        let xi_star = 1.0 + q;
        let width = p_star / xi_star.sqrt();
        let xi0 = xi_star - width;
        let w_r = self.rule.integrate(xi0, xi_star, |xi| {
            let s = ((xi - xi0) / width).max(0.0);
            p_star * s * s.sqrt()
        });
        evals += n;
        let e2 = w_r / w_in;
        let e = e2.sqrt();
        let one_minus_e = ((w_in - w_r) / w_in) / (1.0 + e);
        if !(e.is_finite() && one_minus_e.is_finite() && q.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "u = V/V_Y",
                value: u,
                expected: "a u whose work integrals are finite",
            });
        }
        Ok(QuadratureRebound {
            e,
            one_minus_e,
            integrand_evals: evals,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::plastic::rebound_u;

    #[test]
    fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
        for n in [1, 2, 5, 16, 64] {
            let g = GaussLegendre::new(n);
            assert!((g.weights.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for k in [2 * n - 1, 2 * n - 2] {
                let got = g.integrate(0.0, 1.0, |x| x.powi(k as i32));
                let want = 1.0 / (k as f64 + 1.0);
                // A few roundings per node, summed over n nodes.
                assert!(
                    (got - want).abs() < 1e-14 * n as f64,
                    "n={n} k={k}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn quadrature_converges_to_the_closed_form() {
        // Known answer: the closed form, itself checked against mpmath (tests/plastic.rs). The
        // error in e must fall by > 10x per doubling of n at n >= 8 (algebraic, ~n^-5).
        for u in [1.5, 10.0, 1e6] {
            let want = rebound_u(u).e;
            let err = |n: usize| (WorkQuadrature::new(n).rebound_u(u).unwrap().e - want).abs();
            let (e8, e16, e64) = (err(8), err(16), err(64));
            assert!(e16 < e8 / 10.0, "u={u}: {e8:e} {e16:e}");
            assert!(e64 < 1e-9, "u={u}: {e64:e}");
        }
        assert_eq!(WorkQuadrature::new(4).rebound_u(0.5).unwrap().e, 1.0);
        assert!(WorkQuadrature::new(4).rebound_u(f64::NAN).is_err());
    }
}
