//! The power law's landscape over its exponents (a, b) with A profiled out; the argument for its
//! bound is in the parent module's documentation, its tests beside the separable models' there.

use super::super::bnb::{Bound, Landscape};
use super::super::models::Evaluator;
use super::super::objective::{Objective, chi2_rounding};
use super::super::{sums, vexp};
use lanes::{load, store};
use rayon::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Arc;
use wide::{CmpGt, f64x4};

mod first_order;
mod lanes;
mod linearized;

/// Relative widening of the z ranges of the power law: a few rounding errors of exp and a
/// product (1e-12 is 4500 ulp).
const Z_SLACK: f64 = 1e-12;
/// Newton or bisection steps per cell bound of the power law (each one pass over the points).
const POWERLAW_BOUND_ITERS: usize = 30;
/// On cells where every point's exponent varies by at most NARROW_M (max_i M_i, see
/// [`linearized`]) the linearised bound is tried first, then the first-order one if that did
/// not decide; on cells up to WIDE_M the other way round; wider cells use the first-order bound
/// alone (the linearised one's remainder, about M^2 / 2, is then wider than the first-order
/// range).
const NARROW_M: f64 = 1.0;
const WIDE_M: f64 = 4.0;

/// The power law's landscape over (a, b), A profiled out.
pub struct PowerLaw<'a> {
    /// The evaluator whose memo keeps the rows ([`Evaluator::memo_row`]).
    ev: &'a Evaluator<'a>,
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
    /// Rows exp(-a c1_i) (axis 0) and exp(b c2_i) (axis 1), with their t (each row its own
    /// allocation: one growing array was copied, and faulted in again, as it grew), shared
    /// through the evaluator with every landscape of the same fit's power law (a slice of a
    /// profile starts on the search's cells: 19 rows each on 100 000 points, the same each time).
    rows: [Vec<Arc<Vec<f64>>>; 2],
    /// Each row's largest value (the scale of [`PowerLaw::profile`]'s sums).
    row_max: [Vec<f64>; 2],
    t: [Vec<f64>; 2],
    /// Sensitivity of chi2 to a and b: sqrt(sum w (c y)^2), with c the centred logarithm.
    sens: [f64; 2],
    /// How close to its minimum a cell bound is computed (efficiency only: any stop is valid).
    pub bound_tol: f64,
    /// max_i |c1_i| and max_i |c2_i|.
    c_max: [f64; 2],
    /// The z ranges (zlo, zhi), centre values zc and remainders zc R of the last cell bound
    /// (see [`linearized`]), kept so that each bound does not allocate (and, for large data,
    /// fault in) fresh arrays of the points.
    scratch: RefCell<[Vec<f64>; 4]>,
    /// The centred amplitude minimising chi2 at each node evaluated (a start for the cells'
    /// bounds).
    amplitudes: RefCell<HashMap<[usize; 2], f64>>,
    /// sum_i w_i y_i^2.
    wy2: f64,
    /// sum_i w_i and the model's accuracy: the rounding allowance of the first-order bound.
    w_sum: f64,
    e_accuracy: f64,
}

impl<'a> PowerLaw<'a> {
    pub fn new(obj: &Objective<'a>) -> Self {
        let data = obj.ev.data;
        let n = data.len();
        // The evaluator's logs (computed once per fit; a landscape is made per search, slice
        // and end).
        let (x1, x2) = obj.ev.powerlaw_logs();
        let m1 = x1.iter().sum::<f64>() / n as f64;
        let m2 = x2.iter().sum::<f64>() / n as f64;
        let w: Vec<f64> = obj.inv_sigma.iter().map(|s| s * s).collect();
        let wy2 = (0..n).map(|i| w[i] * (1.0 - data.obs[i].e).powi(2)).sum();
        let wmax = w.iter().cloned().fold(0.0, f64::max);
        PowerLaw {
            ev: obj.ev,
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
            c_max: [
                x1.iter().map(|x| (x - m1).abs()).fold(0.0, f64::max),
                x2.iter().map(|x| (x - m2).abs()).fold(0.0, f64::max),
            ],
            c1: x1.iter().map(|x| x - m1).collect(),
            c2: x2.iter().map(|x| x - m2).collect(),
            m1,
            m2,
            a_range: (obj.lower[0].exp(), obj.upper[0].exp()),
            rows: [Vec::new(), Vec::new()],
            row_max: [Vec::new(), Vec::new()],
            t: [Vec::new(), Vec::new()],
            bound_tol: 0.0,
            scratch: RefCell::new([vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]]),
            amplitudes: RefCell::new(HashMap::new()),
            wy2,
            w_sum: obj.inv_sigma.iter().map(|s| s * s).sum(),
            e_accuracy: obj.e_accuracy,
        }
    }

    fn row(&self, k: usize, r: usize) -> &[f64] {
        &self.rows[k][r]
    }

    /// Holds A at exp(ln_a): its range the one value, so that the nodes are chi2 at that A and
    /// the cell bounds (which minimise over A's range) bound chi2 over the exponents with A
    /// held (the profile of A: [`crate::fit::slice`]).
    pub fn hold_amplitude(&mut self, ln_a: f64) {
        self.amplitude_range(ln_a, ln_a);
    }

    /// A's range cut to exp(ln_lo) ..= exp(ln_hi): the nodes and cell bounds minimise over it
    /// (the part of the region beyond an end of A's interval: [`crate::fit::beyond`]).
    pub fn amplitude_range(&mut self, ln_lo: f64, ln_hi: f64) {
        self.a_range = (ln_lo.exp(), ln_hi.exp());
    }

    /// ln of the factor between A and the centred amplitude: A_c = A exp(-a m1 + b m2).
    fn shift(&self, a: f64, b: f64) -> f64 {
        -a * self.m1 + b * self.m2
    }

    /// The exact minimum over A (in its range) at the node: (ln A, chi2). Two passes over the
    /// points (one with A held), each summed in four lanes (the k-th point of a chunk in lane
    /// k mod 4, the lanes added as (l0 + l1) + (l2 + l3); no padding).
    pub fn profile(&self, r: [usize; 2]) -> (f64, f64) {
        let (za, zb) = (self.row(0, r[0]), self.row(1, r[1]));
        let (a, b) = (self.t[0][r[0]], self.t[1][r[1]]);
        let s = self.shift(a, b);
        let (lo, hi) = (self.a_range.0 * s.exp(), self.a_range.1 * s.exp());
        let ac = if lo == hi {
            // A held ([`PowerLaw::hold_amplitude`]): nothing to minimise.
            lo
        } else {
            self.least_squares_amplitude(r, (lo, hi))
        };
        let (w, y) = (&self.w[..], &self.y[..]);
        let [chi2] = sums::sum(self.n, |points| {
            let mut chi2 = [0.0; 4];
            lanes::each(points, |l, i| {
                let d = ac * za[i] * zb[i] - y[i];
                chi2[l] += w[i] * d * d;
            });
            [lanes::total_of(chi2)]
        });
        (ac.ln() - s, chi2)
    }

    /// The centred amplitude minimising chi2 at the node `r`, kept in [lo, hi] (chi2 is a
    /// convex quadratic in it, so that is the minimum over the range).
    fn least_squares_amplitude(&self, r: [usize; 2], (lo, hi): (f64, f64)) -> f64 {
        // Least squares in A_c with each row scaled by its largest value and w by its own: no
        // overflow in the sums (a scaled z is at most 1, to rounding). A row's largest value is
        // at least 1, to rounding (the logarithms are centred, so some point's exponent is not
        // negative) and finite (a row that overflows failed when it was made): the scales are
        // finite and at most 1.
        let (za, zb) = (self.row(0, r[0]), self.row(1, r[1]));
        let (sa, sb) = (1.0 / self.row_max[0][r[0]], 1.0 / self.row_max[1][r[1]]);
        let (y, ws) = (&self.y[..], &self.w_scaled[..]);
        let [num, den] = sums::sum(self.n, |points| {
            let (mut num, mut den) = ([0.0; 4], [0.0; 4]);
            lanes::each(points, |l, i| {
                let z = (za[i] * sa) * (zb[i] * sb);
                let wz = ws[i] * z;
                num[l] += wz * y[i];
                den[l] += wz * z;
            });
            [lanes::total_of(num), lanes::total_of(den)]
        });
        let ac = num / den * sa * sb;
        if ac.is_nan() || ac < lo {
            lo
        } else if ac > hi {
            hi
        } else {
            ac
        }
    }
}

impl Landscape for PowerLaw<'_> {
    fn add_row(&mut self, axis: usize, t: f64) -> Result<(), String> {
        let c = if axis == 0 { &self.c1 } else { &self.c2 };
        let sign = if axis == 0 { -1.0 } else { 1.0 };
        let row = self.ev.memo_row((2 + axis, t.to_bits()), || {
            let mut row = vec![0.0; self.n];
            if sums::is_large(self.n) {
                // Four exps at a time ([`vexp`], within an ulp of the C library's, as the
                // model's own evaluations on large data): the scalar exp was a third of the
                // slices' time.
                sums::fill_chunks(&mut row, |start, o| {
                    for (k, z) in o.iter_mut().enumerate() {
                        *z = sign * t * c[start + k];
                    }
                    vexp::exp_in_place(o);
                });
            } else {
                sums::fill(&mut row, |i| (sign * t * c[i]).exp());
            }
            row
        });
        let (bad, max) = row.iter().fold((false, 0.0), |(bad, max), &z| {
            (bad || !z.is_finite(), if z > max { z } else { max })
        });
        self.row_max[axis].push(max);
        self.rows[axis].push(row);
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
        let (ln_a, chi2) = self.profile(r);
        let (a, b) = (self.t[0][r[0]], self.t[1][r[1]]);
        self.amplitudes
            .borrow_mut()
            .insert(r, (ln_a + self.shift(a, b)).exp());
        chi2
    }

    fn bound(&self, lo: [usize; 2], hi: [usize; 2], target: f64) -> Bound {
        let (a0, a1) = (self.t[0][lo[0]], self.t[0][hi[0]]);
        let (b0, b1) = (self.t[1][lo[1]], self.t[1][hi[1]]);
        // Half-widths rounded up (a difference and a halving, each within an ulp).
        let h = [
            0.5 * (a1 - a0) * (1.0 + 1e-15),
            0.5 * (b1 - b0) * (1.0 + 1e-15),
        ];
        let m_max = self.m_max(h);
        let (linearise_first, linearise) = (m_max <= NARROW_M, m_max <= WIDE_M);
        let mut scratch = self.scratch.borrow_mut();
        let [zlo, zhi, zc, rz] = &mut *scratch;
        let w_hi = self.fill_cell(lo, hi, linearise.then_some(h), [zlo, zhi, zc, rz]);
        // The box of the centred amplitude over the cell: the shift is linear in a and b.
        let shifts = [
            self.shift(a0, b0),
            self.shift(a1, b0),
            self.shift(a0, b1),
            self.shift(a1, b1),
        ];
        let smin = shifts.iter().cloned().fold(f64::INFINITY, f64::min);
        let smax = shifts.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let ends = (self.a_range.0 * smin.exp(), self.a_range.1 * smax.exp());
        // How much each axis loosens the bound: its width times the model's sensitivity to it.
        let wa = (a1 - a0) * self.sens[0];
        let wb = (b1 - b0) * self.sens[1];
        let loose = [wa * wa, wb * wb];
        let linearised = |zlo: &[f64], zhi: &[f64], zc: &[f64], rz: &[f64]| {
            // sum w a_k^2 for the gradient coefficients a of linearized::Cell::mags: zc <= zhi
            // and rz <= R zhi with R the remainder's bound at max M.
            let r = linearized::remainder_bound(m_max, (m_max.exp()) * (1.0 + 1e-15));
            let f = 1.0 + 1e-9;
            let cell = linearized::Cell {
                y: &self.y,
                w: &self.w,
                c1: &self.c1,
                c2: &self.c2,
                zlo,
                zhi,
                zc,
                rz,
                h,
                ends,
                start: self.start_amplitude(lo, hi),
                wy2: self.wy2,
                mags: [
                    w_hi * f,
                    w_hi * f * (1.0 + linearized::EPS + r).powi(2),
                    w_hi * f * self.c_max[0].powi(2),
                    w_hi * f * self.c_max[1].powi(2),
                ],
            };
            linearized::bound(&cell, target, self.bound_tol)
        };
        let first_order = |zlo: &[f64], zhi: &[f64]| self.first_order_bound(zlo, zhi, ends, target);
        // Narrow cells: the linearised bound first; wide ones: the first-order bound first. The
        // other (not on the widest cells) when the first did not decide: the larger is kept. A
        // NaN (overflow) from the first-order bound is passed on for the search to report; one
        // from the linearised bound gives no bound.
        let mut lb;
        if linearise_first {
            lb = linearised(zlo, zhi, zc, rz);
            if !(lb >= target) {
                let first = first_order(zlo, zhi);
                lb = if first.is_nan() { first } else { lb.max(first) };
            }
        } else {
            lb = first_order(zlo, zhi);
            if linearise && !(lb >= target) {
                let l = linearised(zlo, zhi, zc, rz);
                if l > lb {
                    lb = l;
                }
            }
        }
        // chi2 >= 0 always.
        Bound {
            lb: if lb < 0.0 { 0.0 } else { lb },
            loose,
        }
    }
}

impl PowerLaw<'_> {
    /// The first-order bound as a cell's bound takes it: [`PowerLaw::bound_from_inside`] for
    /// large data, [`PowerLaw::first_order`] for small, lowered by the rounding allowance of two
    /// computations of one chi2 ([`chi2_rounding`]). f is formed as chi2 is, so where the cell's
    /// minimum is a node (at an end of A's box, the model far from the data) it can come out an
    /// ulp above that node's chi2 (fuzz seed 615 case 600: 4.4e-16 above, and every cell was
    /// dropped); the intervals' relative widening (Z_SLACK) does not reach y where A z is tiny.
    pub(super) fn first_order_bound(
        &self,
        zlo: &[f64],
        zhi: &[f64],
        ends: (f64, f64),
        target: f64,
    ) -> f64 {
        let f = if sums::is_large(self.n) {
            self.bound_from_inside(zlo, zhi, ends, target)
        } else {
            self.first_order(zlo, zhi, ends, target)
        };
        if f.is_finite() {
            f - chi2_rounding(self.n, self.w_sum, self.e_accuracy, f)
        } else {
            f
        }
    }

    /// The geometric mean of the amplitudes at the cell's corners (0 when none is known).
    fn start_amplitude(&self, lo: [usize; 2], hi: [usize; 2]) -> f64 {
        let amps = self.amplitudes.borrow();
        let corners = [lo, [hi[0], lo[1]], [lo[0], hi[1]], hi];
        let logs: Vec<f64> = corners
            .iter()
            .filter_map(|r| amps.get(r))
            .filter(|a| a.is_finite() && **a > 0.0)
            .map(|a| a.ln())
            .collect();
        if logs.is_empty() {
            return 0.0;
        }
        (logs.iter().sum::<f64>() / logs.len() as f64).exp()
    }

    /// The scratch arrays of the cell between rows `lo` and `hi`: zlo and zhi (widened by
    /// Z_SLACK), and with the half-widths `h` the centre's zc and the remainder zc R(M_i) of
    /// [`linearized`] (R's bound taking exp(M_i) <= exp(max M), no exp per point); returns
    /// sum_i w_i zhi_i^2.
    fn fill_cell(
        &self,
        lo: [usize; 2],
        hi: [usize; 2],
        h: Option<[f64; 2]>,
        out: [&mut Vec<f64>; 4],
    ) -> f64 {
        let (za0, za1) = (self.row(0, lo[0]), self.row(0, hi[0]));
        let (zb0, zb1) = (self.row(1, lo[1]), self.row(1, hi[1]));
        let (c1, c2, w) = (&self.c1[..], &self.c2[..], &self.w[..]);
        let e_max = h.map_or(0.0, |h| self.m_max(h).exp() * (1.0 + 1e-15));
        // The points start..start + len into the chunk's slices, four at a time ([`lanes`]),
        // without branches; a centre whose corners' product overflows or underflows (rare) is
        // redone after, point by point. Every value stored is the one a loop point by point
        // would give, to the last bit; the sum is taken in lanes.
        let (eps_lo, eps_hi) = (f64x4::splat(1.0 - Z_SLACK), f64x4::splat(1.0 + Z_SLACK));
        let chunk = |start: usize, o: [&mut [f64]; 4]| -> f64 {
            let [o0, o1, o2, o3] = o;
            let len = o0.len();
            let r = start..start + len;
            let (za0, za1) = (&za0[r.clone()], &za1[r.clone()]);
            let (zb0, zb1) = (&zb0[r.clone()], &zb1[r.clone()]);
            let (o1, o2, o3) = (&mut o1[..len], &mut o2[..len], &mut o3[..len]);
            let (c1, c2, w) = (&c1[r.clone()], &c2[r.clone()], &w[r]);
            let mut s = f64x4::ZERO;
            // All ones while every centre so far is finite and positive (padding lanes, 0,
            // clear it too: then the check below runs over the chunk, finding nothing to redo).
            let mut good = f64x4::splat(f64::from_bits(u64::MAX));
            for b in (0..len).step_by(lanes::LANES) {
                let (a0, a1, b0, b1) = (load(za0, b), load(za1, b), load(zb0, b), load(zb1, b));
                let (amin, amax) = (a0.fast_min(a1), a0.fast_max(a1));
                let (bmin, bmax) = (b0.fast_min(b1), b0.fast_max(b1));
                let hi = amax * bmax * eps_hi;
                store(o0, b, amin * bmin * eps_lo);
                store(o1, b, hi);
                s += load(w, b) * hi * hi;
                if let Some([ha, hb]) = h {
                    // exp(-a_c c1 + b_c c2) = sqrt of the product of the corners' rows, which
                    // can overflow where the rows do not: redone below.
                    let zc = (a0 * a1 * (b0 * b1)).sqrt();
                    let m =
                        load(c1, b).abs() * f64x4::splat(ha) + load(c2, b).abs() * f64x4::splat(hb);
                    good = good & zc.is_finite() & zc.cmp_gt(f64x4::ZERO);
                    store(o2, b, zc);
                    store(o3, b, zc * linearized::remainder_bound_x4(m, e_max));
                }
            }
            if let Some([ha, hb]) = h
                && !good.all()
            {
                for j in 0..len {
                    if !(o2[j].is_finite() && o2[j] > 0.0) {
                        let (amin, amax) = (za0[j].min(za1[j]), za0[j].max(za1[j]));
                        let (bmin, bmax) = (zb0[j].min(zb1[j]), zb0[j].max(zb1[j]));
                        let zc = (amin.sqrt() * amax.sqrt()) * (bmin.sqrt() * bmax.sqrt());
                        let m = c1[j].abs() * ha + c2[j].abs() * hb;
                        o2[j] = zc;
                        o3[j] = zc * linearized::remainder_bound(m, e_max);
                    }
                }
            }
            lanes::total(s)
        };
        let n = self.n;
        let [o0, o1, o2, o3] = out;
        if !sums::is_large(n) {
            return chunk(0, [&mut o0[..n], &mut o1[..n], &mut o2[..n], &mut o3[..n]]);
        }
        // Chunks in parallel, their sums added in chunk order (as in [`sums::sum`]).
        let parts: Vec<f64> = o0[..n]
            .par_chunks_mut(sums::CHUNK)
            .zip(o1[..n].par_chunks_mut(sums::CHUNK))
            .zip(o2[..n].par_chunks_mut(sums::CHUNK))
            .zip(o3[..n].par_chunks_mut(sums::CHUNK))
            .enumerate()
            .map(|(c, (((p0, p1), p2), p3))| {
                crate::cpu::fast(|| chunk(c * sums::CHUNK, [p0, p1, p2, p3]))
            })
            .collect();
        parts.iter().sum()
    }

    /// The largest M_i = |c1_i| h_a + |c2_i| h_b over the points.
    fn m_max(&self, h: [f64; 2]) -> f64 {
        self.c_max[0] * h[0] + self.c_max[1] * h[1]
    }
}
