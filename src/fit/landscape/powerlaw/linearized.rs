//! The power law's linearised cell bound: chi2 over a cell of exponents bounded below through the
//! model linearised about the cell's centre (argued in the parent module's doc and in
//! docs/physics.md §7.4).
//!
//! **Solves**: a lower bound of min over the cell x A's box of chi2 = sum_i w_i (y_i - A z_i)^2,
//! z_i = zc_i exp(q_i . delta), q_i = (-c1_i, c2_i), delta = (a, b) - centre in
//! [-h_a, h_a] x [-h_b, h_b]. **Needs**: the centre's zc_i, the ranges [zlo_i, zhi_i] of z_i over
//! the cell, zhi_i / zc_i = exp(M_i) with M_i = |c1_i| h_a + |c2_i| h_b, and A's box [X1, X2],
//! X1 > 0. **Method**: exp(m) = 1 + m + R(m), 0 <= R(m) <= R(M_i) on |m| <= M_i, so with the
//! variables x = (A, P, Q) = (A, A delta_a, A delta_b), A z_i lies in
//! [L_i(x), L_i(x) + A zc_i R(M_i)], L_i(x) = zc_i (A - c1_i P + c2_i Q), and x ranges over the
//! cone section K = {X1 <= A <= X2, |P| <= A h_a, |Q| <= A h_b}. Hence chi2 >= min over K of the
//! convex phi(x) = sum_i w_i dist(y_i, that interval)^2 (each distance is the positive part of
//! an affine function). For any x*, phi(x) >= phi(x*) + grad phi(x*) . (x - x*), and the linear
//! part's minimum over a polytope is at a vertex: a lower bound, exact when x* minimises phi
//! over K (first-order optimality). x* comes from Newton steps on phi's piecewise quadratic
//! (each point's active end fixed, [`qp::min_over_polytope`] over K): semismooth Newton
//! (Nocedal & Wright, "Numerical Optimization", 2nd ed., 2006, §16.5 for the subproblem); any
//! iterate gives a valid bound, the best is kept.
//!
//! The linear part is taken over the slice K' of K with A within a factor (1 +- kappa) of x*'s
//! (its rounding error and its looseness both grow with the range of A, and A's box spans
//! twelve decades); beyond the slice, chi2 >= f(A) of the first-order bound (parent module),
//! convex in A, so f's value at an end of the slice bounds the whole tail when f's slope there
//! points away from the slice. kappa grows when a tail limits the bound.
//!
//! **Rounding** (the bound must hold for chi2 as computed): every interval is widened by
//! EPS A zhi_i (the relative error of the centre's z, of R and of the model's own evaluation,
//! all below 1e-13) plus a few ulps of e (the objective forms e = 1 - y and e - e_obs); A's box
//! by EPS relative. The bound's own arithmetic is accounted for: each point's computed distance
//! is within DELTA (A zhi_i + |y_i|) of the exact one, and a sum of n terms within gamma times
//! the sum of their magnitudes (gamma about 1.5 u times the terms added in a row: n for small
//! data, a chunk of 4096 and then the chunks for large, see [`sums`]; the passes sum four
//! lanes of a quarter of those terms each and add the lanes in pairs, [`super::lanes`]: fewer
//! terms in a row, so the same gamma covers them); these are bounded by
//! Cauchy-Schwarz from sum w zhi^2 and sum w y^2, and phi is lowered by its margin and the
//! linear term by the gradient's margin times the slice's extent.
//!
//! **Known answer** (test below): on noise-free power-law data a cell holding the true exponents
//! has a bound of (nearly) 0 and one far from them a bound near chi2's minimum over it; every
//! bound lies below chi2 sampled in its cell.

use super::super::super::qp;
use super::super::super::sums;
use super::lanes::{self, load};
use wide::f64x4;

/// Relative widening of the model's range and of A's box (see the module doc).
pub(super) const EPS: f64 = 1e-12;
/// Unit roundoff.
const U: f64 = f64::EPSILON / 2.0;
/// Absolute widening for the rounding of e = 1 - y: 4 ulps of (1 + |e|), |e| <= 1 + |y|.
const ABS: f64 = 4.0 * U;
/// Error of a computed distance, relative to A zhi + |y|: about ten operations, each within U of
/// numbers at most that size; 32 U leaves a factor 3.
const DELTA: f64 = 32.0 * U;
/// Newton steps at most (each one pass over the points; 3 to 5 suffice near a minimum).
const ITERS: usize = 8;
/// phi at the iterate within this fraction of the bound: converged (1e-9, a hundredth of the
/// search's relative tolerance; Newton on a piecewise quadratic can cycle between equal
/// vertices once there).
const CONVERGED: f64 = 1e-9;
/// The slice of A first used: within a factor 1 +- KAPPA0 of the iterate's A.
const KAPPA0: f64 = 0.5;

/// One cell: the points' data and the cell's z.
pub(super) struct Cell<'a> {
    pub y: &'a [f64],
    pub w: &'a [f64],
    pub c1: &'a [f64],
    pub c2: &'a [f64],
    pub zlo: &'a [f64],
    pub zhi: &'a [f64],
    pub zc: &'a [f64],
    /// zc_i R(M_i) (an upper bound of it).
    pub rz: &'a [f64],
    /// Half-widths (h_a, h_b), rounded up.
    pub h: [f64; 2],
    /// A's box [X1, X2] before widening, X1 > 0.
    pub ends: (f64, f64),
    /// A guess of the minimising A (0: none).
    pub start: f64,
    /// sum_i w_i y_i^2.
    pub wy2: f64,
    /// Upper bounds of sum_i w_i zhi_i^2 and of sum_i w_i a_ik^2 over the largest gradient
    /// coefficients a_i of either end, ((1 + EPS) zhi_i + rz_i, zc_i c1_i, zc_i c2_i).
    pub mags: [f64; 4],
}

/// An upper bound of R(M) = exp(M) - 1 - M from M >= 0 and exp(M) (e_m): the Taylor series
/// to M^3 and a remainder M^4 / 24 exp(M) (Lagrange's form, exp rising).
pub(super) fn remainder_bound(m: f64, e_m: f64) -> f64 {
    (m * m * (0.5 + m * (1.0 / 6.0 + m * e_m * (1.0 / 24.0)))) * (1.0 + 8.0 * U)
}

/// [`remainder_bound`] of four points at once (the same operations, so the same numbers).
#[inline(always)]
pub(super) fn remainder_bound_x4(m: f64x4, e_m: f64) -> f64x4 {
    let splat = f64x4::splat;
    (m * m * (splat(0.5) + m * (splat(1.0 / 6.0) + m * splat(e_m) * splat(1.0 / 24.0))))
        * splat(1.0 + 8.0 * U)
}

/// What one pass over the points gives at x (module doc): phi, its gradient, the Hessian of the
/// active ends' quadratic, and f and f' at two amplitudes.
struct Pass {
    phi: f64,
    g: [f64; 3],
    h: [[f64; 3]; 3],
    tails: [(f64, f64); 2],
}

/// The sums per point: phi, g (3), H (6), tails (2 x 2).
const SUMS: usize = 14;

/// One point's numbers in a pass.
#[derive(Clone, Copy)]
struct Point {
    y: f64,
    w: f64,
    c1: f64,
    c2: f64,
    zc: f64,
    zhi: f64,
    zlo: f64,
    rz: f64,
}

/// One point's terms of the [`SUMS`] sums at x, with the tails at the amplitudes `at`.
#[inline(always)]
fn point_terms(p: Point, x: [f64; 3], at: [f64; 2]) -> [f64; SUMS] {
    let Point {
        y,
        w,
        c1,
        c2,
        zc,
        zhi,
        zlo,
        rz,
    } = p;
    let [a, pp, q] = x;
    // `c` ? `v` : +0 (a select).
    let sel = |c: bool, v: f64| if c { v } else { 0.0 };
    let lin = zc * (a - c1 * pp + c2 * q);
    let ezhi = EPS * zhi;
    let widen = a * ezhi + ABS * (2.0 + y.abs());
    let u = lin - widen - y;
    let v = lin + a * rz + widen - y;
    let (below, above) = (u > 0.0, v < 0.0);
    // The active end's signed distance and its gradient (A's coefficient; P's and Q's are the
    // same at both ends).
    let r = sel(below, u) + sel(above, v);
    let a0 = sel(below, zc - ezhi) + sel(above, zc + rz + ezhi);
    let act = sel(below, zc) + sel(above, zc);
    let (a1, a2) = (-act * c1, act * c2);
    let wr = w * r;
    let (wa0, wa1) = (w * a0, w * a1);
    let mut t = [0.0; SUMS];
    t[0] = wr * r;
    t[1] = wr * a0;
    t[2] = wr * a1;
    t[3] = wr * a2;
    t[4] = wa0 * a0;
    t[5] = wa0 * a1;
    t[6] = wa0 * a2;
    t[7] = wa1 * a1;
    t[8] = wa1 * a2;
    t[9] = w * a2 * a2;
    for (k, at) in at.into_iter().enumerate() {
        // max(., 0) as a select: +0 for a NaN or a -0 (as the SSE2 max it replaces).
        let pos = |v: f64| if v > 0.0 { v } else { 0.0 };
        let pu = pos(at * zlo - y);
        let pv = pos(y - at * zhi);
        t[10 + 2 * k] = w * (pu * pu + pv * pv);
        t[11 + 2 * k] = w * (zlo * pu - zhi * pv);
    }
    t
}

fn pass(c: &Cell, x: [f64; 3], at: [f64; 2]) -> Pass {
    let n = c.y.len();
    // Four points at a time ([`lanes`]: point j of a range in lane j mod 4, each lane summed in
    // point order), branch-free: the active end is chosen by selects (u > 0: the lower end is
    // above y; v < 0: the upper end is below it; u <= v, so at most one). Plain arrays of four,
    // not `wide`'s SSE2 pairs: in the AVX2 copy the compiler keeps the fourteen sums in
    // 256-bit registers (as pairs they spilled to the stack at every group of points). The
    // same operations lane by lane, so the same numbers.
    let s = sums::sum::<SUMS>(n, |points| {
        let r = points;
        let [y, w, c1, c2] = lanes::slices(&r, [c.y, c.w, c.c1, c.c2]);
        let [zc, zhi, zlo, rz] = lanes::slices(&r, [c.zc, c.zhi, c.zlo, c.rz]);
        let mut s = [[0.0; lanes::LANES]; SUMS];
        for b in (0..r.len()).step_by(lanes::LANES) {
            let ld = |v: &[f64]| load(v, b).to_array();
            let (y, w, c1, c2) = (ld(y), ld(w), ld(c1), ld(c2));
            let (zc, zhi, zlo, rz) = (ld(zc), ld(zhi), ld(zlo), ld(rz));
            for l in 0..lanes::LANES {
                let p = Point {
                    y: y[l],
                    w: w[l],
                    c1: c1[l],
                    c2: c2[l],
                    zc: zc[l],
                    zhi: zhi[l],
                    zlo: zlo[l],
                    rz: rz[l],
                };
                let t = point_terms(p, x, at);
                for (s, t) in s.iter_mut().zip(t) {
                    s[l] += t;
                }
            }
        }
        s.map(lanes::total_of)
    });
    Pass {
        phi: s[0],
        g: [2.0 * s[1], 2.0 * s[2], 2.0 * s[3]],
        h: [
            [2.0 * s[4], 2.0 * s[5], 2.0 * s[6]],
            [2.0 * s[5], 2.0 * s[7], 2.0 * s[8]],
            [2.0 * s[6], 2.0 * s[8], 2.0 * s[9]],
        ],
        tails: [(s[10], 2.0 * s[11]), (s[12], 2.0 * s[13])],
    }
}

/// The bound from one pass at x (module doc), and whether a tail limited it.
fn bound_at(
    c: &Cell,
    ps: &Pass,
    x: [f64; 3],
    slice: (f64, f64),
    ends: (f64, f64),
    gamma: f64,
) -> (f64, bool) {
    let [ha, hb] = c.h;
    let sqrt_phi = ps.phi.sqrt();
    let root = c.mags.map(f64::sqrt);
    // Tails: chi2 >= f(A) >= f(end of the slice) beyond it when f' there points outwards (none
    // when the slice reaches the box's end). f' is a sum of terms of magnitude at most
    // 2 sqrt(sum w zhi^2) sqrt(f) in all (Cauchy-Schwarz).
    let tail = |k: usize, t: f64, outward: f64| -> f64 {
        if t <= ends.0 || t >= ends.1 {
            return f64::INFINITY;
        }
        let (f, d) = ps.tails[k];
        if outward * d - gamma * 2.0 * root[0] * f.sqrt() >= 0.0 {
            f * (1.0 - gamma)
        } else {
            f64::NEG_INFINITY
        }
    };
    let t_lo = tail(0, slice.0, -1.0);
    let t_hi = tail(1, slice.1, 1.0);
    // min over the slice's vertices of g . (v - x): for a given A, P = -sign(g_P) A h_a and Q
    // likewise; linear in A, so at an end of the slice.
    let g = ps.g;
    let lin = |t: f64| g[0] * (t - x[0]) - (g[1].abs() * ha + g[2].abs() * hb) * t;
    let lin_min = lin(slice.0).min(lin(slice.1)) - g[1] * x[1] - g[2] * x[2];
    let reach = [
        (slice.1 - x[0]).abs().max((x[0] - slice.0).abs()),
        slice.1 * ha + x[1].abs(),
        slice.1 * hb + x[2].abs(),
    ];
    // Rounding (module doc), by Cauchy-Schwarz from the cell's magnitudes: the distances' errors
    // delta_i = DELTA (A zhi_i + |y_i|) have sqrt(sum w delta^2) <= sd; phi is off by at most
    // 2 sd sqrt(phi) + sd^2 + gamma phi, gradient component k by
    // sum 2 w |a_k| (2 delta + gamma |r|) <= 2 sqrt(sum w a_k^2) (2 sd + gamma sqrt(phi)).
    let sd = DELTA * (x[0].abs() * root[0] + c.wy2.sqrt());
    let mut margin = sd * (2.0 * sqrt_phi + sd) + gamma * ps.phi;
    for k in 0..3 {
        let g_err = 2.0 * root[1 + k] * (2.0 * sd + gamma * sqrt_phi) + 8.0 * U * g[k].abs();
        margin += g_err * reach[k];
    }
    let mid = ps.phi + lin_min - margin;
    let lb = mid.min(t_lo).min(t_hi);
    (lb, t_lo.min(t_hi) < mid)
}

/// The linearised bound of the module doc; stops early once the bound's relation to `target`
/// is decided or it is within `tol` of phi at the iterate (every stop is valid; a NaN target
/// decides nothing: the iterations run to their end).
pub(super) fn bound(c: &Cell, target: f64, tol: f64) -> f64 {
    let n = c.y.len();
    // Terms added in a row: every point for small data, a chunk and then the chunks for large.
    let run = if sums::is_large(n) {
        sums::CHUNK + n / sums::CHUNK + 1
    } else {
        n
    };
    let gamma = 1.5 * (run + 2) as f64 * U + 4.0 * U;
    let ends = (c.ends.0 * (1.0 - EPS), c.ends.1 * (1.0 + EPS));
    let [ha, hb] = c.h;
    if !(ha > 0.0 && hb > 0.0) {
        return f64::NEG_INFINITY;
    }
    // Newton in the scaled variables (A, P / h_a, Q / h_b), where K is |P'|, |Q'| <= A.
    let scale = [1.0, ha, hb];
    // From the guess at the centre (P = Q = 0), or from A = 0 (where the first step is the
    // least-squares fit of every point's upper end).
    // max/min, not clamp: clamp panics on a NaN end (0 x inf where the box of A meets an
    // overflowing shift), and a NaN end must reach the bound (a failed cell), not abort.
    let guess = c.start.max(ends.0).min(ends.1);
    let mut x = [if c.start > 0.0 { guess } else { 0.0 }, 0.0, 0.0];
    let first = if x[0] > 0.0 { 0 } else { 1 };
    let mut kappa = KAPPA0;
    let mut lb = f64::NEG_INFINITY;
    for it in 0..ITERS {
        // The slice around the iterate's A kept inside A's box. The tangent plane holds at any x,
        // inside K or not, but a QP step can end a rounding error outside the box (A = 3e-18
        // where the box starts at 3.7e-15), and a slice formed beyond the box's end was empty:
        // no A of the box in it and no tail beside it, so the bound was phi near A = 0 (0.356
        // on a cell whose corner has chi2 0.2434; fuzz seed 615 case 391).
        let a = x[0].max(ends.0).min(ends.1);
        let slice = (
            (a * (1.0 - kappa)).max(ends.0),
            (a * (1.0 + kappa)).min(ends.1),
        );
        let ps = pass(c, x, [slice.0, slice.1]);
        if it >= first {
            let (b, tail_limits) = bound_at(c, &ps, x, slice, ends, gamma);
            if b > lb || b.is_nan() {
                lb = b;
            }
            // Decided: excluded; or phi at a point of K below the target (no bound from phi
            // can reach it); or tight.
            if lb >= target || ps.phi < target || ps.phi - lb <= tol.max(CONVERGED * ps.phi) {
                break;
            }
            if tail_limits {
                kappa *= 4.0;
            }
        }
        // The active ends' quadratic about x, minimised over K.
        let mut hs = [[0.0; 3]; 3];
        let mut gs = [0.0; 3];
        for r in 0..3 {
            gs[r] = ps.g[r] * scale[r];
            for s in 0..3 {
                hs[r][s] = ps.h[r][s] * scale[r] * scale[s];
            }
        }
        let xs = [x[0], x[1] / ha, x[2] / hb];
        let mut cons = vec![
            ([1.0, 0.0, 0.0], ends.1 - xs[0]),
            ([-1.0, 0.0, 0.0], xs[0] - ends.0),
        ];
        for k in 1..3 {
            let mut e = [-1.0, 0.0, 0.0];
            e[k] = 1.0;
            cons.push((e, xs[0] - xs[k]));
            e[k] = -1.0;
            cons.push((e, xs[0] + xs[k]));
        }
        let Some(m) = qp::min_over_polytope(hs, gs, ps.phi, &cons) else {
            break;
        };
        let next = [xs[0] + m.x[0], (xs[1] + m.x[1]) * ha, (xs[2] + m.x[2]) * hb];
        if next == x {
            break;
        }
        x = next;
    }
    lb
}

#[cfg(test)]
mod tests {
    use super::super::PowerLaw;
    use super::*;
    use crate::contact::Material;
    use crate::fit::bnb::Landscape;
    use crate::fit::dataset::{FitData, Observation};
    use crate::fit::lsq;
    use crate::fit::models::{Evaluator, ModelKind};
    use crate::fit::objective::Objective;
    use crate::fit::powerlaw::ProfiledPowerLaw;
    use crate::models::viscoelastic::{ContactEnd, VmMethod};

    #[test]
    fn remainder_bound_is_above_exp_m_minus_1_minus_m_and_close_to_it() {
        // R(M) = expm1(M) - M (accurate to a few ulps); the bound's excess over it is at most
        // M^5 exp(M) / 24 (module doc of remainder_bound), checked with 1e-15 relative slack.
        for k in 0..=1000 {
            let m = 1.5 * k as f64 / 1000.0;
            let exact = m.exp_m1() - m;
            let b = remainder_bound(m, m.exp());
            assert!(b >= exact * (1.0 - 1e-15), "M = {m}: {b} < {exact}");
            assert!(
                b <= exact + m.powi(5) * m.exp() / 24.0 + 1e-15 * exact,
                "M = {m}: {b} far above {exact}"
            );
        }
        assert_eq!(remainder_bound(0.0, 1.0), 0.0);
    }

    #[test]
    fn remainder_bound_of_four_points_is_the_scalar_one_to_the_last_bit() {
        // The cell's scratch arrays take it four points at a time (fill_cell): the same
        // operations in the same order, so equal bits, not merely close.
        for k in 0..250 {
            let m = [0, 1, 2, 3].map(|j| 4.0 * (4 * k + j) as f64 / 999.0);
            let e_m = 4.0f64.exp() * (1.0 + 1e-15);
            let x4 = remainder_bound_x4(f64x4::new(m), e_m).to_array();
            for j in 0..4 {
                assert_eq!(
                    x4[j].to_bits(),
                    remainder_bound(m[j], e_m).to_bits(),
                    "M = {}",
                    m[j]
                );
            }
        }
    }

    /// Data of the power law with (A, a, b) = (0.04, 0.5, 0.3) on three sizes, plus a fixed
    /// zigzag of amplitude `noise` in e.
    fn data(noise: f64) -> FitData {
        let m = Material::preset("nylon").unwrap();
        let mut obs = Vec::new();
        for (j, d) in [6.35, 12.7, 25.4].into_iter().enumerate() {
            for k in 0..15usize {
                let v = 0.3 * 1.25f64.powi(k as i32);
                let e = 1.0 - 0.04 * (d / 10.0f64).powf(-0.5) * v.powf(0.3);
                let zig = noise * [1.0, -1.0, 0.5, -0.5][(k + j) % 4];
                obs.push(Observation {
                    d_mm: d,
                    d2_mm: None,
                    v_n_m_s: v,
                    e: e + zig,
                    e_err: Some(0.01),
                });
            }
        }
        FitData::new(m, obs).unwrap()
    }

    /// The bound of the cell [lo, hi] (nodes evaluated first, as the search does), the first
    /// order bound alone, and chi2's minimum over a 41 x 41 grid of the cell.
    fn cell(d: &FitData, lo: [f64; 2], hi: [f64; 2]) -> (f64, f64, f64) {
        let ev = Evaluator::new(d, ContactEnd::Overlap, VmMethod::Master);
        let obj = Objective::new(&ev, ModelKind::PowerLaw).unwrap();
        let mut l = PowerLaw::new(&obj);
        for k in 0..2 {
            l.add_row(k, lo[k]).unwrap();
            l.add_row(k, hi[k]).unwrap();
        }
        for r in [[0, 0], [1, 0], [0, 1], [1, 1]] {
            l.node(r);
        }
        // A NaN target: both iterations run to their end.
        let bound = l.bound([0, 0], [1, 1], f64::NAN).lb;
        // The first-order bound over the same cell, as the cell's bound takes it.
        let s = l.scratch.borrow();
        let ends = (obj.lower[0].exp(), obj.upper[0].exp());
        let shift = |a: f64, b: f64| l.shift(a, b);
        let (smin, smax) = [shift(lo[0], lo[1]), shift(hi[0], lo[1])]
            .into_iter()
            .chain([shift(lo[0], hi[1]), shift(hi[0], hi[1])])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        let first = l.first_order_bound(
            &s[0],
            &s[1],
            (ends.0 * smin.exp(), ends.1 * smax.exp()),
            f64::NAN,
        );
        let prof = ProfiledPowerLaw::new(&obj);
        let mut lowest = f64::INFINITY;
        for i in 0..=40 {
            for j in 0..=40 {
                let a = lo[0] + (hi[0] - lo[0]) * i as f64 / 40.0;
                let b = lo[1] + (hi[1] - lo[1]) * j as f64 / 40.0;
                let chi2 = lsq::chi2(&obj, &[prof.ln_a(&[a, b]), a, b]).unwrap();
                lowest = lowest.min(chi2);
            }
        }
        (bound, first, lowest)
    }

    #[test]
    fn linearised_bound_is_exact_at_the_truth_and_second_order_off_it() {
        // Noise-free: a cell around the true exponents has chi2 = 0 inside, so its bound is 0
        // (to rounding: 1e-18, with chi2's scale sum w y^2 ~ 1e2).
        let clean = data(0.0);
        let (b, _, lowest) = cell(&clean, [0.45, 0.25], [0.55, 0.35]);
        assert!((0.0..=1e-18).contains(&b) && lowest < 1e-20, "{b} {lowest}");
        // Off the truth, noise-free and noisy: cells of half-width h at distances 0.2 to 0.3
        // from the minimum. The linearisation's error is of second order in h (the remainder
        // R(M) ~ M^2 / 2, M ~ 2.3 h here), the first-order bound's of first order: at h = 0.05
        // the bound is within 3% of chi2's minimum over the cell (measured 0.9-2.0%) and the
        // first-order bound at least twice as far below (measured 3 to 25 times). At h = 0.2
        // the remainder's freedom per point is comparable with the data's errors and the
        // first-order bound can be the better one: the cell's bound is the larger of the two,
        // above 40% of the minimum (measured 79-89%). Every bound is below the sampled minimum.
        for d in [clean, data(0.01)] {
            for c in [[0.8, 0.3], [0.5, 0.0], [0.2, 0.55]] {
                for h in [0.05, 0.2] {
                    let (lo, hi) = ([c[0] - h, c[1] - h], [c[0] + h, c[1] + h]);
                    let (b, first, lowest) = cell(&d, lo, hi);
                    assert!(b <= lowest * (1.0 + 1e-12), "{c:?} {h}: {b} > {lowest}");
                    assert!(
                        first <= lowest * (1.0 + 1e-12),
                        "{c:?} {h}: {first} > {lowest}"
                    );
                    if h == 0.05 {
                        assert!(b >= 0.97 * lowest, "{c:?} {h}: {b} << {lowest}");
                        assert!(
                            lowest - first >= 2.0 * (lowest - b),
                            "{c:?} {h}: first order {first}, linearised {b}, chi2 {lowest}"
                        );
                    } else {
                        assert!(
                            b >= first && b >= 0.4 * lowest,
                            "{c:?}: {b} {first} {lowest}"
                        );
                    }
                }
            }
        }
    }
}
