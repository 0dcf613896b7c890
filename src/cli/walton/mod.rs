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

mod render;

use super::{CliResult, Format, MaterialArgs};
use render::{fig6_fit, fig6_points};
use restitution::data::report::walton::{
    Context, render_collisions_csv, render_markdown, render_params_csv, render_table, to_json,
};
use restitution::data::walton::{measure_records, momentum_warning, read_collisions};
use restitution::data::{Table, write_all_atomic};
use restitution::fit::walton::{self as wfit, FitOptions, Weights};
use restitution::models::walton::K_HOMOGENEOUS;
use restitution::plot::walton::fig6_svg;
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

fn run_fit(a: FitArgs) -> CliResult {
    super::check_inertia_k(a.inertia_k)?;
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
    if let Some(w) = momentum_warning(&table.path, &records, &measured) {
        super::warn(w);
    }
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
    let command = std::iter::once("restitution".to_string())
        .chain(std::env::args().skip(1))
        .map(|s| if s.contains(' ') { format!("'{s}'") } else { s })
        .collect::<Vec<_>>()
        .join(" ");
    let ctx = Context::new(&table.path, &records, material, command);
    // Built once when both stdout and --out want it (34 MB for 100 000 collisions).
    let json = (matches!(a.format, Format::Json) || a.out.is_some()).then(|| to_json(&fit, &ctx));
    let text = match a.format {
        Format::Table => render_table(&fit, &ctx),
        Format::Csv => render_params_csv(&fit),
        Format::Json => json.clone().expect("built for --format json"),
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
            (
                dir.join("walton.json"),
                json.expect("built for --out").into_bytes(),
            ),
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
