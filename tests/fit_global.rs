//! Is the fit's minimum global, and does it never hang or hide a failure? Regression tests for
//! what users found, and a seeded subset of the randomized comparison with an independent
//! exhaustive reference (the full run, 400 data sets: `cargo run --release --example
//! fit_global`; the data generator and the reference live in examples/fit_global/ and are used
//! here as they are).

#[path = "../examples/fit_global/cases.rs"]
#[allow(dead_code)]
mod cases;
#[path = "../examples/fit_global/reference.rs"]
#[allow(dead_code)]
mod reference;

use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, Normal};
use restitution::contact::Material;
use restitution::fit::dataset::pair_contact;
use restitution::fit::dataset::{E_ERR_MAX, E_ERR_MIN};
use restitution::fit::models::predict_e;
use restitution::fit::{FitData, FitOptions, ModelKind, Observation, fit, fit_all};
use restitution::models::viscoelastic::{ContactEnd, VmMethod};

/// The PTFE-like set users reported (Y = 5e8 Pa, nu = 0.46, rho = 2200 kg/m^3; 6.35 and 12.7 mm;
/// 0.5-40 m/s), truth `min` with eta = 427 kg/(s m), sigma_y = 4e7 Pa, errors
/// 2 e (0.036 m/s)/v + 0.004, seed `seed`.
fn ptfe(seed: u64) -> FitData {
    let m = Material::new(5e8, 0.46, 2200.0).unwrap();
    let n01 = Normal::new(0.0, 1.0).unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let mut obs = Vec::new();
    for d in [6.35, 12.7] {
        let c = pair_contact(m, d, None).unwrap();
        for k in 0..30 {
            let v = (0.5f64.ln() + (k as f64 / 29.0) * (40f64.ln() - 0.5f64.ln())).exp();
            let e = predict_e(
                ModelKind::Min,
                &c,
                v,
                &[427.0, 4.0e7],
                ContactEnd::Overlap,
                &VmMethod::Master,
            )
            .unwrap();
            let s = 2.0 * e * 0.036 / v + 0.004;
            obs.push(Observation {
                d_mm: d,
                d2_mm: None,
                v_n_m_s: v,
                e: e + s * n01.sample(&mut rng),
                e_err: Some(s),
            });
        }
    }
    FitData::new(m, obs).unwrap()
}

#[test]
fn ptfe_set_where_the_old_search_locked_onto_the_wrong_eta_valley() {
    // On seed 4 the previous search (profile over log sigma_y, log eta in steps of 0.5, best
    // three profile minima; commit 1656880) returned chi2 = 69.5812 at eta = 419.5 as
    // converged, while an independent 400 x 300 grid already reaches 69.2993 at eta = 392.6
    // (measured with both when this test was written). The new search must be at or below the
    // independent reference (1e-6 relative: the reference's own polish tolerance is 1e-13 in
    // the simplex spread) and say it is certified.
    let data = ptfe(4);
    let r = fit(&data, ModelKind::Min, &FitOptions::default()).unwrap();
    let reference = reference::reference_chi2(&data, ModelKind::Min, ContactEnd::Overlap);
    assert!(
        r.chi2 <= reference * (1.0 + 1e-6),
        "fit {} reference {reference}",
        r.chi2
    );
    assert!(r.chi2 < 69.30, "{}", r.chi2);
    assert!(r.converged && r.global.certified, "{:?}", r.warnings);
    let eta = r.param("eta").unwrap().best_fit;
    assert!((eta / 392.6 - 1.0).abs() < 0.05, "{eta}");
}

#[test]
fn a_polish_that_ends_on_the_best_grid_point_is_converged() {
    // Seed 465 of the full run (fresh seeds 400..800, 2026-11-27): truth `pm`, so under `min`
    // and `product` eta sits on a plateau at the edge of its box. Every polish converged on the
    // best grid node itself, but its chi2, summed in another order than the node's, came out
    // one ulp above it (99.91209641685566 against 99.91209641685565), so the fit reported the
    // grid point as not converged, with a warning printing both as 99.91. A difference within
    // the rounding of the sums is no difference.
    for kind in [ModelKind::Min, ModelKind::Product] {
        converged_at_the_reference(465, kind);
    }
}

/// Seed `seed`'s fit by `kind`: at most 1e-6 relative above the reference, converged,
/// certified, without a warning.
fn converged_at_the_reference(seed: u64, kind: ModelKind) {
    let case = cases::make_case(seed);
    let r = fit(&case.data, kind, &FitOptions::default()).unwrap();
    let reference = reference::reference_chi2(&case.data, kind, ContactEnd::Overlap);
    assert!(
        r.chi2 <= reference * (1.0 + 1e-6),
        "seed {seed} {kind}: fit {} reference {reference}",
        r.chi2
    );
    assert!(
        r.converged && r.global.certified && r.warnings.is_empty(),
        "seed {seed} {kind}: converged {} certified {} {:?}",
        r.converged,
        r.global.certified,
        r.warnings
    );
}

#[test]
fn a_polish_that_reaches_the_grid_point_within_the_models_accuracy_is_converged() {
    // Seed 2043 of the full run (seeds 2000..2400, 2026-11-27): the power law on one size, its
    // exponents at the box's corner a = -10, b = 10. The best grid node's chi2 (its e the
    // product of two rows' exponentials) and the polish's at the same point (one exponential
    // of the sum) were 18.93895200413299 and 18.93895200413481: 1.8e-12 apart, each argument's
    // rounding (up to 30 u at |b ln v| ~ 12) a relative error of 1 - e, beyond the rounding of
    // the sums alone (1.7e-13), so the fit reported the grid point as not converged. Within
    // what the model's accuracy allows, the polish reached it.
    converged_at_the_reference(2043, ModelKind::PowerLaw);
}

/// Seed 3634 (`product`, truth `vm`: sigma_y bound from one side only): Levenberg-Marquardt and
/// Newton ran out of iterations creeping along sigma_y, where chi2 hardly changes, and the fit
/// said "not converged" 2.5e-5 below the reference; the Gauss-Newton step from there promises
/// less than tau.
#[test]
fn a_polish_that_creeps_along_a_plateau_within_tau_is_converged() {
    converged_at_the_reference(3634, ModelKind::Product);
}

#[test]
fn a_minimum_in_a_corner_of_the_box_is_reached_not_crept_towards() {
    // Seed 3386 of the full run (seeds 2800..3600, 2026-11-27): the power law on spheres of 1.65
    // and 1.72 mm on a wall (ln A and a nearly collinear), its minimum at the corner A = 1e-9,
    // a = -10 with b inside. Levenberg-Marquardt, its steps clamped to the box, stopped at
    // a = -9.9675 with chi2 958.21 against the reference's 955.66; the profiles' three refits
    // crept after it, and the fit said its intervals were lost and it had not converged.
    // Pinning the parameters that end near an end of their box reaches the corner.
    converged_at_the_reference(3386, ModelKind::PowerLaw);
}

#[test]
fn a_one_parameter_polish_resolves_a_minimum_narrower_than_its_offset() {
    // Fuzzed `fit` (seed 607, case 777): the first ten Fig. 7 rows, one with e_err = 1e-7,
    // fitted by `pm` with the force rule. The standard error of ln sigma_y is 2.9e-7, but Brent's
    // tolerance was 1.5e-8 |ln sigma_y| = 2.4e-7 (the log's offset, not its scale), and the
    // polish stopped 6.2e-5 above the minimum in chi2, reported converged and certified. The
    // reference: chi2 straight from predict_e on 2001 points over +-2 standard errors around the
    // fit (spacing 0.002 of one: the grid's minimum is within 1e-6 of the true one), the fit
    // at most 1e-6 relative above it.
    let m = Material::preset("nylon").unwrap();
    let rows: [(f64, f64, f64); 10] = [
        (0.597, 1.0613, 0.1287070686767169),
        (0.651, 0.9991, 0.11111342549923196),
        (0.694, 1.0126, 0.10563723342939482),
        (0.740, 0.9679, 0.09469724324324326),
        (0.749, 0.9406, 1e-7),
        (0.800, 0.9678, 0.0875859),
        (0.788, 0.8416, 0.07732467005076143),
        (0.839, 0.9130, 0.07878569725864126),
        (1.093, 1.0108, 0.06695509606587374),
        (1.164, 0.9901, 0.06158353951890035),
    ];
    let obs: Vec<Observation> = rows
        .iter()
        .map(|&(v, e, err)| Observation {
            d_mm: 25.4,
            d2_mm: None,
            v_n_m_s: v,
            e,
            e_err: Some(err),
        })
        .collect();
    let data = FitData::new(m, obs).unwrap();
    let rule = ContactEnd::Force;
    let f = fit(
        &data,
        ModelKind::Pm,
        &FitOptions {
            rule,
            ..FitOptions::default()
        },
    )
    .unwrap();
    assert!(f.converged && f.global.certified, "{:?}", f.warnings);
    let c = pair_contact(m, 25.4, None).unwrap();
    let chi2 = |sigma: f64| -> f64 {
        rows.iter()
            .map(|&(v, e, err)| {
                let p = predict_e(ModelKind::Pm, &c, v, &[sigma], rule, &VmMethod::Master).unwrap();
                ((e - p) / err).powi(2)
            })
            .sum()
    };
    let (s0, sd) = (f.params[0].value.unwrap(), f.params[0].stderr.unwrap());
    let grid_min = (0..=2000)
        .map(|k| chi2(s0 + sd * (k as f64 / 500.0 - 2.0)))
        .fold(f64::INFINITY, f64::min);
    assert!(
        f.chi2 <= grid_min * (1.0 + 1e-6),
        "fit {} against {grid_min} on the grid",
        f.chi2
    );
}

#[test]
fn tiny_errors_are_refused_and_the_smallest_accepted_ones_fit() {
    // Four rows with e_err = 1e-80 once looped forever in profile_crossing (a NaN start), and
    // an error far below the accuracy e is computed to makes a residual rounding: one such
    // point among ordinary ones sent the power law's search chasing rounding (fuzzed `fit`,
    // seed 401, case 522). Rows with errors below E_ERR_MIN (5e-11) are an error naming
    // e_err; at the smallest accepted error every model finishes with finite numbers.
    let m = Material::preset("nylon").unwrap();
    let rows = [
        (12.7, 1.0, 0.95),
        (12.7, 2.0, 0.93),
        (6.35, 4.0, 0.90),
        (6.35, 8.0, 0.85),
    ];
    let make = |err: f64| {
        let obs = rows
            .iter()
            .map(|&(d, v, e)| Observation {
                d_mm: d,
                d2_mm: None,
                v_n_m_s: v,
                e,
                e_err: Some(err),
            })
            .collect();
        FitData::new(m, obs)
    };
    for err in [1e-80, 1e-200, 5e-324, E_ERR_MIN * (1.0 - 1e-15)] {
        let e = make(err).unwrap_err().to_string();
        assert!(e.contains("e_err") && e.contains("5e-11"), "{err}: {e}");
    }
    let set = fit_all(
        &make(E_ERR_MIN).unwrap(),
        &ModelKind::ALL,
        &FitOptions::default(),
    )
    .unwrap();
    for f in &set.fits {
        assert!(
            f.chi2.is_finite() && f.chi2 > 1e15,
            "{} {}",
            f.model,
            f.chi2
        );
        for p in &f.params {
            for x in [p.value, p.stderr, p.stderr_abs, p.ci95.0, p.ci95.1]
                .into_iter()
                .flatten()
            {
                assert!(x.is_finite(), "{} {}: {x}", f.model, p.key);
            }
        }
        assert!(f.converged || !f.warnings.is_empty(), "{}", f.model);
    }
    // The ODE is computed to 5e-10 (50 times its tolerance of 1e-11): an error of 1e-8 that
    // the master curve resolves is refused there, before any integration.
    let ode = FitOptions {
        vm_method: VmMethod::Ode(restitution::models::viscoelastic::OdeSettings::DEFAULT),
        ..FitOptions::default()
    };
    let data = make(1e-8).unwrap();
    assert!(fit(&data, ModelKind::Vm, &FitOptions::default()).is_ok());
    let e = fit(&data, ModelKind::Vm, &ode).unwrap_err().to_string();
    assert!(e.contains("e_err") && e.contains("1e-8"), "{e}");
}

#[test]
fn huge_errors_are_refused_and_the_largest_accepted_ones_count_alike_everywhere() {
    // Fuzzed `fit` (seed 604, case 1309): a row with e = 1e300 and sigma_e = 1.1e299. Its
    // weight 1/sigma^2 underflowed to 0 in the search, which saw chi2 = 4.77, while the polishes
    // (residual / sigma) added its 81: the fit reported the grid point as "not converged" with
    // region warnings quoting the other chi2. Errors above E_ERR_MAX (1e100) are refused; at
    // 1e100 the row counts the same in the search and in the polishes, so every model ends
    // converged on one chi2 (the Fig. 7-like rows alone, plus the huge row's constant
    // ((1e150 - e)/1e100)^2 = 1e100 to 1e-16 of it).
    let m = Material::preset("nylon").unwrap();
    let mut obs: Vec<Observation> = (0..12)
        .map(|i| Observation {
            d_mm: [6.35, 12.7, 25.4][i % 3],
            d2_mm: None,
            v_n_m_s: 0.6 * 1.45f64.powi(i as i32),
            e: 0.98 - 0.025 * i as f64,
            e_err: Some(0.02),
        })
        .collect();
    let huge = |e: f64, err: f64| Observation {
        d_mm: 12.7,
        d2_mm: None,
        v_n_m_s: 3.0,
        e,
        e_err: Some(err),
    };
    for err in [E_ERR_MAX * (1.0 + 1e-15), 1.1e299, f64::MAX] {
        let mut o = obs.clone();
        o.push(huge(1e300, err));
        let e = FitData::new(m, o).unwrap_err().to_string();
        assert!(e.contains("e_err") && e.contains("1e100"), "{err}: {e}");
    }
    let base = fit_all(
        &FitData::new(m, obs.clone()).unwrap(),
        &ModelKind::ALL,
        &FitOptions::default(),
    )
    .unwrap();
    obs.push(huge(1e150, E_ERR_MAX));
    let set = fit_all(
        &FitData::new(m, obs).unwrap(),
        &ModelKind::ALL,
        &FitOptions::default(),
    )
    .unwrap();
    for (f, b) in set.fits.iter().zip(&base.fits) {
        assert!(
            f.converged && f.global.certified,
            "{}: {:?}",
            f.model,
            f.warnings
        );
        assert!(
            ((f.chi2 - 1e100) / 1e100).abs() < 1e-12,
            "{}: chi2 {} (without the row {})",
            f.model,
            f.chi2,
            b.chi2
        );
    }
}

#[test]
fn extreme_speeds_give_numbers_or_errors_never_panics() {
    // Speeds from 1e-30 to 1e30 m/s: the search boxes stay finite (the power law's exponents are
    // narrowed, with a warning); whatever is reported is a number or absent.
    let m = Material::preset("nylon").unwrap();
    let obs: Vec<Observation> = [1e-30, 1e-10, 1.0, 1e10, 1e30]
        .iter()
        .enumerate()
        .map(|(i, &v)| Observation {
            d_mm: 12.7,
            d2_mm: None,
            v_n_m_s: v,
            e: 0.9 - 0.1 * i as f64,
            e_err: Some(0.01),
        })
        .collect();
    let data = FitData::new(m, obs).unwrap();
    for kind in ModelKind::ALL {
        match fit(&data, kind, &FitOptions::default()) {
            Ok(f) => {
                assert!(f.chi2.is_finite(), "{kind}");
                for p in &f.params {
                    assert!(p.best_fit.is_finite(), "{kind} {}", p.key);
                    for x in [p.value, p.stderr, p.ci95.0, p.ci95.1]
                        .into_iter()
                        .flatten()
                    {
                        assert!(x.is_finite(), "{kind} {}: {x}", p.key);
                    }
                }
                if kind == ModelKind::PowerLaw {
                    assert!(
                        f.warnings.iter().any(|w| w.contains("exponents")),
                        "{:?}",
                        f.warnings
                    );
                }
            }
            Err(e) => assert!(!e.to_string().is_empty()),
        }
    }
}

#[test]
fn randomized_fits_are_at_or_below_an_independent_exhaustive_reference() {
    // Seeds 0..16 of the full run (examples/fit_global.rs: materials, one to four sizes, walls and
    // unequal pairs, speed ranges, noise levels, seven truths including two the fit does not
    // offer; every model fitted). Zero fits may end more than 1e-6 relative above the
    // reference. The full run's counts are in the README.
    let seeds: Vec<u64> = (0..16).collect();
    let outcomes: Vec<reference::Outcome> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|t| {
                let mine: Vec<u64> = seeds.iter().copied().skip(t).step_by(2).collect();
                s.spawn(move || {
                    mine.into_iter()
                        .flat_map(|seed| reference::check(&cases::make_case(seed)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    assert!(outcomes.len() >= 16 * 4, "{}", outcomes.len());
    let failures: Vec<String> = outcomes
        .iter()
        .filter(|o| !o.pass())
        .map(|o| {
            format!(
                "seed {} {}: fit {} reference {} {:?}",
                o.seed, o.kind, o.fit_chi2, o.ref_chi2, o.error
            )
        })
        .collect();
    eprintln!(
        "{} fits, {} failures, {} not certified",
        outcomes.len(),
        failures.len(),
        outcomes.iter().filter(|o| !o.certified).count()
    );
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Seed 5 (`product`): with eta held at 23.0007 kg/(s m), chi2 over sigma_y falls to a minimum
/// of 60.3107 at 2.885e8 Pa, just before the plateau (60.3401) where every point stays
/// elastic; Levenberg-Marquardt from the fit's sigma_y stepped onto the plateau and stopped
/// there, so the profile read 60.3401, above the threshold 60.3234, and the upper end of eta's
/// interval was put at 22.971 (found by `examples/interval_scan`). The slice's minimum must be
/// at or below a 3000-point scan's (1e-9 relative: the scan's grid only finds upper bounds, the
/// rest is rounding of two summation orders), and certified; at the fit's own eta, where chi2
/// over sigma_y has one minimum, it keeps the fit's point.
#[test]
fn the_profiles_inner_minimum_is_global_past_the_plateau() {
    use restitution::fit::lsq;
    use restitution::fit::models::Evaluator;
    use restitution::fit::objective::Objective;
    use restitution::fit::search::global_minimum;
    use restitution::fit::slice::slice_minimum;
    let case = cases::make_case(5);
    let kind = ModelKind::Product;
    let options = FitOptions {
        rule: case.rule,
        ..FitOptions::default()
    };
    let ev = Evaluator::new(&case.data, case.rule, VmMethod::Master);
    let obj = Objective::new(&ev, kind).unwrap();
    let search = global_minimum(&obj, &options).unwrap();
    let region = search.region.as_ref().expect("product keeps its region");
    let threshold = search.best.chi2 + 3.84 * obj.scale(search.best.chi2);
    let t = 23.0007f64.ln();
    // The plateau point where the local minimisation stopped (sigma_y at the box's edge).
    let plateau = [t, obj.upper[1]];
    let on_plateau = lsq::chi2(&obj, &plateau).unwrap();
    assert!(on_plateau > threshold, "{on_plateau} {threshold}");
    let s = slice_minimum(&obj, 0, t, (&plateau, on_plateau, true), threshold, region)
        .unwrap()
        .expect("product's slices are global");
    let (scan, y) = reference::separable_profile(
        &case.data,
        kind,
        case.rule,
        (0, t),
        (obj.lower[1], obj.upper[1]),
        3000,
    );
    assert!(s.certified);
    assert!(s.chi2 < threshold, "{} {threshold}", s.chi2);
    assert!(
        s.chi2 <= scan * (1.0 + 1e-9),
        "slice {} scan {scan} at {}",
        s.chi2,
        y.exp()
    );
    assert_eq!(s.theta[0], t);
    // At the minimum's eta: nothing lower than the fit's own point.
    let best = &search.best;
    let s = slice_minimum(
        &obj,
        0,
        best.theta[0],
        (&best.theta, best.chi2, true),
        threshold,
        region,
    )
    .unwrap()
    .unwrap();
    assert!(s.certified);
    assert_eq!((s.chi2, &s.theta), (best.chi2, &best.theta));
}

/// Probes beyond each end of parameter j's 95% interval of `r`: at 0.001, 0.003 and 0.01 of
/// the end's distance w from the estimate (where the short ends were) and at 0.2 w to 2 w,
/// inside the box (internal coordinates, `log`: the parameter fitted as a log); (side, t).
fn probes_beyond(
    r: &restitution::fit::FitResult,
    j: usize,
    log: bool,
    (lower, upper): (&[f64], &[f64]),
) -> Vec<(usize, f64)> {
    let mut out = Vec::new();
    for (s, end) in [(0, r.params[j].ci95.0), (1, r.params[j].ci95.1)] {
        let Some(end) = end else { continue };
        let end = if log { end.ln() } else { end };
        let dir = if s == 0 { -1.0 } else { 1.0 };
        // (theta: internal coordinates.)
        let w = (end - r.theta[j]).abs().max(1e-4);
        for f in [0.001, 0.003, 0.01]
            .into_iter()
            .chain((1..=10).map(|k| k as f64 / 5.0))
        {
            let t = end + dir * w * f;
            if lower[j] <= t && t <= upper[j] {
                out.push((s, t));
            }
        }
    }
    out
}

/// The ends of `min`'s and `product`'s 95% intervals bound the region: beyond each end (13
/// probes out to twice its distance w from the estimate, three of them within 0.01 w, where the
/// short ends were), a brute-force profile (3000 log points of the other parameter across the
/// box, as `examples/interval_scan`) stays above the threshold. Seeds 4, 5 and 11 are the
/// fits of seeds 0-11 where an end fell short while the inner minimisation was local (by
/// 7e-5, 1.3e-3 and 2.7e-4 relative).
#[test]
fn interval_ends_are_not_short_of_the_95_percent_region() {
    let mut short = Vec::new();
    for (seed, kind) in [
        (4, ModelKind::Min),
        (5, ModelKind::Product),
        (11, ModelKind::Min),
    ] {
        let case = cases::make_case(seed);
        let (r, lower, upper) = reference::fit_with_box(&case, kind).unwrap();
        assert!(r.converged && r.global.certified, "{:?}", r.warnings);
        let threshold = r.chi2 + r.ci95_delta_chi2;
        for j in 0..2 {
            let o = 1 - j;
            for (s, t) in probes_beyond(&r, j, true, (&lower, &upper)) {
                let (v, _) = reference::separable_profile(
                    &case.data,
                    kind,
                    case.rule,
                    (j, t),
                    (lower[o], upper[o]),
                    3000,
                );
                if v < threshold {
                    short.push(format!("seed {seed} {kind} param {j} end {s}: {v} at {t}"));
                }
            }
        }
    }
    assert!(short.is_empty(), "{short:#?}");
}

/// The ends of the power law's parameters bound the 95% region: beyond each end (the probes of
/// `interval_ends_are_not_short_of_the_95_percent_region`), a brute-force profile stays above
/// the threshold: for an exponent, the other on 1500 points then Brent's method, A at its
/// least-squares value; for A, a 120 x 120 grid of both exponents then polishes from its five
/// lowest local minima (`reference::powerlaw_a_profile`). Seeds 5, 9, 54 and 80 are the fits of
/// seeds 0-100 where an exponent's end fell short while the inner minimisation
/// (Levenberg-Marquardt over A and the other exponent) was local, with chi2 up to 28 below the
/// threshold just beyond the end; on seed 9 the lower end of A fell short too while its inner
/// minimisation (over both exponents) was local: chi2 37 below the threshold 5.1e-4 beyond it
/// in ln A. The scan must first reproduce the fit's own minimum at the fit's value (1e-6
/// relative).
#[test]
fn power_law_ends_are_not_short_of_the_95_percent_region() {
    let kind = ModelKind::PowerLaw;
    let mut short = Vec::new();
    for seed in [5, 9, 54, 80] {
        let case = cases::make_case(seed);
        let (r, lower, upper) = reference::fit_with_box(&case, kind).unwrap();
        assert!(r.converged && r.global.certified, "{:?}", r.warnings);
        let threshold = r.chi2 + r.ci95_delta_chi2;
        let profile = |j: usize, t: f64| {
            if j == 0 {
                reference::powerlaw_a_profile(&case.data, case.rule, t, &lower, &upper)
            } else {
                reference::powerlaw_profile(&case.data, case.rule, (j, t), &lower, &upper)
            }
        };
        for j in 0..3 {
            let at_min = profile(j, r.theta[j]);
            assert!(
                at_min <= r.chi2 * (1.0 + 1e-6),
                "seed {seed} {j}: {at_min} {}",
                r.chi2
            );
            // A's interval is reported in A itself (its internal coordinate is ln A).
            for (s, t) in probes_beyond(&r, j, j == 0, (&lower, &upper)) {
                let v = profile(j, t);
                if v < threshold {
                    short.push(format!("seed {seed} param {j} end {s}: {v} at {t}"));
                }
            }
        }
    }
    assert!(short.is_empty(), "{short:#?}");
}

/// A part of the 95% region between the search grid's nodes, beyond the end the profile from
/// the minimum reaches ([`restitution::fit::beyond`]). `pm` on a 25.4 mm nylon pair: 30 points
/// at 8-31 m/s from sigma_y = 4e7 Pa without noise, their error set so that chi2 of those points
/// is 23 at 0.3 below in ln sigma_y; and one point at the speed where sigma_y 0.27 below starts
/// to yield, its e that of 0.3 below and its error such that it adds 20 while elastic. The
/// minimum (chi2 20) is at 4e7 Pa with that point elastic; chi2 falls below the threshold
/// (23.84) again only where that point yields to its e, in a dip about 0.007 wide in ln sigma_y
/// near 2.96e7 Pa, past a ridge. A brute-force scan of chi2 from the model (20 001 points over
/// 1.5 in ln sigma_y) must see the two parts, and the interval must reach the scan's lowest
/// point inside the threshold: before, the lower end stayed at 3.536e7 Pa with no warning (no
/// grid node fell into the dip).
#[test]
fn a_part_of_the_95_percent_region_between_the_grid_nodes_moves_the_end() {
    let m = Material::preset("nylon").unwrap();
    let d = 25.4;
    let c = pair_contact(m, d, None).unwrap();
    let pm = |v: f64, s: f64| {
        predict_e(
            ModelKind::Pm,
            &c,
            v,
            &[s],
            ContactEnd::Overlap,
            &VmMethod::Master,
        )
        .unwrap()
    };
    let sigma_a = 4e7f64;
    let sigma_dip = (sigma_a.ln() - 0.3).exp();
    let speeds: Vec<f64> = (0..30).map(|k| 8.0 * (1.0 + k as f64 / 10.0)).collect();
    let at_dip: f64 = speeds
        .iter()
        .map(|&v| (pm(v, sigma_dip) - pm(v, sigma_a)).powi(2))
        .sum();
    let err = (at_dip / 23.0).sqrt();
    // The speed where sigma_y 0.03 above the dip starts to yield (bisection on e < 1).
    let sigma_p = (sigma_dip.ln() + 0.03).exp();
    let (mut lo, mut hi) = (1e-6f64, 100.0f64);
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if pm(mid, sigma_p) < 1.0 {
            hi = mid
        } else {
            lo = mid
        }
    }
    let (v_p, e_p) = (hi, pm(hi, sigma_dip));
    let err_p = (1.0 - e_p) / 20f64.sqrt();
    let mut obs: Vec<Observation> = speeds
        .iter()
        .map(|&v| Observation {
            d_mm: d,
            d2_mm: None,
            v_n_m_s: v,
            e: pm(v, sigma_a),
            e_err: Some(err),
        })
        .collect();
    obs.push(Observation {
        d_mm: d,
        d2_mm: None,
        v_n_m_s: v_p,
        e: e_p,
        e_err: Some(err_p),
    });
    let data = FitData::new(m, obs.clone()).unwrap();
    let r = fit(&data, ModelKind::Pm, &FitOptions::default()).unwrap();
    assert!(
        r.converged && r.global.certified && r.warnings.is_empty(),
        "{:?}",
        r.warnings
    );
    let threshold = r.chi2 + r.ci95_delta_chi2;
    let chi2 = |s: f64| -> f64 {
        obs.iter()
            .map(|o| ((o.e - pm(o.v_n_m_s, s)) / o.e_err.unwrap()).powi(2))
            .sum()
    };
    let n = 20_000;
    let step = 1.5 / n as f64;
    let inside: Vec<f64> = (0..=n)
        .map(|k| sigma_a.ln() - 1.0 + step * k as f64)
        .filter(|&t| chi2(t.exp()) < threshold)
        .collect();
    // Two parts: a gap of more than 0.05 in ln sigma_y between consecutive inside points.
    let gaps = inside.windows(2).filter(|w| w[1] - w[0] > 0.05).count();
    assert_eq!(gaps, 1, "{inside:?}");
    let lowest = inside[0];
    let end = r.params[0].ci95.0.unwrap().ln();
    // Not short of the scan's lowest inside point, and within two of its steps of it (the
    // crossing lies between that point and the one below).
    assert!(
        end <= lowest && end >= lowest - 2.0 * step,
        "end {} scan {}",
        end.exp(),
        lowest.exp()
    );
    assert!(
        r.notes
            .iter()
            .any(|n| n.contains("lower end of the 95% interval of sigma_y moved")),
        "{:?}",
        r.notes
    );
}
