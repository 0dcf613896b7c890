//! The chi2 of many nodes in one pass over the points: a whole grid (rows of e_vm x rows of
//! e_pm, the search's starting grid: hundreds of nodes) or a list (a split's new corners), where
//! each node alone is a pass whose single running sum waits on its previous addition at every
//! point.
//!
//! The same numbers as [`super::Separable`]'s node by node, to the last bit: each node's terms
//! are w (c(f, g) - e)^2 formed in the same order of operations (no fused multiply-add: Rust
//! never fuses on its own, and the lanes are IEEE operations lane by lane), added into its
//! own running sum in point order within each chunk of [`sums::CHUNK`] (one range for small
//! data), and the chunks' sums added in chunk order, as [`sums::sum`] does. What changes is
//! only which node's addition waits for which: four nodes (one per lane) advance together (for
//! the grid, a block of points' e_pm values is first transposed so that a point's four nodes
//! are one load).

use super::super::super::sums;
use rayon::prelude::*;

/// Points per transposed block: BLOCK x (e_pm rows, rounded up to groups of four) values stay
/// in the first-level cache for the search's grid (17 rows: 128 x 20 x 8 bytes, 20 KB).
const BLOCK: usize = 128;

/// chi2 at every node (a, b) of `f` x `g` (row-major, `g` fastest): sum_i w_i (c(f_a,i,
/// g_b,i) - e_i)^2 with c = min (`min_rule`) or the product.
pub(super) fn nodes(f: &[&[f64]], g: &[&[f64]], e: &[f64], w: &[f64], min_rule: bool) -> Vec<f64> {
    let part = |r: std::ops::Range<usize>| {
        if min_rule {
            part_fast::<true>(f, g, e, w, r)
        } else {
            part_fast::<false>(f, g, e, w, r)
        }
    };
    in_chunks(e.len(), f.len() * g.len(), part)
}

/// chi2 at each node (f, g) of `pairs`, in order, as [`nodes`] sums them.
pub(super) fn list(pairs: &[(&[f64], &[f64])], e: &[f64], w: &[f64], min_rule: bool) -> Vec<f64> {
    let part = |r: std::ops::Range<usize>| {
        if min_rule {
            list_part_fast::<true>(pairs, e, w, r)
        } else {
            list_part_fast::<false>(pairs, e, w, r)
        }
    };
    in_chunks(e.len(), pairs.len(), part)
}

/// The sums `part` gives over each range of the points (one for small data, the chunks of
/// [`sums::CHUNK`] in parallel for large), added in range order as [`sums::sum`] adds them
/// (starting from +0, which leaves a single range's sum of squares as it is).
fn in_chunks(
    n: usize,
    k: usize,
    part: impl Fn(std::ops::Range<usize>) -> Vec<f64> + Sync,
) -> Vec<f64> {
    let parts: Vec<Vec<f64>> = if sums::is_large(n) {
        (0..n.div_ceil(sums::CHUNK))
            .into_par_iter()
            .map(|c| part(c * sums::CHUNK..((c + 1) * sums::CHUNK).min(n)))
            .collect()
    } else {
        vec![part(0..n)]
    };
    let mut total = vec![0.0; k];
    for p in parts {
        for (t, v) in total.iter_mut().zip(p) {
            *t += v;
        }
    }
    total
}

/// A node's term of point (a, b, e, w): w (c(a, b) - e)^2, c = min (as `f64::min`: a NaN
/// factor gives the other, as in the node by node sum) or the product; one place for both
/// sums.
#[inline(always)]
fn term<const MIN: bool>(a: f64, b: f64, e: f64, w: f64) -> f64 {
    let c = if MIN {
        if b.is_nan() || a < b { a } else { b }
    } else {
        a * b
    };
    let d = c - e;
    w * d * d
}

crate::cpu::wide_copy! {
    /// [`list_part`] through a copy compiled for AVX2 ([`crate::cpu::wide_copy`]).
    fn list_part_fast;
    /// [`list`]'s sums over the points `r`, four nodes at a time, each in point order.
    fn list_part<const MIN: bool>(
        pairs: &[(&[f64], &[f64])],
        e: &[f64],
        w: &[f64],
        r: std::ops::Range<usize>,
    ) -> Vec<f64> {
        let mut out = Vec::with_capacity(pairs.len());
        for group in pairs.chunks(4) {
            // A short last group repeats its last node (its sums dropped).
            let lane = |l: usize| group[l.min(group.len() - 1)];
            let (e, w) = (&e[r.clone()], &w[r.clone()]);
            let m = e.len();
            let w = &w[..m];
            // Every slice cut to m in place (through an array's `map` the lengths were lost, and
            // each load kept its bounds check).
            let fl = |l: usize| &lane(l).0[r.clone()][..m];
            let gl = |l: usize| &lane(l).1[r.clone()][..m];
            let (f0, f1, f2, f3) = (fl(0), fl(1), fl(2), fl(3));
            let (g0, g1, g2, g3) = (gl(0), gl(1), gl(2), gl(3));
            // Lanes as plain arrays (the `wide` type is two halves in a baseline build, and stays
            // so in the AVX2 copy): the same operations, `min` as `wide`'s (the other where one is
            // NaN, else the second unless the first is less).
            let mut s = [0.0; 4];
            for j in 0..m {
                let (ej, wj) = (e[j], w[j]);
                let fj = [f0[j], f1[j], f2[j], f3[j]];
                let gj = [g0[j], g1[j], g2[j], g3[j]];
                for l in 0..4 {
                    s[l] += term::<MIN>(fj[l], gj[l], ej, wj);
                }
            }
            out.extend_from_slice(&s[..group.len()]);
        }
        out
    }
}

crate::cpu::wide_copy! {
    /// [`part_as`] through a copy compiled for AVX2 ([`crate::cpu::wide_copy`]).
    fn part_fast;
    /// The nodes' sums over the points `r`, each in point order.
    fn part_as<const MIN: bool>(
        f: &[&[f64]],
        g: &[&[f64]],
        e: &[f64],
        w: &[f64],
        r: std::ops::Range<usize>,
    ) -> Vec<f64> {
        // The e_pm rows in groups of four lanes (the last group padded with its first row, whose
        // sums are dropped).
        let groups = g.len().div_ceil(4);
        let lane_row = |k: usize| g[k.min(g.len() - 1)];
        // Lanes as plain arrays, as in [`list_part`].
        let mut acc = vec![[0.0; 4]; f.len() * groups];
        let mut block = vec![[0.0; 4]; BLOCK * groups];
        let mut start = r.start;
        while start < r.end {
            let end = (start + BLOCK).min(r.end);
            let m = end - start;
            for q in 0..groups {
                let rows = [0, 1, 2, 3].map(|l| &lane_row(4 * q + l)[start..end]);
                for j in 0..m {
                    block[j * groups + q] = rows.map(|row| row[j]);
                }
            }
            let (e, w) = (&e[start..end], &w[start..end]);
            for (a, fa) in f.iter().enumerate() {
                let fa = &fa[start..end];
                let acc = &mut acc[a * groups..(a + 1) * groups];
                for j in 0..m {
                    let (fj, ej, wj) = (fa[j], e[j], w[j]);
                    for (s, gq) in acc.iter_mut().zip(&block[j * groups..(j + 1) * groups]) {
                        for l in 0..4 {
                            s[l] += term::<MIN>(fj, gq[l], ej, wj);
                        }
                    }
                }
            }
            start = end;
        }
        let mut out = Vec::with_capacity(f.len() * g.len());
        for a in 0..f.len() {
            for b in 0..g.len() {
                out.push(acc[a * groups + b / 4][b % 4]);
            }
        }
        out
    }
}
