//! The command-line front end: one module per subcommand, each with its usage at the top, a small
//! arguments struct and a `run` that parses, calls the library and prints.

use restitution::contact::{Material, PRESETS};

pub mod bench;
pub mod fit;
pub mod frames_out;
pub mod kinematics;
pub mod predict;
pub mod simulate;
pub mod track;
pub mod walton;

/// What a subcommand returns: `Err` is one line for stderr (the binary prefixes it and exits 1).
pub type CliResult = Result<(), String>;

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
            (Some(y), Some(nu), Some(rho)) => Material::new(y, nu, rho).map_err(|e| e.to_string()),
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

/// A number for human eyes: 10 significant digits, exponent form when very small or large.
pub fn readable(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e7).contains(&a) {
        let digits = (9 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.digits$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.9e}")
    }
}
