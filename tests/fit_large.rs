//! Fits of many points with distinct speeds: the global search sums over the points in fixed
//! chunks on all cores above a size (`restitution::fit::sums`), and must find the same certified
//! optimum as the sums in point order did before that path existed. The reference values below
//! were printed by this test's fits on the code before the change (commit 1950704, sums in
//! point order), not by the code under test.

use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, Normal};
use restitution::contact::Material;
use restitution::fit::dataset::pair_contact;
use restitution::fit::models::predict_e;
use restitution::fit::sums::PARALLEL_MIN_POINTS;
use restitution::fit::{FitData, FitOptions, ModelKind, Observation, fit, fit_all};
use restitution::models::viscoelastic::{ContactEnd, VmMethod};

/// 20 000 points (above the parallel threshold) on nylon pairs of 6.35, 12.7 and 25.4 mm, every
/// speed distinct (log-spaced 0.3-30 m/s), truth `min` with eta = 190 kg/(s m) and
/// sigma_y = 4e7 Pa, errors 2 e (0.02 m/s)/v + 0.005, seed 11.
fn data() -> FitData {
    const N: usize = 20_000;
    let m = Material::preset("nylon").unwrap();
    let n01 = Normal::new(0.0, 1.0).unwrap();
    let mut rng = StdRng::seed_from_u64(11);
    let (v0, v1) = (0.3f64.ln(), 30f64.ln());
    let obs = (0..N)
        .map(|i| {
            let d = [6.35, 12.7, 25.4][i % 3];
            let c = pair_contact(m, d, None).unwrap();
            let v = (v0 + (i as f64 + 0.5) / N as f64 * (v1 - v0)).exp();
            let p = [190.0, 4.0e7];
            let rule = ContactEnd::Overlap;
            let e = predict_e(ModelKind::Min, &c, v, &p, rule, &VmMethod::Master).unwrap();
            let s = 2.0 * e * 0.02 / v + 0.005;
            Observation {
                d_mm: d,
                d2_mm: None,
                v_n_m_s: v,
                e: e + s * n01.sample(&mut rng),
                e_err: Some(s),
            }
        })
        .collect();
    FitData::new(m, obs).unwrap()
}

/// Reference fits (before the chunked sums): model, best-fit parameters, chi2.
const REFERENCE: [(ModelKind, &[f64], f64); 5] = [
    (ModelKind::Vm, &[240.9665351685397], 455512.1168717167),
    (ModelKind::Pm, &[38184341.983109765], 367036.5583680615),
    (
        ModelKind::Min,
        &[190.28916511222943, 40003464.98985689],
        19905.03974861306,
    ),
    (
        ModelKind::Product,
        &[144.25414932858033, 45935449.22220788],
        107370.17455255643,
    ),
    (
        ModelKind::PowerLaw,
        &[0.02479968678499714, 0.20662440518743516, 0.6222884577567],
        125156.87463748429,
    ),
];

#[test]
fn many_distinct_points_give_the_certified_optimum_of_the_point_order_sums() {
    let data = data();
    assert!(
        data.len() >= PARALLEL_MIN_POINTS,
        "the test must take the chunked path"
    );
    let mut alone = Vec::new();
    for (kind, best, chi2) in REFERENCE {
        let r = fit(&data, kind, &FitOptions::default()).unwrap();
        alone.push(r.clone());
        let got: Vec<f64> = r.params.iter().map(|p| p.best_fit).collect();
        eprintln!("{kind}: {got:?} chi2 {:?} cells {}", r.chi2, r.global.cells);
        assert!(
            r.converged && r.global.certified,
            "{kind}: {:?}",
            r.warnings
        );
        // The sums' order changes chi2 by rounding only (about n u = 2e-12 relative for 2e4
        // positive terms); 1e-9 relative allows for the polishes stopping at a slightly
        // different point of the flat minimum, and is still 100 times below the certificate's
        // tolerance (1e-7 relative).
        assert!(
            (r.chi2 - chi2).abs() <= 1e-9 * chi2,
            "{kind}: chi2 {} vs {chi2}",
            r.chi2
        );
        // The optimum itself: within 1e-3 standard errors of the reference (a chi2 difference
        // of 1e-6 along the parameter: invisible in every figure the fit prints, which quote
        // two digits of the standard error).
        for (p, want) in r.params.iter().zip(best) {
            let se = p.stderr_abs.unwrap_or(f64::INFINITY);
            assert!(
                (p.best_fit - want).abs() <= 1e-3 * se,
                "{kind} {}: {} vs {want} (stderr {se})",
                p.key,
                p.best_fit
            );
        }
    }
    // All five together (one evaluator, the starting rows computed once and every row shared,
    // the fits as tasks of the thread pool): each the same fit as alone, to the last bit.
    let kinds = REFERENCE.map(|r| r.0);
    let set = fit_all(&data, &kinds, &FitOptions::default()).unwrap();
    for (together, alone) in set.fits.iter().zip(&alone) {
        assert_eq!(together, alone, "{}", alone.model);
    }
}

/// The same fits with the hot loops on the baseline code and on AVX2 and FMA
/// (`restitution::cpu`): the same numbers to the last bit, and the same work. (On a processor
/// without AVX2 and FMA both runs take the baseline code and the comparison is void; it says so.)
#[test]
fn the_wide_registers_change_no_bit() {
    let data = data();
    if !restitution::cpu::uses_avx2_fma() {
        eprintln!("this processor has no AVX2 and FMA: both runs take the baseline code");
    }
    for kind in [ModelKind::Min, ModelKind::Product, ModelKind::PowerLaw] {
        let run = |baseline: bool| {
            restitution::cpu::set_baseline_only(baseline);
            let r = fit(&data, kind, &FitOptions::default()).unwrap();
            restitution::cpu::set_baseline_only(false);
            let bits = |x: f64| x.to_bits();
            let mut v: Vec<u64> = vec![bits(r.chi2), r.evaluations, r.profile_evaluations];
            for p in &r.params {
                v.push(bits(p.best_fit));
                v.push(bits(p.stderr_abs.unwrap_or(f64::NAN)));
                v.push(bits(p.ci95.0.unwrap_or(f64::NAN)));
                v.push(bits(p.ci95.1.unwrap_or(f64::NAN)));
            }
            v.push(bits(r.global.gap_chi2));
            v.push(r.global.cells);
            v.extend(r.predicted.iter().map(|x| bits(*x)));
            v
        };
        assert_eq!(run(true), run(false), "{kind}");
    }
}

/// Fits `min` to `data` (seed `seed`) and checks: converged, certified, no warnings, at most
/// `max_evaluations` evaluations of the model, and chi2 within 1e-9 relative of `want`.
fn certified_min_fit(data: &FitData, seed: u64, want: f64, max_evaluations: u64) {
    let r = fit(data, ModelKind::Min, &FitOptions::default()).unwrap();
    eprintln!(
        "seed {seed}: chi2 {:?}, {} evaluations",
        r.chi2, r.evaluations
    );
    assert!(
        r.converged && r.global.certified,
        "{seed}: {:?}",
        r.warnings
    );
    assert!(r.warnings.is_empty(), "{seed}: {:?}", r.warnings);
    assert!(
        r.evaluations <= max_evaluations,
        "{seed}: {} evaluations",
        r.evaluations
    );
    assert!(
        (r.chi2 - want).abs() <= 1e-9 * want,
        "{seed}: chi2 {} vs {want}",
        r.chi2
    );
}

/// 20 000 points, each on its own pair of sizes (d = 5 mm + i 1e-4 mm on d + 1 mm), speeds
/// uniform in 0.5-5.5 m/s, e uniform in 0.88-0.90 (no model's truth), e_err 0.02: sigma_y is
/// bounded from below only, and each pair yields at its own sigma_y, so `min` has a kink per
/// point along the flat direction.
fn many_sizes(seed: u64) -> FitData {
    use rand::Rng;
    let m = Material::preset("nylon").unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let obs = (0..20_000)
        .map(|i| {
            let d = 5.0 + i as f64 * 1e-4;
            Observation {
                d_mm: d,
                d2_mm: Some(d + 1.0),
                v_n_m_s: rng.random_range(0.5..5.5),
                e: rng.random_range(0.88..0.90),
                e_err: Some(0.02),
            }
        })
        .collect();
    FitData::new(m, obs).unwrap()
}

#[test]
fn many_sizes_with_a_flat_yield_stress_end_certified_without_runaway_work() {
    // Seeds 14, 15 and 22 of the data above (of seeds 12-23, five went wrong before): the
    // polishes across kinks were proposed for every point near its kink (hundreds, 85-393 left
    // unpolished at the limit of 100, so "not converged"), and minima were finished with rounds
    // of profile scans because some point is always near its kink: 47 178, 25 911 and 58 209
    // evaluations of the model, 12-28 s of CPU. The work is counted, not timed: 3000 is what
    // one round of profile scans takes on the one set of the three whose kink promises a gain
    // above tau (seed 14).
    // The chi2 the old search reached (printed by this test's data at 38315a2): 1e-9 relative
    // as above (the profiles' Brent tolerances moved from 1e-13 to 1e-6 standard errors).
    for (seed, want) in [
        (14, 13208.991531943626),
        (15, 13087.723123693604),
        (22, 13150.435182455789),
    ] {
        certified_min_fit(&many_sizes(seed), seed, want, 3000);
    }
}

/// Polydisperse data: 20 000 pairs, each of its own sizes (d = 3 mm + i 1e-3 mm on 1.5 d),
/// speeds log-uniform in 0.3-30 m/s, truth `product` with eta = 190 kg/(s m) and
/// sigma_y = 4e7 Pa, e_err 0.01 (Gaussian noise).
fn polydisperse(seed: u64) -> FitData {
    use rand::Rng;
    let m = Material::preset("nylon").unwrap();
    let n01 = Normal::new(0.0, 1.0).unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let obs = (0..20_000)
        .map(|i| {
            let d = 3.0 + i as f64 * 1e-3;
            let c = pair_contact(m, d, Some(1.5 * d)).unwrap();
            let v = rng.random_range(0.3f64.ln()..30f64.ln()).exp();
            let (p, rule) = ([190.0, 4.0e7], ContactEnd::Overlap);
            let e = predict_e(ModelKind::Product, &c, v, &p, rule, &VmMethod::Master).unwrap();
            Observation {
                d_mm: d,
                d2_mm: Some(1.5 * d),
                v_n_m_s: v,
                e: e + 0.01 * n01.sample(&mut rng),
                e_err: Some(0.01),
            }
        })
        .collect();
    FitData::new(m, obs).unwrap()
}

#[test]
fn polydisperse_min_fits_are_certified() {
    // `min` fitted to polydisperse `product` data, seeds 31 and 33: the same kinks, one per
    // pair. Before, 11 and 17 polishes across kinks were left undone (852 and 749 evaluations):
    // "not converged" though the minimum was found. The chi2 is the old search's (printed by
    // this test's data at 38315a2), to 1e-9 relative as above; 400 evaluations is what a fit of
    // 120 points takes at most.
    for (seed, want) in [(31, 82274.76873660112), (33, 83040.64098876106)] {
        certified_min_fit(&polydisperse(seed), seed, want, 400);
    }
}
