//! The tables, LIGGGHTS lines, JSON summary and printed report of `restitution export`.

use super::FilesFailure;
use super::lammps::{Friction, LammpsLaw};
use super::run::VerifyRow;
use crate::data::fmt_num;
use crate::dem::translate::{ConstantEInputs, Translation};
use serde_json::{Value, json};
use std::fmt::Write as _;

/// `x` with `digits` significant digits for people (machine files use [`fmt_num`]).
pub fn sig(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let mag = x.abs().log10().floor() as i32;
    if (-4..6).contains(&mag) {
        let dec = (digits as i32 - 1 - mag).max(0) as usize;
        format!("{x:.dec$}")
    } else {
        format!("{x:.*e}", digits - 1)
    }
}

fn opt_cell(x: Option<f64>) -> String {
    x.map(fmt_num).unwrap_or_default()
}

fn d_mm(x: Option<f64>) -> String {
    x.map(|d| fmt_num(d * 1e3)).unwrap_or_else(|| "inf".into())
}

/// Writing CSV into memory cannot fail: the writer's only errors are I/O (none into a `Vec`) and
/// records of unequal length (each has the header's by construction); the fields are Rust
/// strings, so the bytes are UTF-8.
const IN_MEMORY: &str = "writing CSV into memory cannot fail";

fn csv_text(w: csv::Writer<Vec<u8>>) -> String {
    String::from_utf8(w.into_inner().expect(IN_MEMORY)).expect(IN_MEMORY)
}

/// constant_e.csv: per pair the best constant e, its deviations, and the engine inputs that
/// produce it. Empty cells: the engine cannot be asked for that e (see the column's note in the
/// README).
pub fn constant_e_csv(
    tr: &Translation,
    inputs: &[ConstantEInputs],
) -> Result<String, FilesFailure> {
    let constant = tr.constant.as_ref().ok_or(FilesFailure::NeedsSpeedRange(
        "constant e needs a speed range",
    ))?;
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "pair",
        "d1_mm",
        "d2_mm",
        "e_mean",
        "max_dev_mean",
        "e_minimax",
        "max_dev_minimax",
        "e_at_lo",
        "e_at_hi",
        "tsuji_alpha",
        "lammps_tsuji_cor",
        "lammps_e_if_given_e_mean",
        "liggghts_e",
        "liggghts_e_if_given_e_mean",
    ])
    .expect(IN_MEMORY);
    for ((pair, c), inp) in tr.pairs.iter().zip(constant).zip(inputs) {
        w.write_record([
            pair.label(),
            fmt_num(pair.d_i_m * 1e3),
            d_mm(pair.d_j_m),
            fmt_num(c.e_mean),
            fmt_num(c.dev_mean),
            fmt_num(c.e_minimax),
            fmt_num(c.dev_minimax),
            fmt_num(c.e_lo),
            fmt_num(c.e_hi),
            fmt_num(inp.alpha),
            opt_cell(inp.lammps_cor),
            fmt_num(inp.lammps_e_if_given_e),
            opt_cell(inp.liggghts_e),
            fmt_num(inp.liggghts_e_if_given_e),
        ])
        .expect(IN_MEMORY);
    }
    Ok(csv_text(w))
}

/// table.csv: e of the fitted curve per pair on the speed grid (event-driven codes interpolate
/// it; linear in ln v is what the reported interpolation error assumes).
pub fn table_csv(tr: &Translation) -> Result<String, FilesFailure> {
    let t = tr
        .table
        .as_ref()
        .ok_or(FilesFailure::NeedsSpeedRange("a table needs a speed range"))?;
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(["pair", "d1_mm", "d2_mm", "v_n_m_s", "e"])
        .expect(IN_MEMORY);
    for (p, pair) in tr.pairs.iter().enumerate() {
        for (v, e) in t.v_m_s.iter().zip(&t.e[p]) {
            w.write_record([
                pair.label(),
                fmt_num(pair.d_i_m * 1e3),
                d_mm(pair.d_j_m),
                fmt_num(*v),
                fmt_num(*e),
            ])
            .expect(IN_MEMORY);
        }
    }
    Ok(csv_text(w))
}

/// liggghts.in: material properties for LIGGGHTS's Hertz model giving the constant e of each
/// pair (`e_mean`), with the wall as the last atom type when the scene has one.
pub fn liggghts_input(
    tr: &Translation,
    inputs: &[ConstantEInputs],
    friction: Option<&Friction>,
) -> String {
    let scene = &tr.request.scene;
    let m = scene.material;
    let n = scene.diameters_m.len();
    let types = n + usize::from(scene.wall);
    let force_rule = tr.request.curve.rule == crate::models::viscoelastic::ContactEnd::Force;
    let mut cor = vec![vec![None; types]; types];
    for (pair, inp) in tr.pairs.iter().zip(inputs) {
        let j = pair.j.unwrap_or(n);
        cor[pair.i][j] = inp.liggghts_e;
        cor[j][pair.i] = inp.liggghts_e;
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# liggghts.in: LIGGGHTS Hertz model with a constant e per pair of types, written by\n\
         # `restitution export` (not run here: no LIGGGHTS on the build machine). Types 1..{n}: the\n\
         # sphere sizes{}. With {} the coefficients below give the\n\
         # e of constant_e.csv (e_mean) exactly: for limitForce off LIGGGHTS's formula is exact.",
        if scene.wall {
            format!("; type {types}: the walls")
        } else {
            String::new()
        },
        if force_rule {
            "limitForce on (the force rule) they are corrected so that"
        } else {
            "limitForce off (the overlap rule)"
        }
    );
    let list = |x: f64| vec![fmt_num(x); types].join(" ");
    let _ = writeln!(
        s,
        "fix m1 all property/global youngsModulus peratomtype {}\n\
         fix m2 all property/global poissonsRatio peratomtype {}",
        list(m.youngs_pa),
        list(m.poisson)
    );
    let mut cells = Vec::new();
    let mut missing = false;
    for row in &cor {
        for c in row {
            match c {
                Some(x) => cells.push(fmt_num(*x)),
                None => {
                    missing = true;
                    cells.push("1".into());
                }
            }
        }
    }
    if missing {
        let _ = writeln!(s, "# Entries 1 (wall-wall) take no part in the scene.");
    }
    let _ = writeln!(
        s,
        "fix m3 all property/global coefficientRestitution peratomtypepair {types} {}",
        cells.join(" ")
    );
    if let Some(fr) = friction {
        let _ = writeln!(
            s,
            "fix m4 all property/global coefficientFriction peratomtypepair {types} {}",
            vec![fmt_num(fr.mu0); types * types].join(" ")
        );
    }
    let _ = writeln!(
        s,
        "pair_style gran model hertz{} tangential history\npair_coeff * *",
        if force_rule { " limitForce on" } else { "" }
    );
    s
}

/// A speed in the round trip's table: six significant digits (the default middle speed, the
/// range's geometric mean, had printed as 4.47213595499958 across the next column; collide.in
/// and export.json keep every digit).
fn speed(v_m_s: f64) -> String {
    crate::data::significant(v_m_s, 6)
}

/// The printed comparison of LAMMPS with the toolkit.
pub fn verify_table(rows: &[VerifyRow], tolerance: f64) -> String {
    let mut s = String::new();
    let rung_names: Vec<String> = rows
        .first()
        .map(|r| r.rungs.iter().map(|(n, _)| format!("e(N={n})")).collect())
        .unwrap_or_default();
    let _ = writeln!(
        s,
        "{:<8} {:>7} {:>16} {}  {:>16} {:>10} {:>9}",
        "pair",
        "v_m_s",
        "toolkit e",
        rung_names
            .iter()
            .map(|n| format!("{n:>16}"))
            .collect::<Vec<_>>()
            .join(" "),
        "LAMMPS e (h->0)",
        "diff",
        "extrap"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:<8} {:>7} {:>16.12} {}  {:>16.12} {:>10.2e} {:>9.1e}",
            r.pair,
            speed(r.v_m_s),
            r.e_toolkit,
            r.rungs
                .iter()
                .map(|(_, e)| format!("{e:>16.12}"))
                .collect::<Vec<_>>()
                .join(" "),
            r.e_extrapolated,
            r.difference(),
            r.extrapolation_change
        );
    }
    let worst = rows
        .iter()
        .map(|r| r.difference().abs())
        .fold(0.0, f64::max);
    let _ = writeln!(
        s,
        "largest |diff| = {:.2e} ({} the tolerance {:.0e}); extrap = change of the extrapolation from the coarser rungs",
        worst,
        if worst <= tolerance {
            "within"
        } else {
            "OUTSIDE"
        },
        tolerance
    );
    s
}

/// Everything `restitution export` knows, for export.json.
pub struct Summary<'a> {
    pub source: &'a str,
    pub engine: &'a str,
    pub tr: &'a Translation,
    pub lammps_law: Option<&'a LammpsLaw>,
    pub constant_inputs: Option<&'a [ConstantEInputs]>,
    pub friction: Option<&'a Friction>,
    pub files: Vec<String>,
    pub verify: Option<&'a [VerifyRow]>,
}

fn num(x: f64) -> Value {
    if x.is_finite() { json!(x) } else { Value::Null }
}

/// export.json: the inputs, every law with its deviations, the engine parameters and (with
/// --verify) the LAMMPS comparison.
pub fn export_json(s: &Summary) -> String {
    let tr = s.tr;
    let req = &tr.request;
    let pairs: Vec<Value> = tr
        .pairs
        .iter()
        .enumerate()
        .map(|(p, pair)| {
            let mut v = json!({
                "pair": pair.label(),
                "d1_mm": num(pair.d_i_m * 1e3),
                "d2_mm": pair.d_j_m.map(|d| num(d * 1e3)).unwrap_or(json!("inf")),
                "m_red_kg": num(pair.contact.m_red_kg),
                "r_eff_m": num(pair.contact.r_eff_m),
                "e_star_pa": num(pair.contact.e_star_pa),
                "viscoelastic_dev_mean": num(tr.viscoelastic.dev_mean_per_pair[p]),
            });
            if let Some(c) = &tr.constant {
                let c = &c[p];
                v["constant_e"] = json!({
                    "e_mean": num(c.e_mean), "max_dev_mean": num(c.dev_mean),
                    "e_minimax": num(c.e_minimax), "max_dev_minimax": num(c.dev_minimax),
                    "e_at_lo": num(c.e_lo), "e_at_hi": num(c.e_hi),
                });
            }
            if let Some(inp) = s.constant_inputs {
                let i = &inp[p];
                v["tsuji"] = json!({
                    "alpha": num(i.alpha),
                    "lammps_cor": i.lammps_cor.map(num).unwrap_or(Value::Null),
                    "lammps_e_if_given_e": num(i.lammps_e_if_given_e),
                    "liggghts_e": i.liggghts_e.map(num).unwrap_or(Value::Null),
                    "liggghts_e_if_given_e": num(i.liggghts_e_if_given_e),
                });
            }
            v
        })
        .collect();
    let vm = &tr.viscoelastic;
    let mut out = json!({
        "source": s.source,
        "engine": s.engine,
        "model": req.curve.kind.name(),
        "params": req.curve.params.iter().zip(req.curve.kind.params()).map(|(x, p)| (p.key.to_string(), num(*x))).collect::<serde_json::Map<_, _>>(),
        "contact_end": req.curve.rule.name(),
        "material": {
            "youngs_pa": num(req.scene.material.youngs_pa),
            "poisson": num(req.scene.material.poisson),
            "density_kg_m3": num(req.scene.material.density_kg_m3),
        },
        "diameters_mm": req.scene.diameters_m.iter().map(|d| num(d * 1e3)).collect::<Vec<_>>(),
        "wall": req.scene.wall,
        "v_range_m_s": req.range.map(|r| json!([num(r.lo_m_s), num(r.hi_m_s)])).unwrap_or(Value::Null),
        "weight": req.weight.name(),
        "viscoelastic": {
            "exact": vm.exact,
            "eta_mean": num(vm.eta_mean), "max_dev_mean": num(vm.dev_mean),
            "eta_minimax": num(vm.eta_minimax), "max_dev_minimax": num(vm.dev_minimax),
            "converged": vm.converged,
            "search_end": vm.search_end.map(|e| e.name()),
        },
        "pairs": pairs,
        "files": s.files,
    });
    if let Some(t) = &tr.table {
        out["table"] = json!({
            "points": t.v_m_s.len(),
            "interpolation": "linear in ln v",
            "max_interpolation_dev": num(t.interpolation_dev),
        });
    }
    if let Some(r) = &tr.recommendation {
        out["recommendation"] = json!({
            "tolerance": num(r.tolerance),
            "deviations": r.deviations.iter().map(|(k, d)| json!({"law": k.name(), "max_dev": num(*d)})).collect::<Vec<_>>(),
            "chosen": r.chosen.map(|k| json!(k.name())).unwrap_or(Value::Null),
        });
    }
    if let Some(law) = s.lammps_law {
        out["lammps"] = match law {
            LammpsLaw::Viscoelastic { eta, note } => json!({
                "damping": "viscoelastic", "eta": num(*eta), "note": note,
                "damp": tr.lammps_viscoelastic(*eta).iter().map(|b| num(b.damp)).collect::<Vec<_>>(),
            }),
            LammpsLaw::Tsuji { cor, note } => json!({
                "damping": "tsuji", "cor": cor.iter().map(|c| num(*c)).collect::<Vec<_>>(), "note": note,
            }),
        };
    }
    if let Some(f) = s.friction {
        out["friction"] = json!({
            "mu0": num(f.mu0),
            "beta0": f.beta0.map(num).unwrap_or(Value::Null),
            "source": f.source,
            "beta0_in_engines": "not a parameter of LAMMPS or LIGGGHTS: the tangential spring and its damping set the tangential restitution; event-driven codes take it directly",
        });
    }
    if let Some(rows) = s.verify {
        out["lammps_verify"] = json!(rows.iter().map(|r| json!({
            "pair": r.pair, "v_m_s": num(r.v_m_s), "e_toolkit": num(r.e_toolkit),
            "rungs": r.rungs.iter().map(|(n, e)| json!({"steps_per_contact": n, "e": num(*e)})).collect::<Vec<_>>(),
            "e_extrapolated": num(r.e_extrapolated), "difference": num(r.difference()),
            "extrapolation_change": num(r.extrapolation_change),
        })).collect::<Vec<_>>());
    }
    serde_json::to_string_pretty(&out).expect("JSON values serialise") + "\n"
}

#[cfg(test)]
mod tests {
    use super::speed;

    #[test]
    fn round_trip_speeds_print_short() {
        // The committed reports' round speeds print as before; the default middle speed of
        // 0.5..40 m/s, sqrt(20), fits its column.
        assert_eq!(speed(0.5), "0.5");
        assert_eq!(speed(2.0), "2");
        assert_eq!(speed(10.0), "10");
        assert_eq!(speed(20f64.sqrt()), "4.47214");
        assert_eq!(speed(123_456.7), "123457");
        assert_eq!(speed(1e-5), "1.00000e-5");
        assert_eq!(speed(0.25), "0.25");
    }
}
