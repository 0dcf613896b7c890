//! The known-answer tests of [`super`]'s branch and bound (see its module doc).

use super::*;

/// f(x, y) = g(x) + (y - 0.3)^2 with g having minima at x = -1 (value 0.5) and x = 2
/// (value 0): both parts are monotone on each side of their minima, so the exact range of
/// f over a cell is known and the bound below is exact.
struct TwoWells {
    x: Vec<f64>,
    y: Vec<f64>,
    /// Loosen the bound by the cell's widths (still valid, but it needs splitting).
    loose: bool,
    /// Nodes evaluated so far.
    evaluated: std::cell::Cell<usize>,
    /// The cells bounded so far: lower and upper corners.
    bounded: std::cell::RefCell<Vec<([f64; 2], [f64; 2])>>,
}
fn g(x: f64) -> f64 {
    ((x + 1.0).powi(2) + 0.5).min((x - 2.0).powi(2))
}
fn lowest(f: impl Fn(f64) -> f64, a: f64, b: f64, minima: &[f64]) -> f64 {
    let mut v = f(a).min(f(b));
    for &m in minima {
        if a <= m && m <= b {
            v = v.min(f(m));
        }
    }
    v
}
impl TwoWells {
    fn new(loose: bool) -> Self {
        TwoWells {
            x: vec![],
            y: vec![],
            loose,
            evaluated: Default::default(),
            bounded: Default::default(),
        }
    }
}

/// A budget no test here reaches.
const AMPLE: Limits = Limits {
    max_cells: 100_000,
    max_rows: 10_000,
};

impl Landscape for TwoWells {
    fn add_row(&mut self, axis: usize, t: f64) -> Result<(), String> {
        if axis == 0 {
            self.x.push(t)
        } else {
            self.y.push(t)
        }
        Ok(())
    }
    fn node(&self, r: [usize; 2]) -> f64 {
        self.evaluated.set(self.evaluated.get() + 1);
        g(self.x[r[0]]) + (self.y[r[1]] - 0.3).powi(2)
    }
    fn bound(&self, lo: [usize; 2], hi: [usize; 2], _target: f64) -> Bound {
        self.bounded.borrow_mut().push((
            [self.x[lo[0]], self.y[lo[1]]],
            [self.x[hi[0]], self.y[hi[1]]],
        ));
        // g's minima and the kink where its two branches meet (x = 1/6, where the lower
        // envelope has a local maximum) are the only interior extremes.
        let gx = lowest(g, self.x[lo[0]], self.x[hi[0]], &[-1.0, 2.0]);
        let gy = lowest(
            |y| (y - 0.3f64).powi(2),
            self.y[lo[1]],
            self.y[hi[1]],
            &[0.3],
        );
        let w = [self.x[hi[0]] - self.x[lo[0]], self.y[hi[1]] - self.y[lo[1]]];
        let slack = if self.loose { w[0] + w[1] } else { 0.0 };
        Bound {
            lb: gx + gy - slack,
            loose: w,
        }
    }
}

#[test]
fn certifies_two_wells_and_proposes_both() {
    let land = TwoWells::new(false);
    let limits = AMPLE;
    let mut b = Bnb::new(land, [(-5.0, 5.0), (-1.0, 1.0)], [10, 4], limits);
    let tau = |_: f64| 1e-3;
    let starts = b.initial_minima(f64::INFINITY, 1e-3);
    // The starting grid (x step 1, y step 0.5) has its nodes at x = -1 and 2: both wells.
    assert!(starts.iter().any(|c| c.t[0] == -1.0) && starts.iter().any(|c| c.t[0] == 2.0));
    // With the true minimum 0 as U, everything is certified within tau.
    b.refine(0.0, &tau, &|u| u);
    let c = b.certificate(0.0);
    assert!(
        c.lowest >= -1e-3 && c.lowest <= 0.0 && c.reasons.is_empty() && c.fine_cells == 0,
        "{c:?}"
    );
    // Candidates are proposed only around the global minimum (2, 0.3): each brackets it. The
    // other well (0.5 above) is excluded by its bounds.
    let c = b.candidates(0.0);
    assert!(!c.is_empty());
    for cand in &c {
        let inside = (0..2)
            .all(|k| cand.bracket_lo[k] <= [2.0, 0.3][k] && [2.0, 0.3][k] <= cand.bracket_hi[k]);
        assert!(inside, "{cand:?}");
    }
    // Loose (first-order) bounds need splitting: certified with the budget, unresolved and
    // reported as such with a budget of one cell.
    let land = TwoWells::new(true);
    let mut b = Bnb::new(land, [(-5.0, 5.0), (-1.0, 1.0)], [10, 4], limits);
    b.refine(0.0, &tau, &|u| u);
    let c = b.certificate(0.0);
    assert!(c.lowest >= -1e-3 && c.reasons.is_empty(), "{c:?}");
    assert!(b.cells > 1000, "{}", b.cells);
    let land = TwoWells::new(true);
    let tight = Limits {
        max_cells: 1,
        max_rows: 10_000,
    };
    let mut b = Bnb::new(land, [(-5.0, 5.0), (-1.0, 1.0)], [10, 4], tight);
    b.refine(0.0, &tau, &|u| u);
    let c = b.certificate(0.0);
    assert!(
        c.lowest < -1e-3 && c.reasons.iter().any(|w| w.contains("budget")),
        "{c:?}"
    );
}

#[test]
fn starting_blocks_give_each_cell_a_valid_bound_with_fewer_bounds() {
    // The 10 x 4 starting cells, bounded by 2 x 2 blocks where a block's exact bound reaches
    // the best node (0.04, at x = 2, y = 0.5): each starting cell is its own unit cell of the
    // grid, in row-major order, with a bound at most f's exact minimum over it (the block's
    // bound where the block decided, else its own, which is exact), and fewer bounds were
    // computed than there are cells (blocks far from the wells decide).
    let land = TwoWells::new(false);
    let limits = AMPLE;
    let b = Bnb::new(land, [(-5.0, 5.0), (-1.0, 1.0)], [10, 4], limits);
    assert_eq!(b.start_cells.len(), 40);
    let step = 1u64 << DEPTH;
    let mut by_block = 0;
    for (k, c) in b.start_cells.iter().enumerate() {
        let (i, j) = (k as u64 / 4, k as u64 % 4);
        assert_eq!(
            (c.p0, c.p1),
            ([i * step, j * step], [(i + 1) * step, (j + 1) * step])
        );
        let (x0, x1) = (-5.0 + i as f64, -4.0 + i as f64);
        let (y0, y1) = (-1.0 + 0.5 * j as f64, -0.5 + 0.5 * j as f64);
        let exact =
            lowest(g, x0, x1, &[-1.0, 2.0]) + lowest(|y| (y - 0.3f64).powi(2), y0, y1, &[0.3]);
        assert!(
            c.bound.lb <= exact + 1e-15,
            "cell {i} {j}: {} > {exact}",
            c.bound.lb
        );
        by_block += usize::from(c.bound.lb < exact - 1e-12);
    }
    assert!(by_block > 0, "no cell took a block's (lower) bound");
    assert!(b.cells < 40, "{} bounds for 40 cells", b.cells);
}

/// [`TwoWells`] whose model cannot be evaluated at x = `fails_at` (the row is appended, and
/// reported failed).
struct FailsAt {
    wells: TwoWells,
    fails_at: f64,
}
impl Landscape for FailsAt {
    fn add_row(&mut self, axis: usize, t: f64) -> Result<(), String> {
        self.wells.add_row(axis, t)?;
        if axis == 0 && t == self.fails_at {
            return Err(format!("no model at x = {t}"));
        }
        Ok(())
    }
    fn node(&self, r: [usize; 2]) -> f64 {
        self.wells.node(r)
    }
    fn bound(&self, lo: [usize; 2], hi: [usize; 2], target: f64) -> Bound {
        self.wells.bound(lo, hi, target)
    }
}

#[test]
fn a_row_that_failed_inside_a_starting_block_leaves_its_cells_failed() {
    // x = -4 is the inner row of the block of cells x in [-5, -3] (far from the wells, where a
    // block's bound decides): the block's bound rests on its corner rows and would pass over
    // it. The cells on either side of that row stay failed, and the search says the model
    // could not be evaluated; every other starting cell is as without the failure.
    let limits = AMPLE;
    let land = FailsAt {
        wells: TwoWells::new(false),
        fails_at: -4.0,
    };
    let mut b = Bnb::new(land, [(-5.0, 5.0), (-1.0, 1.0)], [10, 4], limits);
    for (k, c) in b.start_cells.iter().enumerate() {
        let i = k / 4;
        assert_eq!(c.failed, i < 2, "cell {k}: {c:?}");
    }
    b.refine(0.0, &|_| 1e-3, &|u| u);
    let c = b.certificate(0.0);
    assert!(
        c.reasons.iter().any(|w| w.contains("no model at x = -4")),
        "{c:?}"
    );
}

/// Every point of a 201 x 81 sample of the box that `may_hold_below` excludes lies at or above
/// the target; returns how many were excluded and how many points lie below the target (so
/// that the check is not vacuous).
fn check_exclusions(b: &Bnb<TwoWells>, target: f64) -> (usize, usize) {
    let f = |x: f64, y: f64| g(x) + (y - 0.3f64).powi(2);
    let (mut excluded, mut below) = (0, 0);
    for i in 0..=200 {
        for j in 0..=80 {
            let (x, y) = (-5.0 + 0.05 * i as f64, -1.0 + 0.025 * j as f64);
            below += usize::from(f(x, y) < target);
            if !b.may_hold_below([x, y], target) {
                excluded += 1;
                assert!(f(x, y) >= target, "({x}, {y}): {} < {target}", f(x, y));
            }
        }
    }
    (excluded, below)
}

#[test]
fn points_the_bounds_exclude_are_above_the_target() {
    // Loose bounds: fine cells (resolution 0.05) around the global minimum (2, 0.3), whose best
    // node lies above it; then a budget of 200 cells that leaves cells unresolved. In both the
    // target U - tau (U the best node) lies above f somewhere on the sample, and no point below
    // it may be excluded (the proof the valleys' scans rely on; f is exact, the bounds loose).
    let limits = AMPLE;
    let wells = || TwoWells::new(true);
    let tau = 1e-6;
    let mut b = Bnb::new(wells(), [(-5.0, 5.0), (-1.0, 1.0)], [10, 4], limits);
    assert!(b.may_hold_below([-1.0, 0.3], -1.0), "nothing proved yet");
    b.set_resolution([0.05, 0.05]);
    b.refine(f64::INFINITY, &|_| tau, &|u| u);
    let (_, _, u) = b.best_node().unwrap();
    assert!(b.certificate(u).fine_cells > 0 && u > 0.0, "{u}");
    let target = u - tau;
    assert!(b.may_hold_below([2.0, 0.3], target));
    assert!(!b.may_hold_below([-1.0, 0.3], target));
    assert!(!b.may_hold_below([2.0, -0.9], target));
    assert!(b.may_hold_below([f64::NAN, 0.3], target));
    let (excluded, below) = check_exclusions(&b, target);
    assert!(
        excluded > 15_000 && below > 0,
        "{excluded} excluded, {below} below"
    );
    // A target below every bound excludes everything.
    assert!(!b.may_hold_below([2.0, 0.3], -1e9));

    let small = Limits {
        max_cells: 200,
        max_rows: 10_000,
    };
    let mut b = Bnb::new(wells(), [(-5.0, 5.0), (-1.0, 1.0)], [10, 4], small);
    b.refine(f64::INFINITY, &|_| tau, &|u| u);
    let (_, _, u) = b.best_node().unwrap();
    assert!(!b.certificate(u).reasons.is_empty());
    let (excluded, below) = check_exclusions(&b, u - tau);
    assert!(
        excluded > 0 && below > 0,
        "{excluded} excluded, {below} below"
    );
}

/// [`Bnb::cells_below`] covers every point below its level: with the loose bounds (cells get
/// split) and cells kept up to U + 0.7, every point of a 201 x 81 grid over the box with f below
/// 0.6 lies in a listed cell (the second well, 0.5, among them), and every listed cell's bound
/// is below 0.6. Dropping nothing above U (`keep_of` = identity) lists no cell around the
/// second well.
#[test]
fn the_cells_below_a_level_cover_every_point_below_it() {
    let tau = |_: f64| 1e-3;
    let mut b = Bnb::new(
        TwoWells::new(true),
        [(-5.0, 5.0), (-1.0, 1.0)],
        [10, 4],
        AMPLE,
    );
    b.refine(0.0, &tau, &|u| u + 0.7);
    let cells = b.cells_below(0.6);
    let f = |x: f64, y: f64| g(x) + (y - 0.3f64).powi(2);
    let mut below = 0;
    for i in 0..=200 {
        for k in 0..=80 {
            let (x, y) = (-5.0 + 0.05 * i as f64, -1.0 + 0.025 * k as f64);
            if f(x, y) >= 0.6 {
                continue;
            }
            below += 1;
            let covered = cells
                .iter()
                .any(|c| c.t0[0] <= x && x <= c.t1[0] && c.t0[1] <= y && y <= c.t1[1]);
            assert!(covered, "({x}, {y}) f = {} in no cell", f(x, y));
        }
    }
    assert!(below > 100, "{below}");
    assert!(cells.iter().any(|c| c.t0[0] <= -1.0 && -1.0 <= c.t1[0]));
    let mut b = Bnb::new(
        TwoWells::new(true),
        [(-5.0, 5.0), (-1.0, 1.0)],
        [10, 4],
        AMPLE,
    );
    b.refine(0.0, &tau, &|u| u);
    assert!(
        !b.cells_below(0.6)
            .iter()
            .any(|c| c.t0[0] <= -1.0 && -1.0 <= c.t1[0])
    );
}

/// A branch and bound over TwoWells' box of [`Bnb::new`]'s tests, with no cell yet.
fn sparse_two_wells(loose: bool) -> Bnb<TwoWells> {
    Bnb::sparse(
        TwoWells::new(loose),
        [(-5.0, 5.0), (-1.0, 1.0)],
        [10, 4],
        AMPLE,
    )
}

/// The starting cells of that grid (10 cells of x over [-5, 5], 4 of y) whose x index is in
/// `xs`, as dyadic positions.
fn grid_cells(xs: std::ops::Range<u64>) -> Vec<([u64; 2], [u64; 2])> {
    let at = |i: u64| i << DEPTH;
    xs.flat_map(|i| (0..4).map(move |k| ([at(i), at(k)], [at(i + 1), at(k + 1)])))
        .collect()
}

/// [`Bnb::start_on`] searches only the cells given: from the starting cells around the second
/// well (x in [-2, 0]), the best node is that well's minimum 0.5 at (-1, 0.3), certified there
/// to tau, and no node outside the cells is evaluated.
#[test]
fn a_search_on_given_cells_stays_in_them() {
    let tau = |_: f64| 1e-3;
    let mut b = sparse_two_wells(true);
    b.start_on(&grid_cells(3..5), f64::INFINITY);
    b.refine(f64::INFINITY, &tau, &|u| u);
    let (_, t, v) = b.best_node().unwrap();
    assert!(
        (v - 0.5).abs() < 1e-3 && (t[0] + 1.0).abs() < 0.05,
        "{t:?} {v}"
    );
    let c = b.certificate(v);
    assert!(
        c.lowest >= v - 1e-3 - 1e-12 && c.reasons.is_empty(),
        "{c:?}"
    );
    assert!(
        b.land.x.iter().all(|&x| (-2.0..=0.0).contains(&x)),
        "{:?}",
        b.land.x
    );
}

/// [`Bnb::set_polished`]: the cells holding the polished point are split to the resolution
/// without a bound: every cell left that holds the point is no wider than the resolution (with
/// the exact bounds here the starting cell [2, 3] x [0, 0.5] is otherwise kept whole: its bound
/// 0 clears U - tau once a node is within tau of 0). A polished point off the minimum (the
/// second well, 0.5) costs nothing but its cells: they are dropped by their bounds at the
/// resolution, and the minimum, 0 at (2, 0.3), is still found and certified.
#[test]
fn cells_around_a_polished_point_are_left_at_the_resolution() {
    let tau = |_: f64| 1e-3;
    for p in [[2.0, 0.3], [-1.0, 0.3]] {
        // The whole uniform grid as the starting cells, bounded after set_polished.
        let mut b = sparse_two_wells(false);
        b.set_resolution([0.1, 0.1]);
        b.set_polished(p);
        b.start_on(&grid_cells(0..10), f64::INFINITY);
        b.refine(f64::INFINITY, &tau, &|u| u);
        let holds = |c: &Cell| {
            (0..2).all(|k| b.axes[k].t_at(c.p0[k]) <= p[k] && p[k] <= b.axes[k].t_at(c.p1[k]))
        };
        let left: Vec<&Cell> = b.fine.iter().chain(&b.done).filter(|c| holds(c)).collect();
        // At the resolution the cells get their bounds: those around the second well (0.5)
        // are then dropped, those around the minimum kept.
        assert_eq!(left.is_empty(), p[0] == -1.0, "{p:?}");
        for c in left {
            for k in 0..2 {
                assert!(
                    b.axes[k].t_at(c.p1[k]) - b.axes[k].t_at(c.p0[k]) <= 0.1,
                    "{p:?} {:?} {:?} {:?}",
                    [0, 1].map(|k| b.axes[k].t_at(c.p0[k])),
                    [0, 1].map(|k| b.axes[k].t_at(c.p1[k])),
                    c.bound
                );
            }
        }
        let (_, t, v) = b.best_node().unwrap();
        let c = b.certificate(v);
        assert!(c.reasons.is_empty() && c.lowest >= v - 1e-3, "{c:?}");
        assert!(v < 0.01 && (t[0] - 2.0).abs() < 0.1, "{t:?} {v}");
    }
}

/// The search of TwoWells (exact bounds) restricted to `cut` at `resolution`, against the
/// target 0.005 (tau 1e-4), checked clear: no point of the half-plane below the target less tau,
/// nothing left to a polish.
fn cleared_beyond(cut: Cut, resolution: [f64; 2]) -> Bnb<TwoWells> {
    let tau = |_: f64| 1e-4;
    let mut b = sparse_two_wells(false);
    b.set_cut(cut);
    b.set_resolution(resolution);
    b.start_on(&grid_cells(0..10), 0.005 - 1e-4);
    b.refine(0.005, &tau, &|u| u);
    let c = b.certificate(0.005);
    assert!(
        c.lowest >= 0.005 - 1e-4 && c.reasons.is_empty() && c.fine_cells == 0,
        "{c:?}"
    );
    b
}

/// [`Bnb::set_cut`]: restricted to x <= 1.9, the search sees the minimum of that half-plane
/// (g(1.9) = 0.01 on its edge), not the box's (0 at x = 2, beyond it). Against a target of
/// 0.005 no point of the half-plane is lower: certified to tau although the cells across
/// x = 1.9 hold the box's minimum (they are split on x down to the cut's width, 0.01, where
/// none reaches past 1.91, g >= 0.0081), and no node beyond the cut is taken as the best.
/// At a resolution coarser than that width, the cells across the cut are bounded over their
/// part in the half-plane ([`Bnb::clipped`]). Against 0.02 a node below it is found, on the
/// searched side.
#[test]
fn a_search_restricted_to_a_half_plane_ignores_what_lies_beyond() {
    let tau = |_: f64| 1e-4;
    let cut = Cut {
        axis: 0,
        at: 1.9,
        dir: -1.0,
        width: 0.01,
    };
    let mut b = sparse_two_wells(false);
    b.set_cut(cut);
    b.start_on(&grid_cells(0..10), 0.005 - 1e-4);
    b.refine(0.005, &tau, &|u| u);
    if let Some((_, t, v)) = b.best_node() {
        assert!(v >= 0.005 && t[0] <= 1.9, "{t:?} {v}");
    }
    let c = b.certificate(0.005);
    assert!(
        c.lowest >= 0.005 - 1e-4 && c.reasons.is_empty() && c.fine_cells == 0,
        "{c:?}"
    );
    for c in b.cells_below(f64::INFINITY) {
        assert!(c.t0[0] < 1.9, "{c:?}");
        if c.t1[0] > 1.9 {
            assert!(c.t1[0] - c.t0[0] <= 0.01, "{c:?}");
        }
    }
    // With a resolution of 0.3 the cell across x = 1.9 stops at [1.75, 2] on x: bounded whole
    // it holds x = 2 (0), and over its part x <= 1.9 alone (a row at 1.9) it clears the
    // target: nothing is left to a polish.
    let b = cleared_beyond(Cut { width: 0.3, ..cut }, [0.3, 0.3]);
    assert!(b.land.x.contains(&1.9), "{:?}", b.land.x);
    assert!(
        b.cells_below(f64::INFINITY)
            .iter()
            .any(|c| c.t0[0] == 1.75 && c.t1[0] == 2.0),
        "the cell [1.75, 2] across the cut was not cleared"
    );
    // Without the cut the same cells hold chi2 0 < 0.005.
    let mut b = sparse_two_wells(false);
    b.start_on(&grid_cells(0..10), 0.005 - 1e-4);
    b.refine(0.005, &tau, &|u| u);
    assert!(b.best_node().unwrap().2 < 0.005);
    // A target the half-plane reaches below.
    let mut b = sparse_two_wells(false);
    b.set_cut(cut);
    b.start_on(&grid_cells(0..10), 0.02 - 1e-4);
    b.refine(0.02, &tau, &|u| u);
    let (_, t, v) = b.best_node().unwrap();
    assert!((0.01..0.02).contains(&v) && t[0] <= 1.9, "{t:?} {v}");
    for c in b.candidates(0.02) {
        assert!(c.t[0] <= 1.9, "{c:?}");
    }
}

/// [`Bnb::set_known_nodes`]: a search beyond a cut started on another search's cells, given
/// that search's nodes at their corners ([`Bnb::known_nodes`]), is the same search (the same
/// rows in the same order, best node, certificate, cells and candidates) without evaluating
/// those nodes again; and a known value is what the search takes (a deliberately wrong one
/// shows through), so it is not computed anyway.
#[test]
fn known_nodes_spare_their_evaluation_and_change_nothing_else() {
    let tau = |_: f64| 1e-3;
    let mut first = sparse_two_wells(true);
    first.start_on(&grid_cells(0..10), f64::INFINITY);
    first.refine(f64::INFINITY, &tau, &|u| u);
    let region = first.cells_below(0.6);
    let known = first.known_nodes(&region);
    assert!(!known.0.is_empty());
    let cut = Cut {
        axis: 0,
        at: 1.9,
        dir: -1.0,
        width: 0.01,
    };
    let search = |known: Option<KnownNodes>| {
        let mut b = sparse_two_wells(true);
        b.set_cut(cut);
        if let Some(k) = known {
            b.set_known_nodes(k);
        }
        let cells: Vec<([u64; 2], [u64; 2])> = (region.iter())
            .filter(|c| b.reaches_cut(c))
            .map(|c| (c.p0, c.p1))
            .collect();
        assert!(!cells.is_empty());
        b.start_on(&cells, 0.6 - 1e-3);
        b.refine(0.6, &tau, &|u| u);
        b
    };
    let (mut plain, mut seeded) = (search(None), search(Some(known.clone())));
    assert_eq!(plain.land.x, seeded.land.x);
    assert_eq!(plain.land.y, seeded.land.y);
    assert_eq!(plain.best_node(), seeded.best_node());
    assert_eq!(plain.certificate(0.6), seeded.certificate(0.6));
    assert_eq!(plain.cells, seeded.cells);
    assert_eq!(plain.cells_below(0.6), seeded.cells_below(0.6));
    let (a, b) = (plain.land.evaluated.get(), seeded.land.evaluated.get());
    assert!(
        b < a,
        "{b} nodes evaluated with the known ones, {a} without"
    );
    assert_eq!(plain.candidates(0.6), seeded.candidates(0.6));
    // The best node of the search (before its candidates, which evaluate nodes of their
    // own), given a known value far below: taken as it is.
    let (p, _) = search(Some(known.clone())).best.unwrap();
    let mut wrong = known;
    wrong.0.insert(p, -7.0);
    assert_eq!(search(Some(wrong)).best_node().map(|b| b.2), Some(-7.0));
}

/// A cell across the cut no wider there than the cut's width is bounded over its part beyond
/// the cut before any split: with the resolution on x (0.3) above the width of the starting cell
/// [1.75, 2] across x = 1.9, that cell is cleared whole, not halved on y down to y's
/// resolution (0.01), where each half, still across the cut and holding g(2) = 0 below the
/// target, would only have been cleared at the end by the same bound over its part beyond.
#[test]
fn a_narrow_cell_across_the_cut_is_bounded_over_its_part_beyond_before_any_split() {
    let cut = Cut {
        axis: 0,
        at: 1.9,
        dir: -1.0,
        width: 0.3,
    };
    let b = cleared_beyond(cut, [0.3, 0.01]);
    let across: Vec<CellBox> = b
        .cells_below(f64::INFINITY)
        .into_iter()
        .filter(|c| c.t0[0] < 1.9 && 1.9 < c.t1[0])
        .collect();
    assert!(!across.is_empty());
    for c in across {
        assert!(c.t1[1] - c.t0[1] >= 0.5 - 1e-12, "{c:?}");
    }
}

/// [`Bnb::make_cell`]: beyond a cut at x = 1.7 (x <= 1.7 searched, its lowest point g(1.7) =
/// 0.09 above the target 0.06), the cells across x = 1.7 hold nodes at x = 2 below the target
/// (g(2) = 0 plus (y - 0.3)^2 <= 0.09): such a cell wider than the cut's width is halved on x
/// without a bound, and a cell wholly beyond the cut is dropped without one, so fewer cells are
/// bounded than made (each was before). The search is certified clear all the same.
#[test]
fn cells_across_the_cut_with_a_corner_below_the_target_are_split_unbounded() {
    let (target, tau) = (0.06, 1e-4);
    let cut = Cut {
        axis: 0,
        at: 1.7,
        dir: -1.0,
        width: 0.01,
    };
    let mut b = sparse_two_wells(false);
    b.set_cut(cut);
    b.start_on(&grid_cells(0..10), target - tau);
    b.refine(target, &|_| tau, &|u| u);
    let c = b.certificate(target);
    assert!(
        c.lowest >= target - tau && c.reasons.is_empty() && c.fine_cells == 0,
        "{c:?}"
    );
    let (_, t, v) = b.best_node().unwrap();
    assert!(v >= target && t[0] <= 1.7, "{t:?} {v}");
    let f = |x: f64, y: f64| g(x) + (y - 0.3f64).powi(2);
    let bounded = b.land.bounded.borrow();
    for &(lo, hi) in bounded.iter() {
        assert!(
            lo[0] < 1.7,
            "a cell wholly beyond the cut was bounded: {lo:?} {hi:?}"
        );
        let corner = [lo[0], hi[0]]
            .iter()
            .flat_map(|&x| [lo[1], hi[1]].map(|y| f(x, y)))
            .fold(f64::INFINITY, f64::min);
        let wide_across = lo[0] < 1.7 && 1.7 < hi[0] && hi[0] - lo[0] > cut.width;
        assert!(
            !(wide_across && corner < target - tau),
            "a cell across the cut with a corner at {corner} was bounded: {lo:?} {hi:?}"
        );
    }
    assert!(
        (bounded.len() as u64) < b.cells,
        "{} bounds for {} cells",
        bounded.len(),
        b.cells
    );
}
