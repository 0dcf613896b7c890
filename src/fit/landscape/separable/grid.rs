//! The chi2 of a whole grid of nodes (rows of e_vm x rows of e_pm) in one pass over the points,
//! for the search's starting grid (hundreds of nodes, each alone a pass whose single running
//! sum waits on its previous addition at every point).
//!
//! The same numbers as [`super::Separable`]'s node by node, to the last bit: each node's terms
//! are w (c(f, g) - e)^2 formed in the same order of operations (no fused multiply-add: Rust
//! never fuses on its own, and `wide` lanes are IEEE operations lane by lane), added into its
//! own running sum in point order within each chunk of [`sums::CHUNK`] (one range for small
//! data), and the chunks' sums added in chunk order, as [`sums::sum`] does. What changes is
//! only which node's addition waits for which: four nodes (one per lane) advance together, and
//! a block of points' e_pm values is first transposed so that a point's four nodes are one
//! load.

use super::super::super::sums;
use rayon::prelude::*;
use wide::f64x4;

/// Points per transposed block: BLOCK x (e_pm rows) values stay in the first-level cache for
/// the grid's size (17 rows: 17 KB).
const BLOCK: usize = 128;

/// chi2 at every node (a, b) of `f` x `g` (row-major, `g` fastest): sum_i w_i (c(f_a,i,
/// g_b,i) - e_i)^2 with c = min (`min_rule`) or the product.
pub(super) fn nodes(f: &[&[f64]], g: &[&[f64]], e: &[f64], w: &[f64], min_rule: bool) -> Vec<f64> {
    let n = e.len();
    let ranges: Vec<std::ops::Range<usize>> = if sums::is_large(n) {
        (0..n.div_ceil(sums::CHUNK))
            .map(|c| c * sums::CHUNK..((c + 1) * sums::CHUNK).min(n))
            .collect()
    } else {
        vec![0..n]
    };
    let part = |r: std::ops::Range<usize>| {
        if min_rule {
            part_as::<true>(f, g, e, w, r)
        } else {
            part_as::<false>(f, g, e, w, r)
        }
    };
    let parts: Vec<Vec<f64>> = if sums::is_large(n) {
        ranges
            .into_par_iter()
            .map(|r| crate::cpu::fast(|| part(r)))
            .collect()
    } else {
        ranges.into_iter().map(part).collect()
    };
    let mut total = vec![0.0; f.len() * g.len()];
    for p in parts {
        for (t, v) in total.iter_mut().zip(p) {
            *t += v;
        }
    }
    total
}

/// The nodes' sums over the points `r`, each in point order.
#[inline(always)]
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
    let mut acc = vec![f64x4::ZERO; f.len() * groups];
    let mut block = vec![f64x4::ZERO; BLOCK * groups];
    let mut start = r.start;
    while start < r.end {
        let end = (start + BLOCK).min(r.end);
        let m = end - start;
        for q in 0..groups {
            let rows = [0, 1, 2, 3].map(|l| &lane_row(4 * q + l)[start..end]);
            for j in 0..m {
                block[j * groups + q] = f64x4::new(rows.map(|row| row[j]));
            }
        }
        let (e, w) = (&e[start..end], &w[start..end]);
        for (a, fa) in f.iter().enumerate() {
            let fa = &fa[start..end];
            let acc = &mut acc[a * groups..(a + 1) * groups];
            for j in 0..m {
                let (fj, ej, wj) = (f64x4::splat(fa[j]), f64x4::splat(e[j]), f64x4::splat(w[j]));
                for (s, gq) in acc.iter_mut().zip(&block[j * groups..(j + 1) * groups]) {
                    let c = if MIN { fj.min(*gq) } else { fj * *gq };
                    let d = c - ej;
                    *s += wj * d * d;
                }
            }
        }
        start = end;
    }
    let mut out = Vec::with_capacity(f.len() * g.len());
    for a in 0..f.len() {
        for b in 0..g.len() {
            out.push(acc[a * groups + b / 4].to_array()[b % 4]);
        }
    }
    out
}
