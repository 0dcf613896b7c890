//! From per-frame detections to one collision's tracks, scale, diameters and spins
//! (docs/physics.md §8).
//!
//! Identities: in the first frame showing both spheres, sphere 1 is the larger when the given
//! diameters differ (by more than 5%), else the one on the left; later (and earlier) frames
//! take the assignment nearest to the positions predicted from the previous two frames.
//! Short arcs: a fit whose edge points cover less than 240 degrees is redone with the radius
//! held at the median of that sphere's well-seen fits in the same collision (so the edge
//! detector's own radius bias is the same in both), else at the nominal radius from the given
//! diameter and pixel size. Scale without `pixel_m`: the given diameters over the fitted ones,
//! averaged over the well-seen fits (a fit at least 240 degrees round and inside the image).

use super::circle::{fit_robust, median};
use super::detect::{FrameDetection, RadiusMode, coverage_deg};
use super::spin::{MarkerFrame, Spin, lift, phase_spin};
use crate::kinematics::{FitKind, Frame, G_STANDARD_M_S2, split_at_contact};

mod scale;
use scale::{diameters, refit_and_scale};

/// A frame file as the caller found it.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameMeta {
    /// The integer in the file name.
    pub number: i64,
    /// The file (as shown in messages).
    pub name: String,
}

/// A frame and what its detection gave (`Err`: the frame's problem).
pub type FrameOutcome = (FrameMeta, Result<FrameDetection, FrameProblem>);

/// Why a frame gave no spheres: the file could not be read as an image, or the detector found
/// none it could fit. Either leaves the frame out (or stops a strict run), named in the report.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrameProblem {
    /// The reader's message (the file's name is the frame's, given beside it).
    #[error("{0}")]
    Unreadable(String),
    #[error("{0}")]
    Detect(#[from] super::detect::DetectError),
}

/// Settings of the assembly.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackSettings {
    pub fps: f64,
    /// Pixel size in the object plane, m.
    pub pixel_m: Option<f64>,
    /// Diameters of sphere 1 and 2, m.
    pub d_m: Option<[f64; 2]>,
    /// A bad frame is an error instead of a warning.
    pub strict: bool,
    /// Below this coverage a fit holds its radius (degrees).
    pub free_coverage_deg: f64,
}

/// One sphere in one frame, output coordinates: pixels, x right, y up, origin bottom-left.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereObs {
    pub x_px: f64,
    pub y_px: f64,
    pub r_px: f64,
    pub rms_px: f64,
    pub centre_err_px: [f64; 2],
    pub n_edge: usize,
    pub coverage_deg: f64,
    pub radius_mode: RadiusMode,
    pub clipped: bool,
    /// Edge points of the last pass and whether the fit used them.
    pub edges: Vec<[f64; 2]>,
    pub inliers: Vec<bool>,
    pub markers: Vec<[f64; 2]>,
}

/// One frame's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameResult {
    pub meta: FrameMeta,
    pub t_s: f64,
    /// Sphere 1 and sphere 2 (None: not found).
    pub spheres: [Option<SphereObs>; 2],
    /// In the tracks (both spheres found).
    pub used: bool,
    /// Why the frame, or a sphere in it, was left out.
    pub note: Option<String>,
}

/// The pixel size used and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Scale {
    pub pixel_m: f64,
    /// Standard error (from the scatter of the fitted diameters), when measured.
    pub err_m: Option<f64>,
    /// Measured from the known diameters (true) or given (false).
    pub from_diameters: bool,
    /// Fits it was measured from.
    pub n_fits: usize,
}

/// One collision, tracked.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionResult {
    pub id: String,
    pub width: usize,
    pub height: usize,
    pub frames: Vec<FrameResult>,
    pub scale: Scale,
    pub d_m: [f64; 2],
    /// Standard errors of measured diameters (None when the diameters were given).
    pub d_err_m: Option<[f64; 2]>,
    /// Centres in metres of the used frames, in time order.
    pub tracks: Vec<Frame>,
    /// Index in `frames` of each track row.
    pub track_frames: Vec<usize>,
    /// First post-collision row of `tracks`, when the phases could be separated.
    pub split: Option<usize>,
    /// `spins[sphere][phase]` (phase 0: before, 1: after the collision).
    pub spins: [[Spin; 2]; 2],
    pub warnings: Vec<String>,
}

/// A collision that cannot be tracked (or, with `strict`, a bad frame).
#[derive(Debug, Clone, PartialEq)]
pub struct TrackError {
    /// The file at fault, if one is.
    pub file: Option<String>,
    pub message: String,
}

impl std::fmt::Display for TrackError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.file {
            Some(file) => write!(f, "{file}: {}", self.message),
            None => write!(f, "{}", self.message),
        }
    }
}

impl std::error::Error for TrackError {}

fn err(file: Option<&str>, message: impl Into<String>) -> TrackError {
    TrackError {
        file: file.map(str::to_string),
        message: message.into(),
    }
}

fn to_obs(d: &FrameDetection, i: usize) -> SphereObs {
    let h = d.height as f64;
    let sp = &d.spheres[i];
    SphereObs {
        x_px: sp.circle.cx,
        y_px: h - sp.circle.cy,
        r_px: sp.circle.r,
        rms_px: sp.rms_px,
        centre_err_px: sp.centre_err_px,
        n_edge: sp.n_edge,
        coverage_deg: sp.coverage_deg,
        radius_mode: sp.radius_mode,
        clipped: sp.clipped,
        edges: sp.edges.iter().map(|e| [e.u, h - e.v]).collect(),
        inliers: sp.inliers.clone(),
        markers: d.markers[i].iter().map(|m| [m.u, h - m.v]).collect(),
    }
}

/// Assembles one collision from its frames' detections (`Err`: the frame's problem, e.g. an
/// unreadable file or no sphere). See the module doc.
pub fn assemble(
    id: &str,
    input: Vec<FrameOutcome>,
    s: &TrackSettings,
) -> Result<CollisionResult, TrackError> {
    if !(s.fps.is_finite() && s.fps > 0.0) {
        return Err(err(
            None,
            format!("fps must be a positive number, got {}", s.fps),
        ));
    }
    let mut input = input;
    input.sort_by_key(|x| x.0.number);
    let Some(first) = input.first().map(|x| x.0.number) else {
        return Err(err(Some(id), "no frames"));
    };
    let mut warnings = Vec::new();
    // The frame size most frames have; others are left out.
    let mut sizes: Vec<((usize, usize), usize)> = Vec::new();
    for d in input.iter().filter_map(|x| x.1.as_ref().ok()) {
        match sizes.iter_mut().find(|s| s.0 == (d.width, d.height)) {
            Some(s) => s.1 += 1,
            None => sizes.push(((d.width, d.height), 1)),
        }
    }
    let Some(&((width, height), _)) = sizes.iter().max_by_key(|s| s.1) else {
        let why = input
            .iter()
            .find_map(|x| x.1.as_ref().err().map(|e| (&x.0.name, e)));
        return Err(match why {
            Some((name, e)) => err(
                Some(name),
                format!("{e} (and no frame of this collision was usable)"),
            ),
            None => err(Some(id), "no usable frame"),
        });
    };
    let mut frames = Vec::with_capacity(input.len());
    let mut dets: Vec<Vec<SphereObs>> = Vec::with_capacity(input.len());
    for (meta, res) in input {
        let t_s = (meta.number - first) as f64 / s.fps;
        let (obs, note) = match res {
            Ok(d) if (d.width, d.height) != (width, height) => (
                Vec::new(),
                Some(format!(
                    "{} x {} pixels where the other frames have {width} x {height}",
                    d.width, d.height
                )),
            ),
            Ok(d) => {
                let obs: Vec<SphereObs> = (0..d.spheres.len()).map(|i| to_obs(&d, i)).collect();
                let note = (!d.left_out.is_empty()).then(|| d.left_out.join("; "));
                (obs, note)
            }
            Err(e) => (Vec::new(), Some(e.to_string())),
        };
        if obs.is_empty() {
            let why = note.clone().unwrap_or_default();
            if s.strict {
                return Err(err(Some(&meta.name), why));
            }
            warnings.push(format!("{}: {why}; frame left out", meta.name));
        }
        dets.push(obs);
        frames.push(FrameResult {
            meta,
            t_s,
            spheres: [None, None],
            used: false,
            note,
        });
    }
    label(&mut frames, dets, s)?;
    let scale = refit_and_scale(&mut frames, s, &mut warnings)?;
    let (d_m, d_err_m) = diameters(&frames, s, &scale, id)?;

    let mut tracks = Vec::new();
    let mut track_frames = Vec::new();
    for (k, f) in frames.iter_mut().enumerate() {
        let found = [f.spheres[0].is_some(), f.spheres[1].is_some()];
        if let [Some(a), Some(b)] = &f.spheres {
            f.used = true;
            let p = scale.pixel_m;
            tracks.push(Frame {
                t_s: f.t_s,
                r1_m: [a.x_px * p, a.y_px * p],
                r2_m: [b.x_px * p, b.y_px * p],
            });
            track_frames.push(k);
        } else if found[0] || found[1] {
            let why = format!("sphere {} not found", if found[0] { 2 } else { 1 });
            if s.strict {
                return Err(err(Some(&f.meta.name), why));
            }
            warnings.push(format!("{}: {why}; frame left out", f.meta.name));
            f.note = Some(match &f.note {
                Some(n) => format!("{why}: {n}"),
                None => why,
            });
        }
    }
    if tracks.len() < 2 {
        return Err(err(
            Some(id),
            format!(
                "{} frame(s) show both spheres, tracks need at least 2",
                tracks.len()
            ),
        ));
    }
    let split = split_at_contact(&tracks, FitKind::Free)
        .or_else(|_| {
            split_at_contact(
                &tracks,
                FitKind::FixedGravity {
                    g_m_s2: G_STANDARD_M_S2,
                },
            )
        })
        .ok();
    let spins = std::array::from_fn(|k| {
        std::array::from_fn(|phase| {
            let Some(split) = split else {
                return Spin::None {
                    reason: "phases not separated (too few frames on one side of the collision)"
                        .into(),
                };
            };
            let rows = if phase == 0 {
                0..split
            } else {
                split..tracks.len()
            };
            let mf: Vec<MarkerFrame> = rows
                .map(|row| {
                    let f = &frames[track_frames[row]];
                    let o = f.spheres[k]
                        .as_ref()
                        .expect("used frames have both spheres");
                    MarkerFrame {
                        t_s: f.t_s,
                        dirs: lift([o.x_px, o.y_px], o.r_px, &o.markers, 0.85),
                    }
                })
                .collect();
            let r = median(&mut mf_radii(&frames, &track_frames, k));
            // Matching tolerance: 2 px of marker displacement on the sphere, at least 0.03 rad
            // (centroid and centre errors of a few tenths of a pixel, foreshortening).
            phase_spin(&mf, (2.0 / r).max(0.03))
        })
    });
    Ok(CollisionResult {
        id: id.to_string(),
        width,
        height,
        frames,
        scale,
        d_m,
        d_err_m,
        tracks,
        track_frames,
        split,
        spins,
        warnings,
    })
}

fn mf_radii(frames: &[FrameResult], rows: &[usize], k: usize) -> Vec<f64> {
    rows.iter()
        .filter_map(|&i| frames[i].spheres[k].as_ref().map(|o| o.r_px))
        .collect()
}

/// Assigns the detections of each frame to sphere 1 and 2. See the module doc.
fn label(
    frames: &mut [FrameResult],
    mut dets: Vec<Vec<SphereObs>>,
    s: &TrackSettings,
) -> Result<(), TrackError> {
    let Some(anchor) = dets.iter().position(|d| d.len() == 2) else {
        return Err(err(None, "no frame shows both spheres"));
    };
    let mut pair = std::mem::take(&mut dets[anchor]);
    let swap = match s.d_m {
        Some([d1, d2]) if (d1 - d2).abs() > 0.05 * d1.max(d2) => {
            (pair[0].r_px > pair[1].r_px) != (d1 > d2)
        }
        _ => pair[0].x_px > pair[1].x_px,
    };
    if swap {
        pair.swap(0, 1);
    }
    let b = pair.pop();
    let a = pair.pop();
    frames[anchor].spheres = [a, b];
    for dir in [1i64, -1] {
        let mut hist: [Vec<(f64, f64, f64)>; 2] = std::array::from_fn(|k| {
            let o = frames[anchor].spheres[k].as_ref().expect("anchor has both");
            vec![(frames[anchor].t_s, o.x_px, o.y_px)]
        });
        let mut i = anchor as i64 + dir;
        while i >= 0 && (i as usize) < frames.len() {
            let k = i as usize;
            let t = frames[k].t_s;
            let pred: [[f64; 2]; 2] = std::array::from_fn(|j| predict(&hist[j], t));
            let d2 = |o: &SphereObs, p: [f64; 2]| (o.x_px - p[0]).powi(2) + (o.y_px - p[1]).powi(2);
            let mut obs = std::mem::take(&mut dets[k]);
            let mut slots: [Option<SphereObs>; 2] = [None, None];
            match obs.len() {
                2 => {
                    let keep = d2(&obs[0], pred[0]) + d2(&obs[1], pred[1]);
                    let swapped = d2(&obs[0], pred[1]) + d2(&obs[1], pred[0]);
                    if swapped < keep {
                        obs.swap(0, 1);
                    }
                    slots[1] = obs.pop();
                    slots[0] = obs.pop();
                }
                1 => {
                    let o = obs.pop().expect("one");
                    let j = usize::from(d2(&o, pred[1]) < d2(&o, pred[0]));
                    slots[j] = Some(o);
                }
                _ => {}
            }
            for (j, slot) in slots.iter().enumerate() {
                if let Some(o) = slot {
                    hist[j].push((t, o.x_px, o.y_px));
                }
            }
            frames[k].spheres = slots;
            i += dir;
        }
    }
    Ok(())
}

/// Position at t from the last two observations (straight line), or the last one.
fn predict(hist: &[(f64, f64, f64)], t: f64) -> [f64; 2] {
    match hist {
        [.., a, b] if b.0 != a.0 => {
            let f = (t - b.0) / (b.0 - a.0);
            [b.1 + f * (b.1 - a.1), b.2 + f * (b.2 - a.2)]
        }
        [.., b] => [b.1, b.2],
        [] => [f64::NAN, f64::NAN],
    }
}

fn well_seen(o: &SphereObs, s: &TrackSettings) -> bool {
    o.radius_mode == RadiusMode::Free && o.coverage_deg >= s.free_coverage_deg && !o.clipped
}
