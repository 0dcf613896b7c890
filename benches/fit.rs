//! `restitution fit` on the shipped 120-point example: `cargo bench --bench fit`.
//!
//! Targets: `--model all` including the SVGs under 50 ms, a `vm` fit under 5 ms (the README's
//! "Fitting measured e(v_n)" quotes the medians).

use criterion::{Criterion, criterion_group, criterion_main};
use restitution::contact::Material;
use restitution::data::fit_input::read_fit_csv;
use restitution::data::report::fit::{self as report, ReportContext};
use restitution::data::report::fit_text as report_text;
use restitution::fit::{FitOptions, ModelKind, fit, fit_all};
use restitution::models::viscoelastic::{ContactEnd, OdeSettings, VmMethod};
use restitution::plot::fit::{fig7_svg, residuals_svg};
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/fig7_nylon.csv");
    let nylon = Material::preset("nylon").unwrap();
    let input = read_fit_csv(&path, nylon, false).unwrap();
    let data = &input.data;
    let opts = FitOptions::default();
    let mut g = c.benchmark_group("fit fig7_nylon (120 points)");
    g.bench_function("read and validate the CSV", |b| {
        b.iter(|| read_fit_csv(black_box(&path), nylon, false).unwrap())
    });
    g.bench_function("vm, with profile interval", |b| {
        b.iter(|| fit(black_box(data), ModelKind::Vm, &opts).unwrap())
    });
    let no_ci = FitOptions {
        intervals: false,
        ..FitOptions::default()
    };
    g.bench_function("vm, covariance only", |b| {
        b.iter(|| fit(black_box(data), ModelKind::Vm, &no_ci).unwrap())
    });
    for kind in [
        ModelKind::Pm,
        ModelKind::Min,
        ModelKind::Product,
        ModelKind::PowerLaw,
    ] {
        g.bench_function(format!("{kind}, with profile intervals"), |b| {
            b.iter(|| fit(black_box(data), kind, &opts).unwrap())
        });
    }
    g.bench_function("all five models", |b| {
        b.iter(|| fit_all(black_box(data), &ModelKind::ALL, &opts).unwrap())
    });
    g.bench_function("all five models + tables + both SVGs", |b| {
        b.iter(|| {
            let set = fit_all(black_box(data), &ModelKind::ALL, &opts).unwrap();
            let ctx = ReportContext {
                path: "data/fig7_nylon.csv",
                data,
                error_source: input.error_source.describe(),
                rule: ContactEnd::Overlap,
                vm_method: &VmMethod::Master,
            };
            let j = report::to_json(&ctx, &set).to_string();
            let m = report_text::to_markdown(&ctx, &set);
            let t = report_text::to_table(&ctx, &set);
            let s = report::to_csv(&ctx, &set);
            let f = fig7_svg(data, &set, ContactEnd::Overlap, &VmMethod::Master, "fig7").unwrap();
            let r = residuals_svg(data, &set, "residuals").unwrap();
            j.len() + m.len() + t.len() + s.len() + f.len() + r.len()
        })
    });
    let set = fit_all(data, &ModelKind::ALL, &opts).unwrap();
    g.bench_function("fig7.svg alone", |b| {
        b.iter(|| {
            fig7_svg(
                data,
                black_box(&set),
                ContactEnd::Overlap,
                &VmMethod::Master,
                "f",
            )
            .unwrap()
        })
    });
    g.bench_function("residuals.svg alone", |b| {
        b.iter(|| residuals_svg(data, black_box(&set), "r").unwrap())
    });
    g.sample_size(10);
    let exact = FitOptions {
        vm_method: VmMethod::Ode(OdeSettings::DEFAULT),
        ..FitOptions::default()
    };
    g.bench_function("vm --exact (ODE for every point)", |b| {
        b.iter(|| fit(black_box(data), ModelKind::Vm, &exact).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
