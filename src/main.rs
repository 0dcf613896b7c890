//! The `restitution` binary: a thin front end over the library (see `src/cli/`).

mod cli;

use clap::error::ErrorKind;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Coefficient of restitution of colliding spheres (Labous, Rosato & Dave, PRE 56, 5717, 1997).
#[derive(Parser)]
#[command(name = "restitution", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// e(v) from the viscoelastic or plastic model
    Predict(cli::predict::Args),
    /// Speed against accuracy: work-precision chart and stability map of every method
    Bench(cli::bench::Args),
    /// Fit eta and sigma_y (and more) to measured e(v_n), with uncertainties and a model comparison
    Fit(cli::fit::Args),
    /// Velocities, e, beta and psi from tracked sphere centres (Sec. III)
    Kinematics(cli::kinematics::Args),
    /// A virtual experiment: simulated tracks of collisions seen by a high-speed camera
    Simulate(cli::simulate::Args),
    /// Sphere centres and spins from video frames, one directory per collision (Sec. III)
    Track(cli::track::Args),
    /// Walton's collision operator: fit e, beta_0 and mu_0 to oblique collisions (Fig. 6)
    Walton(cli::walton::Args),
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so `restitution ... | head` would panic on the closed pipe; the
    // default action ends the process quietly, as Unix tools do.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread or I/O exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            return match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    let _ = e.print();
                    ExitCode::SUCCESS
                }
                _ => {
                    // One line: clap's first line names the flag and the value.
                    let text = e.render().to_string();
                    let first = text.lines().next().unwrap_or("invalid arguments");
                    let first = first.strip_prefix("error: ").unwrap_or(first);
                    eprintln!("restitution: error: {first} (see --help)");
                    ExitCode::from(2)
                }
            };
        }
    };
    let result = match cli.command {
        Command::Predict(args) => cli::predict::run(args),
        Command::Bench(args) => cli::bench::run(args),
        Command::Fit(args) => cli::fit::run(args),
        Command::Walton(args) => cli::walton::run(args),
        Command::Kinematics(args) => cli::kinematics::run(args),
        Command::Simulate(args) => cli::simulate::run(args),
        Command::Track(args) => cli::track::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("restitution: error: {msg}");
            ExitCode::FAILURE
        }
    }
}
