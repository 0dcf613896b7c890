//! Generates the example data sets `data/fig7_nylon.csv` and `data/wall_example.csv`.
//!
//! ```text
//! cargo run --release --example gen_fig7_data
//! ```
//!
//! **fig7_nylon.csv** is modelled on the experiment of the paper's Fig. 7 (Labous, Rosato & Dave,
//! PRE 56, 5717, 1997): pairs of identical nylon spheres (Y = 3.5e8 Pa, nu = 0.3,
//! rho = 1140 kg/m^3) of 25.4, 12.7 and 6.35 mm, normal impact speeds of about 0.5 to 40 m/s.
//! True model: `min` (e = min(e_vm, e_pm), overlap rule), with the paper's parameters
//! eta = 190 kg/(s m) and sigma_y = 4.0e7 Pa (V_Y = 6.32 m/s). This reproduces what the paper
//! describes: viscoelastic at low speed with the larger spheres rebounding better, and the
//! plastic universal curve taking over for the small spheres at high speed (for the large ones
//! too above ~10 m/s, where the paper had few data; the speed ranges below follow that).
//!
//! Error model (docs/physics.md §5, the paper's camera): 1000 frames/s, 239 pixels across a 60 mm field
//! of view with a 4x subpixel expansion (0.0628 mm per subpixel) and a centre accuracy of
//! s = 2 subpixels, so s d / n_s = 0.1255 mm for every size. N frames per fit are those the
//! sphere needs to cross half the field (30 mm) at its speed, between 2 and 12 (the paper:
//! "8 to 12 images, but maybe as low as 2 for high velocities"). Then Eq. (8):
//! Delta v = s d / (n_s dt sqrt(N)), written as `v_err_m_s` (0.036 m/s at N = 12, the paper's
//! "about 4% at 1 m/s"), and the fit uses sigma_e = 2 e Delta v / v_n. The measured e is the
//! true e plus Gaussian noise of exactly that sigma (computed from the true e), and the measured
//! v_n the true speed plus Gaussian noise Delta v. The column `frames` is N (extra columns are
//! ignored by `restitution fit`).
//!
//! Speeds are log-uniform per size: 25.4 mm 0.5-12 m/s (30 points), 12.7 mm 0.6-25 m/s (40),
//! 6.35 mm 1-40 m/s (50). Values are rounded as a lab would write them (v to 1 mm/s, e to 1e-4;
//! both far below the errors).
//!
//! **wall_example.csv**: a 12.7 mm nylon sphere dropped on a thick nylon plate (`d2_mm = inf`),
//! 15 drops at 0.3-4 m/s, e measured with a one-sigma error of 0.01 given directly (`e_err`).
//! True model `vm` with eta = 190 kg/(s m): every speed is below this pair's V_Y (12.6 m/s for
//! sigma_y = 4e7 Pa), so the data cannot determine sigma_y and a `min` fit reports a bound.
//!
//! Seeds 1997 and 5717 with rand's `StdRng` (ChaCha12 in rand 0.9; rand does not promise the
//! same stream across major versions, which is why the CSV files are committed).

use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, Normal};
use restitution::contact::Material;
use restitution::data::write_atomic;
use restitution::fit::dataset::pair_contact;
use restitution::fit::models::{ModelKind, predict_e};
use restitution::models::viscoelastic::{ContactEnd, VmMethod};
use std::path::Path;

const ETA: f64 = 190.0;
const SIGMA_Y_PA: f64 = 4.0e7;
/// Position accuracy s d / n_s of the paper's camera (see the module doc), m.
const POSITION_ACCURACY_M: f64 = 2.0 * 0.060 / (239.0 * 4.0);
const FRAME_S: f64 = 1e-3;

fn frames(v_m_s: f64) -> u32 {
    ((0.030 / (v_m_s * FRAME_S)).floor() as u32).clamp(2, 12)
}

/// Eq. (8): Delta v = s d / (n_s dt sqrt(N)).
fn delta_v(n: u32) -> f64 {
    POSITION_ACCURACY_M / (FRAME_S * (n as f64).sqrt())
}

fn log_uniform(rng: &mut StdRng, lo: f64, hi: f64) -> f64 {
    let u: f64 = rand::Rng::random(rng);
    (lo.ln() + u * (hi.ln() - lo.ln())).exp()
}

fn main() {
    let nylon = Material::preset("nylon").expect("nylon preset");
    let method = VmMethod::Master;
    let std_normal = Normal::new(0.0, 1.0).expect("unit normal");

    let mut rng = StdRng::seed_from_u64(1997);
    let mut out = String::new();
    out += "# Synthetic data modelled on Fig. 7 of Labous, Rosato & Dave, PRE 56, 5717 (1997).\n";
    out += "# Made by: cargo run --release --example gen_fig7_data (seed 1997).\n";
    out +=
        "# Nylon (Y = 3.5e8 Pa, nu = 0.3, rho = 1140 kg/m^3), identical spheres, overlap rule.\n";
    out += "# TRUE MODEL: min (e = min(e_vm, e_pm)), eta = 190 kg/(s m), sigma_y = 4.0e7 Pa.\n";
    out += "# Errors: v_err_m_s = Delta v of Eq. (8) for the paper's camera with N = frames;\n";
    out += "# sigma_e = 2 e v_err / v_n. See examples/gen_fig7_data.rs.\n";
    out += "d_mm,v_n_m_s,e,v_err_m_s,frames\n";
    let sets = [
        (25.4, 0.5, 12.0, 30),
        (12.7, 0.6, 25.0, 40),
        (6.35, 1.0, 40.0, 50),
    ];
    for (d_mm, v_lo, v_hi, count) in sets {
        let contact = pair_contact(nylon, d_mm, None).expect("valid pair");
        let mut speeds: Vec<f64> = (0..count)
            .map(|_| log_uniform(&mut rng, v_lo, v_hi))
            .collect();
        speeds.sort_by(f64::total_cmp);
        for v in speeds {
            let e_true = predict_e(
                ModelKind::Min,
                &contact,
                v,
                &[ETA, SIGMA_Y_PA],
                ContactEnd::Overlap,
                &method,
            )
            .expect("model evaluates");
            let n = frames(v);
            let dv = delta_v(n);
            let sigma_e = 2.0 * e_true * dv / v;
            let e = e_true + sigma_e * std_normal.sample(&mut rng);
            let v_meas = v + dv * std_normal.sample(&mut rng);
            out += &format!("{d_mm},{v_meas:.3},{e:.4},{dv:.4},{n}\n");
        }
    }
    write_atomic(Path::new("data/fig7_nylon.csv"), out.as_bytes()).expect("write fig7");

    let mut rng = StdRng::seed_from_u64(5717);
    let mut out = String::new();
    out +=
        "# Synthetic sphere-on-wall data: a 12.7 mm nylon sphere dropped on a thick nylon plate.\n";
    out += "# Made by: cargo run --release --example gen_fig7_data (seed 5717).\n";
    out += "# TRUE MODEL: vm, eta = 190 kg/(s m), overlap rule; e_err = 0.01 (one sigma).\n";
    out += "d_mm,d2_mm,v_n_m_s,e,e_err\n";
    let contact = pair_contact(nylon, 12.7, Some(f64::INFINITY)).expect("valid pair");
    let mut speeds: Vec<f64> = (0..15).map(|_| log_uniform(&mut rng, 0.3, 4.0)).collect();
    speeds.sort_by(f64::total_cmp);
    for v in speeds {
        let e_true = predict_e(
            ModelKind::Vm,
            &contact,
            v,
            &[ETA],
            ContactEnd::Overlap,
            &method,
        )
        .expect("model evaluates");
        let e = e_true + 0.01 * std_normal.sample(&mut rng);
        out += &format!("12.7,inf,{v:.3},{e:.4},0.01\n");
    }
    write_atomic(Path::new("data/wall_example.csv"), out.as_bytes()).expect("write wall");
    eprintln!(
        "wrote data/fig7_nylon.csv and data/wall_example.csv (V_Y wall pair = {:.3} m/s)",
        contact.yield_velocity_m_s(SIGMA_Y_PA)
    );
}
