//! The CSV reader (`data::Table`): `cargo bench --bench reader`.
//!
//! Parses the shipped Fig. 7 data (127 lines) and a 100 000-row file, and, for the ratio, the
//! previous method (a new csv reader for every line), kept here only as a comparator.

use criterion::{Criterion, criterion_group, criterion_main};
use restitution::data::Table;
use std::hint::black_box;

/// The reader before: split lines, build a csv reader per line (no line numbers kept here).
fn per_line(text: &str) -> usize {
    let mut fields = 0;
    for raw in text.lines() {
        let t = raw.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .from_reader(raw.as_bytes());
        if let Some(Ok(rec)) = rdr.records().next() {
            let row: Vec<String> = rec.iter().map(|f| f.trim().to_string()).collect();
            fields += black_box(row).len();
        }
    }
    fields
}

fn bench(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/fig7_nylon.csv");
    let fig7 = std::fs::read_to_string(path).unwrap();
    let mut big = String::from("# 100 000 rows\nd_mm,v_n_m_s,e,e_err\n");
    for i in 0..100_000 {
        big += &format!("25.4,{},0.9{},0.01\n", 0.5 + (i % 400) as f64 * 0.1, i % 10);
    }
    c.bench_function("reader: fig7_nylon.csv (127 lines)", |b| {
        b.iter(|| Table::parse("fig7", black_box(&fig7)).unwrap())
    });
    c.bench_function("reader, previous per-line method: fig7_nylon.csv", |b| {
        b.iter(|| per_line(black_box(&fig7)))
    });
    let mut g = c.benchmark_group("large");
    g.sample_size(10);
    g.bench_function("reader: 100 000 rows", |b| {
        b.iter(|| Table::parse("big", black_box(&big)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
