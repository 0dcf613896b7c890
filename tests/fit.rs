//! Library tests of `restitution::fit`: recovery of planted parameters, coverage of the 95%
//! intervals, the global minimum from poor starts, master curve versus ODE, bounds for
//! parameters the data cannot determine, and the information criteria.
//!
//! Synthetic data are made here from the model functions (`predict_e`) with planted parameters and
//! seeded Gaussian noise of a stated sigma; the expected values are the planted parameters, never
//! numbers produced by the fit.

use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, Normal};
use restitution::contact::Material;
use restitution::fit::dataset::pair_contact;
use restitution::fit::models::predict_e;
use restitution::fit::objective::CHI2_1DOF_95;
use restitution::fit::{
    FitData, FitOptions, ModelKind, Observation, ParamStatus, compare, fit, fit_all,
};
use restitution::models::viscoelastic::{ContactEnd, OdeSettings, VmMethod};

fn nylon() -> Material {
    Material::preset("nylon").unwrap()
}

/// Points (d_mm, v) on a log-uniform grid of speeds per diameter.
fn design(diameters: &[f64], v_lo: f64, v_hi: f64, per_size: usize) -> Vec<(f64, f64)> {
    let mut pts = Vec::new();
    for &d in diameters {
        for k in 0..per_size {
            let f = k as f64 / (per_size - 1) as f64;
            pts.push((d, (v_lo.ln() + f * (v_hi.ln() - v_lo.ln())).exp()));
        }
    }
    pts
}

/// Data of model `kind` with parameters `truth` at the design points; e_err = `sigma(e, v)`, and
/// Gaussian noise of that sigma when `seed` is given (noise-free otherwise).
fn synth(
    kind: ModelKind,
    truth: &[f64],
    pts: &[(f64, f64)],
    sigma: impl Fn(f64, f64) -> f64,
    seed: Option<u64>,
) -> FitData {
    let mut rng = seed.map(StdRng::seed_from_u64);
    let normal = Normal::new(0.0, 1.0).unwrap();
    let obs = pts
        .iter()
        .map(|&(d, v)| {
            let c = pair_contact(nylon(), d, None).unwrap();
            let e = predict_e(kind, &c, v, truth, ContactEnd::Overlap, &VmMethod::Master).unwrap();
            let s = sigma(e, v);
            let noise = rng.as_mut().map_or(0.0, |r| s * normal.sample(r));
            Observation {
                d_mm: d,
                d2_mm: None,
                v_n_m_s: v,
                e: e + noise,
                e_err: Some(s),
            }
        })
        .collect();
    FitData::new(nylon(), obs).unwrap()
}

fn truth_of(kind: ModelKind) -> Vec<f64> {
    match kind {
        ModelKind::Vm => vec![190.0],
        ModelKind::Pm => vec![4.0e7],
        ModelKind::Min | ModelKind::Product => vec![190.0, 4.0e7],
        ModelKind::PowerLaw => vec![0.04, 0.5, 0.3],
    }
}

const SIZES: [f64; 3] = [6.35, 12.7, 25.4];

#[test]
fn noise_free_data_give_back_the_planted_parameters() {
    // Without noise the planted parameters are the exact minimum (chi2 = 0), so the fit must find
    // them to the accuracy of its stopping rule: the polishes stop where the Gauss-Newton step
    // promises less than a hundredth of the search's tolerance, here 1e-6 (chi2 = 0, scale 1),
    // so chi2 at most 1e-8 and each parameter within sqrt(1e-8) = 1e-4 of its standard error
    // of the minimum (2e-4 allows for the models' curvature; with chi2 = 0 the standard error
    // is the one from the error bars, stderr_abs). The one-parameter models' Brent stops at
    // 1e-10 in the log parameter.
    let pts = design(&SIZES, 0.5, 40.0, 12);
    for kind in ModelKind::ALL {
        let truth = truth_of(kind);
        let data = synth(kind, &truth, &pts, |_, _| 0.01, None);
        let r = fit(&data, kind, &FitOptions::default()).unwrap();
        assert!(r.converged, "{kind}: {:?}", r.notes);
        assert!(r.chi2 <= 1e-8, "{kind}: chi2 {}", r.chi2);
        for (p, t) in r.params.iter().zip(&truth) {
            let sd = p.stderr_abs.expect("an estimate");
            assert!(
                (p.best_fit - t).abs() <= 2e-4 * sd,
                "{kind} {}: {} vs {t} (standard error {sd})",
                p.key,
                p.best_fit
            );
        }
    }
}

#[test]
fn noisy_data_recover_the_planted_parameters_within_their_errors() {
    // One seeded realisation per model; each parameter within 4 stderr of the truth (a 4-sigma
    // miss has probability 6e-5 per parameter) and its 95% interval closed.
    let pts = design(&SIZES, 0.5, 40.0, 20);
    for (s, kind) in ModelKind::ALL.into_iter().enumerate() {
        let truth = truth_of(kind);
        let data = synth(kind, &truth, &pts, |_, _| 0.01, Some(100 + s as u64));
        let r = fit(&data, kind, &FitOptions::default()).unwrap();
        assert!(r.converged, "{kind}");
        for (p, t) in r.params.iter().zip(&truth) {
            assert_eq!(p.status, ParamStatus::Estimate, "{kind} {}", p.key);
            let v = p.value.unwrap();
            let se = p.stderr.unwrap();
            assert!(
                (v - t).abs() < 4.0 * se,
                "{kind} {}: {v} +- {se} vs {t}",
                p.key
            );
            let (lo, hi) = (p.ci95.0.unwrap(), p.ci95.1.unwrap());
            assert!(lo < v && v < hi, "{kind} {}", p.key);
        }
    }
}

/// Fraction of seeded repetitions whose 95% interval covers the truth.
fn coverage(kind: ModelKind, pts: &[(f64, f64)], reps: u64) -> Vec<u32> {
    let truth = truth_of(kind);
    let mut covered = vec![0u32; truth.len()];
    for seed in 0..reps {
        let data = synth(
            kind,
            &truth,
            pts,
            |e, v| 2.0 * e * 0.036 / v.max(0.5) + 0.004,
            Some(10_000 + seed),
        );
        let r = fit(&data, kind, &FitOptions::default()).unwrap();
        for (j, (p, t)) in r.params.iter().zip(&truth).enumerate() {
            // Only a converged fit's closed interval counts (a bound or a lost end does not).
            if let (true, ParamStatus::Estimate, Some(lo), Some(hi)) =
                (r.converged, p.status, p.ci95.0, p.ci95.1)
                && lo <= *t
                && *t <= hi
            {
                covered[j] += 1;
            }
        }
    }
    covered
}

#[test]
fn intervals_cover_the_truth_95_percent_of_the_time_one_parameter() {
    // 400 repetitions; if the coverage is 95% the count is Binomial(400, 0.95): mean 380, sd 4.4.
    // Acceptance [367, 393] passes with probability 0.998 for a true coverage of 0.95 and 0.998
    // for 0.958 (what the max(1, chi2/dof) scaling adds at 28 dof), and rejects a coverage of 0.90
    // with probability 0.86 and of 0.985 with probability 0.61. Errors follow the paper's
    // sigma_e = 2 e Delta v / v with Delta v = 0.036 m/s, plus a 0.004 floor.
    let pts = design(&SIZES, 0.5, 5.0, 10);
    let c = coverage(ModelKind::Vm, &pts, 400);
    eprintln!("coverage vm: eta {} of 400", c[0]);
    assert!(
        (367..=393).contains(&c[0]),
        "vm: eta covered {} of 400",
        c[0]
    );
    let pts = design(&SIZES, 8.0, 40.0, 10);
    let c = coverage(ModelKind::Pm, &pts, 400);
    eprintln!("coverage pm: sigma_y {} of 400", c[0]);
    assert!(
        (367..=393).contains(&c[0]),
        "pm: sigma_y covered {} of 400",
        c[0]
    );
}

#[test]
fn intervals_cover_the_truth_95_percent_of_the_time_two_parameters() {
    // The `min` model, VM at low and plastic at high speed; the same band as above for each
    // parameter (each count is Binomial(400, p) on its own; the two are nearly independent
    // because the parameters act on different points).
    let pts = design(&SIZES, 0.5, 40.0, 10);
    let c = coverage(ModelKind::Min, &pts, 400);
    eprintln!("coverage min: eta {}, sigma_y {} of 400", c[0], c[1]);
    for (j, key) in ["eta", "sigma_y"].iter().enumerate() {
        assert!(
            (367..=393).contains(&c[j]),
            "min: {key} covered {} of 400",
            c[j]
        );
    }
}

/// chi2 of a model at physical parameters, computed directly from `predict_e` (independent of
/// the fit's own evaluator).
fn direct_chi2(data: &FitData, kind: ModelKind, p: &[f64]) -> f64 {
    data.obs
        .iter()
        .zip(&data.contacts)
        .map(|(o, c)| {
            let m = predict_e(
                kind,
                c,
                o.v_n_m_s,
                p,
                ContactEnd::Overlap,
                &VmMethod::Master,
            )
            .unwrap();
            ((o.e - m) / o.e_err.unwrap()).powi(2)
        })
        .sum()
}

#[test]
fn global_minimum_from_poor_starting_points() {
    // Fig. 7-like data (VM at low speed, plastic at high speed) and a start on the plateau
    // (sigma_y so high that nothing yields) with a damping a hundred times too large.
    let pts = design(&SIZES, 0.5, 40.0, 14);
    let truth = [190.0, 4.0e7];
    for kind in [ModelKind::Min, ModelKind::Product] {
        let data = synth(kind, &truth, &pts, |e, v| 0.072 * e / v + 0.004, Some(7));
        let poor = vec![1.9e4, 1e9];
        let local = FitOptions {
            scan: false,
            start: Some(poor.clone()),
            intervals: false,
            ..FitOptions::default()
        };
        let stuck = fit(&data, kind, &local).unwrap();
        let global = fit(
            &data,
            kind,
            &FitOptions {
                start: Some(poor),
                ..FitOptions::default()
            },
        )
        .unwrap();
        // The local solver alone ends far above (this is what the scan is for)...
        assert!(
            stuck.chi2 > global.chi2 + 100.0,
            "{kind}: {} vs {}",
            stuck.chi2,
            global.chi2
        );
        // ...and the full search is at least as good as every point of an independent dense
        // grid over the whole search box (150 x 150 in log eta and log sigma_y). The minimum
        // found must be below the best grid point: a local minimum elsewhere would not be.
        let mut best_grid = f64::INFINITY;
        for a in 0..150 {
            let eta = (1.0f64.ln() + a as f64 / 149.0 * (1e5f64.ln() - 1.0f64.ln())).exp();
            for b in 0..150 {
                let sy = (1e6f64.ln() + b as f64 / 149.0 * (1e9f64.ln() - 1e6f64.ln())).exp();
                best_grid = best_grid.min(direct_chi2(&data, kind, &[eta, sy]));
            }
        }
        assert!(
            global.chi2 <= best_grid,
            "{kind}: {} > grid {best_grid}",
            global.chi2
        );
        let direct = direct_chi2(&data, kind, &global.best_fit_values());
        assert!((direct - global.chi2).abs() < 1e-9 * direct, "{kind}");
        for (p, t) in global.params.iter().zip(truth) {
            assert!((p.best_fit / t - 1.0).abs() < 0.1, "{kind} {}", p.key);
        }
    }
}

#[test]
fn exact_ode_and_master_curve_fits_agree() {
    // The master curve is accurate to 2.4e-15 in e and the ODE (Dop853, 1e-12) to ~1e-12, so the
    // two minima differ by ~1e-10 relative; 1e-7 allows for where each minimiser stops (tolerance
    // 1e-10 in log eta, with a Jacobian step of 1e-4 for the ODE) and for the interval roots
    // (Brent to 1e-7 in log eta).
    let pts = design(&SIZES, 0.5, 20.0, 7);
    let data = synth(ModelKind::Vm, &[190.0], &pts, |_, _| 0.01, Some(3));
    let master = fit(&data, ModelKind::Vm, &FitOptions::default()).unwrap();
    let exact = FitOptions {
        vm_method: VmMethod::Ode(OdeSettings::DEFAULT),
        ..FitOptions::default()
    };
    let ode = fit(&data, ModelKind::Vm, &exact).unwrap();
    let (a, b) = (&master.params[0], &ode.params[0]);
    assert!(
        (a.best_fit / b.best_fit - 1.0).abs() < 1e-7,
        "{} {}",
        a.best_fit,
        b.best_fit
    );
    assert!((a.stderr.unwrap() / b.stderr.unwrap() - 1.0).abs() < 1e-5);
    assert!((a.ci95.0.unwrap() / b.ci95.0.unwrap() - 1.0).abs() < 1e-6);
    assert!((a.ci95.1.unwrap() / b.ci95.1.unwrap() - 1.0).abs() < 1e-6);
    // A two-parameter model through the ODE too (without intervals, to keep the test short).
    let data = synth(
        ModelKind::Min,
        &[190.0, 4.0e7],
        &design(&SIZES, 1.0, 40.0, 5),
        |_, _| 0.01,
        Some(4),
    );
    let quick = FitOptions {
        intervals: false,
        ..FitOptions::default()
    };
    let m = fit(&data, ModelKind::Min, &quick).unwrap();
    let o = fit(
        &data,
        ModelKind::Min,
        &FitOptions {
            vm_method: VmMethod::Ode(OdeSettings::DEFAULT),
            ..quick
        },
    )
    .unwrap();
    for (p, q) in m.params.iter().zip(&o.params) {
        assert!((p.best_fit / q.best_fit - 1.0).abs() < 1e-7, "{}", p.key);
    }
}

#[test]
fn undetermined_parameters_are_bounds_not_numbers() {
    // Viscoelastic data below every V_Y: in `min`, sigma_y only has a lower bound.
    let pts = design(&SIZES, 0.3, 3.0, 8);
    let data = synth(ModelKind::Vm, &[190.0], &pts, |_, _| 0.01, Some(11));
    let r = fit(&data, ModelKind::Min, &FitOptions::default()).unwrap();
    let eta = r.param("eta").unwrap();
    assert_eq!(eta.status, ParamStatus::Estimate);
    let sy = r.param("sigma_y").unwrap();
    assert_eq!(sy.status, ParamStatus::LowerBound, "{sy:?}");
    assert!(sy.value.is_none() && sy.stderr.is_none() && sy.stderr_abs.is_none());
    assert!(sy.ci95.0.unwrap() > 0.0 && sy.ci95.1.is_none());
    // Below the bound the plastic branch would act on the data: its V_Y is under the fastest
    // point (3 m/s), else chi2 could not have risen.
    let vy = r.derived("v_yield_m_s").unwrap().ci95.0.unwrap();
    assert!(vy < 3.0, "{vy}");
    // One size only: the power law's a is only known together with A; b stays determined.
    let pts = design(&[12.7], 0.5, 20.0, 15);
    let data = synth(
        ModelKind::PowerLaw,
        &[0.04, 0.5, 0.3],
        &pts,
        |_, _| 0.005,
        Some(12),
    );
    let r = fit(&data, ModelKind::PowerLaw, &FitOptions::default()).unwrap();
    assert_eq!(r.param("a").unwrap().status, ParamStatus::Unconstrained);
    assert_eq!(r.param("A").unwrap().status, ParamStatus::Unconstrained);
    let b = r.param("b").unwrap();
    assert_eq!(b.status, ParamStatus::Estimate);
    assert!((b.value.unwrap() - 0.3).abs() < 4.0 * b.stderr.unwrap());
}

#[test]
fn models_fitted_together_are_fitted_as_alone() {
    // fit_all shares one evaluator (and its rows of e_vm and e_pm) between the models' searches,
    // which run side by side: each fit must be the one it is alone, to the last bit, whatever
    // the other models computed first. Truth min, so that the models' searches go different
    // ways through the shared rows.
    let pts = design(&SIZES, 0.3, 30.0, 8);
    let data = synth(ModelKind::Min, &[190.0, 4e7], &pts, |_, _| 0.01, Some(5));
    let set = fit_all(&data, &ModelKind::ALL, &FitOptions::default()).unwrap();
    for (together, kind) in set.fits.iter().zip(ModelKind::ALL) {
        let alone = fit(&data, kind, &FitOptions::default()).unwrap();
        assert_eq!(*together, alone, "{kind}");
    }
}

#[test]
fn information_criteria_and_preference() {
    // Weighted: AIC = chi2 + 2k, BIC = chi2 + k ln n (Burnham & Anderson); weights sum to 1; the
    // preferred model for VM data is vm, not min with the same chi2 and one more parameter.
    let pts = design(&SIZES, 0.3, 3.0, 8);
    let data = synth(ModelKind::Vm, &[190.0], &pts, |_, _| 0.01, Some(21));
    let set = fit_all(&data, &ModelKind::ALL, &FitOptions::default()).unwrap();
    for f in &set.fits {
        let k = f.params.len() as f64;
        assert!((f.aic - (f.chi2 + 2.0 * k)).abs() < 1e-12 * f.aic.abs().max(1.0));
        assert!((f.bic - (f.chi2 + k * (data.len() as f64).ln())).abs() < 1e-9);
        assert_eq!(f.dof, data.len() - f.params.len());
    }
    let c = set.comparison.as_ref().unwrap();
    let total: f64 = c.rows.iter().map(|r| r.akaike_weight).sum();
    assert!((total - 1.0).abs() < 1e-12);
    assert_eq!(c.preferred, Some(ModelKind::Vm));
    assert_eq!(compare(&set.fits), *c);
    // Unweighted: AIC = n ln(RSS/n) + 2k, and no stderr_abs.
    let obs: Vec<Observation> = data
        .obs
        .iter()
        .map(|o| Observation { e_err: None, ..*o })
        .collect();
    let plain = FitData::new(nylon(), obs).unwrap();
    let r = fit(&plain, ModelKind::Vm, &FitOptions::default()).unwrap();
    let n = plain.len() as f64;
    assert!((r.aic - (n * (r.chi2 / n).ln() + 2.0)).abs() < 1e-9);
    let eta = r.param("eta").unwrap();
    assert!(eta.stderr_abs.is_none() && eta.stderr.is_some());
    // The same minimum as the weighted fit: all sigma were equal.
    let w = fit(&data, ModelKind::Vm, &FitOptions::default()).unwrap();
    assert!((w.params[0].best_fit / eta.best_fit - 1.0).abs() < 1e-8);
}

#[test]
fn stderr_and_interval_use_one_chi2_scale() {
    // Errors stated 3x too large: chi2/dof ~ 0.1. With one scale s = max(1, chi2/dof) = 1 for
    // both, stderr equals stderr_abs and the profile interval is +-1.96 stderr in ln eta (the
    // model is nearly linear in ln eta over so small a range). The old code scaled stderr by
    // sqrt(chi2/dof) = 0.3 but the interval by 1, and failed this by a factor 3. Tolerance 2%:
    // the curvature of e_vm in ln eta over +-2 stderr (measured: 0.3%).
    let pts = design(&SIZES, 0.5, 20.0, 12);
    let clean = synth(ModelKind::Vm, &[190.0], &pts, |_, _| 0.003, Some(31));
    let obs: Vec<Observation> = clean
        .obs
        .iter()
        .map(|o| Observation {
            e_err: Some(0.01),
            ..*o
        })
        .collect();
    let data = FitData::new(nylon(), obs).unwrap();
    let r = fit(&data, ModelKind::Vm, &FitOptions::default()).unwrap();
    assert!(r.reduced_chi2 < 0.3, "{}", r.reduced_chi2);
    assert_eq!(r.scale, 1.0);
    let eta = r.param("eta").unwrap();
    let (se, se_abs) = (eta.stderr.unwrap(), eta.stderr_abs.unwrap());
    assert!((se / se_abs - 1.0).abs() < 1e-12, "{se} {se_abs}");
    let (lo, hi) = (eta.ci95.0.unwrap(), eta.ci95.1.unwrap());
    let half = 0.5 * (hi / lo).ln();
    let expected = CHI2_1DOF_95.sqrt() * se / eta.value.unwrap();
    assert!((half / expected - 1.0).abs() < 0.02, "{half} {expected}");
    // Scatter larger than the errors: s = chi2/dof scales both alike.
    let noisy = synth(ModelKind::Vm, &[190.0], &pts, |_, _| 0.01, Some(32));
    let obs: Vec<Observation> = noisy
        .obs
        .iter()
        .map(|o| Observation {
            e_err: Some(0.004),
            ..*o
        })
        .collect();
    let data = FitData::new(nylon(), obs).unwrap();
    let r = fit(&data, ModelKind::Vm, &FitOptions::default()).unwrap();
    assert!(r.reduced_chi2 > 3.0 && (r.scale / r.reduced_chi2 - 1.0).abs() < 1e-12);
    let eta = r.param("eta").unwrap();
    let (se, se_abs) = (eta.stderr.unwrap(), eta.stderr_abs.unwrap());
    assert!((se / se_abs - r.scale.sqrt()).abs() < 1e-9 * se / se_abs);
    let half = 0.5 * (eta.ci95.1.unwrap() / eta.ci95.0.unwrap()).ln();
    let expected = CHI2_1DOF_95.sqrt() * se / eta.value.unwrap();
    assert!((half / expected - 1.0).abs() < 0.02, "{half} {expected}");
}
