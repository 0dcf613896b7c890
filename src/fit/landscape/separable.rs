//! The separable models' landscape (`vm`, `pm`, `min`, `product`) and its cell bound; the
//! argument is in the parent module's documentation and docs/physics.md §7.4.

use super::super::bnb::{Bound, Landscape};
use super::super::objective::Objective;
use super::super::sums;
use crate::models::plastic::E_CURVATURE_LN_U;
use crate::models::viscoelastic::master::E_CURVATURE_LN_KAPPA;

/// For large data (see [`sums`]) the looseness of a cell (which axis to split) is estimated
/// from every LOOSE_STRIDE-th point: it decides nothing about the cell (13, prime, so that data
/// repeating a pattern of rows are not sampled in step).
const LOOSE_STRIDE: usize = 13;

/// Bounds on |F_i''| and |G_i''| in the search coordinates: ln kappa_i = t0 + ln(kappa_i at
/// eta = 1), so e_vm's own bound in ln kappa; ln u_i = ln(v_i/V_Y,i at 1 Pa) - (5/2) t1 (V_Y
/// scales as sigma_y^(5/2), Eq. 15), so (5/2)^2 times e_pm's bound in ln u.
pub const CURVATURE: [f64; 2] = [E_CURVATURE_LN_KAPPA, 6.25 * E_CURVATURE_LN_U];

/// Rounding of the bound's own arithmetic: a point's interval is formed in about ten operations
/// on numbers of magnitude at most 2 (each rounding at most 2.2e-16 of that), and e = min or
/// product of two computed factors rounds once more.
const ROUND: f64 = 1e-14;

/// Passes over the points per cell bound at most: the first gives the first-order bound and the
/// relaxation at the cell's centre, each further one a projected Newton step towards the
/// relaxation's minimum (any stop is valid; see [`Separable::bound_with`]).
const MAX_PASSES: usize = 6;

/// An affine function a + b s + c u of a cell's coordinates (s, u) in [0, 1]^2.
#[derive(Clone, Copy)]
struct Aff {
    a: f64,
    b: f64,
    c: f64,
}

impl Aff {
    #[inline(always)]
    fn at(&self, x: [f64; 2]) -> f64 {
        self.a + self.b * x[0] + self.c * x[1]
    }
}

/// One point's enclosure on a cell: the computed e lies in [max of `lo` - R, min of `hi` + R]
/// at every (s, u) of the cell, R = r0 + r2[0] s (1 - s) + r2[1] u (1 - u) (a convex lower and
/// a concave upper end).
struct Enclosure {
    lo: [Aff; 2],
    hi: [Aff; 2],
    r0: f64,
    r2: [f64; 2],
}

/// A factor's band around its linear interpolant between the corner rows: half-width
/// c + a t (1 - t) at cell coordinate t.
#[derive(Clone, Copy)]
struct Band {
    c: f64,
    a: f64,
}

impl Band {
    #[inline(always)]
    fn max(&self) -> f64 {
        self.c + 0.25 * self.a
    }
}

/// The larger (`upper` false) or smaller (`upper` true) of two affine functions at x, and the
/// gradient of the one that attains it.
#[inline(always)]
fn pick(p: &[Aff; 2], x: [f64; 2], upper: bool) -> (f64, [f64; 2]) {
    let (v0, v1) = (p[0].at(x), p[1].at(x));
    let k = usize::from(if upper { v1 < v0 } else { v1 > v0 });
    ([v0, v1][k], [p[k].b, p[k].c])
}

/// A cell of the separable landscape: its corner rows and what the bound needs of its widths.
struct Cell<'r> {
    f0: &'r [f64],
    f1: &'r [f64],
    g0: &'r [f64],
    g1: &'r [f64],
    /// CURVATURE[k] h_k^2/8 (0 on an inactive axis): the linear-interpolation error.
    q: [f64; 2],
    /// The computed factor's error around the exact one (0 on an inactive axis: a row of 1).
    eps: [f64; 2],
    /// Widening of the monotone range (the first-order bound's).
    slack: f64,
    min_rule: bool,
}

impl Cell<'_> {
    /// Point i's distance outside its first-order range (as the first-order bound has always
    /// formed it).
    #[inline(always)]
    fn first_order_gap(&self, i: usize, ei: f64) -> f64 {
        let c = |a: f64, b: f64| if self.min_rule { a.min(b) } else { a * b };
        let top = c(self.f0[i], self.g1[i]);
        let bottom = c(self.f1[i], self.g0[i]) - self.slack;
        if ei < bottom {
            bottom - ei
        } else if ei > top + self.slack {
            ei - top - self.slack
        } else {
            0.0
        }
    }

    /// The factors' bands around their linear interpolants (F: 0, G: 1). Linear interpolation
    /// of a function whose second derivative is at most C in magnitude errs by at most
    /// (C/2)(t - t_lo)(t_hi - t) = 4 q s (1 - s), q = C h^2/8, and (the function being monotone)
    /// by at most its range |corner difference|; the computed factor adds its error at the
    /// corners and inside (eps each side). The quadratic band is used while q is below the
    /// range, else the constant one.
    #[inline(always)]
    fn bands(&self, i: usize) -> [Band; 2] {
        let d = [
            (self.f1[i] - self.f0[i]).abs(),
            (self.g1[i] - self.g0[i]).abs(),
        ];
        [0, 1].map(|k| {
            let (q, eps) = (self.q[k], self.eps[k]);
            if q <= d[k] + eps {
                Band { c: eps, a: 4.0 * q }
            } else {
                Band {
                    c: d[k] + 2.0 * eps,
                    a: 0.0,
                }
            }
        })
    }

    /// Which factor is the smaller one all over the cell for point i under `min` (0: F, 1: G),
    /// if one is: its band lies below the other's everywhere.
    #[inline(always)]
    fn side(&self, i: usize, b: [Band; 2]) -> Option<usize> {
        let (f0, f1, g0, g1) = (self.f0[i], self.f1[i], self.g0[i], self.g1[i]);
        let r = [b[0].max(), b[1].max()];
        if f0.max(f1) + r[0] <= g0.min(g1) - r[1] {
            Some(0)
        } else if g0.max(g1) + r[1] <= f0.min(f1) - r[0] {
            Some(1)
        } else {
            None
        }
    }

    /// Point i's enclosure on the cell (see the parent module's doc). The monotone range is
    /// left out: it would put a kink of first order into the relaxation (the first-order bound
    /// holds it, and the larger of the two bounds is taken).
    #[inline(always)]
    fn enclosure(&self, i: usize) -> Enclosure {
        let (f0, f1, g0, g1) = (self.f0[i], self.f1[i], self.g0[i], self.g1[i]);
        let (df, dg) = (f1 - f0, g1 - g0);
        let bands = self.bands(i);
        let [bf, bg] = bands;
        let aff = |a: f64, b: f64, c: f64| Aff { a, b, c };
        if self.min_rule {
            match self.side(i, bands) {
                // One factor is e all over the cell: its band.
                Some(0) => {
                    let l = aff(f0, df, 0.0);
                    return Enclosure {
                        lo: [l, l],
                        hi: [l, l],
                        r0: bf.c,
                        r2: [bf.a, 0.0],
                    };
                }
                Some(_) => {
                    let l = aff(g0, 0.0, dg);
                    return Enclosure {
                        lo: [l, l],
                        hi: [l, l],
                        r0: bg.c,
                        r2: [0.0, bg.a],
                    };
                }
                None => {}
            }
            // Either may be the smaller. With the constant bands F in f0 + s df +- rf, G in
            // g0 + u dg +- rg: e <= the upper ends' min; e >= the lower ends' min, a concave
            // function whose convex envelope on the square is the lower hull of its corner
            // values (two planes through three corners each).
            let (rf, rg) = (bf.max(), bg.max());
            let lf = |s: f64| f0 - rf + s * df;
            let lg = |u: f64| g0 - rg + u * dg;
            let m = |s: f64, u: f64| lf(s).min(lg(u));
            let (m00, m10, m01, m11) = (m(0.0, 0.0), m(1.0, 0.0), m(0.0, 1.0), m(1.0, 1.0));
            let lo = if m00 + m11 <= m10 + m01 {
                [
                    aff(m00, m10 - m00, m11 - m10),
                    aff(m00, m11 - m01, m01 - m00),
                ]
            } else {
                [
                    aff(m00, m10 - m00, m01 - m00),
                    aff(m01 + m10 - m11, m11 - m01, m11 - m10),
                ]
            };
            return Enclosure {
                lo,
                hi: [aff(f0 + rf, df, 0.0), aff(g0 + rg, 0.0, dg)],
                r0: 0.0,
                r2: [0.0, 0.0],
            };
        }
        // F G = (f0 + s df)(g0 + u dg) + remainder, |remainder| <= mf rg + mg rf + rf rg <=
        // (mf + max rf) rg(u) + mg rf(s) (the interpolants lie between their corner values): a
        // concave function of (s, u). The cross term p s u is enclosed by McCormick's envelopes
        // of s u on the square: max(0, s + u - 1) <= s u <= min(s, u).
        let mf = f0.abs().max(f1.abs());
        let mg = g0.abs().max(g1.abs());
        let kg = mf + bf.max();
        let (r0, r2) = (kg * bg.c + mg * bf.c, [mg * bf.a, kg * bg.a]);
        let (a, b, c, p) = (f0 * g0, df * g0, f0 * dg, df * dg);
        let (lo, hi) = if p >= 0.0 {
            (
                [aff(a, b, c), aff(a - p, b + p, c + p)],
                [aff(a, b + p, c), aff(a, b, c + p)],
            )
        } else {
            (
                [aff(a, b + p, c), aff(a, b, c + p)],
                [aff(a, b, c), aff(a - p, b + p, c + p)],
            )
        };
        Enclosure { lo, hi, r0, r2 }
    }

    /// Point i's looseness along each axis under the second-order bound: the band's half-width
    /// that each axis causes, weighted as the first-order looseness is.
    fn loose_second(&self, i: usize, w: f64, e: f64) -> [f64; 2] {
        let (f0, f1, g0, g1) = (self.f0[i], self.f1[i], self.g0[i], self.g1[i]);
        let (df, dg) = ((f1 - f0).abs(), (g1 - g0).abs());
        let (qf, qg) = (self.q[0].min(df), self.q[1].min(dg));
        let (fm, gm) = (0.5 * (f0 + f1), 0.5 * (g0 + g1));
        let (centre, d) = if self.min_rule {
            let d = match self.side(i, self.bands(i)) {
                Some(0) => [qf, 0.0],
                Some(_) => [0.0, qg],
                // Either factor may be the smaller: first order in both.
                None => [df, dg],
            };
            (fm.min(gm), d)
        } else {
            let mf = f0.abs().max(f1.abs());
            let mg = g0.abs().max(g1.abs());
            let cross = 0.25 * df * dg;
            (fm * gm, [mg * qf + cross, mf * qg + cross])
        };
        let r = (centre - e).abs();
        [w * d[0] * (r + d[0]), w * d[1] * (r + d[1])]
    }
}

/// The separable models' landscape: rows of e_vm (axis 0) and e_pm (axis 1).
pub struct Separable<'a> {
    obj: &'a Objective<'a>,
    min_rule: bool,
    active: [bool; 2],
    n: usize,
    rows: [Vec<f64>; 2],
    t: [Vec<f64>; 2],
    e: Vec<f64>,
    w: Vec<f64>,
    slack: f64,
    /// Whether cells get the second-order bound (large data, see [`sums`]), or only the
    /// first-order one: small data's searches cost little, and their fits stay as they were to
    /// the last bit (the second-order bound cuts the 120 shipped points' cells by 2 to 8 times
    /// but moves where a polish stops, within the search's tolerance).
    second_order: bool,
}

/// Sums of one pass over the points (see [`Separable::pass`]).
#[derive(Default, Clone, Copy)]
struct PassSums {
    /// The first-order bound.
    first: f64,
    /// The relaxation phi at x, its gradient and (generalised) Hessian, and the sums of the
    /// gradient terms' magnitudes (for the rounding margin).
    phi: f64,
    g: [f64; 2],
    h: [f64; 3],
    g_abs: [f64; 2],
    /// Looseness per axis: first-order and second-order.
    loose1: [f64; 2],
    loose2: [f64; 2],
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
            t: [Vec::new(), Vec::new()],
            e: obj.ev.data.obs.iter().map(|o| o.e).collect(),
            w: obj.inv_sigma.iter().map(|s| s * s).collect(),
            slack: 2.0 * obj.e_accuracy,
            second_order: sums::is_large(n),
        }
    }

    fn row(&self, k: usize, r: usize) -> &[f64] {
        &self.rows[k][r * self.n..(r + 1) * self.n]
    }

    fn cell(&self, lo: [usize; 2], hi: [usize; 2]) -> Cell<'_> {
        let mut q = [0.0; 2];
        let mut eps = [0.0; 2];
        for k in 0..2 {
            if self.active[k] {
                let h = self.t[k][hi[k]] - self.t[k][lo[k]];
                q[k] = CURVATURE[k] * h * h / 8.0;
                eps[k] = self.slack + ROUND;
            }
        }
        Cell {
            f0: self.row(0, lo[0]),
            f1: self.row(0, hi[0]),
            g0: self.row(1, lo[1]),
            g1: self.row(1, hi[1]),
            q,
            eps,
            slack: self.slack,
            min_rule: self.min_rule,
        }
    }

    /// One pass over the points at cell coordinates x, or (`sample`) over every
    /// LOOSE_STRIDE-th point of each chunk; the first pass and a sample also sum the first-order
    /// bound, and the loosenesses (for large data, only a sample does).
    fn pass(&self, cell: &Cell, x: [f64; 2], first: bool, sample: bool) -> PassSums {
        let (e, w) = (&self.e[..], &self.w[..]);
        let first = first || sample;
        let second_order = self.second_order;
        let point = |i: usize, s: &mut PassSums| {
            let ei = e[i];
            if first {
                let d = cell.first_order_gap(i, ei);
                s.first += w[i] * d * d;
            }
            if !second_order {
                return;
            }
            let enc = cell.enclosure(i);
            let (lo, glo) = pick(&enc.lo, x, false);
            let (hi, ghi) = pick(&enc.hi, x, true);
            let r = enc.r0 + enc.r2[0] * x[0] * (1.0 - x[0]) + enc.r2[1] * x[1] * (1.0 - x[1]);
            let gr = [
                enc.r2[0] * (1.0 - 2.0 * x[0]),
                enc.r2[1] * (1.0 - 2.0 * x[1]),
            ];
            // phi_i = w dist(e, [lo - R, hi + R])^2: convex in x (lo - R convex, hi + R
            // concave); the gradient of the end that e lies beyond, pointing away from e.
            let (d, grad) = if ei < lo - r {
                (lo - r - ei, [glo[0] - gr[0], glo[1] - gr[1]])
            } else if ei > hi + r {
                (ei - hi - r, [-ghi[0] - gr[0], -ghi[1] - gr[1]])
            } else {
                return;
            };
            let wd = w[i] * d;
            s.phi += wd * d;
            for (k, gk) in grad.iter().enumerate() {
                s.g[k] += 2.0 * wd * gk;
                s.g_abs[k] += (2.0 * wd * gk).abs();
            }
            // Hessian of w d^2: 2 w (grad grad^T + d diag(2 r2)) (R's curvature is -2 r2).
            let w2 = 2.0 * w[i];
            s.h[0] += w2 * (grad[0] * grad[0] + 2.0 * d * enc.r2[0]);
            s.h[1] += w2 * grad[0] * grad[1];
            s.h[2] += w2 * (grad[1] * grad[1] + 2.0 * d * enc.r2[1]);
        };
        let min_rule = self.min_rule;
        let loose = |i: usize, s: &mut PassSums| {
            let (f0, f1, g0, g1) = (cell.f0[i], cell.f1[i], cell.g0[i], cell.g1[i]);
            let c = |a: f64, b: f64| if min_rule { a.min(b) } else { a * b };
            let top = c(f0, g1);
            let r = (top - e[i]).abs();
            let d0 = top - c(f1, g1);
            let d1 = top - c(f0, g0);
            s.loose1[0] += w[i] * d0 * (r + d0);
            s.loose1[1] += w[i] * d1 * (r + d1);
            if second_order {
                let l2 = cell.loose_second(i, w[i], e[i]);
                s.loose2[0] += l2[0];
                s.loose2[1] += l2[1];
            }
        };
        let large = sums::is_large(self.n);
        let v = sums::sum(self.n, |points| {
            let mut s = PassSums::default();
            if sample {
                for i in points.step_by(LOOSE_STRIDE) {
                    point(i, &mut s);
                    loose(i, &mut s);
                }
            } else {
                for i in points {
                    point(i, &mut s);
                    if first && !large {
                        loose(i, &mut s);
                    }
                }
            }
            let [g0, g1] = s.g;
            let [h0, h1, h2] = s.h;
            let [a0, a1] = s.g_abs;
            let [o0, o1] = s.loose1;
            let [n0, n1] = s.loose2;
            [s.first, s.phi, g0, g1, h0, h1, h2, a0, a1, o0, o1, n0, n1]
        });
        PassSums {
            first: v[0],
            phi: v[1],
            g: [v[2], v[3]],
            h: [v[4], v[5], v[6]],
            g_abs: [v[7], v[8]],
            loose1: [v[9], v[10]],
            loose2: [v[11], v[12]],
        }
    }

    /// The cell bound: the larger of the first-order bound and tangent-plane bounds of the
    /// convex relaxation phi (parent module's doc), at the cell's centre and at safeguarded
    /// projected Newton steps towards phi's minimum (a step that does not lower phi is halved
    /// back towards the best point), until the bound reaches `target`, phi itself falls below it
    /// (no bound of phi's minimum can reach it then), or MAX_PASSES (always, without a target).
    fn bound_with(&self, lo: [usize; 2], hi: [usize; 2], target: Option<f64>) -> Bound {
        let cell = self.cell(lo, hi);
        let mut x = [0.5, 0.5];
        // Rounding of a sum of n terms: at most n u of the sum of their magnitudes (any order).
        let margin = 2.0 * (self.n as f64 + 10.0) * f64::EPSILON;
        // phi(y) >= phi(x) + g.(y - x) for every y in the cell: its least value is at a corner,
        // each coordinate at the end the gradient points away from.
        let tangent = |s: &PassSums, x: [f64; 2]| {
            let mut t = s.phi;
            for (gk, xk) in s.g.iter().zip(x) {
                t += if *gk >= 0.0 {
                    -gk * xk
                } else {
                    gk * (1.0 - xk)
                };
            }
            t - margin * (s.phi + s.g_abs[0] + s.g_abs[1])
        };
        let choose = |s: &PassSums, second: f64| {
            if second > s.first { s.loose2 } else { s.loose1 }
        };
        // Large data: a sample of the points first. Its terms are a part of the full sums (all
        // non-negative for the first-order bound; phi over a subset of the points is a convex
        // minorant of phi), so its bounds are bounds too, and they settle the cells far from the
        // minimum at a thirteenth of the cost. It also gives the looseness.
        let sampled = sums::is_large(self.n).then(|| {
            let s = self.pass(&cell, x, true, true);
            let second = tangent(&s, x);
            (s, second)
        });
        if let (Some((s, second)), Some(t)) = (&sampled, target)
            && s.first.max(*second) >= t
        {
            return Bound {
                lb: s.first.max(*second),
                loose: choose(s, *second),
            };
        }
        let mut first = PassSums::default();
        let mut best: Option<([f64; 2], PassSums)> = None;
        let mut second = f64::NEG_INFINITY;
        for pass in 0..MAX_PASSES {
            let s = self.pass(&cell, x, pass == 0, false);
            if pass == 0 {
                first = s;
                if let Some((sample, _)) = &sampled {
                    first.loose1 = sample.loose1;
                    first.loose2 = sample.loose2;
                }
                if !self.second_order {
                    return Bound {
                        lb: first.first,
                        loose: first.loose1,
                    };
                }
            }
            let tangent = tangent(&s, x);
            if tangent > second {
                second = tangent;
            }
            let decided = target.is_some_and(|t| first.first.max(second) >= t || s.phi < t);
            if decided || pass + 1 == MAX_PASSES {
                break;
            }
            let next = match best {
                Some((bx, b)) if !(s.phi < b.phi) => {
                    Some([0.5 * (bx[0] + x[0]), 0.5 * (bx[1] + x[1])])
                }
                _ => {
                    best = Some((x, s));
                    newton_step(x, s.g, s.h)
                }
            };
            match next {
                Some(y) if y != x => x = y,
                _ => break,
            }
        }
        Bound {
            lb: first.first.max(second),
            loose: choose(&first, second),
        }
    }
}

/// A Newton step on the quadratic model phi(x) + g.d + d.H d/2, projected onto [0, 1]^2: the
/// full step clipped, then the other coordinate re-minimised with a clipped one held (None when
/// the model has no curvature: phi is then flat or linear over the points that count).
fn newton_step(x: [f64; 2], g: [f64; 2], h: [f64; 3]) -> Option<[f64; 2]> {
    let reg = 1e-12 * (h[0] + h[2]);
    let (a, b, c) = (h[0] + reg, h[1], h[2] + reg);
    let det = a * c - b * b;
    if !(det > 0.0 && det.is_finite()) {
        return None;
    }
    let d = [-(c * g[0] - b * g[1]) / det, -(a * g[1] - b * g[0]) / det];
    let mut y = [(x[0] + d[0]).clamp(0.0, 1.0), (x[1] + d[1]).clamp(0.0, 1.0)];
    let hk = [a, c];
    for k in 0..2 {
        let j = 1 - k;
        if (y[k] == 0.0 || y[k] == 1.0) && hk[j] > 0.0 {
            y[j] = (x[j] - (g[j] + b * (y[k] - x[k])) / hk[j]).clamp(0.0, 1.0);
        }
    }
    y.iter().all(|v| v.is_finite()).then_some(y)
}

impl Landscape for Separable<'_> {
    fn add_row(&mut self, axis: usize, t: f64) -> Result<(), String> {
        let (n, ev) = (self.n, self.obj.ev);
        let start = self.rows[axis].len();
        self.rows[axis].resize(start + n, 1.0);
        self.t[axis].push(t);
        if !self.active[axis] {
            return Ok(());
        }
        self.obj.evals.set(self.obj.evals.get() + 1);
        let x = t.exp();
        let row = &mut self.rows[axis][start..start + n];
        if axis == 1 {
            ev.e_pm_row(x, row);
        } else {
            sums::fill(row, |i| ev.e_vm(i, x).unwrap_or(f64::NAN));
        }
        // The first point that failed names the failure (the evaluation's error if it gave
        // one, else the NaN).
        let Some(i) = row.iter().position(|v| v.is_nan()) else {
            return Ok(());
        };
        let error = if axis == 0 { ev.e_vm(i, x).err() } else { None };
        Err(match error {
            Some(e) => format!("e_vm at eta = {x}: {e}"),
            None => format!(
                "the model is NaN at {} = {x} for {}",
                if axis == 0 { "eta" } else { "sigma_y" },
                self.obj.describe_point(i)
            ),
        })
    }

    fn node(&self, r: [usize; 2]) -> f64 {
        let (f, g) = (self.row(0, r[0]), self.row(1, r[1]));
        let (e, w) = (&self.e[..], &self.w[..]);
        let min_rule = self.min_rule;
        let [s] = sums::sum(self.n, |points| {
            let mut s = 0.0;
            if min_rule {
                for i in points {
                    let d = f[i].min(g[i]) - e[i];
                    s += w[i] * d * d;
                }
            } else {
                for i in points {
                    let d = f[i] * g[i] - e[i];
                    s += w[i] * d * d;
                }
            }
            [s]
        });
        s
    }

    fn bound(&self, lo: [usize; 2], hi: [usize; 2], target: f64) -> Bound {
        self.bound_with(lo, hi, Some(target))
    }
}

#[cfg(test)]
mod tests;
