//! A whole collision from synthetic frames: centres, identities, scale and spins against truth.
mod common;
use common::synth::collision_sequence;
use restitution::frames::detect::{DetectSettings, detect_frame};
use restitution::frames::spin::Spin;
use restitution::frames::track::{FrameMeta, TrackSettings, assemble};

#[test]
fn explore_sequence() {
    let seq = collision_sequence(25.4, 5.1, 12, &[108]);
    let p = 0.25e-3;
    let input: Vec<_> = seq
        .frames
        .iter()
        .map(|(n, sc, _)| {
            let img = sc.render();
            (
                FrameMeta {
                    number: *n,
                    name: format!("f{n}.png"),
                },
                detect_frame(&img, &DetectSettings::default()).map_err(|e| e.to_string()),
            )
        })
        .collect();
    let s = TrackSettings {
        fps: seq.fps,
        pixel_m: None,
        d_m: Some([12.7e-3; 2]),
        strict: false,
        free_coverage_deg: 240.0,
    };
    let r = assemble("c", input, &s).unwrap();
    eprintln!(
        "scale {:?} warnings {:?} split {:?}",
        r.scale, r.warnings, r.split
    );
    for (f, (_, _, truth)) in r.frames.iter().zip(&seq.frames) {
        let e: Vec<String> = (0..2)
            .map(|k| match &f.spheres[k] {
                Some(o) => format!(
                    "({:.3} {:.3} r{:.3} cov{:.0} {:?} m{})",
                    o.x_px - truth[k][0],
                    o.y_px - truth[k][1],
                    o.r_px,
                    o.coverage_deg,
                    o.radius_mode,
                    o.markers.len()
                ),
                None => "-".into(),
            })
            .collect();
        eprintln!("{} {}", f.meta.number, e.join(" "));
    }
    for k in 0..2 {
        for ph in 0..2 {
            eprintln!(
                "spin {k} {ph}: {:?} truth {:?}",
                r.spins[k][ph],
                seq.spins[k][ph].as_slice()
            );
        }
    }
    let _ = (
        p,
        Spin::None {
            reason: String::new(),
        },
    );
}
