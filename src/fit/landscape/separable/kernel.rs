//! One point's terms of a pass over a cell (parent module's [`super::Separable::pass`]), in the
//! form the compiler runs fast: no branches (each case's numbers computed and the right ones
//! selected), the `min` and `product` rules as separate instances, not a flag tested per point,
//! and a run of points formed a block at a time before its terms are summed in four lanes (the
//! forming then proceeds several points at once; see [`run`] for the order of the sums).
//!
//! The arithmetic is, operation for operation, that of [`Cell::first_order_gap`]
//! and `Cell::enclosure` (cell.rs) followed by the tangent terms (docs/physics.md §7.4),
//! so every term is the same to the last bit, and every sum is that of the same terms in the
//! same lanes (a test compares them, bit for bit), and the rounding margins stated there hold
//! unchanged. A term of a point inside its interval is
//! added as a zero (its distance and gradient selected to 0): adding +-0 to a sum leaves it
//! as it was, bit for bit.

use super::cell::Cell;
use wide::f64x4;

/// A pass's per-point sums, as [`super::PassSums`] holds them (the first-order bound; phi,
/// its gradient, (generalised) Hessian and the gradient terms' magnitudes).
#[derive(Default, Clone, Copy)]
pub(super) struct Terms {
    pub first: f64,
    pub phi: f64,
    pub g: [f64; 2],
    pub g_abs: [f64; 2],
    pub h: [f64; 3],
}

/// `a` where `c`, else `b` (both already computed: a select, not a jump).
#[inline(always)]
fn sel(c: bool, a: f64, b: f64) -> f64 {
    if c { a } else { b }
}

/// a + b s + c u at x = (s, u), in `Aff::at`'s order of operations.
#[inline(always)]
fn at(p: [f64; 3], x: [f64; 2]) -> f64 {
    p[0] + p[1] * x[0] + p[2] * x[1]
}

#[inline(always)]
fn sel3(c: bool, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [sel(c, a[0], b[0]), sel(c, a[1], b[1]), sel(c, a[2], b[2])]
}

/// One point's values: its corner rows, e and weight.
#[derive(Clone, Copy)]
pub(super) struct Point {
    pub f0: f64,
    pub f1: f64,
    pub g0: f64,
    pub g1: f64,
    pub e: f64,
    pub w: f64,
}

/// Point `p`'s terms at cell coordinates x, in [`Terms`]' order (first; phi; g; g_abs; h): the
/// first-order bound's (if FIRST, else 0) and the relaxation's (if SECOND, else 0), under the
/// min rule (MIN) or the product.
#[inline(always)]
fn terms<const MIN: bool, const FIRST: bool, const SECOND: bool>(
    cell: &Cell,
    x: [f64; 2],
    p: Point,
) -> [f64; 9] {
    let mut t = [0.0; 9];
    let Point {
        f0,
        f1,
        g0,
        g1,
        e,
        w,
    } = p;
    let c = |a: f64, b: f64| if MIN { a.min(b) } else { a * b };
    if FIRST {
        let top = c(f0, g1);
        let bottom = c(f1, g0) - cell.slack;
        let d = sel(
            e < bottom,
            bottom - e,
            sel(e > top + cell.slack, e - top - cell.slack, 0.0),
        );
        t[0] = w * d * d;
    }
    if !SECOND {
        return t;
    }
    // The factors' bands (Cell::bands): half-width c + a t (1 - t), the quadratic one while q
    // is below the corner difference, else the constant one.
    let (df, dg) = (f1 - f0, g1 - g0);
    let q = cell.q_at::<MIN>(f1);
    let band = |k: usize, d: f64| {
        let (q, eps) = (q[k], cell.eps[k]);
        let quad = q <= d + eps;
        (sel(quad, eps, d + 2.0 * eps), sel(quad, 4.0 * q, 0.0))
    };
    let (bfc, bfa) = band(0, df.abs());
    let (bgc, bga) = band(1, dg.abs());
    let (rf, rg) = (bfc + 0.25 * bfa, bgc + 0.25 * bga);
    // The enclosure (Cell::enclosure): two lower planes (e >= their max - R), two upper
    // planes (e <= their min + R), R = r0 + r2[0] s (1 - s) + r2[1] u (1 - u).
    let (lo, hi, r0, r2) = if MIN {
        let side0 = f0.max(f1) + rf <= g0.min(g1) - rg;
        let side1 = g0.max(g1) + rg <= f0.min(f1) - rf;
        // Either factor may be the smaller: the lower hull of the lower ends' min at the
        // corners below, the upper ends' min above.
        let lf = |s: f64| f0 - rf + s * df;
        let lg = |u: f64| g0 - rg + u * dg;
        let m = |s: f64, u: f64| lf(s).min(lg(u));
        let (m00, m10, m01, m11) = (m(0.0, 0.0), m(1.0, 0.0), m(0.0, 1.0), m(1.0, 1.0));
        let diag = m00 + m11 <= m10 + m01;
        let lo0 = sel3(
            diag,
            [m00, m10 - m00, m11 - m10],
            [m00, m10 - m00, m01 - m00],
        );
        let lo1 = sel3(
            diag,
            [m00, m11 - m01, m01 - m00],
            [m01 + m10 - m11, m11 - m01, m11 - m10],
        );
        let (hi0, hi1) = ([f0 + rf, df, 0.0], [g0 + rg, 0.0, dg]);
        // One factor the smaller all over the cell: its band (F's first, as Cell::side).
        let one = side0 || side1;
        let l = sel3(side0, [f0, df, 0.0], [g0, 0.0, dg]);
        let r0 = sel(side0, bfc, sel(side1, bgc, 0.0));
        let r2 = [sel(side0, bfa, 0.0), sel(side0, 0.0, sel(side1, bga, 0.0))];
        (
            [sel3(one, l, lo0), sel3(one, l, lo1)],
            [sel3(one, l, hi0), sel3(one, l, hi1)],
            r0,
            r2,
        )
    } else {
        // Lf Lg = A + B s + C u + P s u with McCormick's planes for s u, by the sign of P; the
        // remainder concave, (mf + max rf) rg(u) + mg rf(s).
        let mf = f0.abs().max(f1.abs());
        let mg = g0.abs().max(g1.abs());
        let kg = mf + rf;
        let r0 = kg * bgc + mg * bfc;
        let r2 = [mg * bfa, kg * bga];
        let (a, b, c, p) = (f0 * g0, df * g0, f0 * dg, df * dg);
        let pair_a = [[a, b, c], [a - p, b + p, c + p]];
        let pair_b = [[a, b + p, c], [a, b, c + p]];
        let pos = p >= 0.0;
        let lo = [
            sel3(pos, pair_a[0], pair_b[0]),
            sel3(pos, pair_a[1], pair_b[1]),
        ];
        let hi = [
            sel3(pos, pair_b[0], pair_a[0]),
            sel3(pos, pair_b[1], pair_a[1]),
        ];
        (lo, hi, r0, r2)
    };
    // The larger lower plane and the smaller upper one (cell::pick), with their gradients.
    let (vl0, vl1) = (at(lo[0], x), at(lo[1], x));
    let kl = vl1 > vl0;
    let (lo_v, glo) = (
        sel(kl, vl1, vl0),
        [sel(kl, lo[1][1], lo[0][1]), sel(kl, lo[1][2], lo[0][2])],
    );
    let (vh0, vh1) = (at(hi[0], x), at(hi[1], x));
    let kh = vh1 < vh0;
    let (hi_v, ghi) = (
        sel(kh, vh1, vh0),
        [sel(kh, hi[1][1], hi[0][1]), sel(kh, hi[1][2], hi[0][2])],
    );
    let r = r0 + r2[0] * x[0] * (1.0 - x[0]) + r2[1] * x[1] * (1.0 - x[1]);
    let gr = [r2[0] * (1.0 - 2.0 * x[0]), r2[1] * (1.0 - 2.0 * x[1])];
    // w dist(e, [lo - R, hi + R])^2 and the gradient of the end e lies beyond (0 inside).
    let below = e < lo_v - r;
    let above = e > hi_v + r;
    let d = sel(below, lo_v - r - e, sel(above, e - hi_v - r, 0.0));
    let grad = [0, 1].map(|k| sel(below, glo[k] - gr[k], sel(above, -ghi[k] - gr[k], 0.0)));
    let wd = w * d;
    t[1] = wd * d;
    for (k, gk) in grad.iter().enumerate() {
        t[2 + k] = 2.0 * wd * gk;
        t[4 + k] = (2.0 * wd * gk).abs();
    }
    // Hessian of w d^2: 2 w (grad grad^T + d diag(2 r2)) (R's curvature is -2 r2).
    let w2 = 2.0 * w;
    t[6] = w2 * (grad[0] * grad[0] + 2.0 * d * r2[0]);
    t[7] = w2 * grad[0] * grad[1];
    t[8] = w2 * (grad[1] * grad[1] + 2.0 * d * r2[1]);
    t
}

impl Terms {
    #[inline(always)]
    fn from_array(t: [f64; 9]) -> Terms {
        Terms {
            first: t[0],
            phi: t[1],
            g: [t[2], t[3]],
            g_abs: [t[4], t[5]],
            h: [t[6], t[7], t[8]],
        }
    }
}

/// Points per block of [`run`]: the terms of a block are formed first (a loop without a
/// carried sum, which the compiler runs several points at a time) and then added into the
/// lanes. 64 points x 9 terms stay in the first-level cache (a multiple of LANES, so that
/// point j of the range is in lane j mod LANES whatever the block).
const BLOCK: usize = 64;

/// Lanes of the sums of [`run`].
pub(super) const LANES: usize = 4;

/// The terms of points `range` (consecutive) at x, summed in LANES lanes: the range's point j
/// into lane j mod LANES, each lane in point order, and the lanes then added in pairs,
/// (l0 + l1) + (l2 + l3). Four independent sums run at the speed of vector additions where one
/// sum in point order waits on each addition's latency (the pass a tenth faster on 2 Intel
/// Xeon cores, `cargo bench --bench landscape`; a sum of n terms in lanes has fewer terms in a
/// row, so the rounding margins stated for n hold).
#[inline(always)]
pub(super) fn run<const MIN: bool, const FIRST: bool, const SECOND: bool>(
    cell: &Cell,
    e: &[f64],
    w: &[f64],
    x: [f64; 2],
    range: std::ops::Range<usize>,
) -> Terms {
    let mut lanes = [[0.0; LANES]; 9];
    let mut block = [[0.0; BLOCK]; 9];
    // Without the relaxation's terms only the first is not zero: the others are neither stored
    // nor added (their sums stay zero, as adding zeros would leave them).
    let columns = if SECOND { 9 } else { 1 };
    let mut start = range.start;
    while start < range.end {
        let end = (start + BLOCK).min(range.end);
        let (f0, f1) = (&cell.f0[start..end], &cell.f1[start..end]);
        let (g0, g1) = (&cell.g0[start..end], &cell.g1[start..end]);
        let (e, w) = (&e[start..end], &w[start..end]);
        let m = f0.len();
        let (f1, g0, g1, e, w) = (&f1[..m], &g0[..m], &g1[..m], &e[..m], &w[..m]);
        for j in 0..m {
            let p = Point {
                f0: f0[j],
                f1: f1[j],
                g0: g0[j],
                g1: g1[j],
                e: e[j],
                w: w[j],
            };
            let t = terms::<MIN, FIRST, SECOND>(cell, x, p);
            for (b, tk) in block.iter_mut().zip(t).take(columns) {
                b[j] = tk;
            }
        }
        // Point j's nine terms sit in nine columns at index j; each column is added into four
        // lanes (point j into lane j mod 4), a vector addition per four points, the lanes held
        // in registers over the block. The columns are added side by side, four points of
        // each in turn: nine independent additions per step (column after column, each
        // column's additions waited on the last one's latency: a sixth of a pass), the same
        // additions in the same order in every lane.
        let quads = m / LANES * LANES;
        if SECOND {
            let mut acc = lanes.map(f64x4::new);
            for q in (0..quads).step_by(LANES) {
                for (a, b) in acc.iter_mut().zip(&block) {
                    *a += f64x4::new([b[q], b[q + 1], b[q + 2], b[q + 3]]);
                }
            }
            lanes = acc.map(|a| a.to_array());
        } else {
            let mut a = f64x4::new(lanes[0]);
            for q in (0..quads).step_by(LANES) {
                let b = &block[0];
                a += f64x4::new([b[q], b[q + 1], b[q + 2], b[q + 3]]);
            }
            lanes[0] = a.to_array();
        }
        for (acc, b) in lanes.iter_mut().zip(&block).take(columns) {
            for (l, v) in b[quads..m].iter().enumerate() {
                acc[l] += v;
            }
        }
        start = end;
    }
    Terms::from_array(lanes.map(|a| (a[0] + a[1]) + (a[2] + a[3])))
}
