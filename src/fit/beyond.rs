//! Whether the 95% region has a part beyond an end of a profile interval.
//!
//! **Solves**: for parameter j and an end `end` of its interval (found where the profile from
//! the minimum crosses the threshold chi2_min + Delta, [`super::profile`]), either shows that no
//! point with theta_j beyond `end` by more than a margin has chi2 below the threshold (less the
//! search's tolerance tau), or finds one (the interval must then reach it), or says why it
//! could not show it.
//!
//! **Why it is needed**: the profile is followed outwards from the minimum and stops at its
//! first crossing; a second valley further out (a part of the region the profile does not
//! reach, beyond a ridge) is seen only where a node of the global search's grid falls into it
//! ([`super::profile::extend_to_region`]). Between the nodes nothing showed that none lies.
//!
//! **Method** (docs/physics.md §7.5): the global search's own branch and bound ([`super::bnb`], with the cell bounds
//! of the model's landscape, [`super::landscape`]) on the search's region, the cells whose
//! bound is below the threshold (every other point of the box is shown above it), restricted to
//! the half-plane theta_j >= end + margin (or <= end - margin): cells wholly inside are dropped,
//! a cell across it is split on that axis down to the margin or the search's resolution, and
//! then bounded over its part beyond alone (from a row at the edge) before any split on the
//! other axis (whose halves would stay across it), nodes inside do not count.
//! For the power law's A, which the landscape profiles out rather than tabulates, the half-plane
//! is A's range itself: the landscape's bounds and nodes minimise over that range. A cell whose
//! bound reaches the threshold less tau holds no such point; a node below the threshold is one;
//! the cells left at the search's resolution get a local polish (Levenberg-Marquardt with
//! theta_j held to the half-plane) from every grid-local minimum among them, as the search's
//! fine cells do (one whose bracket holds where an earlier polish ended is covered by it, as in
//! the search). The margin is [`MARGIN`] of the interval's half-width on that side: an end
//! may still be short by that much (a part of the region closer to the end than the margin
//! differs from the interval by less).
//!
//! **Known answer** (`tests/fit_global.rs`): a data set whose region has a second part beyond
//! an end, between the grid's nodes, is found; and the randomized test's data sets, whose
//! regions have none, are shown clear.

use super::bnb::{Bnb, Cut, Landscape, Limits};
use super::landscape::{PowerLaw, Separable};
use super::lsq::{self, Residuals};
use super::models::ModelKind;
use super::objective::Objective;
use super::profile::{Extension, Inner, Moved, Profiles, Side, extend_to_region};
use super::search::{
    POWERLAW_N0, Region, TAU_ABS, ToTheta, axes_of, powerlaw_range, powerlaw_theta, separable_grid,
    theta_of, tolerance,
};
use super::sums;
use crate::error::Result;
use crate::models::viscoelastic::VmMethod;
use nalgebra::DMatrix;

/// The margin beyond an end, as a fraction of the interval's half-width on that side.
pub const MARGIN: f64 = 0.05;

/// Local polishes allowed per end (a candidate whose bracket holds where an earlier polish
/// ended is not polished again, as in the search).
const MAX_POLISH: usize = 20;

/// What [`beyond_end`] established.
#[derive(Debug, Clone, PartialEq)]
pub enum Beyond {
    /// No point beyond the end by more than the margin has chi2 below the threshold less tau.
    Clear,
    /// A point beyond the end with chi2 below the threshold: parameters (internal coordinates)
    /// and chi2.
    Found(Vec<f64>, f64),
    /// Neither shown nor found, and why.
    NotShown(String),
}

/// The objective with parameter j's range cut to one side of a value (the polishes' box).
struct Clipped<'a> {
    obj: &'a Objective<'a>,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl Residuals for Clipped<'_> {
    fn n_params(&self) -> usize {
        self.obj.n_params()
    }
    fn n_residuals(&self) -> usize {
        self.obj.n_residuals()
    }
    fn residuals(&self, theta: &[f64], out: &mut [f64]) -> Result<()> {
        self.obj.residuals(theta, out)
    }
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn fd_step(&self) -> f64 {
        self.obj.fd_step()
    }
    fn jacobian_exact(
        &self,
        theta: &[f64],
        free: &[bool],
        out: &mut DMatrix<f64>,
    ) -> Option<Result<()>> {
        self.obj.jacobian_exact(theta, free, out)
    }
    fn residuals_and_jacobian(
        &self,
        theta: &[f64],
        out: &mut [f64],
        free: &[bool],
        jac: &mut DMatrix<f64>,
    ) -> Option<Result<()>> {
        self.obj.residuals_and_jacobian(theta, out, free, jac)
    }
    fn kinked(&self) -> bool {
        self.obj.kinked()
    }
}

/// Whether the 95% region of `obj`'s parameter j has a part beyond `end` (side `s`: 0 below,
/// 1 above) by more than [`MARGIN`] of |end - theta_min\[j\]| (see the module doc), with the
/// threshold chi2 `threshold` (the points' chi2, as the objective's) and the global search's
/// `region` (its cells below the threshold). Errors only where the model cannot be evaluated
/// at all; a polish that fails is a reason not to claim the end.
pub fn beyond_end(
    obj: &Objective,
    theta_min: &[f64],
    j: usize,
    s: usize,
    end: f64,
    threshold: f64,
    region: &Region,
) -> Result<Beyond> {
    let dir = if s == 0 { -1.0 } else { 1.0 };
    let margin = MARGIN * (end - theta_min[j]).abs();
    if !(margin > 0.0 && margin.is_finite() && end.is_finite()) {
        return Ok(Beyond::NotShown(format!(
            "the end is not apart from the minimum (margin {margin})"
        )));
    }
    let at = end + dir * margin;
    let (lo, hi) = (obj.lower[j], obj.upper[j]);
    if (s == 0 && at <= lo) || (s == 1 && at >= hi) {
        // Nothing of the box lies beyond.
        return Ok(Beyond::Clear);
    }
    let ode = matches!(obj.ev.method, VmMethod::Ode(_));
    let limits = Limits {
        max_cells: 20_000,
        max_rows: if ode { 200 } else { 4000 },
    };
    let mut clip = Clipped {
        obj,
        lower: obj.lower.clone(),
        upper: obj.upper.clone(),
    };
    if s == 0 {
        clip.upper[j] = at;
    } else {
        clip.lower[j] = at;
    }
    let end_of = Search {
        obj,
        clip: &clip,
        threshold,
        region,
        limits,
    };
    // A cell across the cut is split on its axis down to the margin or the search's resolution.
    let cut = |axis: usize| Cut {
        axis,
        at,
        dir,
        width: margin.max(region.resolution[axis]),
    };
    match obj.kind {
        ModelKind::Vm | ModelKind::Pm | ModelKind::Min | ModelKind::Product => {
            let kind = obj.kind;
            let (active, range, n0) = separable_grid(obj);
            // The parameter's axis of the landscape (pm's sigma_y is axis 1).
            let axis = if kind == ModelKind::Pm { 1 } else { j };
            let land = Separable::new(obj, kind == ModelKind::Min, active).with_second_order();
            let mut bnb = Bnb::sparse(land, range, n0, limits);
            bnb.set_cut(cut(axis));
            end_of.run(bnb, &move |_: &Separable, _, t| theta_of(kind, t))
        }
        ModelKind::PowerLaw => {
            let mut land = PowerLaw::new(obj);
            land.bound_tol = 0.1 * TAU_ABS;
            if j == 0 {
                // A's half-plane is its range: the landscape minimises over it.
                land.amplitude_range(clip.lower[0], clip.upper[0]);
            }
            let mut bnb = Bnb::sparse(land, powerlaw_range(obj), POWERLAW_N0, limits);
            if j >= 1 {
                bnb.set_cut(cut(j - 1));
            }
            end_of.run(bnb, &powerlaw_theta)
        }
    }
}

/// One end's search (see [`beyond_end`]).
struct Search<'a> {
    obj: &'a Objective<'a>,
    clip: &'a Clipped<'a>,
    threshold: f64,
    region: &'a Region,
    limits: Limits,
}

impl Search<'_> {
    /// The branch and bound `bnb` (its cut set) from the region's cells, its grid-local minima
    /// left at the resolution polished; `to_theta` maps a node to the parameters.
    fn run<L: Landscape>(&self, mut bnb: Bnb<L>, to_theta: ToTheta<'_, L>) -> Result<Beyond> {
        let (obj, threshold) = (self.obj, self.threshold);
        let tau_of = |u: f64| tolerance(obj, u);
        let tau = tau_of(threshold);
        // The region's cells with a point beyond the cut.
        let cells: Vec<([u64; 2], [u64; 2])> = (self.region.cells.iter())
            .filter(|c| bnb.reaches_cut(c))
            .map(|c| (c.p0, c.p1))
            .collect();
        if cells.len() > self.limits.max_cells as usize {
            return Ok(Beyond::NotShown(format!(
                "the search's region has {} cells beyond it, more than the budget of {}",
                cells.len(),
                self.limits.max_cells
            )));
        }

        bnb.set_resolution(self.region.resolution);
        bnb.start_on(&cells, threshold - tau);
        bnb.refine(threshold, &tau_of, &|u| u);
        if let Some((r, t, v)) = bnb.best_node()
            && v < threshold
        {
            return Ok(Beyond::Found(to_theta(&bnb.land, r, t), v));
        }
        let mut polishes = 0;
        let mut ended: Vec<[f64; 2]> = Vec::new();
        let lm = lsq::LmOptions::default();
        let free = vec![true; obj.kind.n_params()];
        for c in bnb.candidates(threshold) {
            let near =
                |t: &[f64; 2]| (0..2).all(|k| c.bracket_lo[k] <= t[k] && t[k] <= c.bracket_hi[k]);
            if c.lb >= threshold - tau || ended.iter().any(near) {
                continue;
            }
            if polishes == MAX_POLISH {
                return Ok(Beyond::NotShown(format!(
                    "more than {MAX_POLISH} local minima left to polish"
                )));
            }
            polishes += 1;
            let mut start = to_theta(&bnb.land, c.rows, c.t);
            for (k, x) in start.iter_mut().enumerate() {
                *x = x.clamp(self.clip.lower[k], self.clip.upper[k]);
            }
            match lsq::levenberg_marquardt(self.clip, &start, &free, &lm) {
                Ok(r) if r.chi2 < threshold => return Ok(Beyond::Found(r.theta, r.chi2)),
                Ok(r) if !r.converged => {
                    return Ok(Beyond::NotShown(format!(
                        "a local polish did not converge ({})",
                        r.reason
                    )));
                }
                Ok(r) => ended.push(axes_of(obj.kind, &r.theta)),
                Err(e) => return Ok(Beyond::NotShown(format!("a local polish failed: {e}"))),
            }
        }
        let cert = bnb.certificate(threshold);
        if let Some(why) = cert.reasons.first() {
            return Ok(Beyond::NotShown(why.clone()));
        }
        if let Some(why) = bnb.row_failures.first() {
            return Ok(Beyond::NotShown(format!(
                "the model could not be evaluated: {why}"
            )));
        }
        if cert.lowest < (threshold - tau) - tau * 1e-9 {
            return Ok(Beyond::NotShown(format!(
                "a cell's bound stays at {} below the threshold {}",
                cert.lowest, threshold
            )));
        }
        Ok(Beyond::Clear)
    }
}

/// An end of an interval whose far side [`certify_ends`] could not clear.
#[derive(Debug, Clone, PartialEq)]
pub struct Unshown {
    /// The parameter, the end (0 lower, 1 upper), where it is (internal coordinates) and why.
    pub j: usize,
    pub s: usize,
    pub end: f64,
    pub why: String,
}

/// What [`certify_ends`] did.
#[derive(Debug, Clone, PartialEq)]
pub enum Certified {
    /// Every found end of the profiles now has no part of the 95% region beyond it (by more
    /// than the margin), except those listed; ends moved past the parts found are appended to
    /// the caller's list.
    Done(Vec<Unshown>),
    /// A point below the minimum: the caller refits from it.
    Lower(Vec<f64>),
}

/// Rounds of moving ends past parts of the region found beyond them.
const ROUNDS: usize = 3;

/// Clears the far side of every found end of `p` ([`beyond_end`]), moving an end past each part
/// of the 95% region found there as [`extend_to_region`] does (from the point found, the profile
/// is searched outwards again), then clearing the moved end, for ROUNDS rounds at most.
/// `theta_min` and `chi2_min`: the minimum (the points' chi2); `moved` gets the ends moved.
pub fn certify_ends(
    obj: &Objective,
    (theta_min, chi2_min): (&[f64], f64),
    cov: &lsq::Covariance,
    p: &mut Profiles,
    region: &Region,
    inner: Option<&Inner>,
    moved: &mut Vec<Moved>,
) -> Result<Certified> {
    let threshold = chi2_min + p.delta;
    // Every found end at first; then the ends that moved.
    let mut todo: Vec<(usize, usize)> = (0..p.sides.len()).flat_map(|j| [(j, 0), (j, 1)]).collect();
    let mut unshown: Vec<Unshown> = Vec::new();
    for round in 0..=ROUNDS {
        let ends: Vec<(usize, usize, f64)> = todo
            .iter()
            .filter_map(|&(j, s)| match p.sides[j][s] {
                Side::At(t) => Some((j, s, t)),
                _ => None,
            })
            .collect();
        let look = |&(j, s, end): &(usize, usize, f64)| {
            beyond_end(obj, theta_min, j, s, end, threshold, region)
        };
        // Side by side for large data, as the profiles' ends.
        let found: Vec<Result<Beyond>> = if sums::is_large(obj.n_residuals()) {
            use rayon::prelude::*;
            ends.par_iter().map(look).collect()
        } else {
            ends.iter().map(look).collect()
        };
        let mut inside = Vec::new();
        for (&(j, s, end), f) in ends.iter().zip(found) {
            unshown.retain(|u| (u.j, u.s) != (j, s));
            match f? {
                Beyond::Clear => {}
                Beyond::Found(th, c) => inside.push((j, s, th, c)),
                Beyond::NotShown(why) => unshown.push(Unshown { j, s, end, why }),
            }
        }
        if inside.is_empty() {
            break;
        }
        if round == ROUNDS {
            for (j, s, ..) in inside {
                let end = match p.sides[j][s] {
                    Side::At(t) => t,
                    _ => f64::NAN,
                };
                unshown.push(Unshown {
                    j,
                    s,
                    end,
                    why: format!(
                        "parts of the region were still found beyond it after {ROUNDS} moves"
                    ),
                });
            }
            break;
        }
        let points: Vec<(Vec<f64>, f64)> = inside
            .iter()
            .map(|(_, _, th, c)| (th.clone(), *c))
            .collect();
        match extend_to_region(obj, chi2_min, cov, p, &points, inner)? {
            Extension::Lower(t) => return Ok(Certified::Lower(t)),
            Extension::Done(m) => {
                todo = m.iter().map(|m| (m.j, m.s)).collect();
                moved.extend(m);
                // A found point the extension did not move past is a bug's sign, not a clear
                // side: said so rather than looked at again.
                for (j, s, th, _) in &inside {
                    if !todo.contains(&(*j, *s)) {
                        unshown.push(Unshown {
                            j: *j,
                            s: *s,
                            end: th[*j],
                            why: "a part of the region beyond it could not be reached".into(),
                        });
                    }
                }
            }
        }
    }
    Ok(Certified::Done(unshown))
}
