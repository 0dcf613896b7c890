//! Where the branch and bound proposes local polishes ([`super::Bnb`]): the local minima of its
//! grid, at the scale of the cells they belong to, in the cells that could still beat the best.

use super::{Bnb, Cell, DEPTH, Landscape, Mix};
use std::collections::HashSet;
use std::hash::BuildHasherDefault;

/// A point proposed for a local polish: a node that is a local minimum of the grid at the scale
/// of the cell it belongs to, with its neighbours' coordinates as a bracket.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    pub t: [f64; 2],
    pub rows: [usize; 2],
    pub chi2: f64,
    pub bracket_lo: [f64; 2],
    pub bracket_hi: [f64; 2],
    /// The lower bound of the cell it came from: a polish from here cannot beat this.
    pub lb: f64,
}

impl<L: Landscape> Bnb<L> {
    /// Local minima of the starting grid (a node not above any of its 8 neighbours, ties broken
    /// by position) that could still lead below `upper - tau` (a cell touching them has a bound
    /// below it), lowest first.
    pub fn initial_minima(&mut self, upper: f64, tau: f64) -> Vec<Candidate> {
        let act = [self.axes[0].active, self.axes[1].active];
        let n = [
            if act[0] { self.axes[0].n0 } else { 0 },
            if act[1] { self.axes[1].n0 } else { 0 },
        ];
        let step = [1u64 << DEPTH, 1u64 << DEPTH];
        let mut out = Vec::new();
        for i in 0..=n[0] {
            for j in 0..=n[1] {
                let p = [i * step[0] * act[0] as u64, j * step[1] * act[1] as u64];
                let (v, r) = self.node_at(p);
                if !v.is_finite() {
                    continue;
                }
                let mut is_min = true;
                let mut touching_lb = f64::INFINITY;
                for di in -1i64..=1 {
                    for dj in -1i64..=1 {
                        let (ii, jj) = (i as i64 + di, j as i64 + dj);
                        if (di, dj) == (0, 0)
                            || ii < 0
                            || jj < 0
                            || ii > n[0] as i64
                            || jj > n[1] as i64
                        {
                            continue;
                        }
                        let q = [
                            ii as u64 * step[0] * act[0] as u64,
                            jj as u64 * step[1] * act[1] as u64,
                        ];
                        let (w, _) = self.node_at(q);
                        let lower = w < v || (w == v && (q[0], q[1]) < (p[0], p[1]));
                        if lower {
                            is_min = false;
                        }
                    }
                }
                if !is_min {
                    continue;
                }
                for c in &self.start_cells {
                    let inside = (0..2).all(|k| c.p0[k] <= p[k] && p[k] <= c.p1[k]);
                    if inside {
                        touching_lb = touching_lb.min(c.bound.lb);
                    }
                }
                if touching_lb < upper - tau || v < upper {
                    out.push(self.candidate(p, r, v, [step[0], step[1]], touching_lb));
                }
            }
        }
        out.sort_by(|a, b| a.chi2.total_cmp(&b.chi2));
        out
    }

    fn candidate(&self, p: [u64; 2], r: [usize; 2], v: f64, w: [u64; 2], lb: f64) -> Candidate {
        let mut lo = [0.0; 2];
        let mut hi = [0.0; 2];
        for k in 0..2 {
            let a = &self.axes[k];
            lo[k] = a.t_at(p[k].saturating_sub(w[k]));
            hi[k] = a.t_at((p[k] + w[k]).min(a.span()));
        }
        Candidate {
            t: self.t_of(r),
            rows: r,
            chi2: v,
            bracket_lo: lo,
            bracket_hi: hi,
            lb,
        }
    }

    /// The best node as a candidate, bracketed by its neighbours 1/1024 of a starting cell away.
    pub fn best_candidate(&mut self) -> Option<Candidate> {
        let (p, v) = self.best?;
        let r = [self.row(0, p[0]), self.row(1, p[1])];
        let w = [
            if self.axes[0].active {
                1u64 << (DEPTH - 10)
            } else {
                0
            },
            if self.axes[1].active {
                1u64 << (DEPTH - 10)
            } else {
                0
            },
        ];
        Some(self.candidate(p, r, v, w, f64::NEG_INFINITY))
    }

    /// Local minima among the nodes of the cells that may still hold a point at or below
    /// `upper`: for each such cell its lowest corner, kept when it is not above its neighbours at
    /// the cell's own scale (ties broken by position). Lowest first. With a cut
    /// ([`Bnb::set_cut`]) only the nodes in its half-plane count, as corners and as neighbours:
    /// the minima of the search restricted to it (on the cut's edge, where chi2 falls across
    /// it, a node beyond is a local minimum of the restricted search though not of the grid).
    pub fn candidates(&mut self, upper: f64) -> Vec<Candidate> {
        let cells: Vec<Cell> = self
            .done
            .iter()
            .chain(&self.fine)
            .chain(self.unresolved.iter().map(|(c, _)| c))
            .filter(|c| c.bound.lb <= upper && !c.failed)
            .copied()
            .collect();
        let mut seen: HashSet<[u64; 2], BuildHasherDefault<Mix>> = HashSet::default();
        let mut out = Vec::new();
        for c in cells {
            let corners = [c.p0, [c.p1[0], c.p0[1]], [c.p0[0], c.p1[1]], c.p1];
            let mut low = (f64::INFINITY, c.p0);
            for p in corners {
                if !self.searched(p) {
                    continue;
                }
                let (v, _) = self.node_at(p);
                if v < low.0 {
                    low = (v, p);
                }
            }
            let (v, p) = low;
            if !v.is_finite() || !seen.insert(p) {
                continue;
            }
            let w = [c.p1[0] - c.p0[0], c.p1[1] - c.p0[1]];
            let mut is_min = true;
            'nb: for k in 0..2 {
                if w[k] == 0 {
                    continue;
                }
                for s in [-1i64, 1] {
                    let q = p[k] as i64 + s * w[k] as i64;
                    if q < 0 || q as u64 > self.axes[k].span() {
                        continue;
                    }
                    let mut pq = p;
                    pq[k] = q as u64;
                    if !self.searched(pq) {
                        continue;
                    }
                    let (u, _) = self.node_at(pq);
                    if u < v || (u == v && (pq[0], pq[1]) < (p[0], p[1])) {
                        is_min = false;
                        break 'nb;
                    }
                }
            }
            if is_min {
                let (_, r) = self.node_at(p);
                out.push(self.candidate(p, r, v, w, c.bound.lb));
            }
        }
        out.sort_by(|a, b| a.chi2.total_cmp(&b.chi2));
        out
    }
}
