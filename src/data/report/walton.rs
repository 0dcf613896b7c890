//! The documents of `restitution walton fit` (and of Python's `walton_fit`): the table, the
//! parameters CSV, the per-collision CSV, JSON and Markdown, built once for both front ends.

use crate::data::{CsvOut, fixed, fmt_num};
use crate::fit::walton::{self as wfit, Bound, Estimate, WaltonFit};
use crate::models::walton::Target;
use serde_json::{Value, json};

/// Everything the renderers need besides the fit.
pub struct Context {
    pub path: String,
    pub diameters_mm: Vec<f64>,
    pub walls: usize,
    pub lines: Vec<usize>,
    pub ids: Vec<Option<String>>,
    pub material: crate::contact::Material,
    pub command: String,
}

impl Context {
    /// The context of a fit of `records` read from `path`: the distinct diameters (mm, to
    /// 1e-9 relative) and the number of wall collisions, each record's line and id.
    pub fn new(
        path: &str,
        records: &[wfit::CollisionRecord],
        material: crate::contact::Material,
        command: String,
    ) -> Context {
        let mut diameters_mm: Vec<f64> = Vec::new();
        let mut walls = 0;
        for r in records {
            let mut add = |d_m: f64| {
                let d = d_m * 1e3;
                if !diameters_mm.iter().any(|x| (x - d).abs() <= 1e-9 * d) {
                    diameters_mm.push(d);
                }
            };
            add(r.pre.sphere.d_m);
            match r.pre.target {
                Target::Sphere(b) => add(b.d_m),
                Target::Wall { .. } => walls += 1,
            }
        }
        diameters_mm.sort_by(f64::total_cmp);
        Context {
            path: path.to_string(),
            diameters_mm,
            walls,
            lines: records.iter().map(|r| r.line).collect(),
            ids: records.iter().map(|r| r.id.clone()).collect(),
            material,
            command,
        }
    }
}

/// A value with as many decimals as its error's two significant digits call for.
fn pm(value: f64, err: Option<f64>) -> (String, String, usize) {
    match err {
        Some(se) if se.is_finite() && se > 0.0 => {
            let decimals = (1 - se.log10().floor() as i32).clamp(0, 12) as usize;
            (fixed(value, decimals), fixed(se, decimals), decimals)
        }
        _ => (crate::data::readable(value), "-".into(), 4),
    }
}

fn interval(ci: Option<(f64, f64)>, decimals: usize) -> String {
    match ci {
        Some((lo, hi)) => format!("[{}, {}]", fixed(lo, decimals), fixed(hi, decimals)),
        None => "-".into(),
    }
}

/// Rows of the parameter table: name, estimate.
fn param_rows(fit: &WaltonFit) -> Vec<(&'static str, Estimate)> {
    vec![
        (
            "e",
            Estimate {
                value: fit.e.value,
                stderr: Some(fit.e.stderr),
                ci95: fit.e.ci95,
                bound: None,
            },
        ),
        ("beta0", fit.beta0),
        ("mu0", fit.mu0),
        ("slope", fit.slope),
        ("psi_kink", fit.kink_psi),
    ]
}

pub fn render_table(fit: &WaltonFit, ctx: &Context) -> String {
    let mut s = format!(
        "Walton fit of {}: {} collisions ({} oblique, {} head-on), K = {}, weights = {}\n\n",
        ctx.path,
        fit.n,
        fit.n - fit.n_head_on,
        fit.n_head_on,
        fmt_num(fit.options.inertia_k),
        fit.options.weights.as_str()
    );
    s += &format!(
        "{:<10} {:>12} {:>10}  {}\n",
        "parameter", "value", "stderr", "95% interval (bootstrap)"
    );
    for (name, est) in param_rows(fit) {
        let (v, se, dec) = pm(est.value, est.stderr);
        let v = if est.bound.is_some() {
            format!(">= {v}")
        } else {
            v
        };
        s += &format!(
            "{:<10} {:>12} {:>10}  {}\n",
            name,
            v,
            se,
            interval(est.ci95, dec)
        );
    }
    s += &format!(
        "\ne over the collisions: spread (sd) {}, range {} .. {}\n",
        fixed(fit.e.spread, 3),
        fixed(fit.e.min, 3),
        fixed(fit.e.max, 3)
    );
    if fit.converged {
        s += &format!(
            "critical angle of incidence gamma_0 = {:.1} deg (cot gamma_0 = -psi*)\n",
            fit.gamma0_deg()
        );
    }
    s += &format!(
        "classes: {} sliding, {} rolling, {} head-on\n",
        fit.n_sliding, fit.n_rolling, fit.n_head_on
    );
    if let Some((m, se)) = fit.impulse_ratio_sliding {
        let (v, se, _) = pm(m, Some(se));
        s += &format!(
            "cross-check: impulse ratio |dP_t|/|dP_n| of the sliding collisions = {v} +- {se} (mu0 by Eq. 6)\n"
        );
    }
    if let Some(rms) = fit.com_dv_rms_m_s {
        s += &format!(
            "momentum check: rms change of the centre-of-mass velocity {} m/s (0 for exact data)\n",
            fixed(rms, 3)
        );
    }
    s += &format!(
        "residuals: rms {} in beta, {} degrees of freedom; bootstrap {} resamples (seed {}, {} left out)\n",
        fixed(fit.residual_rms, 3),
        fit.dof,
        fit.bootstrap.resamples,
        fit.bootstrap.seed,
        fit.bootstrap.failed
    );
    s += &format!("status: {}\n", fit.message);
    s
}

pub fn render_params_csv(fit: &WaltonFit) -> String {
    let mut out = CsvOut::new();
    out.record([
        "parameter",
        "value",
        "stderr",
        "ci95_low",
        "ci95_high",
        "bound",
    ]);
    let opt = |x: Option<f64>| x.map(fmt_num).unwrap_or_default();
    for (name, est) in param_rows(fit) {
        out.record([
            name.to_string(),
            fmt_num(est.value),
            opt(est.stderr),
            opt(est.ci95.map(|c| c.0)),
            opt(est.ci95.map(|c| c.1)),
            match est.bound {
                Some(Bound::Lower) => "lower",
                None => "",
            }
            .to_string(),
        ]);
    }
    out.into_string()
}

pub fn render_collisions_csv(fit: &WaltonFit, ctx: &Context) -> String {
    let mut out = CsvOut::new();
    out.record([
        "line",
        "collision",
        "e",
        "beta",
        "psi",
        "v_n_m_s",
        "v_s_m_s",
        "impulse_ratio",
        "class",
        "residual",
    ]);
    let opt = |x: Option<f64>| x.map(fmt_num).unwrap_or_default();
    for (i, c) in fit.collisions.iter().enumerate() {
        let m = &c.measured;
        out.record([
            ctx.lines[i].to_string(),
            ctx.ids[i].clone().unwrap_or_default(),
            fmt_num(m.e),
            opt(m.beta),
            // Head-on: psi is infinite and the class says so.
            if m.psi.is_finite() {
                fmt_num(m.psi)
            } else {
                String::new()
            },
            fmt_num(m.v_n_m_s),
            fmt_num(m.v_s_m_s),
            fmt_num(m.impulse_ratio),
            class(c).to_string(),
            opt(c.residual),
        ]);
    }
    out.into_string()
}

fn class(c: &wfit::Classified) -> &'static str {
    c.kind.map(|k| k.as_str()).unwrap_or("head_on")
}

fn estimate_json(est: &Estimate) -> Value {
    let mut v = json!({
        "value": est.value,
        "stderr": est.stderr,
        "ci95": est.ci95.map(|(a, b)| vec![a, b]),
    });
    if let Some(Bound::Lower) = est.bound {
        v["bound"] = json!("lower");
    }
    v
}

/// One collision of the JSON report, serialised as it is (a `json!` value per collision, ten
/// keys each, built and dropped a tree of 100 000 maps: half a second of a 100 000-collision
/// `walton fit`). The keys in this order; a non-finite number is `null`, as in `json!`.
#[derive(serde::Serialize)]
struct CollisionJson<'a> {
    line: usize,
    collision: &'a Option<String>,
    e: f64,
    beta: Option<f64>,
    psi: Option<f64>,
    v_n_m_s: f64,
    v_s_m_s: f64,
    impulse_ratio: f64,
    class: &'static str,
    residual: Option<f64>,
}

/// The report with its collisions last, after the other keys of `head`.
#[derive(serde::Serialize)]
struct ReportJson<'a> {
    #[serde(flatten)]
    head: &'a Value,
    collisions: Vec<CollisionJson<'a>>,
}

pub fn to_json(fit: &WaltonFit, ctx: &Context) -> String {
    let collisions: Vec<CollisionJson> = fit
        .collisions
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let m = &c.measured;
            CollisionJson {
                line: ctx.lines[i],
                collision: &ctx.ids[i],
                e: m.e,
                beta: m.beta,
                psi: m.psi.is_finite().then_some(m.psi),
                v_n_m_s: m.v_n_m_s,
                v_s_m_s: m.v_s_m_s,
                impulse_ratio: m.impulse_ratio,
                class: class(c),
                residual: c.residual,
            }
        })
        .collect();
    let v = json!({
        "data": {
            "path": ctx.path,
            "n": fit.n,
            "n_oblique": fit.n - fit.n_head_on,
            "diameters_mm": ctx.diameters_mm,
            "walls": ctx.walls,
        },
        "material": {
            "youngs_pa": ctx.material.youngs_pa,
            "poisson": ctx.material.poisson,
            "density_kg_m3": ctx.material.density_kg_m3,
        },
        "inertia_k": fit.options.inertia_k,
        "weights": fit.options.weights.as_str(),
        "e": {
            "value": fit.e.value,
            "stderr": fit.e.stderr,
            "ci95": fit.e.ci95.map(|(a, b)| vec![a, b]),
            "spread": fit.e.spread,
            "min": fit.e.min,
            "max": fit.e.max,
        },
        "beta0": estimate_json(&fit.beta0),
        "mu0": estimate_json(&fit.mu0),
        "slope": estimate_json(&fit.slope),
        "psi_kink": estimate_json(&fit.kink_psi),
        "gamma0_deg": fit.converged.then(|| fit.gamma0_deg()),
        "n": fit.n,
        "classes": {
            "sliding": fit.n_sliding,
            "rolling": fit.n_rolling,
            "head_on": fit.n_head_on,
        },
        "impulse_ratio_sliding": fit.impulse_ratio_sliding.map(|(m, se)| json!({
            "value": m, "stderr": se, "n": fit.n_sliding,
        })),
        "com_dv_rms_m_s": fit.com_dv_rms_m_s,
        "residual_rms": fit.residual_rms,
        "dof": fit.dof,
        "bootstrap": {
            "resamples": fit.bootstrap.resamples,
            "seed": fit.bootstrap.seed,
            "failed": fit.bootstrap.failed,
        },
        "converged": fit.converged,
        "message": fit.message,
    });
    let report = ReportJson {
        head: &v,
        collisions,
    };
    serde_json::to_string_pretty(&report).expect("JSON values serialise") + "\n"
}

pub fn render_markdown(fit: &WaltonFit, ctx: &Context) -> String {
    let mut s = String::from("# Walton collision properties (Fig. 6 fit)\n\n");
    s += &format!("Made by: `{}`\n\n", ctx.command);
    s += &format!(
        "Data: `{}`, {} collisions ({} oblique, {} head-on), diameters {} mm{}; K = {}; weights: {}.\n\n",
        ctx.path,
        fit.n,
        fit.n - fit.n_head_on,
        fit.n_head_on,
        ctx.diameters_mm
            .iter()
            .map(|d| fmt_num(*d))
            .collect::<Vec<_>>()
            .join(", "),
        if ctx.walls > 0 {
            format!(", {} on a wall", ctx.walls)
        } else {
            String::new()
        },
        fmt_num(fit.options.inertia_k),
        fit.options.weights.as_str()
    );
    s += "| parameter | value | stderr | 95% interval (bootstrap) |\n|---|---|---|---|\n";
    for (name, est) in param_rows(fit) {
        let (v, se, dec) = pm(est.value, est.stderr);
        let v = if est.bound.is_some() {
            format!(">= {v}")
        } else {
            v
        };
        s += &format!("| {name} | {v} | {se} | {} |\n", interval(est.ci95, dec));
    }
    s += &format!(
        "\n- e over the collisions: spread (sd) {}, range {} to {}.\n",
        fixed(fit.e.spread, 3),
        fixed(fit.e.min, 3),
        fixed(fit.e.max, 3)
    );
    s += &format!(
        "- Classes: {} sliding, {} rolling, {} head-on.\n",
        fit.n_sliding, fit.n_rolling, fit.n_head_on
    );
    if fit.converged {
        s += &format!(
            "- Kink psi* = {:.3}: critical angle of incidence gamma_0 = {:.1} degrees.\n",
            fit.kink_psi.value,
            fit.gamma0_deg()
        );
    }
    if let Some((m, se)) = fit.impulse_ratio_sliding {
        let (v, se, _) = pm(m, Some(se));
        s += &format!(
            "- Cross-check: the impulse ratio of the sliding collisions is {v} +- {se} (mu0 by Eq. 6).\n"
        );
    }
    if let Some(rms) = fit.com_dv_rms_m_s {
        s += &format!(
            "- Momentum check: rms change of the centre-of-mass velocity {} m/s (0 for exact data).\n",
            fixed(rms, 3)
        );
    }
    s += &format!(
        "- Residual rms {} in beta, {} degrees of freedom; bootstrap {} resamples, seed {}, {} left out.\n",
        fixed(fit.residual_rms, 3),
        fit.dof,
        fit.bootstrap.resamples,
        fit.bootstrap.seed,
        fit.bootstrap.failed
    );
    s += &format!("- Status: {}.\n\n", fit.message);
    s += "![beta against psi with the fitted Walton hinge](fig6.svg)\n\n";
    s += "Per-collision values: `walton_collisions.csv`. Model: beta = min(-1 + s psi, beta0), \
          s = mu0 (1 + 1/K)(1 + e) (Eq. 7); psi = -v_n/|v_s|.\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_collision_without_a_number_writes_null_and_the_collisions_come_last() {
        // As `json!` did: a non-finite number is null, never NaN or inf in the JSON.
        let id = Some("a, \"b\"".to_string());
        let row = CollisionJson {
            line: 7,
            collision: &id,
            e: f64::NAN,
            beta: Some(f64::INFINITY),
            psi: None,
            v_n_m_s: 1.5,
            v_s_m_s: 0.0,
            impulse_ratio: f64::NEG_INFINITY,
            class: "head_on",
            residual: Some(0.25),
        };
        let head = json!({"n": 1, "message": "ok"});
        let text = serde_json::to_string(&ReportJson {
            head: &head,
            collisions: vec![row],
        })
        .unwrap();
        assert_eq!(
            text,
            "{\"n\":1,\"message\":\"ok\",\"collisions\":[{\"line\":7,\"collision\":\"a, \\\"b\\\"\",\
             \"e\":null,\"beta\":null,\"psi\":null,\"v_n_m_s\":1.5,\"v_s_m_s\":0.0,\
             \"impulse_ratio\":null,\"class\":\"head_on\",\"residual\":0.25}]}"
        );
    }
}
