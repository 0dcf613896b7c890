//! The five models `restitution fit` can fit, and their evaluation at each data point.
//!
//! - `vm`: viscoelastic (Eqs. 9-10, docs/physics.md §2), e = f(kappa), kappa = [`Contact::kappa`]`(eta, v)`;
//!   parameter eta.
//! - `pm`: plastic (Eqs. 12-18, docs/physics.md §3), e = [`plastic::rebound_u`]`(v / V_Y(sigma_y))`;
//!   parameter sigma_y.
//! - `min`: e = min(e_vm, e_pm), a regime switch (the paper's reading of its Fig. 7: viscoelastic
//!   at low speed, plastic once yield dissipates more); parameters eta, sigma_y.
//! - `product`: e = e_vm e_pm, both channels dissipating in series; parameters eta, sigma_y.
//! - `powerlaw`: the empirical 1 - e = A (d/d_ref)^(-a) (v/v_ref)^b with d_ref = 10 mm,
//!   v_ref = 1 m/s; parameters A, a, b. The VM predicts a = 1, b = 1/5 at small dissipation; the
//!   paper argues for a = 1/2. The size d is 4 R~ (docs/physics.md §1), which is the diameter for
//!   identical spheres and makes walls and unequal pairs comparable.
//!
//! Every positive physical parameter (eta, sigma_y, A) is fitted as its logarithm: the data
//! constrain it in relative terms (e depends on eta through kappa, on sigma_y through V_Y ~
//! sigma_y^(5/2)), the search ranges span decades, and positivity then needs no constraint.
//! The exponents a and b are fitted as they are.

use super::dataset::FitData;
use super::sums;
use super::vexp;
use crate::contact::Contact;
use crate::error::{Error, Num, Result};
use crate::models::plastic;
use crate::models::viscoelastic::{self, ContactEnd, VmMethod, master};
use std::collections::HashMap;
use std::fmt;
use std::str::FromStr;
use std::sync::{Arc, Mutex};

mod jacobian;

/// Reference diameter of the power law, mm.
pub const POWERLAW_D_REF_MM: f64 = 10.0;
/// Reference speed of the power law, m/s.
pub const POWERLAW_V_REF_M_S: f64 = 1.0;

/// A unit as it follows a number in prose: " kg/(s m)", and nothing for a pure number (unit
/// "1", which after a value read as a second number: "A = 0.039570 1").
pub fn unit_after(unit: &str) -> String {
    if unit == "1" {
        String::new()
    } else {
        format!(" {unit}")
    }
}

/// A fitted parameter: its key in tables and JSON, its unit, and whether it is fitted as a logarithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamSpec {
    pub key: &'static str,
    pub unit: &'static str,
    pub log: bool,
}

const ETA: ParamSpec = ParamSpec {
    key: "eta",
    unit: "kg/(s m)",
    log: true,
};
const SIGMA_Y: ParamSpec = ParamSpec {
    key: "sigma_y",
    unit: "Pa",
    log: true,
};
const POW_A: ParamSpec = ParamSpec {
    key: "A",
    unit: "1",
    log: true,
};
const POW_EXP_D: ParamSpec = ParamSpec {
    key: "a",
    unit: "1",
    log: false,
};
const POW_EXP_V: ParamSpec = ParamSpec {
    key: "b",
    unit: "1",
    log: false,
};

/// Which model to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr)]
#[strum(serialize_all = "lowercase")]
pub enum ModelKind {
    Vm,
    Pm,
    Min,
    Product,
    PowerLaw,
}

impl ModelKind {
    pub const ALL: [ModelKind; 5] = [
        ModelKind::Vm,
        ModelKind::Pm,
        ModelKind::Min,
        ModelKind::Product,
        ModelKind::PowerLaw,
    ];

    pub fn name(self) -> &'static str {
        self.into()
    }

    /// The model's formula in words, for tables.
    pub fn formula(self) -> &'static str {
        match self {
            ModelKind::Vm => "e = e_vm(kappa(eta, v))",
            ModelKind::Pm => "e = e_pm(v / V_Y(sigma_y))",
            ModelKind::Min => "e = min(e_vm, e_pm)",
            ModelKind::Product => "e = e_vm * e_pm",
            ModelKind::PowerLaw => "1 - e = A (d/10 mm)^(-a) (v/(1 m/s))^b",
        }
    }

    pub fn params(self) -> &'static [ParamSpec] {
        match self {
            ModelKind::Vm => &[ETA],
            ModelKind::Pm => &[SIGMA_Y],
            ModelKind::Min | ModelKind::Product => &[ETA, SIGMA_Y],
            ModelKind::PowerLaw => &[POW_A, POW_EXP_D, POW_EXP_V],
        }
    }

    pub fn n_params(self) -> usize {
        self.params().len()
    }

    /// Internal (fitted) coordinates from physical values: logarithms where [`ParamSpec::log`].
    pub fn to_internal(self, physical: &[f64]) -> Vec<f64> {
        self.params()
            .iter()
            .zip(physical)
            .map(|(p, &x)| if p.log { x.ln() } else { x })
            .collect()
    }

    /// Physical values from internal coordinates.
    pub fn to_physical(self, theta: &[f64]) -> Vec<f64> {
        self.params()
            .iter()
            .zip(theta)
            .map(|(p, &t)| if p.log { t.exp() } else { t })
            .collect()
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ModelKind {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        ModelKind::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                format!("unknown model '{s}': expected one of vm, pm, min, product, powerlaw")
            })
    }
}

/// e_vm of one contact at one speed for damping eta (Eqs. 9-10 through the master curve or ODE).
pub fn e_vm(
    contact: &Contact,
    v_m_s: f64,
    eta: f64,
    rule: ContactEnd,
    method: &VmMethod,
) -> Result<f64> {
    Ok(viscoelastic::restitution(contact.kappa(eta, v_m_s), rule, method)?.e)
}

/// e_pm of one contact at one speed for yield stress sigma_y (docs/physics.md §3 closed form).
/// V_Y is the checked one ([`Contact::try_yield_velocity_m_s`]): an error naming sigma_y and the
/// contact where it is not a normal f64, and one naming v and V_Y where u = v/V_Y overflows.
/// (The direct formula underflows in its intermediates first: V_Y = 0 from sigma_y = 1e-79 Pa
/// on a 0.2 mm sphere, where V_Y is 3.8e-206 m/s, made e = 0; and near that edge it was off in
/// the sixth digit.)
pub fn e_pm(contact: &Contact, v_m_s: f64, sigma_y_pa: f64) -> Result<f64> {
    let vy = contact.try_yield_velocity_m_s(sigma_y_pa)?;
    let u = v_m_s / vy;
    if !u.is_finite() {
        return Err(Error::OutOfRange {
            quantity: "u = V/V_Y",
            value: u,
            cause: format!("v = {} m/s, V_Y = {} m/s", Num(v_m_s), Num(vy)),
        });
    }
    Ok(plastic::e_of_u(u))
}

/// The size variable of the power law, 4 R~ in mm (the diameter for identical spheres).
pub fn powerlaw_d_mm(contact: &Contact) -> f64 {
    4.0 * contact.r_eff_m * 1e3
}

/// e of the power law 1 - e = A (d/d_ref)^(-a) (v/v_ref)^b.
pub fn e_powerlaw(d_mm: f64, v_m_s: f64, a_coef: f64, a: f64, b: f64) -> f64 {
    1.0 - a_coef * (d_mm / POWERLAW_D_REF_MM).powf(-a) * (v_m_s / POWERLAW_V_REF_M_S).powf(b)
}

/// e of any model for one contact at one speed; `physical` holds the model's parameters in
/// the order of [`ModelKind::params`], in SI units.
pub fn predict_e(
    kind: ModelKind,
    contact: &Contact,
    v_m_s: f64,
    physical: &[f64],
    rule: ContactEnd,
    method: &VmMethod,
) -> Result<f64> {
    if physical.len() != kind.n_params() {
        return Err(Error::InvalidParameter {
            name: "number of model parameters",
            value: physical.len() as f64,
            expected: "as many as the model has",
        });
    }
    Ok(match kind {
        ModelKind::Vm => e_vm(contact, v_m_s, physical[0], rule, method)?,
        ModelKind::Pm => e_pm(contact, v_m_s, physical[0])?,
        ModelKind::Min => {
            e_vm(contact, v_m_s, physical[0], rule, method)?.min(e_pm(contact, v_m_s, physical[1])?)
        }
        ModelKind::Product => {
            e_vm(contact, v_m_s, physical[0], rule, method)? * e_pm(contact, v_m_s, physical[1])?
        }
        ModelKind::PowerLaw => e_powerlaw(
            powerlaw_d_mm(contact),
            v_m_s,
            physical[0],
            physical[1],
            physical[2],
        ),
    })
}

/// Evaluates the models at every data point, with per-point constants computed once.
#[derive(Debug, Clone)]
pub struct Evaluator<'a> {
    pub data: &'a FitData,
    pub rule: ContactEnd,
    pub method: VmMethod,
    /// kappa at eta = 1: kappa is linear in eta (C ~ eta, [`Contact::kappa`]).
    kappa_per_eta: Vec<f64>,
    /// V_Y at sigma_y = 1 Pa: V_Y ~ sigma_y^(5/2) (Eq. 15, [`Contact::yield_velocity_m_s`]).
    v_yield_per_pa: Vec<f64>,
    /// The points' speeds, contiguous (read with `v_yield_per_pa` by every evaluation of e_pm;
    /// from the observations' records they were a cache line per point).
    v_n_m_s: Vec<f64>,
    /// ln(d/d_ref) and ln(v/v_ref) of the power law: 1 - e = exp(ln A - a x1 + b x2), one
    /// exp per point instead of two powf.
    powerlaw_ln_d: Vec<f64>,
    powerlaw_ln_v: Vec<f64>,
    /// Per block of [`sums::CHUNK`] points (block b holds points b CHUNK ..), the points'
    /// offsets in the block in increasing order of kappa per unit eta (empty unless the master
    /// curve evaluates e_vm): see [`Evaluator::with_kappas_in_order`].
    kappa_order: Vec<u32>,
    /// kappa per unit eta in that order (read in sequence, not gathered).
    kappa_per_eta_in_order: Vec<f64>,
    /// The rows of e_vm and e_pm the global searches asked for ([`Evaluator::row`]) and the
    /// last rows of a held factor ([`Evaluator::held_row`]).
    rows: RowMemo,
}

/// Rows kept by [`RowMemo`]'s `held`: the profile ends of `min` and `product` run side by side,
/// two with each parameter held, so eight rows serve both models' ends at once.
pub(super) const HELD_ROWS: usize = 8;

/// `kept`: rows of e_vm (axis 0) and e_pm (axis 1) over every point, by axis and the bits of
/// the log of the parameter, and the power law's rows of exp(-a x1) and exp(b x2) (axes 2 and 3,
/// by the bits of a and b; [`Evaluator::memo_row`]). Kept for the whole fit: on 100 000
/// distinct points `fit --model all` peaks at 303 MB against 276 MB when the power law's were
/// not kept. The searches of `vm`, `pm`, `min` and `product` share their grids (the same search
/// boxes cut at the same dyadic points), so on 100 000 distinct points 60 of 150 e_vm rows and
/// 40 of 120 e_pm rows were computed again by another model of `fit --model all`.
/// `held`: the last [`HELD_ROWS`] rows of e_vm (axis 0, by the bits of eta) and of e_pm (axis
/// 1, by the bits of sigma_y) held by a profile's inner fits, most recent last
/// ([`Evaluator::held_row`]). A clone starts empty.
#[derive(Default)]
struct RowMemo {
    kept: Mutex<HashMap<RowKey, Arc<Vec<f64>>>>,
    held: Mutex<Vec<(RowKey, Arc<Vec<f64>>)>>,
}

/// (axis, bits of t).
type RowKey = (usize, u64);

impl Clone for RowMemo {
    fn clone(&self) -> Self {
        RowMemo::default()
    }
}

impl fmt::Debug for RowMemo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("RowMemo")
    }
}

impl<'a> Evaluator<'a> {
    pub fn new(data: &'a FitData, rule: ContactEnd, method: VmMethod) -> Self {
        let (obs, contacts) = (&data.obs, &data.contacts);
        // Each a value per point (on all cores for large data: the fit's start is serial).
        let per_point = |f: &(dyn Fn(usize) -> f64 + Sync)| {
            let mut v = vec![0.0; obs.len()];
            sums::fill(&mut v, f);
            v
        };
        let mut ev = Evaluator {
            data,
            rule,
            method,
            kappa_per_eta: per_point(&|i| contacts[i].kappa(1.0, obs[i].v_n_m_s)),
            v_yield_per_pa: per_point(&|i| contacts[i].yield_velocity_m_s(1.0)),
            v_n_m_s: obs.iter().map(|o| o.v_n_m_s).collect(),
            powerlaw_ln_d: per_point(&|i| (powerlaw_d_mm(&contacts[i]) / POWERLAW_D_REF_MM).ln()),
            powerlaw_ln_v: per_point(&|i| (obs[i].v_n_m_s / POWERLAW_V_REF_M_S).ln()),
            kappa_order: Vec::new(),
            kappa_per_eta_in_order: Vec::new(),
            rows: RowMemo::default(),
        };
        if method == VmMethod::Master {
            let kpe = &ev.kappa_per_eta;
            ev.kappa_order = (0..kpe.len()).map(|i| (i % sums::CHUNK) as u32).collect();
            let sort = |(order, block): (&mut [u32], &[f64])| {
                order.sort_unstable_by(|&x, &y| {
                    block[x as usize]
                        .total_cmp(&block[y as usize])
                        .then(x.cmp(&y))
                })
            };
            // The chunks are independent: large data sort them side by side (a serial part of
            // the fit's start, before any model runs).
            if sums::is_large(kpe.len()) {
                use rayon::prelude::*;
                (ev.kappa_order.par_chunks_mut(sums::CHUNK))
                    .zip(kpe.par_chunks(sums::CHUNK))
                    .for_each(sort);
            } else {
                (ev.kappa_order.chunks_mut(sums::CHUNK))
                    .zip(kpe.chunks(sums::CHUNK))
                    .for_each(sort);
            }
            ev.kappa_per_eta_in_order = (ev.kappa_order.iter().enumerate())
                .map(|(i, &j)| kpe[i / sums::CHUNK * sums::CHUNK + j as usize])
                .collect();
        }
        ev
    }

    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// kappa of point `i` at damping eta.
    pub fn kappa(&self, i: usize, eta: f64) -> f64 {
        self.kappa_per_eta[i] * eta
    }

    /// Largest kappa per unit eta over the data.
    pub fn max_kappa_per_eta(&self) -> f64 {
        self.kappa_per_eta.iter().cloned().fold(0.0, f64::max)
    }

    /// V_Y of point `i`'s pair at yield stress sigma_y.
    pub fn v_yield_m_s(&self, i: usize, sigma_y_pa: f64) -> f64 {
        self.v_yield_per_pa[i] * sigma_y_pa.powf(2.5)
    }

    /// The sigma_y at which point `i`'s pair yields at speed `v_m_s`.
    pub fn sigma_y_for_v_yield(&self, i: usize, v_m_s: f64) -> f64 {
        (v_m_s / self.v_yield_per_pa[i]).powf(0.4)
    }

    pub fn e_vm(&self, i: usize, eta: f64) -> Result<f64> {
        Ok(viscoelastic::restitution(self.kappa(i, eta), self.rule, &self.method)?.e)
    }

    pub fn e_pm(&self, i: usize, sigma_y_pa: f64) -> f64 {
        plastic::e_of_u(self.data.obs[i].v_n_m_s / self.v_yield_m_s(i, sigma_y_pa))
    }

    /// e_pm of every point at sigma_y, into `out`.
    pub fn e_pm_row(&self, sigma_y_pa: f64, out: &mut [f64]) {
        let s25 = sigma_y_pa.powf(2.5);
        let n = self.len().min(out.len());
        super::sums::fill_chunks(&mut out[..n], |start, slots| {
            self.with_e_pm(start, s25, slots, |slot, e| *slot = e)
        });
    }

    /// u = v / V_Y of the points `start..start + out.len()` given s25 = sigma_y^(5/2) (V_Y = V_Y
    /// per Pa^(5/2) x s25), into `out` (read in sequence: several points at once where inlined
    /// into a [`crate::cpu::fast`] caller).
    #[inline(always)]
    pub(super) fn u_into(&self, start: usize, s25: f64, out: &mut [f64]) {
        let at = start..start + out.len();
        for ((u, v), vy) in out
            .iter_mut()
            .zip(&self.v_n_m_s[at.clone()])
            .zip(&self.v_yield_per_pa[at])
        {
            *u = v / (vy * s25);
        }
    }

    /// `combine(slot, e_pm)` for the points `start..start + out.len()` given s25 = sigma_y^(5/2)
    /// (sigma_y's power computed once for all points): e_pm = e(u), u = v / (V_Y per
    /// Pa^(5/2) s25), computed a block at a time by [`plastic::e_of_u_in_place`] (four points
    /// side by side: the same bits as [`plastic::e_of_u`] point by point; inlined into the
    /// evaluations' loops, which [`crate::cpu::fast`] compiles for FMA where there is one).
    #[inline(always)]
    fn with_e_pm(&self, start: usize, s25: f64, out: &mut [f64], combine: impl Fn(&mut f64, f64)) {
        const BLOCK: usize = 256;
        let mut u = [0.0; BLOCK];
        for (b, slots) in out.chunks_mut(BLOCK).enumerate() {
            let at = start + b * BLOCK;
            let u = &mut u[..slots.len()];
            self.u_into(at, s25, u);
            plastic::e_of_u_in_place(u);
            for (slot, e) in slots.iter_mut().zip(u.iter()) {
                combine(slot, *e);
            }
        }
    }

    /// The power law's e at the points `start..start + out.len()` for ln A and exponents a, b,
    /// into `out`: 1 - exp(ln A - a x1 + b x2), the exps four at a time ([`vexp`]; each value
    /// from its own point alone; inf and NaN where the model overflows, as with `f64::exp`).
    fn e_powerlaw(&self, start: usize, ln_a: f64, a: f64, b: f64, out: &mut [f64]) {
        let at = start..start + out.len();
        let (x1, x2) = (&self.powerlaw_ln_d[at.clone()], &self.powerlaw_ln_v[at]);
        for ((o, x1), x2) in out.iter_mut().zip(x1).zip(x2) {
            *o = ln_a - a * x1 + b * x2;
        }
        vexp::exp_in_place(out);
        for o in out.iter_mut() {
            *o = 1.0 - *o;
        }
    }

    /// e_vm of the points `start..start + out.len()` at damping eta, into `out`; an error is
    /// the first failing point's. With the master curve the points are evaluated interleaved
    /// ([`master::e_master_in_place`]: the same numbers, three times faster).
    fn e_vm_chunk(&self, start: usize, eta: f64, out: &mut [f64]) -> Result<()> {
        if self.method != VmMethod::Master {
            for (j, slot) in out.iter_mut().enumerate() {
                *slot = self.e_vm(start + j, eta)?;
            }
            return Ok(());
        }
        self.vm_in_kappa_order(start, eta, out, None)
    }

    /// e_vm of the points `start..start + values.len()` at damping eta by the master curve,
    /// and with `slopes` their slopes de_vm/d ln kappa ([`master::e_and_slope_master_in_place`]).
    /// The kappas go to the curve in increasing order, block by block (`start` a multiple of
    /// [`sums::CHUNK`]), and the results come back in point order. Why: the curve evaluates a
    /// group of kappas on one piece of its table as vector operations (1.4 to 1.6 times as
    /// fast as a group spread over pieces), and sorted kappas almost always share one; each
    /// value is computed alone, so the numbers are the same in any order. An error is the first
    /// failing point's in point order, as without the reordering.
    pub(super) fn vm_in_kappa_order(
        &self,
        start: usize,
        eta: f64,
        values: &mut [f64],
        mut slopes: Option<&mut [f64]>,
    ) -> Result<()> {
        debug_assert_eq!(start % sums::CHUNK, 0, "blocks start at multiples of CHUNK");
        for (b, block) in values.chunks_mut(sums::CHUNK).enumerate() {
            let base = start + b * sums::CHUNK;
            let m = block.len();
            let order = &self.kappa_order[base..base + m];
            // kappa(i, eta) of the points in order (buffers of the block's size: zeroing a
            // whole chunk's would cost small data more than their evaluation; lent by the
            // thread, not allocated per block).
            let with_slopes = slopes.is_some();
            // Both written in full before they are read.
            sums::with_scratch(m, [None, None], |[k, sk]| {
                for (k, c) in k
                    .iter_mut()
                    .zip(&self.kappa_per_eta_in_order[base..base + m])
                {
                    *k = c * eta;
                }
                let done = if with_slopes {
                    master::e_and_slope_master_in_place(k, sk, self.rule)
                } else {
                    master::e_master_in_place(k, self.rule)
                };
                if let Err(pos) = done {
                    let first = (0..m)
                        .find(|&j| {
                            master::restitution_master(self.kappa(base + j, eta), self.rule)
                                .is_none()
                        })
                        .unwrap_or(order[pos] as usize);
                    return Err(self.master_refusal(base + first, eta));
                }
                for (k, &j) in k.iter().zip(order) {
                    block[j as usize] = *k;
                }
                if let Some(out) = slopes.as_deref_mut() {
                    let out = &mut out[b * sums::CHUNK..b * sums::CHUNK + m];
                    for (s, &j) in sk.iter().zip(order) {
                        out[j as usize] = *s;
                    }
                }
                Ok(())
            })?;
        }
        Ok(())
    }

    /// The error for point `i`, whose kappa the interleaved master curve refused: `e_vm`'s own
    /// (the curve refuses only what `e_vm` refuses; the second arm is for that promise broken,
    /// never a silent success).
    fn master_refusal(&self, i: usize, eta: f64) -> Error {
        match self.e_vm(i, eta) {
            Err(e) => e,
            Ok(_) => Error::InvalidParameter {
                name: "dimensionless damping kappa (refused by the interleaved master curve)",
                value: self.kappa(i, eta),
                expected: "a finite number >= 0",
            },
        }
    }

    /// e_vm of every point at damping eta, into `out`; NaN where the model cannot be evaluated
    /// (the global search's rows, which turn NaN into a failure of the cells that use it).
    pub fn e_vm_row(&self, eta: f64, out: &mut [f64]) {
        let n = self.len().min(out.len());
        super::sums::fill_chunks(&mut out[..n], |start, slots| {
            if self.e_vm_chunk(start, eta, slots).is_err() {
                for (j, slot) in slots.iter_mut().enumerate() {
                    *slot = self.e_vm(start + j, eta).unwrap_or(f64::NAN);
                }
            }
        });
    }

    /// The row of e_vm at eta = exp(t) (axis 0) or of e_pm at sigma_y = exp(t) (axis 1) over
    /// every point ([`Evaluator::e_vm_row`], [`Evaluator::e_pm_row`]), computed once per
    /// evaluator: fits of several models through one evaluator, on several threads, share them.
    /// The lock is held only to look up and to insert: two threads asking for a new row at once
    /// both compute it (the same values; the first stored is kept), and none waits on another's
    /// computation (a rayon task waiting there could be the one that has to finish it).
    pub fn row(&self, axis: usize, t: f64) -> Arc<Vec<f64>> {
        self.memo_row((axis, t.to_bits()), || {
            let mut row = vec![0.0; self.len()];
            if axis == 1 {
                self.e_pm_row(t.exp(), &mut row);
            } else {
                self.e_vm_row(t.exp(), &mut row);
            }
            row
        })
    }

    /// The row of e_vm at `x` = eta (axis 0) or of e_pm at `x` = sigma_y (axis 1) over every
    /// point, the same doubles as the evaluations compute point by point, kept among the last
    /// [`HELD_ROWS`] asked for; None where the model cannot be evaluated at some point (the
    /// caller's own evaluation then reports it). Why: the inner fit of a profile of `min` or
    /// `product` holds one factor, which is the same at each of its iterations; on 100 000
    /// points of distinct sizes recomputing it was a third of each iteration.
    pub(super) fn held_row(&self, axis: usize, x: f64) -> Option<Arc<Vec<f64>>> {
        let key = (axis, x.to_bits());
        let memo = || self.rows.held.lock().unwrap_or_else(|e| e.into_inner());
        {
            let mut m = memo();
            if let Some(at) = m.iter().position(|(k, _)| *k == key) {
                let kept = m.remove(at);
                let row = Arc::clone(&kept.1);
                m.push(kept);
                return Some(row);
            }
        }
        let mut row = vec![0.0; self.len()];
        if axis == 0 {
            self.e_vm_row(x, &mut row);
        } else {
            self.e_pm_row(x, &mut row);
        }
        if row.iter().any(|v| v.is_nan()) {
            return None;
        }
        let row = Arc::new(row);
        let mut m = memo();
        if m.len() == HELD_ROWS {
            m.remove(0);
        }
        m.push((key, Arc::clone(&row)));
        Some(row)
    }

    /// The row kept under `key` (an axis and the bits of its t), made by `make` the first time
    /// it is asked for (see [`Evaluator::row`], whose axes are 0 and 1; the power law's
    /// landscape keeps its rows of exp(-a x1) and exp(b x2) under 2 and 3: its searches over
    /// the exponents and every slice of its profiles share the grid's rows).
    pub fn memo_row(&self, key: (usize, u64), make: impl FnOnce() -> Vec<f64>) -> Arc<Vec<f64>> {
        let memo = || self.rows.kept.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(row) = memo().get(&key) {
            return Arc::clone(row);
        }
        let row = make();
        Arc::clone(memo().entry(key).or_insert(Arc::new(row)))
    }

    /// Model e at every point for physical parameters `p` (order of [`ModelKind::params`]).
    /// Large data are evaluated in chunks on all cores ([`super::sums`]); each value is computed
    /// alone, and an error is the first failing point's, as in point order.
    pub fn predict(&self, kind: ModelKind, p: &[f64], out: &mut [f64]) -> Result<()> {
        self.predict_then(kind, p, out, |_, _| {})
    }

    /// [`Evaluator::predict`], then `finish(start, values)` on each chunk of values while it is
    /// still in cache and on its core (the residuals: one pass over the points, not two).
    pub fn predict_then(
        &self,
        kind: ModelKind,
        p: &[f64],
        out: &mut [f64],
        finish: impl Fn(usize, &mut [f64]) + Sync,
    ) -> Result<()> {
        let n = self.len().min(out.len());
        let s25 = match kind {
            ModelKind::Pm => p[0].powf(2.5),
            ModelKind::Min | ModelKind::Product => p[1].powf(2.5),
            _ => f64::NAN,
        };
        let chunk = |start: usize, slots: &mut [f64]| -> Result<()> {
            match kind {
                ModelKind::Vm => self.e_vm_chunk(start, p[0], slots)?,
                ModelKind::Pm => self.with_e_pm(start, s25, slots, |slot, e| *slot = e),
                ModelKind::Min => {
                    self.e_vm_chunk(start, p[0], slots)?;
                    self.with_e_pm(start, s25, slots, |slot, e| *slot = slot.min(e));
                }
                ModelKind::Product => {
                    self.e_vm_chunk(start, p[0], slots)?;
                    self.with_e_pm(start, s25, slots, |slot, e| *slot *= e);
                }
                ModelKind::PowerLaw => self.e_powerlaw(start, p[0].ln(), p[1], p[2], slots),
            }
            finish(start, slots);
            Ok(())
        };
        if !super::sums::is_large(n) {
            return chunk(0, &mut out[..n]);
        }
        use rayon::prelude::*;
        let size = super::sums::CHUNK;
        let results: Vec<Result<()>> = out[..n]
            .par_chunks_mut(size)
            .enumerate()
            .map(|(c, slots)| crate::cpu::fast(|| chunk(c * size, slots)))
            .collect();
        results.into_iter().collect()
    }

    /// The power law's per-point logarithms x1 = ln(d/d_ref) and x2 = ln(v/v_ref), in which
    /// 1 - e = exp(ln A - a x1 + b x2) (for derivatives in closed form).
    pub fn powerlaw_logs(&self) -> (&[f64], &[f64]) {
        (&self.powerlaw_ln_d, &self.powerlaw_ln_v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::fit::dataset::Observation;

    #[test]
    fn precomputed_scalings_match_the_contact_formulas() {
        // kappa linear in eta and V_Y ~ sigma_y^(5/2) are used to avoid recomputing the contact
        // per evaluation; check them against the direct formulas (rounding only: 1e-13).
        let m = Material::preset("nylon").unwrap();
        let obs = vec![
            Observation {
                d_mm: 6.35,
                d2_mm: None,
                v_n_m_s: 3.0,
                e: 0.9,
                e_err: None,
            },
            Observation {
                d_mm: 12.7,
                d2_mm: Some(f64::INFINITY),
                v_n_m_s: 17.0,
                e: 0.8,
                e_err: None,
            },
        ];
        let data = FitData::new(m, obs).unwrap();
        let ev = Evaluator::new(&data, ContactEnd::Overlap, VmMethod::Master);
        for (i, c) in data.contacts.iter().enumerate() {
            let v = data.obs[i].v_n_m_s;
            assert!((ev.kappa(i, 190.0) / c.kappa(190.0, v) - 1.0).abs() < 1e-13);
            assert!((ev.v_yield_m_s(i, 4e7) / c.yield_velocity_m_s(4e7) - 1.0).abs() < 1e-13);
            let s = ev.sigma_y_for_v_yield(i, 5.0);
            assert!((c.yield_velocity_m_s(s) / 5.0 - 1.0).abs() < 1e-13);
            for kind in ModelKind::ALL {
                let p: Vec<f64> = match kind.n_params() {
                    1 if kind == ModelKind::Vm => vec![190.0],
                    1 => vec![4e7],
                    2 => vec![190.0, 4e7],
                    _ => vec![0.05, 0.5, 0.2],
                };
                let mut out = vec![0.0; 2];
                ev.predict(kind, &p, &mut out).unwrap();
                let direct =
                    predict_e(kind, c, v, &p, ContactEnd::Overlap, &VmMethod::Master).unwrap();
                assert!((out[i] - direct).abs() < 1e-13, "{kind}");
            }
        }
        // The power law's size is 4 R~: the diameter for identical spheres, 2 d on a wall.
        assert!((powerlaw_d_mm(&data.contacts[0]) - 6.35).abs() < 1e-12);
        assert!((powerlaw_d_mm(&data.contacts[1]) - 25.4).abs() < 1e-12);
    }

    #[test]
    fn e_pm_is_right_or_an_error_at_extreme_yield_stresses() {
        // A 0.2 mm nylon pair at sigma_y = 1e-79 Pa: V_Y is about 3.8e-206 m/s, a normal
        // double, but the direct formula's intermediates underflowed to V_Y = 0 (e = 0). The
        // reference V_Y comes from V_Y ~ sigma_y^(5/2) in logarithms, from sigma_y = 4e7 Pa
        // (a path that never underflows): rounding of exp at |ln| ~ 470 is ~5e-14 relative, and
        // e ~ u^(-1/4) far beyond yield, so 1e-12 relative is the tolerance.
        let m = Material::preset("nylon").unwrap();
        let c = crate::fit::dataset::pair_contact(m, 0.2, None).unwrap();
        let v_ref = c.yield_velocity_m_s(4e7);
        for sigma in [1e-79, 1e-60, 1e-40, 1e3, 4e7] {
            let vy = (v_ref.ln() + 2.5 * (sigma / 4e7f64).ln()).exp();
            for v in [1e-3, 1.0, 30.0] {
                let want = plastic::e_of_u(v / vy);
                let got = e_pm(&c, v, sigma).unwrap();
                assert!(
                    (got / want - 1.0).abs() < 1e-12,
                    "sigma_y {sigma:e} v {v}: {got:e} against {want:e}"
                );
                let p = predict_e(
                    ModelKind::Pm,
                    &c,
                    v,
                    &[sigma],
                    ContactEnd::Overlap,
                    &VmMethod::Master,
                );
                assert_eq!(p.unwrap(), got);
            }
        }
        // V_Y below the normal range (1e-130 Pa: ~1e-345 m/s), and u = v/V_Y beyond f64::MAX:
        // errors naming the input, not e = 0.
        let msg = e_pm(&c, 1.0, 1e-130).unwrap_err().to_string();
        assert!(
            msg.contains("V_Y") && msg.contains("sigma_y = 1e-130 Pa"),
            "{msg}"
        );
        let msg = e_pm(&c, 1e300, 1e-110).unwrap_err().to_string();
        assert!(
            msg.contains("u = V/V_Y") && msg.contains("v = 1e300 m/s"),
            "{msg}"
        );
        for kind in [ModelKind::Pm, ModelKind::Min, ModelKind::Product] {
            let p: Vec<f64> = if kind == ModelKind::Pm {
                vec![1e-130]
            } else {
                vec![190.0, 1e-130]
            };
            assert!(predict_e(kind, &c, 1.0, &p, ContactEnd::Overlap, &VmMethod::Master).is_err());
        }
    }

    #[test]
    fn a_row_is_computed_once_and_is_the_row_of_its_parameter() {
        // The memo hands back the row its evaluation gives (bit for bit: the same function),
        // by axis and parameter: the same allocation when asked again, another for another
        // parameter or axis; a clone of the evaluator starts empty.
        let m = Material::preset("nylon").unwrap();
        let obs: Vec<Observation> = (0..7)
            .map(|i| Observation {
                d_mm: [6.35, 12.7][i % 2],
                d2_mm: None,
                v_n_m_s: 0.5 + 3.0 * i as f64,
                e: 0.8,
                e_err: None,
            })
            .collect();
        let data = FitData::new(m, obs).unwrap();
        let ev = Evaluator::new(&data, ContactEnd::Overlap, VmMethod::Master);
        let (t_eta, t_sigma) = (190f64.ln(), 4e7f64.ln());
        let (mut vm, mut pm) = (vec![0.0; 7], vec![0.0; 7]);
        ev.e_vm_row(t_eta.exp(), &mut vm);
        ev.e_pm_row(t_sigma.exp(), &mut pm);
        let bits = |r: &[f64]| r.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let a = ev.row(0, t_eta);
        assert_eq!(bits(&a), bits(&vm));
        assert!(Arc::ptr_eq(&a, &ev.row(0, t_eta)));
        let b = ev.row(1, t_sigma);
        assert_eq!(bits(&b), bits(&pm));
        assert!(Arc::ptr_eq(&b, &ev.row(1, t_sigma)));
        assert!(!Arc::ptr_eq(&ev.row(0, t_sigma), &b));
        assert!(!Arc::ptr_eq(&ev.row(0, t_eta + 1e-12), &a));
        assert!(!Arc::ptr_eq(&ev.clone().row(0, t_eta), &a));
    }

    #[test]
    fn large_data_give_each_point_its_own_numbers_bit_for_bit() {
        // 20 000 points (the chunked, parallel path), speeds and sizes in no order: the
        // evaluations that hand the master curve its kappas sorted per chunk must give every
        // point the same double as evaluating it alone (not a tolerance: the order is only a
        // schedule), with the wide registers and without; where some points cannot be
        // evaluated, an error.
        let m = Material::preset("nylon").unwrap();
        let obs: Vec<Observation> = (0..20_000)
            .map(|i| {
                let r = (i as f64 * 0.618_034).fract();
                Observation {
                    d_mm: [6.35, 12.7, 25.4][i % 3],
                    d2_mm: [None, Some(f64::INFINITY), Some(3.0)][i % 5 % 3],
                    v_n_m_s: 0.1 * 1000f64.powf(r),
                    e: 0.8,
                    e_err: None,
                }
            })
            .collect();
        let data = FitData::new(m, obs).unwrap();
        let n = data.len();
        for rule in ContactEnd::ALL {
            let ev = Evaluator::new(&data, rule, VmMethod::Master);
            for baseline in [false, true] {
                crate::cpu::set_baseline_only(baseline);
                let (eta, sy) = (190.0, 4e7);
                let mut row = vec![0.0; n];
                ev.e_vm_row(eta, &mut row);
                let mut vm = vec![0.0; n];
                ev.predict(ModelKind::Vm, &[eta], &mut vm).unwrap();
                let mut prod = vec![0.0; n];
                ev.predict(ModelKind::Product, &[eta, sy], &mut prod)
                    .unwrap();
                for i in 0..n {
                    let alone = ev.e_vm(i, eta).unwrap();
                    assert_eq!(row[i].to_bits(), alone.to_bits(), "{rule:?} point {i}");
                    assert_eq!(vm[i].to_bits(), alone.to_bits(), "{rule:?} point {i}");
                    let p = alone * ev.e_pm(i, sy);
                    assert_eq!(prod[i].to_bits(), p.to_bits(), "{rule:?} point {i}");
                }
                // An eta at which the points with the larger kappas overflow to inf (half of
                // them): an error, e_vm's own for the first of them.
                let mut sorted: Vec<f64> = (0..n).map(|i| ev.kappa(i, 1.0)).collect();
                sorted.sort_by(f64::total_cmp);
                let eta = f64::MAX / sorted[n / 2];
                let first = (0..n).find(|&i| ev.e_vm(i, eta).is_err()).unwrap();
                let want = ev.e_vm(first, eta).unwrap_err().to_string();
                let got = ev.predict(ModelKind::Vm, &[eta], &mut vm).unwrap_err();
                assert_eq!(got.to_string(), want, "{rule:?}");
            }
            crate::cpu::set_baseline_only(false);
        }
    }

    #[test]
    fn names_round_trip() {
        for k in ModelKind::ALL {
            assert_eq!(k.name().parse::<ModelKind>().unwrap(), k);
            let phys: Vec<f64> = (0..k.n_params()).map(|j| 1.5 + j as f64).collect();
            let back = k.to_physical(&k.to_internal(&phys));
            for (a, b) in phys.iter().zip(&back) {
                assert!((a - b).abs() < 1e-14);
            }
        }
        assert!("vmm".parse::<ModelKind>().is_err());
    }
}
