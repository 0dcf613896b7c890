//! `restitution export`'s files: reading the fit's params.json and the Walton fit's walton.json,
//! and writing engine inputs, tables and the export summary (docs/physics.md §9). The numbers
//! come from [`crate::dem`]; this module only formats and parses.
//!
//! Submodules: [`plan`] (which law and files an export gives), [`lammps`] (in.restitution,
//! collide.in), [`job`] (one export from request to files, for the command line and Python),
//! [`run`] (running `lmp` on them and comparing e), [`files`] (constant_e.csv,
//! table.csv, liggghts.in, export.json), [`report`] (the printed summary); the failures of the
//! files and of the round trip are [`FilesFailure`] and [`RunFailure`].

mod error;
pub mod files;
pub mod job;
pub mod lammps;
pub mod plan;
pub mod report;
pub mod run;

pub use error::{FilesFailure, RunFailure};

use super::{DataError, DataFailure};
use crate::contact::Material;
use crate::dem::law::FittedCurve;
use crate::fit::models::ModelKind;
use crate::models::viscoelastic::ContactEnd;
use serde_json::Value;
use std::path::Path;

/// One model of a params.json: its name, parameters (key, value when estimated, status) and
/// whether the fit converged.
#[derive(Debug, Clone, PartialEq)]
pub struct FitEntry {
    pub model: String,
    pub params: Vec<(String, Option<f64>, String)>,
    pub converged: Option<bool>,
}

/// What `restitution export` needs from the params.json written by `restitution fit --out`.
/// Unknown fields are ignored (the format grows: e.g. per-model `warnings`).
#[derive(Debug, Clone, PartialEq)]
pub struct FitParamsFile {
    pub path: String,
    pub material: Material,
    pub contact_end: ContactEnd,
    pub diameters_mm: Vec<f64>,
    /// Whether the fit data include a sphere on a wall (absent in files before the field: no).
    pub wall: bool,
    pub preferred: Option<String>,
    pub fits: Vec<FitEntry>,
}

/// e, mu_0 and beta_0 from the walton.json written by `restitution walton fit --out`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaltonParams {
    pub e: f64,
    pub mu0: f64,
    pub beta0: f64,
    pub converged: bool,
}

fn err(path: &str, kind: DataFailure, message: impl Into<String>) -> DataError {
    DataError {
        path: path.to_string(),
        line: None,
        column: None,
        kind,
        message: message.into(),
    }
}

/// Reads a JSON file; syntax errors name the line and column.
fn read_json(path: &Path) -> Result<(String, Value), DataError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| err(&shown, DataFailure::Io, format!("cannot read: {e}")))?;
    parse_json(&shown, &text)
}

/// Parses JSON text that `name` stands for in messages.
fn parse_json(name: &str, text: &str) -> Result<(String, Value), DataError> {
    let v: Value = serde_json::from_str(text).map_err(|e| DataError {
        path: name.to_string(),
        line: Some(e.line()),
        column: None,
        kind: DataFailure::Format,
        message: format!("not valid JSON (column {}): {e}", e.column()),
    })?;
    Ok((name.to_string(), v))
}

/// The value at a dotted path of keys, or an error naming the path.
fn at<'a>(path: &str, v: &'a Value, keys: &str) -> Result<&'a Value, DataError> {
    let mut cur = v;
    for k in keys.split('.') {
        cur = cur.get(k).ok_or_else(|| {
            err(
                path,
                DataFailure::Schema,
                format!("field '{keys}' is missing"),
            )
        })?;
    }
    Ok(cur)
}

/// A finite number at a dotted path.
fn number(path: &str, v: &Value, keys: &str) -> Result<f64, DataError> {
    let x = at(path, v, keys)?;
    match x.as_f64() {
        Some(n) if n.is_finite() => Ok(n),
        _ => Err(err(
            path,
            DataFailure::Value,
            format!("field '{keys}' is {x}, expected a finite number"),
        )),
    }
}

/// Reads a params.json (see [`FitParamsFile`]).
pub fn read_params_json(path: &Path) -> Result<FitParamsFile, DataError> {
    let (p, v) = read_json(path)?;
    params_from_value(p, v)
}

/// A params.json document given as text (`name` stands for it in messages), as
/// [`read_params_json`] reads it from a file.
pub fn parse_params_json(name: &str, text: &str) -> Result<FitParamsFile, DataError> {
    let (p, v) = parse_json(name, text)?;
    params_from_value(p, v)
}

fn params_from_value(p: String, v: Value) -> Result<FitParamsFile, DataError> {
    let p = p.as_str();
    let material = Material::new(
        number(p, &v, "material.youngs_pa")?,
        number(p, &v, "material.poisson")?,
        number(p, &v, "material.density_kg_m3")?,
    )
    .map_err(|e| err(p, DataFailure::Value, format!("field 'material': {e}")))?;
    let rule_text = at(p, &v, "contact_end")?
        .as_str()
        .ok_or_else(|| err(p, DataFailure::Value, "field 'contact_end' is not a string"))?;
    let contact_end: ContactEnd = rule_text
        .parse()
        .map_err(|e: String| err(p, DataFailure::Value, format!("field 'contact_end': {e}")))?;
    let diameters_mm = match v.get("data").and_then(|d| d.get("diameters_mm")) {
        None => Vec::new(),
        Some(Value::Array(a)) => a
            .iter()
            .map(|x| {
                x.as_f64()
                    .filter(|d| d.is_finite() && *d > 0.0)
                    .ok_or_else(|| {
                        err(
                            p,
                            DataFailure::Value,
                            format!("field 'data.diameters_mm' holds {x}, expected diameters > 0"),
                        )
                    })
            })
            .collect::<Result<_, _>>()?,
        Some(x) => {
            return Err(err(
                p,
                DataFailure::Value,
                format!("field 'data.diameters_mm' is {x}, expected a list"),
            ));
        }
    };
    let wall = match v.get("data").and_then(|d| d.get("wall")) {
        None => false,
        Some(Value::Bool(b)) => *b,
        Some(x) => {
            return Err(err(
                p,
                DataFailure::Value,
                format!("field 'data.wall' is {x}, expected true or false"),
            ));
        }
    };
    let preferred = v
        .get("preferred")
        .and_then(|x| x.as_str())
        .map(str::to_string);
    let fits_v = at(p, &v, "fits")?
        .as_array()
        .ok_or_else(|| err(p, DataFailure::Value, "field 'fits' is not a list"))?;
    let mut fits = Vec::new();
    for (k, f) in fits_v.iter().enumerate() {
        let model = f
            .get("model")
            .and_then(|m| m.as_str())
            .ok_or_else(|| {
                err(
                    p,
                    DataFailure::Schema,
                    format!("fits[{k}]: field 'model' is missing"),
                )
            })?
            .to_string();
        let params_v = f.get("params").and_then(|m| m.as_object()).ok_or_else(|| {
            err(
                p,
                DataFailure::Schema,
                format!("fits[{k}] ({model}): field 'params' is missing"),
            )
        })?;
        let mut params = Vec::new();
        for (key, pv) in params_v {
            let value = match pv.get("value") {
                None | Some(Value::Null) => None,
                Some(x) => Some(x.as_f64().filter(|n| n.is_finite()).ok_or_else(|| {
                    err(
                        p,
                        DataFailure::Value,
                        format!("fits[{k}] ({model}): '{key}.value' is {x}, expected a number"),
                    )
                })?),
            };
            let status = pv
                .get("status")
                .and_then(|s| s.as_str())
                .unwrap_or("estimate")
                .to_string();
            params.push((key.clone(), value, status));
        }
        fits.push(FitEntry {
            model,
            params,
            converged: f.get("converged").and_then(|c| c.as_bool()),
        });
    }
    if fits.is_empty() {
        return Err(err(
            p,
            DataFailure::Schema,
            "field 'fits' is empty: no fitted model to export",
        ));
    }
    Ok(FitParamsFile {
        path: p.to_string(),
        material,
        contact_end,
        diameters_mm,
        wall,
        preferred,
        fits,
    })
}

impl FitParamsFile {
    /// The fitted curve of `model` (when `None`: the file's preferred model, or its only fit,
    /// as `fit --model min --out` writes, which has no comparison to prefer one; the report's
    /// first line names the model exported). Errors: an unknown or absent model, a parameter
    /// missing or only bounded (no value to export).
    pub fn curve(&self, model: Option<&str>) -> Result<(FittedCurve, &FitEntry), DataError> {
        let name = match (model, &self.preferred, &self.fits[..]) {
            (Some(m), ..) => m.to_string(),
            (None, Some(p), _) => p.clone(),
            (None, None, [only]) => only.model.clone(),
            (None, None, fits) => {
                let have: Vec<&str> = fits.iter().map(|f| f.model.as_str()).collect();
                return Err(err(
                    &self.path,
                    DataFailure::Schema,
                    format!(
                        "no 'preferred' model in the file (it has: {}): choose one with --model",
                        have.join(", ")
                    ),
                ));
            }
        };
        let kind: ModelKind = name
            .parse()
            .map_err(|e: String| err(&self.path, DataFailure::Value, e))?;
        let entry = self.fits.iter().find(|f| f.model == name).ok_or_else(|| {
            let have: Vec<&str> = self.fits.iter().map(|f| f.model.as_str()).collect();
            err(
                &self.path,
                DataFailure::Schema,
                format!(
                    "model '{name}' was not fitted in this file (it has: {})",
                    have.join(", ")
                ),
            )
        })?;
        let mut values = Vec::new();
        for spec in kind.params() {
            let (_, value, status) = entry
                .params
                .iter()
                .find(|(k, _, _)| k == spec.key)
                .ok_or_else(|| {
                    err(
                        &self.path,
                        DataFailure::Schema,
                        format!("model '{name}': parameter '{}' is missing", spec.key),
                    )
                })?;
            let x = value.ok_or_else(|| {
                err(
                    &self.path,
                    DataFailure::Value,
                    format!(
                        "model '{name}': parameter '{}' has no value (status {status}: the data \
                         do not determine it); export another model{}, or give the law as numbers \
                         without the fit (its model, parameters and material)",
                        spec.key,
                        self.alternatives(kind, spec.key, status)
                    ),
                )
            })?;
            values.push(x);
        }
        let curve = FittedCurve::new(kind, values, self.contact_end).map_err(|e| {
            err(
                &self.path,
                DataFailure::Value,
                format!("model '{name}': {e}"),
            )
        })?;
        Ok((curve, entry))
    }
}

impl FitParamsFile {
    /// What to export instead of `kind`, whose `key` has no value: " (every parameter has a
    /// value in: vm, pm; the fit tends to 'vm' as sigma_y grows without bound)". The file's
    /// converged fits that export can take, in its order, and the model `kind` tends to where
    /// that is one of them; empty where neither applies.
    fn alternatives(&self, kind: ModelKind, key: &str, status: &str) -> String {
        let ok: Vec<&str> = self
            .fits
            .iter()
            .filter(|f| f.converged != Some(false) && f.params.iter().all(|p| p.1.is_some()))
            .map(|f| f.model.as_str())
            .collect();
        let mut hints = Vec::new();
        if !ok.is_empty() {
            hints.push(format!("every parameter has a value in: {}", ok.join(", ")));
        }
        if let Some(m) = limit_model(kind, key, status).filter(|m| ok.contains(m)) {
            hints.push(format!(
                "the fit tends to '{m}' as {key} grows without bound"
            ));
        }
        if hints.is_empty() {
            String::new()
        } else {
            format!(" ({})", hints.join("; "))
        }
    }
}

/// The one-parameter model that `kind` becomes as parameter `key`, bounded only from below
/// (`status` lower_bound), grows without bound: with sigma_y -> inf no point yields (e_pm = 1),
/// so `min` and `product` are `vm`; with eta -> inf e_vm -> 0, which leaves nothing to export.
fn limit_model(kind: ModelKind, key: &str, status: &str) -> Option<&'static str> {
    let two = matches!(kind, ModelKind::Min | ModelKind::Product);
    (two && key == "sigma_y" && status == "lower_bound").then_some("vm")
}

/// Reads e, beta_0 and mu_0 from a walton.json (see [`WaltonParams`]).
pub fn read_walton_json(path: &Path) -> Result<WaltonParams, DataError> {
    let (p, v) = read_json(path)?;
    walton_from_value(p, v)
}

/// A walton.json document given as text (`name` stands for it in messages).
pub fn parse_walton_json(name: &str, text: &str) -> Result<WaltonParams, DataError> {
    let (p, v) = parse_json(name, text)?;
    walton_from_value(p, v)
}

fn walton_from_value(p: String, v: Value) -> Result<WaltonParams, DataError> {
    let p = p.as_str();
    let e = number(p, &v, "e.value")?;
    let mu0 = number(p, &v, "mu0.value")?;
    let beta0 = number(p, &v, "beta0.value")?;
    if mu0 < 0.0 {
        return Err(err(
            p,
            DataFailure::Value,
            format!("field 'mu0.value' is {mu0}, expected >= 0"),
        ));
    }
    if !(-1.0..=1.0).contains(&beta0) {
        return Err(err(
            p,
            DataFailure::Value,
            format!("field 'beta0.value' is {beta0}, expected a number in [-1, 1]"),
        ));
    }
    let converged = v
        .get("converged")
        .and_then(|c| c.as_bool())
        .unwrap_or(false);
    Ok(WaltonParams {
        e,
        mu0,
        beta0,
        converged,
    })
}
