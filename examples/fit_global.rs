//! Is the fit's minimum global? Seeded synthetic data sets, each fitted by every model and
//! compared with an independent exhaustive reference.
//!
//! ```text
//! cargo run --release --example fit_global            # the full run (400 data sets)
//! cargo run --release --example fit_global -- 0 40    # seeds 0..40 only
//! ```
//!
//! **Data sets** (seed s, rand's StdRng): a material (nu uniform in 0.2-0.49, rho log-uniform in
//! 900-8000 kg/m^3, Y log-uniform in 1e8-2e11 Pa), one to four diameters (1-50 mm) as identical
//! pairs, spheres on a wall or unequal pairs, a speed range (lower end 0.05-2 m/s, 5-300 times
//! wider), 8-40 points per size at log-uniform speeds, a truth drawn from `vm`, `pm`, `min`,
//! `product`, `powerlaw` and two laws the fit does not offer: additive energy losses
//! 1 - e^2 = (1 - e_vm^2) + (1 - e_pm^2) and a two-exponent power law 1 - e = c1 v^p + c2 v^q.
//! Noise: Gaussian with sigma_e = level (constant), level (1 - e) + 1e-4 (relative to the
//! dissipation) or the paper's camera model 2 e Delta v / v, the level log-uniform over 2.5
//! decades; one set in eight without errors (an unweighted fit).
//!
//! **Reference** (independent of the fit's search and polish; only the model functions of the
//! library are shared): the model's search box as the fit's documentation defines it,
//! recomputed here from the contact functions; a dense grid in the log parameters (4000 points
//! for one parameter, 400 x 300 for two, 48 x 64 x 64 for the power law's (ln A, a, b)); from
//! every grid-local minimum (ties broken by position) argmin's Nelder-Mead on chi2 computed
//! point by point with `predict_e`. The reference chi2 is the lowest of all.
//!
//! **Pass**: the fit's chi2 is at most the reference's times (1 + 1e-6); a fit that returns an
//! error fails. Reported too: fits not certified global, fits not converged.

#![allow(dead_code)]

use argmin::core::{CostFunction, Executor};
use argmin::solver::neldermead::NelderMead;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use restitution::contact::{Contact, Material};
use restitution::fit::dataset::pair_contact;
use restitution::fit::models::{
    ModelKind, POWERLAW_D_REF_MM, POWERLAW_V_REF_M_S, e_pm, e_vm, powerlaw_d_mm, predict_e,
};
use restitution::fit::{FitData, FitOptions, Observation, fit};
use restitution::models::viscoelastic::master::KAPPA_MAX;
use restitution::models::viscoelastic::{ContactEnd, VmMethod};

/// The truths the data are made from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Truth {
    Model(ModelKind),
    /// 1 - e^2 = (1 - e_vm^2) + (1 - e_pm^2).
    Additive,
    /// 1 - e = c1 (v/1 m/s)^p + c2 (v/1 m/s)^q.
    TwoPowers,
}

impl Truth {
    pub fn name(self) -> String {
        match self {
            Truth::Model(k) => k.name().to_string(),
            Truth::Additive => "additive".into(),
            Truth::TwoPowers => "two_powers".into(),
        }
    }
}

/// One synthetic data set.
pub struct Case {
    pub seed: u64,
    pub truth: Truth,
    pub data: FitData,
    pub description: String,
}

fn log_uniform(rng: &mut StdRng, lo: f64, hi: f64) -> f64 {
    (lo.ln() + rng.random::<f64>() * (hi.ln() - lo.ln())).exp()
}

/// The data set of seed `seed` (see the module doc).
pub fn make_case(seed: u64) -> Case {
    let mut rng = StdRng::seed_from_u64(0x9e37_79b9 ^ seed);
    let normal = Normal::new(0.0, 1.0).expect("unit normal");
    let nu = rng.random_range(0.2..0.49);
    let rho = log_uniform(&mut rng, 900.0, 8000.0);
    let youngs = log_uniform(&mut rng, 1e8, 2e11);
    let material = Material::new(youngs, nu, rho).expect("valid material");
    let sizes = rng.random_range(1..=4usize);
    let geometry = rng.random_range(0..3u32); // identical, wall, unequal
    let v_lo = log_uniform(&mut rng, 0.05, 2.0);
    let v_hi = v_lo * log_uniform(&mut rng, 5.0, 300.0);
    let truth = match rng.random_range(0..7u32) {
        0 => Truth::Model(ModelKind::Vm),
        1 => Truth::Model(ModelKind::Pm),
        2 => Truth::Model(ModelKind::Min),
        3 => Truth::Model(ModelKind::Product),
        4 => Truth::Model(ModelKind::PowerLaw),
        5 => Truth::Additive,
        _ => Truth::TwoPowers,
    };
    let mut pairs: Vec<(f64, Option<f64>)> = Vec::new();
    for _ in 0..sizes {
        let d = log_uniform(&mut rng, 1.0, 50.0);
        let d2 = match geometry {
            0 => None,
            1 => Some(f64::INFINITY),
            _ => Some(log_uniform(&mut rng, 1.0, 50.0)),
        };
        pairs.push((
            (d * 100.0).round() / 100.0,
            d2.map(|x| (x * 100.0).round() / 100.0),
        ));
    }
    let first = pair_contact(material, pairs[0].0, pairs[0].1).expect("valid pair");
    let v_mid = (v_lo * v_hi).sqrt();
    // Damping with kappa 1e-4..0.5 at the middle speed; yield speed from a third of the lowest
    // to three times the highest speed.
    let eta = first.eta_for_kappa(log_uniform(&mut rng, 1e-4, 0.5), v_mid);
    let sigma_y = first.sigma_y_for_yield_velocity(log_uniform(&mut rng, v_lo / 3.0, 3.0 * v_hi));
    let pow = [
        log_uniform(&mut rng, 0.005, 0.3),
        rng.random_range(-0.5..1.5),
        rng.random_range(0.0..0.8),
    ];
    let two = [
        log_uniform(&mut rng, 0.003, 0.1),
        rng.random_range(0.05..0.4),
        log_uniform(&mut rng, 1e-4, 0.01),
        rng.random_range(0.8..1.6),
    ];
    let noise_kind = rng.random_range(0..3u32);
    let level = log_uniform(&mut rng, 3e-4, 0.1);
    let weighted = rng.random_range(0..8u32) != 0;
    let rule = ContactEnd::Overlap;
    let m = VmMethod::Master;
    let mut obs = Vec::new();
    for &(d, d2) in &pairs {
        let c = pair_contact(material, d, d2).expect("valid pair");
        let n = rng.random_range(8..=40usize);
        for _ in 0..n {
            let v = log_uniform(&mut rng, v_lo, v_hi);
            let e_true = match truth {
                Truth::Model(ModelKind::PowerLaw) => {
                    let one_minus =
                        predict_e(ModelKind::PowerLaw, &c, v, &pow, rule, &m).expect("model");
                    one_minus.clamp(0.02, 1.0)
                }
                Truth::Model(k) => {
                    let p: Vec<f64> = match k {
                        ModelKind::Vm => vec![eta],
                        ModelKind::Pm => vec![sigma_y],
                        _ => vec![eta, sigma_y],
                    };
                    predict_e(k, &c, v, &p, rule, &m).expect("model")
                }
                Truth::Additive => {
                    let a = e_vm(&c, v, eta, rule, &m).expect("model");
                    let b = e_pm(&c, v, sigma_y);
                    (a * a + b * b - 1.0).max(0.0).sqrt()
                }
                Truth::TwoPowers => {
                    let x = v / POWERLAW_V_REF_M_S;
                    (1.0 - two[0] * x.powf(two[1]) - two[2] * x.powf(two[3])).max(0.02)
                }
            };
            let sigma = match noise_kind {
                0 => level * 0.1,
                1 => level * (1.0 - e_true) + 1e-4,
                _ => 2.0 * e_true.max(0.05) * level / v.max(0.1) + 1e-4,
            };
            let e = (e_true + sigma * normal.sample(&mut rng)).abs();
            obs.push(Observation {
                d_mm: d,
                d2_mm: d2,
                v_n_m_s: (v * 1e4).round() / 1e4,
                e,
                e_err: weighted.then_some(sigma),
            });
        }
    }
    let description = format!(
        "Y {youngs:.3e} nu {nu:.3} rho {rho:.0}; {} pairs {:?}; v {v_lo:.3}..{v_hi:.1}; truth {} \
         (eta {eta:.4e}, sigma_y {sigma_y:.4e}); noise {noise_kind} level {level:.2e}{}",
        pairs.len(),
        pairs,
        truth.name(),
        if weighted { "" } else { ", unweighted" }
    );
    Case {
        seed,
        truth,
        data: FitData::new(material, obs).expect("valid data"),
        description,
    }
}

/// chi2 of `kind` at physical parameters `p`, point by point through `predict_e`.
fn chi2_direct(data: &FitData, kind: ModelKind, p: &[f64]) -> f64 {
    data.obs
        .iter()
        .zip(&data.contacts)
        .enumerate()
        .map(|(i, (o, c))| {
            let m = predict_e(
                kind,
                c,
                o.v_n_m_s,
                p,
                ContactEnd::Overlap,
                &VmMethod::Master,
            )
            .unwrap_or(f64::NAN);
            ((o.e - m) / data.sigma(i)).powi(2)
        })
        .sum()
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
        ModelKind::PowerLaw => vec![(1e-9f64.ln(), 1e3f64.ln()), (-10.0, 10.0), (-10.0, 10.0)],
    }
}

struct Chi2Problem<'a> {
    data: &'a FitData,
    kind: ModelKind,
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
        let c = chi2_direct(self.data, self.kind, &p);
        Ok(if c.is_nan() { f64::INFINITY } else { c })
    }
}

/// Nelder-Mead from `start` (internal coordinates) with an initial simplex of `step` per axis.
fn nelder_mead(
    data: &FitData,
    kind: ModelKind,
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
pub fn reference_chi2(data: &FitData, kind: ModelKind) -> f64 {
    reference(data, kind).0
}

/// The reference minimum and where it is (internal coordinates, clamped into the box).
pub fn reference(data: &FitData, kind: ModelKind) -> (f64, Vec<f64>) {
    let bx = reference_box(data, kind);
    let n = data.len();
    let w: Vec<f64> = (0..n).map(|i| data.sigma(i).powi(-2)).collect();
    let rule = ContactEnd::Overlap;
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
            .map(|(o, c)| e_pm(c, o.v_n_m_s, t.exp()))
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
        let (v, p) = nelder_mead(data, kind, &bx, &start, &steps);
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
    pub converged: bool,
    pub error: Option<String>,
}

impl Outcome {
    /// The fit is at most 1e-6 relative above the reference.
    pub fn pass(&self) -> bool {
        self.error.is_none() && self.fit_chi2 <= self.ref_chi2 * (1.0 + 1e-6)
    }
}

/// Fits every model to the case and compares with the reference.
pub fn check(case: &Case) -> Vec<Outcome> {
    ModelKind::ALL
        .iter()
        .filter(|k| case.data.len() > k.n_params())
        .map(|&kind| {
            let r = fit(&case.data, kind, &FitOptions::default());
            let ref_chi2 = reference_chi2(&case.data, kind);
            match r {
                Ok(f) => Outcome {
                    seed: case.seed,
                    truth: case.truth,
                    kind,
                    fit_chi2: f.chi2,
                    ref_chi2,
                    certified: f.global.certified,
                    converged: f.converged,
                    error: None,
                },
                Err(e) => Outcome {
                    seed: case.seed,
                    truth: case.truth,
                    kind,
                    fit_chi2: f64::NAN,
                    ref_chi2,
                    certified: false,
                    converged: false,
                    error: Some(e.to_string()),
                },
            }
        })
        .collect()
}

pub fn main() {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("seed numbers"))
        .collect();
    let (from, to) = match args.as_slice() {
        [a, b] => (*a, *b),
        _ => (0, 400),
    };
    let seeds: Vec<u64> = (from..to).collect();
    let threads = 2;
    let results: Vec<(Case, Vec<Outcome>)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let mine: Vec<u64> = seeds.iter().copied().skip(t).step_by(threads).collect();
                s.spawn(move || {
                    mine.into_iter()
                        .map(|seed| {
                            let case = make_case(seed);
                            let out = check(&case);
                            (case, out)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("worker"))
            .collect()
    });
    let mut total = 0;
    let mut failed = 0;
    let mut uncertified = 0;
    let mut unconverged = 0;
    let mut per_model = std::collections::BTreeMap::new();
    let mut per_truth = std::collections::BTreeMap::new();
    for (case, outs) in &results {
        *per_truth.entry(case.truth.name()).or_insert(0) += 1;
        for o in outs {
            total += 1;
            let e = per_model.entry(o.kind.name()).or_insert((0, 0));
            e.0 += 1;
            if !o.pass() {
                failed += 1;
                e.1 += 1;
                println!(
                    "FAIL seed {} fit {}: fit chi2 {} reference {} ({}) {}",
                    o.seed,
                    o.kind,
                    o.fit_chi2,
                    o.ref_chi2,
                    o.error.as_deref().unwrap_or("-"),
                    case.description
                );
            }
            uncertified += !o.certified as usize;
            unconverged += !o.converged as usize;
            if o.pass() && !(o.certified && o.converged) {
                println!(
                    "note seed {} fit {}: certified {} converged {} (fit {} reference {})",
                    o.seed, o.kind, o.certified, o.converged, o.fit_chi2, o.ref_chi2
                );
            }
        }
    }
    println!(
        "fit_global: {} data sets (seeds {from}..{to}), {total} fits: {failed} above the \
         reference by more than 1e-6 relative; {uncertified} not certified global, \
         {unconverged} not converged",
        results.len()
    );
    println!("truths: {per_truth:?}");
    for (k, (n, f)) in per_model {
        println!("  {k}: {n} fits, {f} failures");
    }
}
