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
//! the preferred one unless --model); WALTON.json what `restitution walton fit --out` writes
//! (mu_0, beta_0). `--d-mm` sets the scene's sphere sizes (one engine type each; default: the fit
//! data's), `--wall` adds sphere-wall contacts. Engines:
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

use super::{CliResult, MaterialArgs};
use restitution::contact::Material;
use restitution::data::export::lammps::Friction;
use restitution::data::export::plan::{self, EngineKind, LawChoice};
use restitution::data::export::{files, read_params_json, read_walton_json, report, run};
use restitution::data::{fmt_num, write_all_atomic};
use restitution::dem::law::FittedCurve;
use restitution::dem::range::{SpeedRange, Weight};
use restitution::dem::scene::Scene;
use restitution::dem::translate::{Request, Translation};
use restitution::fit::models::ModelKind;
use restitution::models::viscoelastic::ContactEnd;
use restitution::plot::export::laws_svg;
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
    /// The exact law for vm, otherwise whichever of the other two is closer to the fit
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
pub struct Args {
    /// params.json written by `restitution fit --out`
    #[arg(value_name = "PARAMS.json")]
    params: Option<PathBuf>,
    #[arg(long, value_enum)]
    engine: Engine,
    /// Model to export (default: the file's preferred model)
    #[arg(long, value_name = "NAME")]
    model: Option<String>,
    /// walton.json written by `restitution walton fit --out` (mu_0, beta_0)
    #[arg(long, value_name = "WALTON.json", conflicts_with_all = ["mu0", "beta0"])]
    walton: Option<PathBuf>,
    #[command(flatten)]
    material: MaterialArgs,
    /// Sphere diameters of the scene, mm (one engine atom type each)
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

/// Largest |LAMMPS e - toolkit e| that --verify accepts (see tests/lammps.rs for why).
const VERIFY_TOLERANCE: f64 = 1e-6;
/// Steps per shortest contact of the --verify ladder.
const LADDER: [u32; 3] = [4000, 8000, 16000];

fn check_positive(flag: &str, x: f64) -> Result<f64, String> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(format!(
            "{flag} {}: expected a finite number > 0",
            fmt_num(x)
        ))
    }
}

/// The fitted curve, material and default sizes from the file or the flags.
fn curve_and_material(a: &Args) -> Result<(FittedCurve, Material, Vec<f64>, String), String> {
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
        let file = read_params_json(path).map_err(|e| e.to_string())?;
        let (curve, entry) = file.curve(a.model.as_deref()).map_err(|e| e.to_string())?;
        if entry.converged == Some(false) {
            eprintln!(
                "restitution: warning: {}: the fit of model {} did not converge",
                file.path, entry.model
            );
        }
        return Ok((
            curve,
            file.material,
            file.diameters_mm.clone(),
            format!("{} (model {})", file.path, entry.model),
        ));
    }
    let material = a.material.resolve()?;
    let kind = match (&a.model, a.eta, a.sigma_y_pa) {
        (Some(m), _, _) => m.parse::<ModelKind>()?,
        (None, Some(_), None) => ModelKind::Vm,
        (None, None, Some(_)) => ModelKind::Pm,
        (None, Some(_), Some(_)) => {
            return Err("both --eta and --sigma-y-pa: choose --model min or product".into());
        }
        (None, None, None) => {
            return Err("give PARAMS.json, or the law as flags (--eta and/or --sigma-y-pa)".into());
        }
    };
    let mut params = Vec::new();
    for spec in kind.params() {
        let x = match spec.key {
            "eta" => a.eta.ok_or("--eta is needed for this model")?,
            "sigma_y" => a
                .sigma_y_pa
                .ok_or("--sigma-y-pa is needed for this model")?,
            _ => {
                return Err(format!(
                    "model {kind} can only be exported from PARAMS.json"
                ));
            }
        };
        params.push(check_positive(
            &format!("--{}", spec.key.replace('_', "-")),
            x,
        )?);
    }
    let curve = FittedCurve::new(kind, params, a.contact_end.unwrap_or(ContactEnd::Overlap))
        .map_err(|e| e.to_string())?;
    Ok((curve, material, Vec::new(), "command-line flags".into()))
}

pub fn run(a: Args) -> CliResult {
    let (curve, material, file_sizes_mm, source) = curve_and_material(&a)?;
    let sizes_mm = if a.d_mm.is_empty() {
        file_sizes_mm
    } else {
        a.d_mm.clone()
    };
    if sizes_mm.is_empty() {
        return Err("give the scene's sphere sizes with --d-mm".into());
    }
    for &d in &sizes_mm {
        check_positive("--d-mm", d)?;
        if !(1e-3..=1e4).contains(&d) {
            return Err(format!(
                "--d-mm {}: expected a diameter from 0.001 to 10000 mm",
                fmt_num(d)
            ));
        }
    }
    if let Some(t) = a.tolerance {
        check_positive("--tolerance", t)?;
        if a.v_range.is_none() {
            return Err("--tolerance needs --v-range LO,HI".into());
        }
    }
    if !(2..=100_000).contains(&a.table_points) {
        return Err(format!(
            "--table-points {}: expected 2 to 100000",
            a.table_points
        ));
    }
    if a.v_range.is_none() && curve.kind != ModelKind::Vm {
        return Err(format!(
            "model {} has no exact engine form: give the scene's speeds with --v-range LO,HI",
            curve.kind
        ));
    }
    if a.engine != Engine::Lammps && a.v_range.is_none() {
        return Err("this engine needs the scene's speeds: --v-range LO,HI".into());
    }
    if a.verify && a.engine == Engine::Table {
        return Err("--verify checks LAMMPS files: use --engine lammps or constant-e".into());
    }
    let friction = match (&a.walton, a.mu0) {
        (Some(w), _) => {
            let wp = read_walton_json(w).map_err(|e| e.to_string())?;
            if !wp.converged {
                eprintln!(
                    "restitution: warning: {}: the Walton fit did not converge",
                    w.display()
                );
            }
            Some(Friction {
                mu0: wp.mu0,
                beta0: Some(wp.beta0),
                source: format!("from {}", w.display()),
            })
        }
        (None, Some(mu)) => {
            if !(mu.is_finite() && mu >= 0.0) {
                return Err(format!(
                    "--mu0 {}: expected a finite number >= 0",
                    fmt_num(mu)
                ));
            }
            if let Some(b) = a.beta0
                && !(-1.0..=1.0).contains(&b)
            {
                return Err(format!(
                    "--beta0 {}: expected a number in [-1, 1]",
                    fmt_num(b)
                ));
            }
            Some(Friction {
                mu0: mu,
                beta0: a.beta0,
                source: "from --mu0".into(),
            })
        }
        (None, None) => None,
    };
    let scene = Scene::new(
        material,
        sizes_mm.iter().map(|d| d * 1e-3).collect(),
        a.wall,
    )
    .map_err(|e| format!("--d-mm: {e}"))?;
    let tr = Translation::new(Request {
        curve,
        scene,
        range: a.v_range,
        weight: match a.weight {
            WeightArg::Log => Weight::LogUniform,
            WeightArg::Uniform => Weight::Uniform,
        },
        table_points: a.table_points,
        tolerance: a.tolerance,
    })
    .map_err(|e| format!("{source}: {e}"))?;

    let speeds: Vec<f64> = if a.speeds.is_empty() {
        plan::default_speeds(a.v_range)
    } else {
        for &v in &a.speeds {
            check_positive("--speeds", v)?;
        }
        a.speeds.clone()
    };
    let engine = match a.engine {
        Engine::Lammps => EngineKind::Lammps,
        Engine::ConstantE => EngineKind::ConstantE,
        Engine::Table => EngineKind::Table,
    };
    let law = match a.law {
        LawArg::Auto => LawChoice::Auto,
        LawArg::Viscoelastic => LawChoice::Viscoelastic,
        LawArg::ConstantE => LawChoice::ConstantE,
    };
    let plan = plan::plan(&tr, engine, law, friction.as_ref(), &speeds, &source)?;
    let mut outputs = plan.outputs.clone();
    if tr.request.range.is_some() {
        let title = format!("Exported laws for {source}");
        outputs.push(("laws.svg".into(), laws_svg(&tr, &title)?.into_bytes()));
    }
    // A failed verification writes nothing (it runs in a private temporary directory).
    let verify_rows = match (&plan.lammps_files, a.verify) {
        (Some(lf), true) => {
            let rows = run::verify_files(&tr, lf, &LADDER)?;
            let worst = rows
                .iter()
                .map(|r| r.difference().abs())
                .fold(0.0, f64::max);
            if worst.is_nan() || worst > VERIFY_TOLERANCE {
                eprint!("{}", files::verify_table(&rows, VERIFY_TOLERANCE));
                return Err(format!(
                    "LAMMPS's e differs from the toolkit's by {worst:.3e} > {VERIFY_TOLERANCE:e}; nothing written"
                ));
            }
            Some(rows)
        }
        _ => None,
    };
    let mut names: Vec<String> = outputs.iter().map(|(n, _)| n.clone()).collect();
    if a.out.is_some() {
        names.push("export.json".into());
    }
    let summary = plan.summary(
        &tr,
        &source,
        friction.as_ref(),
        names,
        verify_rows.as_deref(),
    );
    if let Some(dir) = &a.out {
        outputs.push((
            "export.json".into(),
            files::export_json(&summary).into_bytes(),
        ));
        write_outputs(dir, &outputs)?;
    }
    print!("{}", report::report(&summary));
    if a.out.is_none()
        && let Some(lf) = &plan.lammps_files
    {
        print!("\n--- in.restitution ---\n{}", lf.in_restitution);
    }
    if let Some(rows) = &verify_rows {
        println!("\nLAMMPS round trip (lmp on collide.in, N steps per shortest contact):");
        print!("{}", files::verify_table(rows, VERIFY_TOLERANCE));
    }
    Ok(())
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
