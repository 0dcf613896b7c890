//! A whole collision from synthetic frames (tests/common/synth.rs): identities, centres, the
//! scale from the diameters, the phase split and the spins, against the rendered truth.
mod common;
use common::synth::collision_sequence;
use restitution::frames::detect::{DetectSettings, detect_frame};
use restitution::frames::spin::Spin;
use restitution::frames::track::{CollisionResult, FrameMeta, TrackSettings, assemble};

fn track(r_px: f64, d_mm: f64, pixel_m: Option<f64>) -> (CollisionResult, common::synth::Sequence) {
    let seq = collision_sequence(r_px, 5.1, 12, &[108]);
    let input: Vec<_> = seq
        .frames
        .iter()
        .map(|(n, sc, _)| {
            (
                FrameMeta {
                    number: *n,
                    name: format!("f{n}.png"),
                },
                detect_frame(&sc.render(), &DetectSettings::default()).map_err(Into::into),
            )
        })
        .collect();
    let s = TrackSettings {
        fps: seq.fps,
        pixel_m,
        d_m: Some([d_mm * 1e-3; 2]),
        strict: true,
        free_coverage_deg: 240.0,
    };
    (assemble("c", input, &s).unwrap(), seq)
}

/// Per sphere: the largest centre error and the rms of the error about its mean (the part that
/// does not cancel in velocities), pixels.
fn centre_stats(r: &CollisionResult, seq: &common::synth::Sequence) -> [(f64, f64); 2] {
    std::array::from_fn(|k| {
        let errs: Vec<[f64; 2]> = r
            .frames
            .iter()
            .zip(&seq.frames)
            .map(|(f, (_, _, truth))| {
                let o = f.spheres[k].as_ref().expect("found");
                [o.x_px - truth[k][0], o.y_px - truth[k][1]]
            })
            .collect();
        let n = errs.len() as f64;
        let m = [
            errs.iter().map(|e| e[0]).sum::<f64>() / n,
            errs.iter().map(|e| e[1]).sum::<f64>() / n,
        ];
        let worst = errs.iter().map(|e| e[0].hypot(e[1])).fold(0.0, f64::max);
        let spread = (errs
            .iter()
            .map(|e| (e[0] - m[0]).powi(2) + (e[1] - m[1]).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        (worst, spread)
    })
}

#[test]
fn paper_camera_collision() {
    // 12.7 mm spheres at 0.25 mm/pixel (the paper's camera: 48 mm over 192 pixels).
    let (r, seq) = track(25.4, 12.7, None);
    assert_eq!(r.frames.len(), 11);
    assert_eq!(r.tracks.len(), 11);
    // Frames 100-105 before the contact at 105.1, 106-111 after (108 not filmed).
    assert_eq!(r.split, Some(6));
    assert!((r.tracks[8].t_s - 0.009).abs() < 1e-15);
    let stats = centre_stats(&r, &seq);
    eprintln!("centres: {stats:?}, scale {:?}", r.scale);
    // Identities held through the contact (frame 105 nearly touches): a swap would be a 60 px
    // error. Worst centre error measured 0.46 px (sphere 2, whose right limb the weaker lamp
    // leaves dim); bar 0.8 px. Spread about the mean, what velocities see, measured 0.18 px;
    // bar 0.4 px.
    for (worst, spread) in stats {
        assert!(worst < 0.8 && spread < 0.4, "{stats:?}");
    }
    // Scale from the diameters: the fitted radii are 0.5-0.7 px short of 25.4 px (limb
    // shading), so the pixel size comes out 2.2% large. Bar 4%. Its standard error reflects
    // only the scatter, not this bias.
    let rel = r.scale.pixel_m / 0.25e-3 - 1.0;
    assert!(rel > 0.0 && rel < 0.04, "{rel}");
    assert!(r.scale.from_diameters && r.scale.err_m.is_some());
    // Spins: 2-3 markers per visible hemisphere turning 0.04-0.07 rad per frame, centroids good
    // to ~0.2 px on a 25 px radius (0.008 rad): about 8 rad/s per frame pair. Each component
    // within 3 of its reported standard errors plus 3 rad/s (the error estimate from 4-5
    // pairs is itself rough). Measured: at most 6.1 rad/s off (sphere 2's w_y after the
    // collision, 3.9 of its standard errors: the estimate runs small).
    for k in 0..2 {
        for ph in 0..2 {
            let truth = seq.spins[k][ph];
            match &r.spins[k][ph] {
                Spin::Full {
                    w_rad_s, err_rad_s, ..
                } => {
                    let err = err_rad_s.expect("4-5 pairs give an error");
                    for c in 0..3 {
                        let d = (w_rad_s[c] - truth[c]).abs();
                        eprintln!(
                            "sphere {k} phase {ph} comp {c}: {d:.2} vs err {:.2}",
                            err[c]
                        );
                        assert!(
                            d < 3.0 * err[c] + 3.0,
                            "sphere {k} phase {ph}: {w_rad_s:?} vs {truth:?} +- {err:?}"
                        );
                    }
                }
                other => panic!("sphere {k} phase {ph}: {other:?}"),
            }
        }
    }
}

#[test]
fn larger_spheres_with_a_given_pixel_size() {
    // Radius 40 px, pixel size given: the spins are better resolved (more markers inside 85% of
    // the radius, larger marker motion in pixels).
    let (r, seq) = track(40.0, 20.0, Some(0.25e-3));
    assert!(!r.scale.from_diameters);
    let stats = centre_stats(&r, &seq);
    eprintln!("centres: {stats:?}");
    // Measured: worst 0.42 px, spread 0.20 px.
    for (worst, spread) in stats {
        assert!(worst < 0.8 && spread < 0.4, "{stats:?}");
    }
    for k in 0..2 {
        for ph in 0..2 {
            let truth = seq.spins[k][ph];
            let w = match &r.spins[k][ph] {
                Spin::Full { w_rad_s, .. } => *w_rad_s,
                other => panic!("{other:?}"),
            };
            let d: Vec<f64> = (0..3).map(|c| w[c] - truth[c]).collect();
            eprintln!("sphere {k} phase {ph}: error {d:?}");
            // Measured: at most 4.7 rad/s on spins of 20-70 rad/s. Bar 9 rad/s.
            assert!(
                d.iter().all(|x| x.abs() < 9.0),
                "sphere {k} phase {ph}: {d:?}"
            );
        }
    }
}

/// A sphere at rest spinning about each axis in turn, 6 frames at 1000 frames/s, radius 40 px,
/// 12 dots of 0.15 rad: the spin from the marker pipeline (detection, lifting, matching,
/// Kabsch) against the rendered one. Measured errors at most 1.5 rad/s on 30 rad/s (the dots'
/// centroids, 0.05-0.1 px, over 0.03 rad per frame); bar 3 rad/s.
#[test]
fn spin_of_a_sphere_at_rest() {
    use common::synth::{Scene, ball};
    use nalgebra::{Rotation3, Vector3};
    use restitution::frames::spin::{MarkerFrame, lift, phase_spin};
    let mut worst: f64 = 0.0;
    for (w, noise) in [
        (Vector3::new(0.0, 30.0, 0.0), 0.0),
        (Vector3::new(0.0, 30.0, 0.0), 0.01),
        (Vector3::new(30.0, 0.0, 0.0), 0.0),
        (Vector3::new(0.0, 0.0, 30.0), 0.0),
    ] {
        let mf: Vec<MarkerFrame> = (0..6)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let mut b = ball([96.0, 120.0], 40.0, 12);
                b.marker_rad = 0.15;
                b.attitude = Rotation3::from_scaled_axis(w * t)
                    * Rotation3::from_euler_angles(0.3, -0.2, 0.5);
                let mut sc = Scene::paper_like(192, 239, vec![b]);
                sc.noise = noise;
                let img = sc.render();
                let d = detect_frame(&img, &DetectSettings::default()).unwrap();
                let (sp, h) = (&d.spheres[0], img.height as f64);
                let m: Vec<[f64; 2]> = d.markers[0].iter().map(|m| [m.u, h - m.v]).collect();
                MarkerFrame {
                    t_s: t,
                    dirs: lift([sp.circle.cx, h - sp.circle.cy], sp.circle.r, &m, 0.85),
                }
            })
            .collect();
        match phase_spin(&mf, 0.05) {
            Spin::Full { w_rad_s, pairs, .. } => {
                assert_eq!(pairs, 5);
                for c in 0..3 {
                    assert!((w_rad_s[c] - w[c]).abs() < 3.0, "{w_rad_s:?} vs {w:?}");
                    worst = worst.max((w_rad_s[c] - w[c]).abs());
                }
            }
            other => panic!("{other:?}"),
        }
    }
    // The README quotes this figure.
    eprintln!("frames_track: spin_of_a_sphere_at_rest: worst component error {worst:.2} rad/s");
}
