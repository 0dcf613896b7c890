//! The separable models' exact Jacobian (`vm`, `pm`, `min`, `product`) in the fit's internal
//! coordinates (ln eta, ln sigma_y).
//!
//! **Computes** df_i/dtheta_j for f_i = (e_i(model) - e_i)/sigma_i from the slopes of the two
//! factors ([`master::e_and_slope_master_in_place`], [`plastic::e_and_slope_ln_u_in_place`]):
//! kappa = eta kappa_1 gives d ln kappa/d ln eta = 1, u = v/(V_Y1 sigma_y^(5/2)) gives
//! d ln u/d ln sigma_y = -5/2. `product`: the product rule; `min`: the derivative of the smaller
//! factor (at an exact tie, the mean of the two one-sided derivatives, which is what central
//! differences across the kink give). One pass over the points, where central differences take
//! two evaluations per free parameter; the master curve only (the ODE has no slope: `--exact`
//! fits keep central differences).
//!
//! **Known answer**: the test below compares it with central differences for every model, both
//! contact rules and every set of free parameters.

use super::super::sums;
use super::{Evaluator, ModelKind};
use crate::error::{Error, Result};
use crate::models::plastic;
use crate::models::viscoelastic::VmMethod;
#[cfg(doc)]
use crate::models::viscoelastic::master;
use nalgebra::DMatrix;

impl Evaluator<'_> {
    /// Whether [`Evaluator::jacobian_separable`] serves `kind` with this evaluator's method.
    pub fn has_exact_jacobian(&self, kind: ModelKind) -> bool {
        match kind {
            ModelKind::Pm => true,
            ModelKind::Vm | ModelKind::Min | ModelKind::Product => self.method == VmMethod::Master,
            ModelKind::PowerLaw => false,
        }
    }

    /// The weighted residuals' Jacobian of a separable model at physical parameters `p`, for
    /// the parameters with `free[j]`, into the columns of `out` (n x number of free, in order).
    /// An error is the first failing point's, as [`Evaluator::predict`]'s.
    pub fn jacobian_separable(
        &self,
        kind: ModelKind,
        p: &[f64],
        inv_sigma: &[f64],
        free: &[bool],
        out: &mut DMatrix<f64>,
    ) -> Result<()> {
        self.jacobian_separable_with(kind, p, inv_sigma, free, out, None)
    }

    /// [`Evaluator::jacobian_separable`] and, with `residuals = Some((e_obs, f))`, in the same
    /// pass the weighted residuals f_i = (e_i(model) - e_obs_i) inv_sigma_i (the e of the slopes'
    /// recurrences are those of [`Evaluator::predict`] bit for bit, so f is too): the Jacobian
    /// at a trial point of Levenberg-Marquardt, which needs it there whenever it accepts the
    /// step, for a fraction more than the residuals alone. Residuals need a free parameter.
    pub fn jacobian_separable_with(
        &self,
        kind: ModelKind,
        p: &[f64],
        inv_sigma: &[f64],
        free: &[bool],
        out: &mut DMatrix<f64>,
        residuals: Option<(&[f64], &mut [f64])>,
    ) -> Result<()> {
        if !self.has_exact_jacobian(kind) {
            return Err(Error::InvalidParameter {
                name: "exact Jacobian requested for a model without one (model parameters)",
                value: p.len() as f64,
                expected: "vm, min or product with the master curve, or pm",
            });
        }
        let n = self.len();
        // The factor (0: e_vm, 1: e_pm) each free parameter moves.
        let axes: Vec<usize> = (0..kind.n_params())
            .filter(|&j| free[j])
            .map(|j| if kind == ModelKind::Pm { 1 } else { j })
            .collect();
        let (eta, s25) = match kind {
            ModelKind::Vm => (p[0], f64::NAN),
            ModelKind::Pm => (f64::NAN, p[0].powf(2.5)),
            _ => (p[0], p[1].powf(2.5)),
        };
        let data = out.as_mut_slice();
        let (c0, c1) = data.split_at_mut(if axes.len() == 2 { n } else { data.len() });
        let (e_obs, f_out) = match residuals {
            Some((e, f)) => (e, f),
            None => (&[][..], &mut [][..]),
        };
        // A factor whose parameter is held (a profile's) needs its values, not its slopes: the
        // same values without the slopes' work, and on large data the same at each iteration
        // of the profile's inner fit (kept by the evaluator, [`Evaluator::held_row`]).
        let slope = [axes.contains(&0), axes.contains(&1)];
        let held = match (kind, slope) {
            // One axis free: the other (1 where axis 0 is free) is held, at p[h].
            (ModelKind::Min | ModelKind::Product, [free0, free1])
                if free0 != free1 && sums::is_large(n) =>
            {
                let h = usize::from(free0);
                self.held_row(h, p[h]).map(|r| (h, r))
            }
            _ => None,
        };
        let held_rows = |axis: usize, at: std::ops::Range<usize>| match &held {
            Some((h, row)) if *h == axis => Some(&row[at]),
            _ => None,
        };
        let chunk = |start: usize, c0: &mut [f64], c1: &mut [f64], f: &mut [f64]| -> Result<()> {
            let m = c0.len();
            // An absent factor is 1 with slope 0 (its products below are exact), a slope not
            // computed 0; the others are written in full below.
            let init = [
                (kind == ModelKind::Pm).then_some(1.0),
                (!slope[0]).then_some(0.0),
                (kind == ModelKind::Vm).then_some(1.0),
                (!slope[1]).then_some(0.0),
            ];
            sums::with_scratch(m, init, |[ev, sv, ep, sp]| {
                if let Some(row) = held_rows(0, start..start + m) {
                    ev.copy_from_slice(row);
                } else if kind != ModelKind::Pm {
                    self.vm_in_kappa_order(start, eta, ev, slope[0].then_some(&mut sv[..]))?;
                }
                // e_pm and its slope in ln u (times d ln u/d ln sigma_y = -5/2 below) four
                // points at a time: the same doubles as point by point.
                if let Some(row) = held_rows(1, start..start + m) {
                    ep.copy_from_slice(row);
                } else if kind != ModelKind::Vm {
                    crate::cpu::fast(|| self.u_into(start, s25, ep));
                    if slope[1] {
                        plastic::e_and_slope_ln_u_in_place(ep, sp);
                    } else {
                        plastic::e_of_u_in_place(ep);
                    }
                }
                let factors = Factors {
                    ev,
                    sv,
                    ep,
                    sp,
                    w: &inv_sigma[start..start + m],
                    e_obs: e_obs.get(start..start + m).unwrap_or(&[]),
                };
                crate::cpu::fast(|| factors.columns(kind == ModelKind::Min, &axes, c0, c1, f));
                Ok(())
            })
        };
        if axes.is_empty() {
            if !f_out.is_empty() {
                return Err(Error::InvalidParameter {
                    name: "free parameters of a Jacobian with residuals",
                    value: 0.0,
                    expected: "at least one",
                });
            }
            return Ok(());
        }
        if !sums::is_large(n) {
            return chunk(0, c0, c1, f_out);
        }
        use rayon::prelude::*;
        let size = sums::CHUNK;
        // Empty slices (no second column, no residuals) pair with every chunk as empty pieces.
        fn pieces(v: &mut [f64], n: usize, size: usize) -> Vec<&mut [f64]> {
            if v.is_empty() {
                (0..n.div_ceil(size)).map(|_| &mut [][..]).collect()
            } else {
                v.chunks_mut(size).collect()
            }
        }
        let results: Vec<Result<()>> = c0
            .par_chunks_mut(size)
            .zip(pieces(c1, n, size))
            .zip(pieces(f_out, n, size))
            .enumerate()
            .map(|(c, ((a, b), f))| crate::cpu::fast(|| chunk(c * size, a, b, f)))
            .collect();
        results.into_iter().collect()
    }
}

/// One chunk's factors (e_vm, its slope in ln kappa, e_pm, its slope in ln u; an absent
/// factor 1 with slope 0), the points' weights 1/sigma and observed e (empty without
/// residuals).
struct Factors<'a> {
    ev: &'a [f64],
    sv: &'a [f64],
    ep: &'a [f64],
    sp: &'a [f64],
    w: &'a [f64],
    e_obs: &'a [f64],
}

impl Factors<'_> {
    /// The columns of the free axes (`axes`: 0 for e_vm's parameter, 1 for e_pm's) into `c0`
    /// and `c1`, and the weighted residuals into `f` unless it is empty. `product` (and `vm`,
    /// `pm`, whose absent factor is 1): the product rule; `min`: the smaller factor's
    /// derivative, at an exact tie the mean of the two. One loop instance per case, without a
    /// branch per point, so that it runs several points at once (inlined into a
    /// [`crate::cpu::fast`] caller).
    #[inline(always)]
    fn columns(&self, min: bool, axes: &[usize], c0: &mut [f64], c1: &mut [f64], f: &mut [f64]) {
        let two = axes.len() == 2;
        let second = axes[0] == 1;
        match (min, two, f.is_empty()) {
            (false, false, true) => self.columns_as::<false, false, false>(second, c0, c1, f),
            (false, false, false) => self.columns_as::<false, false, true>(second, c0, c1, f),
            (false, true, true) => self.columns_as::<false, true, false>(second, c0, c1, f),
            (false, true, false) => self.columns_as::<false, true, true>(second, c0, c1, f),
            (true, false, true) => self.columns_as::<true, false, false>(second, c0, c1, f),
            (true, false, false) => self.columns_as::<true, false, true>(second, c0, c1, f),
            (true, true, true) => self.columns_as::<true, true, false>(second, c0, c1, f),
            (true, true, false) => self.columns_as::<true, true, true>(second, c0, c1, f),
        }
    }

    #[inline(always)]
    fn columns_as<const MIN: bool, const TWO: bool, const RES: bool>(
        &self,
        second: bool,
        c0: &mut [f64],
        c1: &mut [f64],
        f: &mut [f64],
    ) {
        let m = c0.len();
        let (ev, sv, ep, sp, w) = (
            &self.ev[..m],
            &self.sv[..m],
            &self.ep[..m],
            &self.sp[..m],
            &self.w[..m],
        );
        let c1 = if TWO { &mut c1[..m] } else { &mut [][..] };
        let (f, e_obs) = if RES {
            (&mut f[..m], &self.e_obs[..m])
        } else {
            (&mut [][..], &[][..])
        };
        let sel = |c: bool, a: f64, b: f64| if c { a } else { b };
        for j in 0..m {
            let (a, sa, b, sb) = (ev[j], sv[j], ep[j], -2.5 * sp[j]);
            let d = if MIN {
                let (lt, gt) = (a < b, b < a);
                [
                    sel(lt, sa, sel(gt, 0.0, 0.5 * sa)),
                    sel(lt, 0.0, sel(gt, sb, 0.5 * sb)),
                ]
            } else {
                [b * sa, a * sb]
            };
            if TWO {
                c0[j] = d[0] * w[j];
                c1[j] = d[1] * w[j];
            } else {
                c0[j] = sel(second, d[1], d[0]) * w[j];
            }
            if RES {
                // As [`Evaluator::predict_then`] and the objective's residuals form it (with
                // an absent factor 1: x 1 is exact).
                let model = if MIN { a.min(b) } else { a * b };
                f[j] = (model - e_obs[j]) * w[j];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::dataset::{FitData, Observation};
    use super::super::super::lsq::{self, Residuals};
    use super::super::super::objective::Objective;
    use super::super::HELD_ROWS;
    use super::*;
    use crate::contact::Material;
    use crate::models::viscoelastic::ContactEnd;
    use std::sync::Arc;

    /// Exact against central differences (h = the objective's fd_step), on data off every model
    /// (residuals of both signs), a pair, unequal spheres and a wall, speeds on both sides of
    /// yield at the parameters tried, for every model, both contact rules and every set of free
    /// parameters the fits use (all; one held, as in the profiles).
    const SEPARABLE: [ModelKind; 4] = [
        ModelKind::Vm,
        ModelKind::Pm,
        ModelKind::Min,
        ModelKind::Product,
    ];

    /// The sets of free parameters the fits use: all, and (two parameters) each one held, as in
    /// the profiles.
    fn free_sets(k: usize) -> Vec<Vec<bool>> {
        if k == 1 {
            vec![vec![true]]
        } else {
            vec![vec![true, true], vec![false, true], vec![true, false]]
        }
    }

    /// The residuals and Jacobian of one pass (Levenberg-Marquardt's trial points) are those of
    /// the two separate computations to the last bit, on small data and on data large enough
    /// for the chunked parallel path (20 000 points, every speed distinct), for every separable
    /// model, both rules and every set of free parameters. With one parameter held on the
    /// large data, the pass's residuals come from the evaluator's held row
    /// ([`Evaluator::held_row`], made by the separate Jacobian just before): to the last bit
    /// those of the residuals computed afresh.
    #[test]
    fn residuals_with_the_jacobian_are_the_separate_ones_bit_for_bit() {
        let m = Material::preset("nylon").unwrap();
        for n in [48, 20_000] {
            let obs: Vec<Observation> = (0..n)
                .map(|i| Observation {
                    d_mm: [6.35, 25.4, 12.7][i % 3],
                    d2_mm: [None, Some(12.7), Some(f64::INFINITY)][i % 3],
                    v_n_m_s: 0.05 * 1.5f64.powf(16.0 * i as f64 / n as f64),
                    e: 0.9 - 0.3 * i as f64 / n as f64 + 0.01 * (i as f64).sin(),
                    e_err: Some(0.005 + 0.001 * (i % 7) as f64),
                })
                .collect();
            let data = FitData::new(m, obs).unwrap();
            for rule in ContactEnd::ALL {
                let ev = Evaluator::new(&data, rule, VmMethod::Master);
                for kind in SEPARABLE {
                    let obj = Objective::new(&ev, kind).unwrap();
                    let k = kind.n_params();
                    let theta: Vec<f64> = (0..k)
                        .map(|j| 0.4 * obj.lower[j] + 0.6 * obj.upper[j])
                        .collect();
                    let frees = free_sets(k);
                    let mut f0 = vec![0.0; n];
                    lsq::residuals_checked(&obj, &theta, &mut f0).unwrap();
                    for free in &frees {
                        let j0 = lsq::jacobian(&obj, &theta, free, &f0).unwrap();
                        let mut f1 = vec![f64::NAN; n];
                        let mut j1 = DMatrix::zeros(n, j0.ncols());
                        let done = obj.residuals_and_jacobian(&theta, &mut f1, free, &mut j1);
                        assert!(matches!(done, Some(Ok(()))), "{kind} {free:?}");
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&f0), bits(&f1), "{n} {rule:?} {kind} {free:?}");
                        assert_eq!(
                            bits(j0.as_slice()),
                            bits(j1.as_slice()),
                            "{n} {rule:?} {kind} {free:?}"
                        );
                    }
                    // Nothing free: nothing to gain, the problem declines.
                    let mut j = DMatrix::zeros(n, 0);
                    let none = vec![false; k];
                    assert!(
                        obj.residuals_and_jacobian(&theta, &mut f0, &none, &mut j)
                            .is_none()
                    );
                }
            }
        }
    }

    /// A held row is the evaluator's own row of that factor, the same row again when asked
    /// again, and made afresh once HELD_ROWS others were asked for since.
    #[test]
    fn held_rows_are_the_factors_rows_kept_for_the_last_asked() {
        let m = Material::preset("nylon").unwrap();
        let obs: Vec<Observation> = (0..300)
            .map(|i| Observation {
                d_mm: 6.35 + 0.01 * i as f64,
                d2_mm: None,
                v_n_m_s: 0.1 * 1.02f64.powi(i),
                e: 0.8,
                e_err: Some(0.01),
            })
            .collect();
        let data = FitData::new(m, obs).unwrap();
        let ev = Evaluator::new(&data, ContactEnd::Overlap, VmMethod::Master);
        let (eta, sigma) = (190.0, 4.0e7);
        let (mut vm, mut pm) = (vec![0.0; 300], vec![0.0; 300]);
        ev.e_vm_row(eta, &mut vm);
        ev.e_pm_row(sigma, &mut pm);
        let a = ev.held_row(0, eta).unwrap();
        assert_eq!(*a, vm);
        assert_eq!(*ev.held_row(1, sigma).unwrap(), pm);
        assert!(Arc::ptr_eq(&a, &ev.held_row(0, eta).unwrap()));
        for k in 0..HELD_ROWS {
            ev.held_row(1, sigma * (1.0 + 0.01 * (k + 1) as f64))
                .unwrap();
        }
        let again = ev.held_row(0, eta).unwrap();
        assert!(!Arc::ptr_eq(&a, &again));
        assert_eq!(*again, vm);
    }

    #[test]
    fn separable_exact_jacobian_matches_central_differences() {
        let m = Material::preset("nylon").unwrap();
        let mut obs = Vec::new();
        for (k, (d, d2)) in [
            (6.35, None),
            (25.4, Some(12.7)),
            (12.7, Some(f64::INFINITY)),
        ]
        .into_iter()
        .enumerate()
        {
            for s in 0..16 {
                let v = 0.05 * 1.5f64.powi(s);
                obs.push(Observation {
                    d_mm: d,
                    d2_mm: d2,
                    v_n_m_s: v,
                    e: 0.9 - 0.02 * s as f64 + 0.01 * ((s as usize + k) as f64).sin(),
                    e_err: Some(0.005 + 0.001 * s as f64),
                });
            }
        }
        let data = FitData::new(m, obs).unwrap();
        let mut checked = 0;
        for rule in ContactEnd::ALL {
            let ev = Evaluator::new(&data, rule, VmMethod::Master);
            for kind in SEPARABLE {
                let obj = Objective::new(&ev, kind).unwrap();
                let k = kind.n_params();
                let mid: Vec<f64> = (0..k)
                    .map(|j| 0.5 * (obj.lower[j] + obj.upper[j]))
                    .collect();
                let near_lo: Vec<f64> = (0..k)
                    .map(|j| 0.8 * obj.lower[j] + 0.2 * obj.upper[j])
                    .collect();
                let frees = free_sets(k);
                for theta in [mid, near_lo] {
                    let mut f0 = vec![0.0; ev.len()];
                    lsq::residuals_checked(&obj, &theta, &mut f0).unwrap();
                    let p = kind.to_physical(&theta);
                    for free in &frees {
                        let exact = lsq::jacobian(&obj, &theta, free, &f0).unwrap();
                        let fd = lsq::jacobian_fd(&obj, &theta, free, &f0).unwrap();
                        assert_eq!(exact.shape(), fd.shape());
                        for c in 0..exact.ncols() {
                            let scale = fd.column(c).amax().max(1e-300);
                            for i in 0..ev.len() {
                                let diff = (exact[(i, c)] - fd[(i, c)]).abs();
                                // Central differences err by h^2 |f'''|/6 (h = fd_step = 1e-5:
                                // about 1e-11 of the column's scale) plus the rounding of the
                                // difference of two values of f_i = (e - e_i) w_i, at most
                                // 2 e_accuracy w_i/(2h) (e near 1 keeps only 1e-16 of 1 - e:
                                // at small kappa this term is the larger, some 1e-6 relative).
                                // Allowed: 1e-7 of the column's largest entry plus that
                                // rounding term; a wrong factor (5/2, a product-rule term)
                                // errs by 1e-1 of the entry or more. `min` at a point within h
                                // of its kink differs by half the jump there: such points (the
                                // two factors within 1e-4) are skipped.
                                let tol =
                                    1e-7 * scale + obj.e_accuracy * obj.inv_sigma[i] / obj.fd_step;
                                let err = diff / scale;
                                let near_kink = kind == ModelKind::Min && {
                                    let a = ev.e_vm(i, p[0]).unwrap();
                                    (a - ev.e_pm(i, p[1])).abs() < 1e-4
                                };
                                assert!(
                                    near_kink || diff <= tol,
                                    "{rule:?} {kind} theta {theta:?} free {free:?} point {i} \
                                     column {c}: {} vs {} ({err:e})",
                                    exact[(i, c)],
                                    fd[(i, c)]
                                );
                                checked += usize::from(!near_kink);
                            }
                        }
                    }
                }
            }
        }
        assert!(checked > 1000, "{checked}");
    }
}
