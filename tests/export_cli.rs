//! `restitution export` as a user runs it: the files each engine writes, the LAMMPS numbers
//! checked against values computed here from the formulas (not by the code under test), and one
//! clear line, a non-zero exit and no output files per bad input.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

const BIN: &str = env!("CARGO_BIN_EXE_restitution");

struct Run {
    ok: bool,
    stdout: String,
    stderr: String,
}

fn run(args: &[&str]) -> Run {
    let out = Command::new(BIN)
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        // --verify must not find a LAMMPS here: the bad-input tests never reach it anyway.
        .output()
        .expect("binary runs");
    Run {
        ok: out.status.success(),
        stdout: String::from_utf8_lossy(&out.stdout).into(),
        stderr: String::from_utf8_lossy(&out.stderr).into(),
    }
}

fn scratch(tag: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let d = std::env::temp_dir().join(format!(
        "restitution-export-cli-{}-{}-{tag}",
        std::process::id(),
        N.fetch_add(1, Ordering::SeqCst)
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into()
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The shipped fit, reports/fit/params.json, as JSON.
fn shipped_fit() -> serde_json::Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("reports/fit/params.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The fit of `model` in a params.json document.
fn fit_of<'a>(doc: &'a mut serde_json::Value, model: &str) -> &'a mut serde_json::Value {
    doc["fits"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|f| f["model"] == model)
        .unwrap()
}

#[test]
fn lammps_export_of_the_shipped_vm_fit() {
    let out = scratch("vm");
    let o = out.to_string_lossy().to_string();
    let r = run(&[
        "export",
        "reports/fit/params.json",
        "--engine",
        "lammps",
        "--model",
        "vm",
        "--walton",
        "reports/walton/walton.json",
        "--wall",
        "--out",
        &o,
    ]);
    assert!(r.ok, "{}", r.stderr);
    assert!(
        r.stdout.contains("0 (the fitted model itself)"),
        "{}",
        r.stdout
    );
    let f = read(&out, "in.restitution");
    let json: serde_json::Value = serde_json::from_str(&read(&out, "export.json")).unwrap();
    let eta = json["viscoelastic"]["eta_mean"].as_f64().unwrap();
    // The fitted eta of reports/fit/params.json (vm), carried over exactly.
    let mut params = shipped_fit();
    let vm = fit_of(&mut params, "vm");
    assert_eq!(eta, vm["params"]["eta"]["value"].as_f64().unwrap());
    // Every pair of the three sizes, written out (no mixing), and one wall fix per size.
    let lines: Vec<&str> = f.lines().filter(|l| l.starts_with("pair_coeff")).collect();
    assert_eq!(lines.len(), 6, "{f}");
    assert_eq!(f.matches("wall/gran granular").count(), 3);
    // damp = 4 eta / m_red with m = (pi/6) d^3 rho: computed here from the sizes.
    let mass = |d: f64| std::f64::consts::PI / 6.0 * d.powi(3) * 1140.0;
    let d = [6.35e-3, 12.7e-3, 25.4e-3];
    let mut k = 0;
    for i in 0..3 {
        for j in i..3 {
            let (mi, mj) = (mass(d[i]), mass(d[j]));
            let want = 4.0 * eta * (mi + mj) / (mi * mj);
            let fields: Vec<&str> = lines[k].split_whitespace().collect();
            assert_eq!(fields[1..3], [&*(i + 1).to_string(), &*(j + 1).to_string()]);
            assert_eq!(fields[3], "hertz/material");
            assert_eq!(fields[4], "350000000");
            let damp: f64 = fields[5].parse().unwrap();
            assert!(
                (damp / want - 1.0).abs() < 1e-14,
                "{}: {damp} vs {want}",
                lines[k]
            );
            assert_eq!(fields[6], "0.3");
            // Mindlin k_t = 8 G*, G* = G/(2 (2 - nu)), G = Y/(2 (1 + nu)); mu_0 from walton.json.
            let kt: f64 = fields[11].parse().unwrap();
            assert!((kt / (8.0 * 3.5e8 / 2.6 / 3.4) - 1.0).abs() < 1e-14);
            assert_eq!(fields[13], "0.17469876337247983");
            assert!(!lines[k].contains("limit_damping"), "overlap rule");
            k += 1;
        }
    }
    // The wall fix of type 1: damp = 4 eta / m, modulus 2 (1 - nu) E* with E* = Y/(2 (1 - nu^2)).
    let wall = f
        .lines()
        .find(|l| l.starts_with("fix restitution_wall_t1"))
        .unwrap();
    let w: Vec<&str> = wall.split_whitespace().collect();
    let e_star = 3.5e8 / (2.0 * 0.91);
    assert!((w[6].parse::<f64>().unwrap() / (1.4 * e_star) - 1.0).abs() < 1e-14);
    assert!((w[7].parse::<f64>().unwrap() / (4.0 * eta / mass(d[0])) - 1.0).abs() < 1e-14);
    let collide = read(&out, "collide.in");
    assert!(collide.contains("include in.restitution"));
    // 9 contacts x 3 speeds x 8 phases print lines, and one mean per contact and speed.
    assert_eq!(collide.matches("print \"restitution-e ").count(), 9 * 3 * 8);
    assert_eq!(collide.matches("print \"restitution-e-mean").count(), 27);
}

#[test]
fn force_rule_writes_limit_damping() {
    let out = scratch("force");
    let o = out.to_string_lossy().to_string();
    let r = run(&[
        "export",
        "--engine",
        "lammps",
        "--material",
        "nylon",
        "--d-mm",
        "6.35,25.4",
        "--eta",
        "190",
        "--contact-end",
        "force",
        "--out",
        &o,
    ]);
    assert!(r.ok, "{}", r.stderr);
    let f = read(&out, "in.restitution");
    let coeffs: Vec<&str> = f.lines().filter(|l| l.starts_with("pair_coeff")).collect();
    assert_eq!(coeffs.len(), 3);
    assert!(coeffs.iter().all(|l| l.ends_with("limit_damping")), "{f}");
    assert!(
        f.contains("tangential linear_nohistory 0 0"),
        "no friction given: frictionless"
    );
}

#[test]
fn constant_e_and_table_engines() {
    let out = scratch("const");
    let o = out.to_string_lossy().to_string();
    let r = run(&[
        "export",
        "reports/fit/params.json",
        "--engine",
        "constant-e",
        "--v-range",
        "0.5,2",
        "--tolerance",
        "0.02",
        "--out",
        &o,
    ]);
    assert!(r.ok, "{}", r.stderr);
    // Below yield the min model's e varies by at most 0.024 over 0.5-2 m/s: within 0.02 of a
    // constant (minimax half-range 0.012), so no velocity dependence is needed.
    assert!(
        r.stdout.contains("simplest law within 0.0200: constant e"),
        "{}",
        r.stdout
    );
    let csv = read(&out, "constant_e.csv");
    assert_eq!(csv.lines().count(), 1 + 6);
    assert!(read(&out, "in.restitution").contains("damping tsuji"));
    assert!(read(&out, "liggghts.in").contains("coefficientRestitution peratomtypepair 3"));
    assert!(read(&out, "laws.svg").starts_with("<svg"));

    let out = scratch("table");
    let o = out.to_string_lossy().to_string();
    let r = run(&[
        "export",
        "reports/fit/params.json",
        "--engine",
        "table",
        "--v-range",
        "0.5,40",
        "--table-points",
        "11",
        "--walton",
        "reports/walton/walton.json",
        "--out",
        &o,
    ]);
    assert!(r.ok, "{}", r.stderr);
    let t = read(&out, "table.csv");
    assert_eq!(t.lines().next(), Some("pair,d1_mm,d2_mm,v_n_m_s,e"));
    assert_eq!(t.lines().count(), 1 + 6 * 11);
    let json: serde_json::Value = serde_json::from_str(&read(&out, "export.json")).unwrap();
    assert_eq!(json["friction"]["beta0"].as_f64(), Some(0.4946949064230879));
    assert!(!out.join("in.restitution").exists());
}

#[test]
fn params_json_with_unknown_fields_is_read() {
    // Someone may add per-model `warnings` (or anything else): ignored.
    let dir = scratch("unknown");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("reports/fit/params.json"),
    )
    .unwrap()
    .replace(
        "\"notes\": []",
        "\"notes\": [], \"warnings\": [\"something\"], \"extra\": {\"x\": 1}",
    );
    assert!(text.contains("warnings"));
    let p = write(&dir, "params.json", &text);
    let r = run(&["export", &p, "--engine", "lammps", "--model", "vm"]);
    assert!(r.ok, "{}", r.stderr);
    assert!(r.stdout.contains("--- in.restitution ---"));
}

/// Runs a bad command: it must fail with one line on stderr containing `want`, and leave the
/// output directory empty.
fn refuses(args: &[&str], want: &str) {
    let out = scratch("bad");
    let o = out.to_string_lossy().to_string();
    let mut full: Vec<&str> = args.to_vec();
    full.extend(["--out", &o]);
    let r = run(&full);
    assert!(!r.ok, "{args:?} succeeded:\n{}", r.stdout);
    let lines: Vec<&str> = r.stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{args:?}: {}", r.stderr);
    assert!(lines[0].contains(want), "{args:?}: {}", r.stderr);
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        0,
        "{args:?} wrote files"
    );
}

#[test]
fn bad_input_gives_one_clear_line_and_no_files() {
    let dir = scratch("inputs");
    let garbled = write(
        &dir,
        "garbled.json",
        "{\n  \"material\": {\n    \"youngs_pa\": 3.5e8,,\n",
    );
    let wrong = write(
        &dir,
        "wrong.json",
        "{\"material\": {\"youngs_pa\": \"hard\"}}",
    );
    let params = "reports/fit/params.json";
    // The shipped fit with min's sigma_y turned into a bound (no value): not exportable.
    let mut doc = shipped_fit();
    let min = fit_of(&mut doc, "min");
    min["params"]["sigma_y"]["value"] = serde_json::Value::Null;
    min["params"]["sigma_y"]["status"] = "lower_bound".into();
    let bound_json = serde_json::to_string_pretty(&doc).unwrap();
    let bound = write(&dir, "bound.json", &bound_json);
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["export", "no/such.json", "--engine", "lammps"],
            "no/such.json: cannot read",
        ),
        (
            vec!["export", &garbled, "--engine", "lammps"],
            "garbled.json:3: not valid JSON",
        ),
        (
            vec!["export", &wrong, "--engine", "lammps"],
            "'material.youngs_pa' is \"hard\"",
        ),
        (
            vec!["export", params, "--engine", "lammps", "--model", "vmm"],
            "unknown model 'vmm'",
        ),
        (
            vec!["export", params, "--engine", "lammps", "--model", "pm"],
            "model pm has no exact engine form",
        ),
        (
            vec![
                "export",
                &bound,
                "--engine",
                "lammps",
                "--model",
                "min",
                "--v-range",
                "1,2",
            ],
            // What to do instead, and only what works: the file's models that have every
            // value, among them vm, which min tends to as sigma_y grows; a --sigma-y-pa flag
            // beside the file is refused.
            "sigma_y' has no value (status lower_bound: the data do not determine it); export another model (every parameter has a value in: vm, pm, product, powerlaw; the fit tends to 'vm' as sigma_y grows without bound), or give the law as numbers without the fit",
        ),
        (
            vec!["export", params, "--engine", "constant-e"],
            "--v-range",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "constant-e",
                "--v-range",
                "2,1",
            ],
            "--v-range",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "constant-e",
                "--v-range",
                "0,1",
            ],
            "lower end > 0",
        ),
        (
            vec!["export", params, "--engine", "constant-e", "--v-range", "1"],
            "not LO,HI",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "constant-e",
                "--v-range",
                "a,2",
            ],
            "'a' is not a number",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "constant-e",
                "--v-range",
                "1,1e300",
            ],
            "at most 1e6 m/s",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "constant-e",
                "--v-range",
                "1,2",
                "--tolerance",
                "0",
            ],
            "--tolerance 0",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "constant-e",
                "--v-range",
                "1,2",
                "--tolerance=-1e-3",
            ],
            "--tolerance -0.001",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "constant-e",
                "--v-range",
                "1,2",
                "--tolerance",
                "nan",
            ],
            "--tolerance NaN",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "lammps",
                "--tolerance",
                "0.01",
            ],
            "--tolerance needs --v-range",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "table",
                "--v-range",
                "1,2",
                "--verify",
            ],
            "--verify checks LAMMPS files",
        ),
        (
            vec!["export", params, "--engine", "lammps", "--eta", "190"],
            "--eta comes from",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "lammps",
                "--model",
                "vm",
                "--d-mm",
                "6.35,6.35",
            ],
            "given twice",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "lammps",
                "--model",
                "vm",
                "--d-mm=-1",
            ],
            "--d-mm -1",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "table",
                "--v-range",
                "1,2",
                "--table-points",
                "1",
            ],
            "--table-points 1",
        ),
        (
            vec![
                "export",
                params,
                "--engine",
                "lammps",
                "--model",
                "vm",
                "--walton",
                "no/w.json",
            ],
            "no/w.json: cannot read",
        ),
        (
            vec![
                "export",
                "--engine",
                "lammps",
                "--material",
                "nylon",
                "--d-mm",
                "5",
            ],
            "give PARAMS.json",
        ),
        (
            vec![
                "export",
                "--engine",
                "lammps",
                "--material",
                "nylon",
                "--d-mm",
                "5",
                "--eta",
                "1e400",
            ],
            "--eta",
        ),
        (
            vec![
                "export",
                "--engine",
                "lammps",
                "--material",
                "nylon",
                "--eta",
                "190",
            ],
            "--d-mm",
        ),
        (
            vec![
                "export",
                "--engine",
                "lammps",
                "--material",
                "nylon",
                "--d-mm",
                "5",
                "--eta",
                "190",
                "--mu0=-1",
            ],
            "--mu0 -1",
        ),
        (
            vec![
                "export",
                "--engine",
                "lammps",
                "--material",
                "nylon",
                "--d-mm",
                "5",
                "--eta",
                "190",
                "--speeds",
                "0",
            ],
            "--speeds 0",
        ),
        (
            vec![
                "export",
                "--engine",
                "lammps",
                "--material",
                "nylon",
                "--d-mm",
                "1e-300",
                "--eta",
                "190",
            ],
            "--d-mm 1e-300: expected a diameter",
        ),
        (
            vec![
                "export",
                "--engine",
                "lammps",
                "--material",
                "nylon",
                "--d-mm",
                "5",
                "--eta",
                "1e300",
            ],
            "overdamped",
        ),
        (
            vec![
                "export",
                "--engine",
                "lammps",
                "--material",
                "nylon",
                "--d-mm",
                "5",
                "--eta",
                "190",
                "--speeds",
                "1e-300,10",
            ],
            "too wide for one run",
        ),
    ];
    for (args, want) in cases {
        refuses(&args, want);
    }
}

#[test]
fn powerlaw_beyond_its_range_is_an_error_not_a_number() {
    // 1 - e = A (d/10 mm)^(-a) v^b reaches e < 0 at high speed: the export must say so.
    refuses(
        &[
            "export",
            "reports/fit/params.json",
            "--engine",
            "table",
            "--model",
            "powerlaw",
            "--v-range",
            "0.5,1e5",
        ],
        "fitted e at speed",
    );
}

#[test]
fn verify_without_lmp_says_so() {
    // PATH without LAMMPS: one clear line, non-zero exit, nothing written.
    let out = scratch("nolmp");
    let empty = scratch("emptypath");
    let r = Command::new(BIN)
        .args([
            "export",
            "--engine",
            "lammps",
            "--material",
            "nylon",
            "--d-mm",
            "5",
            "--eta",
            "190",
            "--verify",
            "--out",
        ])
        .arg(&out)
        .env("PATH", &empty)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success());
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("lmp (LAMMPS) is not on PATH"), "{stderr}");
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 0);
}

/// Without `--d-mm` the scene is the one measured: both spheres of an unequal pair (params.json
/// once listed only the first, so 10 mm on 20 mm data exported a scene of 10 mm spheres alone)
/// and the wall of sphere-on-wall data. Given sizes replace the measured scene, wall included.
#[test]
fn the_default_scene_is_the_measured_one() {
    let dir = scratch("scene");
    let mut csv = String::from("d_mm,d2_mm,v_n_m_s,e,e_err\n");
    for k in 0..8 {
        let v = 0.5 * 1.5f64.powi(k);
        csv += &format!("10,20,{v},{},0.02\n", 0.95 - 0.02 * k as f64);
    }
    let data = write(&dir, "unequal.csv", &csv);
    let fit_dir = dir.join("fit");
    let fitted = |data: &str, out: &Path| {
        let r = run(&[
            "fit",
            data,
            "--material",
            "nylon",
            "--model",
            "vm",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(r.ok, "{}", r.stderr);
        r.stdout
    };
    let text = fitted(&data, &fit_dir);
    assert!(text.contains("8 points, pairs: 10 mm on 20 mm;"), "{text}");
    let params = fit_dir.join("params.json");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&params).unwrap()).unwrap();
    assert_eq!(doc["data"]["diameters_mm"], serde_json::json!([10.0, 20.0]));
    assert_eq!(doc["data"]["wall"], serde_json::json!(false));
    let export = |params: &Path, extra: &[&str]| {
        let mut args = vec!["export", params.to_str().unwrap(), "--engine", "lammps"];
        args.extend(["--model", "vm"]);
        args.extend(extra);
        let r = run(&args);
        assert!(r.ok, "{}", r.stderr);
        r.stdout
    };
    let out = export(&params, &[]);
    assert!(
        out.contains("scene: type 1 = 10 mm, type 2 = 20 mm\n"),
        "{out}"
    );
    assert!(out.contains("pair_coeff 1 2 "), "{out}");
    // The shipped wall example: 12.7 mm on a wall.
    let wall_dir = dir.join("wall");
    let text = fitted("data/wall_example.csv", &wall_dir);
    assert!(
        text.contains("15 points, pairs: 12.7 mm on wall;"),
        "{text}"
    );
    let params = wall_dir.join("params.json");
    let out = export(&params, &[]);
    assert!(
        out.contains("scene: type 1 = 12.7 mm, and walls\n"),
        "{out}"
    );
    assert!(out.contains("wall/gran"), "{out}");
    let out = export(&params, &["--d-mm", "5"]);
    assert!(out.contains("scene: type 1 = 5 mm\n"), "{out}");
    // A params.json from before the field reads as no wall; a wrong one is one clear line.
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&params).unwrap()).unwrap();
    doc["data"].as_object_mut().unwrap().remove("wall");
    let old = write(&dir, "old.json", &doc.to_string());
    let out = export(Path::new(&old), &[]);
    assert!(out.contains("scene: type 1 = 12.7 mm\n"), "{out}");
    doc["data"]["wall"] = serde_json::json!("yes");
    let bad = write(&dir, "bad.json", &doc.to_string());
    refuses(
        &["export", &bad, "--engine", "lammps", "--model", "vm"],
        "field 'data.wall' is \"yes\", expected true or false",
    );
}

/// A negative number is a flag's value: Walton's beta_0 lies in [-1, 1], and `--beta0 -0.5`
/// was read as the short flags `-0` and `.5` ("unexpected argument '-0' found").
#[test]
fn negative_values_are_values() {
    let dir = scratch("negative");
    let out = dir.to_string_lossy().to_string();
    let r = run(&[
        "export",
        "reports/fit/params.json",
        "--engine",
        "lammps",
        "--v-range",
        "0.5,40",
        "--mu0",
        "0.3",
        "--beta0",
        "-0.5",
        "--out",
        &out,
    ]);
    assert!(r.ok, "{}", r.stderr);
    let doc: serde_json::Value = serde_json::from_str(&read(&dir, "export.json")).unwrap();
    assert!(
        r.stdout.contains("beta_0 = -0.500 (given)") && doc.to_string().contains("\"beta0\":-0.5"),
        "{}",
        r.stdout
    );
}

/// A pure number's unit ("1") is not printed after it: "A = 0.039570 1, a = 0.43404 1" read as
/// six numbers. Units that are units stay.
#[test]
fn the_report_prints_no_unit_after_a_pure_number() {
    let r = run(&[
        "export",
        "reports/fit/params.json",
        "--engine",
        "constant-e",
        "--model",
        "powerlaw",
        "--v-range",
        "0.1,5",
    ]);
    assert!(r.ok, "{}", r.stderr);
    let first = r.stdout.lines().next().unwrap();
    assert_eq!(
        first,
        "export of reports/fit/params.json (model powerlaw): model powerlaw (A = 0.039570, \
         a = 0.43404, b = 0.44667), contact end overlap"
    );
    let r = run(&[
        "export",
        "reports/fit/params.json",
        "--engine",
        "table",
        "--model",
        "min",
        "--v-range",
        "0.1,5",
    ]);
    assert!(r.ok, "{}", r.stderr);
    assert!(
        r.stdout
            .starts_with("export of reports/fit/params.json (model min): model min (eta = 190.55 kg/(s m), sigma_y = 4.0222e7 Pa)"),
        "{}",
        r.stdout
    );
}

/// A params.json of one model (`fit --model min --out`: no comparison, so nothing preferred)
/// exports that model without --model, and the report's first line names it.
#[test]
fn a_file_of_one_fit_exports_it() {
    let dir = scratch("one-fit");
    let d = dir.to_string_lossy().to_string();
    let r = run(&[
        "fit",
        "data/fig7_nylon.csv",
        "--material",
        "nylon",
        "--model",
        "min",
        "--out",
        &d,
    ]);
    assert!(r.ok, "{}", r.stderr);
    let params = format!("{d}/params.json");
    let r = run(&["export", &params, "--engine", "table", "--v-range", "0.5,5"]);
    assert!(r.ok, "{}", r.stderr);
    assert!(
        r.stdout.lines().next().unwrap().starts_with(&format!(
            "export of {params} (model min): model min (eta = "
        )),
        "{}",
        r.stdout
    );
}

/// `export` of a law given as numbers for 10 mm nylon spheres: `args` (engine, law, range)
/// then `--out out`.
fn export_nylon_10mm(args: &[&str], out: &Path) -> Run {
    let mut a = vec!["export", "--material", "nylon", "--d-mm", "10"];
    a.extend(args);
    a.extend(["--out", out.to_str().unwrap()]);
    run(&a)
}

/// A lossy law as a constant e: eta = 3e4 kg/(s m) on 10 mm nylon spheres gives e from 1.2e-4
/// at 1 m/s down to 1.2e-7 (mean 1.8e-5). The export had failed with "unphysical unloading
/// state ... p = 0.0000000000000111..." (Tsuji's inversion doubled its bracket past critical
/// damping); with that fixed it wrote `damping tsuji` coefficient 1, an all but elastic contact,
/// because LAMMPS's polynomial cannot damp that much (at most alpha = 1.2728, which gives
/// e = 0.1136 under the overlap rule, 0.2628 under the force rule: the closed form
/// exp(-pi a/sqrt(5 - a^2)) gives the first). Now one error line naming the pair, the e and
/// the floor, and no files. laws.svg labels eta in short form (1e-300 had read 0.0000).
#[test]
fn a_constant_e_out_of_lammpss_reach_is_an_error_not_an_elastic_contact() {
    let dir = scratch("lossy");
    let floor = (-std::f64::consts::PI * 1.2728 / (5.0f64 - 1.2728 * 1.2728).sqrt()).exp();
    assert_eq!(format!("{floor:.4}"), "0.1136");
    for (rule, says) in [
        (
            "overlap",
            "pair 1-1: a constant e of 1.801e-5 is out of reach of LAMMPS's damping \
                     tsuji (the most damping its input can ask for gives e = 0.1136)",
        ),
        (
            "force",
            "pair 1-1: a constant e of 0.01352 is out of reach of LAMMPS's damping tsuji \
                   (the most damping its input can ask for gives e = 0.2628)",
        ),
    ] {
        let out = dir.join(rule);
        let r = export_nylon_10mm(
            &[
                "--engine",
                "constant-e",
                "--eta",
                "3e4",
                "--v-range",
                "1,1e3",
                "--contact-end",
                rule,
            ],
            &out,
        );
        assert!(!r.ok);
        assert!(r.stderr.contains(says), "{}", r.stderr);
        assert_eq!(r.stderr.lines().count(), 1, "{}", r.stderr);
        assert!(!out.exists());
    }
    let out = dir.join("tiny");
    let r = export_nylon_10mm(
        &[
            "--engine",
            "constant-e",
            "--eta",
            "1e-300",
            "--v-range",
            "1e-3,1e3",
        ],
        &out,
    );
    assert!(r.ok, "{}", r.stderr);
    let svg = read(&out, "laws.svg");
    assert!(svg.contains("η = 1e-300 kg/(s m)"), "{svg}");
}

/// `--law auto` picks the closer of the viscoelastic law and a constant e, but only a constant e
/// LAMMPS can give: the plastic law at sigma_y = 1e3 Pa over 0.5-40 m/s (e from 0.003 to 0.001)
/// is closer to a constant e (largest deviation 1.2e-3 against 1.8e-3), which is below
/// `damping tsuji`'s floor (0.1136); the export had failed in Tsuji's inversion and, that
/// fixed, would have written coefficient 1. It carries the viscoelastic law and says why.
#[test]
fn auto_law_passes_over_a_constant_e_lammps_cannot_give() {
    let dir = scratch("auto-reach");
    let out = dir.join("out");
    let r = export_nylon_10mm(
        &[
            "--engine",
            "lammps",
            "--model",
            "pm",
            "--sigma-y-pa",
            "1e3",
            "--v-range",
            "0.5,40",
        ],
        &out,
    );
    assert!(r.ok, "{}", r.stderr);
    assert!(
        r.stdout.contains(
            "a constant e would deviate by 1.166e-3 but is out of reach of LAMMPS's damping tsuji"
        ),
        "{}",
        r.stdout
    );
    let input = read(&out, "in.restitution");
    let coeff: Vec<&str> = input
        .lines()
        .filter(|l| l.starts_with("pair_coeff"))
        .collect();
    assert!(
        !coeff.is_empty() && coeff.iter().all(|l| l.contains("damping viscoelastic")),
        "{input}"
    );
}
