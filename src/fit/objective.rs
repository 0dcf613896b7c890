//! The least-squares problem of one model on one data set: residuals, the search box, the
//! accuracy of the model evaluation, and the chi2 scale shared by errors and intervals.
//!
//! **Search box** (wide enough for any data a user can have; checked finite before any grid is
//! built, with an error naming the data otherwise):
//! - log eta such that the largest kappa in the data lies in [1e-8, 0.999 KAPPA_MAX]: below,
//!   1 - e is under 1.2e-8 at every point (elastic for any measurement); above, e < 1e-9 with
//!   the overlap rule (6.1e-4 with the force rule: a fit to such data ends at the box's edge and
//!   says so) and the master curve hands over to its large-kappa laws;
//! - log sigma_y from where every point has V/V_Y >= 1e6 (e_pm < 0.04) up to where no point
//!   yields (V_Y >= 1.5 v for every point: the plateau where sigma_y stops mattering);
//! - powerlaw: A in [1e-9, 1e3], a and b in [-10, 10], each end of the exponents narrowed (with a
//!   warning) for data so extreme that 1 - e = A (d/10 mm)^(-a) (v/1 m/s)^b would leave
//!   [1e-304, 1e130] at some point inside the box (`powerlaw_exponent_ends`).
//!
//! **Chi2 scale** s (one convention for `stderr` and the intervals): weighted fits use
//! s = max(1, chi2/dof), the Particle Data Group's scale-factor rule (errors as given, unless the
//! scatter shows them too small; never narrower than the stated errors imply); unweighted fits
//! s = chi2/dof, the only scale they have. Then `stderr` = sqrt(s C_jj) and the 95% interval is
//! Delta chi2 = 3.84 s, so for a model linear in its parameters the interval is exactly
//! value +- 1.96 stderr.

use super::dataset::{FitData, Merged};
use super::lsq::Residuals;
use super::models::{Evaluator, ModelKind};
use crate::error::{Error, Result};
use crate::models::viscoelastic::{Integrator, VmMethod, master::KAPPA_MAX};
use nalgebra::DMatrix;
use std::sync::atomic::{AtomicU64, Ordering};

/// chi2 quantile of one degree of freedom at 95% (the profile-likelihood interval threshold).
pub const CHI2_1DOF_95: f64 = 3.841458820694124;

/// Largest ln(1 - e) the power law may reach inside its box: exp(300) = 1.9e130, whose square
/// (the search forms sums of squares of the model) stays below f64::MAX = 1.8e308.
const POWERLAW_MAX_EXPONENT: f64 = 300.0;
/// Largest -ln(1 - e) inside the box: exp(-700) = 9.9e-305 is a normal double (from 2.2e-308
/// down, doubles lose relative precision); its square may underflow in the sums, where it
/// stands beside terms at least 1e-304 times larger.
const POWERLAW_MIN_EXPONENT: f64 = 700.0;

/// The least-squares problem of one model on one data set, counting its evaluations.
pub struct Objective<'a> {
    pub ev: &'a Evaluator<'a>,
    pub kind: ModelKind,
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub fd_step: f64,
    /// Evaluations of the model over every point (atomic: a fit's profiles run side by side;
    /// [`Objective::count_evaluation`], [`Objective::evaluations`]).
    evals: AtomicU64,
    pub inv_sigma: Vec<f64>,
    /// The points' measured e, contiguous.
    e: Vec<f64>,
    /// Bound on the error of one evaluation of e (see [`model_accuracy`]).
    pub e_accuracy: f64,
    /// Things the set-up changed and a user should know (a narrowed box).
    pub warnings: Vec<String>,
    /// Rows of the data as given: more than the evaluator's points when repeats were merged
    /// ([`FitData::merge_repeats`]); the degrees of freedom count rows.
    pub rows: usize,
    /// chi2 of the rows minus chi2 of the points (0 unless repeats were merged): residuals and
    /// [`super::lsq::chi2`] see the points, [`Objective::scale`] and the reports the rows.
    pub chi2_offset: f64,
    /// The first row of each point, when repeats were merged (for messages).
    first_row: Option<Vec<usize>>,
}

impl Residuals for Objective<'_> {
    fn n_params(&self) -> usize {
        self.kind.n_params()
    }
    fn n_residuals(&self) -> usize {
        self.ev.len()
    }
    fn residuals(&self, theta: &[f64], out: &mut [f64]) -> Result<()> {
        self.count_evaluation();
        let p = self.kind.to_physical(theta);
        let (e, inv_sigma) = (&self.e[..], &self.inv_sigma[..]);
        self.ev.predict_then(self.kind, &p, out, |start, slots| {
            let at = start..start + slots.len();
            for ((o, e), w) in slots.iter_mut().zip(&e[at.clone()]).zip(&inv_sigma[at]) {
                *o = (*o - e) * w;
            }
        })
    }
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn fd_step(&self) -> f64 {
        self.fd_step
    }
    fn jacobian_exact(
        &self,
        theta: &[f64],
        free: &[bool],
        out: &mut DMatrix<f64>,
    ) -> Option<Result<()>> {
        match self.kind {
            ModelKind::PowerLaw => {
                self.powerlaw_jacobian(theta, free, out);
                Some(Ok(()))
            }
            k if self.ev.has_exact_jacobian(k) => {
                let p = k.to_physical(theta);
                Some(
                    self.ev
                        .jacobian_separable(k, &p, &self.inv_sigma, free, out),
                )
            }
            _ => None,
        }
    }
    fn kinked(&self) -> bool {
        self.kind == ModelKind::Min
    }
    fn residuals_and_jacobian(
        &self,
        theta: &[f64],
        out: &mut [f64],
        free: &[bool],
        jac: &mut DMatrix<f64>,
    ) -> Option<Result<()>> {
        let k = self.kind;
        // The power law has no exact separable Jacobian (its own is not fused).
        if !self.ev.has_exact_jacobian(k) || !free.contains(&true) {
            return None;
        }
        let shape = (self.ev.len(), free.iter().filter(|&&f| f).count());
        if jac.shape() != shape {
            *jac = DMatrix::zeros(shape.0, shape.1);
        }
        self.count_evaluation();
        let p = k.to_physical(theta);
        Some(self.ev.jacobian_separable_with(
            k,
            &p,
            &self.inv_sigma,
            free,
            jac,
            Some((&self.e, out)),
        ))
    }
}

impl<'a> Objective<'a> {
    /// Counts one evaluation of the model over every point.
    pub fn count_evaluation(&self) {
        self.evals.fetch_add(1, Ordering::Relaxed);
    }

    /// Evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evals.load(Ordering::Relaxed)
    }

    /// How far two computations of this chi2 may differ ([`chi2_rounding`] with this data's
    /// weights and the model's accuracy).
    pub fn evaluation_rounding(&self, chi2: f64) -> f64 {
        let w: f64 = self.inv_sigma.iter().map(|s| s * s).sum();
        chi2_rounding(self.ev.len(), w, self.e_accuracy, chi2)
    }

    /// The problem of `kind` on the evaluator's data, with its search box.
    pub fn new(ev: &'a Evaluator<'a>, kind: ModelKind) -> Result<Objective<'a>> {
        let data = ev.data;
        let mut warnings = Vec::new();
        let (lower, upper) = search_box(kind, ev, &mut warnings)?;
        let inv_sigma: Vec<f64> = (0..data.len()).map(|i| 1.0 / data.sigma(i)).collect();
        if let Some(i) = (0..data.len()).find(|&i| !inv_sigma[i].is_finite()) {
            return Err(Error::InvalidParameter {
                name: "1/e_err (the error is too small to divide by)",
                value: data.sigma(i),
                expected: "an error of e above 1e-300",
            });
        }
        // Rows below the master curve's floor are refused by FitData::new; this catches the
        // ODE's coarser accuracy, and points merged from many repeats.
        let e_accuracy = model_accuracy(&ev.method);
        if let Some(i) = (0..data.len()).find(|&i| data.sigma(i) < ERROR_PER_ACCURACY * e_accuracy)
        {
            return Err(Error::InvalidParameter {
                name: "e_err of a point (merged repeats included)",
                value: data.sigma(i),
                expected: "at least 1000 times the accuracy of the computed e (5e-11 with the \
                           master curve, 5e-7 with the ODE at its default tolerance): the \
                           residual would be rounding",
            });
        }
        Ok(Objective {
            ev,
            kind,
            lower,
            upper,
            fd_step: fd_step_for(kind, &ev.method),
            evals: AtomicU64::new(0),
            inv_sigma,
            e: data.obs.iter().map(|o| o.e).collect(),
            e_accuracy,
            warnings,
            rows: data.len(),
            chi2_offset: 0.0,
            first_row: None,
        })
    }

    /// The problem on merged points (the evaluator's data must be `m.data`), counting the rows
    /// and the constant part of chi2 as given.
    pub fn with_merged(mut self, m: &Merged) -> Objective<'a> {
        self.rows = m.rows;
        self.chi2_offset = m.chi2_offset;
        self.first_row = Some(m.first_row.clone());
        self
    }

    /// The power law's Jacobian in (ln A, a, b): with q_i = (1 - e_i) / sigma_i =
    /// exp(ln A - a x1_i + b x2_i) / sigma_i, df_i/d ln A = -q_i, df_i/da = q_i x1_i and
    /// df_i/db = -q_i x2_i (one exp per point; the columns of the free parameters, in order).
    fn powerlaw_jacobian(&self, theta: &[f64], free: &[bool], out: &mut DMatrix<f64>) {
        let (x1, x2) = self.ev.powerlaw_logs();
        let n = self.ev.len();
        let mut q = vec![0.0; n];
        let inv_sigma = &self.inv_sigma;
        // q_i = exp(ln A - a x1 + b x2) / sigma_i, the exps four at a time (each from its own
        // point: the same numbers for any chunking).
        super::sums::fill_chunks(&mut q, |start, q| {
            let at = start..start + q.len();
            let (x1, x2) = (&x1[at.clone()], &x2[at.clone()]);
            for ((q, x1), x2) in q.iter_mut().zip(x1).zip(x2) {
                *q = theta[0] - theta[1] * x1 + theta[2] * x2;
            }
            super::vexp::exp_in_place(q);
            for (q, w) in q.iter_mut().zip(&inv_sigma[at]) {
                *q *= w;
            }
        });
        let cols = (0..3).filter(|&j| free[j]);
        // Each column in chunks side by side (large data), as slices read in sequence.
        for (col, j) in out.as_mut_slice().chunks_mut(n.max(1)).zip(cols) {
            super::sums::fill_chunks(col, |start, o| {
                let at = start..start + o.len();
                let q = &q[at.clone()];
                match j {
                    0 => o.iter_mut().zip(q).for_each(|(o, q)| *o = -q),
                    1 => {
                        (o.iter_mut().zip(q.iter().zip(&x1[at]))).for_each(|(o, (q, x))| *o = q * x)
                    }
                    _ => (o.iter_mut().zip(q.iter().zip(&x2[at])))
                        .for_each(|(o, (q, x))| *o = -q * x),
                }
            });
        }
    }

    /// Degrees of freedom, rows - k (positive: the engine refuses rows <= k).
    pub fn dof(&self) -> usize {
        self.rows - self.kind.n_params()
    }

    /// The chi2 scale s of the module doc, from the chi2 of the points (the residuals').
    pub fn scale(&self, chi2: f64) -> f64 {
        let red = (chi2 + self.chi2_offset) / self.dof() as f64;
        if !self.ev.data.weighted || red > 1.0 {
            red
        } else {
            1.0
        }
    }

    /// The observation `i` described for error messages.
    pub fn describe_point(&self, i: usize) -> String {
        let o = &self.ev.data.obs[i];
        let row = self.first_row.as_ref().map_or(i, |f| f[i]);
        format!(
            "point {} (d_mm = {}, v_n_m_s = {})",
            row + 1,
            o.d_mm,
            o.v_n_m_s
        )
    }
}

/// The finite-difference step in the log parameters matched to the accuracy of e: the closed
/// forms and the master curve (2.4e-15) give (1e-15)^(1/3) = 1e-5; the ODE its tolerance^(1/3).
fn fd_step_for(kind: ModelKind, method: &VmMethod) -> f64 {
    match (kind, method) {
        (ModelKind::Vm | ModelKind::Min | ModelKind::Product, VmMethod::Ode(s)) => {
            s.rtol.max(s.atol).cbrt().clamp(1e-5, 1e-2)
        }
        _ => 1e-5,
    }
}

/// [`model_accuracy`] of the master curve (and of the plastic closed form, inside it).
pub const MASTER_ACCURACY: f64 = 5e-14;

/// How many times the accuracy of the computed e a point's error must be (1000: the model's
/// rounding then moves a residual by at most a thousandth of its error). Below it the point's
/// residual is set by the rounding, not by the data: one point of e = 1e-20 with sigma_e =
/// 2 e v_err / v_n = 3.5e-22 among errors of 0.04 made the power law's search chase rounding
/// for 2.7 s, its grid's chi2 and the objective's at the same parameters 1e7 apart.
pub const ERROR_PER_ACCURACY: f64 = 1e3;

/// A bound on |computed e - exact e| for one evaluation, used to widen the monotonicity bounds of
/// the global search. Master curve: 2.4e-15 measured against the reference (its module doc),
/// taken as 5e-14 (a factor 20 of margin); the plastic closed form is within 1.2 ulp, inside it.
/// Adaptive ODE settings: the bench measured errors up to 10 tol (Dopri5 at tol 1e-3; Dop853
/// stays below 0.3 tol), taken as 50 tol. Fixed-step RK4: measured 6.3 h^4 at h = 0.05 and less at
/// smaller steps, taken as 100 h^4.
pub fn model_accuracy(method: &VmMethod) -> f64 {
    match method {
        VmMethod::Master => MASTER_ACCURACY,
        VmMethod::Ode(s) => match s.integrator {
            Integrator::Rk4 { h } => (100.0 * h.powi(4)).max(MASTER_ACCURACY),
            _ => (50.0 * s.rtol.max(s.atol)).max(MASTER_ACCURACY),
        },
    }
}

/// How far two computations of one chi2 of `n` points may differ, for weights summing to
/// `w_sum` and a model whose every e is within `e_accuracy` of the exact one: the sums' rounding
/// (each sum of n non-negative terms is within (n - 1) u of the terms' total, u the unit
/// roundoff: Higham, "Accuracy and Stability of Numerical Algorithms", 2nd ed., 2002, §4.2; so
/// 2 (n + 10) u |chi2| covers two of them with room for the few operations that form each term,
/// 2.2e-11 relative at 100 000 points, far below the search's tolerance of 1e-7) and the model's
/// (two computations evaluate e in different forms: the power law's grid node as a product of
/// its rows' exponentials, its polish as one exponential of a sum, each argument's rounding up
/// to 300 u a relative error of e's distance from 1). With d = 2 e_accuracy each residual
/// differs by at most d / sigma_i, and chi2 by at most 2 d sum w_i |r_i| + d^2 W <=
/// 2 d sqrt(W chi2) + d^2 W, W = sum w_i (Cauchy-Schwarz). Seed 2043 of the randomized test
/// (the power law at a = -10, b = 10): node and polish 1.8e-12 apart, where the sums' rounding
/// alone allowed 1.7e-13.
pub fn chi2_rounding(n: usize, w_sum: f64, e_accuracy: f64, chi2: f64) -> f64 {
    let d = 2.0 * e_accuracy;
    2.0 * (n as f64 + 10.0) * (f64::EPSILON / 2.0) * chi2.abs()
        + 2.0 * d * (w_sum * chi2.abs()).sqrt()
        + w_sum * d * d
}

fn box_error(what: &'static str, value: f64) -> Error {
    Error::InvalidParameter {
        name: what,
        value,
        expected: "a finite search range (the data's speeds or sizes, or the material's constants, are too extreme)",
    }
}

/// The search box of `kind` in internal coordinates (see the module doc).
fn search_box(
    kind: ModelKind,
    ev: &Evaluator,
    warnings: &mut Vec<String>,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let eta = || -> Result<(f64, f64)> {
        let k = ev.max_kappa_per_eta();
        let (lo, hi) = ((1e-8 / k).ln(), (0.999 * KAPPA_MAX / k).ln());
        if !(k > 0.0 && lo.is_finite() && hi.is_finite()) {
            return Err(box_error("largest kappa per unit eta over the data", k));
        }
        Ok((lo, hi))
    };
    let sigma = || -> Result<(f64, f64)> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for (i, o) in ev.data.obs.iter().enumerate() {
            let a = ev.sigma_y_for_v_yield(i, o.v_n_m_s * 1e-6).ln();
            let b = ev.sigma_y_for_v_yield(i, o.v_n_m_s * 1.5).ln();
            if !(a.is_finite() && b.is_finite()) {
                return Err(box_error(
                    "log sigma_y at which a point yields (speed of that point)",
                    o.v_n_m_s,
                ));
            }
            lo = lo.min(a);
            hi = hi.max(b);
        }
        Ok((lo, hi))
    };
    Ok(match kind {
        ModelKind::Vm => {
            let (a, b) = eta()?;
            (vec![a], vec![b])
        }
        ModelKind::Pm => {
            let (a, b) = sigma()?;
            (vec![a], vec![b])
        }
        ModelKind::Min | ModelKind::Product => {
            let (a, b) = eta()?;
            let (c, d) = sigma()?;
            (vec![a, c], vec![b, d])
        }
        ModelKind::PowerLaw => {
            let (a_lo, a_hi) = (1e-9f64.ln(), 1e3f64.ln());
            let (x1, x2) = ev.powerlaw_logs();
            let x: Vec<[f64; 2]> = x1.iter().zip(x2).map(|(&a, &b)| [a, b]).collect();
            let ends = powerlaw_exponent_ends(&x, a_lo, a_hi)?;
            if ends != [-10.0, 10.0, -10.0, 10.0] {
                warnings.push(format!(
                    "powerlaw: exponents searched in a in [{:.3}, {:.3}], b in [{:.3}, {:.3}] \
                     instead of [-10, 10]: a box where 1 - e = A (d/10 mm)^(-a) (v/1 m/s)^b \
                     stays within [1e-304, 1e130] at every point of the data",
                    ends[0], ends[1], ends[2], ends[3]
                ));
            }
            (vec![a_lo, ends[0], ends[2]], vec![a_hi, ends[1], ends[3]])
        }
    })
}

/// The power law's exponent box [a_lo, a_hi] x [b_lo, b_hi] (within [-10, 10]^2), given each
/// point's x = (ln(d/10 mm), ln(v/1 m/s)) and the ends of ln A: every end as far out as keeps
/// ln(1 - e) = ln A - a x1 + b x2 in [-POWERLAW_MIN_EXPONENT, POWERLAW_MAX_EXPONENT] at every
/// point of the box, and the same for the search's centred rows (x less its mean over the
/// points, the amplitude's range aside).
///
/// Why each end on its own: the largest of -a x1 + b x2 over the box, for one point, sits at
/// the end of a that the sign of x1 picks and the end of b that the sign of x2 picks (the
/// smallest at the other two). If each of those two ends is at most room / (|x1| + |x2|), their
/// terms add up to at most room. So an end is limited only by the points that load it on the
/// side that can overflow, and on the other side by those that can underflow: one speed of
/// 1e-300 m/s limits b from below to about 0.42 (exp(-0.42 x -691) reaches 1e126) but from
/// above only to about 1 (reaching 1e-300): a box symmetric in |a| and |b| would stop both at
/// 0.42 and miss the data's b = 0.45.
fn powerlaw_exponent_ends(x: &[[f64; 2]], ln_a_lo: f64, ln_a_hi: f64) -> Result<[f64; 4]> {
    let up = POWERLAW_MAX_EXPONENT - ln_a_hi;
    let down = POWERLAW_MIN_EXPONENT + ln_a_lo;
    let n = x.len() as f64;
    let mean = [0, 1].map(|k| x.iter().map(|p| p[k]).sum::<f64>() / n);
    // [a_lo, a_hi, b_lo, b_hi] as magnitudes; the end each sign of x1 (or x2) loads when the
    // sum is largest: x1 > 0 loads a_lo, x1 < 0 a_hi; x2 > 0 loads b_hi, x2 < 0 b_lo (the
    // smallest: the other ones).
    let mut ends = [10.0f64; 4];
    for centred in [false, true] {
        for p in x {
            let (x1, x2) = if centred {
                (p[0] - mean[0], p[1] - mean[1])
            } else {
                (p[0], p[1])
            };
            let reach = x1.abs() + x2.abs();
            if !reach.is_finite() {
                return Err(box_error("largest |ln(d/10 mm)| + |ln(v/1 m/s)|", reach));
            }
            if reach == 0.0 {
                continue;
            }
            let (a_up, a_down) = if x1 > 0.0 { (0, 1) } else { (1, 0) };
            let (b_up, b_down) = if x2 > 0.0 { (3, 2) } else { (2, 3) };
            for (k, room) in [(a_up, up), (b_up, up), (a_down, down), (b_down, down)] {
                ends[k] = ends[k].min(room / reach);
            }
        }
    }
    Ok([-ends[0], ends[1], -ends[2], ends[3]])
}

/// Checks that `data` can be fitted by `kind` at all (more points than parameters).
pub fn check_size(data: &FitData, kind: ModelKind) -> Result<()> {
    if data.len() <= kind.n_params() {
        return Err(Error::InvalidParameter {
            name: "number of data points",
            value: data.len() as f64,
            expected: "more points than the model has parameters",
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::fit::dataset::Observation;
    use crate::fit::lsq;
    use crate::models::viscoelastic::ContactEnd;

    #[test]
    fn powerlaw_exponent_ends_keep_every_point_in_range() {
        let (ln_a_lo, ln_a_hi) = (1e-9f64.ln(), 1e3f64.ln());
        // Ordinary data: the full [-10, 10] box.
        let x: Vec<[f64; 2]> = [(6.35, 0.5), (25.4, 40.0), (12.7, 3.0)]
            .iter()
            .map(|&(d, v): &(f64, f64)| [(d / 10.0).ln(), v.ln()])
            .collect();
        assert_eq!(
            powerlaw_exponent_ends(&x, ln_a_lo, ln_a_hi).unwrap(),
            [-10.0, 10.0, -10.0, 10.0]
        );
        // One speed of 1e-300 m/s among ordinary ones: b is held from below by that point's
        // overflow, ln(1e3) - b ln(1e-300) <= 300 (with its |x1| = ln 2.54), and from above by its
        // underflow, ln(1e-9) + b ln(1e-300) >= -700 (the centred logarithms reach less far:
        // the mean of x2 is about -172, so the point's centred x2 is about -519, and the
        // others' about +175 hold b_hi only to about 1.7).
        let mut x = x;
        x.push([2.54f64.ln(), 1e-300f64.ln()]);
        let ends = powerlaw_exponent_ends(&x, ln_a_lo, ln_a_hi).unwrap();
        let reach = 2.54f64.ln() + 300.0 * 10f64.ln();
        assert!(
            (ends[2] + (300.0 - ln_a_hi) / reach).abs() < 1e-15,
            "{ends:?}"
        );
        assert!(
            (ends[3] - (700.0 + ln_a_lo) / reach).abs() < 1e-15,
            "{ends:?}"
        );
        assert!(ends[3] > 0.95, "b up to about 0.96, not 0.42: {ends:?}");
        // Random data sets over 600 decades of speed and 20 of size: at every corner of the
        // box (and so everywhere in it: the exponent is linear in a and b) every point's
        // ln(1 - e), at both ends of ln A, and its centred exponent stay within the limits
        // (to rounding: 1e-12 relative).
        let mut z = 5u64;
        let mut next = || {
            z = z
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (z >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut narrowed = 0;
        for _ in 0..300 {
            let n = 1 + (next() * 6.0) as usize;
            let x: Vec<[f64; 2]> = (0..n)
                .map(|_| {
                    [
                        (next() - 0.5) * 46.0,
                        (next() - 0.5) * 1380.0 * next().powi(3),
                    ]
                })
                .collect();
            let e = powerlaw_exponent_ends(&x, ln_a_lo, ln_a_hi).unwrap();
            narrowed += usize::from(e != [-10.0, 10.0, -10.0, 10.0]);
            let mean = [0, 1].map(|k| x.iter().map(|p| p[k]).sum::<f64>() / n as f64);
            for p in &x {
                for (x1, x2) in [(p[0], p[1]), (p[0] - mean[0], p[1] - mean[1])] {
                    for a in [e[0], e[1]] {
                        for b in [e[2], e[3]] {
                            let t = -a * x1 + b * x2;
                            assert!(
                                ln_a_hi + t <= 300.0 * (1.0 + 1e-12)
                                    && ln_a_lo + t >= -700.0 * (1.0 + 1e-12),
                                "{x:?}: ends {e:?}, a {a} b {b}"
                            );
                        }
                    }
                }
            }
        }
        assert!(narrowed > 100, "most draws narrow the box: {narrowed}");
    }

    /// The power law's closed-form Jacobian against central differences, on data off the model
    /// (residuals of both signs), at interior points of the box, for every set of free
    /// parameters the fits use (all; one held, as in the profiles).
    #[test]
    fn powerlaw_exact_jacobian_matches_central_differences() {
        let m = Material::preset("nylon").unwrap();
        let mut obs = Vec::new();
        for (k, d) in [3.0, 6.35, 25.4, 50.0].into_iter().enumerate() {
            for s in 0..12 {
                let v = 0.2 * 1.4f64.powi(s);
                let e = 1.0 - 0.05 * (d / 10.0f64).powf(-0.4) * v.powf(0.45);
                obs.push(Observation {
                    d_mm: d,
                    d2_mm: None,
                    v_n_m_s: v,
                    e: e + 0.01 * ((s + k as i32) as f64).sin(),
                    e_err: Some(0.005 + 0.001 * s as f64),
                });
            }
        }
        let data = FitData::new(m, obs).unwrap();
        let ev = Evaluator::new(&data, ContactEnd::Overlap, VmMethod::Master);
        let obj = Objective::new(&ev, ModelKind::PowerLaw).unwrap();
        let frees = [
            [true, true, true],
            [false, true, true],
            [true, false, true],
            [true, true, false],
        ];
        for theta in [[0.05f64.ln(), 0.4, 0.45], [0.3f64.ln(), -1.5, 2.0]] {
            let mut f0 = vec![0.0; ev.len()];
            lsq::residuals_checked(&obj, &theta, &mut f0).unwrap();
            for free in frees {
                let exact = lsq::jacobian(&obj, &theta, &free, &f0).unwrap();
                let fd = lsq::jacobian_fd(&obj, &theta, &free, &f0).unwrap();
                assert_eq!(exact.shape(), fd.shape());
                for c in 0..exact.ncols() {
                    let scale = fd.column(c).amax();
                    let err = (exact.column(c) - fd.column(c)).amax() / scale;
                    // Central differences with h = 1e-5 err by h^2 |f'''| / 6 relative, which
                    // is 1.7e-11 |x|^3 with |x| = |ln(d/d_ref)|, |ln(v/v_ref)| <= 2.1 here
                    // (1.6e-10), plus rounding u |f| / h (measured: 2e-11 to 9e-11 in all);
                    // 1e-9 of the column's largest entry covers both, while a wrong sign,
                    // factor or column order errs by 1e-1 or more.
                    assert!(
                        err < 1e-9,
                        "theta {theta:?} free {free:?} column {c}: {err:e}"
                    );
                }
            }
        }
    }
}
