//! The independent exhaustive reference of the randomized global-minimum test (see `main.rs`):
//! it shares nothing with the fit's search or polish, only the library's model functions.

use crate::cases::{Case, Truth};
use argmin::core::{CostFunction, Executor};
use argmin::solver::neldermead::NelderMead;
use restitution::contact::Contact;
use restitution::fit::models::{
    ModelKind, POWERLAW_D_REF_MM, POWERLAW_V_REF_M_S, e_pm, e_vm, powerlaw_d_mm, predict_e,
};
use restitution::fit::scalar::brent_minimize;
use restitution::fit::{FitData, FitOptions, fit};
use restitution::models::viscoelastic::master::KAPPA_MAX;
use restitution::models::viscoelastic::{ContactEnd, VmMethod};

/// chi2 of `kind` at physical parameters `p`, point by point through `predict_e`.
pub fn chi2_direct(data: &FitData, kind: ModelKind, p: &[f64], rule: ContactEnd) -> f64 {
    data.obs
        .iter()
        .zip(&data.contacts)
        .enumerate()
        .map(|(i, (o, c))| {
            let m = predict_e(kind, c, o.v_n_m_s, p, rule, &VmMethod::Master).unwrap_or(f64::NAN);
            ((o.e - m) / data.sigma(i)).powi(2)
        })
        .sum()
}

/// `case`'s fit by `kind` (with its contact rule) and the fit's search box in internal
/// coordinates (lower, upper), for checking its intervals; None where either fails.
#[allow(dead_code)] // for examples/interval_scan.rs and tests/fit_global.rs
pub fn fit_with_box(
    case: &Case,
    kind: ModelKind,
) -> Option<(restitution::fit::FitResult, Vec<f64>, Vec<f64>)> {
    let options = FitOptions {
        rule: case.rule,
        ..FitOptions::default()
    };
    let r = fit(&case.data, kind, &options).ok()?;
    let ev = restitution::fit::models::Evaluator::new(&case.data, case.rule, VmMethod::Master);
    let obj = restitution::fit::objective::Objective::new(&ev, kind).ok()?;
    Some((r, obj.lower.clone(), obj.upper.clone()))
}

/// A brute-force profile point of `min` or `product`: the least chi2 over `m` + 1 log-spaced
/// values of parameter 1 - j across [lo, hi] (internal coordinates) with parameter j at exp(t),
/// and where. An upper bound of the true profile: it can only find points of the 95% region,
/// never invent them.
#[allow(dead_code)] // for examples/interval_scan.rs and tests/fit_global.rs
pub fn separable_profile(
    data: &FitData,
    kind: ModelKind,
    rule: ContactEnd,
    (j, t): (usize, f64),
    (lo, hi): (f64, f64),
    m: usize,
) -> (f64, f64) {
    (0..=m)
        .map(|k| {
            let y = lo + (hi - lo) * k as f64 / m as f64;
            let p = if j == 0 { [t, y] } else { [y, t] };
            (chi2_direct(data, kind, &p.map(f64::exp), rule), y)
        })
        .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a })
}

/// A brute-force profile point of the power law's exponent j (1: a, 2: b) at t: the least chi2
/// over 1500 values of the other exponent across its box (`lower`, `upper`: the fit's box in
/// internal coordinates, ln A first) then Brent's method within a grid step of the best, each
/// with A at its weighted least-squares value (1 - e is linear in A; kept in A's box, where chi2
/// is a parabola in A); chi2 from the model functions. An upper bound of the true profile, as
/// [`separable_profile`].
#[allow(dead_code)] // for examples/interval_scan.rs and tests/fit_global.rs
pub fn powerlaw_profile(
    data: &FitData,
    rule: ContactEnd,
    (j, t): (usize, f64),
    lower: &[f64],
    upper: &[f64],
) -> f64 {
    let kind = ModelKind::PowerLaw;
    let (a_lo, a_hi) = (lower[0].exp(), upper[0].exp());
    let best_a = |a: f64, b: f64| -> f64 {
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for (i, (o, c)) in data.obs.iter().zip(&data.contacts).enumerate() {
            let x = (powerlaw_d_mm(c) / POWERLAW_D_REF_MM).powf(-a)
                * (o.v_n_m_s / POWERLAW_V_REF_M_S).powf(b);
            let w = data.sigma(i).powi(-2);
            sxy += w * x * (1.0 - o.e);
            sxx += w * x * x;
        }
        (sxy / sxx).clamp(a_lo, a_hi)
    };
    let k = 3 - j;
    let chi2 = |x: f64| {
        let (a, b) = if j == 1 { (t, x) } else { (x, t) };
        chi2_direct(data, kind, &[best_a(a, b), a, b], rule)
    };
    let m = 1500;
    let step = (upper[k] - lower[k]) / m as f64;
    let (x, v) = (0..=m)
        .map(|i| lower[k] + step * i as f64)
        .map(|x| (x, chi2(x)))
        .fold(
            (lower[k], f64::INFINITY),
            |a, b| if b.1 < a.1 { b } else { a },
        );
    let (lo, hi) = ((x - step).max(lower[k]), (x + step).min(upper[k]));
    match restitution::fit::scalar::brent_minimize(|y| Ok(chi2(y)), lo, hi, 1e-12) {
        Ok(r) if r.fx < v => r.fx,
        _ => v,
    }
}

/// A brute-force profile point of the power law's coefficient A at ln A = `ln_a`: the least
/// chi2 over both exponents (a, b) in their box (`lower`, `upper`: the fit's box in internal
/// coordinates, ln A first), with A held. [`powerlaw_a_profile_at`] gives the exponents too.
///
/// With A held nothing is linear, and the valley of (a, b) can be narrow and oblique (the
/// points' ln(d/d_ref) and ln(v/v_ref) nearly collinear), where rounds of one-exponent searches
/// creep: so a 120 x 120 grid over the box, then from each of the 5 lowest grid-local minima a
/// damped Newton polish (Levenberg-Marquardt steps on the exact gradient and Hessian of chi2 in
/// (a, b), the Gauss-Newton Hessian where the exact one is not positive definite, each step
/// projected into the box and kept only where it lowers chi2) alternating with Brent's method
/// along a and along b within a grid step (for a minimum on an edge of the box), until a round
/// lowers chi2 by less than 1e-12 relative. Independent of the fit: nothing of its search,
/// polish or profile is used, only the model functions: the grid and the derivatives are
/// written out here from 1 - e = A (d/d_ref)^(-a) (v/v_ref)^b, and every value compared or
/// returned is [`chi2_direct`]. An upper bound of the true profile, as [`separable_profile`]:
/// it can only find points of the 95% region, never invent them.
#[allow(dead_code)] // for examples/interval_scan.rs
pub fn powerlaw_a_profile(
    data: &FitData,
    rule: ContactEnd,
    ln_a: f64,
    lower: &[f64],
    upper: &[f64],
) -> f64 {
    powerlaw_a_profile_at(data, rule, ln_a, lower, upper).0
}

/// [`powerlaw_a_profile`] and where: (chi2, a, b).
#[allow(dead_code)] // for examples/interval_scan.rs
pub fn powerlaw_a_profile_at(
    data: &FitData,
    rule: ContactEnd,
    ln_a: f64,
    lower: &[f64],
    upper: &[f64],
) -> (f64, f64, f64) {
    let kind = ModelKind::PowerLaw;
    let a_coef = ln_a.exp();
    // Per point: ln(d/d_ref), ln(v/v_ref), 1 - e, weight.
    let pts: Vec<(f64, f64, f64, f64)> = data
        .obs
        .iter()
        .zip(&data.contacts)
        .enumerate()
        .map(|(i, (o, c))| {
            (
                (powerlaw_d_mm(c) / POWERLAW_D_REF_MM).ln(),
                (o.v_n_m_s / POWERLAW_V_REF_M_S).ln(),
                1.0 - o.e,
                data.sigma(i).powi(-2),
            )
        })
        .collect();
    let chi2 = |a: f64, b: f64| {
        let v = chi2_direct(data, kind, &[a_coef, a, b], rule);
        if v.is_nan() { f64::INFINITY } else { v }
    };
    let (a_box, b_box) = ((lower[1], upper[1]), (lower[2], upper[2]));
    let clamp = |a: f64, b: f64| (a.clamp(a_box.0, a_box.1), b.clamp(b_box.0, b_box.1));

    // The grid, from the formula: A exp(-a x1) exp(b x2) with both factors tabulated.
    let n = 120;
    let (ga, gb) = (axis(a_box.0, a_box.1, n), axis(b_box.0, b_box.1, n));
    let (step_a, step_b) = (ga[1] - ga[0], gb[1] - gb[0]);
    let ea: Vec<Vec<f64>> = ga
        .iter()
        .map(|&a| pts.iter().map(|p| a_coef * (-a * p.0).exp()).collect())
        .collect();
    let eb: Vec<Vec<f64>> = gb
        .iter()
        .map(|&b| pts.iter().map(|p| (b * p.1).exp()).collect())
        .collect();
    let mut values = Vec::with_capacity(n * n);
    for ra in &ea {
        for rb in &eb {
            let v: f64 = pts
                .iter()
                .zip(ra.iter().zip(rb))
                .map(|(p, (x, y))| p.3 * (p.2 - x * y).powi(2))
                .sum();
            values.push(if v.is_finite() { v } else { f64::INFINITY });
        }
    }
    let mut minima = grid_minima(&values, &[n, n]);
    minima.sort_by(|&i, &j| values[i].total_cmp(&values[j]));

    // Gradient and Hessian of chi2 in (a, b): with m = A exp(-a x1 + b x2) and r = y - m,
    // dm/da = -x1 m, dm/db = x2 m; H = 2 sum w (dm dm^T - r d2m). Also the Gauss-Newton part.
    let derivs = |a: f64, b: f64| {
        let (mut g, mut h, mut hgn) = ([0.0; 2], [0.0; 3], [0.0; 3]);
        for &(x1, x2, y, w) in &pts {
            let m = a_coef * (-a * x1 + b * x2).exp();
            let r = y - m;
            let (da, db) = (-x1 * m, x2 * m);
            g[0] -= 2.0 * w * r * da;
            g[1] -= 2.0 * w * r * db;
            let gn = [da * da, da * db, db * db];
            let second = [x1 * x1 * m, -x1 * x2 * m, x2 * x2 * m];
            for k in 0..3 {
                hgn[k] += 2.0 * w * gn[k];
                h[k] += 2.0 * w * (gn[k] - r * second[k]);
            }
        }
        (g, h, hgn)
    };
    let pos_def = |h: &[f64; 3]| h[0] > 0.0 && h[2] > 0.0 && h[0] * h[2] - h[1] * h[1] > 0.0;
    // Levenberg-Marquardt from (a, b) at chi2 f, each step projected into the box.
    let newton = |(mut a, mut b, mut f): (f64, f64, f64)| {
        let mut lambda = 1e-3;
        for _ in 0..500 {
            let (g, h, hgn) = derivs(a, b);
            let h = if pos_def(&h) { h } else { hgn };
            let d = [h[0].abs().max(1e-300), h[2].abs().max(1e-300)];
            let mut moved = None;
            while lambda < 1e20 {
                let k = [h[0] + lambda * d[0], h[1], h[2] + lambda * d[1]];
                let det = k[0] * k[2] - k[1] * k[1];
                if pos_def(&k) && det.is_finite() {
                    let sa = -(k[2] * g[0] - k[1] * g[1]) / det;
                    let sb = -(k[0] * g[1] - k[1] * g[0]) / det;
                    let (qa, qb) = clamp(a + sa, b + sb);
                    let fq = chi2(qa, qb);
                    if fq < f {
                        moved = Some((qa, qb, fq));
                        lambda = (lambda / 4.0).max(1e-12);
                        break;
                    }
                }
                lambda *= 4.0;
            }
            let Some((qa, qb, fq)) = moved else { break };
            let gain = f - fq;
            (a, b, f) = (qa, qb, fq);
            if gain <= 1e-13 * f {
                break;
            }
        }
        (a, b, f)
    };
    // Brent's method along a, then along b, within a grid step of the point.
    let sweep = |(mut a, mut b, mut f): (f64, f64, f64)| {
        let (lo, hi) = ((a - step_a).max(a_box.0), (a + step_a).min(a_box.1));
        if let Ok(r) = brent_minimize(|x| Ok(chi2(x, b)), lo, hi, 1e-12)
            && r.fx < f
        {
            (a, f) = (r.x, r.fx);
        }
        let (lo, hi) = ((b - step_b).max(b_box.0), (b + step_b).min(b_box.1));
        if let Ok(r) = brent_minimize(|x| Ok(chi2(a, x)), lo, hi, 1e-12)
            && r.fx < f
        {
            (b, f) = (r.x, r.fx);
        }
        (a, b, f)
    };
    let mut best = (f64::NAN, f64::NAN, f64::INFINITY);
    for &idx in minima.iter().take(5) {
        let (a, b) = (ga[idx / n], gb[idx % n]);
        let mut p = (a, b, chi2(a, b));
        for _ in 0..50 {
            let before = p.2;
            p = sweep(newton(p));
            if !(before - p.2 > 1e-12 * p.2) {
                break;
            }
        }
        if p.2 < best.2 {
            best = p;
        }
    }
    (best.2, best.0, best.1)
}

/// The search box of `kind` as the fit documents it, recomputed from the contact functions.
fn reference_box(data: &FitData, kind: ModelKind) -> Vec<(f64, f64)> {
    let pts = || data.obs.iter().zip(&data.contacts);
    let kmax = pts()
        .map(|(o, c)| c.kappa(1.0, o.v_n_m_s))
        .fold(0.0, f64::max);
    let eta = ((1e-8 / kmax).ln(), (0.999 * KAPPA_MAX / kmax).ln());
    let sigma_at = |c: &Contact, v: f64| c.sigma_y_for_yield_velocity(v).ln();
    let sigma = (
        pts()
            .map(|(o, c)| sigma_at(c, o.v_n_m_s * 1e-6))
            .fold(f64::INFINITY, f64::min),
        pts()
            .map(|(o, c)| sigma_at(c, o.v_n_m_s * 1.5))
            .fold(f64::NEG_INFINITY, f64::max),
    );
    match kind {
        ModelKind::Vm => vec![eta],
        ModelKind::Pm => vec![sigma],
        ModelKind::Min | ModelKind::Product => vec![eta, sigma],
        ModelKind::PowerLaw => {
            let (a, b) = powerlaw_exponent_box(data);
            vec![(1e-9f64.ln(), 1e3f64.ln()), a, b]
        }
    }
}

/// The exponents' ranges as the fit documents them (`fit::objective`): [-10, 10] each, each end
/// brought in, where the data are extreme, to the least room / (|x1| + |x2|) over the points
/// that push ln(1 - e) = ln A - a x1 + b x2 towards its limit at that end: 300 - ln(1e3)
/// towards overflow, 700 + ln(1e-9) towards underflow; the same for x less its mean.
fn powerlaw_exponent_box(data: &FitData) -> ((f64, f64), (f64, f64)) {
    let x: Vec<(f64, f64)> = data
        .obs
        .iter()
        .zip(&data.contacts)
        .map(|(o, c)| {
            (
                (powerlaw_d_mm(c) / POWERLAW_D_REF_MM).ln(),
                (o.v_n_m_s / POWERLAW_V_REF_M_S).ln(),
            )
        })
        .collect();
    let n = x.len() as f64;
    let (m1, m2) = (
        x.iter().map(|p| p.0).sum::<f64>() / n,
        x.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let (over, under) = (300.0 - 1e3f64.ln(), 700.0 + 1e-9f64.ln());
    let (mut a_neg, mut a_pos, mut b_neg, mut b_pos) = (10.0f64, 10.0f64, 10.0f64, 10.0f64);
    for &(p1, p2) in &x {
        for (x1, x2) in [(p1, p2), (p1 - m1, p2 - m2)] {
            let r = x1.abs() + x2.abs();
            if r == 0.0 {
                continue;
            }
            // -a x1 is largest at a < 0 where x1 > 0; b x2 at b > 0 where x2 > 0.
            let (a_over, a_under) = if x1 > 0.0 {
                (&mut a_neg, &mut a_pos)
            } else {
                (&mut a_pos, &mut a_neg)
            };
            *a_over = a_over.min(over / r);
            *a_under = a_under.min(under / r);
            let (b_over, b_under) = if x2 > 0.0 {
                (&mut b_pos, &mut b_neg)
            } else {
                (&mut b_neg, &mut b_pos)
            };
            *b_over = b_over.min(over / r);
            *b_under = b_under.min(under / r);
        }
    }
    ((-a_neg, a_pos), (-b_neg, b_pos))
}

struct Chi2Problem<'a> {
    data: &'a FitData,
    kind: ModelKind,
    rule: ContactEnd,
    bx: Vec<(f64, f64)>,
}

impl CostFunction for Chi2Problem<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, t: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        // Nelder-Mead is unconstrained: project into the box.
        let p: Vec<f64> = t
            .iter()
            .zip(&self.bx)
            .enumerate()
            .map(|(j, (&x, &(lo, hi)))| {
                let x = x.clamp(lo, hi);
                if self.kind == ModelKind::PowerLaw && j > 0 {
                    x
                } else {
                    x.exp()
                }
            })
            .collect();
        let c = chi2_direct(self.data, self.kind, &p, self.rule);
        Ok(if c.is_nan() { f64::INFINITY } else { c })
    }
}

/// Nelder-Mead from `start` (internal coordinates) with an initial simplex of `step` per axis.
fn nelder_mead(
    data: &FitData,
    kind: ModelKind,
    rule: ContactEnd,
    bx: &[(f64, f64)],
    start: &[f64],
    step: &[f64],
) -> (f64, Vec<f64>) {
    let mut simplex = vec![start.to_vec()];
    for j in 0..start.len() {
        let mut p = start.to_vec();
        p[j] += step[j];
        simplex.push(p);
    }
    let problem = Chi2Problem {
        data,
        kind,
        rule,
        bx: bx.to_vec(),
    };
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(1e-13)
        .expect("valid tolerance");
    match Executor::new(problem, solver)
        .configure(|s| s.max_iters(3000))
        .run()
    {
        Ok(r) => {
            let st = r.state();
            let p = st.best_param.clone().unwrap_or_default();
            (st.best_cost, p)
        }
        Err(_) => (f64::INFINITY, Vec::new()),
    }
}

/// Local minima of values on a grid with `dims` (row-major), ties broken by index.
fn grid_minima(values: &[f64], dims: &[usize]) -> Vec<usize> {
    let strides: Vec<usize> = (0..dims.len())
        .map(|k| dims[k + 1..].iter().product())
        .collect();
    let mut out = Vec::new();
    for (idx, &v) in values.iter().enumerate() {
        if !v.is_finite() {
            continue;
        }
        let coord: Vec<usize> = (0..dims.len())
            .map(|k| idx / strides[k] % dims[k])
            .collect();
        let mut is_min = true;
        let n_nb = 3usize.pow(dims.len() as u32);
        for code in 0..n_nb {
            let mut off = code;
            let mut j = 0usize;
            let mut inside = true;
            let mut zero = true;
            for k in 0..dims.len() {
                let d = (off % 3) as i64 - 1;
                off /= 3;
                zero &= d == 0;
                let c = coord[k] as i64 + d;
                if c < 0 || c >= dims[k] as i64 {
                    inside = false;
                    break;
                }
                j += c as usize * strides[k];
            }
            if zero || !inside {
                continue;
            }
            let w = values[j];
            if w < v || (w == v && j < idx) {
                is_min = false;
                break;
            }
        }
        if is_min {
            out.push(idx);
        }
    }
    out
}

fn axis(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
        .collect()
}

/// The reference minimum of chi2 for `kind` (see the module doc).
pub fn reference_chi2(data: &FitData, kind: ModelKind, rule: ContactEnd) -> f64 {
    reference(data, kind, rule).0
}

/// The reference minimum and where it is (internal coordinates, clamped into the box).
pub fn reference(data: &FitData, kind: ModelKind, rule: ContactEnd) -> (f64, Vec<f64>) {
    let bx = reference_box(data, kind);
    let n = data.len();
    let w: Vec<f64> = (0..n).map(|i| data.sigma(i).powi(-2)).collect();
    let m = VmMethod::Master;
    let vm_row = |t: f64| -> Vec<f64> {
        data.obs
            .iter()
            .zip(&data.contacts)
            .map(|(o, c)| e_vm(c, o.v_n_m_s, t.exp(), rule, &m).unwrap_or(f64::NAN))
            .collect()
    };
    let pm_row = |t: f64| -> Vec<f64> {
        data.obs
            .iter()
            .zip(&data.contacts)
            .map(|(o, c)| e_pm(c, o.v_n_m_s, t.exp()).unwrap_or(f64::NAN))
            .collect()
    };
    let chi2_of = |e: &dyn Fn(usize) -> f64| -> f64 {
        (0..n).map(|i| w[i] * (data.obs[i].e - e(i)).powi(2)).sum()
    };
    let (axes, values): (Vec<Vec<f64>>, Vec<f64>) = match kind {
        ModelKind::Vm | ModelKind::Pm => {
            let g = axis(bx[0].0, bx[0].1, 4000);
            let vals = g
                .iter()
                .map(|&t| {
                    let row = if kind == ModelKind::Vm {
                        vm_row(t)
                    } else {
                        pm_row(t)
                    };
                    chi2_of(&|i| row[i])
                })
                .collect();
            (vec![g], vals)
        }
        ModelKind::Min | ModelKind::Product => {
            let (ge, gs) = (axis(bx[0].0, bx[0].1, 400), axis(bx[1].0, bx[1].1, 300));
            let vm: Vec<Vec<f64>> = ge.iter().map(|&t| vm_row(t)).collect();
            let pm: Vec<Vec<f64>> = gs.iter().map(|&t| pm_row(t)).collect();
            let mut vals = Vec::with_capacity(ge.len() * gs.len());
            for a in &vm {
                for b in &pm {
                    vals.push(chi2_of(&|i| {
                        if kind == ModelKind::Min {
                            a[i].min(b[i])
                        } else {
                            a[i] * b[i]
                        }
                    }));
                }
            }
            (vec![ge, gs], vals)
        }
        ModelKind::PowerLaw => {
            let ga = axis(bx[0].0, bx[0].1, 48);
            let (gx, gy) = (axis(bx[1].0, bx[1].1, 64), axis(bx[2].0, bx[2].1, 64));
            let lx: Vec<f64> = data
                .contacts
                .iter()
                .map(|c| (powerlaw_d_mm(c) / POWERLAW_D_REF_MM).ln())
                .collect();
            let lv: Vec<f64> = data
                .obs
                .iter()
                .map(|o| (o.v_n_m_s / POWERLAW_V_REF_M_S).ln())
                .collect();
            let mut vals = Vec::with_capacity(ga.len() * gx.len() * gy.len());
            for &la in &ga {
                for &a in &gx {
                    for &b in &gy {
                        vals.push(chi2_of(&|i| 1.0 - (la - a * lx[i] + b * lv[i]).exp()));
                    }
                }
            }
            (vec![ga, gx, gy], vals)
        }
    };
    let dims: Vec<usize> = axes.iter().map(|a| a.len()).collect();
    let steps: Vec<f64> = axes.iter().map(|a| a[1] - a[0]).collect();
    let (mut best, mut at) = (f64::INFINITY, Vec::new());
    for (idx, &v) in values.iter().enumerate() {
        if v < best {
            best = v;
            at = (0..dims.len())
                .map(|k| axes[k][idx / strides_of(&dims)[k] % dims[k]])
                .collect();
        }
    }
    let strides: Vec<usize> = (0..dims.len())
        .map(|k| dims[k + 1..].iter().product())
        .collect();
    let mut minima = grid_minima(&values, &dims);
    minima.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    // Every grid-local minimum, lowest first (at most 60: beyond that they are plateau noise
    // far above the best; the count is printed by the example when it is reached).
    for &idx in minima.iter().take(60) {
        let start: Vec<f64> = (0..dims.len())
            .map(|k| axes[k][idx / strides[k] % dims[k]])
            .collect();
        let (v, p) = nelder_mead(data, kind, rule, &bx, &start, &steps);
        if v < best {
            best = v;
            at = p.iter().zip(&bx).map(|(x, b)| x.clamp(b.0, b.1)).collect();
        }
    }
    (best, at)
}

fn strides_of(dims: &[usize]) -> Vec<usize> {
    (0..dims.len())
        .map(|k| dims[k + 1..].iter().product())
        .collect()
}

/// One model's comparison on one case.
pub struct Outcome {
    pub seed: u64,
    pub truth: Truth,
    pub kind: ModelKind,
    pub fit_chi2: f64,
    pub ref_chi2: f64,
    pub certified: bool,
    /// How far below its chi2 the fit's certificate allows the global minimum to lie.
    pub gap: f64,
    /// Cells around the minima where the certificate rests on the polishes.
    pub fine_cells: u64,
    /// The rounding of chi2 itself: sum of w (8 eps max(1, |e|))^2, eight ulps in each residual
    /// (the model's few operations and the difference); chi2 values closer than this are equal.
    pub rounding: f64,
    pub converged: bool,
    pub error: Option<String>,
}

impl Outcome {
    /// The fit is at most 1e-6 relative above the reference.
    pub fn pass(&self) -> bool {
        self.error.is_none() && self.fit_chi2 <= self.ref_chi2 * (1.0 + 1e-6) + self.rounding
    }

    /// The fit's certificate holds against the reference: a certified fit lies above the
    /// reference by no more than the gap it states (plus 1e-12 of its chi2 and the rounding of
    /// chi2). A certificate with fine cells leaves them to the polishes: a difference there is
    /// a polish that fell short ([`Outcome::short_in_fine_cells`]), which the output declares
    /// possible; without fine cells it is a false certificate, the worst outcome: a wrong
    /// number that says it is right.
    pub fn certificate_holds(&self) -> bool {
        !self.certified || self.within_gap() || self.fine_cells > 0
    }

    /// A certified fit above the reference by no more than the gap it states (plus 1e-12 of its
    /// chi2 and the rounding of chi2).
    pub fn within_gap(&self) -> bool {
        self.error.is_none()
            && self.certified
            && self.fit_chi2 - self.ref_chi2 <= self.gap + 1e-12 * self.fit_chi2 + self.rounding
    }

    /// A certified fit with fine cells, above the reference by more than the pass allows.
    pub fn short_in_fine_cells(&self) -> bool {
        self.certified && self.fine_cells > 0 && !self.pass() && self.error.is_none()
    }
}

/// Fits every model to the case and compares with the reference.
pub fn check(case: &Case) -> Vec<Outcome> {
    check_data(case.seed, case.truth, &case.data, ContactEnd::Overlap)
}

/// As [`check`], for any data and either contact-end rule.
pub fn check_data(seed: u64, truth: Truth, data: &FitData, rule: ContactEnd) -> Vec<Outcome> {
    let rounding: f64 = (0..data.len())
        .map(|i| (8.0 * f64::EPSILON * data.obs[i].e.max(1.0) / data.sigma(i)).powi(2))
        .sum();
    ModelKind::ALL
        .iter()
        .filter(|k| data.len() > k.n_params())
        .map(|&kind| {
            let r = fit(
                data,
                kind,
                &FitOptions {
                    rule,
                    ..FitOptions::default()
                },
            );
            let ref_chi2 = reference_chi2(data, kind, rule);
            match r {
                Ok(f) => Outcome {
                    seed,
                    truth,
                    kind,
                    fit_chi2: f.chi2,
                    ref_chi2,
                    certified: f.global.certified,
                    gap: f.global.gap_chi2,
                    fine_cells: f.global.fine_cells,
                    rounding,
                    converged: f.converged,
                    error: None,
                },
                Err(e) => Outcome {
                    seed,
                    truth,
                    kind,
                    fit_chi2: f64::NAN,
                    ref_chi2,
                    certified: false,
                    gap: f64::NAN,
                    fine_cells: 0,
                    rounding,
                    converged: false,
                    error: Some(e.to_string()),
                },
            }
        })
        .collect()
}
