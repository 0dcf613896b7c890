//! Criterion benches of the evaluations a DEM modeller repeats millions of times (`cargo bench`).
//! The whole work-precision picture is `restitution bench`; these track the headline numbers.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use restitution::models::plastic::{e_of_u, rebound_u};
use restitution::models::viscoelastic::{
    ContactEnd, OdeSettings, VmMethod, master, restitution, restitution_ode,
};
use std::hint::black_box;
use std::time::Duration;

fn master_curve(c: &mut Criterion) {
    let mut g = c.benchmark_group("master_e_of_kappa");
    for kappa in [1e-3, 0.1, 1.0, 10.0] {
        for rule in ContactEnd::ALL {
            g.bench_with_input(BenchmarkId::new(rule.name(), kappa), &kappa, |b, &k| {
                b.iter(|| restitution(black_box(k), rule, &VmMethod::Master))
            });
        }
    }
    g.finish();
}

/// e(kappa) at 100 000 kappa spread over the table's range (0.01-2, the nylon data's), one at a
/// time and eight interleaved (`master::e_master_in_place`, what the fit uses), in no order and
/// in increasing order (as the fit hands them over): per value, divide the time by 100 000.
fn master_curve_many(c: &mut Criterion) {
    let mut g = c.benchmark_group("master_e_of_kappa_100000");
    g.measurement_time(Duration::from_secs(3));
    let kappas: Vec<f64> = (0..100_000)
        .map(|i| 0.01 + 2.0 * (i as f64 * 0.618_034).fract())
        .collect();
    let mut out = vec![0.0; kappas.len()];
    g.bench_function("one at a time", |b| {
        b.iter(|| {
            for (o, &k) in out.iter_mut().zip(black_box(&kappas)) {
                *o = restitution(k, ContactEnd::Overlap, &VmMethod::Master)
                    .unwrap()
                    .e;
            }
        })
    });
    g.bench_function("eight interleaved", |b| {
        b.iter(|| {
            out.copy_from_slice(black_box(&kappas));
            master::e_master_in_place(&mut out, ContactEnd::Overlap).unwrap();
        })
    });
    // As the fit's evaluator hands them over: groups of eight on one piece of the table.
    let mut sorted = kappas.clone();
    sorted.sort_by(f64::total_cmp);
    g.bench_function("eight interleaved, increasing", |b| {
        b.iter(|| {
            out.copy_from_slice(black_box(&sorted));
            master::e_master_in_place(&mut out, ContactEnd::Overlap).unwrap();
        })
    });
    g.finish();
}

/// The large-kappa laws (kappa >= 10): correctly rounded A kappa^-5 (overlap) and the force rule's
/// table (to 1e7) and law, in double-double.
fn master_curve_large(c: &mut Criterion) {
    let mut g = c.benchmark_group("master_e_of_kappa_large");
    for kappa in [1e3, 1e20, 1e300] {
        for rule in ContactEnd::ALL {
            g.bench_with_input(BenchmarkId::new(rule.name(), kappa), &kappa, |b, &k| {
                b.iter(|| restitution(black_box(k), rule, &VmMethod::Master))
            });
        }
    }
    g.finish();
}

fn ode_default(c: &mut Criterion) {
    let mut g = c.benchmark_group("ode_default_e_of_kappa");
    g.measurement_time(Duration::from_secs(3));
    for kappa in [1e-3, 0.1, 1.0, 5.0] {
        for rule in ContactEnd::ALL {
            g.bench_with_input(BenchmarkId::new(rule.name(), kappa), &kappa, |b, &k| {
                b.iter(|| restitution_ode(black_box(k), rule, &OdeSettings::DEFAULT))
            });
        }
    }
    g.finish();
}

fn plastic(c: &mut Criterion) {
    // rebound_u returns e and 1 - e (the latter through a cancellation-free chain for u near 1);
    // e_of_u computes only e.
    let mut g = c.benchmark_group("plastic_e_of_u");
    for u in [1.001, 10.0, 1e6, 1e300] {
        g.bench_with_input(BenchmarkId::new("rebound_u", u), &u, |b, &u| {
            b.iter(|| rebound_u(black_box(u)))
        });
        g.bench_with_input(BenchmarkId::new("e_of_u", u), &u, |b, &u| {
            b.iter(|| e_of_u(black_box(u)))
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    master_curve,
    master_curve_large,
    master_curve_many,
    ode_default,
    plastic
);
criterion_main!(benches);
