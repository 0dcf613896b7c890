//! `track`'s files: detecting a directory of frames (decoding and detection in parallel) and
//! writing tracks.csv (the `kinematics` schema), detections.csv, spins.csv, collisions.csv and
//! the JSON form of all of it. Numbers in shortest round-trip form; CSV through csv::Writer.

pub mod job;

use super::images::{list_frames, read_gray};
use super::tracks::{CollisionTrack, write_tracks};
use super::{DataError, fmt_num};
use crate::frames::detect::{DetectSettings, detect_frame};
use crate::frames::spin::Spin;
use crate::frames::track::{CollisionResult, FrameMeta, FrameOutcome, FrameProblem, SphereObs};
use rayon::prelude::*;
use serde_json::{Value, json};
use std::path::Path;

/// The collision id of a directory: its name (of the resolved path for `.` and the like).
pub fn collision_id(dir: &Path) -> String {
    dir.file_name()
        .map(|n| n.to_string_lossy().to_string())
        .or_else(|| {
            dir.canonicalize()
                .ok()
                .and_then(|p| p.file_name().map(|n| n.to_string_lossy().to_string()))
        })
        .unwrap_or_else(|| dir.display().to_string())
}

/// Lists, decodes and detects every frame of a directory, in parallel (rayon); `on_frame` is
/// called once per frame done (a progress bar). Each image is dropped once detected, so memory
/// stays at a few frames per thread. A frame that cannot be read or shows no spheres is an
/// `Err` with the reason, for the caller to report by name.
pub fn detect_dir(
    dir: &Path,
    settings: &DetectSettings,
    on_frame: &(dyn Fn() + Sync),
) -> Result<Vec<FrameOutcome>, DataError> {
    let files = list_frames(dir)?;
    Ok(files
        .par_iter()
        .map(|f| {
            let meta = FrameMeta {
                number: f.number,
                name: f.path.display().to_string(),
            };
            let res = read_gray(&f.path)
                .map_err(|e| FrameProblem::Unreadable(e.message))
                .and_then(|img| detect_frame(&img, settings).map_err(FrameProblem::Detect));
            on_frame();
            (meta, res)
        })
        .collect())
}

/// Number of frame files in a directory (for a progress bar's length); 0 if unreadable.
pub fn count_frames(dir: &Path) -> usize {
    list_frames(dir).map(|v| v.len()).unwrap_or(0)
}

fn opt(x: Option<f64>) -> String {
    x.map(fmt_num).unwrap_or_default()
}

/// tracks.csv: the `kinematics` schema, with the phase split used for the spins and the z spins
/// (an empty cell where a sphere's spin was not measured).
pub fn tracks_csv(results: &[CollisionResult]) -> String {
    let tracks: Vec<CollisionTrack> = results
        .iter()
        .map(|r| {
            let wz = |k: usize, p: usize| r.spins[k][p].wz().unwrap_or(f64::NAN);
            let spins = [wz(0, 0), wz(1, 0), wz(0, 1), wz(1, 1)];
            CollisionTrack {
                id: r.id.clone(),
                first_line: 0,
                d1_m: r.d_m[0],
                d2_m: r.d_m[1],
                frames: r.tracks.clone(),
                split: r.split,
                spins_rad_s: spins.iter().any(|w| !w.is_nan()).then_some(spins),
            }
        })
        .collect();
    write_tracks(&tracks)
}

const DETECTION_COLUMNS: [&str; 21] = [
    "collision",
    "frame",
    "file",
    "t_s",
    "kind",
    "sphere",
    "x_px",
    "y_px",
    "x_m",
    "y_m",
    "r_px",
    "r_m",
    "centre_err_px",
    "residual_px",
    "n_edge",
    "coverage_deg",
    "radius_mode",
    "clipped",
    "markers",
    "used",
    "note",
];

fn csv_string(header: &[&str], rows: Vec<Vec<String>>) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    // Writing to memory cannot fail; the rows have the header's length by construction.
    w.write_record(header).expect("in-memory CSV");
    for r in rows {
        w.write_record(&r).expect("in-memory CSV");
    }
    String::from_utf8(w.into_inner().expect("in-memory CSV")).expect("UTF-8 in, UTF-8 out")
}

/// detections.csv: one row per sphere and per marker in every frame, and one `none` row per
/// frame where nothing was found (with the reason). Coordinates: pixels and metres, x right,
/// y up, origin at the image's bottom-left corner.
pub fn detections_csv(results: &[CollisionResult]) -> String {
    let mut rows = Vec::new();
    for r in results {
        let p = r.scale.pixel_m;
        for f in &r.frames {
            let base = |kind: &str, sphere: String| {
                vec![
                    r.id.clone(),
                    f.meta.number.to_string(),
                    f.meta.name.clone(),
                    fmt_num(f.t_s),
                    kind.to_string(),
                    sphere,
                ]
            };
            let note = f.note.clone().unwrap_or_default();
            if f.spheres.iter().all(Option::is_none) {
                let mut row = base("none", String::new());
                row.extend(vec![String::new(); 13]);
                row.push(f.used.to_string());
                row.push(note.clone());
                rows.push(row);
            }
            for (k, o) in f.spheres.iter().enumerate() {
                let Some(o) = o else { continue };
                let mut row = base("sphere", (k + 1).to_string());
                row.extend(sphere_cells(o, p));
                row.push(f.used.to_string());
                row.push(note.clone());
                rows.push(row);
                for m in &o.markers {
                    let mut row = base("marker", (k + 1).to_string());
                    row.extend([
                        fmt_num(m[0]),
                        fmt_num(m[1]),
                        fmt_num(m[0] * p),
                        fmt_num(m[1] * p),
                    ]);
                    row.extend(vec![String::new(); 9]);
                    row.push(f.used.to_string());
                    row.push(String::new());
                    rows.push(row);
                }
            }
        }
    }
    csv_string(&DETECTION_COLUMNS, rows)
}

fn sphere_cells(o: &SphereObs, p: f64) -> Vec<String> {
    vec![
        fmt_num(o.x_px),
        fmt_num(o.y_px),
        fmt_num(o.x_px * p),
        fmt_num(o.y_px * p),
        fmt_num(o.r_px),
        fmt_num(o.r_px * p),
        opt(o.centre_err_px[0].hypot(o.centre_err_px[1]).into_finite()),
        fmt_num(o.rms_px),
        o.n_edge.to_string(),
        fmt_num(o.coverage_deg),
        o.radius_mode.name().to_string(),
        o.clipped.to_string(),
        o.markers.len().to_string(),
    ]
}

trait IntoFinite {
    fn into_finite(self) -> Option<f64>;
}
impl IntoFinite for f64 {
    fn into_finite(self) -> Option<f64> {
        self.is_finite().then_some(self)
    }
}

/// A spin as table cells: status, vector, errors, pairs, reason.
struct SpinRow {
    status: &'static str,
    w: [Option<f64>; 3],
    err: [Option<f64>; 3],
    pairs: usize,
    reason: String,
}

fn spin_parts(s: &Spin) -> SpinRow {
    match s {
        Spin::Full {
            w_rad_s,
            err_rad_s,
            pairs,
        } => SpinRow {
            status: "full",
            w: w_rad_s.map(Some),
            err: err_rad_s.map_or([None; 3], |e| e.map(Some)),
            pairs: *pairs,
            reason: String::new(),
        },
        Spin::ZOnly {
            wz_rad_s,
            err_rad_s,
            pairs,
        } => SpinRow {
            status: "z_only",
            w: [None, None, Some(*wz_rad_s)],
            err: [None, None, *err_rad_s],
            pairs: *pairs,
            reason: "one marker per frame: assumes the spin axis is the camera axis".into(),
        },
        Spin::None { reason } => SpinRow {
            status: "none",
            w: [None; 3],
            err: [None; 3],
            pairs: 0,
            reason: reason.clone(),
        },
    }
}

/// spins.csv: per collision, sphere and phase, the spin vector (rad/s; x right, y up, z towards
/// the camera), its standard error, the frame pairs used, and why it is missing or partial.
pub fn spins_csv(results: &[CollisionResult]) -> String {
    let mut rows = Vec::new();
    for r in results {
        for k in 0..2 {
            for (p, phase) in ["pre", "post"].iter().enumerate() {
                let sr = spin_parts(&r.spins[k][p]);
                let mut row = vec![
                    r.id.clone(),
                    (k + 1).to_string(),
                    phase.to_string(),
                    sr.status.to_string(),
                ];
                row.extend(sr.w.iter().map(|x| opt(*x)));
                row.extend(sr.err.iter().map(|x| opt(*x)));
                row.push(sr.pairs.to_string());
                row.push(sr.reason);
                rows.push(row);
            }
        }
    }
    csv_string(
        &[
            "collision",
            "sphere",
            "phase",
            "status",
            "wx_rad_s",
            "wy_rad_s",
            "wz_rad_s",
            "wx_err_rad_s",
            "wy_err_rad_s",
            "wz_err_rad_s",
            "pairs",
            "reason",
        ],
        rows,
    )
}

/// collisions.csv: per collision the frames, the scale and its source, the diameters.
pub fn collisions_csv(results: &[CollisionResult]) -> String {
    let rows = results
        .iter()
        .map(|r| {
            vec![
                r.id.clone(),
                r.frames.len().to_string(),
                r.tracks.len().to_string(),
                r.split.map(|s| s.to_string()).unwrap_or_default(),
                fmt_num(r.scale.pixel_m),
                opt(r.scale.err_m),
                if r.scale.from_diameters {
                    "diameters"
                } else {
                    "given"
                }
                .to_string(),
                fmt_num(r.d_m[0] * 1e3),
                fmt_num(r.d_m[1] * 1e3),
                opt(r.d_err_m.map(|e| e[0] * 1e3)),
                opt(r.d_err_m.map(|e| e[1] * 1e3)),
                r.width.to_string(),
                r.height.to_string(),
            ]
        })
        .collect();
    csv_string(
        &[
            "collision",
            "frames",
            "frames_used",
            "split",
            "pixel_m",
            "pixel_err_m",
            "scale_from",
            "d1_mm",
            "d2_mm",
            "d1_err_mm",
            "d2_err_mm",
            "width_px",
            "height_px",
        ],
        rows,
    )
}

fn num(x: f64) -> Value {
    // Finite by construction; a non-finite value becomes null rather than invalid JSON.
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

fn onum(x: Option<f64>) -> Value {
    x.map_or(Value::Null, num)
}

/// Everything as JSON (detections without their edge points).
pub fn results_json(results: &[CollisionResult]) -> Value {
    Value::Array(
        results
            .iter()
            .map(|r| {
                let p = r.scale.pixel_m;
                let spins: Vec<Value> = (0..2)
                    .flat_map(|k| {
                        ["pre", "post"].iter().enumerate().map(move |(ph, name)| {
                            let sr = spin_parts(&r.spins[k][ph]);
                            json!({"sphere": k + 1, "phase": name, "status": sr.status,
                                "w_rad_s": sr.w.iter().map(|x| onum(*x)).collect::<Vec<_>>(),
                                "w_err_rad_s": sr.err.iter().map(|x| onum(*x)).collect::<Vec<_>>(),
                                "pairs": sr.pairs, "reason": sr.reason})
                        })
                    })
                    .collect();
                let frames: Vec<Value> = r
                    .frames
                    .iter()
                    .map(|f| {
                        let sph: Vec<Value> = f
                            .spheres
                            .iter()
                            .enumerate()
                            .filter_map(|(k, o)| o.as_ref().map(|o| (k, o)))
                            .map(|(k, o)| {
                                json!({"sphere": k + 1, "x_px": num(o.x_px), "y_px": num(o.y_px),
                                    "x_m": num(o.x_px * p), "y_m": num(o.y_px * p),
                                    "r_px": num(o.r_px), "residual_px": num(o.rms_px),
                                    "n_edge": o.n_edge, "coverage_deg": num(o.coverage_deg),
                                    "radius_mode": o.radius_mode.name(), "clipped": o.clipped,
                                    "markers_px": o.markers.iter().map(|m| vec![num(m[0]), num(m[1])]).collect::<Vec<_>>()})
                            })
                            .collect();
                        json!({"frame": f.meta.number, "file": f.meta.name, "t_s": num(f.t_s),
                            "used": f.used, "note": f.note, "spheres": sph})
                    })
                    .collect();
                json!({
                    "collision": r.id,
                    "width_px": r.width, "height_px": r.height,
                    "pixel_m": num(p), "pixel_err_m": onum(r.scale.err_m),
                    "scale_from": if r.scale.from_diameters { "diameters" } else { "given" },
                    "d_mm": [num(r.d_m[0] * 1e3), num(r.d_m[1] * 1e3)],
                    "d_err_mm": r.d_err_m.map(|e| vec![num(e[0] * 1e3), num(e[1] * 1e3)]),
                    "split": r.split,
                    "spins": spins,
                    "frames": frames,
                    "warnings": r.warnings,
                })
            })
            .collect(),
    )
}

/// [`results_json`] as the text `track --format json` prints.
pub fn results_json_text(results: &[CollisionResult]) -> String {
    serde_json::to_string_pretty(&results_json(results)).expect("JSON values serialise") + "\n"
}
