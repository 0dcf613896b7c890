//! `restitution bench`: speed against accuracy for every way the toolkit computes e.
//!
//! ```text
//! restitution bench [--out DIR] [--quick]
//! ```
//! Writes into DIR (default `reports/bench`, created if missing), all nine files or none:
//! `work_precision.csv` (model,method,setting,knob,rule,error,error_rel_e,error_rel_one_minus_e,
//! ns_per_eval,rhs_evals,points,failed), `work_precision_points.csv` (every evaluation behind it),
//! `work_precision.svg`, `stability.csv`, `stability.svg` and `summary.md` (targets, RK4 order,
//! default-setting candidates, where each method fails, what accuracy a fit needs),
//! `timing_per_point.csv` (the targets' methods timed at each point alone), `fit_accuracy.csv` and
//! `fit_accuracy.svg` (model `vm` fitted to the example data set `data/fig7_nylon.csv`, compiled
//! in, with each evaluation method). Prints the summary. `--quick` measures
//! fewer settings and points with shorter timing batches (well under a minute).

use super::CliResult;
use restitution::bench::{self, BenchConfig};
use restitution::contact::Material;
use restitution::data::fit_input::parse_fit_csv;
use restitution::data::write_all_atomic;
use restitution::plot;
use std::path::PathBuf;

const EXAMPLE_PATH: &str = "data/fig7_nylon.csv";
const EXAMPLE_DATA: &str = include_str!("../../data/fig7_nylon.csv");

/// Speed against accuracy: work-precision chart, stability map, targets
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output directory
    #[arg(long, value_name = "DIR", default_value = "reports/bench")]
    out: PathBuf,
    /// Fewer settings, points and repeats (under a minute)
    #[arg(long)]
    quick: bool,
}

/// The CPU model and core count, for the report (Linux; "unknown" elsewhere).
fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!(
        "{cpu}, {cores} logical CPUs, {} {}",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}

/// The 1-minute load average (Linux), or "unknown".
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|t| t.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into())
}

pub fn run(args: Args) -> CliResult {
    let cfg = BenchConfig { quick: args.quick };
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("--out {}: cannot create directory: {e}", args.out.display()))?;
    let load_before = load_average();
    // The example data set of `restitution fit` (synthetic Fig. 7 nylon data), compiled in.
    let nylon = Material::preset("nylon").expect("the nylon preset exists");
    let example =
        parse_fit_csv(EXAMPLE_PATH, EXAMPLE_DATA, nylon, false).map_err(|e| e.to_string())?;
    let report = bench::run(&cfg, Some(&example.data)).map_err(|e| e.to_string())?;
    let machine = format!(
        "{}; load average (1 min) {} before, {} after (other processes share the CPUs when it is above 0)",
        machine(),
        load_before,
        load_average()
    );
    let summary = report.summary_markdown(&machine);
    let wp_svg = plot::bench::work_precision_svg(&report)?;
    let st_svg = plot::bench::stability_svg(&report)?;
    let fit_svg = plot::bench::fit_accuracy_svg(&report)?;
    let files = vec![
        (
            args.out.join("work_precision.csv"),
            report.work_precision_csv().into_bytes(),
        ),
        (
            args.out.join("work_precision_points.csv"),
            report.points_csv().into_bytes(),
        ),
        (args.out.join("work_precision.svg"), wp_svg.into_bytes()),
        (
            args.out.join("stability.csv"),
            report.stability_csv().into_bytes(),
        ),
        (args.out.join("stability.svg"), st_svg.into_bytes()),
        (
            args.out.join("timing_per_point.csv"),
            report.per_point_csv().into_bytes(),
        ),
        (
            args.out.join("fit_accuracy.csv"),
            report.fit_accuracy_csv().into_bytes(),
        ),
        (args.out.join("fit_accuracy.svg"), fit_svg.into_bytes()),
        (args.out.join("summary.md"), summary.clone().into_bytes()),
    ];
    write_all_atomic(&files).map_err(|e| format!("writing into {}: {e}", args.out.display()))?;
    print!("{summary}");
    println!("\nwrote {} files into {}", files.len(), args.out.display());
    Ok(())
}
