//! A Rust user can depend on the core alone (`restitution = { version = "0.1",
//! default-features = false }`): the physics, numerics, fits, kinematics, frame analysis and DEM
//! laws build without the I/O (`io`), figure (`plot`) and command-line (`cli`) features, and pull
//! in none of their dependencies; each of `io` and `plot` also builds without the others.

use std::path::Path;
use std::process::Command;

const LAYER_DEPENDENCIES: [&str; 7] = [
    "csv",
    "serde",
    "serde_json",
    "plotters",
    "clap",
    "image",
    "indicatif",
];

fn cargo() -> Command {
    // Set by `cargo test` for the tests it runs.
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// The crate's direct normal dependencies under the given feature flags.
fn direct_dependencies(flags: &[&str]) -> Vec<String> {
    let out = cargo()
        .args(["tree", "-e", "normal", "--depth", "1", "--prefix", "none"])
        .args(flags)
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .skip(1) // the crate itself
        .filter_map(|l| l.split(' ').next().map(str::to_string))
        .collect()
}

#[test]
fn the_core_builds_without_io_plot_or_cli() {
    // A target directory of its own: the features differ from the test build's, and sharing
    // one directory would make each build invalidate the other.
    // Warnings are errors: code gated behind the wrong feature shows up as unused imports.
    // Each layer is checked alone as well (the core plus `io`, the core plus `plot`): a file
    // format or a figure must not lean on another layer's feature.
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/core-only");
    for features in ["", "io", "plot"] {
        let out = cargo()
            .args(["check", "--lib", "--no-default-features", "--quiet"])
            .args(["--features", features])
            .env("CARGO_TARGET_DIR", &target)
            .env("RUSTFLAGS", "-D warnings")
            .output()
            .expect("cargo check runs");
        assert!(
            out.status.success(),
            "the core with features [{features}] does not build:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let core = direct_dependencies(&["--no-default-features"]);
    for d in LAYER_DEPENDENCIES {
        assert!(
            !core.iter().any(|c| c == d),
            "{d} is a dependency of the core: {core:?}"
        );
    }
    // The check can fail: the default build (the command line) has every one of them.
    let full = direct_dependencies(&[]);
    for d in LAYER_DEPENDENCIES {
        assert!(full.iter().any(|c| c == d), "{d} missing from {full:?}");
    }
}
