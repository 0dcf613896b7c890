//! What LAMMPS's `damping tsuji` and LIGGGHTS's Hertz model give when asked for a restitution e
//! directly, against the e asked for (the Tsuji dashpot solved by `dem::damped`, both contact
//! rules). Output: reports/export/tsuji_accuracy.txt (scripts/make_reports.sh).
//!
//! cargo run --release --example tsuji_accuracy

use restitution::dem::damped::{Dashpot, alpha_for_e, restitution};
use restitution::dem::engines::{lammps_tsuji_alpha, liggghts_alpha};
use restitution::models::viscoelastic::ContactEnd;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!(
        "# e that LAMMPS damping tsuji / LIGGGHTS hertz give when asked for e (Tsuji dashpot ODE)"
    );
    for rule in ContactEnd::ALL {
        println!(
            "\ncontact end {} ({})",
            rule.name(),
            match rule {
                ContactEnd::Overlap => "LAMMPS without limit_damping, LIGGGHTS limitForce off",
                ContactEnd::Force => "LAMMPS limit_damping, LIGGGHTS limitForce on",
            }
        );
        println!("e asked   LAMMPS gives   LIGGGHTS gives   poly alpha / exact alpha");
        for e in [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99] {
            let exact = alpha_for_e(e, Dashpot::Tsuji, rule)?;
            let lammps = restitution(lammps_tsuji_alpha(e), Dashpot::Tsuji, rule)?;
            let liggghts = restitution(liggghts_alpha(e), Dashpot::Tsuji, rule)?;
            println!(
                "{e:<8}  {lammps:<13.6} {liggghts:<16.6} {:.4}",
                lammps_tsuji_alpha(e) / exact
            );
        }
        // Largest error over e = 0.05 .. 1 in steps of 0.01.
        let (mut worst_l, mut at_l, mut worst_g, mut at_g) = (0.0f64, 0.0, 0.0f64, 0.0);
        for i in 5..=100 {
            let e = i as f64 / 100.0;
            let l = restitution(lammps_tsuji_alpha(e), Dashpot::Tsuji, rule)? - e;
            let g = if e < 1.0 {
                restitution(liggghts_alpha(e), Dashpot::Tsuji, rule)? - e
            } else {
                0.0
            };
            if l.abs() > worst_l {
                (worst_l, at_l) = (l.abs(), e);
            }
            if g.abs() > worst_g {
                (worst_g, at_g) = (g.abs(), e);
            }
        }
        println!(
            "largest |error| for e in [0.05, 1]: LAMMPS {worst_l:.3e} (at e = {at_l}), LIGGGHTS {worst_g:.3e} (at e = {at_g})"
        );
    }
    Ok(())
}
