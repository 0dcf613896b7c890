//! The e study: whole collisions filmed, centres measured, e through `kinematics`; spins from
//! the detector's markers.

use super::{CAMERA, Found, PER_SPEED, SUBPIXELS_PER_PIXEL, methods};
use rand::rngs::StdRng;
use rand_distr::{Distribution, StandardNormal};
use restitution::contact::{Pair, Sphere};
use restitution::experiment::{ExperimentSpec, simulate};
use restitution::fit::models::{ModelKind, predict_e};
use restitution::frames::render::{FilmSpec, Lighting, Sensor, film_collision, marker_pattern};
use restitution::frames::spin::{MarkerFrame, lift, phase_spin};
use restitution::kinematics::{FitKind, Frame, measure_e};
use restitution::models::viscoelastic::{ContactEnd, VmMethod};

pub struct ERow {
    pub v_n: f64,
    pub exposure_s: f64,
    pub method: String,
    pub simulated: usize,
    pub measured: usize,
    pub rms_rel: f64,
    pub median_abs_rel: f64,
    /// Spins (w_z, per sphere and phase) measured, and their rms error, rad/s.
    pub spins: usize,
    pub spin_rms_rad_s: f64,
}

/// Matching tolerance of markers between frames, radians (as in the spin module's tests; a
/// spin of 3 rad/s turns a marker by 0.003 rad per frame).
const SPIN_TOL_RAD: f64 = 0.05;
/// Markers beyond this fraction of the radius are not lifted (z ill-determined near the limb).
const LIFT_MAX_FRAC: f64 = 0.9;

/// e (and the spins) through the chain at each speed: truth centres plus the paper's s = 2
/// subpixels of Gaussian noise, and each method's centres, on the same frames.
pub fn e_study(rng: &mut StdRng) -> Vec<ERow> {
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
