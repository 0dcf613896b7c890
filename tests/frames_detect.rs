//! Detection on synthetic frames with known truth.
mod common;
use common::synth::{Scene, ball};
use restitution::frames::detect::{DetectSettings, detect_frame};

/// Centre errors (dx, dy) and radius error of each ball, pixels, matched to the nearest fit.
fn errors(scene: &Scene, s: &DetectSettings) -> Result<Vec<(f64, f64, f64)>, String> {
    let img = scene.render();
    let det = detect_frame(&img, s).map_err(|e| e.to_string())?;
    let h = img.height as f64;
    Ok(scene
        .balls
        .iter()
        .filter_map(|b| {
            let best = det.spheres.iter().min_by(|a, c| {
                let da = (a.circle.cx - b.centre[0]).hypot(h - a.circle.cy - b.centre[1]);
                let dc = (c.circle.cx - b.centre[0]).hypot(h - c.circle.cy - b.centre[1]);
                da.total_cmp(&dc)
            })?;
            Some((
                best.circle.cx - b.centre[0],
                h - best.circle.cy - b.centre[1],
                best.circle.r - b.radius,
            ))
        })
        .collect())
}

fn show(name: &str, e: &Result<Vec<(f64, f64, f64)>, String>) {
    match e {
        Ok(e) => eprintln!(
            "{name}: {}",
            e.iter()
                .map(|x| format!("({:.3} {:.3} {:.3})", x.0, x.1, x.2))
                .collect::<Vec<_>>()
                .join(" ")
        ),
        Err(e) => eprintln!("{name}: ERR {e}"),
    }
}

#[test]
fn explore() {
    let two = vec![ball([52.3, 150.6], 40.0, 12), ball([140.2, 80.4], 40.0, 12)];
    let sig: f64 = std::env::var("SIG")
        .map(|v| v.parse().unwrap())
        .unwrap_or(0.7);
    let mut d = DetectSettings::default();
    d.profile.sigma = sig;
    let mut known = d.clone();
    known.known_radii_px = vec![40.0];
    let mut sc = Scene::paper_like(192, 239, two.clone());
    sc.noise = 0.0;
    sc.lamps = [0.45, 0.45];
    show("clean", &errors(&sc, &d));
    let mut sc = Scene::paper_like(192, 239, two.clone());
    show("paper-like", &errors(&sc, &d));
    sc.lamps = [0.6, 0.1];
    show("dim known", &errors(&sc, &known));
    // touching
    let mut sc = Scene::paper_like(
        192,
        239,
        vec![
            ball([60.3, 120.6], 40.0, 12),
            ball([60.3 + 80.0 * 0.8, 120.6 + 80.0 * 0.6], 40.0, 12),
        ],
    );
    show("touching", &errors(&sc, &d));
    sc.balls[1].centre = [60.3 + 81.0 * 0.8, 120.6 + 81.0 * 0.6];
    show("gap 1px", &errors(&sc, &d));
    // dark on bright
    let mut sc = Scene::paper_like(192, 239, two.clone());
    sc.base = 0.8;
    sc.gx = 0.05;
    sc.gy = -0.05;
    for b in sc.balls.iter_mut() {
        b.albedo = 0.25;
    }
    sc.marker_albedo = 0.02;
    show("dark on bright", &errors(&sc, &d));
    // partly outside
    let mut sc = Scene::paper_like(
        192,
        239,
        vec![ball([20.0, 150.6], 40.0, 12), ball([140.2, 80.4], 40.0, 12)],
    );
    show("outside 20", &errors(&sc, &known));
    sc.balls[0].centre = [-10.0, 150.6];
    show("outside -10", &errors(&sc, &known));
    // blur
    let mut sc = Scene::paper_like(192, 239, two.clone());
    sc.balls[0].blur = [3.0, -1.0];
    sc.balls[1].blur = [-3.0, 1.0];
    sc.blur_steps = 7;
    show("blur 3px", &errors(&sc, &d));
    // small spheres
    let sc = Scene::paper_like(
        192,
        239,
        vec![ball([52.3, 150.6], 12.7, 6), ball([140.2, 80.4], 12.7, 6)],
    );
    show("small", &errors(&sc, &d));
    // unequal
    let sc = Scene::paper_like(
        192,
        239,
        vec![ball([62.3, 150.6], 50.0, 12), ball([140.2, 80.4], 12.5, 6)],
    );
    show("unequal", &errors(&sc, &d));
    // three
    let sc = Scene::paper_like(
        192,
        239,
        vec![
            ball([40.3, 190.6], 25.0, 6),
            ball([140.2, 80.4], 25.0, 6),
            ball([60.0, 60.0], 25.0, 6),
        ],
    );
    show("three", &errors(&sc, &d));
    // none
    let sc = Scene::paper_like(192, 239, vec![]);
    show("none", &errors(&sc, &d));
}
