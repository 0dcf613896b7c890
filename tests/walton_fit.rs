//! The Fig. 6 fit of Walton's parameters and the oblique-collision CSV schema (the operator:
//! tests/walton.rs; the command: tests/walton_cli.rs).

use nalgebra::Vector3;
use restitution::contact::{Material, Sphere};
use restitution::data::Table;
use restitution::data::walton::{measure_records, read_collisions, write_collisions};
use restitution::fit::walton::{CollisionRecord, FitOptions, Weights, fit};
use restitution::models::walton::{
    Body, K_HOMOGENEOUS, State, Target, WaltonParams, collide, measure,
};
use restitution::synthetic::{SyntheticSpec, synthetic_collisions};

const EPS: f64 = f64::EPSILON;

/// A homogeneous sphere of diameter `d_m` and density `rho` (the elastic constants do not enter
/// Walton's operator).
fn sphere(d_m: f64, rho: f64) -> Sphere {
    Sphere::new(d_m, Material::new(1e9, 0.3, rho).unwrap()).unwrap()
}

// ---------------------------------------------------------------------------------------------
// The fit.

fn measured_of(records: &[CollisionRecord]) -> Vec<restitution::models::walton::Measured> {
    measure_records("synthetic", records).unwrap()
}

#[test]
fn noise_free_collisions_give_the_planted_parameters() {
    let mut spec = SyntheticSpec::paper();
    spec.n = 30;
    let (exact, _) = synthetic_collisions(&spec, 3).unwrap();
    let options = FitOptions {
        bootstrap: 0,
        ..FitOptions::default()
    };
    let f = fit(&measured_of(&exact), &options).unwrap();
    assert!(f.converged, "{}", f.message);
    // Exact data: only rounding remains (ratios of O(1) velocities, sums of 30 terms).
    assert!((f.e.value - 0.97).abs() < 1e-12, "{}", f.e.value);
    assert!((f.beta0.value - 0.5).abs() < 1e-12, "{}", f.beta0.value);
    assert!((f.mu0.value - 0.175).abs() < 1e-12, "{}", f.mu0.value);
    let (m, _) = f.impulse_ratio_sliding.unwrap();
    assert!((m - 0.175).abs() < 1e-12);
    assert!(f.com_dv_rms_m_s.unwrap() < 1e-14);
    // The classification agrees with the operator's own, collision by collision.
    for (c, r) in f.collisions.iter().zip(&exact) {
        let truth = collide(&r.pre, &spec.params).unwrap().kind;
        assert_eq!(c.kind, Some(truth));
    }
}

/// Noisy paper-like data: the truth lies within the 95% intervals of the shipped data set's fit,
/// and in repeated experiments the intervals cover it about 95% of the time.
#[test]
fn fit_recovers_planted_parameters_within_its_intervals() {
    let truth = WaltonParams::PAPER_NYLON;
    let spec = SyntheticSpec::paper();
    let mut covered = [0usize; 3];
    let reps = 100;
    for rep in 0..reps {
        let (_, noisy) = synthetic_collisions(&spec, 500 + rep).unwrap();
        let options = FitOptions {
            bootstrap: 400,
            seed: rep,
            ..FitOptions::default()
        };
        let f = fit(&measured_of(&noisy), &options).unwrap();
        assert!(f.converged, "{}", f.message);
        for (k, (ci, t)) in [
            (f.beta0.ci95, truth.beta0),
            (f.mu0.ci95, truth.mu0),
            (f.e.ci95, truth.e),
        ]
        .into_iter()
        .enumerate()
        {
            let (lo, hi) = ci.unwrap();
            if lo <= t && t <= hi {
                covered[k] += 1;
            }
        }
    }
    // Measured coverage at n = 60 is 92.5-93.6% (examples/walton_coverage.rs, 1000 repetitions).
    // With 100 repetitions the count has sd ~2.5, so [85, 100) fails a correct 93% interval
    // with probability < 0.1% while catching intervals that are too narrow (a 1-sigma
    // interval would cover ~68) or degenerate. The seeds are fixed, so the test is repeatable.
    for (name, c) in ["beta0", "mu0", "e"].iter().zip(covered) {
        assert!(
            (85..100).contains(&c),
            "{name}: {c} of {reps} intervals cover the truth"
        );
    }
}

#[test]
fn fit_reports_what_the_data_cannot_determine() {
    // Only grazing collisions: no plateau, beta0 is a lower bound.
    let mut spec = SyntheticSpec::paper();
    spec.incidence_deg = (60.0, 80.0);
    spec.n = 20;
    let (exact, _) = synthetic_collisions(&spec, 9).unwrap();
    let f = fit(&measured_of(&exact), &FitOptions::default()).unwrap();
    assert!(!f.converged);
    assert!(f.beta0.bound.is_some() && f.beta0.stderr.is_none());
    assert!(f.message.contains("beta0"), "{}", f.message);
    // mu0 is still right.
    assert!((f.mu0.value - 0.175).abs() < 1e-12);
    // Only near-head-on collisions: no sliding line, mu0 is a lower bound.
    spec.incidence_deg = (5.0, 20.0);
    let (exact, _) = synthetic_collisions(&spec, 9).unwrap();
    let f = fit(&measured_of(&exact), &FitOptions::default()).unwrap();
    assert!(!f.converged);
    assert!(f.mu0.bound.is_some());
    assert!((f.beta0.value - 0.5).abs() < 1e-12);
    assert!(
        f.mu0.value <= 0.175 + 1e-12,
        "a lower bound below the truth"
    );
    // Head-on within a degree, with the paper's noise: the tangential velocities (about 0.03
    // m/s) are the noise's size, and on seeds 7 and 19 the plateau's mean beta came out 1.22 and
    // 26.2, which Walton's operator cannot take (beta0 <= 1: above, a collision gains energy).
    // Not determined, saying why; seed 4's 0.58 stays a (noisy) estimate.
    spec.incidence_deg = (0.0, 1.0);
    spec.n = 12;
    for (seed, outside) in [(7, true), (19, true), (4, false)] {
        let (_, noisy) = synthetic_collisions(&spec, seed).unwrap();
        let options = FitOptions {
            bootstrap: 0,
            ..FitOptions::default()
        };
        let f = fit(&measured_of(&noisy), &options).unwrap();
        assert_eq!(
            (-1.0..=1.0).contains(&f.beta0.value),
            !outside,
            "{seed}: {}",
            f.beta0.value
        );
        assert_eq!(
            f.message.contains("outside Walton's range [-1, 1]"),
            outside,
            "{}",
            f.message
        );
        if outside {
            assert!(!f.converged, "{seed}: {}", f.message);
        }
    }
}

#[test]
fn camera_weights_beat_equal_weights_on_paper_like_data() {
    // The reason camera weighting is the default: smaller scatter of beta0 and e over repeated
    // experiments (examples/walton_coverage.rs, 1000 repetitions: sd(beta0) 0.0110 vs 0.0139,
    // sd(e) 0.0042 vs 0.0075). Equal weights let grazing collisions, whose e is poorly measured,
    // and near-head-on ones, whose beta is, dominate. 400 repetitions estimate each sd to ~4%
    // (the e distribution under equal weights has heavy tails, so 40 were not enough), which
    // separates ratios of ~1.8 (e) and ~1.3 (beta0) from 1 with margin.
    let spec = SyntheticSpec::paper();
    let mut est: [[Vec<f64>; 2]; 2] = Default::default();
    for rep in 0..400 {
        let (_, noisy) = synthetic_collisions(&spec, 900 + rep).unwrap();
        let m = measured_of(&noisy);
        for (w, weights) in [Weights::Camera, Weights::Equal].into_iter().enumerate() {
            let o = FitOptions {
                weights,
                bootstrap: 0,
                ..FitOptions::default()
            };
            let f = fit(&m, &o).unwrap();
            est[w][0].push(f.beta0.value);
            est[w][1].push(f.e.value);
        }
    }
    let sd = |v: &Vec<f64>| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
    };
    let sds = [
        sd(&est[0][0]),
        sd(&est[1][0]),
        sd(&est[0][1]),
        sd(&est[1][1]),
    ];
    assert!(sds[2] * 1.4 < sds[3], "e: {sds:?}");
    assert!(sds[0] * 1.1 < sds[1], "beta0: {sds:?}");
}

// ---------------------------------------------------------------------------------------------
// The CSV schema.

fn parse(text: &str) -> Vec<CollisionRecord> {
    let t = Table::parse("t.csv", text).unwrap();
    read_collisions(&t, &Material::preset("nylon").unwrap(), K_HOMOGENEOUS)
        .unwrap()
        .0
}

#[test]
fn written_collisions_read_back_identically() {
    // 3-D pairs (unequal) and walls, through the writer and the reader.
    let mut records = Vec::new();
    for i in 0..4 {
        let x = i as f64;
        let n = Vector3::new(1.0, 0.3 * x, -0.2).normalize();
        let b1 = Body::homogeneous(0.5 * 0.02 * n, &sphere(0.02, 1140.0)).moving(
            Vector3::new(-1.0, 0.1 * x, 0.3),
            Vector3::new(1.0, -2.0, 3.0 + x),
        );
        let pre = if i % 2 == 0 {
            let b2 = Body::homogeneous(-0.5 * 0.01 * n, &sphere(0.01, 1140.0))
                .moving(Vector3::new(0.5, 0.0, -0.1), Vector3::new(0.0, 4.0, -1.0));
            State::pair(b1, b2)
        } else {
            State::on_wall(b1, Vector3::zeros())
        };
        let post = collide(&pre, &WaltonParams::PAPER_NYLON).unwrap().state;
        records.push(CollisionRecord {
            line: 0,
            id: Some(format!("c{i}")),
            pre,
            post,
        });
    }
    let text = write_collisions(&records);
    assert!(text.starts_with("collision,d1_mm,d2_mm,x1_m,y1_m,z1_m,x2_m,y2_m,z2_m,v1x_m_s,"));
    let back = parse(&text);
    assert_eq!(back.len(), records.len());
    for (a, b) in records.iter().zip(&back) {
        assert_eq!(a.id, b.id);
        // mm <-> m conversion of the diameter: one rounding.
        assert!((a.pre.sphere.d_m - b.pre.sphere.d_m).abs() <= 2.0 * EPS * a.pre.sphere.d_m);
        assert_eq!(a.pre.sphere.velocity_m_s, b.pre.sphere.velocity_m_s);
        assert_eq!(a.post.sphere.spin_rad_s, b.post.sphere.spin_rad_s);
        assert_eq!(a.pre.sphere.position_m, b.pre.sphere.position_m);
        let m1 = measure(&a.pre, &a.post).unwrap();
        let m2 = measure(&b.pre, &b.post).unwrap();
        assert!((m1.e - m2.e).abs() < 1e-14 && (m1.e - 0.97).abs() < 1e-14);
        assert!((m1.beta.unwrap() - m2.beta.unwrap()).abs() < 1e-12);
    }
}

#[test]
fn wall_rows_may_omit_sphere_2_motion() {
    let text = "d1_mm,d2_mm,x1_m,y1_m,x2_m,y2_m,v1x_m_s,v1y_m_s,w1z_rad_s,v1x_post_m_s,v1y_post_m_s,w1z_post_rad_s\n\
                10,inf,0,0.005,0,0,1.5,-2,0,0.93,1.8,-114\n";
    let r = parse(text);
    assert!(matches!(r[0].pre.target, Target::Wall { .. }));
    let m = measure(&r[0].pre, &r[0].post).unwrap();
    assert!((m.e - 0.9).abs() < 1e-15);
}
