//! Every subcommand is total: whatever the input, the binary ends within 2 s (of CPU: the
//! machines are shared) with a result free
//! of NaN/inf or with one clear error line and a non-zero exit; never a panic, never a hang.
//!
//! A seeded subset of the fuzzer in `tests/fuzz/` (the larger run: `cargo run --release
//! --example fuzz_cli -- --cases N`), the cases that found bugs, 100 000-row files, property tests
//! of the reader and writer, CSV outputs with awkward ids read back, and a closed stdout.

mod fuzz;

use fuzz::cases::{Command as Command_, Sheet, case_of, fig7};
use fuzz::{Case, Runner, Tally};
use proptest::prelude::*;
use restitution::data::walton::write_collisions;
use restitution::data::{CsvOut, Table, fmt_num};
use restitution::synthetic::{SyntheticSpec, synthetic_collisions};
use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::Mutex;

fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_restitution"))
}

/// The subprocess cases run one at a time, so that the tests of this file do not slow each
/// other towards the time limit (which detects hangs; it is not a speed test).
static SERIAL: Mutex<()> = Mutex::new(());

fn run_all(tag: &str, cases: &[Case]) -> Tally {
    let _guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let runner = Runner::new(bin(), tag);
    let mut tally = Tally::default();
    for (i, c) in cases.iter().enumerate() {
        let r = runner.check(c, i);
        tally.add(c, r);
    }
    let _ = std::fs::remove_dir_all(&runner.root);
    tally
}

fn assert_clean(t: &Tally) {
    assert!(
        t.failures.is_empty(),
        "{} of {} cases broke the rules:\n\n{}",
        t.failures.len(),
        t.cases,
        t.failures.join("\n\n")
    );
}

fn file_case(label: &str, args: &[&str], name: &str, bytes: Vec<u8>, out_dir: bool) -> Case {
    Case {
        label: label.into(),
        args: args.iter().map(|s| s.to_string()).collect(),
        files: vec![(name.into(), bytes)],
        out_dir,
    }
}

/// `fit data.csv --material nylon --model MODEL` and `extra` flags, on `bytes`.
fn fit_case(label: &str, model: &str, extra: &[&str], bytes: Vec<u8>) -> Case {
    let mut args = vec!["fit", "data.csv", "--material", "nylon", "--model", model];
    args.extend_from_slice(extra);
    file_case(label, &args, "data.csv", bytes, false)
}

/// Cases 0..n of seed 1 for one subcommand (see `fuzz::cases::case_of`), without the 100 000-row
/// files (they have their own test); one test per subcommand, so that a failure points at it.
fn seeded(command: Command_, n: u64, min_ok: usize) {
    let base = Sheet::parse(&fig7());
    let cases: Vec<Case> = (0..n)
        .map(|i| case_of(command, 1, i, &base, false))
        .collect();
    let t = run_all(&format!("{command:?}"), &cases);
    assert_clean(&t);
    // The mix must exercise results as well as errors.
    assert!(t.ok >= min_ok, "{} ok, {} errors", t.ok, t.errors);
}

#[test]
fn seeded_fit() {
    seeded(Command_::Fit, 80, 15);
}

#[test]
fn seeded_walton_fit() {
    seeded(Command_::Walton, 50, 10);
}

#[test]
fn seeded_kinematics() {
    seeded(Command_::Kinematics, 50, 5);
}

#[test]
fn seeded_predict() {
    seeded(Command_::Predict, 50, 10);
}

#[test]
fn seeded_simulate() {
    seeded(Command_::Simulate, 40, 5);
}

#[test]
fn seeded_export() {
    seeded(Command_::Export, 60, 5);
}

#[test]
fn seeded_track() {
    seeded(Command_::Track, 40, 5);
}

#[test]
fn seeded_bench_flags() {
    seeded(Command_::Bench, 8, 0);
}

/// Cases of the larger runs (`--cases 2000`, seeds 1-3) that broke the rules before their fixes:
/// `inf` in a fit's warning (a gap with no bound; a contradicted certificate with no cell),
/// NaN positions and inf spins in `simulate` tracks (1e300 m/s, a 1e-80 mm sphere), `predict`
/// printing inf or naming no flag, `export` hanging on a tolerance of 1e308 or failing
/// without naming its input. (Seed 2's case 484, `walton fit` of a 32 MB file of 100 000
/// collisions with `--format json --out`, came down from 1.8 to 1.1 s of CPU when its JSON was
/// built once; it stays out of this list because under a loaded machine it still nears the
/// 2 s hang limit: `hundred_thousand_rows_walton_and_kinematics` covers 100 000 collisions.)
/// And from runs of `fit` cases on 2026-11-27: `fit --out` hanging on speeds of f64::MAX (seed
/// 202: the figure's axis margin overflowed to inf, and its tick loop never ended), and the
/// power law's search taking 2.7 s over an e of 1e-20 whose sigma_e = 2 e v_err / v_n was
/// 2.7e-22 (seed 401: its residual was rounding; errors below 5e-11 are now refused).
#[test]
fn cases_the_larger_runs_found() {
    let base = Sheet::parse(&fig7());
    let found: [(Command_, u64, u64); 17] = [
        (Command_::Fit, 202, 598),
        (Command_::Fit, 401, 522),
        (Command_::Fit, 2, 985),
        (Command_::Fit, 3, 1646),
        (Command_::Fit, 3, 1980),
        (Command_::Simulate, 2, 130),
        (Command_::Simulate, 3, 1762),
        (Command_::Predict, 1, 308),
        (Command_::Predict, 1, 513),
        (Command_::Predict, 1, 632),
        (Command_::Predict, 1, 788),
        (Command_::Predict, 1, 1305),
        (Command_::Predict, 1, 1616),
        // export --tolerance 1e308 (the figure's axis spanned 1e308: a hang); a constant e
        // that the damped Hertz law cannot reach, whose error named neither file nor flag.
        (Command_::Export, 2, 239),
        (Command_::Export, 2, 535),
        // kinematics --fov-m 5e-324: a subpixel of 0 m, and the noise printed as inf subpixels.
        (Command_::Kinematics, 1, 356),
        // simulate --fps 5e-324: a frame interval of inf s, and a panic drawing the clock's
        // phase in [0, inf).
        (Command_::Simulate, 614, 52),
    ];
    let cases: Vec<Case> = found
        .iter()
        .map(|&(c, seed, i)| case_of(c, seed, i, &base, true))
        .collect();
    assert_clean(&run_all("found", &cases));
}

fn fig7_rows(n: usize, error_column: Option<(&str, &str)>) -> Vec<u8> {
    let base = Sheet::parse(&fig7());
    let mut s = base.clone();
    s.rows = (0..n)
        .map(|i| base.rows[i % base.rows.len()].clone())
        .collect();
    if let Some((name, value)) = error_column {
        let c = s.col("v_err_m_s").expect("the Fig. 7 data have v_err_m_s");
        s.header[c] = name.into();
        for r in &mut s.rows {
            r[c] = value.into();
        }
    }
    s.to_bytes()
}

/// Error bars so small (or large) that chi2 spans hundreds of decades: the fits must end.
#[test]
fn extreme_error_bars() {
    let models = ["vm", "pm", "min", "product", "powerlaw", "all"];
    let mut cases = Vec::new();
    for (rows, e_err) in [(4, "1e-80"), (4, "1e80"), (120, "1e-80"), (4, "5e-324")] {
        for m in models {
            cases.push(fit_case(
                &format!("fit --model {m}, {rows} rows, e_err {e_err}"),
                m,
                &[],
                fig7_rows(rows, Some(("e_err", e_err))),
            ));
        }
    }
    assert_clean(&run_all("errbars", &cases));
}

/// The Fig. 7 rows repeated to `n`, every speed moved by a fixed pattern of up to 0.1%: `n`
/// distinct points, which the fit cannot merge (as `scripts/time_big_fit.sh` builds them).
fn fig7_rows_distinct(n: usize) -> Vec<u8> {
    let base = Sheet::parse(&fig7());
    let mut s = base.clone();
    s.rows = (0..n)
        .map(|i| base.rows[i % base.rows.len()].clone())
        .collect();
    let c = s.col("v_n_m_s").expect("the Fig. 7 data have v_n_m_s");
    for (k, r) in s.rows.iter_mut().enumerate() {
        let v: f64 = r[c].parse().expect("a speed");
        r[c] = format!(
            "{:?}",
            v * (1.0 + 1e-3 * ((k * 7919 % 2001) as f64 / 1000.0 - 1.0))
        );
    }
    s.to_bytes()
}

/// 100 000 rows of fit data: read, validated and fitted (or refused with one line) within the
/// limit, for every model: rows that repeat 120 points (merged); and 100 000 distinct points
/// for each model alone (`scripts/time_big_fit.sh`; README, known limitations): on 2 AMD EPYC
/// cores the one-parameter models 0.3-0.4 s of CPU, `min` 0.8-1.1 s, `product` 1.2-1.5 s and `powerlaw`
/// 1.2-1.6 s (user + system; `product` 1.3-1.6 s and `powerlaw` 1.2-1.4 s with one of the two
/// cores kept busy by another process). `--model all` on distinct points takes the five fits'
/// CPU together, less the rows they share (3.7-4.0 s on the two cores, 2.0-2.3 s of wall
/// time). On the faster 2 Intel Xeon cores of 2026-11-27: 0.2 s (`vm`, `pm`), 0.6 s (`min`),
/// 0.9 s (`product`, `powerlaw`), and `--model all` 2.2-2.3 s of CPU, 1.2 s of wall time:
/// beyond the limit, so not a case here (README, known limitations). On 2026-11-28, with the
/// profiles' global inner minimisation and the search beyond each interval end, on these rows
/// (two runs each): 0.2-0.3 s (`vm`, `pm`), 0.75-0.84 s (`min`), 1.0 s (`product`), 1.4-1.7 s
/// (`powerlaw`, three runs; b0aab52 1.2-1.5 s): the thinnest margin, and `--model all`
/// 3.1 s of CPU, 1.7 s of wall time. With one inner search per profile crossing (2026-11-28,
/// eighteenth session) `powerlaw` takes 1.05-1.23 s on these rows against 1.22-1.65 s for
/// 86c6584 (three alternate pairs of three runs).
#[test]
fn hundred_thousand_rows_fit() {
    let mut cases = Vec::new();
    for m in ["vm", "pm", "powerlaw", "min", "product", "all"] {
        cases.push(fit_case(
            &format!("fit --model {m}, 100 000 rows"),
            m,
            &[],
            fig7_rows(100_000, None),
        ));
    }
    let distinct = fig7_rows_distinct(100_000);
    for m in ["vm", "pm", "min", "product", "powerlaw"] {
        cases.push(fit_case(
            &format!("fit --model {m}, 100 000 distinct rows"),
            m,
            &[],
            distinct.clone(),
        ));
    }
    // With the figures: 100 000 markers had made 45 MB of SVG each and a second or more of CPU
    // (the figures now draw a marker once per pixel, or a density: src/plot/fit/points.rs).
    for (label, bytes) in [("", fig7_rows(100_000, None)), (" distinct", distinct)] {
        let args = [
            "fit",
            "data.csv",
            "--material",
            "nylon",
            "--model",
            "vm",
            "--out",
            "{dir}/out",
        ];
        cases.push(file_case(
            &format!("fit --model vm --out, 100 000{label} rows"),
            &args,
            "data.csv",
            bytes,
            true,
        ));
    }
    assert_clean(&run_all("bigfit", &cases));
}

/// `--exact` integrates the ODE at every distinct point for every parameter value tried: where
/// that would take more than about a second (100 000 distinct points: minutes) it is refused with
/// one line, and where it is allowed it ends within the limit. The fuzzer's own `fit` cases
/// draw it only for a few rows (README, fuzzing).
#[test]
fn exact_ends_within_the_limit_or_is_refused() {
    let fig7_bytes = fig7().into_bytes();
    let repeated = fig7_rows(100_000, None);
    let distinct = fig7_rows_distinct(100_000);
    let case = |label: &str, model: &str, bytes: &Vec<u8>| {
        fit_case(
            &format!("fit --exact --model {model}, {label}"),
            model,
            &["--exact"],
            bytes.clone(),
        )
    };
    // Allowed: vm and min on the shipped 119 distinct points (0.22 and 0.62 s of CPU on 2
    // Intel Xeon cores), vm on 100 000 rows of those points. Refused: product and all there
    // (cost 6 and 10 per point, at most 600), vm on 100 000 distinct points.
    let cases = [
        case("the shipped data", "vm", &fig7_bytes),
        case("the shipped data", "min", &fig7_bytes),
        case("100 000 rows of 119 points", "vm", &repeated),
        case("the shipped data", "product", &fig7_bytes),
        case("the shipped data", "all", &fig7_bytes),
        case("100 000 distinct points", "vm", &distinct),
    ];
    let t = run_all("exact", &cases);
    assert_clean(&t);
    assert_eq!((t.ok, t.errors), (3, 3), "{t:?}");
}

/// 100 000 collisions for `walton fit`, 100 000 frames for `kinematics`.
#[test]
fn hundred_thousand_rows_walton_and_kinematics() {
    let mut cases = Vec::new();
    // 100 000 collisions: the same 60 repeated (ids kept unique by the row).
    let mut spec = SyntheticSpec::paper();
    spec.n = 60;
    let (_, noisy) = synthetic_collisions(&spec, 5).unwrap();
    let one = Sheet::parse(&write_collisions(&noisy));
    let mut many = one.clone();
    many.rows = (0..100_000)
        .map(|i| {
            let mut r = one.rows[i % one.rows.len()].clone();
            r[0] = format!("c{i}");
            r
        })
        .collect();
    let walton = many.to_bytes();
    for boot in ["0", "2000"] {
        cases.push(file_case(
            &format!("walton fit, 100 000 collisions, --bootstrap {boot}"),
            &[
                "walton",
                "fit",
                "c.csv",
                "--material",
                "nylon",
                "--bootstrap",
                boot,
            ],
            "c.csv",
            walton.clone(),
            false,
        ));
    }
    // Tracks: 100 000 frames of one collision, and 100 000 one-frame collisions.
    let mut one_long = CsvOut::new();
    one_long.record([
        "collision",
        "t_s",
        "x1_m",
        "y1_m",
        "x2_m",
        "y2_m",
        "d1_mm",
        "d2_mm",
    ]);
    let mut many_short = CsvOut::new();
    many_short.record([
        "collision",
        "t_s",
        "x1_m",
        "y1_m",
        "x2_m",
        "y2_m",
        "d1_mm",
        "d2_mm",
    ]);
    for i in 0..100_000 {
        let t = i as f64 * 1e-5;
        // Two spheres approaching at 1 m/s each, touching at t = 0.5 s, then parting.
        let gap = 0.0254 + 2.0 * (0.5 - t).abs();
        let row = [
            "a".to_string(),
            fmt_num(t),
            fmt_num(-gap / 2.0),
            "0.1".into(),
            fmt_num(gap / 2.0),
            "0.1".into(),
            "25.4".into(),
            "25.4".into(),
        ];
        one_long.record(&row);
        let mut short = row.clone();
        short[0] = format!("c{i}");
        many_short.record(&short);
    }
    for (label, bytes) in [
        ("kinematics, one collision of 100 000 frames", one_long),
        ("kinematics, 100 000 one-frame collisions", many_short),
    ] {
        cases.push(file_case(
            label,
            &["kinematics", "t.csv", "--material", "nylon"],
            "t.csv",
            bytes.into_string().into_bytes(),
            false,
        ));
    }
    assert_clean(&run_all("big", &cases));
}

/// Quotes, commas, line breaks and a leading `#` in ids survive the CSVs that `walton fit` and
/// `kinematics` write: each reads back with the same ids.
#[test]
fn awkward_ids_round_trip_through_written_csv() {
    let _guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let dir = std::env::temp_dir().join(format!("restitution-ids-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let ids = [
        "a,b",
        "say \"hi\"",
        "two\nlines",
        "#3",
        "caf\u{e9}",
        "plain",
    ];
    let id = |i: usize| format!("{} {i}", ids[i % ids.len()]);

    // walton fit: the collisions' ids into walton_collisions.csv.
    let (_, mut noisy) = synthetic_collisions(&SyntheticSpec::paper(), 8).unwrap();
    for (i, r) in noisy.iter_mut().enumerate() {
        r.id = Some(id(i));
    }
    let input = dir.join("collisions.csv");
    std::fs::write(&input, write_collisions(&noisy)).unwrap();
    let out = dir.join("walton");
    let st = Command::new(bin())
        .args(["walton", "fit"])
        .arg(&input)
        .args(["--material", "nylon", "--bootstrap", "50", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let t = Table::read(&out.join("walton_collisions.csv")).unwrap();
    let c = t.require("collision").unwrap();
    let got: Vec<&str> = t.rows.iter().map(|r| t.field(r, c)).collect();
    let want: Vec<String> = (0..noisy.len()).map(id).collect();
    assert_eq!(got, want);
    let csv = Table::read(&out.join("walton.csv")).unwrap();
    assert_eq!(csv.rows.len(), 5);

    // kinematics: simulated tracks renamed with awkward ids, through all three CSVs.
    let sim = dir.join("sim");
    let st = Command::new(bin())
        .args(["simulate", "--material", "nylon", "--n", "6", "--out"])
        .arg(&sim)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let tracks = Table::read(&sim.join("tracks.csv")).unwrap();
    let c = tracks.require("collision").unwrap();
    let mut w = CsvOut::new();
    w.record(&tracks.headers);
    for r in &tracks.rows {
        let mut f: Vec<String> = (0..tracks.headers.len())
            .map(|j| tracks.field(r, j).to_string())
            .collect();
        // The simulated ids are c1, c2, ...
        let n: usize = f[c].trim_start_matches('c').parse().unwrap();
        f[c] = id(n);
        w.record(&f);
    }
    let renamed = dir.join("tracks.csv");
    std::fs::write(&renamed, w.into_string()).unwrap();
    let kin = dir.join("kin");
    let st = Command::new(bin())
        .arg("kinematics")
        .arg(&renamed)
        .args(["--material", "nylon", "--fixed-gravity", "--out"])
        .arg(&kin)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let k = Table::read(&kin.join("kinematics.csv")).unwrap();
    let kc = k.require("collision").unwrap();
    let got: Vec<String> = k.rows.iter().map(|r| k.field(r, kc).to_string()).collect();
    let want: Vec<String> = (1..=6).map(id).collect();
    assert_eq!(got, want);
    let wi = Table::read(&kin.join("walton_input.csv")).unwrap();
    let wc = wi.require("collision").unwrap();
    let got: Vec<String> = wi
        .rows
        .iter()
        .map(|r| wi.field(r, wc).to_string())
        .collect();
    assert_eq!(got, want);
    let fi = Table::read(&kin.join("fit_input.csv")).unwrap();
    assert_eq!(fi.rows.len(), 6);
    // And the chain goes on: the walton input is read by walton fit.
    let st = Command::new(bin())
        .args(["walton", "fit"])
        .arg(kin.join("walton_input.csv"))
        .args(["--material", "nylon", "--bootstrap", "0", "--format", "csv"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        st.status.success() || err.starts_with("restitution: error: "),
        "{err}"
    );
    assert!(!err.contains("line") || !err.contains("fields"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `restitution ... | head -1`: the reader goes away after one line; the command exits 0
/// quietly. Through `print!` (predict) and through the checked writer (walton fit).
#[test]
fn closed_stdout_is_success() {
    let _guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let dir = std::env::temp_dir().join(format!("restitution-pipe-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // Well over a pipe's 64 KiB, so that the writer is still writing when the reader leaves.
    let speeds: Vec<String> = (1..=3000).map(|i| format!("{}", i as f64 * 0.01)).collect();
    let (_, mut noisy) = synthetic_collisions(
        &SyntheticSpec {
            n: 1500,
            ..SyntheticSpec::paper()
        },
        2,
    )
    .unwrap();
    noisy.iter_mut().for_each(|r| r.id = None);
    let input = dir.join("c.csv");
    std::fs::write(&input, write_collisions(&noisy)).unwrap();
    let commands: Vec<Vec<String>> = vec![
        [
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
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([speeds.join(",")])
        .collect(),
        vec![
            "walton".into(),
            "fit".into(),
            input.display().to_string(),
            "--material".into(),
            "nylon".into(),
            "--bootstrap".into(),
            "0".into(),
            "--format".into(),
            "json".into(),
        ],
    ];
    for args in commands {
        let mut child = Command::new(bin())
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = String::new();
        {
            let mut out = BufReader::new(child.stdout.take().unwrap());
            out.read_line(&mut first).unwrap();
        } // The read end closes here, as `head -1` closes it.
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!first.is_empty(), "{}: no first line", args[0]);
        assert_eq!(o.status.code(), Some(0), "{}: {err}", args[0]);
        assert!(err.is_empty(), "{}: stderr {err}", args[0]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A fit case whose data have one cell replaced by `value`.
fn one_cell_case(col: &str, row: usize, value: &str, model: &str) -> Case {
    let base = Sheet::parse(&fig7());
    let mut s = base.clone();
    s.rows.truncate(12);
    let c = s.col(col).unwrap();
    s.rows[row][c] = value.into();
    fit_case(
        &format!("fit --model {model}, {col}[{row}] = {value}"),
        model,
        &["--format", "csv"],
        s.to_bytes(),
    )
}

/// Found by `fit_takes_any_number_in_any_cell` in CI on 2026-11-27: a diameter of 3.8e-90 mm in
/// a power-law fit of 12 rows gives a search region of 41 931 cells, and each slice of A's
/// profile started on all of them. The slice's start looked for repeated corners in a list
/// (quadratic: 24 s of CPU) and then ran out of its budget anyway; a slice now says it is not
/// shown global when the region crosses it in more cells than its budget (0.4 s).
#[test]
fn a_power_law_over_a_diameter_of_1e_minus_90_mm_ends_within_the_limit() {
    let value = format!("{}", 3.7692196493170435e-90);
    let case = one_cell_case("d_mm", 1, &value, "powerlaw");
    assert_clean(&run_all("tiny-d", &[case]));
}

/// Any f64 at all, as Rust prints it (finite, subnormal, huge, zero, negative, NaN, inf).
fn any_number() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|x| format!("{x}")),
        any::<f64>().prop_map(|x| format!("{x:e}")),
        (-330i32..330).prop_map(|e| format!("1e{e}")),
        Just("-0".to_string()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// One cell of the fit data replaced by any number: a result or one clear error.
    #[test]
    fn fit_takes_any_number_in_any_cell(
        col in prop::sample::select(vec!["d_mm", "v_n_m_s", "e", "v_err_m_s"]),
        row in 0usize..12,
        value in any_number(),
        model in prop::sample::select(vec!["vm", "pm", "powerlaw", "min"]),
    ) {
        let case = one_cell_case(col, row, &value, model);
        let t = run_all("prop", &[case]);
        prop_assert!(t.failures.is_empty(), "{}", t.failures.join("\n"));
    }
}
