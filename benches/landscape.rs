//! The separable landscape's cell bound on large data: `cargo bench --bench landscape`.
//!
//! 100 000 distinct points (the shipped fig7_nylon rows repeated, every speed moved by up to
//! 0.1%, as `scripts/time_big_fit.sh` builds them), `min` and `product`, a cell of width 0.01
//! in both log parameters near their minimum. "one pass": a bound asked against +inf stops
//! after the sampled pass and the first full pass (1 + 1/13 passes over the points: the time
//! divided by 1.08e5 is the cost per point and pass); "to the corners": against the corners'
//! least chi2, as the search asks near the minimum (its Newton passes included).

use criterion::{Criterion, criterion_group, criterion_main};
use restitution::contact::Material;
use restitution::data::fit_input::read_fit_csv;
use restitution::fit::ModelKind;
use restitution::fit::bnb::Landscape;
use restitution::fit::dataset::FitData;
use restitution::fit::landscape::Separable;
use restitution::fit::models::Evaluator;
use restitution::fit::objective::Objective;
use restitution::models::viscoelastic::{ContactEnd, VmMethod};
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/fig7_nylon.csv");
    let nylon = Material::preset("nylon").unwrap();
    let rows = read_fit_csv(&path, nylon, false).unwrap().data.obs;
    let obs = (0..100_000)
        .map(|k| {
            let mut o = rows[k % rows.len()];
            o.v_n_m_s *= 1.0 + 1e-3 * ((k * 7919 % 2001) as f64 / 1000.0 - 1.0);
            o
        })
        .collect();
    let data = FitData::new(nylon, obs).unwrap();
    let ev = Evaluator::new(&data, ContactEnd::Overlap, VmMethod::Master);
    let mut g = c.benchmark_group("separable cell bound (100 000 points)");
    g.sample_size(20);
    for (kind, eta, sigma_y) in [
        (ModelKind::Product, 177.4, 5.574e7),
        (ModelKind::Min, 190.0, 4.0e7),
    ] {
        let obj = Objective::new(&ev, kind).unwrap();
        let mut l = Separable::new(&obj, kind == ModelKind::Min, [true, true]);
        let (t0, t1) = (f64::ln(eta), f64::ln(sigma_y));
        for (axis, t) in [
            (0, t0 - 0.004),
            (0, t0 + 0.006),
            (1, t1 - 0.006),
            (1, t1 + 0.004),
        ] {
            l.add_row(axis, t).unwrap();
        }
        let corners = [[0, 0], [1, 0], [0, 1], [1, 1]].map(|r| l.node(r));
        let least = corners.iter().cloned().fold(f64::INFINITY, f64::min);
        g.bench_function(format!("{kind}, one pass"), |b| {
            b.iter(|| l.bound(black_box([0, 0]), [1, 1], f64::INFINITY))
        });
        g.bench_function(format!("{kind}, to the corners"), |b| {
            b.iter(|| l.bound(black_box([0, 0]), [1, 1], least))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
