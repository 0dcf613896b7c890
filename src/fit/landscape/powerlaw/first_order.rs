//! The power law's first-order cell bound (the parent module's and [`super::super`]'s docs):
//! the minimum over A of the convex f(A) = sum_i w_i dist(y_i, [A zlo_i, A zhi_i])^2, bounded
//! below by the crossing of two tangents with slopes of opposite signs.

use super::super::super::sums;
use super::lanes::{self, load};
use super::{POWERLAW_BOUND_ITERS, PowerLaw};
use wide::{CmpGt, f64x4};

impl PowerLaw<'_> {
    /// f(A), f'(A) and f''(A) (from the right) of the module doc. Four points at a time,
    /// branch-free ([`super::lanes`]); every input is finite (rows are checked when they are
    /// made).
    fn f_slope_curv(&self, zlo: &[f64], zhi: &[f64], a: f64) -> (f64, f64, f64) {
        let (y, w) = (&self.y[..], &self.w[..]);
        let (a, zero) = (f64x4::splat(a), f64x4::ZERO);
        let [f, d, h] = sums::sum(self.n, |points| {
            let r = points;
            let [y, w, zlo, zhi] = lanes::slices(&r, [y, w, zlo, zhi]);
            let (mut f, mut d, mut h) = (zero, zero, zero);
            for b in (0..r.len()).step_by(lanes::LANES) {
                let (y, w, zlo, zhi) = (load(y, b), load(w, b), load(zlo, b), load(zhi, b));
                let u = a * zlo - y;
                let v = y - a * zhi;
                // At most one of u, v is positive (zlo <= zhi).
                let (pos_u, pos_v) = (u.cmp_gt(zero), v.cmp_gt(zero));
                let (pu, pv) = (pos_u & u, pos_v & v);
                let (cu, cv) = (pos_u & zlo, pos_v & zhi);
                f += w * (pu * pu + pv * pv);
                d += w * (zlo * pu - zhi * pv);
                h += w * (cu * cu + cv * cv);
            }
            [
                lanes::total(f),
                2.0 * lanes::total(d),
                2.0 * lanes::total(h),
            ]
        });
        (f, d, h)
    }

    /// The least-squares amplitude A with every point's z at the middle of its range: the start
    /// of both bound iterations (four points at a time, [`super::lanes`]).
    fn amplitude_at_middle(&self, zlo: &[f64], zhi: &[f64]) -> f64 {
        let (y, w) = (&self.y[..], &self.w[..]);
        let half = f64x4::splat(0.5);
        let [num, den] = sums::sum(self.n, |points| {
            let r = points;
            let [y, w, zlo, zhi] = lanes::slices(&r, [y, w, zlo, zhi]);
            let (mut num, mut den) = (f64x4::ZERO, f64x4::ZERO);
            for b in (0..r.len()).step_by(lanes::LANES) {
                let z = half * (load(zlo, b) + load(zhi, b));
                let wz = load(w, b) * z;
                num += wz * load(y, b);
                den += wz * z;
            }
            [lanes::total(num), lanes::total(den)]
        });
        num / den
    }

    /// The minimum of f over the box of A, bounded below as in [`Landscape::bound`] for small
    /// data, but starting from the least-squares A at the middle z and evaluating the box's ends
    /// only when a step leaves the bracket: near the minimum (where nearly all cells are) the
    /// two evaluations at the ends of a box of decades were a third of the work. Any two
    /// tangents with slopes of opposite signs cross below the minimum of the convex f; a slope
    /// of the wrong sign at a box end puts the minimum over the box there. Without both kinds of
    /// tangent after the iterations, -inf (no bound: the cell is split).
    pub(super) fn bound_from_inside(
        &self,
        zlo: &[f64],
        zhi: &[f64],
        ends: (f64, f64),
        target: f64,
    ) -> f64 {
        let mut x = self.amplitude_at_middle(zlo, zhi);
        // The latest points with f' < 0 (left of the minimum) and f' > 0 (right of it).
        let mut left: Option<(f64, f64, f64)> = None;
        let mut right: Option<(f64, f64, f64)> = None;
        let mut lb = f64::NEG_INFINITY;
        for _ in 0..POWERLAW_BOUND_ITERS {
            let l = left.map_or(ends.0, |p| p.0);
            let r = right.map_or(ends.1, |p| p.0);
            if !(x > l && x < r) {
                x = if x <= l && left.is_none() {
                    ends.0
                } else if x >= r && right.is_none() {
                    ends.1
                } else if l > 0.0 {
                    (l * r).sqrt()
                } else {
                    0.5 * (l + r)
                };
            }
            let (f, d, h) = self.f_slope_curv(zlo, zhi, x);
            if d == 0.0 || f == 0.0 {
                return f;
            }
            if d < 0.0 {
                if x == ends.1 {
                    return f;
                }
                left = Some((x, f, d));
            } else {
                if x == ends.0 {
                    return f;
                }
                right = Some((x, f, d));
            }
            let step = d / h;
            if let (Some((x1, f1, d1)), Some((x2, f2, d2))) = (left, right) {
                let xc = (f2 - f1 + d1 * x1 - d2 * x2) / (d1 - d2);
                lb = f1 + d1 * (xc - x1);
                // Decided (as for small data).
                if lb >= target || f1.min(f2) < target || f1.min(f2) - lb <= self.bound_tol {
                    break;
                }
                x -= step;
            } else {
                // One side only: a Newton step a little long, to reach the other side (f' is
                // piecewise linear, so an exact step lands on the minimum itself).
                x -= step * (1.0 + 1e-3);
            }
        }
        lb
    }

    /// The first-order bound for small data (module doc of the parent): the tangents' crossing
    /// from the box's ends inwards; negative or NaN passed on.
    pub(super) fn first_order(
        &self,
        zlo: &[f64],
        zhi: &[f64],
        ends: (f64, f64),
        target: f64,
    ) -> f64 {
        let (mut x1, mut x2) = ends;
        let (mut f1, mut d1, _) = self.f_slope_curv(zlo, zhi, x1);
        if d1 >= 0.0 {
            return f1;
        }
        let (mut f2, mut d2, _) = self.f_slope_curv(zlo, zhi, x2);
        if d2 <= 0.0 {
            return f2;
        }
        // f'(x1) < 0 < f'(x2): the tangents' crossing is a lower bound. Newton steps on the
        // piecewise linear f' (exact on each piece) move the bracket in; bisection (geometric, A
        // spans decades) when a step leaves it. Start from the least-squares A at the middle z.
        let mut x = self.amplitude_at_middle(zlo, zhi);
        let mut lb = f64::NEG_INFINITY;
        for _ in 0..POWERLAW_BOUND_ITERS {
            if !(x > x1 && x < x2) {
                x = if x1 > 0.0 {
                    (x1 * x2).sqrt()
                } else {
                    0.5 * (x1 + x2)
                };
            }
            let (f, d, h) = self.f_slope_curv(zlo, zhi, x);
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
        lb
    }
}
