//! The power law profiled over its exponents: for fixed (a, b) the model 1 - e = A z_i is
//! linear in A, so chi2 is a convex quadratic in A and its minimum over A's box is the clamped
//! least-squares value. [`polish_powerlaw`] runs Levenberg-Marquardt over (a, b) alone: with a
//! single size A and a are collinear, and a three-parameter Levenberg-Marquardt pinned at a
//! bound of one of them can stall (seen on a wall data set of the randomized test).
//!
//! **Known answer** (test below): noise-free data give back (A, a, b), and the profiled A at the
//! true exponents is the true A.

use super::lsq::{self, LmOptions, Residuals};
use super::objective::Objective;
use super::polish::Found;
use super::{sums, vexp};
use crate::error::Result;

/// The power law with A eliminated: residuals over (a, b) at the least-squares A for those
/// exponents, clamped to A's box (chi2 is a convex quadratic in A, so the clamped value is the
/// exact minimum over the box).
pub struct ProfiledPowerLaw<'a> {
    obj: &'a Objective<'a>,
    /// The evaluator's ln(d/d_ref) and ln(v/v_ref).
    x1: &'a [f64],
    x2: &'a [f64],
    y: Vec<f64>,
    /// The weights 1/sigma_i^2 scaled by the largest (the sums of [`ProfiledPowerLaw::ln_a`]).
    w: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl<'a> ProfiledPowerLaw<'a> {
    pub fn new(obj: &'a Objective<'a>) -> Self {
        let data = obj.ev.data;
        let wmax = obj.inv_sigma.iter().map(|s| s * s).fold(0.0, f64::max);
        let (x1, x2) = obj.ev.powerlaw_logs();
        ProfiledPowerLaw {
            obj,
            x1,
            x2,
            y: data.obs.iter().map(|o| 1.0 - o.e).collect(),
            w: obj.inv_sigma.iter().map(|s| s * s / wmax).collect(),
            lower: obj.lower[1..].to_vec(),
            upper: obj.upper[1..].to_vec(),
        }
    }

    /// ln A at the minimum over A for exponents (a, b), with z_i = (d/d_ref)^(-a) (v/v_ref)^b.
    /// The z_i are each computed alone (exps four at a time, [`vexp`]) and the two sums are
    /// [`sums::sum`]'s: in point order for small data, in fixed chunks for large data, so the
    /// result never depends on the number of threads.
    pub fn ln_a(&self, ab: &[f64]) -> f64 {
        let (x1, x2, y, w) = (self.x1, self.x2, &self.y, &self.w);
        let n = y.len();
        let mut z = vec![0.0; n];
        sums::fill_chunks(&mut z, |start, z| {
            let at = start..start + z.len();
            for ((z, x1), x2) in z.iter_mut().zip(&x1[at.clone()]).zip(&x2[at]) {
                *z = -ab[0] * x1 + ab[1] * x2;
            }
            vexp::exp_in_place(z);
        });
        // Sums scaled by the largest z and weight so that they cannot overflow.
        let zmax = z.iter().cloned().fold(0.0, f64::max);
        let [num, den] = sums::sum(n, |r| {
            let (mut num, mut den) = (0.0, 0.0);
            for i in r {
                let zs = z[i] / zmax;
                num += w[i] * zs * y[i];
                den += w[i] * zs * zs;
            }
            [num, den]
        });
        let ln_a = (num / den / zmax).ln();
        let (lo, hi) = (self.obj.lower[0], self.obj.upper[0]);
        // A <= 0 (or an undefined ratio) is below the box: its lower end is the minimum there.
        if !(ln_a >= lo) {
            lo
        } else if ln_a > hi {
            hi
        } else {
            ln_a
        }
    }

    /// The full parameters (ln A, a, b) at exponents (a, b).
    pub fn theta(&self, ab: &[f64]) -> Vec<f64> {
        vec![self.ln_a(ab), ab[0], ab[1]]
    }
}

impl Residuals for ProfiledPowerLaw<'_> {
    fn n_params(&self) -> usize {
        2
    }
    fn n_residuals(&self) -> usize {
        self.y.len()
    }
    fn residuals(&self, ab: &[f64], out: &mut [f64]) -> Result<()> {
        self.obj.residuals(&self.theta(ab), out)
    }
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn fd_step(&self) -> f64 {
        self.obj.fd_step
    }
}

/// The power law polished over its exponents with A profiled out, from (a, b) (see the module
/// doc); the result in full parameters.
pub fn polish_powerlaw(obj: &Objective, ab: &[f64]) -> Result<Found> {
    let p = ProfiledPowerLaw::new(obj);
    let r = lsq::levenberg_marquardt(&p, ab, &[true, true], &LmOptions::default())?;
    let theta = p.theta(&r.theta);
    Ok(Found {
        chi2: lsq::chi2(obj, &theta)?,
        theta,
        converged: r.converged,
        reason: r.reason.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::fit::dataset::{FitData, Observation};
    use crate::fit::models::ModelKind;
    use crate::fit::models::{Evaluator, predict_e};
    use crate::models::viscoelastic::{ContactEnd, VmMethod};

    /// Noise-free data of `kind` with parameters `p` (physical) on two sizes.
    fn data(kind: ModelKind, p: &[f64]) -> FitData {
        let m = Material::preset("nylon").unwrap();
        let mut obs = Vec::new();
        for d in [6.35, 25.4] {
            let c = crate::fit::dataset::pair_contact(m, d, None).unwrap();
            for k in 0..15 {
                let v = 0.5 * 1.3f64.powi(k);
                let e = predict_e(kind, &c, v, p, ContactEnd::Overlap, &VmMethod::Master).unwrap();
                obs.push(Observation {
                    d_mm: d,
                    d2_mm: None,
                    v_n_m_s: v,
                    e,
                    e_err: Some(0.01),
                });
            }
        }
        FitData::new(m, obs).unwrap()
    }

    #[test]
    fn profiled_power_law_recovers_noise_free_parameters() {
        // chi2 = 0 at the planted parameters; to 1e-7 (LM tolerance 1e-10).
        let p = [0.04, 0.5, 0.3];
        let d = data(ModelKind::PowerLaw, &p);
        let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
        let obj = Objective::new(&ev, ModelKind::PowerLaw).unwrap();
        let truth = ModelKind::PowerLaw.to_internal(&p);
        let f = polish_powerlaw(&obj, &[1.5, -0.4]).unwrap();
        let close = f
            .theta
            .iter()
            .zip(&truth)
            .all(|(x, y)| (x - y).abs() < 1e-7);
        assert!(close && f.chi2 < 1e-12, "{f:?}");
        // The least-squares A at the true exponents is the true A (to rounding).
        let prof = ProfiledPowerLaw::new(&obj);
        assert!((prof.ln_a(&[0.5, 0.3]) - 0.04f64.ln()).abs() < 1e-12);
    }
}
