//! `restitution walton fit`: e, beta_0 and mu_0 of Walton's collision operator from measured
//! oblique collisions (the paper's Fig. 6).
//!
//! ```text
//! restitution walton fit COLLISIONS.csv
//!     (--material NAME | --youngs-pa Y --poisson NU --density-kg-m3 RHO)
//!     [--inertia-k K] [--weights camera|equal] [--bootstrap N] [--seed S]
//!     [--format table|csv|json] [--out DIR]
//! ```
//! COLLISIONS.csv: a header, then one collision per row; columns in any order; `#` lines and
//! blank lines allowed.
//! * required: `d1_mm,d2_mm` (`d2_mm` = `inf`: a flat wall at rest), `x1_m,y1_m,x2_m,y2_m` (centres
//!   at contact; for a wall, `x2_m,y2_m` is the contact point on the wall),
//!   `v1x_m_s,v1y_m_s,w1z_rad_s,v2x_m_s,v2y_m_s,w2z_rad_s` (before) and
//!   `v1x_post_m_s,v1y_post_m_s,w1z_post_rad_s,v2x_post_m_s,v2y_post_m_s,w2z_post_rad_s` (after).
//!   For a wall, sphere 2's velocity and spin columns may be absent, empty or 0.
//! * optional (0 when absent; they make it 3-D): `z1_m,z2_m`, `v1z_m_s,w1x_rad_s,w1y_rad_s`, the
//!   same for sphere 2 and with `_post`; `collision` (an id carried to the outputs).
//!
//! Output: the fitted e (weighted mean), beta_0 and mu_0 with standard errors and bootstrap 95%
//! intervals, the collisions classed sliding or rolling, and two cross-checks (the sliding
//! collisions' impulse ratio, an independent estimate of mu_0; the momentum balance). `--format
//! csv` prints `parameter,value,stderr,ci95_low,ci95_high,bound`; `--out DIR` writes `walton.md`,
//! `walton.csv` (the parameters), `walton.json`, `walton_collisions.csv` (one row per collision)
//! and `fig6.svg`, all or none.

use super::{CliResult, Format, MaterialArgs};
use restitution::data::CsvOut;
use restitution::data::walton::{measure_records, read_collisions};
use restitution::data::{Table, fmt_num, write_all_atomic};
use restitution::fit::walton::{self as wfit, Bound, Estimate, FitOptions, WaltonFit, Weights};
use restitution::models::walton::{K_HOMOGENEOUS, Target};
use restitution::plot::walton::{Fig6Fit, Fig6Point, fig6_svg};
use serde_json::{Value, json};
use std::path::PathBuf;

/// Most collisions times bootstrap resamples (2000 resamples of up to 2000 collisions).
const MAX_BOOTSTRAP_WORK: usize = 4_000_000;

/// Walton's collision operator: fit its e, beta_0 and mu_0 to oblique collisions
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Subcommand, Debug)]
enum Command {
    /// Fit e, beta_0 and mu_0 to measured oblique collisions (the paper's Fig. 6)
    Fit(FitArgs),
}

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
enum WeightsArg {
    /// Same error on every measured velocity (a camera): weight beta by |v_s|^2, e by v_n^2
    Camera,
    /// Every collision counts the same
    Equal,
}

const COLUMNS: &str = "\
COLLISIONS.csv: a header line, then one collision per row; columns in any order; lines starting
with # and blank lines are skipped (error messages still give the file's own line numbers).
  required   d1_mm, d2_mm                      diameters; d2_mm = inf: a flat wall at rest
             x1_m, y1_m, x2_m, y2_m            centres at contact (wall: x2_m, y2_m = contact point)
             v1x_m_s, v1y_m_s, w1z_rad_s       sphere 1 before; likewise v2x_m_s, v2y_m_s, w2z_rad_s
             v1x_post_m_s, v1y_post_m_s, w1z_post_rad_s, and the same for sphere 2: after
             (a wall's velocity and spin columns may be absent, empty or 0)
  optional   z1_m, z2_m, v1z_m_s, w1x_rad_s, w1y_rad_s, ... and their _post forms: 3-D (0 if absent)
             collision                         an id carried to the outputs
Conventions: n = (r1 - r2)/|r1 - r2|; psi = -v_n/|v_s| with v_c = v1 - v2 - (d1/2 w1 + d2/2 w2) x n.
Example: restitution walton fit data/oblique_collisions.csv --material nylon --out reports/walton";

#[derive(clap::Args, Debug)]
#[command(after_long_help = COLUMNS, allow_negative_numbers = true)]
struct FitArgs {
    /// CSV of measured pre- and post-collision kinematics (columns: see --help)
    #[arg(value_name = "COLLISIONS.csv")]
    path: PathBuf,
    #[command(flatten)]
    material: MaterialArgs,
    /// Inertia factor K = 4I/(m d^2) of the spheres (2/5 for homogeneous spheres)
    #[arg(long = "inertia-k", value_name = "K", default_value_t = K_HOMOGENEOUS)]
    inertia_k: f64,
    /// How collisions are weighted in the fit
    #[arg(long, value_enum, default_value = "camera")]
    weights: WeightsArg,
    /// Bootstrap resamples for the 95% intervals (0: none; resamples times collisions at most
    /// 4 000 000)
    #[arg(long, value_name = "N", default_value_t = 2000)]
    bootstrap: usize,
    /// Seed of the bootstrap (the same seed gives the same intervals)
    #[arg(long, value_name = "S", default_value_t = 1)]
    seed: u64,
    #[arg(long, value_enum, default_value = "table")]
    format: Format,
    /// Write walton.md, walton.csv, walton.json, walton_collisions.csv and fig6.svg into DIR
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

pub fn run(args: Args) -> CliResult {
    match args.command {
        Command::Fit(a) => run_fit(a),
    }
}

/// Everything the renderers need besides the fit.
struct Context {
    path: String,
    diameters_mm: Vec<f64>,
    walls: usize,
    lines: Vec<usize>,
    ids: Vec<Option<String>>,
    material: restitution::contact::Material,
    command: String,
}

fn run_fit(a: FitArgs) -> CliResult {
    if !(a.inertia_k.is_finite() && a.inertia_k > 0.0 && a.inertia_k <= 1.0) {
        return Err(format!(
            "--inertia-k {}: expected a number in (0, 1] (K = 4I/(m d^2); 0.4 for a homogeneous sphere)",
            a.inertia_k
        ));
    }
    if a.bootstrap == 1 {
        return Err("--bootstrap 1: expected 0 (no intervals) or at least 2 resamples".into());
    }
    let material = a.material.resolve()?;
    let table = Table::read(&a.path).map_err(|e| e.to_string())?;
    let (records, warnings) =
        read_collisions(&table, &material, a.inertia_k).map_err(|e| e.to_string())?;
    for w in &warnings {
        super::warn(w);
    }
    // Each resample refits every collision: a cap on the product keeps a run within about
    // 0.2 s of CPU (54 ns per collision and resample, measured at 100 000 collisions).
    let work = records.len().saturating_mul(a.bootstrap);
    if work > MAX_BOOTSTRAP_WORK {
        let most = MAX_BOOTSTRAP_WORK / records.len();
        return Err(format!(
            "--bootstrap {} with {} collisions: too many refits (resamples times collisions at most {MAX_BOOTSTRAP_WORK}); give {}",
            a.bootstrap,
            records.len(),
            if most >= 2 {
                format!("--bootstrap {most} or less, or 0 for standard errors only")
            } else {
                "--bootstrap 0 (standard errors only)".to_string()
            }
        ));
    }
    let measured = measure_records(&table.path, &records).map_err(|e| e.to_string())?;
    let options = FitOptions {
        inertia_k: a.inertia_k,
        weights: match a.weights {
            WeightsArg::Camera => Weights::Camera,
            WeightsArg::Equal => Weights::Equal,
        },
        bootstrap: a.bootstrap,
        seed: a.seed,
    };
    let fit =
        wfit::fit(&measured, &options).map_err(|e| format!("{}: cannot fit: {e}", table.path))?;
    if !fit.converged {
        super::warn(format_args!("{}: {}", table.path, fit.message));
    }
    let mut diameters_mm: Vec<f64> = Vec::new();
    let mut walls = 0;
    for r in &records {
        let mut add = |d_m: f64| {
            let d = d_m * 1e3;
            if !diameters_mm.iter().any(|x| (x - d).abs() <= 1e-9 * d) {
                diameters_mm.push(d);
            }
        };
        add(r.pre.sphere.d_m);
        match r.pre.target {
            Target::Sphere(b) => add(b.d_m),
            Target::Wall { .. } => walls += 1,
        }
    }
    diameters_mm.sort_by(f64::total_cmp);
    let ctx = Context {
        path: table.path.clone(),
        diameters_mm,
        walls,
        lines: records.iter().map(|r| r.line).collect(),
        ids: records.iter().map(|r| r.id.clone()).collect(),
        material,
        command: std::iter::once("restitution".to_string())
            .chain(std::env::args().skip(1))
            .map(|s| if s.contains(' ') { format!("'{s}'") } else { s })
            .collect::<Vec<_>>()
            .join(" "),
    };
    let text = match a.format {
        Format::Table => render_table(&fit, &ctx),
        Format::Csv => render_params_csv(&fit),
        Format::Json => to_json(&fit, &ctx),
    };
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("--out {}: cannot create directory: {e}", dir.display()))?;
        let svg = fig6_svg(
            &fig6_points(&fit),
            &fig6_fit(&fit),
            "Tangential restitution against incidence (cf. the paper's Fig. 6)",
        )?;
        let files = vec![
            (
                dir.join("walton.md"),
                render_markdown(&fit, &ctx).into_bytes(),
            ),
            (dir.join("walton.csv"), render_params_csv(&fit).into_bytes()),
            (dir.join("walton.json"), to_json(&fit, &ctx).into_bytes()),
            (
                dir.join("walton_collisions.csv"),
                render_collisions_csv(&fit, &ctx).into_bytes(),
            ),
            (dir.join("fig6.svg"), svg.into_bytes()),
        ];
        write_all_atomic(&files)
            .map_err(|e| format!("--out {}: cannot write: {e}", dir.display()))?;
    }
    super::emit(&text)
}

pub(crate) fn fig6_points(fit: &WaltonFit) -> Vec<Fig6Point> {
    fit.collisions
        .iter()
        .filter_map(|c| {
            c.measured.beta.map(|beta| Fig6Point {
                psi: c.measured.psi,
                beta,
                sliding: c.kind == Some(restitution::models::walton::ContactKind::Sliding),
            })
        })
        .collect()
}

pub(crate) fn fig6_fit(fit: &WaltonFit) -> Fig6Fit {
    Fig6Fit {
        slope: fit.slope.value,
        beta0: fit.beta0.value,
        kink_psi: fit.kink_psi.value,
        beta0_ci95: fit.beta0.ci95,
        mu0: fit.mu0.value,
        e: fit.e.value,
        converged: fit.converged,
    }
}

/// A value with as many decimals as its error's two significant digits call for.
fn pm(value: f64, err: Option<f64>) -> (String, String, usize) {
    match err {
        Some(se) if se.is_finite() && se > 0.0 => {
            let decimals = (1 - se.log10().floor() as i32).clamp(0, 12) as usize;
            (
                format!("{value:.decimals$}"),
                format!("{se:.decimals$}"),
                decimals,
            )
        }
        _ => (super::readable(value), "-".into(), 4),
    }
}

fn interval(ci: Option<(f64, f64)>, decimals: usize) -> String {
    match ci {
        Some((lo, hi)) => format!("[{lo:.decimals$}, {hi:.decimals$}]"),
        None => "-".into(),
    }
}

/// Rows of the parameter table: name, estimate.
fn param_rows(fit: &WaltonFit) -> Vec<(&'static str, Estimate)> {
    vec![
        (
            "e",
            Estimate {
                value: fit.e.value,
                stderr: Some(fit.e.stderr),
                ci95: fit.e.ci95,
                bound: None,
            },
        ),
        ("beta0", fit.beta0),
        ("mu0", fit.mu0),
        ("slope", fit.slope),
        ("psi_kink", fit.kink_psi),
    ]
}

fn render_table(fit: &WaltonFit, ctx: &Context) -> String {
    let mut s = format!(
        "Walton fit of {}: {} collisions ({} oblique, {} head-on), K = {}, weights = {}\n\n",
        ctx.path,
        fit.n,
        fit.n - fit.n_head_on,
        fit.n_head_on,
        fmt_num(fit.options.inertia_k),
        fit.options.weights.as_str()
    );
    s += &format!(
        "{:<10} {:>12} {:>10}  {}\n",
        "parameter", "value", "stderr", "95% interval (bootstrap)"
    );
    for (name, est) in param_rows(fit) {
        let (v, se, dec) = pm(est.value, est.stderr);
        let v = if est.bound.is_some() {
            format!(">= {v}")
        } else {
            v
        };
        s += &format!(
            "{:<10} {:>12} {:>10}  {}\n",
            name,
            v,
            se,
            interval(est.ci95, dec)
        );
    }
    s += &format!(
        "\ne over the collisions: spread (sd) {:.3}, range {:.3} .. {:.3}\n",
        fit.e.spread, fit.e.min, fit.e.max
    );
    if fit.converged {
        s += &format!(
            "critical angle of incidence gamma_0 = {:.1} deg (cot gamma_0 = -psi*)\n",
            fit.gamma0_deg()
        );
    }
    s += &format!(
        "classes: {} sliding, {} rolling, {} head-on\n",
        fit.n_sliding, fit.n_rolling, fit.n_head_on
    );
    if let Some((m, se)) = fit.impulse_ratio_sliding {
        let (v, se, _) = pm(m, Some(se));
        s += &format!(
            "cross-check: impulse ratio |dP_t|/|dP_n| of the sliding collisions = {v} +- {se} (mu0 by Eq. 6)\n"
        );
    }
    if let Some(rms) = fit.com_dv_rms_m_s {
        s += &format!(
            "momentum check: rms change of the centre-of-mass velocity {:.3} m/s (0 for exact data)\n",
            rms
        );
    }
    s += &format!(
        "residuals: rms {:.3} in beta, {} degrees of freedom; bootstrap {} resamples (seed {}, {} left out)\n",
        fit.residual_rms,
        fit.dof,
        fit.bootstrap.resamples,
        fit.bootstrap.seed,
        fit.bootstrap.failed
    );
    s += &format!("status: {}\n", fit.message);
    s
}

fn render_params_csv(fit: &WaltonFit) -> String {
    let mut out = CsvOut::new();
    out.record([
        "parameter",
        "value",
        "stderr",
        "ci95_low",
        "ci95_high",
        "bound",
    ]);
    let opt = |x: Option<f64>| x.map(fmt_num).unwrap_or_default();
    for (name, est) in param_rows(fit) {
        out.record([
            name.to_string(),
            fmt_num(est.value),
            opt(est.stderr),
            opt(est.ci95.map(|c| c.0)),
            opt(est.ci95.map(|c| c.1)),
            match est.bound {
                Some(Bound::Lower) => "lower",
                None => "",
            }
            .to_string(),
        ]);
    }
    out.into_string()
}

fn render_collisions_csv(fit: &WaltonFit, ctx: &Context) -> String {
    let mut out = CsvOut::new();
    out.record([
        "line",
        "collision",
        "e",
        "beta",
        "psi",
        "v_n_m_s",
        "v_s_m_s",
        "impulse_ratio",
        "class",
        "residual",
    ]);
    let opt = |x: Option<f64>| x.map(fmt_num).unwrap_or_default();
    for (i, c) in fit.collisions.iter().enumerate() {
        let m = &c.measured;
        out.record([
            ctx.lines[i].to_string(),
            ctx.ids[i].clone().unwrap_or_default(),
            fmt_num(m.e),
            opt(m.beta),
            // Head-on: psi is infinite and the class says so.
            if m.psi.is_finite() {
                fmt_num(m.psi)
            } else {
                String::new()
            },
            fmt_num(m.v_n_m_s),
            fmt_num(m.v_s_m_s),
            fmt_num(m.impulse_ratio),
            class(c).to_string(),
            opt(c.residual),
        ]);
    }
    out.into_string()
}

fn class(c: &wfit::Classified) -> &'static str {
    c.kind.map(|k| k.as_str()).unwrap_or("head_on")
}

fn estimate_json(est: &Estimate) -> Value {
    let mut v = json!({
        "value": est.value,
        "stderr": est.stderr,
        "ci95": est.ci95.map(|(a, b)| vec![a, b]),
    });
    if let Some(Bound::Lower) = est.bound {
        v["bound"] = json!("lower");
    }
    v
}

fn to_json(fit: &WaltonFit, ctx: &Context) -> String {
    let collisions: Vec<Value> = fit
        .collisions
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let m = &c.measured;
            json!({
                "line": ctx.lines[i],
                "collision": ctx.ids[i],
                "e": m.e,
                "beta": m.beta,
                "psi": if m.psi.is_finite() { Some(m.psi) } else { None },
                "v_n_m_s": m.v_n_m_s,
                "v_s_m_s": m.v_s_m_s,
                "impulse_ratio": m.impulse_ratio,
                "class": class(c),
                "residual": c.residual,
            })
        })
        .collect();
    let v = json!({
        "data": {
            "path": ctx.path,
            "n": fit.n,
            "n_oblique": fit.n - fit.n_head_on,
            "diameters_mm": ctx.diameters_mm,
            "walls": ctx.walls,
        },
        "material": {
            "youngs_pa": ctx.material.youngs_pa,
            "poisson": ctx.material.poisson,
            "density_kg_m3": ctx.material.density_kg_m3,
        },
        "inertia_k": fit.options.inertia_k,
        "weights": fit.options.weights.as_str(),
        "e": {
            "value": fit.e.value,
            "stderr": fit.e.stderr,
            "ci95": fit.e.ci95.map(|(a, b)| vec![a, b]),
            "spread": fit.e.spread,
            "min": fit.e.min,
            "max": fit.e.max,
        },
        "beta0": estimate_json(&fit.beta0),
        "mu0": estimate_json(&fit.mu0),
        "slope": estimate_json(&fit.slope),
        "psi_kink": estimate_json(&fit.kink_psi),
        "gamma0_deg": fit.converged.then(|| fit.gamma0_deg()),
        "n": fit.n,
        "classes": {
            "sliding": fit.n_sliding,
            "rolling": fit.n_rolling,
            "head_on": fit.n_head_on,
        },
        "impulse_ratio_sliding": fit.impulse_ratio_sliding.map(|(m, se)| json!({
            "value": m, "stderr": se, "n": fit.n_sliding,
        })),
        "com_dv_rms_m_s": fit.com_dv_rms_m_s,
        "residual_rms": fit.residual_rms,
        "dof": fit.dof,
        "bootstrap": {
            "resamples": fit.bootstrap.resamples,
            "seed": fit.bootstrap.seed,
            "failed": fit.bootstrap.failed,
        },
        "converged": fit.converged,
        "message": fit.message,
        "collisions": collisions,
    });
    serde_json::to_string_pretty(&v).expect("JSON values serialise") + "\n"
}

fn render_markdown(fit: &WaltonFit, ctx: &Context) -> String {
    let mut s = String::from("# Walton collision properties (Fig. 6 fit)\n\n");
    s += &format!("Made by: `{}`\n\n", ctx.command);
    s += &format!(
        "Data: `{}`, {} collisions ({} oblique, {} head-on), diameters {} mm{}; K = {}; weights: {}.\n\n",
        ctx.path,
        fit.n,
        fit.n - fit.n_head_on,
        fit.n_head_on,
        ctx.diameters_mm
            .iter()
            .map(|d| fmt_num(*d))
            .collect::<Vec<_>>()
            .join(", "),
        if ctx.walls > 0 {
            format!(", {} on a wall", ctx.walls)
        } else {
            String::new()
        },
        fmt_num(fit.options.inertia_k),
        fit.options.weights.as_str()
    );
    s += "| parameter | value | stderr | 95% interval (bootstrap) |\n|---|---|---|---|\n";
    for (name, est) in param_rows(fit) {
        let (v, se, dec) = pm(est.value, est.stderr);
        let v = if est.bound.is_some() {
            format!(">= {v}")
        } else {
            v
        };
        s += &format!("| {name} | {v} | {se} | {} |\n", interval(est.ci95, dec));
    }
    s += &format!(
        "\n- e over the collisions: spread (sd) {:.3}, range {:.3} to {:.3}.\n",
        fit.e.spread, fit.e.min, fit.e.max
    );
    s += &format!(
        "- Classes: {} sliding, {} rolling, {} head-on.\n",
        fit.n_sliding, fit.n_rolling, fit.n_head_on
    );
    if fit.converged {
        s += &format!(
            "- Kink psi* = {:.3}: critical angle of incidence gamma_0 = {:.1} degrees.\n",
            fit.kink_psi.value,
            fit.gamma0_deg()
        );
    }
    if let Some((m, se)) = fit.impulse_ratio_sliding {
        let (v, se, _) = pm(m, Some(se));
        s += &format!(
            "- Cross-check: the impulse ratio of the sliding collisions is {v} +- {se} (mu0 by Eq. 6).\n"
        );
    }
    if let Some(rms) = fit.com_dv_rms_m_s {
        s += &format!(
            "- Momentum check: rms change of the centre-of-mass velocity {rms:.3} m/s (0 for exact data).\n"
        );
    }
    s += &format!(
        "- Residual rms {:.3} in beta, {} degrees of freedom; bootstrap {} resamples, seed {}, {} left out.\n",
        fit.residual_rms,
        fit.dof,
        fit.bootstrap.resamples,
        fit.bootstrap.seed,
        fit.bootstrap.failed
    );
    s += &format!("- Status: {}.\n\n", fit.message);
    s += "![beta against psi with the fitted Walton hinge](fig6.svg)\n\n";
    s += "Per-collision values: `walton_collisions.csv`. Model: beta = min(-1 + s psi, beta0), \
          s = mu0 (1 + 1/K)(1 + e) (Eq. 7); psi = -v_n/|v_s|.\n";
    s
}
