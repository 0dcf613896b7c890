//! `restitution fit`: measured e against normal impact speed to fitted eta and sigma_y, with
//! uncertainties, a model comparison, parameter tables and a Fig. 7-style figure.
//!
//! ```text
//! restitution fit DATA.csv (--material NAME | --youngs-pa Y --poisson NU --density-kg-m3 RHO)
//!     [--model vm|pm|min|product|powerlaw|all] [--contact-end overlap|force] [--exact]
//!     [--strict] [--format table|csv|json] [--out DIR]
//! ```
//! DATA.csv columns (any order, extra columns ignored, `#` comments and blank lines allowed):
//! `d_mm`, `v_n_m_s`, `e`, optional `e_err`, `v_err_m_s` (sigma_e = 2 e v_err / v_n when `e_err`
//! is absent), `d2_mm` (`inf` = flat wall; absent = identical spheres).
//! stdout: the parameter table, the comparison and the preferred model (or CSV / JSON).
//! `--out DIR` also writes params.md, params.csv, params.json, fig7.svg and residuals.svg, all or
//! none. `--exact` integrates the ODE for every point instead of using the master curve, and is
//! refused (one line) where that would take more than about a second.

use super::{CliResult, Format, MaterialArgs};
use restitution::data::fit_input::read_fit_csv;
use restitution::data::report::fit::{self as report, ReportContext};
use restitution::data::report::fit_text as report_text;
use restitution::data::write_all_atomic;
use restitution::fit::{FitData, FitOptions, ModelKind, fit_all};
use restitution::models::viscoelastic::{ContactEnd, OdeSettings, VmMethod};
use restitution::plot::fit::{fig7_svg, residuals_svg};
use std::path::PathBuf;

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelArg {
    /// Viscoelastic (fits eta)
    Vm,
    /// Plastic (fits sigma_y)
    Pm,
    /// e = min(e_vm, e_pm) (fits eta, sigma_y)
    Min,
    /// e = e_vm * e_pm (fits eta, sigma_y)
    Product,
    /// 1 - e = A (d/10 mm)^(-a) (v/(1 m/s))^b (fits A, a, b)
    Powerlaw,
    /// Every model, compared by AIC
    All,
}

/// Fit models of e(v_n) to measured coefficients of restitution
#[derive(clap::Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct Args {
    /// CSV with columns d_mm, v_n_m_s, e [, e_err | v_err_m_s] [, d2_mm]
    #[arg(value_name = "DATA.csv")]
    data: PathBuf,
    #[command(flatten)]
    material: MaterialArgs,
    #[arg(long, value_enum, default_value = "all")]
    model: ModelArg,
    /// End of contact (vm): overlap (the paper's) or force (Schwager & Poeschel)
    #[arg(long = "contact-end", default_value = "overlap", value_parser = parse_rule)]
    contact_end: ContactEnd,
    /// Integrate the viscoelastic ODE for every point instead of using the master curve (refused
    /// beyond about a second of work: vm up to 600 distinct points, min 200, product 100, all 60)
    #[arg(long)]
    exact: bool,
    /// Treat suspicious values (e > 1, diameters below 0.1 mm) as errors
    #[arg(long)]
    strict: bool,
    #[arg(long, value_enum, default_value = "table")]
    format: Format,
    /// Also write params.md, params.csv, params.json, fig7.svg and residuals.svg into DIR
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

fn parse_rule(s: &str) -> Result<ContactEnd, String> {
    s.parse()
}

/// Most distinct points times the `--exact` cost of the models asked for (see
/// [`exact_cost`]): `vm` at 600 points, about 1.1 s of CPU on 2 Intel Xeon cores (1.8 ms a
/// point), leaving room below the 2 s the fuzzer allows for a slower machine.
const MAX_EXACT_WORK: usize = 600;

/// A model's cost under `--exact` relative to `vm`'s: the ODE runs at every distinct point for
/// every eta tried, and `min` and `product` try about three and six times as many (0.22, 0.62
/// and 1.14 s of CPU on the shipped 120 points); `pm` and the power law integrate nothing.
fn exact_cost(kind: ModelKind) -> usize {
    match kind {
        ModelKind::Vm => 1,
        ModelKind::Min => 3,
        ModelKind::Product => 6,
        ModelKind::Pm | ModelKind::PowerLaw => 0,
    }
}

/// `--exact` integrates the ODE at every distinct point (rows sharing a pair and a speed are
/// one) for every parameter value tried: a cap on points times cost keeps a run within about a
/// second, as the 2 s the fuzzer allows any command asks (100 000 distinct points would take
/// some 3 minutes for `vm` at 1.8 ms a point, half an hour for `all`). The master curve, the
/// default, agrees with the ODE to 1e-7 in eta.
fn check_exact_work(
    path: &str,
    data: &FitData,
    kinds: &[ModelKind],
    model: &str,
) -> Result<(), String> {
    let cost: usize = kinds.iter().map(|&k| exact_cost(k)).sum();
    if cost == 0 {
        return Ok(());
    }
    let points = data.merge_repeats().map_or(data.len(), |m| m.data.len());
    if points.saturating_mul(cost) <= MAX_EXACT_WORK {
        return Ok(());
    }
    Err(format!(
        "--exact with the {points} distinct points of {path} and --model {model}: too many ODE \
         integrations \
         (distinct points times the model's cost, {cost} for {model}, at most {MAX_EXACT_WORK}); \
         give at most {} points{}, or leave out --exact (the master curve agrees with the ODE \
         to 1e-7 in eta)",
        MAX_EXACT_WORK / cost,
        if kinds.len() > 1 {
            ", fewer models"
        } else {
            ""
        }
    ))
}

pub fn run(args: Args) -> CliResult {
    let material = args.material.resolve()?;
    let input = read_fit_csv(&args.data, material, args.strict).map_err(|e| e.to_string())?;
    for w in &input.warnings {
        eprintln!("restitution: warning: {w}");
    }
    let kinds: Vec<ModelKind> = match args.model {
        ModelArg::Vm => vec![ModelKind::Vm],
        ModelArg::Pm => vec![ModelKind::Pm],
        ModelArg::Min => vec![ModelKind::Min],
        ModelArg::Product => vec![ModelKind::Product],
        ModelArg::Powerlaw => vec![ModelKind::PowerLaw],
        ModelArg::All => ModelKind::ALL.to_vec(),
    };
    if args.exact {
        let model = clap::ValueEnum::to_possible_value(&args.model)
            .map_or_else(String::new, |v| v.get_name().to_string());
        check_exact_work(&input.path, &input.data, &kinds, &model)?;
    }
    let vm_method = if args.exact {
        VmMethod::Ode(OdeSettings::DEFAULT)
    } else {
        VmMethod::Master
    };
    let options = FitOptions {
        rule: args.contact_end,
        vm_method,
        ..FitOptions::default()
    };
    let set = fit_all(&input.data, &kinds, &options)
        .map_err(|e| format!("{}: fit failed: {e}", input.path))?;
    let ctx = ReportContext {
        path: &input.path,
        data: &input.data,
        error_source: input.error_source.describe(),
        rule: args.contact_end,
        vm_method: &vm_method,
    };
    // Each rendered once, and only when a file or the chosen format needs it (together a fifth
    // of a small fit's CPU).
    let files = args.out.is_some();
    let json = if files || args.format == Format::Json {
        let text = serde_json::to_string_pretty(&report::to_json(&ctx, &set))
            .map_err(|e| format!("cannot render JSON: {e}"))?;
        text + "\n"
    } else {
        String::new()
    };
    let csv = if files || args.format == Format::Csv {
        report::to_csv(&ctx, &set)
    } else {
        String::new()
    };
    if let Some(dir) = &args.out {
        let name = args
            .data
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_else(|| input.path.clone());
        let fig = fig7_svg(
            &input.data,
            &set,
            args.contact_end,
            &vm_method,
            &format!("Coefficient of restitution vs normal impact speed: {name}"),
        )?;
        let res = residuals_svg(&input.data, &set, &format!("Residuals: {name}"))?;
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("--out {}: cannot create the directory: {e}", dir.display()))?;
        let files = vec![
            (
                dir.join("params.md"),
                report_text::to_markdown(&ctx, &set).into_bytes(),
            ),
            (dir.join("params.csv"), csv.clone().into_bytes()),
            (dir.join("params.json"), json.clone().into_bytes()),
            (dir.join("fig7.svg"), fig.into_bytes()),
            (dir.join("residuals.svg"), res.into_bytes()),
        ];
        write_all_atomic(&files)
            .map_err(|e| format!("--out {}: cannot write the results: {e}", dir.display()))?;
    }
    match args.format {
        Format::Table => print!("{}", report_text::to_table(&ctx, &set)),
        Format::Csv => print!("{csv}"),
        Format::Json => print!("{json}"),
    }
    Ok(())
}
