//! `restitution export`: a fitted contact law as simulation-engine input (docs/physics.md §9).
//!
//! ```text
//! restitution export [PARAMS.json] --engine lammps|constant-e|table [--model NAME]
//!     [--walton WALTON.json | --mu0 MU [--beta0 B]]
//!     [--d-mm D1,D2,...] [--wall] [--v-range LO,HI] [--weight log|uniform]
//!     [--tolerance T] [--table-points N] [--law auto|viscoelastic|constant-e]
//!     [--speeds V1,V2,...] [--out DIR] [--verify]
//!   without PARAMS.json, the same numbers as flags:
//!     (--material NAME | --youngs-pa Y --poisson NU --density-kg-m3 RHO) --d-mm D1,...
//!     [--model vm|pm|min|product] [--eta ETA] [--sigma-y-pa S] [--contact-end overlap|force]
//! ```
//! PARAMS.json is what `restitution fit --out` writes (material, contact end, the fitted models;
//! the preferred one, or the only one, unless --model); WALTON.json what `restitution walton
//! fit --out` writes (mu_0, beta_0). `--d-mm` sets the scene's sphere sizes (one engine type
//! each; default: the fit data's spheres, both of each pair, with a wall if the data hit one),
//! `--wall` adds sphere-wall contacts. Engines:
//! - `lammps`: DIR/in.restitution (`pair_style granular` and every `pair_coeff`), DIR/collide.in;
//!   exact for `vm`, otherwise the closest viscoelastic law or constant e over --v-range
//!   (`--law`, default the closer one);
//! - `constant-e`: the best constant e per pair over --v-range with its largest deviation:
//!   DIR/constant_e.csv, LAMMPS `damping tsuji` files, DIR/liggghts.in;
//! - `table`: DIR/table.csv, e(v) per pair for event-driven codes (--table-points, default 41).
//!
//! `--tolerance T` names the simplest law within T of the fitted e(v). Every run with a range
//! writes DIR/laws.svg and DIR/export.json. `--verify` runs `lmp` on collide.in at 4000, 8000
//! and 16000 steps per contact and compares the extrapolated e with the toolkit's (fails above
//! 1e-6).

use super::{CliResult, MaterialArgs, emit, warn};
use restitution::data::export::job::{
    self, ArgStyle, ExportError, ExportOptions, FittedLaw, JsonSource,
};
use restitution::data::export::plan::{EngineKind, LawChoice};
use restitution::data::write_all_atomic;
use restitution::dem::range::{SpeedRange, Weight};
use restitution::models::viscoelastic::ContactEnd;
use std::path::{Path, PathBuf};

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    /// LAMMPS pair_style granular (hertz/material, viscoelastic damping)
    Lammps,
    /// A velocity-independent e (LIGGGHTS, EDEM, Yade, MercuryDPM, LAMMPS damping tsuji)
    ConstantE,
    /// e(v_n) on a grid for event-driven codes
    Table,
}

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawArg {
    /// The exact law for vm, otherwise whichever of the other two is closer to the fit (a
    /// constant e only where LAMMPS's damping tsuji can give it)
    Auto,
    Viscoelastic,
    ConstantE,
}

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeightArg {
    /// Uniform in ln v
    Log,
    /// Uniform in v
    Uniform,
}

/// A fitted contact law as simulation-engine input
#[derive(clap::Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct Args {
    /// params.json written by `restitution fit --out`
    #[arg(value_name = "PARAMS.json")]
    params: Option<PathBuf>,
    #[arg(long, value_enum)]
    engine: Engine,
    /// Model to export (default: the file's preferred model, or its only one)
    #[arg(long, value_name = "NAME")]
    model: Option<String>,
    /// walton.json written by `restitution walton fit --out` (mu_0, beta_0)
    #[arg(long, value_name = "WALTON.json", conflicts_with_all = ["mu0", "beta0"])]
    walton: Option<PathBuf>,
    #[command(flatten)]
    material: MaterialArgs,
    /// Sphere diameters of the scene, mm (one engine atom type each; default: both spheres of
    /// the fit data's pairs, and a wall if they hit one)
    #[arg(long = "d-mm", value_name = "D", value_delimiter = ',', num_args = 1..)]
    d_mm: Vec<f64>,
    /// Spheres also hit flat walls of the same material
    #[arg(long)]
    wall: bool,
    /// Damping eta, kg/(s m) (without PARAMS.json)
    #[arg(long, value_name = "ETA")]
    eta: Option<f64>,
    /// Yield stress sigma_y, Pa (without PARAMS.json)
    #[arg(long = "sigma-y-pa", value_name = "S")]
    sigma_y_pa: Option<f64>,
    /// Friction coefficient mu_0
    #[arg(long, value_name = "MU")]
    mu0: Option<f64>,
    /// Tangential restitution beta_0 (Walton)
    #[arg(long, value_name = "B", requires = "mu0")]
    beta0: Option<f64>,
    /// End of contact (without PARAMS.json; the file says which rule was fitted)
    #[arg(long = "contact-end", value_parser = parse_rule)]
    contact_end: Option<ContactEnd>,
    /// Normal impact speeds of the scene, m/s: LO,HI
    #[arg(long = "v-range", value_name = "LO,HI", value_parser = parse_range)]
    v_range: Option<SpeedRange>,
    /// How speeds are distributed over the range, for the best constant e and eta
    #[arg(long, value_enum, default_value = "log")]
    weight: WeightArg,
    /// Largest acceptable deviation from the fitted e(v): names the simplest law within it
    #[arg(long, value_name = "T")]
    tolerance: Option<f64>,
    /// Speeds in the e(v) table
    #[arg(long = "table-points", value_name = "N", default_value_t = 41)]
    table_points: usize,
    /// Which law the LAMMPS files carry when the model has no exact LAMMPS form
    #[arg(long, value_enum, default_value = "auto")]
    law: LawArg,
    /// Speeds of the collisions in collide.in, m/s (default: the range's ends and middle, or 0.5,2,10)
    #[arg(long, value_name = "V", value_delimiter = ',', num_args = 1..)]
    speeds: Vec<f64>,
    /// Directory for the files (all or none)
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Run LAMMPS (lmp) on the exported collide.in and compare e with the toolkit
    #[arg(long)]
    verify: bool,
}

fn parse_rule(s: &str) -> Result<ContactEnd, String> {
    s.parse()
}

fn parse_range(s: &str) -> Result<SpeedRange, String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 2 {
        return Err(format!("'{s}' is not LO,HI"));
    }
    let num = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| format!("'{t}' is not a number"))
    };
    SpeedRange::new(num(parts[0])?, num(parts[1])?).map_err(|e| e.to_string())
}

/// The law from PARAMS.json or from the flags (a flag that the file also gives is an error).
fn fitted_law(a: &Args) -> Result<FittedLaw, String> {
    if let Some(path) = &a.params {
        for (given, flag) in [
            (a.eta.is_some(), "--eta"),
            (a.sigma_y_pa.is_some(), "--sigma-y-pa"),
            (a.contact_end.is_some(), "--contact-end"),
            (
                a.material.material.is_some() || a.material.youngs_pa.is_some(),
                "--material",
            ),
        ] {
            if given {
                return Err(format!(
                    "{flag} comes from {} (give either the file or the flags)",
                    path.display()
                ));
            }
        }
        return FittedLaw::from_params(JsonSource::Path(path), a.model.as_deref())
            .map_err(|e| e.to_string());
    }
    FittedLaw::given(
        ArgStyle::Flags,
        a.material.resolve()?,
        a.model.as_deref(),
        a.eta,
        a.sigma_y_pa,
        a.contact_end,
    )
    .map_err(|e| e.to_string())
}

pub fn run(a: Args) -> CliResult {
    let law = fitted_law(&a)?;
    let (friction, friction_warnings) = job::friction(
        ArgStyle::Flags,
        a.walton.as_deref().map(JsonSource::Path),
        a.mu0,
        a.beta0,
    )
    .map_err(|e| e.to_string())?;
    for w in law.warnings.iter().chain(&friction_warnings) {
        warn(w);
    }
    let options = ExportOptions {
        style: ArgStyle::Flags,
        engine: match a.engine {
            Engine::Lammps => EngineKind::Lammps,
            Engine::ConstantE => EngineKind::ConstantE,
            Engine::Table => EngineKind::Table,
        },
        law: match a.law {
            LawArg::Auto => LawChoice::Auto,
            LawArg::Viscoelastic => LawChoice::Viscoelastic,
            LawArg::ConstantE => LawChoice::ConstantE,
        },
        d_mm: a.d_mm,
        wall: a.wall,
        v_range: a.v_range,
        weight: match a.weight {
            WeightArg::Log => Weight::LogUniform,
            WeightArg::Uniform => Weight::Uniform,
        },
        tolerance: a.tolerance,
        table_points: a.table_points,
        speeds_m_s: a.speeds,
        friction,
        verify: a.verify,
        files: a.out.is_some(),
    };
    let done = match job::export(&law, &options) {
        Ok(done) => done,
        Err(ExportError::Verify { message, table }) => {
            eprint!("{table}");
            return Err(message);
        }
        Err(e) => return Err(e.to_string()),
    };
    if let Some(dir) = &a.out {
        write_outputs(dir, &done.outputs)?;
    }
    let mut text = done.report.clone();
    if a.out.is_none()
        && let Some(lf) = &done.in_restitution
    {
        text += &format!("\n--- in.restitution ---\n{lf}");
    }
    if let Some(table) = &done.verify_table {
        text += "\nLAMMPS round trip (lmp on collide.in, N steps per shortest contact):\n";
        text += table;
    }
    emit(&text)
}

fn write_outputs(dir: &Path, outputs: &[(String, Vec<u8>)]) -> Result<(), String> {
    std::fs::create_dir_all(dir)
        .map_err(|e| format!("--out {}: cannot create the directory: {e}", dir.display()))?;
    let files: Vec<(PathBuf, Vec<u8>)> = outputs
        .iter()
        .map(|(n, b)| (dir.join(n), b.clone()))
        .collect();
    write_all_atomic(&files)
        .map_err(|e| format!("--out {}: cannot write the results: {e}", dir.display()))
}
