//! `restitution predict`: e(v) from the viscoelastic (vm) or plastic (pm) model.
//!
//! ```text
//! restitution predict --model vm|pm [--contact-end overlap|force]
//!     (--material NAME | --youngs-pa Y --poisson NU --density-kg-m3 RHO)
//!     --d-mm D [--d2-mm D2 | --wall]
//!     (--eta ETA | --sigma-y-pa SIGMA)
//!     --v-m-s V1,V2,...
//!   or, without material and geometry:
//!     --kappa K1,K2,...   (vm, dimensionless damping)
//!     --u U1,U2,...       (pm, V/V_Y)
//!     [--method master|dop853|dopri5] [--tol T] [--format table|csv|json]
//! ```
//! Columns: the input (`v_m_s`, `kappa` or `u`), then `e`, `one_minus_e`, then per model
//! `kappa, contact_time_s, max_overlap_m, max_force_n` (vm) or `u, v_yield_m_s` (pm); with
//! `--kappa` the dimensionless `tau_contact, x_max, force_max`. e is a number for every finite
//! kappa and u; the contact time and extrema come from the ODE, which covers kappa up to its
//! checked range (1e4 overlap rule, 1e8 force rule): beyond it those cells are empty (CSV),
//! null (JSON) or `-` (table), and a note on stderr says why.

use super::{CliResult, Format, MaterialArgs};
use restitution::contact::{Contact, Pair, Sphere};
use restitution::data::{CsvOut, fmt_num};
use restitution::models::viscoelastic::{ContactEnd, Integrator, OdeSettings, VmMethod};
use restitution::predict::{self, Table};

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// Viscoelastic: Hertz plus damping eta (Eqs. 9-10)
    Vm,
    /// Plastic: Hertz up to yield, then perfectly plastic (Eqs. 12-18)
    Pm,
}

#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodArg {
    Master,
    Dop853,
    Dopri5,
}

/// e(v) from the viscoelastic or plastic model
#[derive(clap::Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct Args {
    #[arg(long, value_enum)]
    model: Model,
    /// End of contact (vm): overlap (the paper's) or force (Schwager & Poeschel)
    #[arg(long = "contact-end", default_value = "overlap", value_parser = parse_rule)]
    contact_end: ContactEnd,
    #[command(flatten)]
    material: MaterialArgs,
    /// Diameter of the (first) sphere, mm
    #[arg(long = "d-mm", value_name = "D")]
    d_mm: Option<f64>,
    /// Diameter of a second, different sphere of the same material, mm
    #[arg(long = "d2-mm", value_name = "D2", conflicts_with = "wall")]
    d2_mm: Option<f64>,
    /// The sphere hits a flat wall of the same material
    #[arg(long)]
    wall: bool,
    /// Damping eta, kg/(s m) (vm)
    #[arg(long, value_name = "ETA")]
    eta: Option<f64>,
    /// Yield stress sigma_y, Pa (pm)
    #[arg(long = "sigma-y-pa", value_name = "SIGMA")]
    sigma_y_pa: Option<f64>,
    /// Normal impact speeds, m/s
    #[arg(long = "v-m-s", value_name = "V", value_delimiter = ',', num_args = 1..)]
    v_m_s: Vec<f64>,
    /// Dimensionless damping values (vm, no material needed)
    #[arg(long, value_name = "K", value_delimiter = ',', num_args = 1.., conflicts_with = "v_m_s")]
    kappa: Vec<f64>,
    /// Speeds in units of the yield speed, V/V_Y (pm, no material needed)
    #[arg(long, value_name = "U", value_delimiter = ',', num_args = 1.., conflicts_with_all = ["v_m_s", "kappa"])]
    u: Vec<f64>,
    /// How vm evaluates e: the master curve (table and large-kappa laws, every kappa) or an ODE integrator
    #[arg(long, value_enum, default_value = "master")]
    method: MethodArg,
    /// Tolerance of the ODE integrators (rtol = atol), in [1e-15, 1): a double cannot meet a
    /// tighter one
    #[arg(long, value_name = "T", default_value_t = OdeSettings::DEFAULT.rtol)]
    tol: f64,
    #[arg(long, value_enum, default_value = "table")]
    format: Format,
}

fn parse_rule(s: &str) -> Result<ContactEnd, String> {
    s.parse()
}

/// The one line of a library failure: the input's flag, its value and why.
fn flagged(f: predict::Failure) -> String {
    format!(
        "--{} {}: {}",
        f.input.key().replace('_', "-"),
        fmt_num(f.value),
        f.error
    )
}

pub fn run(args: Args) -> CliResult {
    OdeSettings::check_tol(args.tol)
        .map_err(|why| format!("--tol {}: {why}", fmt_num(args.tol)))?;
    let ode = match args.method {
        MethodArg::Dop853 => OdeSettings::with_integrator(Integrator::Dop853, args.tol),
        MethodArg::Dopri5 => OdeSettings::with_integrator(Integrator::Dopri5, args.tol),
        MethodArg::Master => OdeSettings::DEFAULT,
    };
    let method = match args.method {
        MethodArg::Master => VmMethod::Master,
        _ => VmMethod::Ode(ode),
    };
    let rule = args.contact_end;
    let out = match args.model {
        Model::Vm if !args.kappa.is_empty() => {
            check_all("--kappa", &args.kappa, |k| k >= 0.0, "a number >= 0")?;
            predict::vm_dimensionless(&args.kappa, rule, &method, &ode, true).map_err(flagged)?
        }
        Model::Pm if !args.u.is_empty() => {
            check_all("--u", &args.u, |u| u >= 0.0, "a number >= 0")?;
            predict::pm_dimensionless(&args.u).map_err(flagged)?
        }
        Model::Vm if !args.u.is_empty() => {
            return Err("--u is for --model pm; vm takes --kappa".into());
        }
        Model::Pm if !args.kappa.is_empty() => {
            return Err("--kappa is for --model vm; pm takes --u".into());
        }
        _ => {
            if args.v_m_s.is_empty() {
                return Err("give speeds with --v-m-s (or --kappa for vm, --u for pm)".into());
            }
            check_all("--v-m-s", &args.v_m_s, |v| v > 0.0, "a speed > 0")?;
            let contact = contact_from(&args)?;
            match args.model {
                Model::Vm => {
                    let eta = args.eta.ok_or("--model vm needs --eta (kg/(s m))")?;
                    predict::vm_dimensional(contact, eta, &args.v_m_s, rule, &method, &ode, true)
                }
                Model::Pm => {
                    let sy = args
                        .sigma_y_pa
                        .ok_or("--model pm needs --sigma-y-pa (Pa)")?;
                    predict::pm_dimensional(contact, sy, &args.v_m_s)
                }
            }
            .map_err(flagged)?
        }
    };
    for note in &out.notes {
        eprintln!("note: {note}");
    }
    print!("{}", render(&out, args.format));
    Ok(())
}

fn check_all(flag: &str, values: &[f64], ok: impl Fn(f64) -> bool, expected: &str) -> CliResult {
    match values.iter().find(|v| !(v.is_finite() && ok(**v))) {
        Some(bad) => Err(format!(
            "{flag} value {}: expected {expected}",
            fmt_num(*bad)
        )),
        None => Ok(()),
    }
}

fn contact_from(args: &Args) -> Result<Contact, String> {
    let material = args.material.resolve()?;
    let d_mm = args.d_mm.ok_or("--d-mm is needed with --v-m-s")?;
    let sphere = Sphere::new(d_mm * 1e-3, material)
        .map_err(|_| format!("--d-mm {}: expected a diameter > 0", fmt_num(d_mm)))?;
    let pair = match (args.d2_mm, args.wall) {
        (Some(d2), _) => {
            let s2 = Sphere::new(d2 * 1e-3, material)
                .map_err(|_| format!("--d2-mm {}: expected a diameter > 0", fmt_num(d2)))?;
            Pair::unequal(sphere, s2)
        }
        (None, true) => Pair::on_wall(sphere, material),
        (None, false) => Pair::identical(sphere),
    };
    let flags = match (args.d2_mm, args.wall) {
        (Some(d2), _) => format!("--d-mm {} --d2-mm {}", fmt_num(d_mm), fmt_num(d2)),
        (None, true) => format!("--d-mm {} --wall", fmt_num(d_mm)),
        (None, false) => format!("--d-mm {}", fmt_num(d_mm)),
    };
    pair.try_contact().map_err(|e| format!("{flags}: {e}"))
}

fn render(out: &Table, format: Format) -> String {
    match format {
        Format::Csv => {
            let mut csv = CsvOut::new();
            csv.record(out.columns.iter().copied());
            for row in &out.rows {
                csv.record(row.iter().map(|x| x.map_or(String::new(), fmt_num)));
            }
            csv.into_string()
        }
        Format::Json => {
            let rows: Vec<serde_json::Value> = out
                .rows
                .iter()
                .map(|row| {
                    let map: serde_json::Map<String, serde_json::Value> = out
                        .columns
                        .iter()
                        .zip(row)
                        .map(|(c, x)| (c.to_string(), serde_json::json!(x)))
                        .collect();
                    serde_json::Value::Object(map)
                })
                .collect();
            serde_json::to_string_pretty(&rows).expect("numbers serialise") + "\n"
        }
        Format::Table => {
            let cells: Vec<Vec<String>> = out
                .rows
                .iter()
                .map(|row| {
                    row.iter()
                        .map(|x| x.map_or("-".to_string(), super::readable))
                        .collect()
                })
                .collect();
            let widths: Vec<usize> = out
                .columns
                .iter()
                .enumerate()
                .map(|(j, c)| {
                    cells
                        .iter()
                        .map(|r| r[j].len())
                        .max()
                        .unwrap_or(0)
                        .max(c.len())
                })
                .collect();
            let mut s = String::new();
            let head: Vec<String> = out
                .columns
                .iter()
                .zip(&widths)
                .map(|(c, w)| format!("{c:>w$}"))
                .collect();
            s += &(head.join("  ") + "\n");
            for row in cells {
                let line: Vec<String> = row
                    .iter()
                    .zip(&widths)
                    .map(|(c, w)| format!("{c:>w$}"))
                    .collect();
                s += &(line.join("  ") + "\n");
            }
            s
        }
    }
}
