//! The separable models' landscape (`vm`, `pm`, `min`, `product`) and its cell bound; the
//! argument is in the parent module's documentation and docs/physics.md §7.4.

use super::super::bnb::{Bound, Landscape};
use super::super::objective::Objective;
use super::super::sums;
use std::sync::Arc;

mod cell;
mod grid;
mod kernel;
use cell::{Cell, ROUND};

/// For large data (see [`sums`]) the looseness of a cell (which axis to split) is estimated
/// from every LOOSE_STRIDE-th point: it decides nothing about the cell (13, prime, so that data
/// repeating a pattern of rows are not sampled in step).
const LOOSE_STRIDE: usize = 13;

/// Passes over the points per cell bound at most: the first gives the first-order bound and the
/// relaxation at the cell's centre, each further one a projected Newton step towards the
/// relaxation's minimum (any stop is valid; see [`Separable::bound_with`]).
const MAX_PASSES: usize = 6;

/// How far the sample's prediction of the first-order bound must clear the target for a pass of
/// the first-order terms alone to be tried first (efficiency only: a pass that does not decide
/// is followed by the usual ones). On the fits of 100 000 distinct points every cell so
/// predicted was decided by that pass.
const FIRST_ONLY_MARGIN: f64 = 1.02;

/// The separable models' landscape: rows of e_vm (axis 0) and e_pm (axis 1).
pub struct Separable<'a> {
    obj: &'a Objective<'a>,
    min_rule: bool,
    active: [bool; 2],
    n: usize,
    /// Each row its own allocation (one growing array of every row was copied at each
    /// reallocation and filled before being written: 4% of a 100 000-point fit), shared with
    /// the other models fitted through the same evaluator
    /// ([`crate::fit::models::Evaluator::row`]).
    rows: [Vec<Arc<Vec<f64>>>; 2],
    t: [Vec<f64>; 2],
    e: Vec<f64>,
    w: Vec<f64>,
    slack: f64,
    /// Whether cells get the second-order bound (large data, see [`sums`]), or only the
    /// first-order one: small data's searches cost little, and their fits stay as they were to
    /// the last bit (the second-order bound cuts the 120 shipped points' cells by 2 to 8 times
    /// but moves where a polish stops, within the search's tolerance).
    second_order: bool,
    /// Large data: the sampled points (every LOOSE_STRIDE-th of each chunk of [`sums::CHUNK`])
    /// stored contiguously, their rows, e and w, and each chunk's range among them. A sampled
    /// pass then streams a thirteenth of the memory a full pass does (reading every 13th point
    /// in place touched a cache line per point and per array: a third of a full pass's time).
    sample: Sample,
    /// Passes over every point so far with the relaxation's terms, and with the first-order
    /// terms alone (what a bound cost; the tests read them).
    passes: std::cell::Cell<[u64; 2]>,
}

#[derive(Default)]
struct Sample {
    rows: [Vec<f64>; 2],
    e: Vec<f64>,
    w: Vec<f64>,
    chunks: Vec<std::ops::Range<usize>>,
    /// The points sampled, in order.
    points: Vec<usize>,
}

impl Sample {
    fn new(n: usize, e: &[f64], w: &[f64]) -> Sample {
        let mut s = Sample::default();
        for c in 0..n.div_ceil(sums::CHUNK) {
            let at = s.points.len();
            s.points
                .extend((c * sums::CHUNK..((c + 1) * sums::CHUNK).min(n)).step_by(LOOSE_STRIDE));
            s.chunks.push(at..s.points.len());
        }
        s.e = s.points.iter().map(|&i| e[i]).collect();
        s.w = s.points.iter().map(|&i| w[i]).collect();
        s
    }

    fn row(&self, k: usize, r: usize) -> &[f64] {
        let m = self.points.len();
        &self.rows[k][r * m..(r + 1) * m]
    }
}

/// Sums of one pass over the points (see [`Separable::pass`]).
#[derive(Default, Clone, Copy)]
struct PassSums {
    /// The first-order bound.
    first: f64,
    /// The relaxation phi at x, its gradient and (generalised) Hessian, and the sums of the
    /// gradient terms' magnitudes (for the rounding margin).
    phi: f64,
    g: [f64; 2],
    h: [f64; 3],
    g_abs: [f64; 2],
    /// Looseness per axis: first-order and second-order.
    loose1: [f64; 2],
    loose2: [f64; 2],
}

impl<'a> Separable<'a> {
    /// `active[k]`: whether axis k (eta, sigma_y) is a parameter; an inactive axis is a row of 1.
    pub fn new(obj: &'a Objective<'a>, min_rule: bool, active: [bool; 2]) -> Self {
        let n = obj.ev.len();
        let e: Vec<f64> = obj.ev.data.obs.iter().map(|o| o.e).collect();
        let w: Vec<f64> = obj.inv_sigma.iter().map(|s| s * s).collect();
        let sample = if sums::is_large(n) {
            Sample::new(n, &e, &w)
        } else {
            Sample::default()
        };
        Separable {
            obj,
            min_rule,
            active,
            n,
            rows: [Vec::new(), Vec::new()],
            t: [Vec::new(), Vec::new()],
            e,
            w,
            slack: 2.0 * obj.e_accuracy,
            second_order: sums::is_large(n),
            sample,
            passes: Default::default(),
        }
    }

    fn row(&self, k: usize, r: usize) -> &[f64] {
        &self.rows[k][r]
    }

    /// The second-order bound for small data too (where no fit's polish depends on where the
    /// cells end: the region beyond an interval's end, [`crate::fit::beyond`]).
    pub fn with_second_order(mut self) -> Self {
        self.second_order = true;
        self
    }

    /// The cell on the sampled points (large data).
    fn sample_cell(&self, lo: [usize; 2], hi: [usize; 2]) -> Cell<'_> {
        let full = self.cell(lo, hi);
        Cell {
            f0: self.sample.row(0, lo[0]),
            f1: self.sample.row(0, hi[0]),
            g0: self.sample.row(1, lo[1]),
            g1: self.sample.row(1, hi[1]),
            ..full
        }
    }

    fn cell(&self, lo: [usize; 2], hi: [usize; 2]) -> Cell<'_> {
        let mut h2 = [0.0; 2];
        let mut eps = [0.0; 2];
        for k in 0..2 {
            if self.active[k] {
                let h = self.t[k][hi[k]] - self.t[k][lo[k]];
                h2[k] = h * h / 8.0;
                eps[k] = self.slack + ROUND;
            }
        }
        Cell {
            f0: self.row(0, lo[0]),
            f1: self.row(0, hi[0]),
            g0: self.row(1, lo[1]),
            g1: self.row(1, hi[1]),
            h2,
            eps,
            slack: self.slack,
            min_rule: self.min_rule,
        }
    }

    /// One pass over the points at cell coordinates x, or (`sample`, `cell` then
    /// [`Separable::sample_cell`]) over every LOOSE_STRIDE-th point of each chunk; the first pass
    /// and a sample also sum the first-order bound, and the loosenesses (for large data, only a
    /// sample does). The per-point terms are [`kernel::run`]'s, one instance per rule and kind
    /// of pass.
    fn pass(&self, cell: &Cell, x: [f64; 2], first: bool, sample: bool) -> PassSums {
        let first = first || sample;
        if !sample {
            self.count_pass(0);
        }
        match (self.min_rule, first, self.second_order) {
            (false, false, false) => self.pass_as::<false, false, false>(cell, x, sample),
            (false, false, true) => self.pass_as::<false, false, true>(cell, x, sample),
            (false, true, false) => self.pass_as::<false, true, false>(cell, x, sample),
            (false, true, true) => self.pass_as::<false, true, true>(cell, x, sample),
            (true, false, false) => self.pass_as::<true, false, false>(cell, x, sample),
            (true, false, true) => self.pass_as::<true, false, true>(cell, x, sample),
            (true, true, false) => self.pass_as::<true, true, false>(cell, x, sample),
            (true, true, true) => self.pass_as::<true, true, true>(cell, x, sample),
        }
    }

    fn pass_as<const MIN: bool, const FIRST: bool, const SECOND: bool>(
        &self,
        cell: &Cell,
        x: [f64; 2],
        sample: bool,
    ) -> PassSums {
        let (e, w) = if sample {
            (&self.sample.e[..], &self.sample.w[..])
        } else {
            (&self.e[..], &self.w[..])
        };
        // The loosenesses in the first pass of small data and in a sample (large data).
        let with_loose = FIRST && (sample || !sums::is_large(self.n));
        let v = if sample {
            // The chunks' sums added in chunk order, as `sums::sum` adds the full pass's (a few
            // thousand points: on this thread).
            // The loosenesses in a loop of their own (with the second-order one inlined: in
            // the pass it would keep the pass out of the wide registers' copy), added where
            // the pass's loop would have added them.
            let mut v = [0.0; 13];
            for r in &self.sample.chunks {
                let mut p = crate::cpu::fast(|| {
                    part_as::<MIN, FIRST, SECOND>(cell, e, w, x, r.clone(), false)
                });
                if with_loose {
                    let l =
                        crate::cpu::fast(|| Self::loose_as::<MIN, SECOND>(cell, e, w, r.clone()));
                    p[9..].copy_from_slice(&l);
                }
                for (v, p) in v.iter_mut().zip(p) {
                    *v += p;
                }
            }
            v
        } else {
            sums::sum(self.n, |points| {
                part_fast::<MIN, FIRST, SECOND>(cell, e, w, x, points, with_loose)
            })
        };
        PassSums {
            first: v[0],
            phi: v[1],
            g: [v[2], v[3]],
            h: [v[4], v[5], v[6]],
            g_abs: [v[7], v[8]],
            loose1: [v[9], v[10]],
            loose2: [v[11], v[12]],
        }
    }

    /// The loosenesses' sums over `points` (consecutive, in order), as `part_as` adds them:
    /// first-order per axis, then second-order per axis (0 without SECOND).
    #[inline(always)]
    fn loose_as<const MIN: bool, const SECOND: bool>(
        cell: &Cell,
        e: &[f64],
        w: &[f64],
        points: std::ops::Range<usize>,
    ) -> [f64; 4] {
        let (mut l1, mut l2) = ([0.0; 2], [0.0; 2]);
        for i in points {
            let a = loose_first::<MIN>(cell, i, w[i], e[i]);
            l1[0] += a[0];
            l1[1] += a[1];
            if SECOND {
                let b = cell.loose_second_inline(i, w[i], e[i]);
                l2[0] += b[0];
                l2[1] += b[1];
            }
        }
        [l1[0], l1[1], l2[0], l2[1]]
    }

    fn count_pass(&self, kind: usize) {
        let mut p = self.passes.get();
        p[kind] += 1;
        self.passes.set(p);
    }

    /// The first-order bound over every point (large data), without the relaxation's terms.
    fn first_order_pass(&self, cell: &Cell) -> f64 {
        self.count_pass(1);
        let (e, w) = (&self.e[..], &self.w[..]);
        let [first] = if self.min_rule {
            sums::sum(self.n, |points| {
                [kernel::run::<true, true, false>(cell, e, w, [0.5, 0.5], points).first]
            })
        } else {
            sums::sum(self.n, |points| {
                [kernel::run::<false, true, false>(cell, e, w, [0.5, 0.5], points).first]
            })
        };
        first
    }

    /// The cell bound: the larger of the first-order bound and tangent-plane bounds of the
    /// convex relaxation phi (parent module's doc), at the cell's centre (large data: at the
    /// sampled pass's Newton step from it) and at safeguarded projected Newton steps towards
    /// phi's minimum (a step that does not lower phi is halved back towards the best point),
    /// until the bound reaches `target`, phi itself falls below it (no bound of phi's minimum
    /// can reach it then), or MAX_PASSES (always, without a target). Large data with a target:
    /// the sampled points' bound first, then the first-order terms alone where the sample
    /// predicts they decide (each a valid bound, returned when it reaches the target).
    fn bound_with(&self, lo: [usize; 2], hi: [usize; 2], target: Option<f64>) -> Bound {
        let cell = self.cell(lo, hi);
        if !self.second_order && !sums::is_large(self.n) {
            return self.first_order(&cell);
        }
        let mut x = [0.5, 0.5];
        // Rounding of a sum of n terms: at most n u of the sum of their magnitudes (any order).
        let margin = 2.0 * (self.n as f64 + 10.0) * f64::EPSILON;
        // phi(y) >= phi(x) + g.(y - x) for every y in the cell: its least value is at a corner,
        // each coordinate at the end the gradient points away from.
        let tangent = |s: &PassSums, x: [f64; 2]| {
            let mut t = s.phi;
            for (gk, xk) in s.g.iter().zip(x) {
                t += if *gk >= 0.0 {
                    -gk * xk
                } else {
                    gk * (1.0 - xk)
                };
            }
            t - margin * (s.phi + s.g_abs[0] + s.g_abs[1])
        };
        let choose = |s: &PassSums, second: f64| {
            if second > s.first { s.loose2 } else { s.loose1 }
        };
        // Large data: a sample of the points first. Its terms are a part of the full sums (all
        // non-negative for the first-order bound; phi over a subset of the points is a convex
        // minorant of phi), so its bounds are bounds too, and they settle the cells far from the
        // minimum at a thirteenth of the cost. It also gives the looseness.
        let sampled = sums::is_large(self.n).then(|| {
            let s = self.pass(&self.sample_cell(lo, hi), x, true, true);
            let second = tangent(&s, x);
            (s, second)
        });
        if let (Some((s, second)), Some(t)) = (&sampled, target)
            && s.first.max(*second) >= t
        {
            return Bound {
                lb: s.first.max(*second),
                loose: choose(s, *second),
            };
        }
        // The sample predicts the first-order bound over every point (its sum is about
        // n / (points sampled) times the sample's): where that clears the target by
        // FIRST_ONLY_MARGIN, a pass of the first-order terms alone (a third of the cost of a
        // pass with the relaxation's) decides the cell; otherwise it goes on as below.
        if let (Some((s, _)), Some(t)) = (&sampled, target)
            && self.n as f64 / self.sample.points.len() as f64 * s.first >= FIRST_ONLY_MARGIN * t
        {
            let first = self.first_order_pass(&cell);
            if first >= t {
                return Bound {
                    lb: first,
                    loose: s.loose1,
                };
            }
        }
        // The sample's sums are those of the full pass thinned out: its Newton step (whose
        // length does not depend on the scale of phi) points where the full pass's would, so the
        // full passes start there, one pass ahead. Any point of the cell gives a valid bound.
        if let Some((s, _)) = &sampled
            && let Some(y) = newton_step(x, s.g, s.h)
        {
            x = y;
        }
        let mut first = PassSums::default();
        let mut best: Option<([f64; 2], PassSums)> = None;
        let mut second = f64::NEG_INFINITY;
        for pass in 0..MAX_PASSES {
            let s = self.pass(&cell, x, pass == 0, false);
            if pass == 0 {
                first = s;
                if let Some((sample, _)) = &sampled {
                    first.loose1 = sample.loose1;
                    first.loose2 = sample.loose2;
                }
                if !self.second_order {
                    return Bound {
                        lb: first.first,
                        loose: first.loose1,
                    };
                }
            }
            let tangent = tangent(&s, x);
            if tangent > second {
                second = tangent;
            }
            let decided = target.is_some_and(|t| first.first.max(second) >= t || s.phi < t);
            if decided || pass + 1 == MAX_PASSES {
                break;
            }
            let next = match best {
                Some((bx, b)) if !(s.phi < b.phi) => {
                    Some([0.5 * (bx[0] + x[0]), 0.5 * (bx[1] + x[1])])
                }
                _ => {
                    best = Some((x, s));
                    newton_step(x, s.g, s.h)
                }
            };
            match next {
                Some(y) if y != x => x = y,
                _ => break,
            }
        }
        Bound {
            lb: first.first.max(second),
            loose: choose(&first, second),
        }
    }
}

impl Separable<'_> {
    /// Tabulates axis `axis` at `t` over every point (see [`Landscape::add_row`]).
    fn add_row_values(&mut self, axis: usize, t: f64) -> Result<(), String> {
        let (n, ev) = (self.n, self.obj.ev);
        self.t[axis].push(t);
        if !self.active[axis] {
            self.rows[axis].push(Arc::new(vec![1.0; n]));
            return Ok(());
        }
        // Counted whether computed here or by another model's search (a fit's count of
        // evaluations does not depend on which thread came first).
        self.obj.count_evaluation();
        let x = t.exp();
        let row = ev.row(axis, t);
        self.rows[axis].push(Arc::clone(&row));
        // The first point that failed names the failure (the evaluation's error if it gave
        // one, else the NaN).
        if !crate::cpu::fast(|| has_nan(&row)) {
            return Ok(());
        }
        let Some(i) = row.iter().position(|v| v.is_nan()) else {
            return Ok(());
        };
        let error = if axis == 0 { ev.e_vm(i, x).err() } else { None };
        Err(match error {
            Some(e) => format!("e_vm at eta = {}: {e}", crate::error::Num(x)),
            None => format!(
                "the model is NaN at {} = {} for {}",
                if axis == 0 { "eta" } else { "sigma_y" },
                crate::error::Num(x),
                self.obj.describe_point(i)
            ),
        })
    }

    /// The first-order bound and looseness alone, summed over every point as they always were
    /// (small data: the same cells, hence the same fits, to the last bit).
    fn first_order(&self, cell: &Cell) -> Bound {
        let (e, w) = (&self.e[..], &self.w[..]);
        let min_rule = self.min_rule;
        let [lb, l0, l1] = sums::sum(self.n, |points| {
            let (mut lb, mut l0, mut l1) = (0.0, 0.0, 0.0);
            for i in points {
                let d = cell.first_order_gap(i, e[i]);
                lb += w[i] * d * d;
                let l = if min_rule {
                    loose_first::<true>(cell, i, w[i], e[i])
                } else {
                    loose_first::<false>(cell, i, w[i], e[i])
                };
                l0 += l[0];
                l1 += l[1];
            }
            [lb, l0, l1]
        });
        Bound {
            lb,
            loose: [l0, l1],
        }
    }
}

crate::cpu::wide_copy! {
    /// A full pass's sums over `points` ([`part_as`]) through a copy compiled for
    /// AVX2 ([`crate::cpu::wide_copy`]: its closure inside `cpu::fast` had been left out of the
    /// wrapper, 3% of `--model all` on 100 000 points of distinct sizes).
    fn part_fast;
    /// A pass's sums over `points` (consecutive, summed in order), in `pass_as`'s order; inlined
    /// into each caller, so that the wide registers' copy of the loop is the one that runs.
    fn part_as<const MIN: bool, const FIRST: bool, const SECOND: bool>(
        cell: &Cell,
        e: &[f64],
        w: &[f64],
        x: [f64; 2],
        points: std::ops::Range<usize>,
        with_loose: bool,
    ) -> [f64; 13] {
        let mut s = PassSums::default();
        if with_loose {
            for i in points.clone() {
                let l1 = loose_first::<MIN>(cell, i, w[i], e[i]);
                s.loose1[0] += l1[0];
                s.loose1[1] += l1[1];
                if SECOND {
                    let l2 = cell.loose_second(i, w[i], e[i]);
                    s.loose2[0] += l2[0];
                    s.loose2[1] += l2[1];
                }
            }
        }
        let t = kernel::run::<MIN, FIRST, SECOND>(cell, e, w, x, points);
        let [g0, g1] = t.g;
        let [h0, h1, h2] = t.h;
        let [a0, a1] = t.g_abs;
        let [o0, o1] = s.loose1;
        let [n0, n1] = s.loose2;
        [t.first, t.phi, g0, g1, h0, h1, h2, a0, a1, o0, o1, n0, n1]
    }
}

/// Whether any value is NaN: blocks without an early exit (a loop the compiler runs several
/// values at once, where a search for the first NaN went value by value over every row).
#[inline(always)]
fn has_nan(row: &[f64]) -> bool {
    row.chunks(256)
        .any(|b| b.iter().fold(false, |a, v| a | v.is_nan()))
}

/// Point i's first-order looseness per axis: how far its corner products move along each axis,
/// weighted by its residual at the top corner.
#[inline(always)]
fn loose_first<const MIN: bool>(cell: &Cell, i: usize, w: f64, e: f64) -> [f64; 2] {
    let (f0, f1, g0, g1) = (cell.f0[i], cell.f1[i], cell.g0[i], cell.g1[i]);
    let c = |a: f64, b: f64| if MIN { a.min(b) } else { a * b };
    let top = c(f0, g1);
    let r = (top - e).abs();
    let d0 = top - c(f1, g1);
    let d1 = top - c(f0, g0);
    [w * d0 * (r + d0), w * d1 * (r + d1)]
}

/// A Newton step on the quadratic model phi(x) + g.d + d.H d/2, projected onto [0, 1]^2: the
/// full step clipped, then the other coordinate re-minimised with a clipped one held (None when
/// the model has no curvature: phi is then flat or linear over the points that count).
fn newton_step(x: [f64; 2], g: [f64; 2], h: [f64; 3]) -> Option<[f64; 2]> {
    let reg = 1e-12 * (h[0] + h[2]);
    let (a, b, c) = (h[0] + reg, h[1], h[2] + reg);
    let det = a * c - b * b;
    if !(det > 0.0 && det.is_finite()) {
        return None;
    }
    let d = [-(c * g[0] - b * g[1]) / det, -(a * g[1] - b * g[0]) / det];
    let mut y = [(x[0] + d[0]).clamp(0.0, 1.0), (x[1] + d[1]).clamp(0.0, 1.0)];
    let hk = [a, c];
    for k in 0..2 {
        let j = 1 - k;
        if (y[k] == 0.0 || y[k] == 1.0) && hk[j] > 0.0 {
            y[j] = (x[j] - (g[j] + b * (y[k] - x[k])) / hk[j]).clamp(0.0, 1.0);
        }
    }
    y.iter().all(|v| v.is_finite()).then_some(y)
}

impl Landscape for Separable<'_> {
    fn add_row(&mut self, axis: usize, t: f64) -> Result<(), String> {
        let done = self.add_row_values(axis, t);
        let (rows, sample) = (self.rows[axis].last().expect("added"), &mut self.sample);
        sample.rows[axis].extend(sample.points.iter().map(|&i| rows[i]));
        done
    }

    fn node(&self, r: [usize; 2]) -> f64 {
        let (f, g) = (self.row(0, r[0]), self.row(1, r[1]));
        let (e, w) = (&self.e[..], &self.w[..]);
        let min_rule = self.min_rule;
        let [s] = sums::sum(self.n, |points| {
            let mut s = 0.0;
            if min_rule {
                for i in points {
                    let d = f[i].min(g[i]) - e[i];
                    s += w[i] * d * d;
                }
            } else {
                for i in points {
                    let d = f[i] * g[i] - e[i];
                    s += w[i] * d * d;
                }
            }
            [s]
        });
        s
    }

    fn nodes_grid(&self, rows0: &[usize], rows1: &[usize]) -> Vec<f64> {
        let f: Vec<&[f64]> = rows0.iter().map(|&r| self.row(0, r)).collect();
        let g: Vec<&[f64]> = rows1.iter().map(|&r| self.row(1, r)).collect();
        if f.is_empty() || g.is_empty() {
            return Vec::new();
        }
        grid::nodes(&f, &g, &self.e, &self.w, self.min_rule)
    }

    fn nodes_list(&self, pairs: &[[usize; 2]]) -> Vec<f64> {
        let rows: Vec<(&[f64], &[f64])> = pairs
            .iter()
            .map(|r| (self.row(0, r[0]), self.row(1, r[1])))
            .collect();
        if rows.is_empty() {
            return Vec::new();
        }
        grid::list(&rows, &self.e, &self.w, self.min_rule)
    }

    fn bound(&self, lo: [usize; 2], hi: [usize; 2], target: f64) -> Bound {
        self.bound_with(lo, hi, Some(target))
    }
}

#[cfg(test)]
mod tests;
