//! Case generators: valid inputs of each subcommand, then mutations.

use super::Case;
pub use super::sheet::{EXTREMES, Sheet, mutate};
use rand::rngs::StdRng;
use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use restitution::data::tracks::{CollisionTrack, write_tracks};
use restitution::data::walton::write_collisions;
use restitution::experiment::{ExperimentSpec, simulate};
use restitution::synthetic::{SyntheticSpec, synthetic_collisions};

fn flag_value(rng: &mut StdRng, typical: &[&str]) -> String {
    if rng.random_bool(0.6) {
        typical.choose(rng).expect("not empty").to_string()
    } else {
        EXTREMES.choose(rng).expect("not empty").to_string()
    }
}

fn material(rng: &mut StdRng) -> Vec<String> {
    match rng.random_range(0..10) {
        0 => vec!["--material".into(), "unobtainium".into()],
        1 => {
            let mut args = Vec::new();
            flag(
                &mut args,
                "--youngs-pa",
                flag_value(rng, &["3.5e8", "2e11"]),
            );
            flag(
                &mut args,
                "--poisson",
                flag_value(rng, &["0.3", "0.49", "-0.9"]),
            );
            flag(
                &mut args,
                "--density-kg-m3",
                flag_value(rng, &["1140", "7800"]),
            );
            args
        }
        _ => vec!["--material".into(), "nylon".into()],
    }
}

/// `--flag value`, or `--flag=value` when the value starts with `-` (which a parser would take
/// for a flag), so that negative values reach the value checks.
fn flag(args: &mut Vec<String>, name: &str, value: String) {
    if value.starts_with('-') {
        args.push(format!("{name}={value}"));
    } else {
        args.extend([name.to_string(), value]);
    }
}

fn pick(rng: &mut StdRng, options: &[&str]) -> String {
    options.choose(rng).expect("not empty").to_string()
}

/// The shipped Fig. 7 data, the base of `fit` cases.
pub fn fig7() -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/fig7_nylon.csv");
    std::fs::read_to_string(path).expect("data/fig7_nylon.csv")
}

/// A `fit` case: a sample of the Fig. 7 data (or all of it), mutated, with random flags.
pub fn fit_case(rng: &mut StdRng, base: &Sheet, big_rows: bool) -> Case {
    let mut sheet = base.clone();
    let keep = *[4usize, 10, 120].choose(rng).expect("not empty");
    sheet.rows.truncate(keep);
    if rng.random_bool(0.3) {
        // The e_err form of the errors instead of v_err_m_s.
        if let (Some(cv), Some(ce), Some(cerr)) =
            (sheet.col("v_n_m_s"), sheet.col("e"), sheet.col("v_err_m_s"))
        {
            sheet.header[cerr] = "e_err".into();
            for row in &mut sheet.rows {
                let (v, e, dv): (f64, f64, f64) = (
                    row[cv].parse().unwrap_or(1.0),
                    row[ce].parse().unwrap_or(0.9),
                    row[cerr].parse().unwrap_or(0.01),
                );
                row[cerr] = format!("{}", 2.0 * e * dv / v);
            }
        }
    }
    if rng.random_bool(0.15) {
        sheet.header.push("d2_mm".into());
        let d2 = pick(rng, &["inf", "12.7", "6.35", "0", "-1"]);
        for row in &mut sheet.rows {
            row.push(d2.clone());
        }
    }
    let mutations = mutate(&mut sheet, rng, big_rows);
    let model = pick(rng, &["vm", "pm", "min", "product", "powerlaw", "all"]);
    let mut args = vec!["fit".into(), "data.csv".into()];
    args.extend(material(rng));
    args.extend(["--model".into(), model.clone()]);
    if rng.random_bool(0.3) {
        args.extend(["--contact-end".into(), pick(rng, &["overlap", "force"])]);
    }
    args.extend(["--format".into(), pick(rng, &["table", "csv", "json"])]);
    if rng.random_bool(0.2) {
        args.push("--strict".into());
    }
    if sheet.rows.len() <= 6 && (model == "vm" || model == "pm") && rng.random_bool(0.3) {
        args.push("--exact".into());
    }
    let out_dir = rng.random_bool(0.3);
    if out_dir {
        args.extend(["--out".into(), "{dir}/out".into()]);
    }
    Case {
        label: format!("fit: {}", mutations.join("; ")),
        args,
        files: vec![("data.csv".into(), sheet.to_bytes())],
        out_dir,
    }
}

/// A `walton fit` case: synthetic collisions, mutated, with random flags.
pub fn walton_case(rng: &mut StdRng, big_rows: bool) -> Case {
    let mut spec = SyntheticSpec::paper();
    spec.n = *[3usize, 5, 20, 60].choose(rng).expect("not empty");
    let (_, noisy) = synthetic_collisions(&spec, rng.random()).expect("the synthetic experiment");
    let mut sheet = Sheet::parse(&write_collisions(&noisy));
    let mutations = mutate(&mut sheet, rng, big_rows);
    let mut args = vec!["walton".into(), "fit".into(), "collisions.csv".into()];
    args.extend(material(rng));
    if rng.random_bool(0.2) {
        flag(
            &mut args,
            "--inertia-k",
            flag_value(rng, &["0.4", "1", "0.1"]),
        );
    }
    args.extend(["--weights".into(), pick(rng, &["camera", "equal"])]);
    let boot = if sheet.rows.len() > 1000 {
        pick(rng, &["0", "2", "20", "2000"])
    } else {
        pick(rng, &["0", "1", "2", "50", "2000"])
    };
    args.extend([
        "--bootstrap".into(),
        boot,
        "--seed".into(),
        rng.random::<u32>().to_string(),
    ]);
    args.extend(["--format".into(), pick(rng, &["table", "csv", "json"])]);
    let out_dir = rng.random_bool(0.3);
    if out_dir {
        args.extend(["--out".into(), "{dir}/out".into()]);
    }
    Case {
        label: format!("walton fit: {}", mutations.join("; ")),
        args,
        files: vec![("collisions.csv".into(), sheet.to_bytes())],
        out_dir,
    }
}

/// A `kinematics` case: a simulated film of a few collisions, mutated, with random flags.
pub fn kinematics_case(rng: &mut StdRng, big_rows: bool) -> Case {
    let spec = ExperimentSpec {
        n: rng.random_range(1..=4),
        ..ExperimentSpec::paper()
    };
    let e_of = |_v: f64| Ok(0.9);
    let mut sim_rng = StdRng::seed_from_u64(rng.random());
    let sims = simulate(&spec, &e_of, &mut sim_rng).expect("the virtual experiment");
    let tracks: Vec<CollisionTrack> = sims
        .iter()
        .map(|s| CollisionTrack {
            id: s.id.clone(),
            first_line: 0,
            d1_m: spec.d1_m,
            d2_m: spec.d2_m,
            frames: s.frames.clone(),
            split: rng.random_bool(0.7).then_some(s.split),
            spins_rad_s: rng.random_bool(0.5).then_some(s.spins_measured_rad_s),
        })
        .collect();
    let mut sheet = Sheet::parse(&write_tracks(&tracks));
    let mutations = mutate(&mut sheet, rng, big_rows);
    let mut args = vec!["kinematics".into(), "tracks.csv".into()];
    args.extend(material(rng));
    if rng.random_bool(0.5) {
        args.push("--fixed-gravity".into());
        if rng.random_bool(0.3) {
            flag(&mut args, "--g-m-s2", flag_value(rng, &["9.81", "1.62"]));
        }
    }
    for (name, typical) in [
        ("--inertia-k", &["0.4"][..]),
        ("--s-subpixels", &["2", "0.5"][..]),
        ("--subpixel-m", &["6.25e-5", "1e-4"][..]),
        ("--fov-m", &["0.048", "0.1"][..]),
        ("--pixels-x", &["192", "1", "4000"][..]),
        ("--subpixel-expansion", &["4", "1"][..]),
    ] {
        if rng.random_bool(0.12) {
            flag(&mut args, name, flag_value(rng, typical));
        }
    }
    if rng.random_bool(0.2) {
        args.push("--strict".into());
    }
    args.extend(["--format".into(), pick(rng, &["table", "csv", "json"])]);
    let out_dir = rng.random_bool(0.3);
    if out_dir {
        args.extend(["--out".into(), "{dir}/out".into()]);
    }
    Case {
        label: format!("kinematics: {}", mutations.join("; ")),
        args,
        files: vec![("tracks.csv".into(), sheet.to_bytes())],
        out_dir,
    }
}

/// A `simulate` case: random flags, some extreme.
pub fn simulate_case(rng: &mut StdRng) -> Case {
    let mut args = vec!["simulate".into(), "--out".into(), "{dir}/out".into()];
    args.extend(material(rng));
    args.extend([
        "--n".into(),
        pick(rng, &["0", "1", "2", "10", "60", "1000", "100000"]),
        "--seed".into(),
        rng.random::<u32>().to_string(),
    ]);
    let pairs =
        |rng: &mut StdRng, a: &[&str]| format!("{},{}", flag_value(rng, a), flag_value(rng, a));
    for (name, typical) in [
        ("--d-mm", &["25.4", "6.35"][..]),
        ("--d2-mm", &["12.7"][..]),
        ("--eta", &["190", "0"][..]),
        ("--sigma-y-pa", &["4e7"][..]),
        ("--mu0", &["0.175", "0"][..]),
        ("--beta0", &["0.5", "-1", "1"][..]),
        ("--fps", &["1000", "5000"][..]),
        ("--pixels-x", &["192"][..]),
        ("--pixels-y", &["239"][..]),
        ("--fov-m", &["0.048"][..]),
        ("--subpixel-expansion", &["4"][..]),
        ("--s-subpixels", &["2"][..]),
        ("--spin-noise-rad-s", &["3", "0"][..]),
    ] {
        if rng.random_bool(0.15) {
            flag(&mut args, name, flag_value(rng, typical));
        }
    }
    for (name, typical) in [
        ("--v-n-m-s", &["0.5", "5", "40"][..]),
        ("--incidence-deg", &["0", "30", "80", "90"][..]),
        ("--frames", &["2", "8", "12"][..]),
    ] {
        if rng.random_bool(0.2) {
            flag(&mut args, name, pairs(rng, typical));
        }
    }
    if rng.random_bool(0.2) {
        args.extend([
            "--model".into(),
            pick(rng, &["vm", "pm", "min", "product", "powerlaw", "x"]),
        ]);
    }
    if rng.random_bool(0.1) {
        args.extend([
            "--camera-study".into(),
            "--study-n".into(),
            pick(rng, &["0", "1", "3"]),
        ]);
    }
    Case {
        label: "simulate: flags".into(),
        args,
        files: Vec::new(),
        out_dir: true,
    }
}

/// A `predict` case: random flags, some extreme.
pub fn predict_case(rng: &mut StdRng) -> Case {
    let model = pick(rng, &["vm", "pm"]);
    let mut args = vec!["predict".into(), "--model".into(), model.clone()];
    let list = |rng: &mut StdRng, typical: &[&str]| {
        let n = rng.random_range(1..=4);
        (0..n)
            .map(|_| flag_value(rng, typical))
            .collect::<Vec<_>>()
            .join(",")
    };
    match rng.random_range(0..4) {
        0 if model == "vm" => flag(&mut args, "--kappa", list(rng, &["0.01", "1", "100"])),
        0 => flag(&mut args, "--u", list(rng, &["0.5", "2", "1e6"])),
        _ => {
            args.extend(material(rng));
            flag(&mut args, "--d-mm", flag_value(rng, &["25.4", "6.35"]));
            match rng.random_range(0..3) {
                0 => args.push("--wall".into()),
                1 => flag(&mut args, "--d2-mm", flag_value(rng, &["12.7"])),
                _ => {}
            }
            if model == "vm" {
                flag(&mut args, "--eta", flag_value(rng, &["190", "0", "1e4"]));
            } else {
                flag(&mut args, "--sigma-y-pa", flag_value(rng, &["4e7", "1e9"]));
            }
            flag(&mut args, "--v-m-s", list(rng, &["0.5", "2", "10", "40"]));
        }
    }
    if rng.random_bool(0.3) {
        args.extend(["--contact-end".into(), pick(rng, &["overlap", "force"])]);
    }
    if rng.random_bool(0.25) {
        args.extend([
            "--method".into(),
            pick(rng, &["master", "dop853", "dopri5"]),
        ]);
        if rng.random_bool(0.5) {
            flag(
                &mut args,
                "--tol",
                flag_value(rng, &["1e-6", "1e-11", "1e-3"]),
            );
        }
    }
    args.extend(["--format".into(), pick(rng, &["table", "csv", "json"])]);
    Case {
        label: "predict: flags".into(),
        args,
        files: Vec::new(),
        out_dir: false,
    }
}

/// A `bench` case with a bad flag (a valid bench run takes far longer than a case may).
pub fn bench_case(rng: &mut StdRng) -> Case {
    let bad: &[&[&str]] = &[
        &["bench", "--bogus"],
        &["bench", "--out"],
        &["bench", "--quick=3"],
        &["bench", "--quick", "extra"],
        &["bench", "--out", "blocker/inside"],
        &["bench", "--out", "blocker"],
    ];
    let args: Vec<String> = bad
        .choose(rng)
        .expect("not empty")
        .iter()
        .map(|s| s.to_string())
        .collect();
    Case {
        label: "bench: a bad flag".into(),
        args,
        // A file where the output directory should be.
        files: vec![("blocker".into(), b"not a directory".to_vec())],
        out_dir: false,
    }
}

/// The subcommands the fuzzer drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    Fit,
    Walton,
    Kinematics,
    Predict,
    Simulate,
    Bench,
    Export,
    Track,
}

/// The `i`-th case of `command` in a seeded run (each case its own stream of choices).
pub fn case_of(command: Command, seed: u64, i: u64, fit_base: &Sheet, big_rows: bool) -> Case {
    let stream = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(i.wrapping_mul(0xD1B5_4A32_D192_ED03))
        ^ command as u64;
    let mut rng = StdRng::seed_from_u64(stream);
    let mut c = match command {
        Command::Fit => fit_case(&mut rng, fit_base, big_rows),
        Command::Walton => walton_case(&mut rng, big_rows),
        Command::Kinematics => kinematics_case(&mut rng, big_rows),
        Command::Predict => predict_case(&mut rng),
        Command::Simulate => simulate_case(&mut rng),
        Command::Bench => bench_case(&mut rng),
        Command::Export => export_case(&mut rng),
        Command::Track => track_case(&mut rng),
    };
    c.label = format!("{command:?} case {i} (seed {seed}) {}", c.label);
    c
}

/// The `i`-th case of a seeded run over every subcommand in turn.
pub fn case(seed: u64, i: u64, fit_base: &Sheet, big_rows: bool) -> Case {
    let command = match i % 14 {
        0..=3 => Command::Fit,
        4..=5 => Command::Walton,
        6..=7 => Command::Kinematics,
        8..=9 => Command::Predict,
        10 => Command::Simulate,
        11 => Command::Export,
        12 => Command::Track,
        _ => Command::Bench,
    };
    case_of(command, seed, i, fit_base, big_rows)
}

/// The shipped fit's params.json, the valid input that export cases mutate.
const PARAMS_JSON: &str = include_str!("../../reports/fit/params.json");
/// The shipped Walton fit's walton.json.
const WALTON_JSON: &str = include_str!("../../reports/walton/walton.json");

/// A JSON document with one of its numbers replaced by an extreme value, or cut short, or with
/// bytes that are not UTF-8.
fn mutate_json(rng: &mut StdRng, doc: &str) -> Vec<u8> {
    match rng.random_range(0..8) {
        0 => doc.as_bytes()[..rng.random_range(0..doc.len())].to_vec(),
        1 => {
            let mut b = doc.as_bytes().to_vec();
            let at = rng.random_range(0..b.len());
            b[at] = 0xFF;
            b
        }
        2 => doc.as_bytes().to_vec(),
        _ => {
            // A number token: a digit after ':', ' ', '[' or '-' up to the next ',', ']', '}' or
            // line break.
            let starts: Vec<usize> = doc
                .char_indices()
                .filter(|&(i, c)| {
                    c.is_ascii_digit() && i > 0 && b": [-".contains(&doc.as_bytes()[i - 1])
                })
                .map(|(i, _)| i)
                .collect();
            let Some(&s) = starts.choose(rng) else {
                return doc.as_bytes().to_vec();
            };
            let s = if doc.as_bytes()[s - 1] == b'-' {
                s - 1
            } else {
                s
            };
            let e = s + doc[s..]
                .find([',', ']', '}', '\n'])
                .unwrap_or(doc.len() - s);
            let v = pick(
                rng,
                &[
                    "1e300", "-1e300", "0", "5e-324", "1e-300", "-1", "\"x\"", "null",
                ],
            );
            format!("{}{}{}", &doc[..s], v, &doc[e..]).into_bytes()
        }
    }
}

/// An `export` case: the shipped params.json (mutated or not) or the law as flags, with the
/// scene's flags drawn typical or extreme. No --verify (it needs LAMMPS and takes seconds).
pub fn export_case(rng: &mut StdRng) -> Case {
    let mut args: Vec<String> = vec!["export".into()];
    let mut files = Vec::new();
    let from_file = rng.random_bool(0.5);
    if from_file {
        args.push("params.json".into());
        files.push(("params.json".to_string(), mutate_json(rng, PARAMS_JSON)));
        if rng.random_bool(0.3) {
            args.extend([
                "--model".into(),
                pick(rng, &["vm", "pm", "min", "product", "powerlaw", "nope"]),
            ]);
        }
    } else {
        args.extend(material(rng));
        let model = pick(rng, &["vm", "pm", "min", "product", ""]);
        if !model.is_empty() {
            args.extend(["--model".into(), model]);
        }
        if rng.random_bool(0.7) {
            flag(&mut args, "--eta", flag_value(rng, &["190", "2000"]));
        }
        if rng.random_bool(0.5) {
            flag(&mut args, "--sigma-y-pa", flag_value(rng, &["4e7"]));
        }
        if rng.random_bool(0.3) {
            args.extend(["--contact-end".into(), pick(rng, &["overlap", "force"])]);
        }
    }
    if !from_file || rng.random_bool(0.3) {
        let n = rng.random_range(1..=3);
        let d: Vec<String> = (0..n)
            .map(|_| flag_value(rng, &["6.35", "12.7", "25.4"]))
            .collect();
        flag(&mut args, "--d-mm", d.join(","));
    }
    args.extend([
        "--engine".into(),
        pick(rng, &["lammps", "constant-e", "table"]),
    ]);
    if rng.random_bool(0.7) {
        let lo = flag_value(rng, &["0.5", "1"]);
        let hi = flag_value(rng, &["40", "2"]);
        flag(&mut args, "--v-range", format!("{lo},{hi}"));
    }
    if rng.random_bool(0.3) {
        args.push("--wall".into());
    }
    if rng.random_bool(0.2) {
        flag(&mut args, "--tolerance", flag_value(rng, &["0.01", "0.1"]));
    }
    if rng.random_bool(0.2) {
        flag(
            &mut args,
            "--table-points",
            pick(rng, &["2", "41", "1000", "0", "1", "100001", "-3"]),
        );
    }
    if rng.random_bool(0.2) {
        let n = rng.random_range(1..=3);
        let v: Vec<String> = (0..n)
            .map(|_| flag_value(rng, &["0.5", "3", "20"]))
            .collect();
        flag(&mut args, "--speeds", v.join(","));
    }
    match rng.random_range(0..5) {
        0 => {
            args.extend(["--walton".into(), "walton.json".into()]);
            files.push(("walton.json".to_string(), mutate_json(rng, WALTON_JSON)));
        }
        1 => {
            flag(&mut args, "--mu0", flag_value(rng, &["0.175", "0"]));
            if rng.random_bool(0.5) {
                flag(&mut args, "--beta0", flag_value(rng, &["0.5", "-1", "1"]));
            }
        }
        _ => {}
    }
    if rng.random_bool(0.2) {
        args.extend(["--weight".into(), pick(rng, &["log", "uniform"])]);
    }
    if rng.random_bool(0.2) {
        args.extend([
            "--law".into(),
            pick(rng, &["auto", "viscoelastic", "constant-e"]),
        ]);
    }
    let out_dir = rng.random_bool(0.6);
    if out_dir {
        args.extend(["--out".into(), "{dir}/out".into()]);
    }
    Case {
        label: format!(
            "export: {}",
            if from_file { "params.json" } else { "flags" }
        ),
        args,
        files,
        out_dir,
    }
}

/// An 8-bit grey PNG of two bright discs (radius `r` px, soft 1-px edges) on a dark
/// background, in memory.
fn disc_png(w: u32, h: u32, discs: &[([f64; 2], f64)]) -> Vec<u8> {
    let img = image::GrayImage::from_fn(w, h, |x, y| {
        let mut v = 20.0;
        for &([cx, cy], r) in discs {
            let d = ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt();
            v += 200.0 * (r - d + 0.5).clamp(0.0, 1.0);
        }
        image::Luma([v.min(255.0) as u8])
    });
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .expect("PNG encodes in memory");
    bytes
}

/// A `track` case: one or two directories of frames of two discs closing in, then mutations
/// (a corrupt, blank, resized or three-disc frame, a file without a frame number, an empty
/// directory) and flags drawn typical or extreme.
pub fn track_case(rng: &mut StdRng) -> Case {
    let mut args: Vec<String> = vec!["track".into()];
    let mut files = Vec::new();
    let n_dirs = rng.random_range(1..=2);
    let (w, h, r) = (96, 80, 14.0);
    for k in 0..n_dirs {
        let dir = format!("c{}", k + 1);
        let n = rng.random_range(2..=8);
        for i in 0..n {
            let t = i as f64 / n as f64;
            let discs = [
                ([20.0 + 25.0 * t, 40.0 + 3.0 * t], r),
                ([76.0 - 25.0 * t, 38.0 - 2.0 * t], r),
            ];
            files.push((
                format!("{dir}/frame{:03}.png", 10 + i),
                disc_png(w, h, &discs),
            ));
        }
        args.push(dir);
    }
    let at = rng.random_range(0..files.len());
    match rng.random_range(0..9) {
        0 => {
            let b = &mut files[at].1;
            b.truncate(rng.random_range(0..b.len()));
        }
        1 => files[at].1 = disc_png(w, h, &[]),
        2 => files[at].1 = disc_png(w + 7, h, &[([30.0, 40.0], r), ([70.0, 40.0], r)]),
        3 => {
            files[at].1 = disc_png(
                w,
                h,
                &[([15.0, 40.0], r), ([48.0, 40.0], r), ([81.0, 40.0], r)],
            )
        }
        4 => files.push(("c1/notes.png".into(), disc_png(w, h, &[]))),
        5 => files.retain(|(n, _)| !n.starts_with("c1/")),
        6 => files[at].1 = vec![0xFF; 64],
        _ => {}
    }
    if files.iter().all(|(n, _)| !n.starts_with("c1/")) {
        // The directory must exist to be empty rather than missing.
        files.push(("c1/readme.txt".into(), b"no frames here".to_vec()));
    }
    flag(&mut args, "--fps", flag_value(rng, &["1000", "5000"]));
    match rng.random_range(0..4) {
        0 => flag(&mut args, "--pixel-m", flag_value(rng, &["2.5e-4", "1e-3"])),
        1 => {
            flag(&mut args, "--pixel-m", flag_value(rng, &["2.5e-4"]));
            flag(&mut args, "--d-mm", flag_value(rng, &["7", "12.7"]));
        }
        2 => {
            let d1 = flag_value(rng, &["7", "12.7"]);
            let d2 = flag_value(rng, &["7", "6"]);
            flag(&mut args, "--d-mm", format!("{d1},{d2}"));
        }
        _ => flag(&mut args, "--d-mm", flag_value(rng, &["7", "12.7"])),
    }
    if rng.random_bool(0.2) {
        args.push("--strict".into());
    }
    args.extend(["--format".into(), pick(rng, &["table", "csv", "json"])]);
    let out_dir = rng.random_bool(0.5);
    if out_dir {
        args.extend(["--out".into(), "{dir}/out".into()]);
    }
    Case {
        label: format!(
            "track: {n_dirs} director{}",
            if n_dirs == 1 { "y" } else { "ies" }
        ),
        args,
        files,
        out_dir,
    }
}
