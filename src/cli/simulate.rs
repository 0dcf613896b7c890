//! `restitution simulate`: a virtual experiment like the paper's apparatus (Sec. III).
//!
//! ```text
//! restitution simulate --out DIR [--n N] [--seed S]
//!     (--material NAME | --youngs-pa Y --poisson NU --density-kg-m3 RHO)
//!     [--d-mm D] [--d2-mm D2]
//!     [--model vm|pm|min|product --eta ETA --sigma-y-pa SIGMA] [--contact-end overlap|force]
//!     [--mu0 M] [--beta0 B] [--v-n-m-s MIN,MAX] [--incidence-deg MIN,MAX]
//!     [--fps F] [--pixels-x N] [--pixels-y N] [--fov-m W] [--subpixel-expansion X]
//!     [--s-subpixels S] [--frames MIN,MAX] [--spin-noise-rad-s W]
//!     [--frames-out DIR [rendering flags: see cli/frames_out.rs]]
//! ```
//! Draws collisions (normal speed log-uniform, incidence uniform), resolves them with Walton's
//! operator with e = e_model(v_n), films both spheres' ballistic flight under gravity at the frame
//! rate, and adds the camera's position noise. Writes `DIR/tracks.csv` (the `kinematics` input),
//! `DIR/truth.csv` (per collision: true v_n, e, beta, psi, velocities) and `DIR/truth.json` (the
//! parameters), all or none. Seeded: the same flags give the same files.

use super::{CliResult, MaterialArgs};
use rand::SeedableRng;
use rand::rngs::StdRng;
use restitution::contact::Pair;
use restitution::data::frames::job::{FPS_RANGE, PIXEL_M_RANGE};
use restitution::data::report::camera_study::camera_study_csv;
use restitution::data::tracks::{CollisionTrack, write_tracks};
use restitution::data::{CsvOut, fmt_num, write_all_atomic};
use restitution::experiment::{
    Camera, ExperimentSpec, STUDY_SPEEDS_M_S, camera_study, simulate, study_cameras,
};
use restitution::fit::models::{ModelKind, predict_e};
use restitution::models::viscoelastic::{ContactEnd, VmMethod};
use restitution::models::walton::Target;
use serde_json::json;
use std::path::PathBuf;

/// A virtual experiment: simulated tracks of oblique collisions seen by a high-speed camera
#[derive(clap::Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct Args {
    /// Directory for tracks.csv, truth.csv and truth.json
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Number of collisions (at most 2000)
    #[arg(long, default_value_t = 60, conflicts_with = "camera_study")]
    n: usize,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    #[command(flatten)]
    material: MaterialArgs,
    /// Diameter of sphere 1, mm
    #[arg(long = "d-mm", default_value_t = 25.4)]
    d_mm: f64,
    /// Diameter of sphere 2, mm (default: as sphere 1)
    #[arg(long = "d2-mm")]
    d2_mm: Option<f64>,
    /// Model of e(v_n): vm (eta), pm (sigma_y), min or product (both)
    #[arg(long, default_value = "product", value_parser = parse_model)]
    model: ModelKind,
    /// Damping eta, kg/(s m)
    #[arg(long, default_value_t = 190.0)]
    eta: f64,
    /// Yield stress, Pa
    #[arg(long = "sigma-y-pa", default_value_t = 4.0e7)]
    sigma_y_pa: f64,
    #[arg(long = "contact-end", default_value = "overlap", value_parser = parse_rule)]
    contact_end: ContactEnd,
    /// Walton's friction coefficient
    #[arg(long, default_value_t = 0.175)]
    mu0: f64,
    /// Walton's limiting tangential restitution
    #[arg(long, default_value_t = 0.5)]
    beta0: f64,
    /// Range of the normal impact speed, m/s (log-uniform; the camera study has its own speeds)
    #[arg(long = "v-n-m-s", value_delimiter = ',', default_values_t = [0.5, 5.0],
          conflicts_with = "camera_study")]
    v_n_m_s: Vec<f64>,
    /// Range of the angle of incidence, degrees (0 = head-on)
    #[arg(long = "incidence-deg", value_delimiter = ',', default_values_t = [0.0, 80.0])]
    incidence_deg: Vec<f64>,
    /// Camera frame rate, 1/s
    #[arg(long, default_value_t = Camera::PAPER.frames_per_s)]
    fps: f64,
    #[arg(long = "pixels-x", default_value_t = Camera::PAPER.pixels_x)]
    pixels_x: u32,
    #[arg(long = "pixels-y", default_value_t = Camera::PAPER.pixels_y)]
    pixels_y: u32,
    /// Width of the field of view, m
    #[arg(long = "fov-m", default_value_t = Camera::PAPER.fov_x_m)]
    fov_m: f64,
    #[arg(long = "subpixel-expansion", default_value_t = Camera::PAPER.subpixel_expansion)]
    subpixel_expansion: f64,
    /// Accuracy of a centre, subpixels
    #[arg(long = "s-subpixels", default_value_t = Camera::PAPER.s_subpixels)]
    s_subpixels: f64,
    /// Frames per phase, drawn in this range (fewer when fast, never below 2)
    #[arg(long, value_delimiter = ',', default_values_t = [8usize, 12])]
    frames: Vec<usize>,
    /// Error of spins measured from markers, rad/s
    #[arg(long = "spin-noise-rad-s", default_value_t = 3.0)]
    spin_noise_rad_s: f64,
    /// Instead of tracks: a Monte Carlo of the measured e's bias and scatter against v_n for
    /// this camera and three better ones (camera_study.csv, camera_study.svg); faster cameras
    /// film the same time window, in proportionally more frames
    #[arg(long = "camera-study")]
    camera_study: bool,
    /// Collisions per camera and speed in the camera study (at most 500)
    #[arg(long = "study-n", default_value_t = 200, requires = "camera_study")]
    study_n: usize,
    #[command(flatten)]
    render: Box<super::frames_out::FramesArgs>,
}

/// Most collisions one run simulates.
const MAX_COLLISIONS: usize = 2000;
/// Most collisions per camera and speed in the camera study (28 points: 1000 took about 1 s).
const MAX_STUDY_N: usize = 500;
/// Most frames per phase, and most frames per phase times collisions (the defaults, 12 and 60,
/// make 720; 5000 collisions of 12 frames took about 1 s).
const MAX_FRAMES: usize = 1000;
const MAX_FRAME_WORK: usize = 24_000;
/// The same for the camera study, which films each collision with four cameras, up to five
/// times the frames (1000 collisions of 12 frames per camera and speed took about 1 s).
const MAX_FRAME_WORK_STUDY: usize = 6_000;

fn parse_model(s: &str) -> Result<ModelKind, String> {
    match s.parse::<ModelKind>()? {
        ModelKind::PowerLaw => {
            Err("powerlaw is a fit, not a physical model: use vm, pm, min or product".into())
        }
        m => Ok(m),
    }
}

fn parse_rule(s: &str) -> Result<ContactEnd, String> {
    s.parse()
}

fn check(flag: &str, v: f64, ok: bool, expected: &str) -> CliResult {
    if v.is_finite() && ok {
        Ok(())
    } else {
        Err(format!("{flag} {}: expected {expected}", fmt_num(v)))
    }
}

/// [`check`] for a flag of two values MIN,MAX.
fn check_range(flag: &str, r: &[f64], ok: bool, expected: &str) -> CliResult {
    if r.iter().all(|v| v.is_finite()) && ok {
        Ok(())
    } else {
        let values: Vec<String> = r.iter().map(|&v| fmt_num(v)).collect();
        Err(format!("{flag} {}: expected {expected}", values.join(",")))
    }
}

pub fn run(args: Args) -> CliResult {
    for (flag, n) in [
        ("--v-n-m-s", args.v_n_m_s.len()),
        ("--incidence-deg", args.incidence_deg.len()),
        ("--frames", args.frames.len()),
    ] {
        if n != 2 {
            return Err(format!("{flag}: expected two values MIN,MAX, got {n}"));
        }
    }
    let material = args.material.resolve()?;
    check("--d-mm", args.d_mm, args.d_mm > 0.0, "a diameter > 0 (mm)")?;
    let d2_mm = args.d2_mm.unwrap_or(args.d_mm);
    check("--d2-mm", d2_mm, d2_mm > 0.0, "a diameter > 0 (mm)")?;
    check("--eta", args.eta, args.eta >= 0.0, "a damping >= 0")?;
    check(
        "--sigma-y-pa",
        args.sigma_y_pa,
        args.sigma_y_pa > 0.0,
        "a stress > 0",
    )?;
    let (v, g) = (&args.v_n_m_s, &args.incidence_deg);
    check_range(
        "--v-n-m-s",
        v,
        v[0] > 0.0 && v[1] >= v[0],
        "speeds 0 < MIN <= MAX (m/s)",
    )?;
    check_range(
        "--incidence-deg",
        g,
        (0.0..90.0).contains(&g[0]) && (g[0]..90.0).contains(&g[1]),
        "angles 0 <= MIN <= MAX < 90 (degrees)",
    )?;
    check(
        "--mu0",
        args.mu0,
        args.mu0 >= 0.0,
        "a friction coefficient >= 0",
    )?;
    check(
        "--beta0",
        args.beta0,
        (-1.0..=1.0).contains(&args.beta0),
        "a number in [-1, 1]",
    )?;
    let (lo, hi) = FPS_RANGE;
    check(
        "--fps",
        args.fps,
        (lo..=hi).contains(&args.fps),
        &format!("a frame rate in [{}, {}] per s", fmt_num(lo), fmt_num(hi)),
    )?;
    check("--fov-m", args.fov_m, args.fov_m > 0.0, "a width > 0 (m)")?;
    check(
        "--subpixel-expansion",
        args.subpixel_expansion,
        args.subpixel_expansion >= 1.0,
        "a factor >= 1",
    )?;
    // The subpixel `kinematics` will read these tracks with: the same range it accepts.
    let (lo, hi) = PIXEL_M_RANGE;
    let subpixel_m = args.fov_m / f64::from(args.pixels_x) / args.subpixel_expansion;
    if args.pixels_x > 0 && !(lo..=hi).contains(&subpixel_m) {
        return Err(format!(
            "--fov-m {} / --pixels-x {} / --subpixel-expansion {} = {} m: expected a subpixel size in [{}, {}] m",
            fmt_num(args.fov_m),
            args.pixels_x,
            fmt_num(args.subpixel_expansion),
            fmt_num(subpixel_m),
            fmt_num(lo),
            fmt_num(hi)
        ));
    }
    check(
        "--s-subpixels",
        args.s_subpixels,
        args.s_subpixels >= 0.0,
        "an accuracy >= 0",
    )?;
    check(
        "--spin-noise-rad-s",
        args.spin_noise_rad_s,
        args.spin_noise_rad_s >= 0.0,
        "a spread >= 0",
    )?;
    if args.n == 0 || args.pixels_x == 0 || args.pixels_y == 0 {
        return Err("--n, --pixels-x and --pixels-y must be > 0".into());
    }
    // Caps that keep a run well under a second (10 000 collisions took 1.4 s and wrote 37 MB;
    // a campaign like the paper's has 60-200): more collisions come from further seeds.
    if args.n > MAX_COLLISIONS {
        return Err(format!(
            "--n {}: expected at most {MAX_COLLISIONS} collisions per run (run again with another --seed for more)",
            args.n
        ));
    }
    if args.camera_study && !(1..=MAX_STUDY_N).contains(&args.study_n) {
        return Err(format!(
            "--study-n {}: expected 1 to {MAX_STUDY_N} collisions per camera and speed",
            args.study_n
        ));
    }
    let frames_max = args.frames.get(1).copied().unwrap_or(0);
    let (work, budget) = if args.camera_study {
        (args.study_n, MAX_FRAME_WORK_STUDY)
    } else {
        (args.n, MAX_FRAME_WORK)
    };
    if frames_max > MAX_FRAMES || work.saturating_mul(frames_max) > budget {
        return Err(format!(
            "--frames {},{frames_max} with {work} collisions: expected at most {MAX_FRAMES} frames per phase and {budget} frames per phase times collisions (--{})",
            args.frames.first().copied().unwrap_or(0),
            if args.camera_study { "study-n" } else { "n" }
        ));
    }
    if args.frames[0] < 2 || args.frames[1] < args.frames[0] {
        return Err(format!(
            "--frames {},{}: expected 2 <= MIN <= MAX",
            args.frames[0], args.frames[1]
        ));
    }
    let camera = Camera {
        frames_per_s: args.fps,
        pixels_x: args.pixels_x,
        pixels_y: args.pixels_y,
        fov_x_m: args.fov_m,
        subpixel_expansion: args.subpixel_expansion,
        s_subpixels: args.s_subpixels,
        frames_min: args.frames[0],
        frames_max: args.frames[1],
    };
    let spec = ExperimentSpec {
        n: args.n,
        d1_m: args.d_mm * 1e-3,
        d2_m: d2_mm * 1e-3,
        material,
        v_n_range_m_s: (args.v_n_m_s[0], args.v_n_m_s[1]),
        incidence_deg: (args.incidence_deg[0], args.incidence_deg[1]),
        mu0: args.mu0,
        beta0: args.beta0,
        spin_noise_rad_s: args.spin_noise_rad_s,
        camera,
        ..ExperimentSpec::paper()
    };
    let s1 = restitution::contact::Sphere::new(spec.d1_m, material)
        .map_err(|e| format!("--d-mm {}: {e}", fmt_num(args.d_mm)))?;
    let s2 = restitution::contact::Sphere::new(spec.d2_m, material)
        .map_err(|e| format!("--d2-mm {}: {e}", fmt_num(d2_mm)))?;
    // What a failure of the simulation is due to: the flags that set the physics.
    let context = format!(
        "the virtual experiment failed with --d-mm {} --d2-mm {} --model {} --eta {} --sigma-y-pa {} --v-n-m-s {},{}",
        fmt_num(args.d_mm),
        fmt_num(d2_mm),
        args.model.name(),
        fmt_num(args.eta),
        fmt_num(args.sigma_y_pa),
        fmt_num(args.v_n_m_s[0]),
        fmt_num(args.v_n_m_s[1])
    );
    let contact = Pair::unequal(s1, s2).contact();
    let params: Vec<f64> = match args.model {
        ModelKind::Vm => vec![args.eta],
        ModelKind::Pm => vec![args.sigma_y_pa],
        _ => vec![args.eta, args.sigma_y_pa],
    };
    let e_of = |v: f64| {
        predict_e(
            args.model,
            &contact,
            v,
            &params,
            args.contact_end,
            &VmMethod::Master,
        )
    };
    // The model at both ends of the speed range first: what can fail (V_Y under- or
    // overflowing with sigma_y, kappa overflowing with eta at the fastest speed) fails at an end
    // if anywhere, and is named by the model's parameters rather than by every physics flag.
    for v in &args.v_n_m_s {
        e_of(*v).map_err(|e| {
            let flags = match args.model {
                ModelKind::Vm => format!("--eta {}", fmt_num(args.eta)),
                ModelKind::Pm => format!("--sigma-y-pa {}", fmt_num(args.sigma_y_pa)),
                _ => format!(
                    "--eta {} --sigma-y-pa {}",
                    fmt_num(args.eta),
                    fmt_num(args.sigma_y_pa)
                ),
            };
            format!(
                "{flags} (--model {}, v_n = {} m/s): {e}",
                args.model.name(),
                fmt_num(*v)
            )
        })?;
    }
    let mut rng = StdRng::seed_from_u64(args.seed);
    if args.camera_study && args.render.wanted() {
        return Err("--frames-out renders a simulation, not the camera study".into());
    }
    if args.camera_study {
        return study(&args, &spec, &e_of, &mut rng).map_err(|e| format!("{context}: {e}"));
    }
    let sims = simulate(&spec, &e_of, &mut rng).map_err(|e| format!("{context}: {e}"))?;
    let frame_files = args.render.render(&sims, &spec, args.seed)?;

    let tracks: Vec<CollisionTrack> = sims
        .iter()
        .map(|s| CollisionTrack {
            id: s.id.clone(),
            first_line: 0,
            d1_m: spec.d1_m,
            d2_m: spec.d2_m,
            frames: s.frames.clone(),
            split: Some(s.split),
            spins_rad_s: Some(s.spins_measured_rad_s),
        })
        .collect();
    let mut truth = CsvOut::new();
    truth.record([
        "collision",
        "v_n_m_s",
        "e",
        "beta",
        "psi",
        "contact",
        "v1x_m_s",
        "v1y_m_s",
        "v2x_m_s",
        "v2y_m_s",
        "v1x_post_m_s",
        "v1y_post_m_s",
        "v2x_post_m_s",
        "v2y_post_m_s",
        "w1z_rad_s",
        "w2z_rad_s",
        "w1z_post_rad_s",
        "w2z_post_rad_s",
    ]);
    for s in &sims {
        let (Target::Sphere(a), Target::Sphere(b)) = (&s.pre.target, &s.post.target) else {
            unreachable!("simulated pairs");
        };
        let (p1, q1) = (&s.pre.sphere, &s.post.sphere);
        let cells: Vec<String> = std::iter::once(s.id.clone())
            .chain([s.v_n_m_s, s.e, s.beta, s.psi].iter().map(|&x| fmt_num(x)))
            .chain(std::iter::once(s.kind.as_str().to_string()))
            .chain(
                [
                    p1.velocity_m_s.x,
                    p1.velocity_m_s.y,
                    a.velocity_m_s.x,
                    a.velocity_m_s.y,
                    q1.velocity_m_s.x,
                    q1.velocity_m_s.y,
                    b.velocity_m_s.x,
                    b.velocity_m_s.y,
                    p1.spin_rad_s.z,
                    a.spin_rad_s.z,
                    q1.spin_rad_s.z,
                    b.spin_rad_s.z,
                ]
                .iter()
                .map(|&x| fmt_num(x)),
            )
            .collect();
        truth.record(cells);
    }
    let meta = json!({
        "seed": args.seed,
        "n": args.n,
        "material": {"youngs_pa": material.youngs_pa, "poisson": material.poisson, "density_kg_m3": material.density_kg_m3},
        "d1_mm": args.d_mm, "d2_mm": d2_mm,
        "model": args.model.name(),
        "eta": if matches!(args.model, ModelKind::Pm) { None } else { Some(args.eta) },
        "sigma_y_pa": if matches!(args.model, ModelKind::Vm) { None } else { Some(args.sigma_y_pa) },
        "v_yield_m_s": contact.yield_velocity_m_s(args.sigma_y_pa),
        "contact_end": args.contact_end.name(),
        "mu0": args.mu0, "beta0": args.beta0,
        "v_n_range_m_s": args.v_n_m_s, "incidence_deg": args.incidence_deg,
        "camera": {"frames_per_s": args.fps, "pixels_x": args.pixels_x, "pixels_y": args.pixels_y, "fov_x_m": args.fov_m,
                   "subpixel_expansion": args.subpixel_expansion, "s_subpixels": args.s_subpixels,
                   "sigma_position_m": camera.sigma_m(), "frames_per_phase": args.frames},
        "g_m_s2": spec.g_m_s2,
        "spin_noise_rad_s": args.spin_noise_rad_s,
    });
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("{}: cannot create: {e}", args.out.display()))?;
    let mut files = vec![
        (
            args.out.join("tracks.csv"),
            write_tracks(&tracks).into_bytes(),
        ),
        (args.out.join("truth.csv"), truth.into_string().into_bytes()),
        (
            args.out.join("truth.json"),
            (serde_json::to_string_pretty(&meta).expect("serialisable") + "\n").into_bytes(),
        ),
    ];
    let n_frame_files = frame_files.len();
    files.extend(frame_files);
    write_all_atomic(&files).map_err(|e| format!("{}: cannot write: {e}", args.out.display()))?;
    let frames: usize = sims.iter().map(|s| s.frames.len()).sum();
    super::emit(&format!(
        "simulated {} collisions ({} frames, position noise {} m) -> {}/tracks.csv, truth.csv, truth.json\n",
        sims.len(),
        frames,
        fmt_num(camera.sigma_m()),
        args.out.display()
    ))?;
    if let Some(line) = args.render.summary(n_frame_files) {
        super::emit(&format!("{line}\n"))?;
    }
    Ok(())
}

/// The camera study: this camera, twice the frame rate, four times the pixels, and both better.
fn study(
    args: &Args,
    spec: &ExperimentSpec,
    e_of: &dyn Fn(f64) -> restitution::Result<f64>,
    rng: &mut StdRng,
) -> CliResult {
    let c = spec.camera;
    let cameras = study_cameras(c);
    let points = camera_study(spec, &cameras, &STUDY_SPEEDS_M_S, args.study_n, e_of, rng)
        .map_err(|e| e.to_string())?;
    let csv = camera_study_csv(&points);
    let title = format!(
        "Measured e against true e: {} mm {}, s = {} subpixels, {}-{} frames per phase at the base rate",
        fmt_num(args.d_mm),
        args.material.material.as_deref().unwrap_or("spheres"),
        fmt_num(c.s_subpixels),
        c.frames_min,
        c.frames_max
    );
    let svg = restitution::plot::kinematics::camera_study_svg(&points, &title)?;
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("{}: cannot create: {e}", args.out.display()))?;
    write_all_atomic(&[
        (args.out.join("camera_study.csv"), csv.into_bytes()),
        (args.out.join("camera_study.svg"), svg.into_bytes()),
    ])
    .map_err(|e| format!("{}: cannot write: {e}", args.out.display()))?;
    super::emit(&format!(
        "camera study: {} points -> {}/camera_study.csv, camera_study.svg\n",
        points.len(),
        args.out.display()
    ))
}
