//! `restitution kinematics`: from tracked sphere centres to velocities, e, beta and psi.
//!
//! ```text
//! restitution kinematics TRACKS.csv
//!     (--material NAME | --youngs-pa Y --poisson NU --density-kg-m3 RHO)
//!     [--fixed-gravity [--g-m-s2 G]] [--inertia-k K]
//!     [--s-subpixels S] [--subpixel-m P | --fov-m W --pixels-x N --subpixel-expansion X]
//!     [--format table|csv|json] [--out DIR]
//! ```
//! TRACKS.csv: `collision,t_s,x1_m,y1_m,x2_m,y2_m,d1_mm,d2_mm`, optional `phase` (pre/post) and
//! `w1z_rad_s,w2z_rad_s,w1z_post_rad_s,w2z_post_rad_s` (spins from markers). y is up.
//!
//! Per collision: quadratic fits per coordinate and phase (or straight lines plus gravity with
//! `--fixed-gravity`), the collision time (centre distance reaching (d1 + d2)/2 on the
//! pre-collision fits; fallback, flagged `fits_meet`: where pre and post fits come closest), the
//! velocities there, v_n, e, beta, psi, the momentum check, and e's error both from the fits'
//! covariance (`e_err`) and from Eq. (8) (`e_err_eq8`). `--out DIR` writes `kinematics.csv`,
//! `fit_input.csv` (the `restitution fit` schema) and `walton_input.csv` (the `walton fit`
//! schema), all or none, so that the three commands chain.

use super::{CliResult, Format, MaterialArgs};
use restitution::data::report::kinematics::{
    Measured, fit_input_csv, kinematics_csv, kinematics_json, measure_tracks,
};
use restitution::data::tracks::read_tracks;
use restitution::data::walton::write_collisions;
use restitution::data::{CsvOut, fixed, fmt_num, write_all_atomic};
use restitution::experiment::Camera;
use restitution::kinematics::batch::BatchOptions;
use restitution::kinematics::{Eq8Inputs, FitKind, G_EXPECTED, G_STANDARD_M_S2, g_ok};
use restitution::models::walton::K_HOMOGENEOUS;
use std::path::PathBuf;

/// Velocities, e, beta and psi from tracked sphere centres (Sec. III)
#[derive(clap::Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct Args {
    /// Tracks CSV (collision, t_s, x1_m, y1_m, x2_m, y2_m, d1_mm, d2_mm [, phase, spins])
    #[arg(value_name = "TRACKS.csv")]
    path: PathBuf,
    #[command(flatten)]
    material: MaterialArgs,
    /// Fit straight lines plus the known gravity (y up) instead of free quadratics
    #[arg(long = "fixed-gravity")]
    fixed_gravity: bool,
    /// Gravitational acceleration for --fixed-gravity, m/s^2 (at most 1e6)
    #[arg(long = "g-m-s2", value_name = "G", default_value_t = G_STANDARD_M_S2)]
    g_m_s2: f64,
    /// Inertia factor K = 4I/(m d^2) (2/5 for homogeneous spheres)
    #[arg(long = "inertia-k", value_name = "K", default_value_t = K_HOMOGENEOUS)]
    inertia_k: f64,
    /// Eq. (8): accuracy of a centre in subpixels
    #[arg(long = "s-subpixels", value_name = "S", default_value_t = Camera::PAPER.s_subpixels)]
    s_subpixels: f64,
    /// Eq. (8): subpixel size in the object plane, 1e-12 to 1 m (default: from the field of view)
    #[arg(long = "subpixel-m", value_name = "P")]
    subpixel_m: Option<f64>,
    /// Field of view width, m
    #[arg(long = "fov-m", value_name = "W", default_value_t = Camera::PAPER.fov_x_m)]
    fov_m: f64,
    /// Camera pixels across the field of view
    #[arg(long = "pixels-x", value_name = "N", default_value_t = Camera::PAPER.pixels_x)]
    pixels_x: u32,
    /// Subpixel expansion factor
    #[arg(long = "subpixel-expansion", value_name = "X", default_value_t = Camera::PAPER.subpixel_expansion)]
    subpixel_expansion: f64,
    #[arg(long, value_enum, default_value = "table")]
    format: Format,
    /// Stop at the first collision that cannot be measured instead of skipping it
    #[arg(long)]
    strict: bool,
    /// Write kinematics.csv, fit_input.csv and walton_input.csv here
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Most skipped collisions named one by one.
const MAX_WARNINGS: usize = 20;

/// The subpixel sizes Eq. (8) accepts, m: the pixel range of `track` (a subpixel is a pixel over
/// the expansion factor). Outside it a subnormal or absurd size gave 0 m subpixels and an
/// infinite noise in subpixels on stdout (the fuzzer's `--fov-m 5e-324`).
const SUBPIXEL_M_RANGE: (f64, f64) = restitution::data::frames::job::PIXEL_M_RANGE;

pub fn run(args: Args) -> CliResult {
    let material = args.material.resolve()?;
    for (flag, v) in [
        ("--s-subpixels", args.s_subpixels),
        ("--fov-m", args.fov_m),
        ("--subpixel-expansion", args.subpixel_expansion),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("{flag} {}: expected a number > 0", fmt_num(v)));
        }
    }
    super::check_inertia_k(args.inertia_k)?;
    if !g_ok(args.g_m_s2) {
        return Err(format!(
            "--g-m-s2 {}: expected {G_EXPECTED}",
            fmt_num(args.g_m_s2)
        ));
    }
    if args.pixels_x == 0 {
        return Err("--pixels-x 0: expected a pixel count > 0".into());
    }
    let (lo, hi) = SUBPIXEL_M_RANGE;
    let subpixel_m = match args.subpixel_m {
        Some(p) if (lo..=hi).contains(&p) => p,
        Some(p) => {
            return Err(format!(
                "--subpixel-m {}: expected a size in [{}, {}] m",
                fmt_num(p),
                fmt_num(lo),
                fmt_num(hi)
            ));
        }
        None => {
            let p = args.fov_m / args.pixels_x as f64 / args.subpixel_expansion;
            if !(lo..=hi).contains(&p) {
                return Err(format!(
                    "--fov-m {} / --pixels-x {} / --subpixel-expansion {} = {} m: expected a subpixel size in [{}, {}] m",
                    fmt_num(args.fov_m),
                    args.pixels_x,
                    fmt_num(args.subpixel_expansion),
                    fmt_num(p),
                    fmt_num(lo),
                    fmt_num(hi)
                ));
            }
            p
        }
    };
    let eq8 = Eq8Inputs {
        s_subpixels: args.s_subpixels,
        subpixel_m,
    };
    let kind = if args.fixed_gravity {
        FitKind::FixedGravity {
            g_m_s2: args.g_m_s2,
        }
    } else {
        FitKind::Free
    };
    let tracks = read_tracks(&args.path).map_err(|e| e.to_string())?;
    let shown = args.path.display().to_string();
    let options = BatchOptions {
        material,
        inertia_k: args.inertia_k,
        kind,
        eq8,
    };
    // The noise pooled over every collision; a collision that cannot be measured (too few
    // frames, receding spheres) is skipped with a warning naming it, so one bad track does not
    // lose a campaign; --strict makes it an error.
    let measured = measure_tracks(&shown, &tracks, &options);
    for line in &measured.unmeasured_spins {
        super::warn(line);
    }
    if let Some(why) = measured.refusal(&shown, args.strict) {
        return Err(why);
    }
    // Built before `measured` is taken apart, and only when printed (100 000 collisions' records).
    let json = matches!(args.format, Format::Json).then(|| kinematics_json(&measured));
    let Measured {
        rows,
        records,
        skipped,
        fits_meet,
        sigma_pos_m: sigma,
        ..
    } = measured;
    if !skipped.is_empty() {
        // One line each, up to a screenful; a file of 100 000 bad tracks gets a count.
        for s in skipped.iter().take(MAX_WARNINGS) {
            super::warn(format_args!("skipped {s}"));
        }
        if skipped.len() > MAX_WARNINGS {
            super::warn(format_args!(
                "skipped {} more collisions that cannot be measured",
                skipped.len() - MAX_WARNINGS
            ));
        }
    }
    let fallbacks: Vec<String> = fits_meet
        .iter()
        .map(|id| restitution::data::shown(id))
        .collect();
    if !fallbacks.is_empty() {
        super::warn(format_args!(
            "{} collision(s) never reach contact distance on the pre-collision fits (noise); their time is where pre and post fits meet: {}",
            fallbacks.len(),
            fallbacks[..fallbacks.len().min(MAX_WARNINGS)].join(", ")
                + if fallbacks.len() > MAX_WARNINGS {
                    ", ..."
                } else {
                    ""
                }
        ));
    }
    // The files say what they leave out: skipped collisions are often the fast ones (too few
    // frames), so a fit of what is left sees a narrower range of speeds than was filmed.
    let comment = format!(
        "made by restitution kinematics from {shown} ({}){}",
        if args.fixed_gravity {
            "fixed-gravity fits"
        } else {
            "free quadratic fits"
        },
        if skipped.is_empty() {
            String::new()
        } else {
            format!(
                "; {} of {} collisions skipped: they cannot be measured (the command's warnings say why)",
                skipped.len(),
                rows.len() + skipped.len()
            )
        }
    );
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
        let mut walton_csv = CsvOut::new();
        walton_csv.comment(&comment);
        write_all_atomic(&[
            (
                dir.join("kinematics.csv"),
                kinematics_csv(&rows, Some(&comment)).into_bytes(),
            ),
            (
                dir.join("fit_input.csv"),
                fit_input_csv(&rows, &comment).into_bytes(),
            ),
            (
                dir.join("walton_input.csv"),
                (walton_csv.into_string() + &write_collisions(&records)).into_bytes(),
            ),
        ])
        .map_err(|e| format!("{}: cannot write: {e}", dir.display()))?;
    }
    let text = match args.format {
        // The same document as the --out directory's kinematics.csv, its comment included
        // (what made it, and how many collisions were skipped).
        Format::Csv => kinematics_csv(&rows, Some(&comment)),
        Format::Json => json.expect("built for --format json"),
        Format::Table => {
            let mut s = format!(
                "{:>10} {:>7} {:>9} {:>8} {:>8} {:>8} {:>8} {:>7} {:>7} {:>5}/{:<5} time\n",
                "collision",
                "v_n",
                "e",
                "e_err",
                "e_eq8",
                "beta",
                "psi",
                "dv_x",
                "dv_y",
                "n_pre",
                "post"
            );
            for r in &rows {
                let me = &r.m.measured;
                let dv = |k: usize| {
                    me.com_velocity_change_m_s
                        .map_or("-".into(), |v| fixed(v[k], 3))
                };
                s += &format!(
                    "{:>10} {:>7} {:>9} {:>8} {:>8} {:>8} {:>8} {:>7} {:>7} {:>5}/{:<5} {}\n",
                    r.id,
                    fixed(me.v_n_m_s, 3),
                    fixed(me.e, 4),
                    fixed(r.m.e_err, 4),
                    fixed(r.m.e_err_eq8, 4),
                    me.beta.map_or_else(|| "-".into(), |b| fixed(b, 3)),
                    if me.psi.is_finite() {
                        fixed(me.psi, 3)
                    } else {
                        "-".into()
                    },
                    dv(0),
                    dv(1),
                    r.m.kinematics.n_pre,
                    r.m.kinematics.n_post,
                    r.m.kinematics.time_rule.name()
                );
            }
            let sigma_subpixels = sigma / subpixel_m;
            if !sigma_subpixels.is_finite() {
                return Err(format!(
                    "{shown}: the position noise {} m is out of range in subpixels of {} m",
                    fmt_num(sigma),
                    fmt_num(subpixel_m)
                ));
            }
            s += &format!(
                "(speeds m/s; e_err from the fits' covariance with the position noise pooled over all collisions: {} m = {:.2} subpixels; e_eq8 from Eq. 8 with s = {} subpixels of {} m; dv: momentum check)\n",
                fmt_num(sigma),
                sigma_subpixels,
                fmt_num(args.s_subpixels),
                fmt_num(subpixel_m)
            );
            // A table kept in a file loses the warnings on stderr: it says what it leaves out.
            if !skipped.is_empty() {
                s += &format!(
                    "({} of {} collisions skipped: they cannot be measured; the warnings say why)\n",
                    skipped.len(),
                    rows.len() + skipped.len()
                );
            }
            s
        }
    };
    super::emit(&text)
}
