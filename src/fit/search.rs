//! The global minimum of chi2 for every model, shown global rather than hoped for.
//!
//! **Solves** min chi2 over the model's search box ([`super::objective`]) and establishes, for
//! the value U it reports: (1) outside small cells around the minima, no point of the box has
//! chi2 below U - tau, tau = 1e-7 U + 1e-6 s (s the chi2 scale; far below anything a user could
//! see); (2) inside those cells, every local minimum of the grid that could beat U was polished.
//!
//! **Argument.** At every point, each model's e is monotone in each search coordinate with the
//! others fixed (e_vm falls with eta, e_pm rises with sigma_y, min and product rise with both),
//! or, for the power law, linear in the one parameter profiled out (A); so the model's range over
//! any grid cell, hence a lower bound of chi2 over the whole cell, follows from the cell's corner
//! rows alone ([`super::landscape`]; widened by the model's accuracy, and tested against chi2
//! sampled inside cells). Branch and bound ([`super::bnb`]) starts from a uniform grid (log eta
//! in 24 cells of about 1, log sigma_y in 16, the power law's exponents in 10 x 10 cells of 2)
//! and splits, lowest bound first, only the cells whose bound is below U - tau, down to 40
//! halvings: a cell it drops holds no point below U - tau whatever the shape of chi2 inside it,
//! so no valley, however narrow, is missed (the old search scanned log eta in steps of 0.5 and
//! could lock onto the wrong eta valley). First-order bounds cannot close the last gap around a
//! smooth minimum (the cells needed grow like 1/tau), so splitting stops at a resolution of a
//! fraction of a standard error (1/4 for one parameter and for `min` and `product`, 1 for the
//! smooth power law; 1/4096 of the box for a parameter the data do not determine, where a
//! plateau may end in a narrow dip as a point starts to yield): those fine cells are where
//! local polishes take over, not a place the search skipped.
//!
//! **Polishes** ([`super::polish`], [`super::kinks`], [`super::powerlaw`]): from every grid-local
//! minimum (a node not above its neighbours at its cell's scale) in a cell whose bound could beat
//! U: Brent's method for one parameter, Levenberg-Marquardt for two, Levenberg-Marquardt over the
//! power law's exponents with A profiled out. For `min`, starts mirrored across nearby kinks
//! (one per cell of the resolution, none where the bounds already exclude chi2 below U - tau:
//! [`super::bnb::Bnb::may_hold_below`]). The minima within 1e-5 relative of the best are
//! finished, once per cell of the resolution: for `min`, rounds of Brent on the profiles where
//! Levenberg-Marquardt ran out of iterations or stopped on a kink short of the minimum by more
//! than tau as far as its Gauss-Newton step tells ([`super::lsq::gauss_newton_decrease`]),
//! while a round gains more than tau; for the others, damped Newton where it ran out of
//! iterations; for all, line searches along the covariance's axes (whose scans skip the points
//! where the bounds already exclude chi2 below U - tau). On many points of many sizes some
//! point is always near its kink, and the kinks are many and weak: these rules keep the work
//! of such a fit that of any other. The reported minimum is the lowest polished point, the best
//! grid node only where every polish ended above it by more than the rounding of the sums (a
//! node and a polish sum chi2 in different orders). A point below the certified bound would
//! contradict the bounds: a warning, never ignored.
//!
//! **Costs**: e_vm and e_pm are tabulated once per grid value of eta or sigma_y (a row over all
//! points, counted as one evaluation); a node of `min` or `product` then costs one min or product
//! per point.
//!
//! **Not certified** (the fit says so: a warning and `converged: false`): when the search budget
//! (200000 cells, 40000 rows with the master curve, 400 with the ODE) or the number of polishes
//! (100) runs out, when the model cannot be evaluated on part of the box, or with the scan
//! switched off ([`super::FitOptions::scan`]).

use super::FitOptions;
use super::bnb::{Bnb, Candidate, CellBox, KnownNodes, Landscape, Limits, starting_rows};
use super::kinks::{KinkStart, axis_stderr, kink_starts, polish_profiles};
use super::landscape::{PowerLaw, Separable};
use super::models::{Evaluator, ModelKind};
use super::objective::{CHI2_1DOF_95, Objective};
use super::polish::{
    Found, polish_at_bounds, polish_brent, polish_lm, polish_newton, polish_valleys,
};
use super::powerlaw::polish_powerlaw;
use super::result::{GlobalSearch, show};
use super::{lsq, sums};
use crate::error::{Error, Num, Result};
use crate::models::viscoelastic::VmMethod;
use std::collections::HashMap;

/// tau = TAU_REL U + TAU_ABS s (see the module doc).
pub const TAU_REL: f64 = 1e-7;
pub const TAU_ABS: f64 = 1e-6;
/// The separable models' starting grid: cells of log eta and of log sigma_y.
pub(crate) const SEPARABLE_N0: [u64; 2] = [24, 16];
/// The power law's starting grid: cells of its exponents (a, b).
pub(crate) const POWERLAW_N0: [u64; 2] = [10, 10];
/// Local polishes allowed per fit.
const MAX_POLISH: u64 = 100;
/// Local minima within this relative distance of the best are finished with line searches
/// (1e-5: ten times the randomized test's criterion), at most MAX_FINISH of them.
const FINISH_MARGIN: f64 = 1e-5;
const MAX_FINISH: usize = 4;

/// What the search found and established.
#[derive(Debug, Clone)]
pub struct SearchOutcome {
    pub best: Found,
    pub global: GlobalSearch,
    pub warnings: Vec<String>,
    /// Grid nodes with chi2 within 3.84 s of the minimum (full internal coordinates, chi2): for
    /// checking that the 95% region has no part the profile intervals miss.
    pub near_nodes: Vec<(Vec<f64>, f64)>,
    /// `min`, `product` and the power law: the cells of the branch and bound that may hold chi2
    /// within 3.84 s of the minimum (no other point of the box does), for the profiles' inner
    /// minimisation ([`super::slice`]); None for the other models and without the search.
    pub region: Option<Region>,
}

/// The part of the box where chi2 may be within 3.84 s of the minimum, as cells of the global
/// search, and the search's resolution (internal units per axis).
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    pub cells: Vec<CellBox>,
    pub resolution: [f64; 2],
    /// The chi2 the search computed at the cells' corners (for a search on the same landscape).
    pub nodes: KnownNodes,
}

/// The tolerance tau for a best value U of the points' chi2 (the rows' chi2 sets the relative
/// part, as the module doc states it for the chi2 a user sees).
pub fn tolerance(obj: &Objective, upper: f64) -> f64 {
    TAU_REL * (upper + obj.chi2_offset) + TAU_ABS * obj.scale(upper)
}

/// Computes the rows of the starting grids of the separable models among `kinds` ([`Evaluator::row`]):
/// `vm`, `min` and `product` start from the same rows of e_vm, `pm`, `min` and `product` from
/// the same rows of e_pm (the same boxes, the same cells). Done before their searches start
/// side by side, each row is computed once (all of them in parallel) rather than once by each
/// search that reaches it first; the searches' results do not change (a row is the same numbers
/// whoever computes it). A box that cannot be built is left to the fits to report.
pub fn share_starting_rows(ev: &Evaluator, kinds: &[ModelKind], options: &FitOptions) {
    use rayon::prelude::*;
    let uses = |k: usize| {
        kinds
            .iter()
            .filter(|&&m| match m {
                ModelKind::Vm => k == 0,
                ModelKind::Pm => k == 1,
                ModelKind::Min | ModelKind::Product => true,
                ModelKind::PowerLaw => false,
            })
            .count()
    };
    if !options.scan {
        return;
    }
    // The boxes of min and product: those of vm and of pm (search_box).
    let Ok(obj) = Objective::new(ev, ModelKind::Min) else {
        return;
    };
    let rows: Vec<(usize, f64)> = [0, 1]
        .into_iter()
        .filter(|&k| uses(k) >= 2)
        .flat_map(|k| {
            starting_rows((obj.lower[k], obj.upper[k]), SEPARABLE_N0[k])
                .into_iter()
                .map(move |t| (k, t))
        })
        .collect();
    // Small data on this thread: waking the pool costs more than their rows.
    if sums::is_large(ev.len()) {
        rows.par_iter().for_each(|&(k, t)| {
            ev.row(k, t);
        });
    } else {
        for &(k, t) in &rows {
            ev.row(k, t);
        }
    }
}

/// The global minimum (see the module doc).
pub fn global_minimum(obj: &Objective, options: &FitOptions) -> Result<SearchOutcome> {
    let kind = obj.kind;
    let mut polished = Vec::new();
    if let Some(s) = &options.start {
        polished.push(polish_lm(obj, &kind.to_internal(s))?);
    }
    if !options.scan {
        if polished.is_empty() {
            let mid: Vec<f64> = (0..kind.n_params())
                .map(|j| 0.5 * (obj.lower[j] + obj.upper[j]))
                .collect();
            polished.push(polish_lm(obj, &mid)?);
        }
        let best = polished.swap_remove(0);
        return Ok(SearchOutcome {
            global: GlobalSearch {
                certified: false,
                gap_chi2: f64::INFINITY,
                tolerance_chi2: tolerance(obj, best.chi2),
                cells: 0,
                polishes: 1,
                fine_cells: 0,
            },
            best,
            warnings: vec![
                "global search switched off: the minimum is the local solver's from the start"
                    .into(),
            ],
            near_nodes: Vec::new(),
            region: None,
        });
    }
    let ode = matches!(obj.ev.method, VmMethod::Ode(_));
    let limits = Limits {
        max_cells: 200_000,
        max_rows: if ode { 400 } else { 40000 },
    };
    match kind {
        ModelKind::Vm | ModelKind::Pm | ModelKind::Min | ModelKind::Product => {
            let (active, range, n0) = separable_grid(obj);
            let land = Separable::new(obj, kind == ModelKind::Min, active);
            let bnb = Bnb::new(land, range, n0, limits);
            let to_theta = move |_: &Separable, _: [usize; 2], t: [f64; 2]| theta_of(kind, t);
            let polish = move |_: &Separable, c: &Candidate| -> Result<Found> {
                if kind.n_params() == 2 {
                    return polish_lm(obj, &[c.t[0], c.t[1]]);
                }
                let k = if kind == ModelKind::Vm { 0 } else { 1 };
                polish_brent(obj, c.t[k], c.bracket_lo[k], c.bracket_hi[k], c.chi2)
            };
            run(obj, bnb, polished, &to_theta, &polish)
        }
        ModelKind::PowerLaw => {
            let mut land = PowerLaw::new(obj);
            land.bound_tol = 0.1 * TAU_ABS;
            let bnb = Bnb::new(land, powerlaw_range(obj), POWERLAW_N0, limits);
            let to_theta = powerlaw_theta;
            // The profile over the exponents first, then all three parameters from there; the
            // lower of the two.
            let polish = |_: &PowerLaw, c: &Candidate| -> Result<Found> {
                let p = polish_powerlaw(obj, &c.t)?;
                let q = polish_lm(obj, &p.theta)?;
                Ok(if q.chi2 < p.chi2 { q } else { p })
            };
            run(obj, bnb, polished, &to_theta, &polish)
        }
    }
}

/// Resolution of the branch and bound around the minima, in standard errors (the cost grows as
/// 1/RESOLUTION): `min` and `product`, whose e_pm has a kink (min) or a jump of curvature at
/// yield that can put shallow minima close together; the smooth power law; one-parameter
/// models, held to the same 1/4 as the kinked two-parameter ones (1/32 cost 2.2 million
/// instructions more per `vm` fit of the 120 shipped points, the same optimum to the last digit,
/// and the same 0 failures in 400 data sets of `examples/fit_global`).
const RESOLUTION_2D: f64 = 0.25;
const RESOLUTION_SMOOTH: f64 = 1.0;
const RESOLUTION_1D: f64 = 0.25;

/// Maps a landscape cell (grid indices and offsets) to the model's parameters.
pub(crate) type ToTheta<'a, L> = &'a dyn Fn(&L, [usize; 2], [f64; 2]) -> Vec<f64>;

/// The separable models' grid: which axes are parameters (e_vm's eta, e_pm's sigma_y), their
/// ranges (the search box; an inactive axis one row at 0) and starting cells. Every branch and
/// bound on a separable landscape of one fit takes it from here: the global search's region
/// cells, as dyadic positions, mean the same cells in its slices ([`super::slice`]) and beyond
/// its interval ends ([`super::beyond`]).
pub(crate) fn separable_grid(obj: &Objective) -> ([bool; 2], [(f64, f64); 2], [u64; 2]) {
    let kind = obj.kind;
    let active = [kind != ModelKind::Pm, kind != ModelKind::Vm];
    let range = match kind {
        ModelKind::Vm => [(obj.lower[0], obj.upper[0]), (0.0, 0.0)],
        ModelKind::Pm => [(0.0, 0.0), (obj.lower[0], obj.upper[0])],
        _ => [(obj.lower[0], obj.upper[0]), (obj.lower[1], obj.upper[1])],
    };
    let n0 = [0, 1].map(|k| if active[k] { SEPARABLE_N0[k] } else { 0 });
    (active, range, n0)
}

/// The power law's grid over its exponents (a, b) (the search box; starting cells
/// [`POWERLAW_N0`]), as [`separable_grid`] for the separable models.
pub(crate) fn powerlaw_range(obj: &Objective) -> [(f64, f64); 2] {
    [(obj.lower[1], obj.upper[1]), (obj.lower[2], obj.upper[2])]
}

/// The parameters of a separable `kind` model at the landscape's coordinates `t` (the inverse
/// of [`axes_of`]).
pub(crate) fn theta_of(kind: ModelKind, t: [f64; 2]) -> Vec<f64> {
    match kind {
        ModelKind::Vm => vec![t[0]],
        ModelKind::Pm => vec![t[1]],
        _ => vec![t[0], t[1]],
    }
}

/// The power law's parameters at a node of its landscape: A at its least-squares value there.
pub(crate) fn powerlaw_theta(land: &PowerLaw, r: [usize; 2], t: [f64; 2]) -> Vec<f64> {
    vec![land.profile(r).0, t[0], t[1]]
}

/// The coordinates on the branch and bound's axes of the parameters `th` of a `kind` model (its
/// landscape's: e_vm's eta and e_pm's sigma_y, or the power law's exponents).
pub(crate) fn axes_of(kind: ModelKind, th: &[f64]) -> [f64; 2] {
    match kind {
        ModelKind::Vm => [th[0], 0.0],
        ModelKind::Pm => [0.0, th[0]],
        ModelKind::Min | ModelKind::Product => [th[0], th[1]],
        ModelKind::PowerLaw => [th[1], th[2]],
    }
}

/// The common driver: initial minima, branch and bound, candidates, certificate.
fn run<L: Landscape>(
    obj: &Objective,
    mut bnb: Bnb<L>,
    mut polished: Vec<Found>,
    to_theta: ToTheta<'_, L>,
    polish: &dyn Fn(&L, &Candidate) -> Result<Found>,
) -> Result<SearchOutcome> {
    let tau_of = |u: f64| tolerance(obj, u);
    let Some((_, _, first)) = bnb.best_node() else {
        return Err(Error::InvalidParameter {
            name: "chi2 on the search grid (not a number anywhere)",
            value: f64::NAN,
            expected: "a model that can be evaluated somewhere in the search box",
        });
    };
    if !first.is_finite() {
        return Err(Error::InvalidParameter {
            name: "smallest chi2 on the search grid (the squares overflow: e far from the model, or e_err too small?)",
            value: first,
            expected: "a finite number",
        });
    }
    let lowest_of = |p: &[Found]| p.iter().map(|f| f.chi2).fold(f64::INFINITY, f64::min);
    let best_of = |p: &[Found]| {
        p.iter()
            .filter(|f| !f.chi2.is_nan())
            .min_by(|a, b| a.chi2.total_cmp(&b.chi2))
            .cloned()
    };
    let mut upper = first.min(lowest_of(&polished));
    let mut starts: Vec<[f64; 2]> = Vec::new();
    let mut n_polish = polished.len() as u64;
    let mut skipped = 0u64;
    let axes_of = |th: &[f64]| axes_of(obj.kind, th);
    let mut try_polish = |bnb: &Bnb<L>,
                          c: &Candidate,
                          polished: &mut Vec<Found>,
                          upper: &mut f64|
     -> Result<()> {
        let near = |t: [f64; 2]| (0..2).all(|k| c.bracket_lo[k] <= t[k] && t[k] <= c.bracket_hi[k]);
        let cannot_beat = c.lb >= *upper - tau_of(*upper);
        if cannot_beat || starts.contains(&c.t) || polished.iter().any(|f| near(axes_of(&f.theta)))
        {
            return Ok(());
        }
        if n_polish >= MAX_POLISH {
            skipped += 1;
            return Ok(());
        }
        n_polish += 1;
        starts.push(c.t);
        let f = polish(&bnb.land, c)?;
        if f.chi2 < *upper {
            *upper = f.chi2;
        }
        polished.push(f);
        Ok(())
    };
    for c in bnb.initial_minima(upper, tau_of(upper)) {
        try_polish(&bnb, &c, &mut polished, &mut upper)?;
    }
    let resolution = match obj.kind {
        ModelKind::Vm | ModelKind::Pm => RESOLUTION_1D,
        ModelKind::Min | ModelKind::Product => RESOLUTION_2D,
        ModelKind::PowerLaw => RESOLUTION_SMOOTH,
    };
    // The widths of the finest cells (none without a polished point: nothing is refined).
    let mut fine_width = None;
    if let Some(b) = best_of(&polished) {
        let sd = axis_stderr(obj, &b.theta)?;
        let w = [resolution * sd[0], resolution * sd[1]];
        bnb.set_resolution(w);
        fine_width = Some(w);
    }
    // For the profiles of the two-parameter models and the power law, the cells that may hold
    // chi2 within 3.84 s of the minimum are kept ([`Region`]).
    let keeps_region = true;
    let keep_of = |u: f64| {
        if keeps_region {
            u + CHI2_1DOF_95 * obj.scale(u)
        } else {
            u
        }
    };
    bnb.refine(upper, &tau_of, &keep_of);
    if let Some((_, _, v)) = bnb.best_node()
        && v < upper
    {
        upper = v;
    }
    for c in bnb.candidates(upper) {
        try_polish(&bnb, &c, &mut polished, &mut upper)?;
    }
    if obj.kind == ModelKind::Min {
        // Across the kinks near the best minimum (and again from what that finds, twice). A best
        // within a cell of the resolution of one looked across, and not lower by more than a
        // hundredth of tau, is that minimum found again: its starts would be the same ones (one
        // per cell of the resolution), each polished again for nothing (before, the exact
        // comparison of the points repeated all six polishes of `min` on 100 000 points of
        // distinct sizes).
        let mut looked: Vec<(Vec<f64>, f64, [f64; 2])> = Vec::new();
        for _ in 0..3 {
            let Some(b) = best_of(&polished) else { break };
            let again = |(th, c, sd): &(Vec<f64>, f64, [f64; 2])| {
                b.chi2 >= c - 0.01 * tau_of(*c)
                    && (0..2).all(|k| (b.theta[k] - th[k]).abs() <= resolution * sd[k])
            };
            if looked.iter().any(again) {
                break;
            }
            let sd = axis_stderr(obj, &b.theta)?;
            looked.push((b.theta.clone(), b.chi2, sd));
            // On many points of many sizes there are hundreds of starts. One where the bounds
            // already exclude chi2 below U - tau is not where a lower minimum sits (a start is
            // a guess at one); of those a cell of the search's resolution (around the minimum)
            // holds, the one across the highest ridge: the resolution is where the bounds hand
            // over to the local polishes, one per cell.
            let u = upper.min(lowest_of(&polished));
            let target = u - tau_of(u);
            let mut cells: HashMap<[i64; 2], KinkStart> = HashMap::new();
            for s in kink_starts(obj, &b.theta, sd)?.0 {
                if !bnb.may_hold_below(axes_of(&s.theta), target) {
                    continue;
                }
                let key = [0, 1]
                    .map(|k| ((s.theta[k] - b.theta[k]) / (resolution * sd[k])).round() as i64);
                match cells.get(&key) {
                    Some(kept) if kept.ridge >= s.ridge => {}
                    _ => {
                        cells.insert(key, s);
                    }
                }
            }
            let mut kept: Vec<([i64; 2], KinkStart)> = cells.into_iter().collect();
            kept.sort_by_key(|(key, _)| *key);
            for (_, start) in kept {
                let start = start.theta;
                if n_polish >= MAX_POLISH {
                    skipped += 1;
                    continue;
                }
                n_polish += 1;
                polished.push(polish_lm(obj, &start)?);
            }
        }
    }
    if obj.kind.n_params() > 1 {
        // Every local minimum close to the best (within FINISH_MARGIN relative) is finished
        // with line searches, and with the profiles when it sits on a kink of `min`: a shallow
        // minimum where a point starts to yield is where Levenberg-Marquardt stops short.
        let best = lowest_of(&polished);
        let mut close: Vec<Found> = polished
            .iter()
            .filter(|f| f.chi2 <= best + FINISH_MARGIN * best.abs() + tau_of(best))
            .cloned()
            .collect();
        close.sort_by(|a, b| a.chi2.total_cmp(&b.chi2));
        // The same minimum reached from several starts is finished once (1e-7 in the internal
        // coordinates: far below any standard error, far above the polishes' tolerance).
        let mut unique: Vec<Found> = Vec::new();
        for f in close {
            let same = |g: &Found| {
                f.theta
                    .iter()
                    .zip(&g.theta)
                    .all(|(a, b)| (a - b).abs() < 1e-7)
            };
            if !unique.iter().any(same) {
                unique.push(f);
            }
        }
        let close = unique;
        // Where the bounds exclude chi2 below U - tau the valleys' scans need not look.
        let u = upper.min(best);
        let target = u - tau_of(u);
        let may_beat = |th: &[f64]| bnb.may_hold_below(axes_of(th), target);
        let mut finished: Vec<Found> = Vec::new();
        for b in close.into_iter().take(MAX_FINISH) {
            // A minimum within a finest cell's width of one already finished and not below it
            // is the same minimum at the resolution the bounds stop at, reached again, and
            // within reach of that one's finishing (its scans span +-VALLEY_REACH standard
            // errors).
            let at = axes_of(&b.theta);
            let covered = fine_width.is_some_and(|w| {
                finished.iter().any(|f| {
                    f.chi2 <= b.chi2
                        && (0..2).all(|k| {
                            let (x, y) = (at[k], axes_of(&f.theta)[k]);
                            x == y || (x - y).abs() <= w[k]
                        })
                })
            });
            if covered {
                continue;
            }
            n_polish += 1;
            // Levenberg-Marquardt that ran out of iterations (creeping along a narrow curved
            // valley) or stopped on a kink of `min` hands over to Brent on the profiles.
            let mut v = b;
            for _ in 0..3 {
                // On a kink of `min` only where Levenberg-Marquardt stopped short of the
                // minimum by more than tau as far as its Gauss-Newton step can tell: at a V-shaped
                // kink chi2 is the larger of its two branches, so no lower than the minimum of
                // the active branch's quadratic model. Many points of many sizes always have
                // some point near its kink, and kinks too weak to matter.
                let stuck = !v.converged
                    || (obj.kind == ModelKind::Min
                        && kink_starts(obj, &v.theta, axis_stderr(obj, &v.theta)?)?.1
                        && lsq::gauss_newton_decrease(obj, &v.theta)? > tau_of(v.chi2));
                if obj.kind == ModelKind::PowerLaw || !stuck {
                    break;
                }
                let before = v.chi2;
                v = if obj.kind == ModelKind::Min {
                    polish_profiles(obj, v, tau_of(before))?
                } else {
                    polish_newton(obj, v)?
                };
                // Another round of profiles for a gain below tau would not move the answer
                // beyond the accuracy the search states (Newton goes on while it gains: it
                // also ends Levenberg-Marquardt's unconverged runs).
                let min_gain = if obj.kind == ModelKind::Min {
                    tau_of(before)
                } else {
                    0.0
                };
                if !(v.chi2 < before - min_gain) {
                    break;
                }
            }
            let v = polish_valleys(obj, v, &may_beat)?;
            let mut v = polish_at_bounds(obj, v)?;
            // Levenberg-Marquardt or Newton that ran out of iterations creeping along a
            // parameter the data bound from one side only, where chi2 hardly changes, stopped
            // within tau of a stationary point as far as the Gauss-Newton step from there can
            // tell: converged to the accuracy the search states (randomized test seed 3634,
            // `product`, was reported "not converged" 2.5e-5 below the reference).
            if !v.converged && lsq::gauss_newton_decrease(obj, &v.theta)? <= tau_of(v.chi2) {
                v.converged = true;
                v.reason = format!(
                    "{}, then the Gauss-Newton step promised less than the tolerance",
                    v.reason
                );
            }
            finished.push(v.clone());
            polished.push(v);
        }
    }
    let mut warnings = Vec::new();
    // The answer: the lowest polished point; the best node only if every polish ended above it
    // (after one more polish from the node itself) by more than the rounding of the sums: a
    // node's chi2 and a polish's are summed in different orders, so a polish that converged on
    // the node itself can end an ulp above it (and was reported as not converged).
    let reaches = |f: &Found, node_v: f64| f.chi2 <= node_v + obj.evaluation_rounding(node_v);
    let (_, _, node_v) = bnb.best_node().expect("checked above");
    if best_of(&polished).is_none_or(|f| !reaches(&f, node_v))
        && let Some(c) = bnb.best_candidate()
    {
        n_polish += 1;
        polished.push(polish(&bnb.land, &c)?);
    }
    let (node_r, node_t, node_v) = bnb.best_node().expect("checked above");
    let best = match best_of(&polished) {
        Some(f) if reaches(&f, node_v) => f,
        other => {
            // Both in full (shortest round-trip): close values must not print alike.
            warnings.push(format!(
                "no local polish reached the best grid point (chi2 {}{}); the grid point is \
                 reported",
                Num(node_v + obj.chi2_offset),
                other
                    .as_ref()
                    .map(|f| format!(
                        ", best polish {} ({})",
                        Num(f.chi2 + obj.chi2_offset),
                        f.reason
                    ))
                    .unwrap_or_default()
            ));
            Found {
                theta: to_theta(&bnb.land, node_r, node_t),
                chi2: node_v,
                converged: false,
                reason: "best grid point".into(),
            }
        }
    };
    let tau = tau_of(best.chi2);
    let cert = bnb.certificate(best.chi2);
    let gap = if cert.lowest < best.chi2 {
        best.chi2 - cert.lowest
    } else {
        0.0
    };
    let mut certified = cert.reasons.is_empty() && gap <= tau * (1.0 + 1e-9);
    // The cell holding the reported point has a bound at most the point's chi2 and is kept
    // (cells are discarded only when their bound exceeds U); anything else means a bound was
    // wrong (rounding allowed: 1e-9 relative).
    let lowest_any = cert.lowest.min(cert.lowest_fine);
    if !(lowest_any <= best.chi2 + 1e-9 * best.chi2.abs().max(1.0)) {
        certified = false;
        // With no cell kept the lowest bound is +inf: said in words, never printed as a number.
        // Bound and point in full (shortest round-trip): they may differ in the fifth digit.
        let bound = if lowest_any.is_finite() {
            format!("lowest bound {}", Num(lowest_any + obj.chi2_offset))
        } else {
            "no cell's bound at or below it".into()
        };
        warnings.push(format!(
            "the global search's lower bounds were contradicted ({bound}, point {}): the \
             certificate is void",
            Num(best.chi2 + obj.chi2_offset)
        ));
    }
    // The gap is +inf when no bound is known at all: said in words, never printed as a number.
    let below = if gap.is_finite() {
        format!("a chi2 up to {} below the reported one", show(gap))
    } else {
        "any lower chi2".to_string()
    };
    for why in &cert.reasons {
        warnings.push(format!(
            "global minimum not certified: {why}; {below} cannot be excluded"
        ));
    }
    if cert.reasons.is_empty() && gap > tau * (1.0 + 1e-9) {
        warnings.push(format!(
            "global minimum not certified: a chi2 up to {} below the reported one cannot be \
             excluded (tolerance {})",
            Num(gap),
            Num(tau)
        ));
    }
    if !bnb.row_failures.is_empty() && cert.reasons.is_empty() {
        warnings.push(format!(
            "the model could not be evaluated on part of the search box (excluded by the \
             bounds of its neighbours): {}",
            bnb.row_failures.join("; ")
        ));
    }
    if skipped > 0 {
        certified = false;
        warnings.push(format!(
            "{skipped} candidate minima were not polished (limit {MAX_POLISH}): a lower \
             minimum within the tolerance may have been missed"
        ));
    }
    let threshold = best.chi2 + CHI2_1DOF_95 * obj.scale(best.chi2);
    let near_nodes = bnb
        .nodes_below(threshold)
        .into_iter()
        .map(|(r, t, v)| (to_theta(&bnb.land, r, t), v))
        .collect();
    let region = keeps_region.then(|| {
        let cells = bnb.cells_below(threshold);
        Region {
            nodes: bnb.known_nodes(&cells),
            cells,
            resolution: fine_width.unwrap_or([0.0, 0.0]),
        }
    });
    Ok(SearchOutcome {
        global: GlobalSearch {
            certified,
            gap_chi2: gap,
            tolerance_chi2: tau,
            cells: bnb.cells,
            polishes: n_polish,
            fine_cells: bnb.fine_cells_below(best.chi2 - tau),
        },
        best,
        warnings,
        near_nodes,
        region,
    })
}
