//! A fitted law translated for a scene: every exportable law with its distance from the fitted
//! curve, and the engine parameters of each (docs/physics.md §9).

use super::damped::{self, Dashpot};
use super::engines::{
    self, lammps_pair_material, lammps_tsuji_alpha, lammps_tsuji_cor_for_alpha,
    lammps_viscoelastic_damp, lammps_wall_youngs, liggghts_alpha, liggghts_e_for_alpha, mindlin_kt,
};
use super::law::{self, ConstantE, FittedCurve, LawKind, Recommendation, Table, ViscoelasticFit};
use super::range::{SpeedRange, Weight};
use super::scene::{Scene, ScenePair};
use crate::error::{Error, Result};
use crate::fit::models::e_vm;
use crate::models::viscoelastic::{ContactEnd, OdeSettings, Viscoelastic, VmMethod};

/// What a scene asks of the translation.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    pub curve: FittedCurve,
    pub scene: Scene,
    /// Needed for every law but the exact viscoelastic one (a `vm` fit).
    pub range: Option<SpeedRange>,
    pub weight: Weight,
    /// Speeds in the e(v) table (>= 2).
    pub table_points: usize,
    /// Largest deviation from the fitted curve the scene accepts, for the recommendation.
    pub tolerance: Option<f64>,
}

/// The parameters of one pair for LAMMPS's `hertz/material` with `damping viscoelastic` and a
/// Mindlin tangential spring (see [`super::engines`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LammpsViscoelastic {
    pub youngs_pa: f64,
    pub poisson: f64,
    /// 4 eta/m_red, 1/(m s).
    pub damp: f64,
    /// Mindlin k_t = 8 G*, Pa.
    pub kt_pa: f64,
}

/// What the constant-e engines need to produce a given e for one pair, and what they produce
/// when given e itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantEInputs {
    /// The e to reproduce.
    pub e: f64,
    /// Tsuji's alpha that gives it under the contact-end rule ([`damped::alpha_for_e`]).
    pub alpha: f64,
    /// `cor` for LAMMPS `damping tsuji` so that its polynomial gives alpha; `None` when alpha is
    /// below the polynomial's floor 3e-4 (e within about 4e-4 of 1).
    pub lammps_cor: Option<f64>,
    /// The e LAMMPS gives when asked for e itself.
    pub lammps_e_if_given_e: f64,
    /// `coefficientRestitution` for LIGGGHTS's Hertz model so that it gives e (equal to e for the
    /// overlap rule, where its formula is exact); `None` when alpha >= sqrt 5.
    pub liggghts_e: Option<f64>,
    /// The e LIGGGHTS gives when asked for e itself.
    pub liggghts_e_if_given_e: f64,
}

/// The inputs of [`ConstantEInputs`] for restitution e under `rule`.
pub fn constant_e_inputs(e: f64, rule: ContactEnd) -> Result<ConstantEInputs> {
    engines::check_e(e)?;
    let alpha = damped::alpha_for_e(e, Dashpot::Tsuji, rule)?;
    let lammps_e_if_given_e = damped::restitution(lammps_tsuji_alpha(e), Dashpot::Tsuji, rule)?;
    let liggghts_e_if_given_e = if e == 1.0 {
        1.0
    } else {
        damped::restitution(liggghts_alpha(e), Dashpot::Tsuji, rule)?
    };
    Ok(ConstantEInputs {
        e,
        alpha,
        lammps_cor: lammps_tsuji_cor_for_alpha(alpha),
        lammps_e_if_given_e,
        // Overlap rule: LIGGGHTS's formula is the exact e of Tsuji's dashpot (module note of
        // [`damped`]), so e itself is the input; the force rule needs the alpha that gives e.
        liggghts_e: match rule {
            ContactEnd::Overlap => Some(e),
            ContactEnd::Force => liggghts_e_for_alpha(alpha),
        },
        liggghts_e_if_given_e,
    })
}

/// The translation of one fitted curve for one scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Translation {
    pub request: Request,
    pub pairs: Vec<ScenePair>,
    /// Best constant e per pair (needs a range).
    pub constant: Option<Vec<ConstantE>>,
    /// The closest viscoelastic law (exact for `vm`).
    pub viscoelastic: ViscoelasticFit,
    /// The fitted curve tabulated (needs a range).
    pub table: Option<Table>,
    /// The simplest law within the tolerance (needs a range and a tolerance).
    pub recommendation: Option<Recommendation>,
}

impl Translation {
    /// Computes every law the request allows. Without a range only an exact viscoelastic law
    /// (a `vm` curve) can be given; anything else is an error saying so.
    pub fn new(request: Request) -> Result<Self> {
        let pairs = request.scene.pairs();
        let contacts: Vec<_> = pairs.iter().map(|p| p.contact).collect();
        let Some(range) = request.range else {
            if request.curve.kind != crate::fit::models::ModelKind::Vm {
                return Err(Error::InvalidParameter {
                    name: "speed range (needed for every model but vm)",
                    value: f64::NAN,
                    expected: "a range LO,HI of impact speeds",
                });
            }
            let viscoelastic = law::viscoelastic_fit(
                &request.curve,
                &contacts,
                &SpeedRange::new(1.0, 2.0)?,
                request.weight,
            )?;
            return Ok(Translation {
                request,
                pairs,
                constant: None,
                viscoelastic,
                table: None,
                recommendation: None,
            });
        };
        let mut constant = Vec::new();
        for c in &contacts {
            constant.push(law::constant_e(&request.curve, c, &range, request.weight)?);
        }
        let viscoelastic =
            law::viscoelastic_fit(&request.curve, &contacts, &range, request.weight)?;
        let table = law::table(&request.curve, &contacts, &range, request.table_points)?;
        let recommendation = match request.tolerance {
            None => None,
            Some(t) => {
                let const_dev = constant.iter().map(|c| c.dev_minimax).fold(0.0, f64::max);
                Some(law::recommend(
                    t,
                    &[
                        (LawKind::ConstantE, const_dev),
                        (LawKind::Viscoelastic, viscoelastic.dev_minimax),
                        (LawKind::Table, table.interpolation_dev),
                    ],
                )?)
            }
        };
        Ok(Translation {
            request,
            pairs,
            constant: Some(constant),
            viscoelastic,
            table: Some(table),
            recommendation,
        })
    }

    /// LAMMPS parameters of every pair for the viscoelastic law with damping `eta`.
    pub fn lammps_viscoelastic(&self, eta: f64) -> Vec<LammpsViscoelastic> {
        let m = self.request.scene.material;
        self.pairs
            .iter()
            .map(|p| {
                let c = &p.contact;
                let (youngs_pa, poisson) = match p.j {
                    Some(_) => lammps_pair_material(&m, &m, c.e_star_pa),
                    None => (lammps_wall_youngs(c.e_star_pa, m.poisson), m.poisson),
                };
                LammpsViscoelastic {
                    youngs_pa,
                    poisson,
                    damp: lammps_viscoelastic_damp(c, eta),
                    kt_pa: mindlin_kt(&m, &m),
                }
            })
            .collect()
    }

    /// e of the viscoelastic law with damping `eta` for pair `p` at speed v.
    pub fn e_viscoelastic(&self, p: usize, v_m_s: f64, eta: f64) -> Result<f64> {
        e_vm(
            &self.pairs[p].contact,
            v_m_s,
            eta,
            self.request.curve.rule,
            &VmMethod::Master,
        )
    }

    /// e of the fitted curve for pair `p` at speed v.
    pub fn e_fitted(&self, p: usize, v_m_s: f64) -> Result<f64> {
        self.request.curve.e(&self.pairs[p].contact, v_m_s)
    }
}

/// The law an engine file carries, with what it needs to predict the engine's e.
#[derive(Debug, Clone, PartialEq)]
pub enum EngineLaw {
    /// Hertz with viscoelastic damping eta (LAMMPS `damping viscoelastic`).
    Viscoelastic { eta: f64 },
    /// Hertz with Tsuji's dashpot, one alpha per pair (LAMMPS `damping tsuji`).
    Tsuji { alpha: Vec<f64> },
}

/// One head-on collision of a verification run: what the law predicts for it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    pub pair: usize,
    pub v_m_s: f64,
    /// e of the law (what the engine must reproduce).
    pub e: f64,
    /// How long the contact force acts, s.
    pub contact_time_s: f64,
    /// When the surfaces separate, s: later than the contact's end under the force rule, where
    /// the spheres still overlap (x_end) when the force vanishes and part at speed e v.
    pub separation_time_s: f64,
}

impl Translation {
    /// e, contact duration and separation time of the exported law for every pair at every speed (ODE for the
    /// viscoelastic law, [`damped::rebound`] for Tsuji's).
    pub fn collisions(&self, law: &EngineLaw, speeds: &[f64]) -> Result<Vec<Collision>> {
        let rule = self.request.curve.rule;
        let mut out = Vec::new();
        for (p, pair) in self.pairs.iter().enumerate() {
            for &v in speeds {
                crate::error::positive("collision speed (m/s)", v)?;
                // e, the contact duration (units of T) and the overlap left when it ends (V T).
                let (e, tau, x_end) = match law {
                    EngineLaw::Viscoelastic { eta } => {
                        let im = Viscoelastic::new(pair.contact, *eta)?.impact(
                            v,
                            rule,
                            &OdeSettings::DEFAULT,
                        )?;
                        (im.e, im.dimensionless.tau_contact, im.dimensionless.x_end)
                    }
                    EngineLaw::Tsuji { alpha } => {
                        let r =
                            damped::rebound(alpha[p], Dashpot::Tsuji, rule, damped::DEFAULT_STEPS)?;
                        (r.e, r.tau_contact, r.x_end)
                    }
                };
                let t = pair.contact.time_scale_s(v);
                out.push(Collision {
                    pair: p,
                    v_m_s: v,
                    e,
                    contact_time_s: tau * t,
                    separation_time_s: (tau + x_end / e) * t,
                });
            }
        }
        Ok(out)
    }
}
