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
//! none. `--exact` integrates the ODE for every point instead of using the master curve.

use super::{CliResult, Format, MaterialArgs};
use restitution::data::fit_input::read_fit_csv;
use restitution::data::report::fit::{self as report, ReportContext};
use restitution::data::report::fit_text as report_text;
use restitution::data::write_all_atomic;
use restitution::fit::{FitOptions, ModelKind, fit_all};
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
    /// Integrate the viscoelastic ODE for every point instead of using the master curve
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
