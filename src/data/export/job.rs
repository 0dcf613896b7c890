//! One export from request to files: the fitted law (from a params.json or given), the friction,
//! the checks of the request, the scene, the translation, the plan, the optional LAMMPS round
//! trip and the summary. The command line (`restitution export`) and the Python package
//! (`restitution.export`) both call [`export`], so they give the same files and numbers; they
//! differ only in how an argument is named in a message ([`ArgStyle`]).

use super::files::{self, verify_table};
use super::lammps::Friction;
use super::plan::{self, EngineKind, LawChoice};
use super::run::{self, VerifyRow};
use super::{
    FilesFailure, FitParamsFile, RunFailure, WaltonParams, parse_params_json, parse_walton_json,
    read_params_json, read_walton_json, report,
};
use crate::contact::Material;
pub use crate::data::ArgStyle;
use crate::data::fmt_num;
use crate::dem::law::FittedCurve;
use crate::dem::range::{SpeedRange, Weight};
use crate::dem::scene::Scene;
use crate::dem::translate::{Request, Translation};
use crate::fit::models::ModelKind;
use crate::models::viscoelastic::ContactEnd;
use std::path::Path;

/// Largest |LAMMPS e - toolkit e| that the round trip accepts: the extrapolated engine e agrees
/// with the toolkit's to ~1e-9 (tests/lammps.rs), so 1e-6 leaves room for the ladder's residual
/// without letting a wrong law through (a wrong damping moves e by > 1e-3).
pub const VERIFY_TOLERANCE: f64 = 1e-6;
/// Steps per shortest contact of the round trip's ladder (first-order error in e: Richardson).
pub const LADDER: [u32; 3] = [4000, 8000, 16000];

/// Why an export did not happen. Nothing is written in either case.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// A bad argument or combination of arguments: one line.
    #[error("{0}")]
    Input(String),
    /// The library refused the law or the scene (a parameter outside its domain, a translation
    /// that failed); `context` names the flag or the law it came from.
    #[error("{}", with_context(context.as_deref(), source))]
    Law {
        context: Option<String>,
        source: crate::Error,
    },
    /// An input document (params.json, walton.json) at fault: its name, and where it can be.
    #[error(transparent)]
    Data(#[from] super::super::DataError),
    /// The engine files could not be built for the law (`law`: the law as the user gave it).
    #[error("{law}: {kind}")]
    Files { law: String, kind: FilesFailure },
    /// The engine could not be run for the round trip, or its output could not be read.
    #[error(transparent)]
    Engine(#[from] RunFailure),
    /// LAMMPS ran but its e differs from the toolkit's; `table` shows every collision.
    #[error("{message}")]
    Verify { message: String, table: String },
    /// laws.svg could not be drawn.
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}

fn with_context(context: Option<&str>, source: &crate::Error) -> String {
    match context {
        Some(c) => format!("{c}: {source}"),
        None => source.to_string(),
    }
}

impl From<String> for ExportError {
    fn from(s: String) -> Self {
        ExportError::Input(s)
    }
}

/// A JSON document (params.json, walton.json): a file, or text held in memory with the name
/// messages give it.
#[derive(Debug, Clone, Copy)]
pub enum JsonSource<'a> {
    Path(&'a Path),
    Text { name: &'a str, text: &'a str },
}

impl JsonSource<'_> {
    fn params(self) -> Result<FitParamsFile, ExportError> {
        Ok(match self {
            JsonSource::Path(p) => read_params_json(p)?,
            JsonSource::Text { name, text } => parse_params_json(name, text)?,
        })
    }

    fn walton(self) -> Result<(WaltonParams, String), ExportError> {
        Ok(match self {
            JsonSource::Path(p) => (read_walton_json(p)?, p.display().to_string()),
            JsonSource::Text { name, text } => (parse_walton_json(name, text)?, name.to_string()),
        })
    }
}

/// The fitted law to export, with the material and sphere sizes it was fitted for.
#[derive(Debug, Clone)]
pub struct FittedLaw {
    pub curve: FittedCurve,
    pub material: Material,
    /// The fit data's diameters, mm (empty when the law was given as numbers).
    pub diameters_mm: Vec<f64>,
    /// Whether the fit data include a sphere on a wall.
    pub wall: bool,
    /// Where the law came from, for the report and the files' comments (worded alike for every
    /// front end, so the files do not depend on which one ran).
    pub source: String,
    /// The law as the user gave it, for error messages: the file, or the arguments by name.
    pub shown: String,
    /// What the user should know about it (a fit that did not converge).
    pub warnings: Vec<String>,
}

impl FittedLaw {
    /// The law of a params.json written by `restitution fit --out`: the preferred model, or
    /// `model`.
    pub fn from_params(params: JsonSource, model: Option<&str>) -> Result<FittedLaw, ExportError> {
        let file = params.params()?;
        let (curve, entry) = file.curve(model)?;
        let mut warnings = Vec::new();
        if entry.converged == Some(false) {
            warnings.push(format!(
                "{}: the fit of model {} did not converge",
                file.path, entry.model
            ));
        }
        Ok(FittedLaw {
            curve,
            material: file.material,
            diameters_mm: file.diameters_mm.clone(),
            wall: file.wall,
            source: format!("{} (model {})", file.path, entry.model),
            shown: format!("{} (model {})", file.path, entry.model),
            warnings,
        })
    }

    /// A law given as numbers: `model` (default: vm with eta alone, pm with sigma_y alone) with
    /// its parameters.
    pub fn given(
        style: ArgStyle,
        material: Material,
        model: Option<&str>,
        eta: Option<f64>,
        sigma_y_pa: Option<f64>,
        contact_end: Option<ContactEnd>,
    ) -> Result<FittedLaw, ExportError> {
        let (n_eta, n_sigma) = (style.name("eta"), style.name("sigma_y_pa"));
        let kind = match (model, eta, sigma_y_pa) {
            (Some(m), _, _) => m.parse::<ModelKind>()?,
            (None, Some(_), None) => ModelKind::Vm,
            (None, None, Some(_)) => ModelKind::Pm,
            (None, Some(_), Some(_)) => {
                return Err(format!(
                    "both {n_eta} and {n_sigma}: choose {} min or product",
                    style.name("model")
                )
                .into());
            }
            (None, None, None) => {
                return Err(format!(
                    "give PARAMS.json, or the law as numbers ({n_eta} and/or {n_sigma})"
                )
                .into());
            }
        };
        let mut params = Vec::new();
        for spec in kind.params() {
            let (x, name) = match spec.key {
                "eta" => (eta, &n_eta),
                "sigma_y" => (sigma_y_pa, &n_sigma),
                _ => {
                    return Err(
                        format!("model {kind} can only be exported from PARAMS.json").into(),
                    );
                }
            };
            let x = x.ok_or_else(|| format!("{name} is needed for this model"))?;
            params.push(positive(name, x)?);
        }
        let curve = FittedCurve::new(kind, params, contact_end.unwrap_or(ContactEnd::Overlap))
            .map_err(|source| ExportError::Law {
                context: None,
                source,
            })?;
        Ok(FittedLaw {
            curve,
            material,
            diameters_mm: Vec::new(),
            wall: false,
            source: "the numbers given".into(),
            shown: [(n_eta.as_str(), eta), (n_sigma.as_str(), sigma_y_pa)]
                .iter()
                .filter_map(|(n, v)| v.map(|v| format!("{n} {}", fmt_num(v))))
                .collect::<Vec<_>>()
                .join(", "),
            warnings: Vec::new(),
        })
    }
}

/// The friction of the exported scene, from a walton.json or given, and its warnings.
pub fn friction(
    style: ArgStyle,
    walton: Option<JsonSource>,
    mu0: Option<f64>,
    beta0: Option<f64>,
) -> Result<(Option<Friction>, Vec<String>), ExportError> {
    match (walton, mu0) {
        (Some(_), Some(_)) => Err(format!(
            "{} and {}: give one",
            style.name("walton"),
            style.name("mu0")
        )
        .into()),
        (Some(w), None) => {
            let (wp, w) = w.walton()?;
            let mut warnings = Vec::new();
            if !wp.converged {
                warnings.push(format!("{w}: the Walton fit did not converge"));
            }
            Ok((
                Some(Friction {
                    mu0: wp.mu0,
                    beta0: Some(wp.beta0),
                    source: format!("from {w}"),
                }),
                warnings,
            ))
        }
        (None, Some(mu)) => {
            if !(mu.is_finite() && mu >= 0.0) {
                return Err(format!(
                    "{} {}: expected a finite number >= 0",
                    style.name("mu0"),
                    fmt_num(mu)
                )
                .into());
            }
            if let Some(b) = beta0
                && !(-1.0..=1.0).contains(&b)
            {
                return Err(format!(
                    "{} {}: expected a number in [-1, 1]",
                    style.name("beta0"),
                    fmt_num(b)
                )
                .into());
            }
            Ok((
                Some(Friction {
                    mu0: mu,
                    beta0,
                    source: "given".into(),
                }),
                Vec::new(),
            ))
        }
        (None, None) => match beta0 {
            Some(_) => Err(format!("{} needs {}", style.name("beta0"), style.name("mu0")).into()),
            None => Ok((None, Vec::new())),
        },
    }
}

/// What the export is for, besides the law.
#[derive(Debug, Clone)]
pub struct ExportOptions {
    pub style: ArgStyle,
    pub engine: EngineKind,
    pub law: LawChoice,
    /// The scene's sphere sizes, mm (one engine type each); empty: the law's.
    pub d_mm: Vec<f64>,
    pub wall: bool,
    pub v_range: Option<SpeedRange>,
    pub weight: Weight,
    pub tolerance: Option<f64>,
    pub table_points: usize,
    /// Speeds of collide.in, m/s; empty: [`plan::default_speeds`].
    pub speeds_m_s: Vec<f64>,
    pub friction: Option<Friction>,
    /// Run `lmp` on collide.in ([`LADDER`]) and fail above [`VERIFY_TOLERANCE`].
    pub verify: bool,
    /// The files will be written, so export.json is one of them (and lists itself).
    pub files: bool,
}

/// A finished export: every file (name, bytes), the summary document (export.json's text), the
/// printed report and the round trip's table.
#[derive(Debug, Clone)]
pub struct Exported {
    pub outputs: Vec<(String, Vec<u8>)>,
    pub json: String,
    pub report: String,
    /// in.restitution's text, when the engine is LAMMPS (the command line prints it without
    /// --out).
    pub in_restitution: Option<String>,
    pub verify: Option<Vec<VerifyRow>>,
    /// The round trip's table, as printed.
    pub verify_table: Option<String>,
}

fn positive(name: &str, x: f64) -> Result<f64, ExportError> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(ExportError::Input(format!(
            "{name} {}: expected a finite number > 0",
            fmt_num(x)
        )))
    }
}

/// Checks the request, translates the law for the scene and builds every file. With
/// `verify`, LAMMPS (`lmp`) runs in a private temporary directory.
pub fn export(law: &FittedLaw, o: &ExportOptions) -> Result<Exported, ExportError> {
    let name = |k: &str| o.style.name(k);
    let sizes_mm = if o.d_mm.is_empty() {
        law.diameters_mm.clone()
    } else {
        o.d_mm.clone()
    };
    if sizes_mm.is_empty() {
        return Err(format!("give the scene's sphere sizes with {}", name("d_mm")).into());
    }
    for &d in &sizes_mm {
        positive(&name("d_mm"), d)?;
        if !(1e-3..=1e4).contains(&d) {
            return Err(format!(
                "{} {}: expected a diameter from 0.001 to 10000 mm",
                name("d_mm"),
                fmt_num(d)
            )
            .into());
        }
    }
    if let Some(t) = o.tolerance {
        // A deviation of e, which lies in [0, 1], is at most 1: a larger tolerance is a typo.
        if !(t > 0.0 && t <= 1.0) {
            return Err(format!(
                "{} {}: expected a deviation of e in (0, 1]",
                name("tolerance"),
                fmt_num(t)
            )
            .into());
        }
        if o.v_range.is_none() {
            return Err(format!("{} needs {} LO,HI", name("tolerance"), name("v_range")).into());
        }
    }
    if !(2..=100_000).contains(&o.table_points) {
        return Err(format!(
            "{} {}: expected 2 to 100000",
            name("table_points"),
            o.table_points
        )
        .into());
    }
    if o.v_range.is_none() && law.curve.kind != ModelKind::Vm {
        return Err(format!(
            "model {} has no exact engine form: give the scene's speeds with {} LO,HI",
            law.curve.kind,
            name("v_range")
        )
        .into());
    }
    if o.engine != EngineKind::Lammps && o.v_range.is_none() {
        return Err(format!(
            "this engine needs the scene's speeds: {} LO,HI",
            name("v_range")
        )
        .into());
    }
    if o.verify && o.engine == EngineKind::Table {
        return Err(format!(
            "{} checks LAMMPS files: use {} lammps or constant-e",
            name("verify"),
            name("engine")
        )
        .into());
    }
    // Without sizes given, the scene is the one measured: its spheres, and its wall if any.
    let wall = o.wall || (o.d_mm.is_empty() && law.wall);
    let scene = Scene::new(
        law.material,
        sizes_mm.iter().map(|d| d * 1e-3).collect(),
        wall,
    )
    .map_err(|source| ExportError::Law {
        context: Some(name("d_mm")),
        source,
    })?;
    let tr = Translation::new(Request {
        curve: law.curve.clone(),
        scene,
        range: o.v_range,
        weight: o.weight,
        table_points: o.table_points,
        tolerance: o.tolerance,
    })
    .map_err(|source| ExportError::Law {
        context: Some(law.shown.clone()),
        source,
    })?;
    let speeds: Vec<f64> = if o.speeds_m_s.is_empty() {
        plan::default_speeds(o.v_range)
    } else {
        for &v in &o.speeds_m_s {
            positive(&name("speeds"), v)?;
        }
        o.speeds_m_s.clone()
    };
    let plan = plan::plan(
        &tr,
        o.engine,
        o.law,
        o.friction.as_ref(),
        &speeds,
        &law.source,
    )
    .map_err(|kind| ExportError::Files {
        law: law.shown.clone(),
        kind,
    })?;
    let mut outputs = plan.outputs.clone();
    #[cfg(feature = "plot")]
    if tr.request.range.is_some() {
        let title = format!("Exported laws for {}", law.source);
        outputs.push((
            "laws.svg".into(),
            crate::plot::export::laws_svg(&tr, &title)?.into_bytes(),
        ));
    }
    let verify_rows = match (&plan.lammps_files, o.verify) {
        (Some(lf), true) => {
            let rows = run::verify_files(&tr, lf, &LADDER)?;
            let worst = rows
                .iter()
                .map(|r| r.difference().abs())
                .fold(0.0, f64::max);
            if worst.is_nan() || worst > VERIFY_TOLERANCE {
                return Err(ExportError::Verify {
                    message: format!(
                        "LAMMPS's e differs from the toolkit's by {worst:.3e} > {VERIFY_TOLERANCE:e}; nothing written"
                    ),
                    table: verify_table(&rows, VERIFY_TOLERANCE),
                });
            }
            Some(rows)
        }
        _ => None,
    };
    let mut names: Vec<String> = outputs.iter().map(|(n, _)| n.clone()).collect();
    if o.files {
        names.push("export.json".into());
    }
    let summary = plan.summary(
        &tr,
        &law.source,
        o.friction.as_ref(),
        names,
        verify_rows.as_deref(),
    );
    let json = files::export_json(&summary);
    let report = report::report(&summary);
    if o.files {
        outputs.push(("export.json".into(), json.clone().into_bytes()));
    }
    let verify_table = verify_rows
        .as_deref()
        .map(|rows| verify_table(rows, VERIFY_TOLERANCE));
    Ok(Exported {
        outputs,
        json,
        report,
        in_restitution: plan
            .lammps_files
            .as_ref()
            .map(|lf| lf.in_restitution.clone()),
        verify: verify_rows,
        verify_table,
    })
}
