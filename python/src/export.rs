//! `export`: the call of `restitution export` (src/cli/export.rs): the law from a params.json
//! (a file or a fit's document) or from numbers, the friction, then the library's one export job
//! (`data::export::job::export`), so the files are the command line's byte for byte.

use crate::{Failure, Outcome, run_detached};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use restitution::data::export::job::{
    self, ArgStyle, ExportError, ExportOptions, FittedLaw, JsonSource,
};
use restitution::data::export::plan::{EngineKind, LawChoice};
use restitution::data::{fmt_num, write_all_atomic};
use restitution::dem::range::{SpeedRange, Weight};
use restitution::models::viscoelastic::ContactEnd;
use std::path::PathBuf;

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(export, m)?)?;
    m.add("VERIFY_TOLERANCE", job::VERIFY_TOLERANCE)?;
    Ok(())
}

/// A JSON document argument: a path, or text with the name messages give it.
enum Doc {
    Path(PathBuf),
    Text { name: String, text: String },
}

impl Doc {
    fn new(
        what: &str,
        path: Option<PathBuf>,
        name: Option<String>,
        text: Option<String>,
    ) -> Outcome<Option<Doc>> {
        match (path, text) {
            (None, None) => Ok(None),
            (Some(p), None) => Ok(Some(Doc::Path(p))),
            (None, Some(text)) => Ok(Some(Doc::Text {
                name: name.unwrap_or_else(|| format!("<{what}>")),
                text,
            })),
            _ => Err(Failure::Input(format!(
                "{what}: give a path or a document, not both"
            ))),
        }
    }

    fn source(&self) -> JsonSource<'_> {
        match self {
            Doc::Path(p) => JsonSource::Path(p),
            Doc::Text { name, text } => JsonSource::Text { name, text },
        }
    }

    fn shown(&self) -> String {
        match self {
            Doc::Path(p) => p.display().to_string(),
            Doc::Text { name, .. } => name.clone(),
        }
    }
}

fn input(e: ExportError) -> Failure {
    match e {
        ExportError::Input(m) => Failure::Input(m),
        ExportError::Data(d) => Failure::Data(d),
        // A parameter or a scene outside the library's domain is the caller's input; a
        // translation that failed on a valid law is numerical.
        e @ ExportError::Law {
            source:
                restitution::Error::InvalidParameter { .. } | restitution::Error::OutOfRange { .. },
            ..
        } => Failure::Input(e.to_string()),
        e @ ExportError::Law { .. } => Failure::Numerical(e.to_string()),
        // The law asks for files the engine cannot take (an overdamped pair, contacts too
        // different for one run): the caller's input.
        e @ ExportError::Files { .. } => Failure::Input(e.to_string()),
        // LAMMPS missing or its output unreadable: not the caller's input.
        ExportError::Engine(e) => Failure::Numerical(e.to_string()),
        // LAMMPS ran and disagrees: a numerical failure, not bad input.
        ExportError::Verify { message, .. } => Failure::Numerical(message),
        // The curves of laws.svg could not be evaluated or drawn: not the caller's input.
        ExportError::Plot(e) => Failure::Numerical(e.to_string()),
    }
}

fn choice<T: Copy>(arg: &str, value: &str, options: &[(&str, T)]) -> Outcome<T> {
    options
        .iter()
        .find(|(n, _)| *n == value)
        .map(|(_, t)| *t)
        .ok_or_else(|| {
            let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
            Failure::Input(format!(
                "{arg} '{value}': expected one of {}",
                names.join(", ")
            ))
        })
}

/// What the extension returns: export.json's text, the report, every file, the warnings.
struct Done {
    json: String,
    report: String,
    files: Vec<(String, Vec<u8>)>,
    warnings: Vec<String>,
    verify_table: Option<String>,
}

/// A fitted law as simulation-engine input, as `restitution export` makes it.
#[pyfunction]
#[pyo3(signature = (
    engine, params_path=None, params_name=None, params_text=None, model=None, walton_path=None,
    walton_name=None, walton_text=None, mu0=None, beta0=None, material=None, youngs_pa=None,
    poisson=None, density_kg_m3=None, d_mm=None, wall=false, eta=None, sigma_y_pa=None,
    contact_end=None, v_range=None, weight="log", tolerance=None, table_points=41, law="auto",
    speeds_m_s=None, out=None, verify=false
))]
#[allow(clippy::too_many_arguments)]
fn export<'py>(
    py: Python<'py>,
    engine: &str,
    params_path: Option<PathBuf>,
    params_name: Option<String>,
    params_text: Option<String>,
    model: Option<String>,
    walton_path: Option<PathBuf>,
    walton_name: Option<String>,
    walton_text: Option<String>,
    mu0: Option<f64>,
    beta0: Option<f64>,
    material: Option<String>,
    youngs_pa: Option<f64>,
    poisson: Option<f64>,
    density_kg_m3: Option<f64>,
    d_mm: Option<Vec<f64>>,
    wall: bool,
    eta: Option<f64>,
    sigma_y_pa: Option<f64>,
    contact_end: Option<String>,
    v_range: Option<(f64, f64)>,
    weight: &str,
    tolerance: Option<f64>,
    table_points: usize,
    law: &str,
    speeds_m_s: Option<Vec<f64>>,
    out: Option<PathBuf>,
    verify: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let engine = choice(
        "engine",
        engine,
        &[
            ("lammps", EngineKind::Lammps),
            ("constant-e", EngineKind::ConstantE),
            ("table", EngineKind::Table),
        ],
    );
    let law_choice = choice(
        "law",
        law,
        &[
            ("auto", LawChoice::Auto),
            ("viscoelastic", LawChoice::Viscoelastic),
            ("constant-e", LawChoice::ConstantE),
        ],
    );
    let weight = choice(
        "weight",
        weight,
        &[("log", Weight::LogUniform), ("uniform", Weight::Uniform)],
    );
    let done = run_detached(py, move || -> Outcome<Done> {
        let (engine, law_choice, weight) = (engine?, law_choice?, weight?);
        let params = Doc::new("params", params_path, params_name, params_text)?;
        let walton = Doc::new("walton", walton_path, walton_name, walton_text)?;
        let contact_end = contact_end
            .map(|c| {
                c.parse::<ContactEnd>()
                    .map_err(|e| Failure::Input(format!("contact_end: {e}")))
            })
            .transpose()?;
        let fitted = match &params {
            Some(doc) => {
                for (given, arg) in [
                    (eta.is_some(), "eta"),
                    (sigma_y_pa.is_some(), "sigma_y_pa"),
                    (contact_end.is_some(), "contact_end"),
                    (material.is_some() || youngs_pa.is_some(), "material"),
                ] {
                    if given {
                        return Err(Failure::Input(format!(
                            "{arg} comes from {} (give either params or the numbers)",
                            doc.shown()
                        )));
                    }
                }
                FittedLaw::from_params(doc.source(), model.as_deref()).map_err(input)?
            }
            None => {
                let m = crate::material(material.as_deref(), youngs_pa, poisson, density_kg_m3)?;
                FittedLaw::given(
                    ArgStyle::Keywords,
                    m,
                    model.as_deref(),
                    eta,
                    sigma_y_pa,
                    contact_end,
                )
                .map_err(input)?
            }
        };
        let (friction, friction_warnings) = job::friction(
            ArgStyle::Keywords,
            walton.as_ref().map(Doc::source),
            mu0,
            beta0,
        )
        .map_err(input)?;
        let v_range = v_range
            .map(|(lo, hi)| {
                SpeedRange::new(lo, hi).map_err(|e| {
                    Failure::Input(format!("v_range ({}, {}): {e}", fmt_num(lo), fmt_num(hi)))
                })
            })
            .transpose()?;
        let options = ExportOptions {
            style: ArgStyle::Keywords,
            engine,
            law: law_choice,
            d_mm: d_mm.unwrap_or_default(),
            wall,
            v_range,
            weight,
            tolerance,
            table_points,
            speeds_m_s: speeds_m_s.unwrap_or_default(),
            friction,
            verify,
            files: out.is_some(),
        };
        let done = job::export(&fitted, &options).map_err(input)?;
        if let Some(dir) = &out {
            std::fs::create_dir_all(dir).map_err(|e| {
                Failure::Input(format!(
                    "out {}: cannot create the directory: {e}",
                    dir.display()
                ))
            })?;
            let files: Vec<(PathBuf, Vec<u8>)> = done
                .outputs
                .iter()
                .map(|(n, b)| (dir.join(n), b.clone()))
                .collect();
            write_all_atomic(&files).map_err(|e| {
                Failure::Input(format!(
                    "out {}: cannot write the results: {e}",
                    dir.display()
                ))
            })?;
        }
        let mut warnings = fitted.warnings;
        warnings.extend(friction_warnings);
        Ok(Done {
            json: done.json,
            report: done.report,
            files: done.outputs,
            warnings,
            verify_table: done.verify_table,
        })
    })?;
    let d = PyDict::new(py);
    d.set_item("json", done.json)?;
    d.set_item("report", done.report)?;
    let files = PyDict::new(py);
    for (name, bytes) in &done.files {
        files.set_item(name, PyBytes::new(py, bytes))?;
    }
    d.set_item("files", files)?;
    d.set_item("warnings", done.warnings)?;
    d.set_item("verify_table", done.verify_table)?;
    Ok(d)
}
