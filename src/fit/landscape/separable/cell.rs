//! A cell of the separable landscape: each point's enclosure of e over the cell, from the
//! corner rows and the curvature bounds (parent module's doc, docs/physics.md §7.4).

use crate::models::plastic::E_CURVATURE_LN_U;
use crate::models::viscoelastic::master::{E_CURVATURE_LN_KAPPA, E_CURVATURE_PER_LOSS};

/// Bounds on |F_i''| and |G_i''| in the search coordinates: ln kappa_i = t0 + ln(kappa_i at
/// eta = 1), so e_vm's own bound in ln kappa; ln u_i = ln(v_i/V_Y,i at 1 Pa) - (5/2) t1 (V_Y
/// scales as sigma_y^(5/2), Eq. 15), so (5/2)^2 times e_pm's bound in ln u. Each is the bound
/// over every value of the factor; [`Cell::q_at`] takes a smaller one for F where its values
/// over the cell allow.
pub const CURVATURE: [f64; 2] = [E_CURVATURE_LN_KAPPA, 6.25 * E_CURVATURE_LN_U];

/// Rounding of the bound's own arithmetic: a point's interval is formed in about ten operations
/// on numbers of magnitude at most 2 (each rounding at most 2.2e-16 of that), and e = min or
/// product of two computed factors rounds once more.
pub(super) const ROUND: f64 = 1e-14;

/// An affine function a + b s + c u of a cell's coordinates (s, u) in [0, 1]^2.
#[derive(Clone, Copy)]
#[cfg(test)]
pub(super) struct Aff {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

#[cfg(test)]
impl Aff {
    #[inline(always)]
    fn at(&self, x: [f64; 2]) -> f64 {
        self.a + self.b * x[0] + self.c * x[1]
    }
}

/// One point's enclosure on a cell: the computed e lies in [max of `lo` - R, min of `hi` + R]
/// at every (s, u) of the cell, R = r0 + r2[0] s (1 - s) + r2[1] u (1 - u) (a convex lower and
/// a concave upper end).
#[cfg(test)]
pub(super) struct Enclosure {
    pub lo: [Aff; 2],
    pub hi: [Aff; 2],
    pub r0: f64,
    pub r2: [f64; 2],
}

/// A factor's band around its linear interpolant between the corner rows: half-width
/// c + a t (1 - t) at cell coordinate t.
#[derive(Clone, Copy)]
pub(super) struct Band {
    pub c: f64,
    pub a: f64,
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
#[cfg(test)]
pub(super) fn pick(p: &[Aff; 2], x: [f64; 2], upper: bool) -> (f64, [f64; 2]) {
    let (v0, v1) = (p[0].at(x), p[1].at(x));
    let k = usize::from(if upper { v1 < v0 } else { v1 > v0 });
    ([v0, v1][k], [p[k].b, p[k].c])
}

/// A cell of the separable landscape: its corner rows and what the bound needs of its widths.
pub(super) struct Cell<'r> {
    pub f0: &'r [f64],
    pub f1: &'r [f64],
    pub g0: &'r [f64],
    pub g1: &'r [f64],
    /// h_k^2/8 (0 on an inactive axis): [`Cell::q_at`] times it by the curvature bound.
    pub h2: [f64; 2],
    /// The computed factor's error around the exact one (0 on an inactive axis: a row of 1).
    pub eps: [f64; 2],
    /// Widening of the monotone range (the first-order bound's).
    pub slack: f64,
    pub min_rule: bool,
}

impl Cell<'_> {
    /// Point i's q = C h^2/8 on each axis, C the curvature bound over the values the factor
    /// takes on the cell. F is non-increasing in eta, so its loss 1 - F over the cell is at most
    /// 1 - f1 + eps (f1 its corner value at the larger eta), and |F''| <=
    /// min(CURVATURE[0], E_CURVATURE_PER_LOSS (1 - f1 + eps)): near a fit's minimum, where e is
    /// often 0.8-0.95, 4 to 15 times below the global bound (100 000 points of distinct sizes:
    /// `product`'s full passes 858 -> 756). G keeps its global bound (a like bound,
    /// |e_pm''| (1 - e_pm) <= 0.022, measured 0.0146, was tried: the points near a fit's minimum
    /// are near yield, where it gives nothing, and its division cost more than it saved).
    ///
    /// `min` (MIN) keeps the global bound for F too: there the tighter bands left fewer cells at
    /// the search's resolution, hence fewer local polishes across the kinks of `min`, and on
    /// seed 22 of `tests/fit_large.rs` none of them reached the minimum (7 tolerances above it).
    #[inline(always)]
    pub(super) fn q_at<const MIN: bool>(&self, f1: f64) -> [f64; 2] {
        let cf = if MIN {
            CURVATURE[0]
        } else {
            (E_CURVATURE_PER_LOSS * (1.0 - f1 + self.eps[0])).min(CURVATURE[0])
        };
        [cf * self.h2[0], CURVATURE[1] * self.h2[1]]
    }

    /// [`Cell::q_at`] under the cell's rule.
    #[inline(always)]
    fn q_of(&self, f1: f64) -> [f64; 2] {
        if self.min_rule {
            self.q_at::<true>(f1)
        } else {
            self.q_at::<false>(f1)
        }
    }

    /// Point i's distance outside its first-order range (as the first-order bound has always
    /// formed it).
    #[inline(always)]
    pub(super) fn first_order_gap(&self, i: usize, ei: f64) -> f64 {
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
    pub(super) fn bands(&self, i: usize) -> [Band; 2] {
        let d = [
            (self.f1[i] - self.f0[i]).abs(),
            (self.g1[i] - self.g0[i]).abs(),
        ];
        let q = self.q_of(self.f1[i]);
        [0, 1].map(|k| {
            let (q, eps) = (q[k], self.eps[k]);
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
    /// holds it, and the larger of the two bounds is taken). This is the enclosure as stated;
    /// the passes run `kernel.rs`'s branch-free form of it, which the tests compare with this
    /// one bit for bit.
    #[cfg(test)]
    pub(super) fn enclosure(&self, i: usize) -> Enclosure {
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
    /// that each axis causes, weighted as the first-order looseness is. A call, not inlined:
    /// inlined into the passes it kept them out of their wide registers' copy (see
    /// [`crate::cpu::fast`]); the sampled passes' own loop inlines [`Cell::loose_second_inline`].
    #[inline(never)]
    pub(super) fn loose_second(&self, i: usize, w: f64, e: f64) -> [f64; 2] {
        self.loose_second_inline(i, w, e)
    }

    /// [`Cell::loose_second`]'s body.
    #[inline(always)]
    pub(super) fn loose_second_inline(&self, i: usize, w: f64, e: f64) -> [f64; 2] {
        let (f0, f1, g0, g1) = (self.f0[i], self.f1[i], self.g0[i], self.g1[i]);
        let (df, dg) = ((f1 - f0).abs(), (g1 - g0).abs());
        let [qf, qg] = self.q_of(f1);
        let (qf, qg) = (qf.min(df), qg.min(dg));
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
