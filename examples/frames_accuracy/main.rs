//! What the frame pipeline can measure: centre, spin and e errors on rendered frames, against
//! noise, sphere size, blur and speed, for the detector and a naive thresholded-blob centroid.
//!
//! ```sh
//! cargo run --release --example frames_accuracy            # writes reports/frames/
//! ```
//! Seeded and deterministic. Every frame is rendered by `frames::render` with the paper's camera
//! (192 x 239 pixels of 0.25 mm, 8-bit grey) and a known truth; each method's centres are compared
//! with it. Conditions vary one at a time from a base: a 25.4 mm sphere (radius 50.8 pixels, the
//! paper's test spheres), bright on dark, cube markers, read noise 0.01 of full scale (2.55 grey
//! levels), no blur. The e study films whole collisions of 12.7 mm spheres (`experiment::simulate`),
//! measures centres in every frame where both spheres are wholly in view and apart, and runs
//! `kinematics` (fixed gravity) on them.

mod centre;
mod detector;
mod e_study;
mod naive;

use centre::{CentreRow, centre_study};
use e_study::{ERow, e_study};
use rand::SeedableRng;
use rand::rngs::StdRng;
use restitution::data::{fmt_num, write_all_atomic};
use restitution::experiment::Camera;
use restitution::frames::GrayImage;
use restitution::plot::frames_accuracy::{Line, Panel, accuracy_svg};
use std::path::PathBuf;

const CAMERA: Camera = Camera::PAPER;
/// Frames per condition of the single-frame study.
const PER_CONDITION: usize = 60;
/// Collisions per speed in the e study.
const PER_SPEED: usize = 40;
const SUBPIXELS_PER_PIXEL: f64 = 4.0;

/// What a method found of one sphere: centre and radius (pixels; col right, row down from the
/// top-left corner, pixel centres at +0.5) and marker positions (same coordinates).
#[derive(Debug, Clone)]
pub struct Found {
    pub centre: [f64; 2],
    pub radius: f64,
    pub markers: Vec<[f64; 2]>,
}

/// A centre-finding method: the spheres near `hints` (rough positions, used only to say which
/// found sphere is which; `radii` are the known radii), or None where it found none.
pub type Method = fn(&GrayImage, &[[f64; 2]], &[f64]) -> Vec<Option<Found>>;

fn methods() -> Vec<(&'static str, Method)> {
    vec![
        ("naive blob centroid", naive_centres),
        ("detector (src/frames)", detector::detector),
    ]
}

/// The naive baseline: for each hint, the centroid of the blob nearest to it (within half the
/// radius, else none).
fn naive_centres(img: &GrayImage, hints: &[[f64; 2]], radii: &[f64]) -> Vec<Option<Found>> {
    let blobs = naive::blobs(img);
    hints
        .iter()
        .zip(radii)
        .map(|(h, r)| {
            blobs
                .iter()
                .map(|b| ((b.col - h[0]).hypot(b.row - h[1]), b))
                .filter(|(d, _)| *d < 0.5 * r)
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, b)| Found {
                    centre: [b.col, b.row],
                    radius: (b.area as f64 / std::f64::consts::PI).sqrt(),
                    markers: Vec::new(),
                })
        })
        .collect()
}

fn main() -> Result<(), String> {
    let out = PathBuf::from("reports/frames");
    let mut rng = StdRng::seed_from_u64(1997);
    let centre = centre_study(&mut rng);
    let e_rows = e_study(&mut rng);

    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "sweep",
        "x",
        "radius_px",
        "read_noise",
        "blur_px",
        "lighting",
        "method",
        "frames",
        "failed",
        "rms_px",
        "rms_subpixels",
        "bias_col_px",
        "bias_row_px",
        "p95_px",
    ])
    .map_err(|e| e.to_string())?;
    for r in &centre {
        let c = &r.cond;
        let s = &r.stats;
        w.write_record([
            c.sweep.to_string(),
            fmt_num(c.x),
            fmt_num(c.radius_px),
            fmt_num(c.read_noise),
            fmt_num(c.blur_px),
            c.lighting.to_string(),
            r.method.to_string(),
            s.n.to_string(),
            s.failed.to_string(),
            fmt_num(s.rms),
            fmt_num(s.rms * SUBPIXELS_PER_PIXEL),
            fmt_num(s.bias[0]),
            fmt_num(s.bias[1]),
            fmt_num(s.p95),
        ])
        .map_err(|e| e.to_string())?;
    }
    let centre_csv = w.into_inner().map_err(|e| e.to_string())?;
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "v_n_m_s",
        "exposure_s",
        "method",
        "collisions",
        "measured",
        "rms_rel_e",
        "median_abs_rel_e",
        "spins_measured",
        "spin_rms_err_rad_s",
    ])
    .map_err(|e| e.to_string())?;
    for r in &e_rows {
        w.write_record([
            fmt_num(r.v_n),
            fmt_num(r.exposure_s),
            r.method.clone(),
            r.simulated.to_string(),
            r.measured.to_string(),
            fmt_num(r.rms_rel),
            fmt_num(r.median_abs_rel),
            r.spins.to_string(),
            if r.spins > 0 {
                fmt_num(r.spin_rms_rad_s)
            } else {
                String::new()
            },
        ])
        .map_err(|e| e.to_string())?;
    }
    let e_csv = w.into_inner().map_err(|e| e.to_string())?;

    let svg = figure(&centre, &e_rows)?;
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    write_all_atomic(&[
        (out.join("centre_accuracy.csv"), centre_csv),
        (out.join("e_accuracy.csv"), e_csv),
        (out.join("accuracy.svg"), svg.into_bytes()),
    ])
    .map_err(|e| format!("{}: {e}", out.display()))?;
    for r in centre
        .iter()
        .filter(|r| r.cond.sweep.starts_with("lighting") || r.cond.sweep == "base")
    {
        println!(
            "{:>15} {:>15} noise {:>5}: {:>22} rms {:.4} px ({:.3} subpixels), p95 {:.4}, failed {}",
            r.cond.sweep,
            r.cond.lighting,
            r.cond.read_noise,
            r.method,
            r.stats.rms,
            r.stats.rms * SUBPIXELS_PER_PIXEL,
            r.stats.p95,
            r.stats.failed
        );
    }
    for r in &e_rows {
        println!(
            "e: v_n {} m/s, exposure {} s, {}: {}/{} measured, rms {:.5}, median |rel| {:.5}; {} spins, rms error {:.3} rad/s",
            r.v_n,
            r.exposure_s,
            r.method,
            r.measured,
            r.simulated,
            r.rms_rel,
            r.median_abs_rel,
            r.spins,
            r.spin_rms_rad_s
        );
    }
    println!(
        "wrote {}/centre_accuracy.csv, e_accuracy.csv, accuracy.svg",
        out.display()
    );
    Ok(())
}

fn figure(centre: &[CentreRow], e_rows: &[ERow]) -> Result<String, String> {
    let mut names: Vec<&str> = Vec::new();
    for r in centre {
        if !names.contains(&r.method) {
            names.push(r.method);
        }
    }
    let refs = vec![
        ("paper: s = 2 subpixels = 0.5 px".to_string(), 0.5),
        ("aim, clean: 0.02 px".to_string(), 0.02),
    ];
    let panel = |sweep: &str, title: &str, x_desc: &str, log_x: bool| Panel {
        title: title.into(),
        x_desc: x_desc.into(),
        y_desc: "rms centre error (pixels)".into(),
        log_x,
        lines: names
            .iter()
            .map(|n| Line {
                label: n.to_string(),
                points: centre
                    .iter()
                    .filter(|r| r.cond.sweep == sweep && r.method == *n)
                    // Zero noise and zero blur go at the left end of a log axis as 1e-3 and 0.3.
                    .map(|r| {
                        (
                            if log_x && r.cond.x == 0.0 {
                                if sweep == "noise" { 1e-3 } else { 0.3 }
                            } else {
                                r.cond.x
                            },
                            r.stats.rms,
                        )
                    })
                    .collect(),
            })
            .collect(),
        references: refs.clone(),
    };
    let mut e_lines = Vec::new();
    let mut labels: Vec<(String, f64)> = Vec::new();
    for r in e_rows {
        if !labels
            .iter()
            .any(|(m, x)| *m == r.method && *x == r.exposure_s)
        {
            labels.push((r.method.clone(), r.exposure_s));
        }
    }
    for (m, x) in labels {
        e_lines.push(Line {
            label: if x > 0.0 {
                format!("{m}, {} ms exposure", x * 1e3)
            } else {
                m.clone()
            },
            points: e_rows
                .iter()
                .filter(|r| r.method == m && r.exposure_s == x)
                .map(|r| (r.v_n, 100.0 * r.rms_rel))
                .collect(),
        });
    }
    let panels = vec![
        panel(
            "noise",
            "against read noise (R = 50.8 px)",
            "read noise sd (full scale; 0 drawn at 1e-3)",
            true,
        ),
        panel(
            "radius",
            "against sphere size",
            "sphere radius (pixels)",
            true,
        ),
        panel(
            "blur",
            "against motion blur (R = 50.8 px)",
            "blur length (pixels; 0 drawn at 0.3)",
            true,
        ),
        Panel {
            title: "e through kinematics (12.7 mm spheres, fixed gravity)".into(),
            x_desc: "normal impact speed v_n (m/s)".into(),
            y_desc: "rms error of e (%)".into(),
            log_x: true,
            lines: e_lines,
            references: vec![],
        },
    ];
    Ok(accuracy_svg(
        &panels,
        2,
        "Rendered frames: centre error by method (paper's camera, 8-bit, bright on dark)",
    )?)
}
