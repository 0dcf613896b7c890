//! Branch and bound over a box of one or two dimensions, for the global search of the fit.
//!
//! **Solves**: certifies that no point of a box has chi2 below a known value U minus a tolerance
//! tau, or finds the cells where it might. **Needs** a [`Landscape`]: chi2 at grid nodes and, for
//! any cell between nodes, a lower bound of chi2 over the whole cell (for the fit's models these
//! come from monotonicity, see [`super::search`]). **Method**: the classic branch and bound
//! (Horst & Tuy, "Global Optimization: Deterministic Approaches", 3rd ed., 1996, ch. IV): a cell
//! whose bound exceeds U - tau is done (it cannot hold a point lower than U - tau); the others
//! are split, lowest bound first, until none is left or a budget runs out. Cells lie on a dyadic
//! grid (up to 40 halvings of a uniform starting grid), so their corners are shared and each
//! grid value of an axis is tabulated once. The starting cells are bounded 2 x 2 at a time where
//! that block's bound already clears the target (each cell then takes the block's bound: a lower
//! bound over the block is one over each of its cells).
//!
//! A cell whose bound could not change what becomes of it is not bounded: around the polished
//! point, wholly outside a cut ([`Bnb::set_cut`]), and across a cut with a corner below the
//! target (split on the cut's axis; bounded only if it comes to a decision otherwise).
//!
//! The caller lowers U as it finds better points (local polishes from the candidates this module
//! proposes) and refines again; the certificate is then min(bound over the remaining cells),
//! whatever the polishes did.
//!
//! **Known answer** (test below): a separable two-minimum function whose bounds are exact on
//! every cell is certified to the tolerance, both minima are proposed, and a cell budget of 1
//! ends unresolved; its starting cells each get a bound below the function's exact minimum over
//! them, with fewer bounds computed than cells.

mod candidates;
pub use candidates::Candidate;

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// A small hasher for the integer keys of the grid (std's SipHash costs more than the work it
/// indexes): words folded by multiplication, finished by splitmix64's mixer so that dyadic
/// positions (low bits zero) spread over the table.
#[derive(Default, Clone, Copy)]
struct Mix(u64);

impl Hasher for Mix {
    fn finish(&self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(23) ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
}

type Map<K, V> = HashMap<K, V, BuildHasherDefault<Mix>>;

/// Halvings of the starting cells allowed.
pub const DEPTH: u32 = 40;

/// The largest block of starting cells bounded as one ([`Bnb::new`]). Blocks of 4 x 4 and then
/// 2 x 2 bounded fewer cells on 100 000 distinct points (192 against 244 for `min`) for the same
/// CPU.
const START_BLOCK: u64 = 2;

/// The function a [`Bnb`] works on.
pub trait Landscape {
    /// Tabulates axis `axis` at internal coordinate `t`; row ids are assigned in call order per
    /// axis, and a row must be appended even when it fails (the error text is returned).
    fn add_row(&mut self, axis: usize, t: f64) -> Result<(), String>;
    /// chi2 at the node of rows `r` (+inf allowed; NaN only when a row failed).
    fn node(&self, r: [usize; 2]) -> f64;
    /// chi2 at every node of the grid `rows0` x `rows1` (rows that did not fail), row-major
    /// (`rows1` fastest): the same numbers as [`Landscape::node`], to the last bit. A landscape
    /// may compute them together (the starting grid's nodes are most of its work).
    fn nodes_grid(&self, rows0: &[usize], rows1: &[usize]) -> Vec<f64> {
        let pairs: Vec<[usize; 2]> = rows0
            .iter()
            .flat_map(|&a| rows1.iter().map(move |&b| [a, b]))
            .collect();
        self.nodes_list(&pairs)
    }
    /// chi2 at each node of `pairs` (rows that did not fail), in order: the same numbers as
    /// [`Landscape::node`], to the last bit (a split's new corners, computed together).
    fn nodes_list(&self, pairs: &[[usize; 2]]) -> Vec<f64> {
        pairs.iter().map(|&r| self.node(r)).collect()
    }
    /// A lower bound of chi2 over the cell between rows `lo` (lower coordinate) and `hi` on each
    /// axis, and how much of its looseness each axis causes (to choose the axis to split). Only
    /// its position relative to `target` matters: an iterative bound may stop once that is
    /// decided.
    fn bound(&self, lo: [usize; 2], hi: [usize; 2], target: f64) -> Bound;
}

/// A cell's lower bound and the looseness per axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    pub lb: f64,
    pub loose: [f64; 2],
}

/// One axis of the box: its range, starting cells, and the rows tabulated so far.
struct Axis {
    lo: f64,
    hi: f64,
    n0: u64,
    active: bool,
    row_of: Map<u64, usize>,
    t: Vec<f64>,
    ok: Vec<bool>,
}

impl Axis {
    fn new(range: (f64, f64), n0: u64) -> Axis {
        Axis {
            lo: range.0,
            hi: range.1,
            n0: n0.max(1),
            active: n0 > 0,
            row_of: Map::default(),
            t: Vec::new(),
            ok: Vec::new(),
        }
    }
    fn span(&self) -> u64 {
        if self.active { self.n0 << DEPTH } else { 0 }
    }
    fn t_at(&self, p: u64) -> f64 {
        if !self.active {
            self.lo
        } else if p == self.span() {
            self.hi
        } else {
            self.lo + (self.hi - self.lo) * (p as f64 / self.span() as f64)
        }
    }
}

/// A cell: dyadic positions of its lower and upper corners.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cell {
    p0: [u64; 2],
    p1: [u64; 2],
    bound: Bound,
    failed: bool,
    /// Its bound not computed yet (lb -inf): a cell across the cut with a corner below the
    /// target ([`Bnb::make_cell`]), bounded only where it is not split on the cut's axis.
    deferred: bool,
}

struct ByBound(Cell);
impl PartialEq for ByBound {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for ByBound {}
impl PartialOrd for ByBound {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for ByBound {
    /// Reversed: the max-heap pops the lowest bound first.
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.bound.lb.total_cmp(&self.0.bound.lb)
    }
}

/// What splitting a cell gave.
enum Split {
    Cells(Vec<Cell>),
    /// Every axis that matters is at the statistical resolution.
    Fine,
    /// An axis that matters cannot be halved again on the dyadic grid.
    Finest,
}

/// A cell of the grid ([`Bnb::cells_below`]): the dyadic positions of its corners, and their
/// internal coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellBox {
    pub p0: [u64; 2],
    pub p1: [u64; 2],
    pub t0: [f64; 2],
    pub t1: [f64; 2],
}

/// Nodes' chi2 by dyadic position, from another branch and bound on the same landscape and grid
/// ([`Bnb::known_nodes`], [`Bnb::set_known_nodes`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KnownNodes(Map<[u64; 2], f64>);

/// A half-plane of the box ([`Bnb::set_cut`]): the points whose coordinate on `axis` is `at` or
/// beyond it in direction `dir` (+1 above, -1 below); a cell straddling `at` is split on `axis`
/// down to `width`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cut {
    pub axis: usize,
    pub at: f64,
    pub dir: f64,
    pub width: f64,
}

impl Cut {
    /// Whether internal coordinate `t` on the cut's axis lies on the searched side (at `at` too).
    fn keeps(&self, t: f64) -> bool {
        (t - self.at) * self.dir >= 0.0
    }

    /// Whether a cell spanning `t0 ..= t1` on the cut's axis has a point in the half-plane, not
    /// counting an edge on `at` (it belongs to a cell beyond too).
    fn reaches(&self, t0: f64, t1: f64) -> bool {
        if self.dir > 0.0 {
            t1 > self.at
        } else {
            t0 < self.at
        }
    }
}

/// Budgets of a [`Bnb`].
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    pub max_cells: u64,
    pub max_rows: usize,
}

/// The branch and bound state (see the module doc).
pub struct Bnb<L: Landscape> {
    pub land: L,
    axes: [Axis; 2],
    nodes: Map<[usize; 2], f64>,
    /// Lowest node so far: positions and chi2.
    best: Option<([u64; 2], f64)>,
    heap: BinaryHeap<ByBound>,
    /// Cells not split further: bound at or above U - tau when last looked at.
    done: Vec<Cell>,
    /// Cells that could not be resolved, with the reason.
    unresolved: Vec<(Cell, String)>,
    /// Cells set aside with a bound above U but at most `keep_of(U)` ([`Bnb::refine`]): with
    /// the others they cover every point of the box that may have chi2 that low
    /// ([`Bnb::cells_below`]).
    kept: Vec<Cell>,
    /// Cells left at the statistical resolution ([`Bnb::set_resolution`]) with a bound below
    /// U - tau: they surround the minima, where local polishes take over.
    fine: Vec<Cell>,
    /// Widths below which an axis is not split (internal units; 0 = down to the dyadic grid).
    resolution: [f64; 2],
    /// A point a local minimisation converged at ([`Bnb::set_polished`]).
    polished: Option<[f64; 2]>,
    /// The half-plane the search is restricted to ([`Bnb::set_cut`]), and the row at its
    /// edge once made ([`Bnb::clipped`]; not a dyadic position, so in no axis' `row_of`).
    cut: Option<Cut>,
    cut_row: Option<usize>,
    /// Starting grid, for [`Bnb::initial_minima`].
    start_cells: Vec<Cell>,
    pub cells: u64,
    limits: Limits,
    /// Whether [`Bnb::refine`] has taken the starting cells yet.
    started: bool,
    /// U - tau at the last look (what a cell bound is compared with).
    target: f64,
    /// Rows that could not be evaluated (reason, first few).
    pub row_failures: Vec<String>,
    /// Nodes whose chi2 another search on the same landscape computed ([`Bnb::set_known_nodes`]).
    known: KnownNodes,
}

/// The t of the starting grid's rows on an axis of `range` cut in `n0` cells, as [`Bnb::new`]
/// asks the landscape for them (none for an inactive axis, `n0` = 0).
pub fn starting_rows(range: (f64, f64), n0: u64) -> Vec<f64> {
    let axis = Axis::new(range, n0);
    if !axis.active {
        return Vec::new();
    }
    (0..=n0).map(|i| axis.t_at(i << DEPTH)).collect()
}

impl<L: Landscape> Bnb<L> {
    /// No node or cell yet.
    fn empty(land: L, range: [(f64, f64); 2], n0: [u64; 2], limits: Limits) -> Self {
        Bnb {
            land,
            axes: [Axis::new(range[0], n0[0]), Axis::new(range[1], n0[1])],
            nodes: Map::default(),
            best: None,
            heap: BinaryHeap::new(),
            done: Vec::new(),
            unresolved: Vec::new(),
            kept: Vec::new(),
            fine: Vec::new(),
            resolution: [0.0, 0.0],
            polished: None,
            cut: None,
            cut_row: None,
            start_cells: Vec::new(),
            cells: 0,
            limits,
            started: false,
            target: f64::INFINITY,
            row_failures: Vec::new(),
            known: KnownNodes::default(),
        }
    }

    /// A uniform starting grid of `n0[k]` cells over `range[k]` (an axis with `n0 = 0` is
    /// inactive: one row at its `lo`). Evaluates every starting node, and bounds every starting
    /// cell (by blocks of cells where a block's bound decides them: see the module doc).
    pub fn new(land: L, range: [(f64, f64); 2], n0: [u64; 2], limits: Limits) -> Self {
        let mut b = Bnb::empty(land, range, n0, limits);
        let step = |k: usize, b: &Self| if b.axes[k].active { 1u64 << DEPTH } else { 0 };
        let (s0, s1) = (step(0, &b), step(1, &b));
        let (c0, c1) = (
            if b.axes[0].active { n0[0] } else { 1 },
            if b.axes[1].active { n0[1] } else { 1 },
        );
        // Nodes first: the best of them is the target the starting cells' bounds are judged by.
        // The rows in the order the nodes would create them, the nodes' chi2 all together, then
        // recorded in that order (the best node is the first of the lowest, as node by node).
        let mut rows = [Vec::new(), Vec::new()];
        for i in 0..=c0 {
            for j in 0..=c1 {
                let r = [b.row(0, i * s0), b.row(1, j * s1)];
                // (An inactive axis has one row, met at every step.)
                for k in 0..2 {
                    if !rows[k].contains(&r[k]) {
                        rows[k].push(r[k]);
                    }
                }
            }
        }
        let ok = |k: usize, b: &Self| -> Vec<usize> {
            rows[k]
                .iter()
                .copied()
                .filter(|&r| b.axes[k].ok[r])
                .collect()
        };
        let (ok0, ok1) = (ok(0, &b), ok(1, &b));
        let values = b.land.nodes_grid(&ok0, &ok1);
        // Row-major over the rows, as the values over the rows that did not fail.
        let nodes: Vec<([u64; 2], [usize; 2])> = (rows[0].iter().enumerate())
            .flat_map(|(i, &r0)| {
                (rows[1].iter().enumerate())
                    .map(move |(j, &r1)| ([i as u64 * s0, j as u64 * s1], [r0, r1]))
            })
            .collect();
        b.record_nodes(nodes, values);
        b.target = b.best.map_or(f64::INFINITY, |(_, v)| v);
        // The starting cells by blocks of up to START_BLOCK x START_BLOCK cells: where a
        // block's bound reaches the target, each of its cells takes that bound (a lower bound
        // over the block is one over each of its cells) without a bound of its own. Far from
        // the minimum, where most starting cells are, a few bounds for many cells.
        let mut cells: Vec<Option<Cell>> = vec![None; (c0 * c1) as usize];
        for i in (0..c0).step_by(START_BLOCK as usize) {
            for j in (0..c1).step_by(START_BLOCK as usize) {
                b.start_block([i, j], [c0, c1], START_BLOCK, [s0, s1], &mut cells);
            }
        }
        b.start_cells = cells.into_iter().flatten().collect();
        b
    }

    /// A branch and bound over the grid [`Bnb::new`] would build on `range` and `n0`, with no
    /// cell yet: its starting cells are given by [`Bnb::start_on`] (after
    /// [`Bnb::set_resolution`] and [`Bnb::set_polished`], which they depend on).
    pub fn sparse(land: L, range: [(f64, f64); 2], n0: [u64; 2], limits: Limits) -> Self {
        Bnb::empty(land, range, n0, limits)
    }

    /// Starts from the cells `cells` (dyadic corner positions) instead of the whole uniform
    /// grid: the rest of the box is known not to matter (for example a slice of another branch
    /// and bound's box, [`Bnb::cells_below`]). Their bounds are judged against the lower of the
    /// best node and `target` (U - tau, where the caller knows a U: an iterative bound stops
    /// sooner). Not for [`Bnb::initial_minima`], which reads the uniform grid.
    pub fn start_on(&mut self, cells: &[([u64; 2], [u64; 2])], target: f64) {
        let corners: Vec<[u64; 2]> = cells
            .iter()
            .flat_map(|&(p0, p1)| [p0, [p1[0], p0[1]], [p0[0], p1[1]], p1])
            .collect();
        self.nodes_at(&corners);
        self.target = self.best.map_or(target, |(_, v)| v.min(target));
        self.start_cells = cells
            .iter()
            .map(|&(p0, p1)| self.make_cell(p0, p1))
            .collect();
    }

    /// The starting cells of the block of `size` x `size` cells (fewer at the grid's edges)
    /// whose first cell is `at`, into `cells` (row-major over the `n` cells of the grid; `step`
    /// the dyadic width of a cell): one bound for the whole block where it reaches the target
    /// and every row of the grid inside the block could be evaluated (a block's bound rests on
    /// its corner rows alone: a row that failed inside it must leave its cells failed, as they
    /// are on their own), else blocks of half the size, down to each cell's own bound.
    fn start_block(
        &mut self,
        at: [u64; 2],
        n: [u64; 2],
        size: u64,
        step: [u64; 2],
        cells: &mut [Option<Cell>],
    ) {
        let end = [(at[0] + size).min(n[0]), (at[1] + size).min(n[1])];
        let p = |i: u64, j: u64| [i * step[0], j * step[1]];
        let rows_ok = |b: &mut Self| {
            (at[0]..=end[0]).all(|i| {
                let r = b.row(0, i * step[0]);
                b.axes[0].ok[r]
            }) && (at[1]..=end[1]).all(|j| {
                let r = b.row(1, j * step[1]);
                b.axes[1].ok[r]
            })
        };
        if (end[0] - at[0]) * (end[1] - at[1]) > 1 && rows_ok(self) {
            let block = self.make_cell(p(at[0], at[1]), p(end[0], end[1]));
            if !block.failed && block.bound.lb >= self.target {
                for i in at[0]..end[0] {
                    for j in at[1]..end[1] {
                        cells[(i * n[1] + j) as usize] = Some(Cell {
                            deferred: false,
                            p0: p(i, j),
                            p1: p(i + 1, j + 1),
                            ..block
                        });
                    }
                }
                return;
            }
        }
        if size == 1 {
            let cell = self.make_cell(p(at[0], at[1]), p(at[0] + 1, at[1] + 1));
            cells[(at[0] * n[1] + at[1]) as usize] = Some(cell);
            return;
        }
        let half = size / 2;
        for i in (at[0]..end[0]).step_by(half as usize) {
            for j in (at[1]..end[1]).step_by(half as usize) {
                self.start_block([i, j], n, half, step, cells);
            }
        }
    }

    /// The rows of the node at dyadic position `p` (each axis's made if new).
    fn rows_at(&mut self, p: [u64; 2]) -> [usize; 2] {
        [self.row(0, p[0]), self.row(1, p[1])]
    }

    fn row(&mut self, k: usize, p: u64) -> usize {
        if let Some(&r) = self.axes[k].row_of.get(&p) {
            return r;
        }
        let r = self.add_row(k, self.axes[k].t_at(p));
        self.axes[k].row_of.insert(p, r);
        r
    }

    /// Tabulates axis k at t (a failure recorded, the row kept as failed); its row id.
    fn add_row(&mut self, k: usize, t: f64) -> usize {
        let ok = match self.land.add_row(k, t) {
            Ok(()) => true,
            Err(why) => {
                if self.row_failures.len() < 3 {
                    self.row_failures.push(why);
                }
                false
            }
        };
        let a = &mut self.axes[k];
        a.t.push(t);
        a.ok.push(ok);
        a.t.len() - 1
    }

    fn rows_total(&self) -> usize {
        self.axes[0].t.len() + self.axes[1].t.len()
    }

    fn node_at(&mut self, p: [u64; 2]) -> (f64, [usize; 2]) {
        let r = self.rows_at(p);
        if let Some(&v) = self.nodes.get(&r) {
            return (v, r);
        }
        let v = if !self.rows_ok(r) {
            f64::NAN
        } else if let Some(&v) = self.known.0.get(&p) {
            v
        } else {
            self.land.node(r)
        };
        self.record_node(p, r, v);
        (v, r)
    }

    /// [`Bnb::node_at`] at each of `ps` in order (the same rows created in the same order, the
    /// same nodes recorded in the same order), the chi2 of the new ones computed together.
    fn nodes_at(&mut self, ps: &[[u64; 2]]) {
        let mut new: Vec<([u64; 2], [usize; 2])> = Vec::new();
        // A set, not a search of `new`: a slice starts on every cell of the search's region at
        // once (fuzz: 41 931 cells, whose corners' search of the list took 5 s of CPU).
        let mut seen: HashSet<[usize; 2]> = HashSet::new();
        for &p in ps {
            let r = self.rows_at(p);
            if !self.nodes.contains_key(&r) && seen.insert(r) {
                new.push((p, r));
            }
        }
        let pairs: Vec<[usize; 2]> = new
            .iter()
            .filter(|&&(p, r)| self.rows_ok(r) && !self.known.0.contains_key(&p))
            .map(|&(_, r)| r)
            .collect();
        let values = self.land.nodes_list(&pairs);
        self.record_nodes(new, values);
    }

    /// The chi2 of the nodes at the corners of `cells` that this search evaluated (rows that
    /// failed left out), for another search on the same landscape and grid
    /// ([`Bnb::set_known_nodes`]).
    pub fn known_nodes(&self, cells: &[CellBox]) -> KnownNodes {
        let mut known = Map::default();
        for c in cells {
            for p in [c.p0, [c.p1[0], c.p0[1]], [c.p0[0], c.p1[1]], c.p1] {
                let r = [0, 1].map(|k| self.axes[k].row_of.get(&p[k]).copied());
                if let [Some(r0), Some(r1)] = r
                    && let Some(&v) = self.nodes.get(&[r0, r1])
                    && !v.is_nan()
                {
                    known.insert(p, v);
                }
            }
        }
        KnownNodes(known)
    }

    /// Takes the chi2 of the nodes in `known` as computed: from a search on the same landscape
    /// (the same rows at the same dyadic positions: the same numbers, to the last bit, which
    /// [`Landscape::node`] and [`Landscape::nodes_list`] give alike), before any node is
    /// evaluated. The search is the one it would be without them, less their cost: the region
    /// beyond an interval's end ([`crate::fit::beyond`]) starts on the global search's cells,
    /// whose corners that search evaluated (a twentieth of a fit of 100 000 points of distinct
    /// sizes went to evaluating them again).
    pub fn set_known_nodes(&mut self, known: KnownNodes) {
        self.known = known;
    }

    fn rows_ok(&self, r: [usize; 2]) -> bool {
        self.axes[0].ok[r[0]] && self.axes[1].ok[r[1]]
    }

    /// Records `nodes` in order: a known node's value ([`Bnb::set_known_nodes`]), else the next
    /// of `values` (computed, in the same order, for the nodes whose rows did not fail and that
    /// are not known), NaN where a row failed.
    fn record_nodes(&mut self, nodes: Vec<([u64; 2], [usize; 2])>, values: Vec<f64>) {
        let mut values = values.into_iter();
        for (p, r) in nodes {
            let v = if !self.rows_ok(r) {
                f64::NAN
            } else if let Some(&v) = self.known.0.get(&p) {
                v
            } else {
                values
                    .next()
                    .expect("one value per node of the rows that did not fail and not known")
            };
            self.record_node(p, r, v);
        }
    }

    fn record_node(&mut self, p: [u64; 2], r: [usize; 2], v: f64) {
        self.nodes.insert(r, v);
        // A node outside the cut is no point of the search (its chi2 may well be lower).
        if self.searched(p) && !v.is_nan() && self.best.is_none_or(|(_, b)| v < b) {
            self.best = Some((p, v));
        }
    }

    /// A new cell, its corners' nodes evaluated and its bound computed, except where the bound
    /// could not change what becomes of it: around the polished point
    /// ([`Bnb::around_polished`]: split or left to the polish whatever it is), wholly outside
    /// the cut (dropped), and across the cut with a corner below the target by more than a
    /// millionth of it (its bound, at most that corner's chi2, cannot reach the target: it is
    /// split on the cut's axis, or bounded when it reaches the refinement otherwise,
    /// [`Bnb::refine`]). The corner may lie outside the cut, inside the interval: the region
    /// beyond an end of a profile interval ([`crate::fit::beyond`]) is entered from the
    /// search's cells around the minimum, whose bounds cost a third of its passes over the
    /// points on 100 000 points of distinct sizes for nothing.
    fn make_cell(&mut self, p0: [u64; 2], p1: [u64; 2]) -> Cell {
        self.cells += 1;
        let mut lowest = f64::INFINITY;
        for p in [p0, [p1[0], p0[1]], [p0[0], p1[1]], p1] {
            let (v, _) = self.node_at(p);
            if v < lowest {
                lowest = v;
            }
        }
        let (lo, hi) = (self.rows_at(p0), self.rows_at(p1));
        let ok = lo
            .iter()
            .chain(&hi)
            .enumerate()
            .all(|(n, &r)| self.axes[n % 2].ok[r]);
        let target = self.target;
        let deferred = ok && self.crosses_cut(p0, p1) && lowest < target - 1e-6 * target.abs();
        let unneeded = deferred || self.around_polished(p0, p1) || !self.reaches(p0, p1);
        let mut bound = if ok && !unneeded {
            self.land.bound(lo, hi, target)
        } else {
            Bound {
                lb: f64::NEG_INFINITY,
                loose: [1.0, 1.0],
            }
        };
        let failed = !ok || bound.lb.is_nan();
        if bound.lb.is_nan() {
            bound.lb = f64::NEG_INFINITY;
        }
        Cell {
            p0,
            p1,
            bound,
            failed,
            deferred,
        }
    }

    /// A deferred cell's bound ([`Bnb::make_cell`]), against the current target.
    fn bound_deferred(&mut self, c: &mut Cell) {
        let (lo, hi) = (self.rows_at(c.p0), self.rows_at(c.p1));
        c.bound = self.land.bound(lo, hi, self.target);
        c.deferred = false;
        if c.bound.lb.is_nan() {
            c.bound.lb = f64::NEG_INFINITY;
            c.failed = true;
        }
    }

    /// Whether the cell holds the polished point and is wider than the resolution on an active
    /// axis (closed cells; the slack of [`Bnb::may_hold_below`]).
    fn around_polished(&self, p0: [u64; 2], p1: [u64; 2]) -> bool {
        let Some(t) = self.polished else {
            return false;
        };
        let (mut inside, mut coarse) = (true, false);
        for (k, a) in self.axes.iter().enumerate() {
            if !a.active {
                continue;
            }
            let (lo, hi) = (a.t_at(p0[k]), a.t_at(p1[k]));
            let slack = 1e-12 * (a.hi - a.lo).abs();
            inside &= lo - slack <= t[k] && t[k] <= hi + slack;
            coarse |= hi - lo > self.resolution[k];
        }
        inside && coarse
    }

    /// Restricts the search to the half-plane `cut` (see [`Cut`]): cells wholly outside it are
    /// dropped, nodes outside it are not the best node, and a cell across its `at` is split on
    /// its axis down to its width, then bounded over its part in the half-plane
    /// (`Bnb::clipped`) before any split on the other axis. Before the starting cells
    /// ([`Bnb::start_on`]).
    pub fn set_cut(&mut self, cut: Cut) {
        self.cut = Some(cut);
    }

    /// A point a local minimisation converged at: the cells holding it are split down to the
    /// resolution without a bound (near such a point a bound cannot clear a target close to its
    /// value before the resolution anyway: its cells would be split regardless, and their bounds
    /// are the work), and left there to that minimisation, as the cells around the minima are
    /// left to the polishes. For a point whose value is within the tolerance of the target.
    pub fn set_polished(&mut self, t: [f64; 2]) {
        self.polished = Some(t);
    }

    /// The lowest node evaluated so far: rows, internal coordinates and chi2.
    pub fn best_node(&self) -> Option<([usize; 2], [f64; 2], f64)> {
        let (p, v) = self.best?;
        let r = [self.axes[0].row_of[&p[0]], self.axes[1].row_of[&p[1]]];
        Some((r, self.t_of(r), v))
    }

    /// Internal coordinates of rows.
    pub fn t_of(&self, rows: [usize; 2]) -> [f64; 2] {
        [self.axes[0].t[rows[0]], self.axes[1].t[rows[1]]]
    }

    /// Every evaluated node with chi2 at most `below`: rows, internal coordinates and chi2.
    pub fn nodes_below(&self, below: f64) -> Vec<([usize; 2], [f64; 2], f64)> {
        self.nodes
            .iter()
            .filter(|(_, v)| **v <= below)
            .map(|(r, v)| (*r, self.t_of(*r), *v))
            .collect()
    }

    /// Sets the widths below which an axis is not split any more (see the module doc).
    pub fn set_resolution(&mut self, w: [f64; 2]) {
        self.resolution = w;
    }

    /// Splits cells until every remaining one has a bound of at least U - tau, with U the lower
    /// of `upper` and the best node so far (tau recomputed from U by `tau_of`), or is at the
    /// resolution, or the budget runs out. Cells whose bound exceeds U are dropped, but kept
    /// aside where it is at most `keep_of(U)` (`|u| u` keeps none).
    pub fn refine(
        &mut self,
        upper: f64,
        tau_of: &dyn Fn(f64) -> f64,
        keep_of: &dyn Fn(f64) -> f64,
    ) {
        let pending: Vec<Cell> = if self.started {
            std::mem::take(&mut self.done)
        } else {
            self.started = true;
            self.start_cells.clone()
        };
        let u_of = |s: &Self| s.best.map_or(upper, |(_, b)| b.min(upper));
        for c in pending {
            self.push(c, u_of(self), tau_of, keep_of);
        }
        while let Some(ByBound(mut cell)) = self.heap.pop() {
            let u = u_of(self);
            let tau = tau_of(u);
            self.target = u - tau;
            if cell.bound.lb >= u - tau {
                self.done.push(cell);
                continue;
            }
            if self.cells >= self.limits.max_cells || self.rows_total() >= self.limits.max_rows {
                if cell.deferred {
                    self.bound_deferred(&mut cell);
                }
                self.unresolved
                    .push((cell, "the search budget ran out".to_string()));
                continue;
            }
            // A cell across the cut no wider there than the cut's width is bounded over its part
            // beyond the cut first, as at the resolution: split on the other axis, its halves
            // stay across the cut, holding points inside the interval below the target that no
            // bound over them whole can clear (`product`'s upper end of eta on 100 000 points of
            // distinct sizes: sigma_y halved down to its resolution, 146 cells, now 43).
            if self.cut.is_some()
                && !self.straddles_cut(&cell)
                && let Some(c) = self.clipped(&cell, u - tau)
            {
                self.done.push(c);
                continue;
            }
            // A deferred cell is bounded here unless it is split on the cut's axis (across the
            // cut and wider there than the cut's width, with room for a dyadic split).
            if cell.deferred && !self.halved_on_cut(&cell) {
                self.bound_deferred(&mut cell);
                if cell.failed || cell.bound.lb >= u - tau {
                    self.push(cell, u, tau_of, keep_of);
                    continue;
                }
            }
            let children = match self.split(&cell) {
                Split::Cells(c) => c,
                // A cell across the cut never comes here wider than the cut's width (it is
                // split on the cut's axis), so its part beyond was bounded above already.
                Split::Fine => {
                    self.fine.push(cell);
                    continue;
                }
                Split::Finest => {
                    self.unresolved.push((
                        cell,
                        "a cell reached the finest dyadic resolution".to_string(),
                    ));
                    continue;
                }
            };
            for c in children {
                self.push(c, u_of(self), tau_of, keep_of);
            }
        }
    }

    fn push(&mut self, c: Cell, u: f64, tau_of: &dyn Fn(f64) -> f64, keep_of: &dyn Fn(f64) -> f64) {
        if !self.within_cut(&c) {
            // No point of it is searched (its edge on the cut, at `at`, is in the cells beyond).
        } else if c.failed {
            let why = self
                .row_failures
                .first()
                .cloned()
                .unwrap_or_else(|| "the lower bound is not a number".into());
            self.unresolved
                .push((c, format!("the model could not be evaluated: {why}")));
        } else if c.bound.lb < u - tau_of(u) {
            self.heap.push(ByBound(c));
        } else if c.bound.lb <= u {
            self.done.push(c);
        } else if c.bound.lb <= keep_of(u) {
            self.kept.push(c);
        }
    }

    /// Whether the node at dyadic position `p` lies in the cut's half-plane (all, without one).
    fn searched(&self, p: [u64; 2]) -> bool {
        self.cut
            .is_none_or(|c| c.keeps(self.axes[c.axis].t_at(p[c.axis])))
    }

    /// Whether some point of the cell lies in the cut's half-plane (all, without a cut), not
    /// counting an edge on the cut's `at` ([`Cut::reaches`]).
    fn within_cut(&self, c: &Cell) -> bool {
        self.reaches(c.p0, c.p1)
    }

    /// [`Bnb::within_cut`] for the cell between dyadic positions `p0` and `p1`.
    fn reaches(&self, p0: [u64; 2], p1: [u64; 2]) -> bool {
        self.cut.is_none_or(|k| {
            let a = &self.axes[k.axis];
            k.reaches(a.t_at(p0[k.axis]), a.t_at(p1[k.axis]))
        })
    }

    /// Whether the cell between dyadic positions `p0` and `p1` has the cut's `at` strictly
    /// inside it.
    fn crosses_cut(&self, p0: [u64; 2], p1: [u64; 2]) -> bool {
        self.cut.is_some_and(|k| {
            let a = &self.axes[k.axis];
            a.t_at(p0[k.axis]) < k.at && k.at < a.t_at(p1[k.axis])
        })
    }

    /// Whether a cell of another branch and bound on the same grid has a point in the cut's
    /// half-plane (a region's, before starting on it: [`Bnb::start_on`] bounds every cell it is
    /// given).
    pub fn reaches_cut(&self, c: &CellBox) -> bool {
        self.cut
            .is_none_or(|k| k.reaches(c.t0[k.axis], c.t1[k.axis]))
    }

    /// A cell across the cut's `at` (no wider there than the cut's width), bounded over its
    /// part in the half-plane alone (between a row at `at` and its far edge): the cell with
    /// that bound where it reaches `target` (it holds no searched point below it), else None.
    /// A cell across the cut holds points outside it, inside an interval, whose chi2 is below
    /// the target: bounded whole it could only be left to a polish.
    fn clipped(&mut self, c: &Cell, target: f64) -> Option<Cell> {
        let k = self.cut?;
        let a = &self.axes[k.axis];
        let (t0, t1) = (a.t_at(c.p0[k.axis]), a.t_at(c.p1[k.axis]));
        if !(t0 < k.at && k.at < t1) {
            return None;
        }
        let cut_row = self.cut_row(k)?;
        let (mut lo, mut hi) = (self.rows_at(c.p0), self.rows_at(c.p1));
        if k.dir > 0.0 {
            lo[k.axis] = cut_row;
        } else {
            hi[k.axis] = cut_row;
        }
        if !(self.rows_ok(lo) && self.rows_ok(hi)) {
            return None;
        }
        self.cells += 1;
        let bound = self.land.bound(lo, hi, target);
        (bound.lb >= target).then_some(Cell {
            bound,
            deferred: false,
            ..*c
        })
    }

    /// The row at the cut's `at` on its axis (made once; None where the model fails there).
    fn cut_row(&mut self, k: Cut) -> Option<usize> {
        let r = match self.cut_row {
            Some(r) => r,
            None => {
                let r = self.add_row(k.axis, k.at);
                self.cut_row = Some(r);
                r
            }
        };
        self.axes[k.axis].ok[r].then_some(r)
    }

    /// Whether the cell crosses the cut's `at` and is wider than its width on the cut's axis.
    fn straddles_cut(&self, c: &Cell) -> bool {
        self.cut.is_some_and(|k| {
            let a = &self.axes[k.axis];
            let (t0, t1) = (a.t_at(c.p0[k.axis]), a.t_at(c.p1[k.axis]));
            t0 < k.at && k.at < t1 && t1 - t0 > k.width
        })
    }

    /// Whether [`Bnb::split`] halves the cell on the cut's axis (whatever its bound): across
    /// the cut, wider there than the cut's width, and not at the finest dyadic resolution.
    fn halved_on_cut(&self, c: &Cell) -> bool {
        self.straddles_cut(c) && self.cut.is_some_and(|k| c.p1[k.axis] - c.p0[k.axis] >= 2)
    }

    fn split(&mut self, c: &Cell) -> Split {
        let width = |k: usize| self.axes[k].t_at(c.p1[k]) - self.axes[k].t_at(c.p0[k]);
        let coarse = |k: usize| self.axes[k].active && width(k) > self.resolution[k];
        let l = c.bound.loose;
        let max_over =
            |f: &dyn Fn(usize) -> bool| (0..2).filter(|&k| f(k)).map(|k| l[k]).fold(0.0, f64::max);
        let lmax = max_over(&|k| coarse(k));
        let lall = max_over(&|k| self.axes[k].active);
        // Split the coarse axes that carry the most looseness (both when comparable); a coarse
        // axis with none to speak of (a plateau: the model does not change along it; 1e-6 of
        // the largest is rounding) is not worth it. A cell across a cut is split on the cut's
        // axis alone, whatever its looseness: its bound covers points outside the cut (inside
        // an interval, below the target), which no split elsewhere removes.
        let across = self
            .straddles_cut(c)
            .then(|| self.cut.map(|k| k.axis))
            .flatten();

        let pick: Vec<usize> = match across {
            Some(k) => vec![k],
            None => (0..2)
                .filter(|&k| coarse(k) && l[k] > 1e-6 * lall && l[k] >= 0.5 * lmax)
                .collect(),
        };
        if pick.is_empty() {
            return Split::Fine;
        }
        let dyadic: Vec<usize> = pick
            .into_iter()
            .filter(|&k| c.p1[k] - c.p0[k] >= 2)
            .collect();
        if dyadic.is_empty() {
            return Split::Finest;
        }
        let cuts = |k: usize| -> Vec<(u64, u64)> {
            if dyadic.contains(&k) {
                let m = c.p0[k] + (c.p1[k] - c.p0[k]) / 2;
                vec![(c.p0[k], m), (m, c.p1[k])]
            } else {
                vec![(c.p0[k], c.p1[k])]
            }
        };
        let mut corners = Vec::with_capacity(4);
        for (a0, a1) in cuts(0) {
            for (b0, b1) in cuts(1) {
                corners.push(([a0, b0], [a1, b1]));
            }
        }
        // The children's new nodes together, in the order their cells would meet them.
        self.nodes_at(
            &corners
                .iter()
                .flat_map(|&(p0, p1)| [p0, [p1[0], p0[1]], [p0[0], p1[1]], p1])
                .collect::<Vec<_>>(),
        );
        Split::Cells(
            corners
                .into_iter()
                .map(|(p0, p1)| self.make_cell(p0, p1))
                .collect(),
        )
    }

    /// Whether the point at internal coordinates `t` may have chi2 below `target` as far as the
    /// bounds know: it lies in a cell left at the resolution, unresolved or still queued whose
    /// bound is below `target`. Every other cell of the box was dropped or set aside with a
    /// bound at or above U - tau for a U at least the current one, and U - tau grows with U, so
    /// for `target` <= U - tau a false answer is a proof (cells are closed: a point on a shared
    /// edge belongs to both; a relative slack of 1e-12 of the box covers the rounding of the
    /// corners' coordinates).
    pub fn may_hold_below(&self, t: [f64; 2], target: f64) -> bool {
        let inside = |c: &Cell| {
            (0..2).all(|k| {
                let a = &self.axes[k];
                if !a.active {
                    return true;
                }
                let slack = 1e-12 * (a.hi - a.lo).abs();
                a.t_at(c.p0[k]) - slack <= t[k] && t[k] <= a.t_at(c.p1[k]) + slack
            })
        };
        // Before the first refinement nothing is proved; NaN coordinates are outside every cell,
        // and nothing is known of them.
        if !self.started || t.iter().any(|x| x.is_nan()) {
            return true;
        }
        self.fine
            .iter()
            .chain(self.unresolved.iter().map(|(c, _)| c))
            .chain(self.heap.iter().map(|b| &b.0))
            .any(|c| !(c.bound.lb >= target) && inside(c))
    }

    /// Every cell whose bound is below `below`, for `below` at most `keep_of(U)` of the last
    /// [`Bnb::refine`]: no other point of the box has chi2 below it (every cell not listed was
    /// dropped with a bound above it, or was kept, set aside or split with one at least U - tau
    /// for a U at least the current one; both grow with U).
    pub fn cells_below(&self, below: f64) -> Vec<CellBox> {
        self.done
            .iter()
            .chain(&self.fine)
            .chain(&self.kept)
            .chain(self.unresolved.iter().map(|(c, _)| c))
            .chain(self.heap.iter().map(|b| &b.0))
            .filter(|c| !(c.bound.lb >= below))
            .map(|c| CellBox {
                p0: c.p0,
                p1: c.p1,
                t0: [0, 1].map(|k| self.axes[k].t_at(c.p0[k])),
                t1: [0, 1].map(|k| self.axes[k].t_at(c.p1[k])),
            })
            .collect()
    }

    /// How many cells were left at the resolution with a bound below `target`.
    pub fn fine_cells_below(&self, target: f64) -> u64 {
        self.fine.iter().filter(|c| !(c.bound.lb >= target)).count() as u64
    }

    /// The certificate for `upper` (see [`Certificate`]).
    pub fn certificate(&self, upper: f64) -> Certificate {
        let lowest = |it: &mut dyn Iterator<Item = &Cell>| {
            it.map(|c| c.bound.lb)
                .fold(f64::INFINITY, |a, b| if b < a { b } else { a })
        };
        let coarse = lowest(
            &mut self
                .done
                .iter()
                .chain(self.unresolved.iter().map(|(c, _)| c))
                .chain(self.heap.iter().map(|b| &b.0)),
        );
        let mut reasons: Vec<String> = Vec::new();
        for (c, w) in &self.unresolved {
            if c.bound.lb < upper && !reasons.contains(w) {
                reasons.push(w.clone());
            }
        }
        Certificate {
            lowest: coarse,
            lowest_fine: lowest(&mut self.fine.iter()),
            fine_cells: self.fine.len(),
            reasons,
        }
    }
}

/// What a [`Bnb`] established.
#[derive(Debug, Clone, PartialEq)]
pub struct Certificate {
    /// No point outside the fine cells has chi2 below this.
    pub lowest: f64,
    /// The lowest bound of the fine cells (+inf without any).
    pub lowest_fine: f64,
    pub fine_cells: usize,
    /// Why some cells with a bound below U were left unresolved (empty when none were).
    pub reasons: Vec<String>,
}

#[cfg(test)]
mod tests;
