//! chi2 of each model on a grid, and lower bounds of chi2 over grid cells, for the branch and
//! bound of the global search ([`super::bnb`], argued in [`super::search`]).
//!
//! **Separable models** (`vm`, `pm`, `min`, `product`): e_i = c(F_i(log eta), G_i(log sigma_y))
//! with F_i = e_vm (non-increasing in eta: kappa grows with eta and e_vm falls with kappa),
//! G_i = e_pm (non-decreasing in sigma_y: V_Y grows with it), and c = min or product, both
//! non-decreasing in each argument on [0, 1]; `vm` and `pm` are the product with a constant 1.
//! So over a cell [eta0, eta1] x [s0, s1] each e_i lies in
//! [c(F_i(eta1), G_i(s0)), c(F_i(eta0), G_i(s1))], known from the cell's corner rows, and
//! chi2 >= sum_i w_i dist(e_i, that range)^2. Each range is widened by twice the accuracy of one
//! evaluation ([`super::objective::model_accuracy`]), so the bound holds for the computed model.
//! A grid row (e_vm at one eta, or e_pm at one sigma_y, for every point) is tabulated once; a
//! node costs one min or product per point.
//!
//! **Power law** 1 - e = A (d/d_ref)^(-a) (v/v_ref)^b: for fixed (a, b) it is linear in A, so
//! chi2 is a convex quadratic in A and its minimum over the box of A is the clamped
//! least-squares solution: the search runs over (a, b) with A profiled out exactly. With
//! z_i = exp(-a x1_i + b x2_i) (x1 = ln(d/d_ref), x2 = ln(v/v_ref), centred to keep the bound
//! tight) each z_i ranges over [zlo_i, zhi_i] on a cell (the exponent is linear in a and b), and
//! for every A, chi2 >= f(A) = sum_i w_i dist(y_i, [A zlo_i, A zhi_i])^2 with y_i = 1 - e_i. f is
//! convex in A (a sum of squares of positive parts of affine functions), so two points A1 < A2
//! with f'(A1) <= 0 <= f'(A2) give a valid lower bound of its minimum: the crossing of the
//! tangents there.

use super::bnb::{Bound, Landscape};
use super::models::{POWERLAW_D_REF_MM, POWERLAW_V_REF_M_S, powerlaw_d_mm};
use super::objective::Objective;

/// The separable models' landscape: rows of e_vm (axis 0) and e_pm (axis 1).
pub struct Separable<'a> {
    obj: &'a Objective<'a>,
    min_rule: bool,
    active: [bool; 2],
    n: usize,
    rows: [Vec<f64>; 2],
    e: Vec<f64>,
    w: Vec<f64>,
    slack: f64,
}

impl<'a> Separable<'a> {
    /// `active[k]`: whether axis k (eta, sigma_y) is a parameter; an inactive axis is a row of 1.
    pub fn new(obj: &'a Objective<'a>, min_rule: bool, active: [bool; 2]) -> Self {
        let n = obj.ev.len();
        Separable {
            obj,
            min_rule,
            active,
            n,
            rows: [Vec::new(), Vec::new()],
            e: obj.ev.data.obs.iter().map(|o| o.e).collect(),
            w: obj.inv_sigma.iter().map(|s| s * s).collect(),
            slack: 2.0 * obj.e_accuracy,
        }
    }

    fn row(&self, k: usize, r: usize) -> &[f64] {
        &self.rows[k][r * self.n..(r + 1) * self.n]
    }

    fn bound_with(&self, c: impl Fn(f64, f64) -> f64, lo: [usize; 2], hi: [usize; 2]) -> Bound {
        let (f0, f1) = (self.row(0, lo[0]), self.row(0, hi[0]));
        let (g0, g1) = (self.row(1, lo[1]), self.row(1, hi[1]));
        let (mut lb, mut l0, mut l1) = (0.0, 0.0, 0.0);
        for i in 0..self.n {
            // F falls along axis 0, G rises along axis 1: the extremes are opposite corners.
            let top = c(f0[i], g1[i]);
            let bottom = c(f1[i], g0[i]) - self.slack;
            let e = self.e[i];
            let d = if e < bottom {
                bottom - e
            } else if e > top + self.slack {
                e - top - self.slack
            } else {
                0.0
            };
            let w = self.w[i];
            lb += w * d * d;
            let r = (top - e).abs();
            let d0 = top - c(f1[i], g1[i]);
            let d1 = top - c(f0[i], g0[i]);
            l0 += w * d0 * (r + d0);
            l1 += w * d1 * (r + d1);
        }
        Bound {
            lb,
            loose: [l0, l1],
        }
    }
}

impl Landscape for Separable<'_> {
    fn add_row(&mut self, axis: usize, t: f64) -> Result<(), String> {
        let (n, ev) = (self.n, self.obj.ev);
        let mut failure = None;
        let start = self.rows[axis].len();
        self.rows[axis].resize(start + n, 1.0);
        if self.active[axis] {
            self.obj.evals.set(self.obj.evals.get() + 1);
            let x = t.exp();
            if axis == 1 {
                ev.e_pm_row(x, &mut self.rows[1][start..start + n]);
            }
            for i in 0..n {
                let v = if axis == 0 {
                    match ev.e_vm(i, x) {
                        Ok(v) => v,
                        Err(e) => {
                            failure.get_or_insert(format!("e_vm at eta = {x}: {e}"));
                            f64::NAN
                        }
                    }
                } else {
                    self.rows[1][start + i]
                };
                if v.is_nan() && failure.is_none() {
                    failure = Some(format!(
                        "the model is NaN at {} = {x} for {}",
                        if axis == 0 { "eta" } else { "sigma_y" },
                        self.obj.describe_point(i)
                    ));
                }
                self.rows[axis][start + i] = v;
            }
        }
        failure.map_or(Ok(()), Err)
    }

    fn node(&self, r: [usize; 2]) -> f64 {
        let (f, g) = (self.row(0, r[0]), self.row(1, r[1]));
        let mut s = 0.0;
        if self.min_rule {
            for i in 0..self.n {
                let d = f[i].min(g[i]) - self.e[i];
                s += self.w[i] * d * d;
            }
        } else {
            for i in 0..self.n {
                let d = f[i] * g[i] - self.e[i];
                s += self.w[i] * d * d;
            }
        }
        s
    }

    fn bound(&self, lo: [usize; 2], hi: [usize; 2], _target: f64) -> Bound {
        if self.min_rule {
            self.bound_with(f64::min, lo, hi)
        } else {
            self.bound_with(|a, b| a * b, lo, hi)
        }
    }
}

/// Relative widening of the z ranges of the power law: a few rounding errors of exp and a
/// product (1e-12 is 4500 ulp).
const Z_SLACK: f64 = 1e-12;
/// Newton or bisection steps per cell bound of the power law (each one pass over the points).
const POWERLAW_BOUND_ITERS: usize = 30;

/// The power law's landscape over (a, b), A profiled out.
pub struct PowerLaw {
    n: usize,
    y: Vec<f64>,
    w: Vec<f64>,
    /// w / max(w), for sums that must not overflow.
    w_scaled: Vec<f64>,
    /// Centred -ln(d/d_ref) and ln(v/v_ref), and the centres.
    c1: Vec<f64>,
    c2: Vec<f64>,
    m1: f64,
    m2: f64,
    a_range: (f64, f64),
    /// Rows exp(-a c1_i) (axis 0) and exp(b c2_i) (axis 1), with their t.
    rows: [Vec<f64>; 2],
    t: [Vec<f64>; 2],
    /// Sensitivity of chi2 to a and b: sqrt(sum w (c y)^2), with c the centred logarithm.
    sens: [f64; 2],
    /// How close to its minimum a cell bound is computed (efficiency only: any stop is valid).
    pub bound_tol: f64,
}

impl PowerLaw {
    pub fn new(obj: &Objective) -> Self {
        let data = obj.ev.data;
        let n = data.len();
        let x1: Vec<f64> = data
            .contacts
            .iter()
            .map(|c| (powerlaw_d_mm(c) / POWERLAW_D_REF_MM).ln())
            .collect();
        let x2: Vec<f64> = data
            .obs
            .iter()
            .map(|o| (o.v_n_m_s / POWERLAW_V_REF_M_S).ln())
            .collect();
        let m1 = x1.iter().sum::<f64>() / n as f64;
        let m2 = x2.iter().sum::<f64>() / n as f64;
        let w: Vec<f64> = obj.inv_sigma.iter().map(|s| s * s).collect();
        let wmax = w.iter().cloned().fold(0.0, f64::max);
        PowerLaw {
            n,
            y: data.obs.iter().map(|o| 1.0 - o.e).collect(),
            w_scaled: w.iter().map(|x| x / wmax).collect(),
            sens: [
                (0..n)
                    .map(|i| w[i] * ((x1[i] - m1) * (1.0 - data.obs[i].e)).powi(2))
                    .sum::<f64>()
                    .sqrt(),
                (0..n)
                    .map(|i| w[i] * ((x2[i] - m2) * (1.0 - data.obs[i].e)).powi(2))
                    .sum::<f64>()
                    .sqrt(),
            ],
            w,
            c1: x1.iter().map(|x| x - m1).collect(),
            c2: x2.iter().map(|x| x - m2).collect(),
            m1,
            m2,
            a_range: (obj.lower[0].exp(), obj.upper[0].exp()),
            rows: [Vec::new(), Vec::new()],
            t: [Vec::new(), Vec::new()],
            bound_tol: 0.0,
        }
    }

    fn row(&self, k: usize, r: usize) -> &[f64] {
        &self.rows[k][r * self.n..(r + 1) * self.n]
    }

    /// ln of the factor between A and the centred amplitude: A_c = A exp(-a m1 + b m2).
    fn shift(&self, a: f64, b: f64) -> f64 {
        -a * self.m1 + b * self.m2
    }

    /// The exact minimum over A (in its box) at the node: (ln A, chi2).
    pub fn profile(&self, r: [usize; 2]) -> (f64, f64) {
        let (za, zb) = (self.row(0, r[0]), self.row(1, r[1]));
        let (a, b) = (self.t[0][r[0]], self.t[1][r[1]]);
        // Least squares in A_c with z and w scaled by their maxima (no overflow in the sums).
        let zmax = (0..self.n).map(|i| za[i] * zb[i]).fold(0.0, f64::max);
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..self.n {
            let z = za[i] * zb[i] / zmax;
            let w = self.w_scaled[i];
            num += w * z * self.y[i];
            den += w * z * z;
        }
        let s = self.shift(a, b);
        let (lo, hi) = (self.a_range.0 * s.exp(), self.a_range.1 * s.exp());
        let ac = num / den / zmax;
        let ac = if ac.is_nan() || ac < lo {
            lo
        } else if ac > hi {
            hi
        } else {
            ac
        };
        let mut chi2 = 0.0;
        for i in 0..self.n {
            let d = ac * za[i] * zb[i] - self.y[i];
            chi2 += self.w[i] * d * d;
        }
        (ac.ln() - s, chi2)
    }

    /// f(A), f'(A) and f''(A) (from the right) of the module doc. Branch-free (selects), so it
    /// vectorises; every input is finite (rows are checked when they are made).
    fn f_slope_curv(&self, zlo: &[f64], zhi: &[f64], a: f64) -> (f64, f64, f64) {
        let (mut f, mut d, mut h) = (0.0, 0.0, 0.0);
        for i in 0..self.n {
            let w = self.w[i];
            let u = a * zlo[i] - self.y[i];
            let v = self.y[i] - a * zhi[i];
            // At most one of u, v is positive (zlo <= zhi).
            let pu = if u > 0.0 { u } else { 0.0 };
            let pv = if v > 0.0 { v } else { 0.0 };
            let cu = if u > 0.0 { zlo[i] } else { 0.0 };
            let cv = if v > 0.0 { zhi[i] } else { 0.0 };
            f += w * (pu * pu + pv * pv);
            d += 2.0 * w * (zlo[i] * pu - zhi[i] * pv);
            h += 2.0 * w * (cu * cu + cv * cv);
        }
        (f, d, h)
    }
}

impl Landscape for PowerLaw {
    fn add_row(&mut self, axis: usize, t: f64) -> Result<(), String> {
        let c = if axis == 0 { &self.c1 } else { &self.c2 };
        let sign = if axis == 0 { -1.0 } else { 1.0 };
        let row: Vec<f64> = c.iter().map(|x| (sign * t * x).exp()).collect();
        let bad = row.iter().any(|z| !z.is_finite());
        self.rows[axis].extend(row);
        self.t[axis].push(t);
        if bad {
            return Err(format!(
                "the power law overflows at {} = {t}",
                if axis == 0 { "a" } else { "b" }
            ));
        }
        Ok(())
    }

    fn node(&self, r: [usize; 2]) -> f64 {
        self.profile(r).1
    }

    fn bound(&self, lo: [usize; 2], hi: [usize; 2], target: f64) -> Bound {
        let (za0, za1) = (self.row(0, lo[0]), self.row(0, hi[0]));
        let (zb0, zb1) = (self.row(1, lo[1]), self.row(1, hi[1]));
        let mut zlo = Vec::with_capacity(self.n);
        let mut zhi = Vec::with_capacity(self.n);
        for i in 0..self.n {
            zlo.push(za0[i].min(za1[i]) * zb0[i].min(zb1[i]) * (1.0 - Z_SLACK));
            zhi.push(za0[i].max(za1[i]) * zb0[i].max(zb1[i]) * (1.0 + Z_SLACK));
        }
        // The box of the centred amplitude over the cell: the shift is linear in a and b.
        let (a0, a1) = (self.t[0][lo[0]], self.t[0][hi[0]]);
        let (b0, b1) = (self.t[1][lo[1]], self.t[1][hi[1]]);
        let shifts = [
            self.shift(a0, b0),
            self.shift(a1, b0),
            self.shift(a0, b1),
            self.shift(a1, b1),
        ];
        let smin = shifts.iter().cloned().fold(f64::INFINITY, f64::min);
        let smax = shifts.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let (mut x1, mut x2) = (self.a_range.0 * smin.exp(), self.a_range.1 * smax.exp());
        // How much each axis loosens the bound: its width times the model's sensitivity to it.
        let wa = (a1 - a0) * self.sens[0];
        let wb = (b1 - b0) * self.sens[1];
        let loose = |_: f64| [wa * wa, wb * wb];
        let (mut f1, mut d1, _) = self.f_slope_curv(&zlo, &zhi, x1);
        if d1 >= 0.0 {
            return Bound {
                lb: f1,
                loose: loose(x1),
            };
        }
        let (mut f2, mut d2, _) = self.f_slope_curv(&zlo, &zhi, x2);
        if d2 <= 0.0 {
            return Bound {
                lb: f2,
                loose: loose(x2),
            };
        }
        // f'(x1) < 0 < f'(x2): the tangents' crossing is a lower bound. Newton steps on the
        // piecewise linear f' (exact on each piece) move the bracket in; bisection (geometric, A
        // spans decades) when a step leaves it. Start from the least-squares A at the middle z.
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..self.n {
            let z = 0.5 * (zlo[i] + zhi[i]);
            num += self.w[i] * z * self.y[i];
            den += self.w[i] * z * z;
        }
        let mut x = num / den;
        let mut lb = f64::NEG_INFINITY;
        for _ in 0..POWERLAW_BOUND_ITERS {
            if !(x > x1 && x < x2) {
                x = if x1 > 0.0 {
                    (x1 * x2).sqrt()
                } else {
                    0.5 * (x1 + x2)
                };
            }
            let (f, d, h) = self.f_slope_curv(&zlo, &zhi, x);
            if d == 0.0 || f == 0.0 {
                lb = f;
                break;
            }
            if d < 0.0 {
                (x1, f1, d1) = (x, f, d);
            } else {
                (x2, f2, d2) = (x, f, d);
            }
            let xc = (f2 - f1 + d1 * x1 - d2 * x2) / (d1 - d2);
            lb = f1 + d1 * (xc - x1);
            // Decided: the cell is excluded (lb above the target), or it holds a point below
            // the target (so it will be split whatever the bound), or the bound is tight.
            if lb >= target || f1.min(f2) < target || f1.min(f2) - lb <= self.bound_tol {
                break;
            }
            x -= d / h;
        }
        // chi2 >= 0 always; a NaN bound (overflow) is passed on for the search to report.
        Bound {
            lb: if lb < 0.0 { 0.0 } else { lb },
            loose: loose(0.5 * (x1 + x2)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::fit::dataset::{FitData, Observation};
    use crate::fit::lsq;
    use crate::fit::models::{Evaluator, ModelKind};
    use crate::models::viscoelastic::{ContactEnd, VmMethod, master::KAPPA_MAX, restitution};

    /// Noisy-looking data (a fixed pattern, no model behind it) on three sizes and a wall.
    fn data() -> FitData {
        let m = Material::preset("nylon").unwrap();
        let obs = (0..40)
            .map(|k| Observation {
                d_mm: [6.35, 12.7, 25.4, 12.7][k % 4],
                d2_mm: if k % 4 == 3 {
                    Some(f64::INFINITY)
                } else {
                    None
                },
                v_n_m_s: 0.4 * 1.12f64.powi(k as i32),
                e: 0.97 - 0.006 * k as f64 + 0.02 * ((k * 7 % 5) as f64 - 2.0) / 2.0,
                e_err: Some(0.01 + 0.001 * (k % 3) as f64),
            })
            .collect();
        FitData::new(m, obs).unwrap()
    }

    #[test]
    fn the_monotonicity_the_bounds_rest_on_holds() {
        // e_vm non-increasing in kappa over the master curve's range and e_pm non-decreasing in
        // sigma_y, each to twice the accuracy allowed for (5e-14): 20000 log-spaced points.
        for rule in [ContactEnd::Overlap, ContactEnd::Force] {
            let mut last = f64::INFINITY;
            for k in 0..20000 {
                let kappa = 1e-10 * (KAPPA_MAX / 1e-10).powf(k as f64 / 19999.0);
                let e = restitution(kappa, rule, &VmMethod::Master).unwrap().e;
                assert!(e <= last + 1e-13, "{rule:?} kappa {kappa}: {e} > {last}");
                last = e;
            }
        }
        let mut last = f64::NEG_INFINITY;
        for k in 0..20000 {
            let u = 1e6f64.powf(1.0 - k as f64 / 19999.0);
            let e = crate::models::plastic::rebound_u(u).e;
            assert!(e >= last - 1e-13, "u {u}: {e} < {last}");
            last = e;
        }
    }

    /// Every bound must lie below chi2 at every point of its cell: checked on a 9 x 9 sample of
    /// each of a set of cells, chi2 computed directly from the model (not from the rows).
    fn check_bounds(kind: ModelKind, cells: &[([f64; 2], [f64; 2])]) {
        let d = data();
        let ev = Evaluator::new(&d, ContactEnd::Overlap, VmMethod::Master);
        let obj = Objective::new(&ev, kind).unwrap();
        for &(lo, hi) in cells {
            let direct = |t: [f64; 2]| -> f64 {
                let theta = match kind {
                    ModelKind::Vm => vec![t[0]],
                    ModelKind::Pm => vec![t[1]],
                    ModelKind::Min | ModelKind::Product => vec![t[0], t[1]],
                    ModelKind::PowerLaw => {
                        vec![
                            super::super::powerlaw::ProfiledPowerLaw::new(&obj).ln_a(&t),
                            t[0],
                            t[1],
                        ]
                    }
                };
                lsq::chi2(&obj, &theta).unwrap()
            };
            let bound = if kind == ModelKind::PowerLaw {
                let mut l = PowerLaw::new(&obj);
                for k in 0..2 {
                    l.add_row(k, lo[k]).unwrap();
                    l.add_row(k, hi[k]).unwrap();
                }
                l.bound([0, 0], [1, 1], f64::NEG_INFINITY).lb
            } else {
                let active = [kind != ModelKind::Pm, kind != ModelKind::Vm];
                let mut l = Separable::new(&obj, kind == ModelKind::Min, active);
                for k in 0..2 {
                    l.add_row(k, lo[k]).unwrap();
                    l.add_row(k, hi[k]).unwrap();
                }
                l.bound([0, 0], [1, 1], f64::NEG_INFINITY).lb
            };
            let mut lowest = f64::INFINITY;
            for i in 0..9 {
                for j in 0..9 {
                    let t = [
                        lo[0] + (hi[0] - lo[0]) * i as f64 / 8.0,
                        lo[1] + (hi[1] - lo[1]) * j as f64 / 8.0,
                    ];
                    lowest = lowest.min(direct(t));
                }
            }
            // The power law's A is minimised inside the bound: compare with its profile.
            assert!(
                bound <= lowest * (1.0 + 1e-12),
                "{kind} {lo:?} {hi:?}: {bound} > {lowest}"
            );
            assert!(bound >= 0.0 && bound.is_finite());
        }
    }

    #[test]
    fn bounds_are_below_chi2_everywhere_in_their_cells() {
        let e = 190f64.ln();
        let s = 4e7f64.ln();
        let cells = [
            ([e - 0.5, s - 0.3], [e + 0.5, s + 0.3]),
            ([e - 0.01, s - 0.01], [e + 0.02, s + 0.005]),
            ([e + 2.0, s - 2.0], [e + 4.0, s - 1.0]),
        ];
        for kind in [
            ModelKind::Vm,
            ModelKind::Pm,
            ModelKind::Min,
            ModelKind::Product,
        ] {
            check_bounds(kind, &cells);
        }
        check_bounds(
            ModelKind::PowerLaw,
            &[
                ([0.3, 0.1], [0.7, 0.5]),
                ([-3.0, 2.0], [1.0, 4.0]),
                ([0.49, 0.29], [0.51, 0.31]),
            ],
        );
    }
}
