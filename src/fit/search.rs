//! The global minimum of chi2 for every model, shown global rather than hoped for.
//!
//! **Solves** min chi2 over the model's search box ([`super::objective`]) and proves, for the
//! value U it reports, that no point of the box has chi2 below U - tau, with the tolerance
//! tau = 0.05 s (s the chi2 scale: 1.3% of the 95% interval's 3.84 s; a chi2 difference of
//! 0.05 moves a parameter by a fifth of its standard error), and that every local minimum that
//! could beat U by more than rounding has been polished.
//!
//! **Argument.** Every model's e at every point is monotone in each search coordinate once the
//! others are fixed (or, for the power law, linear in the one parameter profiled out), which
//! gives a lower bound of chi2 over any cell of a grid from its corners alone
//! ([`super::landscape`]). Branch and bound ([`super::bnb`]) then splits only the cells whose
//! bound is below U - tau, starting from a uniform grid (log eta in 24 cells of about 1, log
//! sigma_y in 16, the power law's exponents in 20 cells of 1) and refining to 40 halvings: a cell
//! it drops holds no point below U - tau, whatever the shape of chi2 inside it, so no valley,
//! however narrow, is missed (the old search scanned log eta in steps of 0.5 and could lock onto
//! the wrong eta valley). The bound tightens as cells shrink, so the refinement ends; the
//! remaining cells sit around the minima within tau of U. Every local minimum of the grid (a
//! node not above its neighbours at its cell's scale) in a cell that could still beat U is
//! polished: Brent's method inside its bracket for one-parameter models, Levenberg-Marquardt
//! ([`super::lsq`]) for two, and for the power law Levenberg-Marquardt in (A, a, b) from the
//! node's exact profile in A. The reported minimum is the lowest polished point. A polished
//! value below the certified lower bound would contradict the bounds: it is reported as a
//! warning, never ignored.
//!
//! **Costs**: e_vm and e_pm are tabulated once per grid value of eta or sigma_y (a row over all
//! points, counted as one evaluation); a node of `min` or `product` then costs one min or product
//! per point.
//!
//! **Not certified** (the fit says so: a warning and `converged: false`): when the search budget
//! (200000 cells, 4000 rows with the master curve, 400 with the ODE) or the number of polishes
//! (40) runs out, when the model cannot be evaluated on part of the box, or with the scan
//! switched off ([`super::FitOptions::scan`]).

use super::FitOptions;
use super::bnb::{Bnb, Candidate, Landscape, Limits};
use super::landscape::{PowerLaw, Separable};
use super::lsq::{self, LmOptions};
use super::models::ModelKind;
use super::objective::Objective;
use super::result::{GlobalSearch, show};
use super::scalar;
use crate::error::{Error, Result};
use crate::models::viscoelastic::VmMethod;

/// tau = TAU_REL U + TAU_ABS s (see the module doc).
pub const TAU_REL: f64 = 1e-7;
pub const TAU_ABS: f64 = 1e-6;
/// Local polishes allowed per fit.
const MAX_POLISH: u64 = 100;

/// A local minimum (or the best point) found by the search.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    pub theta: Vec<f64>,
    pub chi2: f64,
    pub converged: bool,
    pub reason: String,
}

/// What the search found and established.
#[derive(Debug, Clone)]
pub struct SearchOutcome {
    pub best: Found,
    pub global: GlobalSearch,
    pub warnings: Vec<String>,
    /// Grid nodes with chi2 within 3.84 s of the minimum (full internal coordinates, chi2): for
    /// checking that the 95% region has no part the profile intervals miss.
    pub near_nodes: Vec<(Vec<f64>, f64)>,
}

/// The tolerance tau for a best value U.
pub fn tolerance(obj: &Objective, upper: f64) -> f64 {
    TAU_REL * upper + TAU_ABS * obj.scale(upper)
}

fn polish_lm(obj: &Objective, start: &[f64]) -> Result<Found> {
    let all = vec![true; start.len()];
    let r = lsq::levenberg_marquardt(obj, start, &all, &LmOptions::default())?;
    Ok(Found {
        theta: r.theta,
        chi2: r.chi2,
        converged: r.converged,
        reason: r.reason.to_string(),
    })
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
            },
            best,
            warnings: vec![
                "global search switched off: the minimum is the local solver's from the start"
                    .into(),
            ],
            near_nodes: Vec::new(),
        });
    }
    let ode = matches!(obj.ev.method, VmMethod::Ode(_));
    let limits = Limits {
        max_cells: 200_000,
        max_rows: if ode { 400 } else { 4000 },
    };
    let (el, eh) = (obj.lower[0], obj.upper[0]);
    match kind {
        ModelKind::Vm | ModelKind::Pm | ModelKind::Min | ModelKind::Product => {
            let (sl, sh) = match kind {
                ModelKind::Vm => (0.0, 0.0),
                ModelKind::Pm => (obj.lower[0], obj.upper[0]),
                _ => (obj.lower[1], obj.upper[1]),
            };
            let active = [kind != ModelKind::Pm, kind != ModelKind::Vm];
            let land = Separable::new(obj, kind == ModelKind::Min, active);
            let range = [if active[0] { (el, eh) } else { (0.0, 0.0) }, (sl, sh)];
            let n0 = [
                if active[0] { 24 } else { 0 },
                if active[1] { 16 } else { 0 },
            ];
            let bnb = Bnb::new(land, range, n0, limits);
            let to_theta = move |_: &Separable, _: [usize; 2], t: [f64; 2]| match kind {
                ModelKind::Vm => vec![t[0]],
                ModelKind::Pm => vec![t[1]],
                _ => vec![t[0], t[1]],
            };
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
            let range = [(obj.lower[1], obj.upper[1]), (obj.lower[2], obj.upper[2])];
            let bnb = Bnb::new(land, range, [10, 10], limits);
            let to_theta =
                |land: &PowerLaw, r: [usize; 2], t: [f64; 2]| vec![land.profile(r).0, t[0], t[1]];
            let polish = |land: &PowerLaw, c: &Candidate| -> Result<Found> {
                let ln_a = land.profile(c.rows).0;
                polish_lm(obj, &[ln_a, c.t[0], c.t[1]])
            };
            run(obj, bnb, polished, &to_theta, &polish)
        }
    }
}

/// Brent's method inside the bracket of a grid minimum (value `at_node` at `t`); the node itself
/// is kept when Brent ends higher (a minimum on the edge of the box).
fn polish_brent(obj: &Objective, t: f64, lo: f64, hi: f64, at_node: f64) -> Result<Found> {
    if !(lo < hi) {
        return Ok(Found {
            theta: vec![t],
            chi2: at_node,
            converged: false,
            reason: "empty bracket".into(),
        });
    }
    // 1e-10 in the log parameter: far below any standard error a fit can have.
    let m = scalar::brent_minimize(|x| lsq::chi2(obj, &[x]), lo, hi, 1e-10)?;
    if m.fx.is_nan() || at_node < m.fx {
        return Ok(Found {
            theta: vec![t],
            chi2: at_node,
            converged: m.converged,
            reason: m.reason,
        });
    }
    Ok(Found {
        theta: vec![m.x],
        chi2: m.fx,
        converged: m.converged,
        reason: m.reason,
    })
}

/// The standard errors of the landscape's axes at theta (internal units, scaled by sqrt(s)), for
/// the resolution of the branch and bound; a parameter the data do not determine gets 1/64 of
/// its box.
fn axis_stderr(obj: &Objective, theta: &[f64]) -> Result<[f64; 2]> {
    let mut f0 = vec![0.0; obj.ev.len()];
    lsq::residuals_checked(obj, theta, &mut f0)?;
    let jac = lsq::jacobian(obj, theta, &vec![true; theta.len()], &f0)?;
    let cov = lsq::covariance(&jac);
    let s = obj.scale(lsq::chi2(obj, theta)?);
    let sd = |j: usize| {
        let v = (cov.matrix[(j, j)] * s).sqrt();
        let cap = (obj.upper[j] - obj.lower[j]) / 256.0;
        if v.is_finite() && v > 0.0 && v < cap {
            v
        } else {
            cap
        }
    };
    Ok(match obj.kind {
        ModelKind::Vm => [sd(0), 0.0],
        ModelKind::Pm => [0.0, sd(0)],
        ModelKind::Min | ModelKind::Product => [sd(0), sd(1)],
        ModelKind::PowerLaw => [sd(1), sd(2)],
    })
}

/// Starts across the kinks of `min` near theta: for each point whose two branches meet within
/// [`KINK_REACH`] standard errors and whose residual is positive there (chi2 then has a ridge
/// along the kink, so a second minimum may sit just across it), theta mirrored across the kink
/// (linearised). Convex kinks (negative residual) cannot hide a second minimum.
fn kink_starts(obj: &Objective, theta: &[f64], sd: [f64; 2]) -> Result<(Vec<Vec<f64>>, bool)> {
    let ev = obj.ev;
    let (t0, t1) = (theta[0], theta[1]);
    // Central differences in the log parameters, step matched to the model (see fd_step).
    let h = obj.fd_step;
    let mut out = Vec::new();
    let mut on_kink = false;
    for i in 0..ev.len() {
        let f = ev.e_vm(i, t0.exp())?;
        let g = ev.e_pm(i, t1.exp());
        let convex = f.min(g) <= ev.data.obs[i].e;
        let df = (ev.e_vm(i, (t0 + h).exp())? - ev.e_vm(i, (t0 - h).exp())?) / (2.0 * h);
        let dg = (ev.e_pm(i, (t1 + h).exp()) - ev.e_pm(i, (t1 - h).exp())) / (2.0 * h);
        let (gx, gy) = (df, -dg);
        let norm2 = gx * gx + gy * gy;
        let reach = ((gx * sd[0]).powi(2) + (gy * sd[1]).powi(2)).sqrt();
        let gap = f - g;
        // Within 1% of a standard error of its kink: the polish may have stopped there.
        on_kink |= norm2 > 0.0 && gap.abs() <= 0.01 * reach;
        if convex || !(norm2 > 0.0) || !(gap.abs() <= KINK_REACH * reach) {
            continue;
        }
        let k = -2.0 * gap / norm2;
        let start = vec![
            (t0 + k * gx).clamp(obj.lower[0], obj.upper[0]),
            (t1 + k * gy).clamp(obj.lower[1], obj.upper[1]),
        ];
        if start.iter().all(|x| x.is_finite()) {
            out.push(start);
        }
    }
    Ok((out, on_kink))
}

/// Line searches from a local minimum along the principal axes of its covariance (the valley
/// first), each a grid of [`VALLEY_POINTS`] over +-[`VALLEY_REACH`] standard errors then Brent's
/// method around the best grid point, followed by Levenberg-Marquardt from the lowest point;
/// repeated while it gains. Levenberg-Marquardt can stop on a kink of `min` (its Gauss-Newton
/// model sees one branch) or in a long flat valley with shallow wiggles; a derivative-free line
/// search along the valley does not.
fn polish_valleys(obj: &Objective, start: Found) -> Result<Found> {
    let k = start.theta.len();
    let mut best = start;
    for _ in 0..VALLEY_ROUNDS {
        let before = best.chi2;
        for (dir, sd) in principal_axes(obj, &best.theta)? {
            // The part of the line within reach that stays inside the box.
            let (mut amin, mut amax) = (-VALLEY_REACH * sd, VALLEY_REACH * sd);
            for (j, &dj) in dir.iter().enumerate().take(k) {
                if dj != 0.0 {
                    let a = (obj.lower[j] - best.theta[j]) / dj;
                    let b = (obj.upper[j] - best.theta[j]) / dj;
                    amin = amin.max(a.min(b));
                    amax = amax.min(a.max(b));
                }
            }
            if !(amax > amin) {
                continue;
            }
            let base = best.theta.clone();
            let at = |a: f64| -> Vec<f64> {
                (0..k)
                    .map(|j| (base[j] + a * dir[j]).clamp(obj.lower[j], obj.upper[j]))
                    .collect()
            };
            let grid: Vec<f64> = (0..VALLEY_POINTS)
                .map(|i| amin + (amax - amin) * i as f64 / (VALLEY_POINTS - 1) as f64)
                .collect();
            let vals = grid
                .iter()
                .map(|&a| lsq::chi2(obj, &at(a)))
                .collect::<Result<Vec<f64>>>()?;
            let Some(i) = (0..grid.len())
                .filter(|&i| !vals[i].is_nan())
                .min_by(|&x, &y| vals[x].total_cmp(&vals[y]))
            else {
                continue;
            };
            let (mut x, mut fx) = (grid[i], vals[i]);
            let (lo, hi) = (grid[i.saturating_sub(1)], grid[(i + 1).min(grid.len() - 1)]);
            if lo < hi {
                let m = scalar::brent_minimize(|a| lsq::chi2(obj, &at(a)), lo, hi, 1e-12)?;
                if m.fx < fx {
                    (x, fx) = (m.x, m.fx);
                }
            }
            if fx < best.chi2 {
                best = Found {
                    theta: at(x),
                    chi2: fx,
                    converged: best.converged,
                    reason: best.reason.clone(),
                };
            }
        }
        if best.chi2 < before {
            let again = polish_lm(obj, &best.theta)?;
            if again.chi2 <= best.chi2 {
                best = again;
            }
        }
        if !(best.chi2 < before - 1e-12 * before.abs()) {
            break;
        }
    }
    Ok(best)
}

/// Unit directions of the principal axes of (J^T J)^-1 at theta and the standard error along
/// each (error bars as given); a direction the data do not determine gets 1/256 of the box.
fn principal_axes(obj: &Objective, theta: &[f64]) -> Result<Vec<(Vec<f64>, f64)>> {
    let k = theta.len();
    let mut f0 = vec![0.0; obj.ev.len()];
    lsq::residuals_checked(obj, theta, &mut f0)?;
    let jac = lsq::jacobian(obj, theta, &vec![true; k], &f0)?;
    let jtj = jac.transpose() * &jac;
    let diag = (0..k)
        .map(|j| (obj.upper[j] - obj.lower[j]).powi(2))
        .sum::<f64>()
        .sqrt();
    if jtj.iter().any(|x| !x.is_finite()) {
        return Ok((0..k)
            .map(|j| {
                let mut d = vec![0.0; k];
                d[j] = 1.0;
                (d, diag / 256.0)
            })
            .collect());
    }
    let eig = jtj.symmetric_eigen();
    let lmax = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    let mut out: Vec<(Vec<f64>, f64)> = (0..k)
        .map(|q| {
            let lam = eig.eigenvalues[q];
            let sd = if lam > 1e-12 * lmax {
                (1.0 / lam).sqrt().min(diag / 256.0)
            } else {
                diag / 256.0
            };
            (eig.eigenvectors.column(q).iter().copied().collect(), sd)
        })
        .collect();
    out.sort_by(|a, b| b.1.total_cmp(&a.1));
    Ok(out)
}

/// The profile of a two-parameter model along axis `outer` at `u`: the other parameter
/// minimised by Levenberg-Marquardt from `centre` (the last profile point's minimum, so the
/// profile follows its valley, however narrow). Returns chi2 and the minimising inner value.
fn profile_point(obj: &Objective, outer: usize, u: f64, centre: f64) -> Result<(f64, f64)> {
    let inner = 1 - outer;
    let mut th = vec![0.0; 2];
    th[outer] = u;
    th[inner] = centre;
    let mut free = vec![true; 2];
    free[outer] = false;
    let r = lsq::levenberg_marquardt(obj, &th, &free, &LmOptions::default())?;
    Ok((r.chi2, r.theta[inner]))
}

/// Brent's method on the profile along each axis of a two-parameter model in turn (see
/// [`profile_point`]), over +-[`VALLEY_REACH`] standard errors, then Levenberg-Marquardt; repeated
/// while it gains.
fn polish_profiles(obj: &Objective, start: Found) -> Result<Found> {
    let mut best = start;
    for _ in 0..VALLEY_ROUNDS {
        let before = best.chi2;
        let sd = axis_stderr(obj, &best.theta)?;
        for outer in 0..2 {
            let inner = 1 - outer;
            let base = best.theta.clone();
            let centre = std::cell::Cell::new(base[inner]);
            let p = |u: f64| -> Result<f64> {
                let (v, at) = profile_point(obj, outer, u, centre.get())?;
                centre.set(at);
                Ok(v)
            };
            let (a, b) = (
                (base[outer] - VALLEY_REACH * sd[outer]).max(obj.lower[outer]),
                (base[outer] + VALLEY_REACH * sd[outer]).min(obj.upper[outer]),
            );
            if !(a < b) {
                continue;
            }
            let n = 9;
            let grid: Vec<f64> = (0..n)
                .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
                .collect();
            // From the middle outwards, each point warm-started from its neighbour.
            let mut vals = vec![f64::INFINITY; n];
            for half in [(n / 2..n).collect::<Vec<_>>(), (0..n / 2).rev().collect()] {
                centre.set(base[inner]);
                for i in half {
                    vals[i] = p(grid[i])?;
                }
            }
            let i = (0..n)
                .min_by(|&x, &y| vals[x].total_cmp(&vals[y]))
                .unwrap_or(0);
            let (lo, hi) = (grid[i.saturating_sub(1)], grid[(i + 1).min(n - 1)]);
            centre.set(base[inner]);
            let m = scalar::brent_minimize(p, lo, hi, 1e-12)?;
            let (u, fu) = if m.fx < vals[i] {
                (m.x, m.fx)
            } else {
                (grid[i], vals[i])
            };
            if fu < best.chi2 {
                let (v, at) = profile_point(obj, outer, u, centre.get())?;
                let mut th = vec![0.0; 2];
                th[outer] = u;
                th[inner] = at;
                if v < best.chi2 {
                    best = Found {
                        theta: th,
                        chi2: v,
                        converged: best.converged,
                        reason: best.reason.clone(),
                    };
                }
            }
        }
        let again = polish_lm(obj, &best.theta)?;
        if again.chi2 <= best.chi2 {
            best = again;
        }
        if !(best.chi2 < before - 1e-12 * before.abs()) {
            break;
        }
    }
    Ok(best)
}

const VALLEY_ROUNDS: usize = 3;
const VALLEY_POINTS: usize = 25;
const VALLEY_REACH: f64 = 4.0;

/// How far (in standard errors) from a minimum a kink of `min` is looked across.
const KINK_REACH: f64 = 3.0;
/// Resolution of the branch and bound around the minima, in standard errors (the cost grows as
/// 1/RESOLUTION): `min` and `product`, whose e_pm has a kink (min) or a jump of curvature at
/// yield that can put shallow minima close together; the smooth power law; one-parameter
/// models, where it is cheap.
const RESOLUTION_2D: f64 = 0.25;
const RESOLUTION_SMOOTH: f64 = 1.0;
const RESOLUTION_1D: f64 = 1.0 / 32.0;

/// Maps a landscape cell (grid indices and offsets) to the model's parameters.
type ToTheta<'a, L> = &'a dyn Fn(&L, [usize; 2], [f64; 2]) -> Vec<f64>;

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
            name: "smallest chi2 on the search grid (the squares overflow: e_err too small?)",
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
    let axes_of = |th: &[f64]| -> [f64; 2] {
        match obj.kind {
            ModelKind::Vm => [th[0], 0.0],
            ModelKind::Pm => [0.0, th[0]],
            ModelKind::Min | ModelKind::Product => [th[0], th[1]],
            ModelKind::PowerLaw => [th[1], th[2]],
        }
    };
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
    if let Some(b) = best_of(&polished) {
        let sd = axis_stderr(obj, &b.theta)?;
        let k = match obj.kind {
            ModelKind::Vm | ModelKind::Pm => RESOLUTION_1D,
            ModelKind::Min | ModelKind::Product => RESOLUTION_2D,
            ModelKind::PowerLaw => RESOLUTION_SMOOTH,
        };
        bnb.set_resolution([k * sd[0], k * sd[1]]);
    }
    bnb.refine(upper, &tau_of);
    if let Some((_, _, v)) = bnb.best_node()
        && v < upper
    {
        upper = v;
    }
    for c in bnb.candidates(upper) {
        try_polish(&bnb, &c, &mut polished, &mut upper)?;
    }
    if obj.kind == ModelKind::Min {
        // Across the kinks near the best minimum (and again from what that finds, twice).
        let mut looked: Vec<Vec<f64>> = Vec::new();
        for _ in 0..3 {
            let Some(b) = best_of(&polished) else { break };
            if looked.contains(&b.theta) {
                break;
            }
            looked.push(b.theta.clone());
            let sd = axis_stderr(obj, &b.theta)?;
            for start in kink_starts(obj, &b.theta, sd)?.0 {
                if n_polish >= MAX_POLISH {
                    skipped += 1;
                    continue;
                }
                n_polish += 1;
                polished.push(polish_lm(obj, &start)?);
            }
        }
    }
    if obj.kind.n_params() > 1
        && let Some(b) = best_of(&polished)
    {
        n_polish += 1;
        let mut v = polish_valleys(obj, b)?;
        // Levenberg-Marquardt may have stopped on a kink of `min`: follow the profiles then.
        for _ in 0..VALLEY_ROUNDS {
            if obj.kind != ModelKind::Min
                || !kink_starts(obj, &v.theta, axis_stderr(obj, &v.theta)?)?.1
            {
                break;
            }
            let before = v.chi2;
            v = polish_profiles(obj, v)?;
            if !(v.chi2 < before) {
                break;
            }
        }
        polished.push(v);
    }
    let mut warnings = Vec::new();
    // The answer: the lowest polished point; the best node only if every polish ended above it
    // (after one more polish from the node itself).
    let (_, _, node_v) = bnb.best_node().expect("checked above");
    if best_of(&polished).is_none_or(|f| f.chi2 > node_v)
        && let Some(c) = bnb.best_candidate()
    {
        n_polish += 1;
        polished.push(polish(&bnb.land, &c)?);
    }
    let (node_r, node_t, node_v) = bnb.best_node().expect("checked above");
    let best = match best_of(&polished) {
        Some(f) if f.chi2 <= node_v => f,
        other => {
            warnings.push(format!(
                "no local polish reached the best grid point (chi2 {}{}); the grid point is \
                 reported",
                show(node_v),
                other
                    .as_ref()
                    .map(|f| format!(", best polish {} ({})", show(f.chi2), f.reason))
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
    // The cell holding the reported point was never dropped, so some bound is at most the
    // point's chi2; anything else means a bound was wrong (rounding allowed: 1e-9 relative).
    let lowest_any = cert.lowest.min(cert.lowest_fine);
    if !(lowest_any <= best.chi2 + 1e-9 * best.chi2.abs().max(1.0)) {
        certified = false;
        warnings.push(format!(
            "the global search's lower bounds were contradicted (bound {}, point {}): the \
             certificate is void",
            show(lowest_any),
            show(best.chi2)
        ));
    }
    for why in &cert.reasons {
        warnings.push(format!(
            "global minimum not certified: {why}; a chi2 up to {} below the reported one \
             cannot be excluded",
            show(gap)
        ));
    }
    if cert.reasons.is_empty() && gap > tau * (1.0 + 1e-9) {
        warnings.push(format!(
            "global minimum not certified: a chi2 up to {} below the reported one cannot be \
             excluded (tolerance {})",
            show(gap),
            show(tau)
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
    let scale = obj.scale(best.chi2);
    let near_nodes = bnb
        .nodes_below(best.chi2 + super::objective::CHI2_1DOF_95 * scale)
        .into_iter()
        .map(|(r, t, v)| (to_theta(&bnb.land, r, t), v))
        .collect();
    Ok(SearchOutcome {
        global: GlobalSearch {
            certified,
            gap_chi2: gap,
            tolerance_chi2: tau,
            cells: bnb.cells,
            polishes: n_polish,
        },
        best,
        warnings,
        near_nodes,
    })
}
