//! One `track` run from directories to results and files, for the command line and Python
//! alike: the checks of the request, detection of every directory, the tracks, the warnings,
//! and the files of `--out` (with one overlay figure per collision).

use super::{collision_id, detect_dir};
#[cfg(feature = "plot")]
use super::{collisions_csv, detections_csv, spins_csv, tracks_csv};
use crate::data::{ArgStyle, DataError, fmt_num};
use crate::frames::detect::DetectSettings;
use crate::frames::spin::Spin;
use crate::frames::track::{CollisionResult, TrackError, TrackSettings, assemble};
use std::path::PathBuf;

/// Why a `track` run gave no result, by kind; each is one line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrackJobError {
    /// A bad argument: a frame rate, pixel size or diameter out of range, no or repeated
    /// directories.
    #[error("{0}")]
    Input(String),
    /// A directory or frame file at fault (missing, unreadable, not an image, mixed sizes).
    #[error(transparent)]
    Data(#[from] DataError),
    /// The frames were read but a collision cannot be tracked (or, with `strict`, a bad frame).
    #[error(transparent)]
    Tracking(#[from] TrackError),
    /// An overlay figure could not be drawn.
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}

/// Accepted frame rates, frames per second.
pub const FPS_RANGE: (f64, f64) = (1e-6, 1e10);
/// Accepted pixel sizes in the object plane, m.
pub const PIXEL_M_RANGE: (f64, f64) = (1e-12, 1.0);
/// Accepted sphere diameters, mm (as `export` accepts).
pub const D_MM_RANGE: (f64, f64) = (1e-3, 1e4);

/// What a `track` run needs besides the directories, as the user gave it.
#[derive(Debug, Clone)]
pub struct TrackRequest {
    pub style: ArgStyle,
    /// Frames per second.
    pub fps: f64,
    /// Pixel size in the object plane, m.
    pub pixel_m: Option<f64>,
    /// Sphere diameters, mm: one (both spheres) or two.
    pub d_mm: Option<Vec<f64>>,
    /// A bad frame is an error instead of a warning.
    pub strict: bool,
}

impl TrackRequest {
    /// The detector's and the tracker's settings, or a one-line error naming the argument.
    pub fn settings(&self) -> Result<(DetectSettings, TrackSettings), TrackJobError> {
        let name = |k: &str| self.style.name(k);
        let positive = |k: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(TrackJobError::Input(format!(
                    "{} {}: expected a positive number",
                    name(k),
                    fmt_num(v)
                )))
            }
        };
        // Ranges wide enough for any camera and sphere, narrow enough that no time, position,
        // speed or scale uncertainty derived from them can overflow (a number or an error).
        let within = |k: &str, v: f64, lo: f64, hi: f64, unit: &str| {
            let v = positive(k, v)?;
            if (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err(TrackJobError::Input(format!(
                    "{} {}: expected {} to {} {unit}",
                    name(k),
                    fmt_num(v),
                    fmt_num(lo),
                    fmt_num(hi)
                )))
            }
        };
        let fps = within(
            "fps",
            self.fps,
            FPS_RANGE.0,
            FPS_RANGE.1,
            "frames per second",
        )?;
        let pixel_m = self
            .pixel_m
            .map(|p| within("pixel_m", p, PIXEL_M_RANGE.0, PIXEL_M_RANGE.1, "m"))
            .transpose()?;
        let d = |v: f64| within("d_mm", v, D_MM_RANGE.0, D_MM_RANGE.1, "mm").map(|d| d * 1e-3);
        let d_m = match self.d_mm.as_deref() {
            None => None,
            Some([d1]) => Some([d(*d1)?; 2]),
            Some([d1, d2]) => Some([d(*d1)?, d(*d2)?]),
            Some(_) => {
                return Err(TrackJobError::Input(format!(
                    "{} takes one or two diameters",
                    name("d_mm")
                )));
            }
        };
        if pixel_m.is_none() && d_m.is_none() {
            return Err(TrackJobError::Input(format!(
                "the scale is missing: give {} P (pixel size in the object plane, m) or {} D1[,D2] (the diameters set it)",
                name("pixel_m"),
                name("d_mm")
            )));
        }
        let mut detect = DetectSettings::default();
        if let (Some(d), Some(p)) = (d_m, pixel_m) {
            detect.known_radii_px = vec![d[0] / p / 2.0, d[1] / p / 2.0];
        }
        let settings = TrackSettings {
            fps,
            pixel_m,
            d_m,
            strict: self.strict,
            free_coverage_deg: detect.free_coverage_deg,
        };
        Ok((detect, settings))
    }
}

/// Detects and tracks every directory (one collision each; the id is the directory's name).
/// `on_frame` is called once per frame done (a progress bar).
pub fn track_dirs(
    dirs: &[PathBuf],
    request: &TrackRequest,
    on_frame: &(dyn Fn() + Sync),
) -> Result<Vec<CollisionResult>, TrackJobError> {
    let (detect, settings) = request.settings()?;
    if dirs.is_empty() {
        return Err(TrackJobError::Input("no directory of frames given".into()));
    }
    let mut results: Vec<CollisionResult> = Vec::new();
    for dir in dirs {
        let id = collision_id(dir);
        if results.iter().any(|r| r.id == id) {
            return Err(TrackJobError::Input(format!(
                "{}: collision id '{id}' is already used by another directory (the id is the directory's name)",
                dir.display()
            )));
        }
        let dets = detect_dir(dir, &detect, on_frame)?;
        results.push(assemble(&id, dets, &settings)?);
    }
    Ok(results)
}

/// Everything the user should know about the results: the tracker's warnings and every
/// sphere without a spin, one line each, prefixed with the collision's id.
pub fn warnings(results: &[CollisionResult]) -> Vec<String> {
    let mut out = Vec::new();
    for r in results {
        for w in &r.warnings {
            out.push(format!("{}: {w}", r.id));
        }
        for (k, phases) in r.spins.iter().enumerate() {
            if let [Spin::None { reason }, Spin::None { .. }] = phases {
                out.push(format!(
                    "{}: sphere {}: no spin ({reason}); tracks.csv leaves w{}z empty, which kinematics reads as 0",
                    r.id,
                    k + 1,
                    k + 1
                ));
            }
        }
    }
    out
}

/// The files of `track --out`: tracks.csv (the `kinematics` schema, with spins),
/// detections.csv, spins.csv, collisions.csv and `overlay_<collision>.svg` (the frame of closest
/// approach with edge points, circles, centres and markers).
#[cfg(feature = "plot")]
pub fn track_files(results: &[CollisionResult]) -> Result<Vec<(String, Vec<u8>)>, TrackJobError> {
    use crate::data::images::{encode_png, read_gray};
    use crate::data::readable;
    use crate::plot::frames::overlay_svg;
    let mut files = vec![
        ("tracks.csv".to_string(), tracks_csv(results).into_bytes()),
        (
            "detections.csv".to_string(),
            detections_csv(results).into_bytes(),
        ),
        ("spins.csv".to_string(), spins_csv(results).into_bytes()),
        (
            "collisions.csv".to_string(),
            collisions_csv(results).into_bytes(),
        ),
    ];
    for r in results {
        // The frame of closest approach (the last before the collision when the phases are
        // known): it shows the contact region, the hardest part.
        let row = match r.split {
            Some(s) if s > 0 => s - 1,
            _ => closest(r),
        };
        let f = &r.frames[r.track_frames[row]];
        let frame = std::path::Path::new(&f.meta.name);
        let png = encode_png(frame, &read_gray(frame)?)?;
        let title = format!(
            "{}: frame {} (t = {} s)",
            r.id,
            f.meta.number,
            readable(f.t_s)
        );
        let svg = overlay_svg(&png, r.width, r.height, f, &title)?;
        files.push((format!("overlay_{}.svg", sanitise(&r.id)), svg.into_bytes()));
    }
    Ok(files)
}

#[cfg(feature = "plot")]
fn closest(r: &CollisionResult) -> usize {
    let d = |f: &crate::kinematics::Frame| (f.r1_m[0] - f.r2_m[0]).hypot(f.r1_m[1] - f.r2_m[1]);
    (0..r.tracks.len())
        .min_by(|&a, &b| d(&r.tracks[a]).total_cmp(&d(&r.tracks[b])))
        .unwrap_or(0)
}

/// A collision id as a file name: characters other than letters, digits, '-', '_' and '.'
/// become '_'.
pub fn sanitise(id: &str) -> String {
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
