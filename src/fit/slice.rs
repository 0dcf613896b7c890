//! The global minimum of chi2 over one parameter of `min` or `product` with the other held: the
//! inner minimisation of their profile intervals ([`super::profile`]).
//!
//! **Solves** min over x in its search box of chi2(theta) with theta_j = t, x the other
//! parameter, and establishes, for the value U it reports, that no x outside small cells around
//! the minima has chi2 below U - tau (tau of [`super::search::tolerance`]), and that every local
//! minimum of the grid inside those cells that could beat U was polished.
//!
//! **Why it is needed**: the profile's Levenberg-Marquardt is local, and chi2 along x need not
//! have one minimum. With eta held, chi2 over sigma_y ends in a plateau where every point stays
//! elastic (e_pm = 1), and a step onto the plateau sees a zero gradient and stops there
//! "converged", above a minimum just before the plateau: the randomized test's seed 5
//! (`product`) then put the upper end of eta's interval at 22.971 where chi2 is below the
//! threshold at 23.001. The kinks of `min` can hold a second minimum the same way.
//!
//! **Method**: the global search's own ([`super::search`]) on a slice of its box: branch and
//! bound ([`super::bnb`]) over x alone, the held parameter an axis of one row, with the cell
//! bounds of the separable landscape ([`super::landscape::Separable`]: each point's e is
//! monotone in x), from the local minimum's value as U; then Brent's method from every grid-local
//! minimum in a cell whose bound could beat U. The rows of x's grid are the same at every t of a
//! profile (the same box, the same dyadic grid), so the evaluator computes each once per fit.
//!
//! **Known answer** (`tests/fit_global.rs`, `the_profiles_inner_minimum_is_global_past_the_plateau`:
//! the data sets live with the randomized test): the slice where the local minimisation stopped
//! on the plateau (the seed above) gets the minimum a 3000-point scan finds, and a slice with one
//! minimum keeps the local one.

use super::bnb::{Bnb, Limits};
use super::landscape::Separable;
use super::lsq;
use super::models::ModelKind;
use super::objective::Objective;
use super::scalar;
use super::search::{Region, SEPARABLE_N0, tolerance};
use crate::error::Result;
use crate::models::viscoelastic::VmMethod;

/// Rounds of refinement and polishes while a polish lowers the minimum.
const ROUNDS: usize = 4;

/// What [`slice_minimum`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct SliceMinimum {
    pub theta: Vec<f64>,
    pub chi2: f64,
    /// Whether no point of the slice is shown to have chi2 below the lower of `chi2` and the
    /// target by more than tau (no budget ran out, no row failed, no bound below that outside
    /// the cells left at the resolution, whose grid-local minima were polished).
    pub certified: bool,
}

/// The minimum over parameter o = 1 - j with theta_j = t (see the module doc), for `min` and
/// `product`, as far as it matters below `target`: `local` is the local minimisation's point,
/// chi2 (kept when nothing beats it) and whether it converged, `region` the global search's cells that may hold chi2
/// below `target` (at least: every other point of the box is shown above it).
pub fn slice_minimum(
    obj: &Objective,
    j: usize,
    t: f64,
    local: (&[f64], f64, bool),
    target: f64,
    region: &Region,
) -> Result<SliceMinimum> {
    debug_assert!(matches!(obj.kind, ModelKind::Min | ModelKind::Product));
    let o = 1 - j;
    let mut best = (local.0.to_vec(), local.1);
    if best.1.is_nan() {
        best.1 = f64::INFINITY;
    }
    // The search's cells the slice crosses (cells are closed: one on either side of t when t is
    // on their shared edge; a relative slack of 1e-12 of the box covers the rounding of the
    // corners' coordinates), as intervals of the other axis: dyadic, so any two are nested or
    // disjoint, and a nested one adds nothing.
    let slack = 1e-12 * (obj.upper[j] - obj.lower[j]).abs();
    let mut spans: Vec<(u64, u64)> = region
        .cells
        .iter()
        .filter(|c| c.t0[j] - slack <= t && t <= c.t1[j] + slack)
        .map(|c| (c.p0[o], c.p1[o]))
        .collect();
    spans.sort_by_key(|&(a, b)| (a, std::cmp::Reverse(b)));
    spans.dedup_by(|inner, outer| inner.1 <= outer.1);
    if spans.is_empty() {
        return Ok(SliceMinimum {
            theta: best.0,
            chi2: best.1,
            certified: true,
        });
    }
    let at = |x: f64| {
        let mut th = vec![0.0; 2];
        th[j] = t;
        th[o] = x;
        th
    };
    let mut range = [(obj.lower[0], obj.upper[0]), (obj.lower[1], obj.upper[1])];
    range[j] = (t, t);
    let mut n0 = SEPARABLE_N0;
    n0[j] = 0;
    let cells: Vec<([u64; 2], [u64; 2])> = spans
        .iter()
        .map(|&(a, b)| {
            let (mut p0, mut p1) = ([0; 2], [0; 2]);
            p0[o] = a;
            p1[o] = b;
            (p0, p1)
        })
        .collect();
    let ode = matches!(obj.ev.method, VmMethod::Ode(_));
    let limits = Limits {
        max_cells: 20_000,
        max_rows: if ode { 200 } else { 4000 },
    };
    let land = Separable::new(obj, obj.kind == ModelKind::Min, [true, true]);
    let mut bnb = Bnb::sparse(land, range, n0, limits);
    // The search's resolution (1/4096 of the box without one).
    let mut resolution = [0.0; 2];
    resolution[o] = if region.resolution[o] > 0.0 {
        region.resolution[o]
    } else {
        (obj.upper[o] - obj.lower[o]) / 4096.0
    };
    bnb.set_resolution(resolution);
    let tau_of = |u: f64| tolerance(obj, u);
    let x_local = local.0.get(o).copied().unwrap_or(f64::NAN);
    // Near the profile's crossing the local value is within tau of the target, and the cells
    // around the local minimum go to the resolution whatever their bounds: not bounded on the
    // way (a third to a half of such a slice's cell bounds on 100 000 points).
    let u0 = best.1.min(target);
    if local.2 && x_local.is_finite() && best.1 <= u0 + tau_of(u0) {
        bnb.set_polished(at(x_local).try_into().expect("two parameters"));
    }
    bnb.start_on(&cells, u0 - tau_of(u0));
    // A polish that lowers U leaves cells set aside against the old U - tau: refined again
    // against the new one (a few rounds; the certificate below says whether they sufficed).
    for _ in 0..ROUNDS {
        let before = best.1;
        bnb.refine(best.1.min(target), &tau_of, &|u| u);
        if let Some((_, tt, v)) = bnb.best_node()
            && v < best.1
        {
            best = (at(tt[o]), v);
        }
        let u = best.1.min(target);
        for c in bnb.candidates(u) {
            let (lo, hi) = (c.bracket_lo[o], c.bracket_hi[o]);
            // Not where the local minimisation already polished (as the search: a polished
            // point inside the bracket).
            if c.lb >= u - tau_of(u) || !(lo < hi) || (lo <= x_local && x_local <= hi) {
                continue;
            }
            // 1e-10 in the log parameter, as the one-parameter polishes: far below any
            // standard error.
            let m = scalar::brent_minimize(|x| lsq::chi2(obj, &at(x)), lo, hi, 1e-10)?;
            if m.fx < best.1 {
                best = (at(m.x), m.fx);
            }
        }
        if !(best.1 < before) {
            break;
        }
    }
    let u = best.1.min(target);
    let cert = bnb.certificate(u);
    let certified = cert.reasons.is_empty()
        && bnb.row_failures.is_empty()
        && !(cert.lowest < u - tau_of(u) * (1.0 + 1e-9));
    Ok(SliceMinimum {
        theta: best.0,
        chi2: best.1,
        certified,
    })
}
