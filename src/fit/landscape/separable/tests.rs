use super::*;
use crate::contact::Material;
use crate::fit::dataset::{FitData, Observation};
use crate::fit::lsq;
use crate::fit::models::{Evaluator, ModelKind};
use crate::models::viscoelastic::{ContactEnd, VmMethod};

const KINDS: [ModelKind; 4] = [
    ModelKind::Vm,
    ModelKind::Pm,
    ModelKind::Min,
    ModelKind::Product,
];

/// Points on three sizes and a wall over speeds 0.4 to 0.4 x 1.12^(n-1) m/s, every speed moved
/// a little (distinct points). `model`: e from `min` at eta = 190, sigma_y = 4e7 plus a fixed
/// scatter of 0.01 (a landscape with a minimum); else a fixed pattern with no model behind it.
fn data(n: usize, model: bool) -> FitData {
    let m = Material::preset("nylon").unwrap();
    let mut obs: Vec<Observation> = (0..n)
        .map(|k| Observation {
            d_mm: [6.35, 12.7, 25.4, 12.7][k % 4],
            d2_mm: if k % 4 == 3 {
                Some(f64::INFINITY)
            } else {
                None
            },
            v_n_m_s: 0.4
                * 1.12f64.powi((k % 40) as i32)
                * (1.0 + 1e-3 * ((k * 7919 % 2001) as f64 / 1000.0 - 1.0)),
            e: 0.97 - 0.006 * (k % 40) as f64 + 0.02 * ((k * 7 % 5) as f64 - 2.0) / 2.0,
            e_err: Some(0.01 + 0.001 * (k % 3) as f64),
        })
        .collect();
    if model {
        let d = FitData::new(m, obs.clone()).unwrap();
        let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
        let mut e = vec![0.0; n];
        ev.predict(ModelKind::Min, &[190.0, 4e7], &mut e).unwrap();
        for (k, o) in obs.iter_mut().enumerate() {
            o.e = e[k] + 0.01 * ((k * 7 % 5) as f64 - 2.0) / 2.0;
        }
    }
    FitData::new(m, obs).unwrap()
}

/// chi2 at internal coordinates t (log eta, log sigma_y), straight from the model.
fn direct(obj: &Objective, t: [f64; 2]) -> f64 {
    let theta = match obj.kind {
        ModelKind::Vm => vec![t[0]],
        ModelKind::Pm => vec![t[1]],
        _ => vec![t[0], t[1]],
    };
    lsq::chi2(obj, &theta).unwrap()
}

/// The landscape of `kind` with the two rows of each axis of one cell.
fn cell_landscape<'a>(obj: &'a Objective<'a>, lo: [f64; 2], hi: [f64; 2]) -> Separable<'a> {
    let kind = obj.kind;
    let active = [kind != ModelKind::Pm, kind != ModelKind::Vm];
    let mut l = Separable::new(obj, kind == ModelKind::Min, active);
    l.second_order = true;
    for k in 0..2 {
        l.add_row(k, lo[k]).unwrap();
        l.add_row(k, hi[k]).unwrap();
    }
    l
}

/// The least chi2 on an m x m grid of the cell (corners included).
fn sampled_min(obj: &Objective, lo: [f64; 2], hi: [f64; 2], m: usize) -> f64 {
    let mut lowest = f64::INFINITY;
    for i in 0..m {
        for j in 0..m {
            let f = |k: usize, a: usize| lo[k] + (hi[k] - lo[k]) * a as f64 / (m - 1) as f64;
            lowest = lowest.min(direct(obj, [f(0, i), f(1, j)]));
        }
    }
    lowest
}

/// Every bound, whatever the target it is asked for (or none: every pass), lies below chi2 sampled densely in its
/// cell (an m x m grid; chi2 computed from the model, not from the rows), and is finite and
/// non-negative. Rounding allowed: 1e-12 relative (the two sides sum the same squares in
/// different forms).
fn check(d: &FitData, rule: ContactEnd, cells: &[([f64; 2], [f64; 2])], m: usize) {
    let ev = Evaluator::new(d, rule, VmMethod::Master);
    for kind in KINDS {
        let obj = Objective::new(&ev, kind).unwrap();
        for &(lo, hi) in cells {
            let l = cell_landscape(&obj, lo, hi);
            let lowest = sampled_min(&obj, lo, hi, m);
            let targets = [f64::NEG_INFINITY, 0.5 * lowest, lowest, f64::INFINITY];
            let full = l.bound_with([0, 0], [1, 1], None).lb;
            for b in targets
                .map(|t| l.bound([0, 0], [1, 1], t).lb)
                .into_iter()
                .chain([full])
            {
                assert!(
                    b <= lowest * (1.0 + 1e-12),
                    "{kind} {rule:?} {lo:?} {hi:?}: {b} > {lowest}"
                );
                assert!(b >= 0.0 && b.is_finite(), "{kind} {lo:?} {hi:?}: {b}");
            }
        }
    }
}

/// Cells of widths 1e-4 to 3 in each log parameter around the minimum of the model data, away
/// from it, across the yield edge (sigma_y where the points start to yield) and on the plateau
/// where none yields.
fn cells() -> Vec<([f64; 2], [f64; 2])> {
    let (e, s) = (190f64.ln(), 4e7f64.ln());
    let mut out = Vec::new();
    for (ce, cs) in [
        (e, s),
        (e + 0.02, s - 0.01),
        (e + 1.5, s - 1.0),
        (e - 2.0, s + 0.5),
        (e, s + 1.5),
        (e + 0.3, s + 4.0),
    ] {
        for (w0, w1) in [
            (1e-4, 1e-4),
            (1e-2, 3e-3),
            (0.1, 0.3),
            (1.0, 0.05),
            (3.0, 2.0),
        ] {
            out.push((
                [ce - 0.4 * w0, cs - 0.6 * w1],
                [ce + 0.6 * w0, cs + 0.4 * w1],
            ));
        }
    }
    out
}

#[test]
fn bounds_are_below_chi2_everywhere_in_their_cells_of_every_size() {
    for model in [true, false] {
        check(&data(40, model), ContactEnd::Overlap, &cells(), 17);
    }
    check(&data(40, true), ContactEnd::Force, &cells(), 9);
}

#[test]
fn large_data_bounds_are_below_chi2_everywhere_in_their_cells() {
    // Above the parallel threshold the sums are chunked and the looseness sampled: a few cells
    // of each size class on distinct points.
    let d = data(sums::PARALLEL_MIN_POINTS + 1000, true);
    assert!(sums::is_large(d.len()));
    let cells: Vec<_> = cells().into_iter().step_by(4).collect();
    check(&d, ContactEnd::Overlap, &cells, 7);
}

#[test]
fn large_data_cells_the_sample_predicts_are_decided_by_the_first_order_pass_alone() {
    // Where the sample's first-order bound, scaled to every point, clears the target by
    // FIRST_ONLY_MARGIN, the bound returned is the first-order pass's over every point (bit for
    // bit), at least the target, and below chi2 everywhere in the cell, with no pass of the
    // relaxation's terms; a target between the sample's and the full first-order bound is the
    // case. Counted, so the path is shown taken.
    let d = data(sums::PARALLEL_MIN_POINTS + 1000, true);
    let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
    let mut taken = 0;
    for kind in KINDS {
        let obj = Objective::new(&ev, kind).unwrap();
        for (lo, hi) in cells().into_iter().step_by(2) {
            let l = cell_landscape(&obj, lo, hi);
            let first = l.first_order_pass(&l.cell([0, 0], [1, 1]));
            let sample = l.pass(&l.sample_cell([0, 0], [1, 1]), [0.5, 0.5], true, true);
            let scale = l.n as f64 / l.sample.points.len() as f64;
            let target = scale * sample.first / FIRST_ONLY_MARGIN;
            if !(first > 0.0 && target > sample.first && first >= target) {
                continue;
            }
            let before = l.passes.get();
            let b = l.bound([0, 0], [1, 1], target).lb;
            let after = l.passes.get();
            let lowest = sampled_min(&obj, lo, hi, 7);
            assert!(
                b <= lowest * (1.0 + 1e-12),
                "{kind} {lo:?} {hi:?}: {b} > {lowest}"
            );
            assert!(b >= target, "{kind} {lo:?} {hi:?}: {b} < {target}");
            assert_eq!(b.to_bits(), first.to_bits(), "{kind} {lo:?} {hi:?}");
            assert_eq!(
                [after[0] - before[0], after[1] - before[1]],
                [0, 1],
                "{kind} {lo:?} {hi:?}: passes (relaxation, first-order alone)"
            );
            taken += 1;
        }
    }
    assert!(taken >= 5, "{taken} cells decided by the first-order pass");
}

#[test]
fn the_bound_is_second_order_in_the_cell_width() {
    // Near the minimum of the model data (where the search spends its cells) the first-order
    // bound's gap to chi2 falls like the width h and the second-order one's like h^2 (or
    // vanishes, when chi2 is least at a corner: the bands are zero there). A quarter of the
    // width must cut the second-order gap by more than 8 (16 in the limit; a first-order bound
    // gives 4), unless it is already below 1e-6 of chi2, and at h = 0.005 it must be under a
    // tenth of the first-order gap.
    let d = data(40, true);
    let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
    for kind in KINDS {
        let obj = Objective::new(&ev, kind).unwrap();
        for (ce, cs) in [
            (190f64.ln(), 4e7f64.ln()),
            (190f64.ln() + 0.1, 4e7f64.ln() - 0.05),
        ] {
            let gaps = |h: f64| {
                let (lo, hi) = ([ce - 0.5 * h, cs - 0.5 * h], [ce + 0.5 * h, cs + 0.5 * h]);
                let l = cell_landscape(&obj, lo, hi);
                let lowest = sampled_min(&obj, lo, hi, 17);
                let b = l.bound_with([0, 0], [1, 1], None);
                let first = l
                    .pass(&l.cell([0, 0], [1, 1]), [0.5, 0.5], true, false)
                    .first;
                // The first-order bound is not exact here (the data straddle the model).
                assert!(
                    lowest - first > 1e-4 * lowest,
                    "{kind}: {first} vs {lowest}"
                );
                (lowest - b.lb, lowest - first, lowest)
            };
            let (g2, _, _) = gaps(0.02);
            let (h2, h1, lowest) = gaps(0.005);
            eprintln!("{kind} {ce} {cs}: second {g2:e} -> {h2:e}, first {h1:e}");
            assert!(g2 >= 0.0 && h2 >= 0.0, "{kind}: {g2} {h2}");
            assert!(h2 < 0.1 * h1, "{kind}: {h2} vs first order {h1}");
            assert!(h2 < g2 / 8.0 || h2 < 1e-6 * lowest, "{kind}: {g2} -> {h2}");
        }
    }
}

#[test]
fn every_factor_lies_in_its_band_over_its_cell() {
    // F's band rests on a curvature bound taken at each point's loss at the cell's far end
    // (`Cell::q_at`): e_vm from 0.999 down to about 0.03 (eta from 1 to 3e4 on these points),
    // and e_pm from below yield to far past it (sigma_y from 1e5 to 1e9 Pa), cells 1e-3 to 2
    // wide in each log parameter. At 33 points inside each cell every point's factor, computed
    // by the model, must lie within its band around the linear interpolant of its corner rows:
    // |F(s) - (f0 + s (f1 - f0))| <= c + a s (1 - s), and likewise G in u. No tolerance: the
    // band's c holds the factor's own error.
    let d = data(40, true);
    let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
    let obj = Objective::new(&ev, ModelKind::Product).unwrap();
    let mut quadratic = [0usize; 2];
    for (c0, c1) in [
        (0.0, 12.0),
        (3.0, 14.0),
        (5.2, 16.5),
        (7.0, 17.5),
        (10.3, 20.7),
    ] {
        for w in [1e-3, 0.05, 0.5, 2.0] {
            let (lo, hi) = ([c0 - 0.5 * w, c1 - 0.5 * w], [c0 + 0.5 * w, c1 + 0.5 * w]);
            let l = cell_landscape(&obj, lo, hi);
            let cell = l.cell([0, 0], [1, 1]);
            for j in 1..34 {
                let s = j as f64 / 34.0;
                let rows = [0, 1].map(|k| ev.row(k, lo[k] + s * (hi[k] - lo[k])));
                for i in 0..d.len() {
                    let bands = cell.bands(i);
                    let ends = [(cell.f0[i], cell.f1[i]), (cell.g0[i], cell.g1[i])];
                    for (k, (row, (a, b))) in rows.iter().zip(ends).enumerate() {
                        let off = (row[i] - (a + s * (b - a))).abs();
                        let band = bands[k].c + bands[k].a * s * (1.0 - s);
                        assert!(
                            off <= band,
                            "axis {k}, cell {lo:?} {hi:?}, point {i}, s {s}: {off} > {band}"
                        );
                        if bands[k].a > 0.0 {
                            quadratic[k] += 1;
                        }
                    }
                }
            }
        }
    }
    // Both axes' quadratic bands were put to the test, not only the constant ones.
    assert!(quadratic[0] > 1000 && quadratic[1] > 1000, "{quadratic:?}");
}

#[test]
fn newton_steps_stay_in_the_cell_and_stop_without_curvature() {
    // A quadratic with its minimum at (0.8, 0.3) is reached in one step; one outside the cell
    // (at (1.5, 0.3), no correlation) is clipped to s = 1 with u re-minimised to 0.3; a model
    // with no curvature has no step.
    let h = [2.0, 0.0, 4.0];
    let g_at = |x: [f64; 2], m: [f64; 2]| [2.0 * (x[0] - m[0]), 4.0 * (x[1] - m[1])];
    let y = newton_step([0.5, 0.5], g_at([0.5, 0.5], [0.8, 0.3]), h).unwrap();
    assert!(
        (y[0] - 0.8).abs() < 1e-9 && (y[1] - 0.3).abs() < 1e-9,
        "{y:?}"
    );
    let y = newton_step([0.5, 0.5], g_at([0.5, 0.5], [1.5, 0.3]), h).unwrap();
    assert!(y[0] == 1.0 && (y[1] - 0.3).abs() < 1e-9, "{y:?}");
    assert!(newton_step([0.5, 0.5], [1.0, 1.0], [0.0; 3]).is_none());
}

/// A pass's sums as the per-point terms were first written (branches, `Cell::enclosure` and
/// `pick`), over every point in order: the reference for `kernel.rs`.
fn reference_terms(l: &Separable, cell: &Cell, x: [f64; 2], first: bool) -> kernel::Terms {
    reference_terms_of(l, cell, x, first, 0..l.n)
}

/// [`reference_terms`] over `points`: the k-th of them added into lane k mod 4 of the sums,
/// each lane in their order, the lanes then added as (l0 + l1) + (l2 + l3) (`kernel::run`'s
/// stated order).
fn reference_terms_of(
    l: &Separable,
    cell: &Cell,
    x: [f64; 2],
    first: bool,
    points: impl Iterator<Item = usize>,
) -> kernel::Terms {
    let mut lanes = [kernel::Terms::default(); kernel::LANES];
    for (k, i) in points.enumerate() {
        let s = &mut lanes[k % kernel::LANES];
        let (ei, wi) = (l.e[i], l.w[i]);
        if first {
            let d = cell.first_order_gap(i, ei);
            s.first += wi * d * d;
        }
        let enc = cell.enclosure(i);
        let (lo, glo) = cell::pick(&enc.lo, x, false);
        let (hi, ghi) = cell::pick(&enc.hi, x, true);
        let r = enc.r0 + enc.r2[0] * x[0] * (1.0 - x[0]) + enc.r2[1] * x[1] * (1.0 - x[1]);
        let gr = [
            enc.r2[0] * (1.0 - 2.0 * x[0]),
            enc.r2[1] * (1.0 - 2.0 * x[1]),
        ];
        let (d, grad) = if ei < lo - r {
            (lo - r - ei, [glo[0] - gr[0], glo[1] - gr[1]])
        } else if ei > hi + r {
            (ei - hi - r, [-ghi[0] - gr[0], -ghi[1] - gr[1]])
        } else {
            continue;
        };
        let wd = wi * d;
        s.phi += wd * d;
        for (k, gk) in grad.iter().enumerate() {
            s.g[k] += 2.0 * wd * gk;
            s.g_abs[k] += (2.0 * wd * gk).abs();
        }
        let w2 = 2.0 * wi;
        s.h[0] += w2 * (grad[0] * grad[0] + 2.0 * d * enc.r2[0]);
        s.h[1] += w2 * grad[0] * grad[1];
        s.h[2] += w2 * (grad[1] * grad[1] + 2.0 * d * enc.r2[1]);
    }
    let pair = |f: &dyn Fn(&kernel::Terms) -> f64| {
        (f(&lanes[0]) + f(&lanes[1])) + (f(&lanes[2]) + f(&lanes[3]))
    };
    kernel::Terms {
        first: pair(&|t| t.first),
        phi: pair(&|t| t.phi),
        g: [pair(&|t| t.g[0]), pair(&|t| t.g[1])],
        g_abs: [pair(&|t| t.g_abs[0]), pair(&|t| t.g_abs[1])],
        h: [pair(&|t| t.h[0]), pair(&|t| t.h[1]), pair(&|t| t.h[2])],
    }
}

#[test]
fn a_sample_sums_every_thirteenth_point_of_each_chunk_bit_for_bit() {
    // The sampled pass of large data runs over its own contiguous copy of the points: its
    // sums must be those of every LOOSE_STRIDE-th point of each chunk of the full data, taken
    // in place, each chunk in point order and the chunks in order (no tolerance).
    let d = data(sums::PARALLEL_MIN_POINTS + 1000, true);
    let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
    let mut compared = 0;
    for kind in KINDS {
        let obj = Objective::new(&ev, kind).unwrap();
        for (lo, hi) in cells().into_iter().step_by(3) {
            let l = cell_landscape(&obj, lo, hi);
            let cell = l.cell([0, 0], [1, 1]);
            for x in [[0.5, 0.5], [0.17, 0.83]] {
                let got = l.pass(&l.sample_cell([0, 0], [1, 1]), x, true, true);
                let mut want = [0.0; 9];
                for c in 0..l.n.div_ceil(sums::CHUNK) {
                    let points =
                        (c * sums::CHUNK..((c + 1) * sums::CHUNK).min(l.n)).step_by(LOOSE_STRIDE);
                    let t = reference_terms_of(&l, &cell, x, true, points);
                    let t = [
                        t.first, t.phi, t.g[0], t.g[1], t.g_abs[0], t.g_abs[1], t.h[0], t.h[1],
                        t.h[2],
                    ];
                    for (w, t) in want.iter_mut().zip(t) {
                        *w += t;
                    }
                }
                let got = [
                    got.first,
                    got.phi,
                    got.g[0],
                    got.g[1],
                    got.g_abs[0],
                    got.g_abs[1],
                    got.h[0],
                    got.h[1],
                    got.h[2],
                ];
                assert_eq!(
                    got.map(f64::to_bits),
                    want.map(f64::to_bits),
                    "{kind} {lo:?} {hi:?} {x:?}"
                );
                compared += usize::from(want[1] > 0.0);
            }
        }
    }
    assert!(compared > 10, "{compared} cases with phi > 0");
}

#[test]
fn the_branch_free_kernel_sums_what_the_stated_enclosure_gives_bit_for_bit() {
    // Same operations in the same order, only selects for branches: every sum equal to the
    // last bit (no tolerance; the reference adds in the kernel's lanes), on both kinds of data, every rule and cell size class, at the
    // centre, corners, edges and points inside (where the Newton steps go), for first and
    // later passes. Data of 40 points: small enough that the kernel sums them in one run, in
    // the order the reference does.
    let xs = [
        [0.5, 0.5],
        [0.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [1.0, 0.3],
        [0.17, 0.83],
        [0.71, 0.02],
    ];
    let mut compared = 0;
    for model in [true, false] {
        let d = data(40, model);
        for rule in [ContactEnd::Overlap, ContactEnd::Force] {
            let ev = Evaluator::new(&d, rule, VmMethod::Master);
            for kind in KINDS {
                let obj = Objective::new(&ev, kind).unwrap();
                for (lo, hi) in cells() {
                    let l = cell_landscape(&obj, lo, hi);
                    let cell = l.cell([0, 0], [1, 1]);
                    for x in xs {
                        for first in [true, false] {
                            let want = reference_terms(&l, &cell, x, first);
                            let got = l.pass(&cell, x, first, false);
                            let bits = |t: [f64; 9]| t.map(f64::to_bits);
                            let flat = |t: &kernel::Terms| {
                                [
                                    t.first, t.phi, t.g[0], t.g[1], t.g_abs[0], t.g_abs[1], t.h[0],
                                    t.h[1], t.h[2],
                                ]
                            };
                            let got_t = kernel::Terms {
                                first: got.first,
                                phi: got.phi,
                                g: got.g,
                                g_abs: got.g_abs,
                                h: got.h,
                            };
                            assert_eq!(
                                bits(flat(&got_t)),
                                bits(flat(&want)),
                                "{kind} {rule:?} {lo:?} {hi:?} {x:?} first {first}"
                            );
                            compared += usize::from(want.phi > 0.0);
                        }
                    }
                }
            }
        }
    }
    // Most cases have points outside their intervals (the test is not of zeros alone).
    assert!(compared > 500, "{compared} cases with phi > 0");
}

#[test]
fn a_grid_of_nodes_is_each_node_alone_bit_for_bit() {
    // The starting grid's nodes (and a list of nodes) summed together (four lanes, transposed blocks) against each
    // node's own pass: the same bits, small data (one range) and large (chunks), both rules,
    // with row counts that are not multiples of the four lanes and a point count that is not
    // a multiple of the block.
    for n in [121, sums::PARALLEL_MIN_POINTS + 1003] {
        let d = data(n, true);
        let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
        for kind in KINDS {
            let obj = Objective::new(&ev, kind).unwrap();
            let active = [kind != ModelKind::Pm, kind != ModelKind::Vm];
            let mut l = Separable::new(&obj, kind == ModelKind::Min, active);
            for k in 0..5 {
                l.add_row(0, (120.0 + 40.0 * k as f64).ln()).unwrap();
            }
            for k in 0..7 {
                l.add_row(1, (1e7 * 1.6f64.powi(k)).ln()).unwrap();
            }
            let (r0, r1) = ([4, 0, 2, 3], [6, 1, 0, 2, 5, 3, 4]);
            let got = l.nodes_grid(&r0, &r1);
            let mut want = Vec::new();
            for a in r0 {
                for b in r1 {
                    want.push(l.node([a, b]).to_bits());
                }
            }
            assert_eq!(
                got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                want,
                "{kind}, {n} points"
            );
            assert!(got.iter().all(|v| *v > 0.0), "{kind}: sums of squares");
            // A list of nodes (a split's new corners), five of them: a full group of four
            // lanes and a short one, repeats allowed.
            let pairs = [[0, 0], [4, 6], [2, 2], [3, 5], [2, 2]];
            let got = l.nodes_list(&pairs);
            let want: Vec<u64> = pairs.iter().map(|&r| l.node(r).to_bits()).collect();
            assert_eq!(
                got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                want,
                "{kind}, {n} points, list"
            );
        }
    }
}

/// The rows' NaN scan finds a NaN wherever it is (first, inside a block, in a short last block)
/// and none in a row without one.
#[test]
fn a_nan_anywhere_in_a_row_is_found() {
    let n = 1000;
    assert!(!has_nan(&vec![0.5; n]));
    assert!(!has_nan(&[]));
    for at in [0, 1, 255, 256, 700, 999] {
        let mut row = vec![0.5; n];
        row[at] = f64::NAN;
        assert!(has_nan(&row), "{at}");
    }
}
