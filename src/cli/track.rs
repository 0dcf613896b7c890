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

use super::{CliResult, Format, readable};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use restitution::data::frames::{
    collision_id, collisions_csv, count_frames, detect_dir, detections_csv, results_json,
    spins_csv, tracks_csv,
};
use restitution::data::images::{encode_png, read_gray};
use restitution::data::write_all_atomic;
use restitution::frames::detect::DetectSettings;
use restitution::frames::spin::Spin;
use restitution::frames::track::{CollisionResult, TrackSettings, assemble};
use restitution::plot::frames::overlay_svg;
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

fn positive(name: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{name} must be a positive number, got {v}"))
    }
}

pub fn run(args: Args) -> CliResult {
    let fps = positive("--fps", args.fps)?;
    let pixel_m = args.pixel_m.map(|p| positive("--pixel-m", p)).transpose()?;
    let d_m = match args.d_mm.as_deref() {
        None => None,
        Some([d]) => Some([positive("--d-mm", *d)? * 1e-3; 2]),
        Some([d1, d2]) => Some([
            positive("--d-mm", *d1)? * 1e-3,
            positive("--d-mm", *d2)? * 1e-3,
        ]),
        Some(_) => return Err("--d-mm takes one or two diameters".into()),
    };
    if pixel_m.is_none() && d_m.is_none() {
        return Err(
            "the scale is missing: give --pixel-m P (pixel size in the object plane, m) or --d-mm D1[,D2] (the diameters set it)".into(),
        );
    }
    let mut detect = DetectSettings::default();
    if let (Some(d), Some(p)) = (d_m, pixel_m) {
        detect.known_radii_px = vec![d[0] / p / 2.0, d[1] / p / 2.0];
    }
    let settings = TrackSettings {
        fps,
        pixel_m,
        d_m,
        strict: args.strict,
        free_coverage_deg: detect.free_coverage_deg,
    };
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
    let mut results: Vec<CollisionResult> = Vec::new();
    for dir in &args.dirs {
        let id = collision_id(dir);
        if results.iter().any(|r| r.id == id) {
            return Err(format!(
                "{}: collision id '{id}' is already used by another directory (the id is the directory's name)",
                dir.display()
            ));
        }
        let dets = detect_dir(dir, &detect, &|| bar.inc(1)).map_err(|e| e.to_string())?;
        let r = assemble(&id, dets, &settings).map_err(|e| e.to_string())?;
        results.push(r);
    }
    bar.finish_and_clear();
    for r in &results {
        for w in &r.warnings {
            eprintln!("restitution: warning: {}: {w}", r.id);
        }
        for (k, phases) in r.spins.iter().enumerate() {
            if let [Spin::None { reason }, Spin::None { .. }] = phases {
                eprintln!(
                    "restitution: warning: {}: sphere {}: no spin ({reason}); tracks.csv leaves w{}z empty, which kinematics reads as 0",
                    r.id,
                    k + 1,
                    k + 1
                );
            }
        }
    }

    if let Some(out) = &args.out {
        let mut files = vec![
            (out.join("tracks.csv"), tracks_csv(&results).into_bytes()),
            (
                out.join("detections.csv"),
                detections_csv(&results).into_bytes(),
            ),
            (out.join("spins.csv"), spins_csv(&results).into_bytes()),
            (
                out.join("collisions.csv"),
                collisions_csv(&results).into_bytes(),
            ),
        ];
        for r in &results {
            // The frame of closest approach (the last before the collision when the phases
            // are known): it shows the contact region, the hardest part.
            let row = match r.split {
                Some(s) if s > 0 => s - 1,
                _ => closest(r),
            };
            let f = &r.frames[r.track_frames[row]];
            let img = read_gray(std::path::Path::new(&f.meta.name)).map_err(|e| e.to_string())?;
            let png = encode_png(&img)?;
            let title = format!(
                "{}: frame {} (t = {} s)",
                r.id,
                f.meta.number,
                readable(f.t_s)
            );
            let svg = overlay_svg(&png, r.width, r.height, f, &title)?;
            let name = format!("overlay_{}.svg", sanitise(&r.id));
            files.push((out.join(name), svg.into_bytes()));
        }
        std::fs::create_dir_all(out)
            .map_err(|e| format!("{}: cannot create the directory: {e}", out.display()))?;
        write_all_atomic(&files).map_err(|e| format!("{}: cannot write: {e}", out.display()))?;
    }

    match args.format {
        Format::Csv => print!("{}", tracks_csv(&results)),
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(&results_json(&results)).map_err(|e| e.to_string())?
        ),
        Format::Table => print_table(&results),
    }
    Ok(())
}

fn closest(r: &CollisionResult) -> usize {
    let d =
        |f: &restitution::kinematics::Frame| (f.r1_m[0] - f.r2_m[0]).hypot(f.r1_m[1] - f.r2_m[1]);
    (0..r.tracks.len())
        .min_by(|&a, &b| d(&r.tracks[a]).total_cmp(&d(&r.tracks[b])))
        .unwrap_or(0)
}

/// A collision id as a file name: characters other than letters, digits, '-', '_' and '.'
/// become '_'.
fn sanitise(id: &str) -> String {
    id.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn print_table(results: &[CollisionResult]) {
    for r in results {
        let scale = match (r.scale.from_diameters, r.scale.err_m) {
            (true, Some(e)) => format!(
                "{} +- {} m/pixel (from the diameters, {} fits)",
                readable(r.scale.pixel_m),
                readable(e),
                r.scale.n_fits
            ),
            (true, None) => format!(
                "{} m/pixel (from the diameters, 1 fit: no uncertainty)",
                readable(r.scale.pixel_m)
            ),
            (false, _) => format!("{} m/pixel (given)", readable(r.scale.pixel_m)),
        };
        println!(
            "collision {}: {} frames, {} used, {} x {} pixels; scale {scale}",
            r.id,
            r.frames.len(),
            r.tracks.len(),
            r.width,
            r.height
        );
        let d = match r.d_err_m {
            Some(e) => format!(
                "d1 = {} +- {} mm, d2 = {} +- {} mm (measured)",
                readable(r.d_m[0] * 1e3),
                readable(e[0] * 1e3),
                readable(r.d_m[1] * 1e3),
                readable(e[1] * 1e3)
            ),
            None => format!(
                "d1 = {} mm, d2 = {} mm",
                readable(r.d_m[0] * 1e3),
                readable(r.d_m[1] * 1e3)
            ),
        };
        println!("{d}");
        println!(
            "{:>6} {:>9} {:>10} {:>10} {:>8} {:>8} {:>10} {:>10} {:>8} {:>8}  note",
            "frame",
            "t_s",
            "x1_px",
            "y1_px",
            "r1_px",
            "res1_px",
            "x2_px",
            "y2_px",
            "r2_px",
            "res2_px"
        );
        for f in &r.frames {
            let cell = |k: usize| match &f.spheres[k] {
                Some(o) => format!(
                    "{:>10.3} {:>10.3} {:>8.3} {:>8.3}",
                    o.x_px, o.y_px, o.r_px, o.rms_px
                ),
                None => format!("{:>10} {:>10} {:>8} {:>8}", "-", "-", "-", "-"),
            };
            println!(
                "{:>6} {:>9} {} {}  {}",
                f.meta.number,
                readable(f.t_s),
                cell(0),
                cell(1).trim_start(),
                f.note
                    .as_deref()
                    .unwrap_or(if f.used { "" } else { "left out" })
            );
        }
        for (k, phases) in r.spins.iter().enumerate() {
            for (p, s) in phases.iter().enumerate() {
                let phase = if p == 0 { "before" } else { "after" };
                let text = match s {
                    Spin::Full {
                        w_rad_s,
                        err_rad_s,
                        pairs,
                    } => format!(
                        "w = ({}, {}, {}) rad/s{} from {pairs} frame pairs",
                        readable(w_rad_s[0]),
                        readable(w_rad_s[1]),
                        readable(w_rad_s[2]),
                        err_rad_s
                            .map(|e| format!(
                                " +- ({}, {}, {})",
                                readable(e[0]),
                                readable(e[1]),
                                readable(e[2])
                            ))
                            .unwrap_or_default()
                    ),
                    Spin::ZOnly {
                        wz_rad_s, pairs, ..
                    } => format!(
                        "w_z = {} rad/s from {pairs} frame pairs (one marker: assumes the axis is the camera axis)",
                        readable(*wz_rad_s)
                    ),
                    Spin::None { reason } => format!("no spin: {reason}"),
                };
                println!("sphere {} {phase}: {text}", k + 1);
            }
        }
        println!();
    }
}
