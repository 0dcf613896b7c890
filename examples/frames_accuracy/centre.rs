//! The single-frame study: one sphere per frame, conditions varied one at a time from a base.

use super::{CAMERA, PER_CONDITION, methods};
use nalgebra::{UnitQuaternion, Vector3};
use rand::Rng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, StandardNormal};
use restitution::frames::GrayImage;
use restitution::frames::render::{
    Lighting, Renderer, Sensor, SpherePose, View, expose, marker_pattern,
};

/// One condition of the single-frame study.
#[derive(Debug, Clone, Copy)]
pub struct Condition {
    pub sweep: &'static str,
    pub x: f64,
    pub radius_px: f64,
    pub read_noise: f64,
    pub blur_px: f64,
    pub lighting: &'static str,
}

pub const BASE: Condition = Condition {
    sweep: "base",
    x: 0.0,
    radius_px: 50.8,
    read_noise: 0.01,
    blur_px: 0.0,
    lighting: "bright-on-dark",
};

pub fn random_rotation(rng: &mut StdRng) -> UnitQuaternion<f64> {
    let q: [f64; 4] = std::array::from_fn(|_| StandardNormal.sample(rng));
    UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// Renders one frame of a single sphere for `c`; returns it and the true centre (col, row).
pub fn single_frame(c: &Condition, rng: &mut StdRng) -> (GrayImage, [f64; 2]) {
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
pub struct Stats {
    pub n: usize,
    pub failed: usize,
    pub rms: f64,
    pub bias: [f64; 2],
    pub p95: f64,
}

pub fn stats(errors: &[[f64; 2]], failed: usize) -> Stats {
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

pub fn conditions() -> Vec<Condition> {
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

pub struct CentreRow {
    pub cond: Condition,
    pub method: &'static str,
    pub stats: Stats,
}

pub fn centre_study(rng: &mut StdRng) -> Vec<CentreRow> {
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
