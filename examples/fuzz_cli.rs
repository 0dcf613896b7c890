//! The seeded fuzzer of every subcommand, at any size (the test suite runs a small subset of the
//! same cases in `tests/fuzz_cli.rs`).
//!
//! Run: `cargo run --release --example fuzz_cli -- --cases N [--seed S] [--from I]
//! [--no-big] [--command fit|walton|kinematics|predict|simulate|bench] [--verbose]
//! [--dump DIR]`. It builds the binary first (`cargo build --release --bin
//! restitution`), runs cases I .. I+N of seed S (default 1), prints every failure (command,
//! files, what happened) and a summary, and exits 1 if any case failed. `--no-big` leaves out
//! the 100 000-row files. `--dump DIR` also writes each case's input files and its arguments
//! (`DIR/case-I/args.txt`, one per line, `{dir}` standing for the case's directory), to rerun
//! one by hand.

#[path = "../tests/fuzz/mod.rs"]
mod fuzz;

use fuzz::cases::{Command, Sheet, case, case_of, fig7};
use fuzz::{Runner, Tally, sibling_binary};

fn main() {
    let mut cases = 200u64;
    let mut seed = 1u64;
    let mut from = 0u64;
    let mut big = true;
    let mut verbose = false;
    let mut dump: Option<std::path::PathBuf> = None;
    let mut only: Option<Command> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut num = |name: &str| -> u64 {
            args.next()
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| fail(&format!("{name} needs a whole number")))
        };
        match a.as_str() {
            "--cases" => cases = num("--cases"),
            "--seed" => seed = num("--seed"),
            "--from" => from = num("--from"),
            "--no-big" => big = false,
            "--verbose" => verbose = true,
            "--dump" => {
                dump = Some(
                    args.next()
                        .unwrap_or_else(|| fail("--dump needs a directory"))
                        .into(),
                )
            }
            "--command" => {
                only = Some(match args.next().as_deref() {
                    Some("fit") => Command::Fit,
                    Some("walton") => Command::Walton,
                    Some("kinematics") => Command::Kinematics,
                    Some("predict") => Command::Predict,
                    Some("simulate") => Command::Simulate,
                    Some("bench") => Command::Bench,
                    Some("export") => Command::Export,
                    Some("track") => Command::Track,
                    _ => fail(
                        "--command: fit, walton, kinematics, predict, simulate, bench, export or track",
                    ),
                })
            }
            other => fail(&format!("unknown argument '{other}'")),
        }
    }
    if let Ok(cargo) = std::env::var("CARGO") {
        let ok = std::process::Command::new(cargo)
            .args(["build", "--release", "--quiet", "--bin", "restitution"])
            .status()
            .is_ok_and(|s| s.success());
        if !ok {
            fail("cargo build --release --bin restitution failed");
        }
    }
    let bin = sibling_binary();
    if !bin.exists() {
        fail(&format!(
            "{} not found: run cargo build --release first",
            bin.display()
        ));
    }
    let runner = Runner::new(bin, "example");
    let base = Sheet::parse(&fig7());
    let mut tally = Tally::default();
    for i in from..from + cases {
        let c = match only {
            Some(command) => case_of(command, seed, i, &base, big),
            None => case(seed, i, &base, big),
        };
        if let Some(d) = &dump {
            write_case(&d.join(format!("case-{i}")), &c);
        }
        let r = runner.check(&c, 0);
        if verbose {
            match &r {
                Ok(o) => eprintln!(
                    "{} -> exit {:?} in {:.3} s {}",
                    c.label,
                    o.code,
                    o.elapsed.as_secs_f64(),
                    o.stderr.lines().last().unwrap_or("")
                ),
                Err(e) => eprintln!("{} -> FAIL {e}", c.label),
            }
        }
        tally.add(&c, r);
    }
    for f in &tally.failures {
        println!("FAIL {f}\n");
    }
    println!(
        "{} cases (seed {seed}, from {from}): {} succeeded, {} failed cleanly, {} broke the rules; slowest {:.2} s of wall time ({})",
        tally.cases,
        tally.ok,
        tally.errors,
        tally.failures.len(),
        tally.slowest.0,
        tally.slowest.1
    );
    let _ = std::fs::remove_dir_all(&runner.root);
    if !tally.failures.is_empty() {
        std::process::exit(1);
    }
}

fn write_case(dir: &std::path::Path, c: &fuzz::Case) {
    let written = std::fs::create_dir_all(dir).and_then(|_| {
        for (name, bytes) in &c.files {
            std::fs::write(dir.join(name), bytes)?;
        }
        std::fs::write(dir.join("args.txt"), c.args.join("\n") + "\n")
    });
    if let Err(e) = written {
        fail(&format!("--dump: {}: {e}", dir.display()));
    }
}

fn fail(msg: &str) -> ! {
    eprintln!("fuzz_cli: {msg}");
    std::process::exit(2);
}
