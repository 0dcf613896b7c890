//! `restitution walton fit`: outputs, reproducibility and errors that name the place.

use nalgebra::Vector3;
use restitution::contact::{Material, Sphere};
use restitution::data::walton::write_collisions;
use restitution::fit::walton::CollisionRecord;
use restitution::models::walton::{Body, State, WaltonParams, collide};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A homogeneous sphere of diameter `d_m` and density `rho` (the elastic constants do not enter
/// Walton's operator).
fn sphere(d_m: f64, rho: f64) -> Sphere {
    Sphere::new(d_m, Material::new(1e9, 0.3, rho).unwrap()).unwrap()
}

// ---------------------------------------------------------------------------------------------
// The command line.

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_restitution"))
}

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("restitution-walton-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn run(args: &[&str]) -> (bool, String, String) {
    let out = bin().args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// `restitution walton fit PATH --material nylon`: (success, stdout, stderr).
fn fit_nylon(path: &Path) -> (bool, String, String) {
    run(&[
        "walton",
        "fit",
        path.to_str().unwrap(),
        "--material",
        "nylon",
    ])
}

fn shipped() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/oblique_collisions.csv")
        .display()
        .to_string()
}

#[test]
fn shipped_data_fit_covers_the_planted_values() {
    let (ok, out, err) = run(&[
        "walton",
        "fit",
        &shipped(),
        "--material",
        "nylon",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    // The JSON shape the README documents: {"e": {"value", "stderr"}, "beta0": {...}, "mu0": {...}, "n"}.
    for key in ["e", "beta0", "mu0"] {
        assert!(v[key]["value"].is_f64(), "{key}");
        assert!(v[key]["stderr"].is_f64(), "{key}");
        assert_eq!(v[key]["ci95"].as_array().unwrap().len(), 2, "{key}");
    }
    assert_eq!(v["n"], 60);
    assert_eq!(v["converged"], true);
    let classes = &v["classes"];
    assert_eq!(
        classes["sliding"].as_u64().unwrap() + classes["rolling"].as_u64().unwrap(),
        60
    );
    assert_eq!(v["collisions"].as_array().unwrap().len(), 60);
    assert!(v["collisions"][0]["class"].is_string());
    for (key, truth) in [("e", 0.97), ("beta0", 0.5), ("mu0", 0.175)] {
        let ci = v[key]["ci95"].as_array().unwrap();
        let (lo, hi) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
        assert!(
            lo <= truth && truth <= hi,
            "{key}: {truth} not in [{lo}, {hi}]"
        );
    }
}

#[test]
fn cli_writes_all_outputs_and_is_reproducible() {
    let dir = scratch("out");
    let out = dir.join("report");
    let args = [
        "walton",
        "fit",
        &shipped(),
        "--material",
        "nylon",
        "--bootstrap",
        "300",
        "--seed",
        "7",
        "--format",
        "csv",
        "--out",
        out.to_str().unwrap(),
    ];
    let (ok, csv1, err) = run(&args);
    assert!(ok, "{err}");
    assert!(csv1.starts_with("parameter,value,stderr,ci95_low,ci95_high,bound\ne,"));
    for f in [
        "walton.md",
        "walton.csv",
        "walton.json",
        "walton_collisions.csv",
        "fig6.svg",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert_eq!(
        std::fs::read_to_string(out.join("walton.csv")).unwrap(),
        csv1
    );
    let (_, csv2, _) = run(&args);
    assert_eq!(csv1, csv2, "same seed, same intervals");
    let svg = std::fs::read_to_string(out.join("fig6.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("sliding"));
}

/// Each bad input: one line naming file, line, column and value; non-zero exit; no output.
#[test]
fn cli_bad_input_errors_name_the_place() {
    let dir = scratch("bad");
    let good = std::fs::read_to_string(shipped()).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    let header_idx = lines.iter().position(|l| !l.starts_with('#')).unwrap();
    let header: Vec<&str> = lines[header_idx].split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    // The file with the first data row's cells (file line header_idx + 2) edited by `edit`.
    let with_row = |edit: &dyn Fn(&mut Vec<String>)| {
        let mut ls: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
        let mut cells: Vec<String> = ls[header_idx + 1].split(',').map(String::from).collect();
        edit(&mut cells);
        ls[header_idx + 1] = cells.join(",");
        ls.join("\n") + "\n"
    };
    let with_cell = |name: &str, value: &str| with_row(&|cells| cells[col(name)] = value.into());
    let data_line = header_idx + 2;
    let cases: Vec<(&str, String, Vec<String>)> = vec![
        (
            "not_a_number",
            with_cell("v1x_m_s", "1,5x"),
            vec![], // field count changes: checked separately below
        ),
        (
            "nan",
            with_cell("v1y_m_s", "nan"),
            vec![format!(":{data_line}:"), "'v1y_m_s'".into(), "'nan'".into()],
        ),
        (
            "text",
            with_cell("w1z_rad_s", "fast"),
            vec![
                format!(":{data_line}:"),
                "'w1z_rad_s'".into(),
                "'fast'".into(),
            ],
        ),
        (
            "negative_diameter",
            with_cell("d1_mm", "-25.4"),
            vec![format!(":{data_line}:"), "'d1_mm'".into(), "'-25.4'".into()],
        ),
        (
            "millimetres",
            with_cell("x1_m", "58.181"),
            vec![format!(":{data_line}:"), "metres".into()],
        ),
        (
            "missing_column",
            good.replace("w2z_post_rad_s", "w2z_post"),
            vec!["'w2z_post_rad_s'".into(), "missing".into()],
        ),
    ];
    for (name, text, needles) in &cases {
        let path = dir.join(format!("{name}.csv"));
        std::fs::write(&path, text).unwrap();
        let out = dir.join(format!("{name}_out"));
        let (ok, stdout, err) = run(&[
            "walton",
            "fit",
            path.to_str().unwrap(),
            "--material",
            "nylon",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok, "{name} should fail");
        assert!(stdout.is_empty(), "{name}: nothing on stdout");
        assert!(
            !out.exists() || std::fs::read_dir(&out).unwrap().next().is_none(),
            "{name}: no output"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: one line: {err}");
        assert!(err.starts_with("restitution: error: "), "{err}");
        assert!(
            err.contains(path.to_str().unwrap()),
            "{name}: names the file: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        for n in needles {
            assert!(
                err.contains(n.as_str()),
                "{name}: '{n}' missing from: {err}"
            );
        }
    }
    // Receding spheres: swap the pre- and post-collision columns' meaning by reversing velocities.
    let receding = with_row(&|cells| {
        for c in ["v1x_m_s", "v1y_m_s", "v2x_m_s", "v2y_m_s"] {
            let v: f64 = cells[col(c)].parse().unwrap();
            cells[col(c)] = format!("{}", -v);
        }
    });
    let path = dir.join("receding.csv");
    std::fs::write(&path, receding).unwrap();
    let (ok, _, err) = fit_nylon(&path);
    assert!(!ok);
    assert!(
        err.contains(&format!(":{data_line}:")) && err.contains("not approaching"),
        "{err}"
    );
    // Still approaching after the collision (e < 0): the post-collision velocities equal to the
    // pre-collision ones, e = -1. A mistyped post velocity (1e40) had been averaged into
    // e = -7e37 with a 95% interval of [1, 1].
    let approaching = with_row(&|cells| {
        for (post, pre) in [
            ("v1x_post_m_s", "v1x_m_s"),
            ("v1y_post_m_s", "v1y_m_s"),
            ("v2x_post_m_s", "v2x_m_s"),
            ("v2y_post_m_s", "v2y_m_s"),
        ] {
            cells[col(post)] = cells[col(pre)].clone();
        }
    });
    let path = dir.join("approaching.csv");
    std::fs::write(&path, approaching).unwrap();
    let (ok, stdout, err) = fit_nylon(&path);
    assert!(!ok && stdout.is_empty(), "{stdout}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains(&format!(":{data_line}:"))
            && err.contains("after the collision")
            && err.contains("e >= 0"),
        "{err}"
    );
    // A mistyped post-collision velocity that still separates the spheres (-1e40 m/s): the fit
    // runs, but a warning names the row whose momentum is not conserved.
    let path = dir.join("typo.csv");
    std::fs::write(&path, with_cell("v1x_post_m_s", "-1e40")).unwrap();
    let (ok, stdout, err) = fit_nylon(&path);
    assert!(ok, "{err}");
    // Its absurd numbers in exponent form (fixed decimals had printed 40-digit values).
    let spread = stdout
        .lines()
        .find(|l| l.starts_with("e over the collisions"))
        .unwrap();
    assert!(
        spread.contains("e38") && spread.split_whitespace().all(|t| t.len() <= 12),
        "{spread}"
    );
    // Two warnings: the row, and the fit it spoils (its beta, 7.5e37 on the plateau, is outside
    // Walton's range: not determined).
    let lines: Vec<&str> = err.trim_end().lines().collect();
    assert_eq!(lines.len(), 2, "{err}");
    assert!(
        lines[0].starts_with("restitution: warning: ")
            && lines[0].contains(&format!(":{data_line}: collision '1':"))
            && lines[0].contains("momentum is not conserved"),
        "{err}"
    );
    assert!(
        lines[1].contains("not determined") && lines[1].contains("outside Walton's range [-1, 1]"),
        "{err}"
    );
    let (ok, _, err) = run(&["walton", "fit", &shipped(), "--material", "nylon"]);
    assert!(
        ok && err.is_empty(),
        "the shipped data warn of nothing: {err}"
    );
    // A moving wall.
    let wall = "d1_mm,d2_mm,x1_m,y1_m,x2_m,y2_m,v1x_m_s,v1y_m_s,w1z_rad_s,v2x_m_s,v2y_m_s,w2z_rad_s,v1x_post_m_s,v1y_post_m_s,w1z_post_rad_s,v2x_post_m_s,v2y_post_m_s,w2z_post_rad_s\n\
                # a comment line, counted\n\
                10,inf,0,0.005,0,0,1.5,-2,0,0.3,0,0,0.93,1.8,-114,0,0,0\n";
    let path = dir.join("wall.csv");
    std::fs::write(&path, wall).unwrap();
    let (ok, _, err) = fit_nylon(&path);
    assert!(!ok);
    assert!(
        err.contains(":3: column 'v2x_m_s'") && err.contains("'0.3'") && err.contains("wall"),
        "{err}"
    );
    // Too few collisions to fit (the same wall row, now at rest, once).
    let path = dir.join("one.csv");
    std::fs::write(&path, wall.replace(",0.3,0,0,0.93", ",0,0,0,0.93")).unwrap();
    let (ok, _, err) = fit_nylon(&path);
    assert!(
        !ok && err.contains("cannot fit") && err.contains(">= 3"),
        "{err}"
    );
    // Bad flags.
    let (ok, _, err) = run(&[
        "walton",
        "fit",
        &shipped(),
        "--material",
        "nylon",
        "--inertia-k",
        "1.5",
    ]);
    assert!(!ok && err.contains("--inertia-k 1.5"), "{err}");
    let (ok, _, err) = run(&["walton", "fit", &shipped()]);
    assert!(!ok && err.contains("material"), "{err}");
    let (ok, _, err) = run(&["walton", "fit", "/nonexistent/c.csv", "--material", "nylon"]);
    assert!(
        !ok && err.contains("/nonexistent/c.csv") && err.contains("cannot read"),
        "{err}"
    );
    // A changed field count names the line.
    let path = dir.join("not_a_number.csv");
    let (ok, _, err) = fit_nylon(&path);
    assert!(
        !ok && err.contains(&format!(":{data_line}:")) && err.contains("fields"),
        "{err}"
    );
}

#[test]
fn three_d_and_wall_collisions_fit_end_to_end() {
    // Noise-free 3-D wall collisions over a range of incidences: the CLI returns the planted
    // values (only rounding through the CSV's shortest round-trip numbers).
    let p = WaltonParams::new(0.8, 0.3, 0.35).unwrap();
    let mut records = Vec::new();
    for i in 0..24 {
        let theta = (5.0 + 3.5 * i as f64).to_radians();
        let n = Vector3::new(0.1, 0.2, 1.0).normalize();
        let t = n.cross(&Vector3::new(1.0, 0.0, 0.0)).normalize();
        let v = -2.0 * (theta.cos() * n) + 2.0 * theta.sin() * t;
        let b = Body::homogeneous(0.005 * n, &sphere(0.01, 7850.0))
            .moving(v, Vector3::new(3.0, -1.0, 2.0));
        let pre = State::on_wall(b, Vector3::zeros());
        let post = collide(&pre, &p).unwrap().state;
        records.push(CollisionRecord {
            line: 0,
            id: None,
            pre,
            post,
        });
    }
    let dir = scratch("walls");
    let path = dir.join("walls.csv");
    std::fs::write(&path, write_collisions(&records)).unwrap();
    let (ok, out, err) = run(&[
        "walton",
        "fit",
        path.to_str().unwrap(),
        "--material",
        "steel",
        "--format",
        "json",
        "--bootstrap",
        "0",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["data"]["walls"], 24);
    // Rounding through ~17-digit CSV numbers and ratios of O(1) velocities.
    assert!(
        (v["e"]["value"].as_f64().unwrap() - 0.8).abs() < 1e-12,
        "{out}"
    );
    assert!((v["beta0"]["value"].as_f64().unwrap() - 0.35).abs() < 1e-12);
    assert!((v["mu0"]["value"].as_f64().unwrap() - 0.3).abs() < 1e-12);
    assert_eq!(v["e"]["ci95"], serde_json::Value::Null);
}

#[test]
fn json_collisions_keep_their_keys_in_order_and_null_where_there_is_no_number() {
    // The shipped collisions and a head-on one (no tangential speed: beta and psi have no
    // value), its id with a comma and quotes.
    let dir = scratch("json-keys");
    let path = dir.join("c.csv");
    let mut text = std::fs::read_to_string(shipped()).unwrap();
    text += "\"head, \"\"on\"\"\",25.4,25.4,0,0,0.0254,0,1,0,0,-1,0,0,-0.9,0,0,0.9,0,0\n";
    std::fs::write(&path, text).unwrap();
    let (ok, out, err) = run(&[
        "walton",
        "fit",
        path.to_str().unwrap(),
        "--material",
        "nylon",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(keys.last().map(|k| k.as_str()), Some("collisions"));
    let all = v["collisions"].as_array().unwrap();
    assert_eq!(all.len(), 61);
    let head_on = &all[60];
    let keys: Vec<&str> = head_on
        .as_object()
        .unwrap()
        .keys()
        .map(|k| k.as_str())
        .collect();
    assert_eq!(
        keys,
        [
            "line",
            "collision",
            "e",
            "beta",
            "psi",
            "v_n_m_s",
            "v_s_m_s",
            "impulse_ratio",
            "class",
            "residual"
        ]
    );
    assert_eq!(head_on["collision"], "head, \"on\"");
    assert_eq!(head_on["class"], "head_on");
    assert!(
        head_on["beta"].is_null() && head_on["psi"].is_null(),
        "{head_on}"
    );
    assert!(
        (head_on["e"].as_f64().unwrap() - 0.9).abs() < 1e-12,
        "{head_on}"
    );
    assert!(all[0]["psi"].is_f64() && all[0]["beta"].is_f64());
}
