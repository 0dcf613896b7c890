//! The `restitution` binary: a thin front end over the library (see `src/cli/`).

mod cli;

use clap::error::ErrorKind;
use clap::{Parser, Subcommand};
use std::any::Any;
use std::io::Write;
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
    /// A fitted contact law as simulation-engine input (LAMMPS, constant-e engines, tables)
    Export(cli::export::Args),
}

/// Whether a panic is the standard library's `print!` failing on a closed stdout or stderr (the
/// reader of a pipe has gone). Subcommands that write through [`cli::emit`] never get there;
/// this covers the ones that still use `print!`.
fn is_closed_pipe_panic(payload: &(dyn Any + Send)) -> bool {
    let text = payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied());
    text.is_some_and(|t| {
        (t.starts_with("failed printing to stdout") || t.starts_with("failed printing to stderr"))
            && (t.contains("Broken pipe") || t.contains("os error 32"))
    })
}

/// One line on stderr; a closed stderr is ignored (there is nobody to tell).
fn error_line(message: impl std::fmt::Display) {
    let _ = writeln!(std::io::stderr(), "restitution: error: {message}");
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so writing to a closed pipe is an error value, not a signal: a closed
    // stdout ends the command quietly with exit 0 (as `restitution ... | head` expects), either
    // through `cli::emit` or, for `print!`, through the panic it raises, silenced here.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !is_closed_pipe_panic(info.payload()) {
            default_hook(info);
        }
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            return match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    let _ = e.print();
                    ExitCode::SUCCESS
                }
                _ => {
                    // One line: clap's first line names the flag and the value, or ends in
                    // a colon with the names on the indented lines below (missing arguments:
                    // their names had been cut off).
                    let text = e.render().to_string();
                    let mut lines = text.lines();
                    let first = lines.next().unwrap_or("invalid arguments");
                    let mut first = first.strip_prefix("error: ").unwrap_or(first).to_string();
                    if first.ends_with(':') {
                        let names: Vec<&str> = lines
                            .take_while(|l| l.starts_with("  "))
                            .map(str::trim)
                            .collect();
                        first = format!("{first} {}", names.join(", "));
                    }
                    error_line(format_args!("{first} (see --help)"));
                    ExitCode::from(2)
                }
            };
        }
    };
    let run = std::panic::catch_unwind(move || match cli.command {
        Command::Predict(args) => cli::predict::run(args),
        Command::Bench(args) => cli::bench::run(args),
        Command::Fit(args) => cli::fit::run(args),
        Command::Walton(args) => cli::walton::run(args),
        Command::Kinematics(args) => cli::kinematics::run(args),
        Command::Simulate(args) => cli::simulate::run(args),
        Command::Track(args) => cli::track::run(args),
        Command::Export(args) => cli::export::run(args),
    });
    match run {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(msg)) => {
            error_line(msg);
            ExitCode::FAILURE
        }
        Err(payload) if is_closed_pipe_panic(payload.as_ref()) => ExitCode::SUCCESS,
        Err(payload) => std::panic::resume_unwind(payload),
    }
}
