//! `restitution predict` as a user runs it: outputs, formats and one-line errors.

use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_restitution"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn csv_has_the_input_then_e_in_shortest_round_trip_form() {
    let o = run(&[
        "predict", "--model", "pm", "--u", "1,2,1e12", "--format", "csv",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let mut lines = out.lines();
    assert_eq!(lines.next().unwrap(), "u,e,one_minus_e");
    let row: Vec<&str> = lines.nth(1).unwrap().split(',').collect();
    assert_eq!(row[0], "2");
    // mpmath: e(2) = 0.930625877273653262066687423862 -> shortest f64 form.
    assert_eq!(
        row[1].parse::<f64>().unwrap(),
        0.930625877273653262066687423862
    );
    assert_eq!(row[1], format!("{}", 0.930625877273653262066687423862f64));
}

#[test]
fn vm_dimensional_columns_and_json() {
    let o = run(&[
        "predict",
        "--model",
        "vm",
        "--material",
        "nylon",
        "--d-mm",
        "25.4",
        "--eta",
        "190",
        "--v-m-s",
        "0.5,2,40",
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let rows = v.as_array().unwrap();
    assert_eq!(rows.len(), 3);
    let keys: Vec<&String> = rows[0].as_object().unwrap().keys().collect();
    assert_eq!(keys[..3], ["v_m_s", "e", "one_minus_e"]);
    let e: Vec<f64> = rows.iter().map(|r| r["e"].as_f64().unwrap()).collect();
    assert!(e[0] > e[1] && e[1] > e[2] && e[2] > 0.0);
    assert!(rows[0]["contact_time_s"].as_f64().unwrap() > 0.0);
}

#[test]
fn methods_agree_on_e() {
    let get = |m: &str| {
        let o = run(&[
            "predict", "--model", "vm", "--kappa", "0.3", "--method", m, "--format", "csv",
        ]);
        assert!(o.status.success());
        stdout(&o)
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .nth(1)
            .unwrap()
            .parse::<f64>()
            .unwrap()
    };
    // Both the table and the default ODE are within the 1e-10 bar of the mpmath value
    // (tests/fixtures/vm_reference.csv, overlap rule, kappa = 0.3).
    let reference = 0.7140448799921524765697882;
    assert!((get("master") - reference).abs() < 1e-10);
    assert!((get("dop853") - reference).abs() < 1e-10);
}

#[test]
fn bad_input_is_one_line_and_non_zero() {
    let cases: &[&[&str]] = &[
        &["predict", "--model", "vm", "--kappa", "abc"],
        &["predict", "--model", "vm", "--kappa", "-1"],
        &["predict", "--model", "vm", "--kappa", "nan"],
        &["predict", "--model", "xx", "--kappa", "1"],
        &[
            "predict",
            "--model",
            "vm",
            "--material",
            "wood",
            "--d-mm",
            "1",
            "--eta",
            "1",
            "--v-m-s",
            "1",
        ],
        &[
            "predict",
            "--model",
            "vm",
            "--material",
            "nylon",
            "--d-mm",
            "0",
            "--eta",
            "1",
            "--v-m-s",
            "1",
        ],
        &[
            "predict",
            "--model",
            "vm",
            "--material",
            "nylon",
            "--d-mm",
            "1",
            "--eta",
            "-5",
            "--v-m-s",
            "1",
        ],
        &[
            "predict",
            "--model",
            "pm",
            "--material",
            "nylon",
            "--d-mm",
            "1",
            "--v-m-s",
            "1",
        ],
        &[
            "predict",
            "--model",
            "vm",
            "--youngs-pa",
            "1e9",
            "--poisson",
            "0.7",
            "--density-kg-m3",
            "1000",
            "--d-mm",
            "1",
            "--eta",
            "1",
            "--v-m-s",
            "1",
        ],
        &["predict", "--model", "vm", "--kappa", "1", "--tol", "0"],
        &["predict", "--model", "vm", "--kappa", "1", "--bogus"],
        &["predict", "--model", "vm"],
    ];
    for args in cases {
        let o = run(args);
        let err = stderr(&o);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("restitution: error: "), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(stdout(&o).is_empty(), "{args:?} printed output");
    }
    // The message names the offending value.
    let o = run(&["predict", "--model", "vm", "--kappa", "-1"]);
    assert!(stderr(&o).contains("-1"));
    // A tolerance tighter than a double can meet names the tolerance (it made the integrator
    // fail with an error that named the speed: `--v-m-s 3: dop853 integration failed ...`).
    for tol in ["1e-25", "1e-200"] {
        let args = format!(
            "predict --model vm --material nylon --d-mm 10 --eta 200 --v-m-s 3 --method dop853 \
             --tol {tol}"
        );
        let o = run(&args.split_whitespace().collect::<Vec<_>>());
        assert!(!o.status.success());
        assert_eq!(
            stderr(&o),
            format!("restitution: error: --tol {tol}: expected a number in [1e-15, 1)\n")
        );
    }
}

#[test]
fn plastic_at_huge_u_prints_the_right_numbers() {
    // Reported: --u 1e308 printed e = 1 with 1 - e = NaN, and e = 0 above u ~ 1e246. mpmath
    // (tests/fixtures/pm_reference.csv): e(1e308) = 1.184992992212371492...e-77 (C u^(-1/4):
    // the 1/u terms are far below rounding), e(1e246) = 3.74727686672926466e-62.
    let o = run(&[
        "predict",
        "--model",
        "pm",
        "--u",
        "1e308,1e246",
        "--format",
        "csv",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let rows: Vec<Vec<f64>> = out
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    for (row, want) in rows
        .iter()
        .zip([1.18499299221237149e-77, 3.74727686672926466e-62])
    {
        // 4 ulp: the closed form's bar (tests/plastic.rs).
        assert!((row[1] / want - 1.0).abs() < 4.0 * f64::EPSILON, "{row:?}");
        assert_eq!(row[2], 1.0, "1 - e of a tiny e rounds to 1: {row:?}");
    }
    assert!(!out.contains("NaN") && !out.contains("inf"), "{out}");
}

#[test]
fn yield_speed_underflow_is_one_clear_error() {
    // Reported: --sigma-y-pa 1e-130 made V_Y = 0 and printed e = 1 (fully elastic) where the truth
    // is e -> 0. V_Y ~ sigma_y^(5/2) ~ 1e-345 m/s is below the smallest double: an error.
    let o = run(&[
        "predict",
        "--model",
        "pm",
        "--material",
        "nylon",
        "--d-mm",
        "25.4",
        "--sigma-y-pa",
        "1e-130",
        "--v-m-s",
        "1",
    ]);
    assert!(!o.status.success());
    assert!(stdout(&o).is_empty(), "no half output: {}", stdout(&o));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("sigma_y = 1e-130 Pa") && err.contains("V_Y") && err.contains("underflow"),
        "{err}"
    );
}

#[test]
fn viscoelastic_e_for_every_kappa_with_named_gaps() {
    // The master curve gives e at any kappa; the ODE-only columns (contact time, extrema) are
    // empty beyond the ODE's range, with a note on stderr naming why. Overlap rule at kappa = 1e6:
    // e = A 1e-30, A = 5.158381704267685216 (mpmath).
    let o = run(&[
        "predict", "--model", "vm", "--kappa", "1e6,5", "--format", "csv",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let first: Vec<&str> = out.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(first[0], "1000000");
    assert_eq!(first[1].parse::<f64>().unwrap(), 5.158381704267685216e-30);
    assert_eq!(&first[3..], ["", "", ""]);
    let second: Vec<&str> = out.lines().nth(2).unwrap().split(',').collect();
    assert!(
        second[3..].iter().all(|c| c.parse::<f64>().is_ok()),
        "{second:?}"
    );
    let err = stderr(&o);
    assert!(
        err.contains("note: kappa = 1000000") && err.contains("checked range"),
        "{err}"
    );
}
