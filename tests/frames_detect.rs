//! Detection on synthetic frames with known truth.
mod common;
use common::synth::{Scene, ball};
use restitution::frames::detect::{DetectSettings, detect_frame};

fn errors(scene: &Scene, s: &DetectSettings) -> Vec<(f64, f64, f64)> {
    let img = scene.render();
    let det = detect_frame(&img, s).unwrap_or_else(|e| panic!("{e}"));
    let h = img.height as f64;
    scene
        .balls
        .iter()
        .map(|b| {
            let best = det
                .spheres
                .iter()
                .min_by(|a, c| {
                    let da = (a.circle.cx - b.centre[0]).hypot(h - a.circle.cy - b.centre[1]);
                    let dc = (c.circle.cx - b.centre[0]).hypot(h - c.circle.cy - b.centre[1]);
                    da.total_cmp(&dc)
                })
                .unwrap();
            (
                best.circle.cx - b.centre[0],
                h - best.circle.cy - b.centre[1],
                best.circle.r - b.radius,
            )
        })
        .collect()
}

#[test]
fn explore() {
    let mut sc = Scene::paper_like(192, 239, vec![ball([52.3, 150.6], 40.0, 12), ball([140.2, 80.4], 40.0, 12)]);
    for (name, noise, lamps) in [("clean", 0.0, [0.45, 0.45]), ("noisy", 0.01, [0.55, 0.35]), ("dim", 0.01, [0.6, 0.1])] {
        sc.noise = noise;
        sc.lamps = lamps;
        for (sig, sf, kr) in [(1.0, 0.4, 0.0), (0.7, 0.4, 0.0), (1.0, 0.4, 40.0), (0.7, 0.4, 40.0), (0.7, 0.4, 39.7)] {
            let mut s = DetectSettings::default();
            if kr > 0.0 { s.known_radii_px = vec![kr]; }
            s.profile.sigma = sig;
            s.step_fraction = sf;
            let e = errors(&sc, &s);
            eprintln!("{name} sigma {sig} sf {sf} kr {kr}: {}", e.iter().map(|x| format!("({:.3} {:.3} {:.3})", x.0, x.1, x.2)).collect::<Vec<_>>().join(" "));
        }
    }
}

#[test]
fn dump_dim() {
    let mut sc = Scene::paper_like(192, 239, vec![ball([52.3, 150.6], 40.0, 12), ball([140.2, 80.4], 40.0, 12)]);
    sc.noise = 0.01;
    sc.lamps = [0.6, 0.1];
    let img = sc.render();
    let mut s = DetectSettings::default();
    s.profile.sigma = 0.7;
    let det = detect_frame(&img, &s).unwrap();
    let mut out = image::RgbImage::new(img.width as u32 * 3, img.height as u32 * 3);
    for (x, y, p) in out.enumerate_pixels_mut() {
        let v = (img.get((x / 3) as usize, (y / 3) as usize) * 255.0) as u8;
        *p = image::Rgb([v, v, v]);
    }
    for sp in &det.spheres {
        for (e, &inl) in sp.edges.iter().zip(&sp.inliers) {
            let (x, y) = ((e.u * 3.0) as u32, (e.v * 3.0) as u32);
            if x < out.width() && y < out.height() {
                out.put_pixel(x, y, if inl { image::Rgb([0, 255, 0]) } else { image::Rgb([255, 0, 0]) });
            }
        }
        eprintln!("{:?} n {} cov {}", sp.circle, sp.n_edge, sp.coverage_deg);
    }
    out.save("/tmp/dim.png").unwrap();
}
