//! The Rust side of `python/bench/bench_speed.py`: the same library calls the Python functions
//! make, timed in Rust without Python around them. Prints one JSON line.
//!
//! ```text
//! cargo run --release --manifest-path python/Cargo.toml --example rust_baseline -- DATA.csv N REPEATS
//! ```
//! * `e_of_kappa_ns`: ns per element of the loop `restitution(kappa, Overlap, Master)` over N
//!   values of kappa = 10^(-4 + 5 i/(N-1)) (numpy's logspace(-4, 1, N)), the loop
//!   `restitution.e_of_kappa` runs; the minimum over REPEATS runs.
//! * `fit_all_ms`, `fit_vm_ms`: read the CSV, fit (all models / vm) and render the JSON
//!   document, as `restitution fit --format json` does; the minimum over REPEATS runs.

use restitution::contact::Material;
use restitution::data::fit_input::read_fit_csv;
use restitution::data::report::fit::{self as report, ReportContext};
use restitution::fit::{FitOptions, ModelKind, fit_all};
use restitution::models::viscoelastic::{ContactEnd, VmMethod, restitution as e_vm};
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

fn min_time<T>(repeats: usize, mut f: impl FnMut() -> T) -> f64 {
    (0..repeats)
        .map(|_| {
            let t = Instant::now();
            black_box(f());
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn fit_json(path: &Path, kinds: &[ModelKind]) -> String {
    let nylon = Material::preset("nylon").expect("preset");
    let input = read_fit_csv(path, nylon, false).expect("readable data");
    let options = FitOptions::default();
    let set = fit_all(&input.data, kinds, &options).expect("fit");
    let ctx = ReportContext {
        path: &input.path,
        data: &input.data,
        error_source: input.error_source.describe(),
        rule: options.rule,
        vm_method: &options.vm_method,
    };
    report::to_json(&ctx, &set).to_string()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: rust_baseline DATA.csv N REPEATS";
    let path = Path::new(args.get(1).expect(usage));
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).expect(usage);
    let repeats: usize = args.get(3).and_then(|s| s.parse().ok()).expect(usage);
    let kappa: Vec<f64> = (0..n)
        .map(|i| 10f64.powf(-4.0 + 5.0 * i as f64 / (n - 1) as f64))
        .collect();
    let loop_s = min_time(repeats, || {
        kappa
            .iter()
            .map(|&k| e_vm(k, ContactEnd::Overlap, &VmMethod::Master).map(|r| r.e))
            .collect::<Result<Vec<f64>, _>>()
            .expect("master curve")
    });
    let all_s = min_time(repeats, || fit_json(path, &ModelKind::ALL));
    let vm_s = min_time(repeats, || fit_json(path, &[ModelKind::Vm]));
    println!(
        "{{\"n\": {n}, \"e_of_kappa_ns\": {}, \"fit_all_ms\": {}, \"fit_vm_ms\": {}}}",
        loop_s / n as f64 * 1e9,
        all_s * 1e3,
        vm_s * 1e3
    );
}
