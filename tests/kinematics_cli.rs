//! `kinematics` on tracks with spins: an empty spin cell (a sphere whose spin `track` could not
//! measure) is taken as 0 and the command says so, naming the collision and the cell; beta
//! changes with the spin, so the number printed depends on it and the warning is not cosmetic.

use std::path::PathBuf;
use std::process::Command;

fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_restitution"))
}

fn tracks() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/reports/track/tracks.csv"
    ))
    .unwrap()
}

/// Runs `kinematics` on `text` (CSV output) with `flags` and returns (stdout, stderr).
fn kinematics(tag: &str, text: &str, flags: &[&str]) -> (String, String) {
    let dir = std::env::temp_dir().join(format!("restitution-kin-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tracks.csv");
    std::fs::write(&path, text).unwrap();
    let o = Command::new(bin())
        .args(["kinematics", path.to_str().unwrap(), "--material", "nylon"])
        .args(["--format", "csv"])
        .args(flags)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (
        String::from_utf8(o.stdout).unwrap(),
        String::from_utf8(o.stderr).unwrap(),
    )
}

/// The text with column `name` emptied in every row.
fn blank(text: &str, name: &str) -> String {
    let mut lines = text.lines();
    let head = lines.next().unwrap();
    let j = head.split(',').position(|c| c == name).unwrap();
    let mut out = vec![head.to_string()];
    for l in lines {
        let mut f: Vec<&str> = l.split(',').collect();
        f[j] = "";
        out.push(f.join(","));
    }
    out.join("\n") + "\n"
}

fn beta(csv: &str) -> String {
    let mut lines = csv.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let j = head.iter().position(|c| *c == "beta").unwrap();
    lines.next().unwrap().split(',').nth(j).unwrap().to_string()
}

#[test]
fn an_unmeasured_spin_is_named_not_silently_zero() {
    let full = tracks();
    let (out_full, err_full) = kinematics("full", &full, &[]);
    assert!(!err_full.contains("not measured"), "{err_full}");
    let (out_blank, err_blank) = kinematics("blank", &blank(&full, "w2z_post_rad_s"), &[]);
    assert!(
        err_blank.contains("collision 'shot_7': w2z_post_rad_s not measured (empty): taken as 0"),
        "{err_blank}"
    );
    // And it matters: sphere 2's post-collision spin enters beta.
    assert_ne!(beta(&out_full), beta(&out_blank));
}

/// Runs `kinematics` on the committed track with extra flags; (exit ok, stdout, stderr).
fn kinematics_with(tag: &str, flags: &[&str]) -> (bool, String, String) {
    let dir = std::env::temp_dir().join(format!("restitution-kinf-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tracks.csv");
    std::fs::write(&path, tracks()).unwrap();
    let out = dir.join("out");
    let o = Command::new(bin())
        .args(["kinematics", path.to_str().unwrap(), "--material", "nylon"])
        .args(["--out", out.to_str().unwrap()])
        .args(flags)
        .output()
        .unwrap();
    let wrote = out.exists();
    let _ = std::fs::remove_dir_all(&dir);
    let ok = o.status.success();
    assert_eq!(
        ok, wrote,
        "output written exactly when the command succeeds"
    );
    (
        ok,
        String::from_utf8(o.stdout).unwrap(),
        String::from_utf8(o.stderr).unwrap(),
    )
}

#[test]
fn the_subpixel_size_is_checked_given_or_derived() {
    // Eq. (8)'s subpixel, given (--subpixel-m) or derived (--fov-m / --pixels-x /
    // --subpixel-expansion), must lie in [1e-12, 1] m, as track's pixel size: a subnormal
    // --fov-m gave a subpixel of 0 m and "inf subpixels" on stdout.
    for (tag, flags, named) in [
        (
            "sub0",
            &["--subpixel-m", "5e-324"][..],
            "--subpixel-m 5e-324",
        ),
        ("sub1", &["--subpixel-m", "9e-13"][..], "--subpixel-m 9e-13"),
        ("sub2", &["--subpixel-m", "1.5"][..], "--subpixel-m 1.5"),
        ("fov0", &["--fov-m", "5e-324"][..], "--fov-m 5e-324"),
        (
            "fov1",
            &["--fov-m", "1e300", "--subpixel-expansion", "1e-300"][..],
            "--subpixel-expansion 1e-300",
        ),
    ] {
        let (ok, stdout, stderr) = kinematics_with(tag, flags);
        assert!(!ok && stdout.is_empty(), "{flags:?}: {stdout}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{flags:?}: {stderr}");
        assert!(
            stderr.contains(named) && stderr.contains("[1e-12, 1] m"),
            "{flags:?}: {stderr}"
        );
    }
    // The ends of the range are sizes like any other: a number of subpixels, finite.
    for (tag, p) in [("lo", "1e-12"), ("hi", "1")] {
        let (ok, stdout, stderr) = kinematics_with(tag, &["--subpixel-m", p]);
        assert!(ok, "--subpixel-m {p}: {stderr}");
        let last = stdout.lines().last().unwrap();
        assert!(
            last.contains(&format!("subpixels of {p} m")) && !last.contains("inf"),
            "{last}"
        );
    }
}

#[test]
fn the_files_say_how_many_collisions_were_skipped() {
    // The committed collision and a copy of it with one frame before and after the contact: the
    // copy cannot be measured, is skipped with a warning, and every file written says so.
    let full = tracks();
    let mut lines = full.lines();
    let head = lines.next().unwrap();
    let rows: Vec<&str> = lines.collect();
    let short: Vec<String> = [rows[0], rows[rows.len() - 1]]
        .iter()
        .map(|l| l.replacen("shot_7", "short", 1))
        .collect();
    let text = format!("{head}\n{}\n{}\n", rows.join("\n"), short.join("\n"));
    let dir = std::env::temp_dir().join(format!("restitution-kin-skip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tracks.csv");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let o = Command::new(bin())
        .args(["kinematics", path.to_str().unwrap(), "--material", "nylon"])
        .args(["--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("skipped") && err.contains("'short'"), "{err}");
    for f in ["fit_input.csv", "kinematics.csv", "walton_input.csv"] {
        let text = std::fs::read_to_string(out.join(f)).unwrap();
        let first = text.lines().next().unwrap();
        assert!(
            first.starts_with('#') && first.contains("; 1 of 2 collisions skipped"),
            "{f}: {first}"
        );
    }
    // So does every format on stdout: a table or document kept in a file loses the warnings.
    let printed = |format: &str| {
        let o = Command::new(bin())
            .args(["kinematics", path.to_str().unwrap(), "--material", "nylon"])
            .args(["--format", format])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    let table = printed("table");
    assert!(
        table.contains("(1 of 2 collisions skipped: they cannot be measured"),
        "{table}"
    );
    let csv = printed("csv");
    assert_eq!(
        csv,
        std::fs::read_to_string(out.join("kinematics.csv")).unwrap()
    );
    let doc: serde_json::Value = serde_json::from_str(&printed("json")).unwrap();
    assert_eq!(doc["collisions"].as_array().unwrap().len(), 1);
    assert_eq!(doc["collisions"][0]["collision"], "shot_7");
    let skipped = doc["skipped"].as_array().unwrap();
    assert_eq!(skipped.len(), 1);
    let why = skipped[0].as_str().unwrap();
    assert!(
        why.contains("collision 'short'") && why.contains("frames"),
        "{why}"
    );
    assert_eq!(doc["unmeasured_spins"], serde_json::json!([]));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Flags every collision depends on are checked by name: with `--inertia-k 1e300` (Walton's
/// bodies take K in (0, 1]) or `--fixed-gravity --g-m-s2 1e300` every collision was skipped and
/// the error gave the first collision's own reason; where a whole file cannot be measured the
/// error now says so.
#[test]
fn flags_that_no_collision_survives_are_named() {
    for (tag, flags, named) in [
        (
            "k",
            &["--inertia-k", "1e300"][..],
            "--inertia-k 1e300: expected a number in (0, 1]",
        ),
        (
            "g",
            &["--fixed-gravity", "--g-m-s2", "1e300"][..],
            "--g-m-s2 1e300: expected a number > 0, at most 1e6 m/s^2 (1e5 g, a centrifuge's)",
        ),
    ] {
        let (ok, stdout, stderr) = kinematics_with(tag, flags);
        assert!(!ok && stdout.is_empty(), "{flags:?}: {stdout}");
        assert!(
            stderr.starts_with(&format!("restitution: error: {named}")),
            "{stderr}"
        );
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    }
    // Every collision of a file too short to measure: the error counts them.
    let text = tracks();
    let mut lines = text.lines();
    let head = lines.next().unwrap();
    let id = head.split(',').position(|c| c == "collision").unwrap();
    let first_id = lines
        .clone()
        .next()
        .unwrap()
        .split(',')
        .nth(id)
        .unwrap()
        .to_string();
    // Two copies of the first collision's first two frames, under two ids.
    let rows: Vec<&str> = lines
        .filter(|l| l.split(',').nth(id) == Some(&first_id))
        .take(2)
        .collect();
    let mut short = vec![head.to_string()];
    for copy in ["a", "b"] {
        for r in &rows {
            let mut f: Vec<&str> = r.split(',').collect();
            f[id] = copy;
            short.push(f.join(","));
        }
    }
    let dir = std::env::temp_dir().join(format!("restitution-kin-none-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tracks.csv");
    std::fs::write(&path, short.join("\n") + "\n").unwrap();
    let o = Command::new(bin())
        .args(["kinematics", path.to_str().unwrap(), "--material", "nylon"])
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(!o.status.success());
    assert!(
        err.starts_with("restitution: error: none of the 2 collisions of ")
            && err.contains("could be measured; the first: ")
            && err.contains("collision 'a'"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

/// A collision whose spheres still approach after it (here they keep closing at 1 m/s: e = -0.5
/// by the formula, surfaces that would interpenetrate) is no measurement of e: skipped with a
/// warning naming it, while a proper one beside it is measured (e = 0.9 exactly: each sphere at
/// 1 m/s before and 0.9 m/s after; straight tracks, fixed gravity with a negligible g).
#[test]
fn a_collision_still_approaching_afterwards_is_skipped() {
    let d = 0.0127;
    let mut text = String::from("collision,t_s,x1_m,y1_m,x2_m,y2_m,d1_mm,d2_mm,phase\n");
    for (id, v_post) in [("good", -0.9), ("closing", 0.5)] {
        for k in (-6..=6).filter(|&k| k != 0) {
            let t = f64::from(k) * 1e-3;
            let (v, phase) = if t < 0.0 {
                (1.0, "pre")
            } else {
                (v_post, "post")
            };
            let (x1, x2) = (-d / 2.0 + v * t, d / 2.0 - v * t);
            text += &format!("{id},{t},{x1},0,{x2},0,12.7,12.7,{phase}\n");
        }
    }
    let (out, err) = kinematics("closing", &text, &["--fixed-gravity", "--g-m-s2", "1e-9"]);
    assert!(
        err.contains("skipped") && err.contains("'closing'") && err.contains("after the collision"),
        "{err}"
    );
    let rows: Vec<&str> = out.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows.len(), 2, "{out}");
    let head: Vec<&str> = rows[0].split(',').collect();
    let cells: Vec<&str> = rows[1].split(',').collect();
    let e: f64 = cells[head.iter().position(|c| *c == "e").unwrap()]
        .parse()
        .unwrap();
    // Exact straight tracks: e to the fits' rounding.
    assert!((e - 0.9).abs() < 1e-9, "{e}");
    assert_eq!(cells[0], "good");
}

/// The table's fixed-decimals columns switch to exponent form for large values: an absurd
/// `--s-subpixels 1e300` (Eq. 8's claimed centre accuracy) had printed e_eq8 with 300 digits.
#[test]
fn huge_values_print_in_exponent_form() {
    let (ok, out, err) = kinematics_with("huge-s", &["--s-subpixels", "1e300"]);
    assert!(ok, "{err}");
    let rows: Vec<&str> = out
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with('('))
        .collect();
    assert!(!rows.is_empty(), "{out}");
    for row in rows {
        let e_eq8 = row.split_whitespace().nth(4).unwrap();
        assert!(
            e_eq8.len() <= 10 && e_eq8.contains("e29"),
            "{e_eq8} in {row}"
        );
    }
}
