//! The command-line front end: one module per subcommand, each with its usage at the top, a small
//! arguments struct and a `run` that parses, calls the library and prints.

use restitution::contact::{Material, PRESETS};
use restitution::data::fmt_num;
use std::io::{self, Write};

pub mod bench;
pub mod export;
pub mod fit;
pub mod frames_out;
pub mod kinematics;
pub mod predict;
pub mod simulate;
pub mod track;
pub mod walton;

/// What a subcommand returns: `Err` is one line for stderr (the binary prefixes it and exits 1).
pub type CliResult = Result<(), String>;

/// Whether an I/O error says that the reader of our output has gone (`restitution ... | head`).
pub fn is_closed_pipe(e: &io::Error) -> bool {
    e.kind() == io::ErrorKind::BrokenPipe
}

/// Writes a subcommand's output to stdout. A closed stdout is success: whoever reads the output
/// has taken what they wanted (as `head` does), so the command stops quietly with exit 0, as Unix
/// tools do; any other write error is an error.
pub fn emit(text: &str) -> CliResult {
    let mut out = io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if is_closed_pipe(&e) => Ok(()),
        Err(e) => Err(format!("cannot write to stdout: {e}")),
    }
}

/// A warning line on stderr (`restitution: warning: ...`); a closed stderr is ignored.
pub fn warn(message: impl std::fmt::Display) {
    let _ = writeln!(io::stderr(), "restitution: warning: {message}");
}

/// `--inertia-k K` of `walton fit` and `kinematics`, checked here so that the flag is named (in
/// `kinematics` every collision was skipped for it and the error named the first collision's
/// own reason).
pub fn check_inertia_k(k: f64) -> CliResult {
    use restitution::models::walton::{INERTIA_K_EXPECTED, inertia_k_ok};
    if inertia_k_ok(k) {
        Ok(())
    } else {
        Err(format!(
            "--inertia-k {}: expected {INERTIA_K_EXPECTED}",
            restitution::data::fmt_num(k)
        ))
    }
}

/// Material flags shared by the subcommands: a preset or the three constants.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct MaterialArgs {
    /// Material preset: nylon (the paper's), steel, glass, aluminium
    #[arg(long, value_name = "NAME", conflicts_with_all = ["youngs_pa", "poisson", "density_kg_m3"])]
    pub material: Option<String>,
    /// Young's modulus Y, Pa
    #[arg(long = "youngs-pa", value_name = "Y")]
    pub youngs_pa: Option<f64>,
    /// Poisson ratio nu, in (-1, 0.5)
    #[arg(long, value_name = "NU")]
    pub poisson: Option<f64>,
    /// Density, kg/m^3
    #[arg(long = "density-kg-m3", value_name = "RHO")]
    pub density_kg_m3: Option<f64>,
}

impl MaterialArgs {
    pub fn resolve(&self) -> Result<Material, String> {
        if let Some(name) = &self.material {
            return Material::preset(name).ok_or_else(|| {
                let names: Vec<&str> = PRESETS.iter().map(|(n, _)| *n).collect();
                format!(
                    "--material '{name}' is not a preset: expected one of {}",
                    names.join(", ")
                )
            });
        }
        match (self.youngs_pa, self.poisson, self.density_kg_m3) {
            (Some(y), Some(nu), Some(rho)) => {
                for (flag, v, ok, expected) in [
                    ("--youngs-pa", y, y.is_finite() && y > 0.0, "a modulus > 0 (Pa)"),
                    (
                        "--poisson",
                        nu,
                        nu.is_finite() && nu > -1.0 && nu < 0.5,
                        "a number in (-1, 0.5)",
                    ),
                    (
                        "--density-kg-m3",
                        rho,
                        rho.is_finite() && rho > 0.0,
                        "a density > 0 (kg/m^3)",
                    ),
                ] {
                    if !ok {
                        return Err(format!("{flag} {}: expected {expected}", fmt_num(v)));
                    }
                }
                Material::new(y, nu, rho)
                    .map_err(|e| format!("--youngs-pa, --poisson, --density-kg-m3: {e}"))
            }
            _ => Err("a material is needed: --material NAME, or all of --youngs-pa, --poisson and --density-kg-m3".into()),
        }
    }
}

/// Output format of the tabular subcommands.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Format {
    #[default]
    Table,
    Csv,
    Json,
}

pub use restitution::data::readable;
