//! Walton's operator and the Fig. 6 fit: `cargo bench --bench walton`.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use restitution::contact::{Material, Sphere};
use restitution::data::walton::measure_records;
use restitution::fit::walton::{FitOptions, fit};
use restitution::models::walton::{Body, State, WaltonParams, collide, measure};
use restitution::synthetic::{SyntheticSpec, synthetic_collisions};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let d = 0.0254;
    let n = Vector3::new(0.6, 0.8, 0.0);
    let nylon = Sphere::new(d, Material::preset("nylon").unwrap()).unwrap();
    let b1 = Body::homogeneous(0.5 * d * n, &nylon)
        .moving(Vector3::new(-1.9, 0.4, 0.1), Vector3::new(0.0, 1.0, 5.0));
    let b2 = Body::homogeneous(-0.5 * d * n, &nylon)
        .moving(Vector3::new(2.0, -0.1, 0.0), Vector3::new(2.0, 0.0, -3.0));
    let pre = State::pair(b1, b2);
    let p = WaltonParams::PAPER_NYLON;
    c.bench_function("walton collide (3-D pair)", |b| {
        b.iter(|| collide(black_box(&pre), black_box(&p)).unwrap())
    });
    let post = collide(&pre, &p).unwrap().state;
    c.bench_function("walton measure (3-D pair)", |b| {
        b.iter(|| measure(black_box(&pre), black_box(&post)).unwrap())
    });
    let (_, noisy) = synthetic_collisions(&SyntheticSpec::paper(), 1997).unwrap();
    let m = measure_records("bench", &noisy).unwrap();
    let no_boot = FitOptions {
        bootstrap: 0,
        ..FitOptions::default()
    };
    c.bench_function("walton fit, 60 collisions, no bootstrap", |b| {
        b.iter(|| fit(black_box(&m), &no_boot).unwrap())
    });
    c.bench_function("walton fit, 60 collisions, 2000 bootstrap resamples", |b| {
        b.iter(|| fit(black_box(&m), &FitOptions::default()).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
