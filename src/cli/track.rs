//! `restitution track`: video frames of collisions to tracked centres and spins.
//!
//! ```text
//! restitution track DIR [DIR ...] --fps F (--pixel-m P | --d-mm D1[,D2])
//!     [--out OUT] [--format table|csv|json] [--strict]
//! ```
//! Each DIR holds one collision's frames (PNG 8/16-bit grey or colour, TIFF), ordered by the
//! integer in the file name; the collision id is the directory's name; t_s = (frame number -
//! first frame number) / fps. Coordinates in metres, x right, y up, origin at the image's
//! bottom-left corner. Without --pixel-m the pixel size comes from the known diameters.
//! stdout: a summary per collision (table), tracks.csv (csv) or everything (json).
//! `--out OUT` writes tracks.csv (the `kinematics` schema, with spins), detections.csv,
//! spins.csv, collisions.csv and overlay_<collision>.svg, all or none. A bad frame is left out
//! with a warning naming it (`--strict`: an error).

use super::{CliResult, Format, emit, warn};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use restitution::data::frames::job::{TrackRequest, track_dirs, track_files, warnings};
use restitution::data::frames::{count_frames, results_json_text, tracks_csv};
use restitution::data::report::track::to_table;
use restitution::data::{ArgStyle, write_all_atomic};
use std::io::IsTerminal;
use std::path::PathBuf;

/// Sphere centres and spins from video frames (one directory per collision)
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Directories of frames, one collision each
    #[arg(value_name = "DIR", required = true)]
    dirs: Vec<PathBuf>,
    /// Frame rate, frames per second
    #[arg(long, value_name = "F", allow_negative_numbers = true)]
    fps: f64,
    /// Pixel size in the object plane, m
    #[arg(long = "pixel-m", value_name = "P", allow_negative_numbers = true)]
    pixel_m: Option<f64>,
    /// Sphere diameters, mm (one value: both spheres)
    #[arg(
        long = "d-mm",
        value_name = "D1[,D2]",
        value_delimiter = ',',
        num_args = 1..=2,
        allow_negative_numbers = true
    )]
    d_mm: Option<Vec<f64>>,
    /// Write tracks.csv, detections.csv, spins.csv, collisions.csv and overlays here
    #[arg(long, value_name = "OUT")]
    out: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "table")]
    format: Format,
    /// A bad frame is an error instead of a warning
    #[arg(long)]
    strict: bool,
}

pub fn run(args: Args) -> CliResult {
    let request = TrackRequest {
        style: ArgStyle::Flags,
        fps: args.fps,
        pixel_m: args.pixel_m,
        d_mm: args.d_mm,
        strict: args.strict,
    };
    // Checked before the frames are counted, so a bad flag fails at once.
    request.settings().map_err(|e| e.to_string())?;
    let total: usize = args.dirs.iter().map(|d| count_frames(d)).sum();
    let bar = if std::io::stderr().is_terminal() {
        ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr())
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed}")
            .map_err(|e| e.to_string())?,
    );
    let results = track_dirs(&args.dirs, &request, &|| bar.inc(1)).map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    for w in warnings(&results) {
        warn(w);
    }
    if let Some(out) = &args.out {
        let files: Vec<(PathBuf, Vec<u8>)> = track_files(&results)
            .map_err(|e| e.to_string())?
            .into_iter()
            .map(|(name, bytes)| (out.join(name), bytes))
            .collect();
        std::fs::create_dir_all(out)
            .map_err(|e| format!("{}: cannot create the directory: {e}", out.display()))?;
        write_all_atomic(&files).map_err(|e| format!("{}: cannot write: {e}", out.display()))?;
    }
    emit(&match args.format {
        Format::Csv => tracks_csv(&results),
        Format::Json => results_json_text(&results),
        Format::Table => to_table(&results),
    })
}
