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

mod detector;
mod naive;

use nalgebra::{UnitQuaternion, Vector3};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use restitution::contact::{Pair, Sphere};
use restitution::data::{fmt_num, write_all_atomic};
use restitution::experiment::{Camera, ExperimentSpec, simulate};
use restitution::fit::models::{ModelKind, predict_e};
use restitution::frames::GrayImage;
use restitution::frames::render::{
    FilmSpec, Lighting, Renderer, Sensor, SpherePose, View, expose, film_collision, marker_pattern,
};
use restitution::frames::spin::{MarkerFrame, lift, phase_spin};
use restitution::kinematics::{FitKind, Frame, measure_e};
use restitution::models::viscoelastic::{ContactEnd, VmMethod};
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

/// One condition of the single-frame study.
#[derive(Debug, Clone, Copy)]
struct Condition {
    sweep: &'static str,
    x: f64,
    radius_px: f64,
    read_noise: f64,
    blur_px: f64,
    lighting: &'static str,
}

const BASE: Condition = Condition {
    sweep: "base",
    x: 0.0,
    radius_px: 50.8,
    read_noise: 0.01,
    blur_px: 0.0,
    lighting: "bright-on-dark",
};

fn random_rotation(rng: &mut StdRng) -> UnitQuaternion<f64> {
    let q: [f64; 4] = std::array::from_fn(|_| StandardNormal.sample(rng));
    UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// Renders one frame of a single sphere for `c`; returns it and the true centre (col, row).
fn single_frame(c: &Condition, rng: &mut StdRng) -> (GrayImage, [f64; 2]) {
    let p = CAMERA.pixel_m();
    let (w, h) = (CAMERA.pixels_x as usize, CAMERA.pixels_y as usize);
    let rend = Renderer::new(
        View {
            width: w,
            height: h,
            pixel_m: p,
            supersample: 8,
        },
        Lighting::preset(c.lighting).expect("a preset"),
        marker_pattern("cube", 10f64.to_radians()).expect("a pattern"),
    )
    .expect("valid settings");
    let u = 0.5 * w as f64 + rng.random_range(-2.0..2.0);
    let v = 0.5 * h as f64 + rng.random_range(-2.0..2.0);
    let q = random_rotation(rng);
    let dir: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    // Blur of blur_px over a 0.5 ms exposure; sub-frames every 0.1 pixel of motion.
    let exposure = 5e-4;
    let speed_px_s = c.blur_px / exposure;
    let subframes = ((c.blur_px / 0.1).ceil() as usize).max(1);
    let poses = |t: f64| {
        Ok(vec![SpherePose {
            centre_m: Vector3::new(
                (u + speed_px_s * t * dir.cos()) * p,
                (v + speed_px_s * t * dir.sin()) * p,
                0.0,
            ),
            radius_m: c.radius_px * p,
            orientation: q,
        }])
    };
    let clean = rend
        .render_exposure(
            &poses,
            0.0,
            if c.blur_px > 0.0 { exposure } else { 0.0 },
            subframes,
        )
        .expect("renders");
    let sensor = Sensor {
        read_noise: c.read_noise,
        full_well_e: None,
        bits: Some(8),
    };
    let img = expose(&clean, &sensor, rng).expect("exposes");
    (img, [u, h as f64 - v])
}

/// Error statistics of one method under one condition, pixels.
#[derive(Debug, Clone)]
struct Stats {
    n: usize,
    failed: usize,
    rms: f64,
    bias: [f64; 2],
    p95: f64,
}

fn stats(errors: &[[f64; 2]], failed: usize) -> Stats {
    let n = errors.len();
    let mut radial: Vec<f64> = errors.iter().map(|e| e[0].hypot(e[1])).collect();
    radial.sort_by(f64::total_cmp);
    let m = n.max(1) as f64;
    Stats {
        n,
        failed,
        rms: (radial.iter().map(|r| r * r).sum::<f64>() / m).sqrt(),
        bias: [
            errors.iter().map(|e| e[0]).sum::<f64>() / m,
            errors.iter().map(|e| e[1]).sum::<f64>() / m,
        ],
        p95: radial
            .get(((0.95 * n as f64).ceil() as usize).saturating_sub(1))
            .copied()
            .unwrap_or(f64::NAN),
    }
}

fn conditions() -> Vec<Condition> {
    let mut out = Vec::new();
    for x in [0.0, 0.005, 0.01, 0.02, 0.05, 0.1] {
        out.push(Condition {
            sweep: "noise",
            x,
            read_noise: x,
            ..BASE
        });
    }
    for x in [6.35, 12.7, 25.4, 50.8, 76.2] {
        out.push(Condition {
            sweep: "radius",
            x,
            radius_px: x,
            ..BASE
        });
    }
    for x in [0.0, 1.0, 2.0, 5.0, 10.0, 20.0] {
        out.push(Condition {
            sweep: "blur",
            x,
            blur_px: x,
            ..BASE
        });
    }
    for (i, l) in ["bright-on-dark", "dark-on-bright", "uneven-lamps"]
        .iter()
        .enumerate()
    {
        out.push(Condition {
            sweep: "lighting",
            x: i as f64,
            lighting: l,
            ..BASE
        });
        out.push(Condition {
            sweep: "lighting_clean",
            x: i as f64,
            lighting: l,
            read_noise: 0.0,
            ..BASE
        });
    }
    out
}

struct CentreRow {
    cond: Condition,
    method: &'static str,
    stats: Stats,
}

fn centre_study(rng: &mut StdRng) -> Vec<CentreRow> {
    let ms = methods();
    let mut rows = Vec::new();
    for cond in conditions() {
        let mut errs: Vec<Vec<[f64; 2]>> = vec![Vec::new(); ms.len()];
        let mut failed = vec![0usize; ms.len()];
        for _ in 0..PER_CONDITION {
            let (img, truth) = single_frame(&cond, rng);
            for (k, (_, m)) in ms.iter().enumerate() {
                match &m(&img, &[truth], &[cond.radius_px])[0] {
                    Some(f) => errs[k].push([f.centre[0] - truth[0], f.centre[1] - truth[1]]),
                    None => failed[k] += 1,
                }
            }
        }
        for (k, (name, _)) in ms.iter().enumerate() {
            rows.push(CentreRow {
                cond,
                method: name,
                stats: stats(&errs[k], failed[k]),
            });
        }
        eprintln!("centre study: {} = {} done", cond.sweep, cond.x);
    }
    rows
}

struct ERow {
    v_n: f64,
    exposure_s: f64,
    method: String,
    simulated: usize,
    measured: usize,
    rms_rel: f64,
    median_abs_rel: f64,
    /// Spins (w_z, per sphere and phase) measured, and their rms error, rad/s.
    spins: usize,
    spin_rms_rad_s: f64,
}

/// Matching tolerance of markers between frames, radians (as in the spin module's tests; a
/// spin of 3 rad/s turns a marker by 0.003 rad per frame).
const SPIN_TOL_RAD: f64 = 0.05;
/// Markers beyond this fraction of the radius are not lifted (z ill-determined near the limb).
const LIFT_MAX_FRAC: f64 = 0.9;

/// e (and the spins) through the chain at each speed: truth centres plus the paper's s = 2
/// subpixels of Gaussian noise, and each method's centres, on the same frames.
fn e_study(rng: &mut StdRng) -> Vec<ERow> {
    let material = restitution::contact::Material::preset("nylon").expect("preset");
    let d = 0.0127;
    let s1 = Sphere::new(d, material).expect("sphere");
    let contact = Pair::unequal(s1, s1).contact();
    let e_of = |v: f64| {
        predict_e(
            ModelKind::Product,
            &contact,
            v,
            &[190.0, 4.0e7],
            ContactEnd::Overlap,
            &VmMethod::Master,
        )
    };
    let p = CAMERA.pixel_m();
    let h_px = CAMERA.pixels_y as f64;
    let ms = methods();
    let mut rows = Vec::new();
    for exposure in [0.0, 2.5e-4] {
        for v in [1.0, 2.0, 5.0, 10.0] {
            let spec = ExperimentSpec {
                n: PER_SPEED,
                d1_m: d,
                d2_m: d,
                v_n_range_m_s: (v, v),
                incidence_deg: (0.0, 30.0),
                ..ExperimentSpec::paper()
            };
            let sims = simulate(&spec, &e_of, rng).expect("simulates");
            let film = FilmSpec::new(
                &CAMERA,
                Lighting::BRIGHT_ON_DARK,
                marker_pattern("cube", 10f64.to_radians()).expect("pattern"),
                8,
                Sensor {
                    read_noise: 0.01,
                    full_well_e: None,
                    bits: Some(8),
                },
                exposure,
            )
            .expect("film spec");
            let labels: Vec<String> = std::iter::once("truth + s = 2 subpixels".to_string())
                .chain(ms.iter().map(|(n, _)| n.to_string()))
                .collect();
            let mut rel: Vec<Vec<f64>> = vec![Vec::new(); labels.len()];
            let mut spin_err: Vec<Vec<f64>> = vec![Vec::new(); labels.len()];
            let sigma_px = 2.0 / SUBPIXELS_PER_PIXEL;
            for sim in &sims {
                let f = film_collision(sim, &film, rng).expect("films");
                let mut tracks: Vec<(Vec<Frame>, usize)> = vec![(Vec::new(), 0); labels.len()];
                // Marker frames per method, sphere and phase.
                let mut marks: Vec<[[Vec<MarkerFrame>; 2]; 2]> =
                    (0..labels.len()).map(|_| Default::default()).collect();
                let mut true_wz = [[f64::NAN; 2]; 2];
                for (img, t) in f.frames.iter().zip(&f.truth) {
                    let [a, b] = t.spheres;
                    let phase = usize::from(t.post);
                    true_wz[0][phase] = a.spin_rad_s[2];
                    true_wz[1][phase] = b.spin_rad_s[2];
                    let gap = (a.col_px - b.col_px).hypot(a.row_px - b.row_px)
                        - a.radius_px
                        - b.radius_px;
                    // A frame whose exposure spans the contact mixes two flights.
                    if !(a.in_view && b.in_view && gap > 3.0 && t.t_s.abs() > 0.5 * exposure) {
                        continue;
                    }
                    let truth = [[a.col_px, a.row_px], [b.col_px, b.row_px]];
                    let mut found: Vec<Option<[Found; 2]>> = Vec::new();
                    let noisy = truth.map(|c| Found {
                        centre: c.map(|x| {
                            let z: f64 = StandardNormal.sample(rng);
                            x + sigma_px * z
                        }),
                        radius: a.radius_px,
                        markers: Vec::new(),
                    });
                    found.push(Some(noisy));
                    for (_, m) in &ms {
                        let mut c = m(img, &truth, &[a.radius_px, b.radius_px]);
                        found.push(match (c[0].take(), c[1].take()) {
                            (Some(x), Some(y)) => Some([x, y]),
                            _ => None,
                        });
                    }
                    let to_m = |c: [f64; 2]| [c[0] * p, (h_px - c[1]) * p];
                    for (k, fd) in found.into_iter().enumerate() {
                        let Some(pair) = fd else { continue };
                        if !t.post {
                            tracks[k].1 += 1;
                        }
                        tracks[k].0.push(Frame {
                            t_s: t.t_s,
                            r1_m: to_m(pair[0].centre),
                            r2_m: to_m(pair[1].centre),
                        });
                        for (i, s) in pair.iter().enumerate() {
                            // The spin module works y up.
                            let up = |c: [f64; 2]| [c[0], h_px - c[1]];
                            let pts: Vec<[f64; 2]> = s.markers.iter().map(|&m| up(m)).collect();
                            marks[k][i][phase].push(MarkerFrame {
                                t_s: t.t_s,
                                dirs: lift(up(s.centre), s.radius, &pts, LIFT_MAX_FRAC),
                            });
                        }
                    }
                }
                for (k, (frames, split)) in tracks.iter().enumerate() {
                    let kind = FitKind::FixedGravity {
                        g_m_s2: spec.g_m_s2,
                    };
                    if let Ok((e, _)) = measure_e(frames, *split, d, d, kind)
                        && e.is_finite()
                    {
                        rel[k].push(e / sim.e - 1.0);
                    }
                    for i in 0..2 {
                        for ph in 0..2 {
                            let mf = &marks[k][i][ph];
                            if mf.iter().all(|m| m.dirs.is_empty()) {
                                continue;
                            }
                            if let Some(wz) = phase_spin(mf, SPIN_TOL_RAD).wz() {
                                spin_err[k].push(wz - true_wz[i][ph]);
                            }
                        }
                    }
                }
            }
            for (k, label) in labels.iter().enumerate() {
                let r = &rel[k];
                let m = r.len().max(1) as f64;
                let mut abs: Vec<f64> = r.iter().map(|x| x.abs()).collect();
                abs.sort_by(f64::total_cmp);
                let se = &spin_err[k];
                rows.push(ERow {
                    v_n: v,
                    exposure_s: exposure,
                    method: label.clone(),
                    simulated: sims.len(),
                    measured: r.len(),
                    rms_rel: (r.iter().map(|x| x * x).sum::<f64>() / m).sqrt(),
                    median_abs_rel: abs.get(abs.len() / 2).copied().unwrap_or(f64::NAN),
                    spins: se.len(),
                    spin_rms_rad_s: if se.is_empty() {
                        f64::NAN
                    } else {
                        (se.iter().map(|x| x * x).sum::<f64>() / se.len() as f64).sqrt()
                    },
                });
            }
            eprintln!("e study: v_n = {v} m/s, exposure {exposure} s done");
        }
    }
    rows
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
    accuracy_svg(
        &panels,
        2,
        "Rendered frames: centre error by method (paper's camera, 8-bit, bright on dark)",
    )
}
