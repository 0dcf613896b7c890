//! Which files an export writes and what they carry: the engine's law (exact, closest
//! viscoelastic or constant e), the LAMMPS inputs, the constant-e and table files.

use super::FilesFailure;
use super::files::{self, Summary};
use super::lammps::{self, Friction, LammpsFiles, LammpsLaw};
use crate::data::fmt_num;
use crate::dem::damped::{self, Dashpot};
use crate::dem::engines::lammps_tsuji_alpha;
use crate::dem::range::SpeedRange;
use crate::dem::translate::{ConstantEInputs, Translation, constant_e_inputs};

/// The engine family the user exports for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "kebab-case")]
pub enum EngineKind {
    Lammps,
    ConstantE,
    Table,
}

impl EngineKind {
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Which law the LAMMPS files carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawChoice {
    /// The exact law for `vm`; otherwise the closer of the other two (largest deviation of the
    /// exported values: least-squares eta, weighted-mean constant e).
    Auto,
    Viscoelastic,
    ConstantE,
}

/// Collision speeds of collide.in when the user gives none: the range's ends and geometric
/// middle, or 0.5, 2 and 10 m/s without a range (named in collide.in's comments).
pub fn default_speeds(range: Option<SpeedRange>) -> Vec<f64> {
    match range {
        Some(r) => vec![r.lo_m_s, (r.lo_m_s * r.hi_m_s).sqrt(), r.hi_m_s],
        None => vec![0.5, 2.0, 10.0],
    }
}

/// An export ready to write: the files (name, bytes) and what the report needs.
#[derive(Debug, Clone)]
pub struct Plan {
    pub engine: EngineKind,
    pub lammps_law: Option<LammpsLaw>,
    pub lammps_files: Option<LammpsFiles>,
    /// Engine inputs for each pair's constant e (shown for the constant-e engine).
    pub constant_inputs: Option<Vec<ConstantEInputs>>,
    pub outputs: Vec<(String, Vec<u8>)>,
}

/// Builds the files of an export (everything but the figure and export.json, which
/// [`Plan::summary`] and the plot module give).
pub fn plan(
    tr: &Translation,
    engine: EngineKind,
    law: LawChoice,
    friction: Option<&Friction>,
    speeds: &[f64],
    source: &str,
) -> Result<Plan, FilesFailure> {
    let rule = tr.request.curve.rule;
    let needs_constant = engine == EngineKind::ConstantE
        || (engine == EngineKind::Lammps && law != LawChoice::Viscoelastic);
    let const_inputs = match (&tr.constant, needs_constant) {
        (Some(c), true) => Some(
            c.iter()
                .map(|x| constant_e_inputs(x.e_mean, rule))
                .collect::<Result<Vec<_>, _>>()
                .map_err(FilesFailure::ConstantE)?,
        ),
        _ => None,
    };
    // LAMMPS's `damping tsuji` coefficient per pair, or why a pair's e is out of its reach.
    // The polynomial cannot ask for less damping than at cor = 1 (e above 0.99958): then cor = 1,
    // and collide.in's expected e says what LAMMPS gives instead. Nor for more than at cor = 0
    // (alpha = 1.2728; e = 0.114 under the overlap rule): writing cor = 1 there, as before, made
    // a lossy pair all but elastic without a word, so it is an error.
    // Computed once: both the law's choice and the file need it.
    let lammps_cor: Option<Result<Vec<f64>, FilesFailure>> =
        const_inputs.as_deref().map(|inputs| {
            inputs
                .iter()
                .zip(&tr.pairs)
                .map(|(i, pair)| match i.lammps_cor {
                    Some(c) => Ok(c),
                    None if i.alpha < lammps_tsuji_alpha(0.0) => Ok(1.0),
                    None => Err(FilesFailure::OutOfReach {
                        pair: pair.label(),
                        engine: "LAMMPS's damping tsuji",
                        e: i.e,
                        e_floor: damped::restitution(lammps_tsuji_alpha(0.0), Dashpot::Tsuji, rule)
                            .map_err(FilesFailure::ConstantE)?,
                    }),
                })
                .collect()
        });
    let tsuji_law = |note: String| -> Result<LammpsLaw, FilesFailure> {
        let cor = lammps_cor.clone().ok_or(FilesFailure::NeedsSpeedRange(
            "a constant e needs the scene's speeds (--v-range)",
        ))??;
        Ok(LammpsLaw::Tsuji { cor, note })
    };
    let vm = &tr.viscoelastic;
    let kind = tr.request.curve.kind;
    let lammps_law = match engine {
        EngineKind::Table => None,
        EngineKind::ConstantE => Some(tsuji_law(
            "Hertz with Tsuji's damping, a constant e per pair (the weighted mean of the fitted \
             e(v) over the speed range; constant_e.csv)"
                .into(),
        )?),
        EngineKind::Lammps => {
            let const_dev = tr
                .constant
                .as_ref()
                .map(|c| c.iter().map(|x| x.dev_mean).fold(0.0, f64::max));
            let const_reachable = lammps_cor.as_ref().is_some_and(|c| c.is_ok());
            let use_const = match law {
                LawChoice::Viscoelastic => false,
                LawChoice::ConstantE => true,
                // A constant e LAMMPS cannot give is no candidate.
                LawChoice::Auto => {
                    !vm.exact && const_dev.is_some_and(|d| d < vm.dev_mean) && const_reachable
                }
            };
            Some(if use_const {
                tsuji_law(format!(
                    "a constant e per pair (largest deviation from the fitted {kind} curve {:.3e}; \
                     the closest viscoelastic law would deviate by {:.3e})",
                    const_dev.unwrap_or(f64::NAN),
                    vm.dev_mean
                ))?
            } else if vm.exact {
                LammpsLaw::Viscoelastic {
                    eta: vm.eta_mean,
                    note: format!(
                        "Hertz + viscoelastic damping (Eqs. 9-10) with the fitted eta = {} kg/(s m): exact",
                        fmt_num(vm.eta_mean)
                    ),
                }
            } else {
                LammpsLaw::Viscoelastic {
                    eta: vm.eta_mean,
                    note: format!(
                        "the viscoelastic law closest to the fitted {kind} curve (eta = {} kg/(s m), \
                         least squares over the speed range): largest deviation {:.3e}{}",
                        fmt_num(vm.eta_mean),
                        vm.dev_mean,
                        const_dev
                            .map(|d| format!(
                                "; a constant e would deviate by {d:.3e}{}",
                                if const_reachable {
                                    ""
                                } else {
                                    " but is out of reach of LAMMPS's damping tsuji"
                                }
                            ))
                            .unwrap_or_default()
                    ),
                }
            })
        }
    };

    let mut outputs: Vec<(String, Vec<u8>)> = Vec::new();
    let mut lammps_files = None;
    if let Some(l) = &lammps_law {
        let lf = lammps::lammps_files(tr, l, friction, speeds, source)?;
        outputs.push((
            "in.restitution".into(),
            lf.in_restitution.clone().into_bytes(),
        ));
        outputs.push(("collide.in".into(), lf.collide_in.clone().into_bytes()));
        lammps_files = Some(lf);
    }
    let constant_inputs = if engine == EngineKind::ConstantE {
        const_inputs
    } else {
        None
    };
    if let Some(inputs) = &constant_inputs {
        // LIGGGHTS's formula cannot ask for more than critical damping (alpha = sqrt 5): with
        // limitForce on, e below its value there is out of reach (the file had written 1 for
        // such a pair, an elastic contact, saying such entries take no part in the scene).
        for (i, pair) in inputs.iter().zip(&tr.pairs) {
            if i.liggghts_e.is_none() {
                return Err(FilesFailure::OutOfReach {
                    pair: pair.label(),
                    engine: "LIGGGHTS's Hertz model with limitForce on",
                    e: i.e,
                    e_floor: damped::restitution(
                        damped::TSUJI_OVERLAP_CRITICAL,
                        Dashpot::Tsuji,
                        rule,
                    )
                    .map_err(FilesFailure::ConstantE)?,
                });
            }
        }
        outputs.push((
            "constant_e.csv".into(),
            files::constant_e_csv(tr, inputs)?.into_bytes(),
        ));
        outputs.push((
            "liggghts.in".into(),
            files::liggghts_input(tr, inputs, friction).into_bytes(),
        ));
    }
    if engine == EngineKind::Table {
        outputs.push(("table.csv".into(), files::table_csv(tr)?.into_bytes()));
    }
    Ok(Plan {
        engine,
        lammps_law,
        lammps_files,
        constant_inputs,
        outputs,
    })
}

impl Plan {
    /// What the report and export.json say about this plan.
    pub fn summary<'a>(
        &'a self,
        tr: &'a Translation,
        source: &'a str,
        friction: Option<&'a Friction>,
        files: Vec<String>,
        verify: Option<&'a [super::run::VerifyRow]>,
    ) -> Summary<'a> {
        Summary {
            source,
            engine: self.engine.name(),
            tr,
            lammps_law: self.lammps_law.as_ref(),
            constant_inputs: self.constant_inputs.as_deref(),
            friction,
            files,
            verify,
        }
    }
}
