//! The seeded synthetic data sets of the randomized global-minimum test (see `main.rs`).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use restitution::contact::Material;
use restitution::fit::dataset::pair_contact;
use restitution::fit::models::{ModelKind, POWERLAW_V_REF_M_S, e_pm, e_vm, predict_e};
use restitution::fit::{FitData, Observation};
use restitution::models::viscoelastic::{ContactEnd, VmMethod};

/// The truths the data are made from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Truth {
    Model(ModelKind),
    /// 1 - e^2 = (1 - e_vm^2) + (1 - e_pm^2).
    Additive,
    /// 1 - e = c1 (v/1 m/s)^p + c2 (v/1 m/s)^q.
    TwoPowers,
    /// Not made here: a data file given (`--dumped`), truth unknown.
    File,
}

impl Truth {
    pub fn name(self) -> String {
        match self {
            Truth::Model(k) => k.name().to_string(),
            Truth::Additive => "additive".into(),
            Truth::TwoPowers => "two_powers".into(),
            Truth::File => "file".into(),
        }
    }
}

/// One synthetic data set.
pub struct Case {
    pub seed: u64,
    pub truth: Truth,
    /// The contact-end rule of the fits (the synthetic sets: the overlap rule).
    pub rule: ContactEnd,
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
                    let b = e_pm(&c, v, sigma_y).expect("model");
                    (a * a + b * b - 1.0).max(0.0).sqrt()
                }
                Truth::File => unreachable!("drawn truths only"),
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
        rule,
        data: FitData::new(material, obs).expect("valid data"),
        description,
    }
}
