//! Detection speed: `cargo bench --bench frames`. Targets: a 192 x 239 frame with two spheres
//! under 1 ms, a 1024 x 1024 frame under 20 ms (one core). The frames are the tests' synthetic
//! scenes (tests/common/synth.rs), rendered once outside the timing.

#[path = "../tests/common/synth.rs"]
mod synth;

use criterion::{Criterion, criterion_group, criterion_main};
use restitution::frames::detect::{DetectSettings, detect_frame};
use std::hint::black_box;
use synth::{Scene, ball};

fn bench(c: &mut Criterion) {
    let s = DetectSettings::default();
    // The paper's camera: 192 x 239, 12.7 mm spheres (radius 25.4 px), markers, noise.
    let small = Scene::paper_like(
        192,
        239,
        vec![ball([60.3, 150.6], 25.4, 12), ball([130.2, 80.4], 25.4, 12)],
    )
    .render();
    c.bench_function("detect 192x239, two spheres r = 25 px", |b| {
        b.iter(|| detect_frame(black_box(&small), &s).unwrap())
    });
    // Touching spheres of radius 40 px (one merged blob).
    let touching = Scene::paper_like(
        192,
        239,
        vec![
            ball([60.3, 120.6], 40.0, 12),
            ball([124.3, 168.6], 40.0, 12),
        ],
    )
    .render();
    c.bench_function("detect 192x239, touching spheres r = 40 px", |b| {
        b.iter(|| detect_frame(black_box(&touching), &s).unwrap())
    });
    let mut big = Scene::paper_like(
        1024,
        1024,
        vec![
            ball([300.3, 600.6], 200.0, 12),
            ball([700.2, 380.4], 200.0, 12),
        ],
    );
    big.supersample = 2;
    let big = big.render();
    c.bench_function("detect 1024x1024, two spheres r = 200 px", |b| {
        b.iter(|| detect_frame(black_box(&big), &s).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30);
    targets = bench
}
criterion_main!(benches);
