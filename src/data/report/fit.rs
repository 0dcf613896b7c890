//! Renders fits as CSV and JSON (strings only; writing files is the caller's job), every number
//! in shortest round-trip form; the human formats are in [`super::fit_text`]. Each fit carries
//! its `warnings` (what was lost: JSON list, CSV column) next to `converged`.

use crate::data::fmt_num;
use crate::fit::compare::PREFERENCE_RULE;
use crate::fit::dataset::FitData;
use crate::fit::engine::FitSet;
use crate::fit::models::{ModelKind, POWERLAW_D_REF_MM, POWERLAW_V_REF_M_S};
use crate::fit::result::{FitResult, ParamEstimate};
use crate::models::viscoelastic::{ContactEnd, VmMethod};
use serde_json::{Map, Value, json};

/// What a report says about where the numbers came from.
#[derive(Debug, Clone, Copy)]
pub struct ReportContext<'a> {
    /// The input file as the user named it.
    pub path: &'a str,
    pub data: &'a FitData,
    /// Where the errors of e came from, in words (see [`crate::data::fit_input::ErrorSource::describe`]).
    pub error_source: &'a str,
    pub rule: ContactEnd,
    pub vm_method: &'a VmMethod,
}

/// "master curve" or "ODE dop853, rtol = atol = 1e-12".
pub fn vm_method_name(method: &VmMethod) -> String {
    match method {
        VmMethod::Master => "master curve".into(),
        VmMethod::Ode(s) => format!(
            "ODE {}, rtol = {}, atol = {}",
            s.integrator.name(),
            fmt_num(s.rtol),
            fmt_num(s.atol)
        ),
    }
}

fn num(x: f64) -> Value {
    if x.is_finite() { json!(x) } else { Value::Null }
}

fn opt(x: Option<f64>) -> Value {
    x.map(num).unwrap_or(Value::Null)
}

fn param_json(p: &ParamEstimate) -> Value {
    json!({
        "value": opt(p.value),
        "stderr": opt(p.stderr),
        "stderr_abs": opt(p.stderr_abs),
        "ci95": [opt(p.ci95.0), opt(p.ci95.1)],
        "unit": p.unit,
        "status": p.status.name(),
        "best_fit": num(p.best_fit),
    })
}

fn fit_json(f: &FitResult) -> Value {
    let mut params = Map::new();
    for p in &f.params {
        params.insert(p.key.into(), param_json(p));
    }
    let mut derived = Map::new();
    for d in &f.derived {
        derived.insert(d.key.into(), opt(d.value));
        derived.insert(format!("{}_stderr", d.key), opt(d.stderr));
        derived.insert(
            format!("{}_ci95", d.key),
            json!([opt(d.ci95.0), opt(d.ci95.1)]),
        );
        derived.insert(format!("{}_status", d.key), json!(d.status.name()));
    }
    let mut corr = Map::new();
    for (i, pi) in f.params.iter().enumerate() {
        let mut row = Map::new();
        for (j, pj) in f.params.iter().enumerate() {
            row.insert(pj.key.into(), num(f.correlation[i][j]));
        }
        corr.insert(pi.key.into(), Value::Object(row));
    }
    let mut m = Map::new();
    m.insert("model".into(), json!(f.model.name()));
    m.insert("formula".into(), json!(f.model.formula()));
    if f.model == ModelKind::PowerLaw {
        m.insert(
            "constants".into(),
            json!({"d_ref_mm": POWERLAW_D_REF_MM, "v_ref_m_s": POWERLAW_V_REF_M_S}),
        );
    }
    m.insert("params".into(), Value::Object(params));
    m.insert("derived".into(), Value::Object(derived));
    m.insert("correlation".into(), Value::Object(corr));
    m.insert("chi2".into(), num(f.chi2));
    m.insert("dof".into(), json!(f.dof));
    m.insert("reduced_chi2".into(), num(f.reduced_chi2));
    m.insert("aic".into(), num(f.aic));
    m.insert("aicc".into(), opt(f.aicc));
    m.insert("bic".into(), num(f.bic));
    m.insert("weighted".into(), json!(f.weighted));
    m.insert("scale".into(), num(f.scale));
    m.insert("ci95_delta_chi2".into(), num(f.ci95_delta_chi2));
    m.insert("converged".into(), json!(f.converged));
    let g = &f.global;
    m.insert(
        "global_search".into(),
        json!({
            "certified": g.certified,
            "gap_chi2": num(g.gap_chi2),
            "tolerance_chi2": num(g.tolerance_chi2),
            "cells": g.cells,
            "polishes": g.polishes,
            "fine_cells": g.fine_cells,
        }),
    );
    m.insert("evaluations".into(), json!(f.evaluations));
    m.insert("profile_evaluations".into(), json!(f.profile_evaluations));
    m.insert("warnings".into(), json!(f.warnings));
    m.insert("notes".into(), json!(f.notes));
    Value::Object(m)
}

/// The JSON document of `restitution fit --format json` (and `params.json`).
pub fn to_json(ctx: &ReportContext, set: &FitSet) -> Value {
    let mat = ctx.data.material;
    let comparison = match &set.comparison {
        Some(c) => Value::Array(
            c.rows
                .iter()
                .map(|r| {
                    json!({
                        "model": r.model.name(), "k": r.k, "chi2": num(r.chi2),
                        "reduced_chi2": num(r.reduced_chi2), "aic": num(r.aic), "bic": num(r.bic),
                        "delta_aic": num(r.delta_aic), "akaike_weight": num(r.akaike_weight),
                        "converged": r.converged,
                    })
                })
                .collect(),
        ),
        None => Value::Null,
    };
    let preferred = set
        .comparison
        .as_ref()
        .and_then(|c| c.preferred)
        .map(|m| json!(m.name()))
        .unwrap_or(Value::Null);
    json!({
        "data": {
            "path": ctx.path,
            "n": ctx.data.len(),
            "diameters_mm": ctx.data.diameters_mm(),
            "wall": ctx.data.on_wall(),
            "errors": ctx.error_source,
        },
        "material": {
            "youngs_pa": mat.youngs_pa,
            "poisson": mat.poisson,
            "density_kg_m3": mat.density_kg_m3,
        },
        "contact_end": ctx.rule.name(),
        "vm_method": vm_method_name(ctx.vm_method),
        "fits": set.fits.iter().map(fit_json).collect::<Vec<_>>(),
        "comparison": comparison,
        "preferred": preferred,
        "preferred_rule": PREFERENCE_RULE,
        "unranked": set.comparison.as_ref().and_then(|c| c.unranked.clone()),
        "skipped_models": set.skipped.iter().map(|k| k.name()).collect::<Vec<_>>(),
    })
}

/// The header of `params.csv`.
pub const CSV_HEADER: [&str; 19] = [
    "model",
    "parameter",
    "unit",
    "status",
    "value",
    "stderr",
    "stderr_abs",
    "ci95_low",
    "ci95_high",
    "best_fit",
    "chi2",
    "dof",
    "reduced_chi2",
    "aic",
    "bic",
    "delta_aic",
    "akaike_weight",
    "converged",
    "warnings",
];

/// `params.csv`: one row per model and parameter (derived ones too), full precision; the fit's
/// warnings joined by "; " in the last column (empty for a clean fit). Writing CSV into memory
/// cannot fail: the writer's only errors are I/O (none into a `Vec`) and records of unequal
/// length (each has the header's 19 by its type), and Rust strings in give UTF-8 out.
pub fn to_csv(_ctx: &ReportContext, set: &FitSet) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let o = |x: Option<f64>| x.filter(|v| v.is_finite()).map(fmt_num).unwrap_or_default();
    let mut rows: Vec<[String; 19]> = Vec::new();
    for (i, f) in set.fits.iter().enumerate() {
        let row = set.comparison.as_ref().map(|c| &c.rows[i]);
        for p in f.params.iter().chain(&f.derived) {
            rows.push([
                f.model.name().to_string(),
                p.key.into(),
                p.unit.into(),
                p.status.name().into(),
                o(p.value),
                o(p.stderr),
                o(p.stderr_abs),
                o(p.ci95.0),
                o(p.ci95.1),
                o(Some(p.best_fit)),
                o(Some(f.chi2)),
                f.dof.to_string(),
                o(Some(f.reduced_chi2)),
                o(Some(f.aic)),
                o(Some(f.bic)),
                o(row.map(|r| r.delta_aic)),
                o(row.map(|r| r.akaike_weight)),
                f.converged.to_string(),
                f.warnings.join("; "),
            ]);
        }
    }
    const IN_MEMORY: &str = "writing CSV into memory cannot fail";
    w.write_record(CSV_HEADER).expect(IN_MEMORY);
    for r in &rows {
        w.write_record(r).expect(IN_MEMORY);
    }
    String::from_utf8(w.into_inner().expect(IN_MEMORY)).expect(IN_MEMORY)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::fit::{FitOptions, Observation, fit_all};

    #[test]
    fn csv_quotes_and_carries_warnings() {
        // A warning with a comma and a quote must survive a CSV round trip as one cell.
        let m = Material::preset("nylon").unwrap();
        let obs: Vec<Observation> = (0..6)
            .map(|k| Observation {
                d_mm: 12.7,
                d2_mm: None,
                v_n_m_s: 0.5 + k as f64,
                e: 0.95 - 0.002 * k as f64,
                e_err: Some(0.01),
            })
            .collect();
        let data = FitData::new(m, obs).unwrap();
        let mut set = fit_all(&data, &[ModelKind::Vm], &FitOptions::default()).unwrap();
        set.fits[0].warnings = vec!["a, \"b\"".into(), "c".into()];
        let ctx = ReportContext {
            path: "x.csv",
            data: &data,
            error_source: "e_err",
            rule: ContactEnd::Overlap,
            vm_method: &VmMethod::Master,
        };
        let text = to_csv(&ctx, &set);
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let head: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
        assert_eq!(head, CSV_HEADER);
        let first = r.records().next().unwrap().unwrap();
        assert_eq!(&first[18], "a, \"b\"; c");
        assert_eq!(&first[0], "vm");
    }
}
