//! The exact minimum of a quadratic over a small polytope, for the second-order cell bounds of
//! the global search ([`super::landscape`]).
//!
//! **Solves**: min q(x) = c + g . x + 1/2 x^T H x over P = {x : a_j . x <= b_j}, x in R^D,
//! D <= 3, with H symmetric of any inertia (convex or not).
//! **Needs**: P bounded (a box, or a box of one coordinate with the others within multiples of
//! it); at most [`MAX_CONSTRAINTS`] constraints.
//! **Method**: active-set enumeration (Nocedal & Wright, "Numerical Optimization", 2nd ed.,
//! 2006, §16.1 and §16.5). P is compact, so q attains its minimum at some x* in the relative
//! interior of a face F of P (a vertex is a face). There x* is a stationary point of q on the
//! affine hull of F, i.e. it solves the equality-constrained (KKT) system of F's active
//! constraints. If that system is singular, q is constant along a direction inside F (the
//! gradient at x* is orthogonal to it, and the curvature along it is zero), so the same value
//! is also reached on F's relative boundary, a face of lower dimension. Hence the minimum over
//! the feasible solutions of every nonsingular system of at most D active constraints is the
//! minimum of q over P: each candidate is a point of P (so not below the minimum) and x* or a
//! point of equal value is among them. Stationary points that are maxima or saddles of a face
//! are feasible points too: they cannot pull the result below the minimum.
//!
//! Rounding: a candidate is accepted when it violates a constraint by at most 1e-9 of the
//! constraint's scale (a slightly infeasible point only lowers the result, the safe side for a
//! lower bound), and the value returned is q at the best candidate minus 1e-12 times the sum of
//! the magnitudes of q's terms there (q is evaluated in a handful of operations, so its rounding
//! error is below 1e-15 of that sum).
//!
//! **Known answers** (tests below): interior, edge and vertex minima of convex quadratics on a
//! box, a concave quadratic (a vertex), a 3-D cone section against a dense sample of the
//! polytope, and an empty polytope.

/// Constraints accepted (2^6 active sets of at most 3 of them: 42 systems at D = 3).
pub const MAX_CONSTRAINTS: usize = 8;

/// Relative violation of a constraint still accepted (see the module doc).
const FEASIBILITY_TOL: f64 = 1e-9;
/// Rounding margin, relative to the magnitudes of q's terms (see the module doc).
const ROUNDING_MARGIN: f64 = 1e-12;

/// The minimum of q over P (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Minimum<const D: usize> {
    /// q at the minimiser minus the rounding margin: a lower bound of q over P.
    pub lower: f64,
    /// The minimiser.
    pub x: [f64; D],
}

/// q(x) and the sum of the magnitudes of its terms.
fn value<const D: usize>(h: &[[f64; D]; D], g: &[f64; D], c: f64, x: &[f64; D]) -> (f64, f64) {
    let (mut q, mut size) = (c, c.abs());
    for k in 0..D {
        q += g[k] * x[k];
        size += (g[k] * x[k]).abs();
        for l in 0..D {
            let t = 0.5 * h[k][l] * x[k] * x[l];
            q += t;
            size += t.abs();
        }
    }
    (q, size)
}

/// The minimum of c + g . x + 1/2 x^T H x over {x : a_j . x <= b_j} (module doc); `None` when
/// no candidate is feasible (an empty polytope), when an input is not finite, or with more than
/// [`MAX_CONSTRAINTS`] constraints or D > 3.
pub fn min_over_polytope<const D: usize>(
    h: [[f64; D]; D],
    g: [f64; D],
    c: f64,
    cons: &[([f64; D], f64)],
) -> Option<Minimum<D>> {
    let m = cons.len();
    let finite = h.iter().flatten().chain(&g).all(|v| v.is_finite())
        && c.is_finite()
        && cons
            .iter()
            .all(|(a, b)| b.is_finite() && a.iter().all(|v| v.is_finite()));
    if D > 3 || m > MAX_CONSTRAINTS || !finite {
        return None;
    }
    let mut best: Option<(f64, f64, [f64; D])> = None;
    for set in 0u32..(1 << m) {
        let k = set.count_ones() as usize;
        if k > D {
            continue;
        }
        // The KKT system [H A^T; A 0] (x, lambda) = (-g, b) of the active constraints, of
        // order D + k.
        let n = D + k;
        let mut kkt = [[0.0; 6]; 6];
        let mut rhs = [0.0; 6];
        for r in 0..D {
            kkt[r][..D].copy_from_slice(&h[r]);
            rhs[r] = -g[r];
        }
        let mut row = D;
        for (j, (a, b)) in cons.iter().enumerate() {
            if set & (1 << j) != 0 {
                for r in 0..D {
                    kkt[row][r] = a[r];
                    kkt[r][row] = a[r];
                }
                rhs[row] = *b;
                row += 1;
            }
        }
        let Some(sol) = lu_solve(&mut kkt, &mut rhs, n) else {
            continue;
        };
        let mut x = [0.0; D];
        x.copy_from_slice(&sol[..D]);
        if !x.iter().all(|v| v.is_finite()) {
            continue;
        }
        let feasible = cons.iter().all(|(a, b)| {
            let (mut ax, mut scale) = (0.0, b.abs());
            for r in 0..D {
                ax += a[r] * x[r];
                scale += (a[r] * x[r]).abs();
            }
            ax - b <= FEASIBILITY_TOL * scale + f64::MIN_POSITIVE
        });
        if !feasible {
            continue;
        }
        let (q, size) = value(&h, &g, c, &x);
        if best.is_none_or(|(bq, _, _)| q < bq) {
            best = Some((q, size, x));
        }
    }
    best.map(|(q, size, x)| Minimum {
        lower: q - ROUNDING_MARGIN * size,
        x,
    })
}

/// Solves the leading n x n block of `a` (row-major) with right-hand side `b`, by LU with
/// partial pivoting; `None` where a pivot is exactly zero (a singular system).
///
/// The operations are nalgebra's `Matrix6::lu().solve()` (nalgebra 0.34, `linalg/lu.rs`,
/// `linalg/solve.rs`) in the same order, on the system without the identity rows that padded it
/// to 6 x 6: those rows and columns only ever added zeros, so the solution is the same to the
/// last bit (a test compares the two). Written out because the padded solve, with an
/// allocation per active set, was most of the power law's cell bounds on small data.
#[allow(clippy::needless_range_loop)] // by index, as the reference algorithm reads
fn lu_solve(a: &mut [[f64; 6]; 6], b: &mut [f64; 6], n: usize) -> Option<[f64; 6]> {
    let mut perm = [(0usize, 0usize); 6];
    let mut swaps = 0;
    for i in 0..n {
        // The first row of largest magnitude in column i, at or below the diagonal.
        let mut piv = i;
        for r in i + 1..n {
            if a[r][i].abs() > a[piv][i].abs() {
                piv = r;
            }
        }
        let diag = a[piv][i];
        if diag == 0.0 {
            continue;
        }
        if piv != i {
            perm[swaps] = (i, piv);
            swaps += 1;
            a.swap(i, piv);
        }
        let inv = 1.0 / diag;
        for r in i + 1..n {
            a[r][i] *= inv;
        }
        for k in i + 1..n {
            let p = a[i][k];
            for r in i + 1..n {
                a[r][k] += -p * a[r][i];
            }
        }
    }
    for &(i, piv) in &perm[..swaps] {
        b.swap(i, piv);
    }
    for i in 0..n {
        let c = b[i];
        for r in i + 1..n {
            b[r] += -c * a[r][i];
        }
    }
    for i in (0..n).rev() {
        let diag = a[i][i];
        if diag == 0.0 {
            return None;
        }
        let c = b[i] / diag;
        b[i] = c;
        for r in 0..i {
            b[r] += -c * a[r][i];
        }
    }
    Some(*b)
}

/// Box constraints lo_k <= x_k <= hi_k, for [`min_over_polytope`].
pub fn box_constraints<const D: usize>(lo: [f64; D], hi: [f64; D]) -> Vec<([f64; D], f64)> {
    let mut out = Vec::with_capacity(2 * D);
    for k in 0..D {
        let mut a = [0.0; D];
        a[k] = 1.0;
        out.push((a, hi[k]));
        a[k] = -1.0;
        out.push((a, -lo[k]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q2(h: [[f64; 2]; 2], g: [f64; 2], c: f64, x: [f64; 2]) -> f64 {
        value(&h, &g, c, &x).0
    }

    /// `lower` is at most the exact minimum and below it by no more than the rounding margin
    /// (1e-12 of the terms' magnitudes at the minimiser) plus the rounding of q (1e-15 of them).
    fn just_below<const D: usize>(
        m: &Minimum<D>,
        h: [[f64; D]; D],
        g: [f64; D],
        c: f64,
        exact: f64,
    ) {
        let size = value(&h, &g, c, &m.x).1;
        assert!(m.lower <= exact, "{} above {exact}", m.lower);
        assert!(
            exact - m.lower <= 1.001e-12 * size,
            "{} far below {exact}",
            m.lower
        );
    }

    #[test]
    fn convex_box_minima_interior_edge_and_vertex() {
        // (x - 0.3)^2 + 2 (y + 0.1)^2 = 0.29 - 0.6 x + 0.4 y + x^2 + 2 y^2 + ... written out:
        // c = 0.09 + 0.02, g = (-0.6, 0.4), H = diag(2, 4).
        let (h, g, c) = ([[2.0, 0.0], [0.0, 4.0]], [-0.6, 0.4], 0.11);
        let cons = box_constraints([-1.0, -1.0], [1.0, 1.0]);
        let m = min_over_polytope(h, g, c, &cons).unwrap();
        assert!((m.x[0] - 0.3).abs() < 1e-15 && (m.x[1] + 0.1).abs() < 1e-15);
        just_below(&m, h, g, c, 0.0);
        // Edge: the same bowl on [0.5, 1] x [-1, 1]: x = 0.5, y = -0.1, q = 0.04.
        let m = min_over_polytope(h, g, c, &box_constraints([0.5, -1.0], [1.0, 1.0])).unwrap();
        assert!((m.x[0] - 0.5).abs() < 1e-15 && (m.x[1] + 0.1).abs() < 1e-15);
        just_below(&m, h, g, c, 0.04);
        // Vertex: (x - 2)^2 + (y - 3)^2 on the unit square: (1, 1), q = 5.
        let (h, g, c) = ([[2.0, 0.0], [0.0, 2.0]], [-4.0, -6.0], 13.0);
        let m = min_over_polytope(h, g, c, &box_constraints([0.0, 0.0], [1.0, 1.0])).unwrap();
        assert_eq!(m.x, [1.0, 1.0]);
        just_below(&m, h, g, c, 5.0);
    }

    #[test]
    fn correlated_bowl_minimum_on_an_edge() {
        // q = (x + y - 1)^2 + 0.01 (x - y)^2 on [0, 0.2] x [0, 2]: unconstrained minimum at
        // (0.5, 0.5), outside; on the edge x = 0.2, dq/dy = 2 (y - 0.8) - 0.02 (0.2 - y) = 0, i.e.
        // 2.02 y = 1.604.
        let h = [[2.02, 1.98], [1.98, 2.02]];
        let g = [-2.0, -2.0];
        let c = 1.0;
        let m = min_over_polytope(h, g, c, &box_constraints([0.0, 0.0], [0.2, 2.0])).unwrap();
        let y = 1.604 / 2.02;
        assert!(
            (m.x[0] - 0.2).abs() < 1e-15 && (m.x[1] - y).abs() < 1e-15,
            "{:?}",
            m.x
        );
        let exact = (0.2 + y - 1.0f64).powi(2) + 0.01 * (0.2 - y).powi(2);
        just_below(&m, h, g, c, exact);
    }

    #[test]
    fn concave_quadratic_takes_the_farthest_vertex() {
        let h = [[-2.0, 0.0], [0.0, -2.0]];
        let m = min_over_polytope(
            h,
            [0.0, 0.0],
            0.0,
            &box_constraints([-1.0, -1.0], [2.0, 1.0]),
        )
        .unwrap();
        assert_eq!(m.x[0], 2.0);
        assert_eq!(m.x[1].abs(), 1.0);
        just_below(&m, h, [0.0, 0.0], 0.0, -5.0);
        assert_eq!(q2(h, [0.0, 0.0], 0.0, m.x), -5.0);
    }

    #[test]
    fn one_dimension() {
        // 3 (x - 4)^2 on [0, 1]: x = 1, q = 27; on [3, 5]: x = 4, q = 0.
        let (h, g, c) = ([[6.0]], [-24.0], 48.0);
        let m = min_over_polytope(h, g, c, &box_constraints([0.0], [1.0])).unwrap();
        assert_eq!(m.x, [1.0]);
        just_below(&m, h, g, c, 27.0);
        let m = min_over_polytope(h, g, c, &box_constraints([3.0], [5.0])).unwrap();
        assert_eq!(m.x, [4.0]);
    }

    #[test]
    fn empty_polytope_and_bad_input_give_none() {
        let h = [[1.0, 0.0], [0.0, 1.0]];
        let empty = box_constraints([1.0, 0.0], [0.0, 1.0]);
        assert_eq!(min_over_polytope(h, [0.0, 0.0], 0.0, &empty), None);
        let cons = box_constraints([0.0, 0.0], [1.0, 1.0]);
        assert_eq!(min_over_polytope(h, [f64::NAN, 0.0], 0.0, &cons), None);
        assert_eq!(min_over_polytope(h, [0.0, 0.0], f64::INFINITY, &cons), None);
    }

    /// A small seeded generator (the tests must not depend on a crate's stream changing).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn sym(&mut self) -> f64 {
            2.0 * self.next() - 1.0
        }
    }

    /// The KKT system as the solver first built it: nalgebra's LU of the 6 x 6 matrix padded
    /// with identity rows, the active constraints' rows from index 3.
    #[allow(clippy::needless_range_loop)]
    fn padded_solve<const D: usize>(
        h: &[[f64; D]; D],
        g: &[f64; D],
        act: &[([f64; D], f64)],
    ) -> Option<Vec<f64>> {
        use nalgebra::{Matrix6, Vector6};
        let mut kkt = Matrix6::<f64>::identity();
        let mut rhs = Vector6::<f64>::zeros();
        for r in 0..D {
            for s in 0..D {
                kkt[(r, s)] = h[r][s];
            }
            rhs[r] = -g[r];
        }
        for (slot, (a, b)) in act.iter().enumerate() {
            let row = 3 + slot;
            kkt[(row, row)] = 0.0;
            for r in 0..D {
                kkt[(row, r)] = a[r];
                kkt[(r, row)] = a[r];
            }
            rhs[row] = *b;
        }
        let sol = kkt.lu().solve(&rhs)?;
        Some((0..D).chain(3..3 + act.len()).map(|r| sol[r]).collect())
    }

    #[allow(clippy::needless_range_loop)] // symmetric matrices read best by index
    fn solve_cases<const D: usize>(rng: &mut Lcg) -> usize {
        let mut singular = 0;
        for case in 0..2000 {
            let mut h = [[0.0; D]; D];
            for r in 0..D {
                for s in r..D {
                    // Small integers now and then: exact ties between pivots, and singular
                    // systems.
                    let v = if case % 4 == 0 {
                        (3.0 * rng.sym()).round()
                    } else {
                        4.0 * rng.sym()
                    };
                    h[r][s] = v;
                    h[s][r] = v;
                }
            }
            let g: [f64; D] = std::array::from_fn(|_| 3.0 * rng.sym());
            let k = case % (D + 1);
            let act: Vec<([f64; D], f64)> = (0..k)
                .map(|_| {
                    let a = std::array::from_fn(|_| {
                        if case % 4 == 0 {
                            (2.0 * rng.sym()).round()
                        } else {
                            rng.sym()
                        }
                    });
                    (a, rng.sym())
                })
                .collect();
            let mut kkt = [[0.0; 6]; 6];
            let mut rhs = [0.0; 6];
            for r in 0..D {
                kkt[r][..D].copy_from_slice(&h[r]);
                rhs[r] = -g[r];
            }
            for (slot, (a, b)) in act.iter().enumerate() {
                for r in 0..D {
                    kkt[D + slot][r] = a[r];
                    kkt[r][D + slot] = a[r];
                }
                rhs[D + slot] = *b;
            }
            let ours = lu_solve(&mut kkt, &mut rhs, D + k).map(|x| x[..D + k].to_vec());
            let theirs = padded_solve(&h, &g, &act);
            singular += usize::from(theirs.is_none());
            let bits = |v: &Option<Vec<f64>>| {
                v.as_ref()
                    .map(|x| x.iter().map(|y| y.to_bits()).collect::<Vec<_>>())
            };
            assert_eq!(
                bits(&ours),
                bits(&theirs),
                "D = {D}, case {case}: {ours:?} against {theirs:?}"
            );
        }
        singular
    }

    #[test]
    fn lu_solve_is_the_padded_nalgebra_solve_to_the_last_bit() {
        let mut rng = Lcg(11);
        let singular =
            solve_cases::<1>(&mut rng) + solve_cases::<2>(&mut rng) + solve_cases::<3>(&mut rng);
        // Singular systems were among them (both give None).
        assert!(singular > 0);
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // symmetric matrices read best by index
    fn cone_sections_agree_with_a_dense_sample() {
        // The power law's cell shape: A in [a_lo, a_hi], |B_k| <= A w_k. Random quadratics
        // (convex, indefinite and concave), each compared with q on a 41^3 grid over the
        // bounding box, keeping the grid points inside the polytope. The minimum is exact, so
        // q at the minimiser must not exceed any sample (up to rounding, 1e-12 relative), and
        // the sample's minimum can exceed it only by the grid's resolution (checked with the
        // gradient's size times the grid step, a first-order bound of the distance).
        let mut rng = Lcg(7);
        for case in 0..60 {
            let (a_lo, a_hi) = (0.5 + rng.next(), 2.0 + rng.next());
            let w = [0.1 + rng.next(), 0.1 + 0.5 * rng.next()];
            let mut hm = [[0.0; 3]; 3];
            for r in 0..3 {
                for s in r..3 {
                    let v = 4.0 * rng.sym();
                    hm[r][s] = v;
                    hm[s][r] = v;
                }
            }
            if case % 3 == 0 {
                // A convex one: H = M^T M.
                let mm = hm;
                for r in 0..3 {
                    for s in 0..3 {
                        hm[r][s] = (0..3).map(|t| mm[t][r] * mm[t][s]).sum();
                    }
                }
            }
            let g = [3.0 * rng.sym(), 3.0 * rng.sym(), 3.0 * rng.sym()];
            let c = rng.sym();
            let mut cons = vec![([1.0, 0.0, 0.0], a_hi), ([-1.0, 0.0, 0.0], -a_lo)];
            for (k, wk) in w.iter().enumerate() {
                let mut a = [-wk, 0.0, 0.0];
                a[1 + k] = 1.0;
                cons.push((a, 0.0));
                let mut a = [-wk, 0.0, 0.0];
                a[1 + k] = -1.0;
                cons.push((a, 0.0));
            }
            let m = min_over_polytope(hm, g, c, &cons).unwrap();
            let q = |x: [f64; 3]| value(&hm, &g, c, &x).0;
            let inside = |x: [f64; 3]| {
                cons.iter()
                    .all(|(a, b)| a[0] * x[0] + a[1] * x[1] + a[2] * x[2] <= b + 1e-12)
            };
            assert!(inside(m.x), "case {case}: {:?} outside", m.x);
            let qm = q(m.x);
            assert!(m.lower <= qm);
            let n = 40;
            let mut sample_min = f64::INFINITY;
            let (mut step, mut grad) = (0.0f64, 0.0f64);
            for i in 0..=n {
                let a = a_lo + (a_hi - a_lo) * i as f64 / n as f64;
                for j in 0..=n {
                    for k in 0..=n {
                        let x = [
                            a,
                            a * w[0] * (2.0 * j as f64 / n as f64 - 1.0),
                            a * w[1] * (2.0 * k as f64 / n as f64 - 1.0),
                        ];
                        if !inside(x) {
                            continue;
                        }
                        let v = q(x);
                        assert!(
                            qm <= v + 1e-12 * (1.0 + v.abs()),
                            "case {case}: minimum {qm} above the sample {v} at {x:?}"
                        );
                        sample_min = sample_min.min(v);
                        let gx: f64 = (0..3)
                            .map(|r| (g[r] + (0..3).map(|s| hm[r][s] * x[s]).sum::<f64>()).powi(2))
                            .sum::<f64>()
                            .sqrt();
                        grad = grad.max(gx);
                    }
                }
                step = step
                    .max((a_hi - a_lo) / n as f64)
                    .max(2.0 * a * w[0].max(w[1]) / n as f64);
            }
            // Some grid point lies within d = 2 sqrt(3) steps of the minimiser (the B grid is
            // scaled with A: one step in A moves it by at most another step); q rises from the
            // minimiser to it by at most |grad q(x*)| d + |H| d^2 / 2, with |grad q(x*)| at most
            // the sampled maximum plus |H| d (|H| <= its Frobenius norm).
            let hn = hm.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
            let d = 2.0 * 3f64.sqrt() * step;
            assert!(
                sample_min - qm <= grad * d + 1.5 * hn * d * d,
                "case {case}: sample {sample_min} far above the minimum {qm}"
            );
        }
    }
}
