//! LAMMPS files of `restitution export`: in.restitution (the contact law for `pair_style
//! granular`), collide.in (head-on collisions that print e), and the round trip that runs `lmp`
//! on them (docs/physics.md §9).

use super::FilesFailure;
use crate::data::fmt_num;
use crate::dem::engines::lammps_tsuji_alpha;
use crate::dem::translate::{Collision, EngineLaw, LammpsViscoelastic, Translation};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The law written into in.restitution.
#[derive(Debug, Clone, PartialEq)]
pub enum LammpsLaw {
    /// `damping viscoelastic` with this eta; `note` says where eta comes from.
    Viscoelastic { eta: f64, note: String },
    /// `damping tsuji` with one `cor` per pair (already corrected for LAMMPS's polynomial);
    /// `note` says what e each is meant to give.
    Tsuji { cor: Vec<f64>, note: String },
}

impl LammpsLaw {
    /// The law as the engine will apply it (for the expected e of each collision).
    pub fn engine_law(&self) -> EngineLaw {
        match self {
            LammpsLaw::Viscoelastic { eta, .. } => EngineLaw::Viscoelastic { eta: *eta },
            LammpsLaw::Tsuji { cor, .. } => EngineLaw::Tsuji {
                alpha: cor.iter().map(|&c| lammps_tsuji_alpha(c)).collect(),
            },
        }
    }
}

/// Tangential friction for the pair_coeff lines.
#[derive(Debug, Clone, PartialEq)]
pub struct Friction {
    pub mu0: f64,
    /// Walton's tangential restitution, when known (not a LAMMPS parameter: see the file's note).
    pub beta0: Option<f64>,
    /// Where mu_0 came from, for the comment.
    pub source: String,
}

/// Collisions per pair and speed, with contact starts staggered over one time step: LAMMPS's e
/// depends on where in a step the contact begins (an error of first order in the step that
/// changes with this phase, measured up to 2e-7 at 8000 steps per contact, 6.35 mm nylon), and
/// the mean over 8 evenly spread phases removes it to about 1e-8.
pub const PHASES: usize = 8;

/// Steps per shortest contact in collide.in unless `-var steps N` says otherwise.
pub const DEFAULT_STEPS: u32 = 8000;

/// in.restitution and collide.in, and the collisions collide.in runs.
#[derive(Debug, Clone, PartialEq)]
pub struct LammpsFiles {
    pub in_restitution: String,
    pub collide_in: String,
    pub collisions: Vec<Collision>,
}

/// One `hertz/material` coefficient set: the numbers of a pair_coeff line (or wall fix).
struct Coeff<'a> {
    youngs: f64,
    damp: f64,
    nu: f64,
    damping: &'a str,
    kt: f64,
    friction: Option<&'a Friction>,
    force_rule: bool,
}

impl Coeff<'_> {
    fn write(&self, out: &mut String, head: &str, tail: &str) {
        let tangential = match self.friction {
            Some(f) => format!(
                "tangential mindlin {} 0 {}",
                fmt_num(self.kt),
                fmt_num(f.mu0)
            ),
            None => "tangential linear_nohistory 0 0".to_string(),
        };
        let _ = writeln!(
            out,
            "{head} hertz/material {} {} {} damping {} {tangential}{}{tail}",
            fmt_num(self.youngs),
            fmt_num(self.damp),
            fmt_num(self.nu),
            self.damping,
            if self.force_rule {
                " limit_damping"
            } else {
                ""
            },
        );
    }
}

/// Writes in.restitution and collide.in for the translation `tr` and the law `law`, with
/// collisions at `speeds` (m/s). `source` names the input (for the header comments).
pub fn lammps_files(
    tr: &Translation,
    law: &LammpsLaw,
    friction: Option<&Friction>,
    speeds: &[f64],
    source: &str,
) -> Result<LammpsFiles, FilesFailure> {
    let scene = &tr.request.scene;
    let m = scene.material;
    let rule = tr.request.curve.rule;
    let force_rule = rule == crate::models::viscoelastic::ContactEnd::Force;
    let n_types = scene.diameters_m.len();
    // Elastic constants and the Mindlin stiffness are the same for every damping law.
    let base = tr.lammps_viscoelastic(match law {
        LammpsLaw::Viscoelastic { eta, .. } => *eta,
        LammpsLaw::Tsuji { .. } => 0.0,
    });
    let (damping, damps): (&str, Vec<f64>) = match law {
        LammpsLaw::Viscoelastic { .. } => ("viscoelastic", base.iter().map(|b| b.damp).collect()),
        LammpsLaw::Tsuji { cor, .. } => ("tsuji", cor.clone()),
    };
    let note = match law {
        LammpsLaw::Viscoelastic { note, .. } | LammpsLaw::Tsuji { note, .. } => note,
    };

    let mut f = String::new();
    let _ = writeln!(
        f,
        "# in.restitution: contact law for LAMMPS pair_style granular, written by\n\
         # `restitution export` from {source}.\n# Law: {note}\n\
         # Contact end: {} ({}).",
        rule.name(),
        if force_rule {
            "limit_damping: no attractive normal force, the contact ends when the force is zero"
        } else {
            "no limit_damping: the contact ends when the overlap is zero (the paper's rule)"
        }
    );
    let _ = writeln!(
        f,
        "# Units: si. Needs atom_style sphere, comm_modify vel yes, and atoms of these types\n\
         # (set diameter before density: `set type T diameter D` then `set type T density RHO`):"
    );
    for (t, &d) in scene.diameters_m.iter().enumerate() {
        let mass = std::f64::consts::PI / 6.0 * d.powi(3) * m.density_kg_m3;
        let _ = writeln!(
            f,
            "#   type {}: diameter {} m, density {} kg/m^3 (mass {} kg)",
            t + 1,
            fmt_num(d),
            fmt_num(m.density_kg_m3),
            fmt_num(mass)
        );
    }
    match law {
        LammpsLaw::Viscoelastic { .. } => {
            let _ = writeln!(
                f,
                "# damp = 4 eta/m_red (m_red = reduced mass) differs for every pair of sizes: keep one\n\
                 # type per size and every pair_coeff line below. Never rely on LAMMPS's mixing: the\n\
                 # 29 Sep 2021 release gives an unset cross pair of hertz/material a linear force."
            );
        }
        LammpsLaw::Tsuji { .. } => {
            let _ = writeln!(
                f,
                "# damping tsuji turns its coefficient into alpha with a polynomial whose alpha is about\n\
                 # 0.7 of the one that gives e (docs/physics.md §9): the coefficients below are not the\n\
                 # e you want but the inputs that make LAMMPS produce it (see constant_e.csv)."
            );
        }
    }
    match friction {
        Some(fr) => {
            let _ = writeln!(
                f,
                "# Tangential: Mindlin, k_t = 8 G* a, no tangential damping (x_t = 0), friction mu_0 = {}\n\
                 # ({}). Walton's beta_0{} is not a LAMMPS parameter: the tangential\n\
                 # restitution of sticking collisions follows from k_t and x_t; if it matters, tune x_t\n\
                 # (the 0 after k_t) with oblique collisions (rolling friction is a different effect).",
                fmt_num(fr.mu0),
                fr.source,
                fr.beta0
                    .map(|b| format!(" = {}", fmt_num(b)))
                    .unwrap_or_default()
            );
        }
        None => {
            let _ = writeln!(
                f,
                "# Tangential: none (frictionless; give --walton walton.json or --mu0 for friction)."
            );
        }
    }
    let _ = writeln!(f, "pair_style granular");
    let mut wall_lines = String::new();
    for (p, pair) in tr.pairs.iter().enumerate() {
        let b: &LammpsViscoelastic = &base[p];
        let coeff = Coeff {
            youngs: b.youngs_pa,
            damp: damps[p],
            nu: b.poisson,
            damping,
            kt: b.kt_pa,
            friction,
            force_rule,
        };
        match pair.j {
            Some(j) => coeff.write(&mut f, &format!("pair_coeff {} {}", pair.i + 1, j + 1), ""),
            None => {
                let t = pair.i + 1;
                let _ = writeln!(wall_lines, "group restitution_t{t} type {t}");
                coeff.write(
                    &mut wall_lines,
                    &format!("fix restitution_wall_t{t} restitution_t{t} wall/gran granular"),
                    " ${restitution_wall}",
                );
            }
        }
    }
    if !wall_lines.is_empty() {
        let _ = writeln!(
            f,
            "# Sphere-wall contacts: one fix per sphere type (damp = 4 eta/m differs per size). Define\n\
             # the wall first, e.g. variable restitution_wall string \"zplane 0.0 NULL\", and include this\n\
             # file after the atoms exist (the groups take the atoms present). The modulus here is\n\
             # 2 (1 - nu) E*, because LAMMPS 29 Sep 2021's wall/gran forms E*= E/(2 (1 - nu)) from it."
        );
        f.push_str(&wall_lines);
    }

    // The viscoelastic ODE gives up beyond kappa ~ 3000 (e < 1e-17 there); say so in the
    // user's terms before it does.
    if let LammpsLaw::Viscoelastic { eta, .. } = law {
        for pair in &tr.pairs {
            for &v in speeds {
                let kappa = pair.contact.kappa(*eta, v);
                if kappa.is_nan() || kappa > 1000.0 {
                    return Err(FilesFailure::Overdamped {
                        pair: pair.label(),
                        v_m_s: v,
                        kappa,
                        eta: *eta,
                    });
                }
            }
        }
    }
    let collisions = tr
        .collisions(&law.engine_law(), speeds)
        .map_err(FilesFailure::Collisions)?;
    let collide_in = collide_input(tr, &collisions, n_types)?;
    Ok(LammpsFiles {
        in_restitution: f,
        collide_in,
        collisions,
    })
}

/// collide.in: every collision of `collisions`, [`PHASES`] times each, in one run.
fn collide_input(
    tr: &Translation,
    collisions: &[Collision],
    n_types: usize,
) -> Result<String, FilesFailure> {
    let scene = &tr.request.scene;
    let d_max = scene.diameters_m.iter().cloned().fold(0.0, f64::max);
    let tc_min = collisions
        .iter()
        .map(|c| c.contact_time_s)
        .fold(f64::INFINITY, f64::min);
    let t_sep_max = collisions
        .iter()
        .map(|c| c.separation_time_s)
        .fold(0.0, f64::max);
    if !(tc_min.is_finite() && tc_min > 0.0) {
        return Err(FilesFailure::NoCollision);
    }
    // One run steps through the longest collision at the shortest one's step: beyond a ratio of
    // 1000 that is over 1e7 steps at the default N (hours), so the speeds (or sizes) must be
    // split over several exports.
    if t_sep_max / tc_min > 1000.0 {
        return Err(FilesFailure::ContactsTooWide {
            shortest_s: tc_min,
            longest_s: t_sep_max,
        });
    }
    // The contact starts 10 to 11 steps after the run starts (see the gaps below); 20% beyond the
    // latest separation leaves every pair apart at the end, which collide.in prints as a gap.
    let t_run = 1.2 * t_sep_max;
    let spacing = 4.0 * d_max + 0.01;
    let n_coll = collisions.len() * PHASES;
    let per_row = (n_coll as f64).sqrt().ceil() as usize;
    let extent = spacing * (per_row as f64 + 1.0);
    let z_pairs = 0.5 * extent + 2.0 * d_max;

    let mut s = String::new();
    let _ = writeln!(
        s,
        "# collide.in: head-on collisions for every contact of in.restitution, {PHASES} per pair and speed\n\
         # with contact starts spread over one time step; prints e for each and their mean.\n\
         # Run here: lmp -in collide.in [-var steps N]   (N time steps per shortest contact, {:.3e} s)\n\
         # LAMMPS's error in e is first order in the step: run N and 2N and take 2 e(2N) - e(N),\n\
         # as `restitution export --verify` does. Expected e (the toolkit's) are in the comments.",
        tc_min
    );
    let _ = writeln!(
        s,
        "variable steps index {DEFAULT_STEPS}\nunits si\natom_style sphere\natom_modify map array\n\
         boundary f f f\nnewton off\ncomm_modify vel yes\n\
         region box block {} {} {} {} {} {} units box\ncreate_box {n_types} box\n\
         variable dt equal {}/${{steps}}\ntimestep ${{dt}}",
        fmt_num(-spacing),
        fmt_num(extent),
        fmt_num(-spacing),
        fmt_num(extent),
        fmt_num(-0.01),
        fmt_num(extent + 4.0 * d_max),
        fmt_num(tc_min)
    );
    // (atom id of the first sphere, collision, phase) for the print lines.
    let mut made = Vec::new();
    let mut id = 0usize;
    let mut slot = 0usize;
    for (c, col) in collisions.iter().enumerate() {
        let pair = &tr.pairs[col.pair];
        let v = col.v_m_s;
        let _ = writeln!(
            s,
            "# pair {} at {} m/s: toolkit e = {}",
            pair.label(),
            fmt_num(v),
            fmt_num(col.e)
        );
        for k in 0..PHASES {
            let (gx, gy) = (slot % per_row, slot / per_row);
            slot += 1;
            let (x0, y0) = (gx as f64 * spacing, gy as f64 * spacing);
            let ri = 0.5 * pair.d_i_m;
            // Gap closed in 10 + k/PHASES steps at the relative speed v.
            let gap = format!("{}*v_dt*(10+{k}/{PHASES})", fmt_num(v));
            match pair.d_j_m {
                Some(dj) => {
                    let rj = 0.5 * dj;
                    let _ = writeln!(
                        s,
                        "create_atoms {} single $({}-{}-0.5*{gap}) {} {} units box\n\
                         create_atoms {} single $({}+{}+0.5*{gap}) {} {} units box",
                        pair.i + 1,
                        fmt_num(x0),
                        fmt_num(ri),
                        fmt_num(y0),
                        fmt_num(z_pairs),
                        pair.j.map_or(0, |j| j + 1),
                        fmt_num(x0),
                        fmt_num(rj),
                        fmt_num(y0),
                        fmt_num(z_pairs)
                    );
                    made.push((id + 1, c, k, true));
                    id += 2;
                }
                None => {
                    let _ = writeln!(
                        s,
                        "create_atoms {} single {} {} $({}+{gap}) units box",
                        pair.i + 1,
                        fmt_num(x0),
                        fmt_num(y0),
                        fmt_num(ri)
                    );
                    made.push((id + 1, c, k, false));
                    id += 1;
                }
            }
        }
    }
    for (t, &d) in scene.diameters_m.iter().enumerate() {
        let _ = writeln!(
            s,
            "set type {} diameter {}\nset type {} density {}",
            t + 1,
            fmt_num(d),
            t + 1,
            fmt_num(scene.material.density_kg_m3)
        );
    }
    let _ = writeln!(s, "velocity all set 0 0 0");
    for &(a, c, _, sphere_pair) in &made {
        let v = collisions[c].v_m_s;
        if sphere_pair {
            let _ = writeln!(
                s,
                "set atom {a} vx {}\nset atom {} vx {}",
                fmt_num(0.5 * v),
                a + 1,
                fmt_num(-0.5 * v)
            );
        } else {
            let _ = writeln!(s, "set atom {a} vz {}", fmt_num(-v));
        }
    }
    let _ = writeln!(
        s,
        "variable restitution_wall string \"zplane 0.0 NULL\"\ninclude in.restitution\n\
         fix restitution_nve all nve/sphere\nthermo_style custom step\nthermo 100000000\n\
         run $(ceil({}/v_dt))",
        fmt_num(t_run)
    );
    let mut by_case: BTreeMap<usize, Vec<String>> = BTreeMap::new();
    for &(a, c, k, sphere_pair) in &made {
        let col = &collisions[c];
        let pair = &tr.pairs[col.pair];
        let v = fmt_num(col.v_m_s);
        let ri = 0.5 * pair.d_i_m;
        let (e_expr, gap_expr) = if sphere_pair {
            let rj = 0.5 * pair.d_j_m.unwrap_or(0.0);
            (
                format!("(vx[{}]-vx[{a}])/{v}", a + 1),
                format!("x[{}]-x[{a}]-{}", a + 1, fmt_num(ri + rj)),
            )
        } else {
            (format!("vz[{a}]/{v}"), format!("z[{a}]-{}", fmt_num(ri)))
        };
        let _ = writeln!(
            s,
            "print \"restitution-e pair={} v_m_s={v} phase={k} e=$({e_expr}:%.17g) gap_m=$({gap_expr}:%.6g)\"",
            pair.label()
        );
        by_case.entry(c).or_default().push(e_expr);
    }
    for (c, exprs) in &by_case {
        let col = &collisions[*c];
        let _ = writeln!(
            s,
            "print \"restitution-e-mean pair={} v_m_s={} e=$(({})/{}:%.17g) toolkit_e={}\"",
            tr.pairs[col.pair].label(),
            fmt_num(col.v_m_s),
            exprs.join("+"),
            exprs.len(),
            fmt_num(col.e)
        );
    }
    Ok(s)
}
