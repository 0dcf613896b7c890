//! `restitution simulate --frames-out` as a user runs it: the directory layout, the truth file,
//! the frame format, determinism, tracks unchanged by rendering, and one-line errors that leave
//! nothing behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_restitution"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn tmp(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("restitution-render-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn simulate(out: &Path, frames: Option<&Path>, extra: &[&str]) -> Output {
    let mut args = vec![
        "simulate",
        "--material",
        "nylon",
        "--n",
        "2",
        "--seed",
        "4",
        "--d-mm",
        "12.7",
        "--v-n-m-s",
        "1,3",
        "--out",
        s(out),
    ];
    if let Some(f) = frames {
        args.extend(["--frames-out", s(f)]);
    }
    args.extend(extra);
    run(&args)
}

#[test]
fn layout_truth_and_determinism() {
    let (out, frames) = (tmp("a"), tmp("af"));
    let o = simulate(&out, Some(&frames), &["--exposure-s", "2e-4"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let truth = std::fs::read_to_string(frames.join("truth.csv")).unwrap();
    let mut lines = truth.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        &header[..7],
        &[
            "collision",
            "frame",
            "file",
            "t_s",
            "phase",
            "subframes",
            "sphere"
        ]
    );
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    // Two rows (spheres) per frame, every frame's file present and a 192 x 239 8-bit grey PNG.
    let tracks = std::fs::read_to_string(out.join("tracks.csv")).unwrap();
    let tracked_frames = tracks.lines().filter(|l| !l.starts_with('#')).count() - 1;
    assert_eq!(rows.len(), 2 * tracked_frames);
    for r in rows.iter().step_by(2) {
        let bytes = std::fs::read(frames.join(&r[2])).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        // IHDR: width and height (big-endian) at bytes 16..24, bit depth 8, colour type 0 (grey).
        let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
        let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
        assert_eq!((w, h, bytes[24], bytes[25]), (192, 239, 8, 0));
    }
    assert!(frames.join("c1").join("frame_000000.png").exists());
    assert!(frames.join("c2").is_dir());
    // Radius 6.35 mm on 0.25 mm pixels.
    let radius_px: f64 = rows[0][header.iter().position(|h| *h == "radius_px").unwrap()]
        .parse()
        .unwrap();
    assert!((radius_px - 25.4).abs() < 1e-9);
    // The same flags give the same bytes; rendering does not change the tracks.
    let (out2, frames2) = (tmp("b"), tmp("bf"));
    assert!(
        simulate(&out2, Some(&frames2), &["--exposure-s", "2e-4"])
            .status
            .success()
    );
    for f in [
        "truth.csv",
        "render.json",
        "c1/frame_000003.png",
        "c2/frame_000000.png",
    ] {
        assert_eq!(
            std::fs::read(frames.join(f)).unwrap(),
            std::fs::read(frames2.join(f)).unwrap(),
            "{f}"
        );
    }
    let out3 = tmp("c");
    assert!(simulate(&out3, None, &[]).status.success());
    assert_eq!(
        std::fs::read(out.join("tracks.csv")).unwrap(),
        std::fs::read(out3.join("tracks.csv")).unwrap()
    );
    for d in [out, frames, out2, frames2, out3] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn bad_rendering_flags_are_one_line_errors_and_write_nothing() {
    for (flag, value, says) in [
        ("--lighting", "disco", "--lighting 'disco'"),
        ("--markers", "stars", "--markers 'stars'"),
        ("--bits", "12", "--bits 12"),
        ("--sphere-albedo", "5", "sphere brightness"),
        ("--background", "nan", "background"),
        ("--read-noise", "2", "read noise"),
        ("--exposure-s", "1", "exposure"),
        ("--lamps", "1,2,3", "--lamps"),
        ("--marker-radius-deg", "1e300", "--marker-radius-deg"),
    ] {
        let (out, frames) = (tmp("e"), tmp("ef"));
        let o = simulate(&out, Some(&frames), &[flag, value]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{flag} {value} was accepted");
        assert_eq!(err.trim().lines().count(), 1, "{flag}: {err}");
        assert!(err.contains(says), "{flag}: {err}");
        assert!(!out.join("tracks.csv").exists() && !frames.join("truth.csv").exists());
    }
}

/// The physics flags' errors name the flag and its values: a speed or angle range out of order
/// or out of bounds, and a model that cannot be evaluated at the range's ends (V_Y underflowing
/// for a tiny sigma_y). They were reported as "the virtual experiment failed with" every physics
/// flag, defaults included, and the library's name for the quantity.
#[test]
fn bad_physics_flags_name_themselves() {
    for (extra, says) in [
        (
            &["--v-n-m-s", "2,1"][..],
            "--v-n-m-s 2,1: expected speeds 0 < MIN <= MAX (m/s)",
        ),
        (
            &["--v-n-m-s", "1,inf"][..],
            "--v-n-m-s 1,inf: expected speeds",
        ),
        (
            &["--v-n-m-s", "1,2", "--incidence-deg", "90,90"][..],
            "--incidence-deg 90,90: expected angles 0 <= MIN <= MAX < 90 (degrees)",
        ),
        (
            &[
                "--v-n-m-s",
                "1,2",
                "--model",
                "pm",
                "--sigma-y-pa",
                "1e-200",
            ][..],
            "--sigma-y-pa 1e-200 (--model pm, v_n = 1 m/s): V_Y (m/s) = 0 is out of the range of f64 \
             (underflow)",
        ),
    ] {
        let out = tmp("physics");
        let mut args = vec![
            "simulate",
            "--material",
            "nylon",
            "--n",
            "2",
            "--out",
            s(&out),
        ];
        args.extend(extra);
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{extra:?} was accepted");
        assert_eq!(err.trim().lines().count(), 1, "{extra:?}: {err}");
        assert!(
            err.starts_with(&format!("restitution: error: {says}")),
            "{err}"
        );
        assert!(!out.join("tracks.csv").exists());
    }
}

/// The camera study with a field of view of 1e-6 m: two frames per phase, so free quadratic
/// fits measure nothing and their lines had vanished from the figure without a word; it now
/// says so under the panels. Flags the study does not use (`--n`, `--v-n-m-s`; it has its own
/// speeds) and `--study-n` without the study are refused instead of ignored, and a missing
/// argument is named (clap's list on the lines below its first had been cut off).
#[test]
fn the_camera_study_says_what_it_leaves_out_and_refuses_what_it_ignores() {
    let out = tmp("study-fov");
    let r = run(&[
        "simulate",
        "--material",
        "nylon",
        "--camera-study",
        "--study-n",
        "5",
        "--fov-m",
        "1e-6",
        "--out",
        s(&out),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let svg = std::fs::read_to_string(out.join("camera_study.svg")).unwrap();
    assert!(
        svg.contains(
            "No free quadratic fit line: fewer than 2 collisions measured at every speed."
        ),
        "{svg}"
    );
    assert!(
        svg.contains("28 of 56 camera, fit and speed points left out"),
        "{svg}"
    );
    assert!(!svg.contains(">\n-0.0\n<"), "a tick printed -0.0");
    for (args, says) in [
        (
            &["--camera-study", "--v-n-m-s", "1,2"][..],
            "'--camera-study' cannot be used with '--v-n-m-s",
        ),
        (
            &["--camera-study", "--n", "3"][..],
            "cannot be used with '--n",
        ),
        (
            &["--study-n", "3"][..],
            "the following required arguments were not provided: --camera-study",
        ),
    ] {
        let dir = tmp("study-refused");
        let mut a = vec!["simulate", "--material", "nylon", "--out", s(&dir)];
        a.extend(args);
        let r = run(&a);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!dir.exists());
    }
    let r = run(&["fit"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("not provided: <DATA.csv>"), "{err}");
}
