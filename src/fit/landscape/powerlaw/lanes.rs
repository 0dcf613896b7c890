//! Sums over the points four at a time, for the power law's cell bounds (each bound is a few
//! passes over every point, the search's main cost on large data).
//!
//! A range of points is read in groups of four (the last group padded with zeros, whose terms
//! in every sum of [`super`] are exactly 0: their weight is 0 and every factor finite); point j
//! of the range goes to lane j mod 4, each lane is summed in point order and the lanes are
//! added as (l0 + l1) + (l2 + l3). The result depends only on the points and the range, never
//! on the machine ([`wide::f64x4`] is a pair of SSE2 registers on x86-64 and an array
//! elsewhere, IEEE operations lane by lane, no fused multiply-add). A lane adds about a
//! quarter of the terms in a row, so the rounding of such a sum is within the bound stated for
//! the sum in point order ([`super::linearized`]'s gamma).

use wide::f64x4;

/// Points per group.
pub(super) const LANES: usize = 4;

/// The part `r` of each of the point arrays `s` (a chunk of a sum over the points).
#[inline(always)]
pub(super) fn slices<'a, const K: usize>(
    r: &std::ops::Range<usize>,
    s: [&'a [f64]; K],
) -> [&'a [f64]; K] {
    s.map(|v| &v[r.clone()])
}

/// `s[b..b + 4]` as one group, zeros past the end of `s`.
#[inline(always)]
pub(super) fn load(s: &[f64], b: usize) -> f64x4 {
    if let Some(g) = s.get(b..b + LANES) {
        return f64x4::new([g[0], g[1], g[2], g[3]]);
    }
    let mut g = [0.0; LANES];
    for (x, v) in g.iter_mut().zip(&s[b.min(s.len())..]) {
        *x = *v;
    }
    f64x4::new(g)
}

/// `g` into `s[b..b + 4]`, the lanes past the end of `s` dropped.
#[inline(always)]
pub(super) fn store(s: &mut [f64], b: usize, g: f64x4) {
    let g = g.to_array();
    if let Some(d) = s.get_mut(b..b + LANES) {
        // A copy of fixed length (inlined; a variable one is a call to memmove).
        d.copy_from_slice(&g);
        return;
    }
    let from = b.min(s.len());
    for (d, v) in s[from..].iter_mut().zip(g) {
        *d = v;
    }
}

/// `f(l, i)` for each point i of `r` in order, l = (i - r.start) mod 4 its lane: full groups of
/// four, then the rest (no padding), for sums kept as four-element arrays that the compiler
/// runs as vector operations.
#[inline(always)]
pub(super) fn each(r: std::ops::Range<usize>, mut f: impl FnMut(usize, usize)) {
    let quads = r.start + r.len() / LANES * LANES;
    for b in (r.start..quads).step_by(LANES) {
        for l in 0..LANES {
            f(l, b + l);
        }
    }
    for (l, i) in (quads..r.end).enumerate() {
        f(l, i);
    }
}

/// The sum of the lanes, (l0 + l1) + (l2 + l3).
#[inline(always)]
pub(super) fn total(v: f64x4) -> f64 {
    total_of(v.to_array())
}

/// [`total`] of four lanes held as an array.
#[inline(always)]
pub(super) fn total_of(l: [f64; LANES]) -> f64 {
    (l[0] + l[1]) + (l[2] + l[3])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_are_padded_with_zeros_and_lanes_added_in_pairs() {
        let s = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        assert_eq!(load(&s, 0).to_array(), [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(load(&s, 4).to_array(), [5.0, 6.0, 0.0, 0.0]);
        assert_eq!(load(&s, 8).to_array(), [0.0; 4]);
        let mut t = [0.0; 6];
        store(&mut t, 0, f64x4::new([1.0, 2.0, 3.0, 4.0]));
        store(&mut t, 4, f64x4::new([5.0, 6.0, 7.0, 8.0]));
        assert_eq!(t, s);
        // The pairing is the stated one: 1e16 + 1 rounds to 1e16 (ties to even), so
        // (1e16 + 1) + (-1e16 + 1) is 0, where the sum in order would be 1.
        assert_eq!(total(f64x4::new([1e16, 1.0, -1e16, 1.0])), 0.0);
        assert_eq!(((1e16 + 1.0) - 1e16) + 1.0, 1.0);
        assert_eq!(total(f64x4::new([1.0, 2.0, 3.0, 4.0])), 10.0);
    }

    #[test]
    fn each_visits_every_point_once_in_order_with_its_lane() {
        for r in [0..0, 3..5, 10..21, 8..16] {
            let mut seen = Vec::new();
            each(r.clone(), |l, i| seen.push((l, i)));
            let want: Vec<(usize, usize)> = r.clone().map(|i| ((i - r.start) % 4, i)).collect();
            assert_eq!(seen, want, "{r:?}");
        }
    }
}
