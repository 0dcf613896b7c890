//! The failures of the engine files and of the LAMMPS round trip, as values: the job
//! ([`super::job::ExportError`]) carries them as fields, so no caller reads or rewrites their
//! text. Each prints as the one line the command line shows.

use crate::data::fmt_num;

/// Why the engine files of an export (in.restitution, collide.in, constant_e.csv, table.csv)
/// could not be built for a law.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FilesFailure {
    /// The file needs the scene's speed range, which the translation was made without (what
    /// needs it, as the message says it).
    #[error("{0}")]
    NeedsSpeedRange(&'static str),
    /// No engine input gives a pair's constant e.
    #[error("constant e: {0}")]
    ConstantE(crate::error::Error),
    /// A pair at one of collide.in's speeds is overdamped beyond what the exported law is
    /// meant for (kappa > 1000, e < 1e-10).
    #[error(
        "pair {pair} at {} m/s: dimensionless damping kappa = {} (eta = {} kg/(s m)); beyond 1000 the collision is overdamped (e < 1e-10): lower eta or the speed",
        fmt_num(*v_m_s),
        fmt_num(*kappa),
        fmt_num(*eta)
    )]
    Overdamped {
        pair: String,
        v_m_s: f64,
        kappa: f64,
        eta: f64,
    },
    /// A pair's constant e lies beyond what an engine's damping input can ask for: writing the
    /// nearest input would give another e without a word (LAMMPS's `damping tsuji` polynomial
    /// damps at most alpha = 1.2728; LIGGGHTS's formula with limitForce on reaches no e below
    /// its value at critical damping).
    #[error(
        "pair {pair}: a constant e of {} is out of reach of {engine} (the most damping its input can ask for gives e = {}); use --engine table, or --engine lammps with the viscoelastic law",
        crate::data::significant(*e, 4),
        crate::data::significant(*e_floor, 4)
    )]
    OutOfReach {
        pair: String,
        engine: &'static str,
        e: f64,
        e_floor: f64,
    },
    /// The toolkit could not predict collide.in's collisions.
    #[error("cannot predict the collisions: {0}")]
    Collisions(crate::error::Error),
    /// collide.in would hold no collision.
    #[error("no collision to write")]
    NoCollision,
    /// collide.in's contacts last too different times for one run at the shortest one's step.
    #[error(
        "collide.in: contacts last from {shortest_s:.3e} s to {longest_s:.3e} s, too wide for one run at the shortest one's step; give --speeds closer together"
    )]
    ContactsTooWide { shortest_s: f64, longest_s: f64 },
}

/// Why the LAMMPS round trip could not be run, or its output not read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunFailure {
    /// `lmp` is not on PATH.
    #[error(
        "lmp (LAMMPS) is not on PATH: install it (Debian/Ubuntu: apt-get install lammps) or run collide.in yourself"
    )]
    NotOnPath,
    /// `lmp` could not be started (the system's reason).
    #[error("cannot run lmp: {0}")]
    CannotStart(String),
    /// `lmp` stopped with an error: the directory, its exit status and its first ERROR line.
    #[error("lmp failed on {dir}/collide.in ({status}): {error_line}")]
    Failed {
        dir: String,
        status: String,
        error_line: String,
    },
    /// A `restitution-e` line of collide.in's output without one of its fields.
    #[error("collide.in output line without '{field}': {line}")]
    MissingField { field: String, line: String },
    /// A `restitution-e` line whose e or gap (`what`) is not a number.
    #[error("collide.in printed a non-number {what}: {line}")]
    NotANumber { what: &'static str, line: String },
    /// A `restitution-e` line whose e is not finite.
    #[error("collide.in printed e = {e}: {line}")]
    NonFiniteE { e: f64, line: String },
    /// A collision whose spheres were still in contact (or overlapping) when the run stopped.
    #[error("a collision had not ended when the run stopped (gap {gap_m} m): {line}")]
    NotEnded { gap_m: f64, line: String },
    /// The output has no `restitution-e` line at all.
    #[error("collide.in printed no restitution-e lines")]
    NoOutput,
    /// The output has no line for one of the collisions (pair and speed as collide.in names
    /// them).
    #[error("collide.in printed nothing for pair {pair} at {v_m_s} m/s")]
    MissingCollision { pair: String, v_m_s: String },
    /// The ladder of steps is not at least two rungs, each twice the last.
    #[error("the step ladder needs at least two rungs, each twice the last")]
    Ladder,
    /// The private directory of the run could not be made or written (`action`: what failed;
    /// the system's reason).
    #[error("{dir}: cannot {action}: {reason}")]
    Scratch {
        dir: String,
        action: &'static str,
        reason: String,
    },
}
