//! The pairs bootstrap of the Walton fit and its percentile intervals.

use super::hinge::{HingeShape, hinge_sorted};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// One collision as the bootstrap sees it: e with its weight, and (psi, beta, weight) when the
/// collision has a beta (not head-on).
#[derive(Debug, Clone, Copy)]
pub(super) struct Point {
    pub e: f64,
    pub we: f64,
    pub hinge: Option<(f64, f64, f64)>,
}

/// The fitted numbers of every resample whose hinge had collisions on both sides of the kink.
#[derive(Debug, Default)]
pub(super) struct Replicates {
    pub e: Vec<f64>,
    pub beta0: Vec<f64>,
    pub mu0: Vec<f64>,
    pub slope: Vec<f64>,
    pub kink: Vec<f64>,
    /// Resamples left out: fewer than 3 oblique collisions, or a degenerate hinge.
    pub failed: usize,
}

/// Pairs bootstrap (Efron & Tibshirani, An Introduction to the Bootstrap, 1993, Sec. 9.5):
/// `resamples` times, n collisions are drawn with replacement from the n of `points`, and the
/// weighted mean e and the global hinge are refitted; mu_0 = s/(factor (1 + e)).
///
/// Needs: valid points (as [`super::fit_hinge`] checks), `factor` = 1 + 1/K. Seeded: the same
/// seed gives the same replicates. A resample is kept as the counts of each collision: the
/// oblique collisions are sorted by psi once, and a resample listed in that order is sorted, so
/// each refit costs O(n) instead of a sort. Known-answer test: the replicates equal those of the
/// direct method (list the drawn collisions, refit with [`super::fit_hinge`]) to rounding.
pub(super) fn pairs_bootstrap(
    points: &[Point],
    factor: f64,
    resamples: usize,
    seed: u64,
) -> Replicates {
    let n = points.len();
    let mut out = Replicates::default();
    if n == 0 {
        out.failed = resamples;
        return out;
    }
    let mut sorted: Vec<usize> = (0..n).filter(|&i| points[i].hinge.is_some()).collect();
    let psi = |i: usize| points[i].hinge.map_or(0.0, |h| h.0);
    sorted.sort_by(|&a, &b| psi(a).total_cmp(&psi(b)));
    let mut rng = StdRng::seed_from_u64(seed);
    let mut counts = vec![0u32; n];
    let (mut x, mut b, mut w) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..resamples {
        counts.fill(0);
        for _ in 0..n {
            counts[rng.random_range(0..n)] += 1;
        }
        let (mut swe, mut swee) = (0.0, 0.0);
        for (p, &c) in points.iter().zip(&counts) {
            let c = f64::from(c);
            swe += c * p.we;
            swee += c * p.we * p.e;
        }
        let e_mean = swee / swe;
        x.clear();
        b.clear();
        w.clear();
        for &i in &sorted {
            if let Some((psi, beta, wb)) = points[i].hinge {
                for _ in 0..counts[i] {
                    x.push(psi);
                    b.push(beta);
                    w.push(wb);
                }
            }
        }
        if x.len() < 3 {
            out.failed += 1;
            continue;
        }
        let h = hinge_sorted(&x, &b, &w);
        if h.shape != HingeShape::Both {
            out.failed += 1;
            continue;
        }
        out.e.push(e_mean);
        out.beta0.push(h.beta0);
        out.slope.push(h.slope);
        out.mu0.push(h.slope / (factor * (1.0 + e_mean)));
        out.kink.push(h.kink_psi);
    }
    out
}

/// The 2.5% and 97.5% points of `v` (sorted in place), by linear interpolation between order
/// statistics (Hyndman & Fan type 7, numpy's default). `None` for fewer than 2 values.
pub(super) fn percentile_interval(v: &mut [f64]) -> Option<(f64, f64)> {
    if v.len() < 2 {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let h = (v.len() - 1) as f64 * p;
        let lo = h.floor() as usize;
        let hi = (lo + 1).min(v.len() - 1);
        v[lo] + (h - lo as f64) * (v[hi] - v[lo])
    };
    Some((q(0.025), q(0.975)))
}

#[cfg(test)]
mod tests {
    use super::super::fit_hinge;
    use super::*;

    #[test]
    fn percentiles_match_numpy_type_7() {
        // numpy.percentile(range(11), [2.5, 97.5]) = [0.25, 9.75].
        let mut v: Vec<f64> = (0..11).rev().map(f64::from).collect();
        let (lo, hi) = percentile_interval(&mut v).unwrap();
        assert!((lo - 0.25).abs() < 1e-15 && (hi - 9.75).abs() < 1e-15);
        assert_eq!(percentile_interval(&mut [1.0]), None);
    }

    /// The counting method against the direct one: the same draws, the drawn collisions listed in
    /// draw order and refitted by `fit_hinge` (which sorts), the weighted mean summed in draw order.
    #[test]
    fn counts_equal_the_direct_resampling() {
        let mut rng = StdRng::seed_from_u64(3);
        let points: Vec<Point> = (0..40)
            .map(|i| {
                let psi: f64 = rng.random_range(0.0..4.0);
                let noise: f64 = rng.random_range(-0.1..0.1);
                Point {
                    e: 0.9 + rng.random_range(-0.05..0.05),
                    we: rng.random_range(0.5..2.0),
                    // Every fifth collision head-on; a few exact ties in psi.
                    hinge: (i % 5 != 0).then_some((
                        if i % 7 == 0 { 1.0 } else { psi },
                        (-1.0 + 1.2 * psi).min(0.5) + noise,
                        rng.random_range(0.5..2.0),
                    )),
                }
            })
            .collect();
        let factor = 3.5;
        let got = pairs_bootstrap(&points, factor, 200, 11);
        let mut rng = StdRng::seed_from_u64(11);
        let mut want = Replicates::default();
        for _ in 0..200 {
            let draws: Vec<usize> = (0..points.len())
                .map(|_| rng.random_range(0..points.len()))
                .collect();
            let (swe, swee) = draws.iter().fold((0.0, 0.0), |(a, b), &i| {
                (a + points[i].we, b + points[i].we * points[i].e)
            });
            let e = swee / swe;
            let h: Vec<(f64, f64, f64)> = draws.iter().filter_map(|&i| points[i].hinge).collect();
            let psi: Vec<f64> = h.iter().map(|p| p.0).collect();
            let beta: Vec<f64> = h.iter().map(|p| p.1).collect();
            let wb: Vec<f64> = h.iter().map(|p| p.2).collect();
            match fit_hinge(&psi, &beta, &wb) {
                Ok(f) if f.shape == HingeShape::Both => {
                    want.e.push(e);
                    want.beta0.push(f.beta0);
                    want.slope.push(f.slope);
                    want.mu0.push(f.slope / (factor * (1.0 + e)));
                    want.kink.push(f.kink_psi);
                }
                _ => want.failed += 1,
            }
        }
        assert_eq!(got.failed, want.failed);
        assert_eq!(got.e.len(), 200 - want.failed);
        // Only the order of the sums differs: agreement to a few ulps of O(1) numbers.
        for (g, w) in [
            (&got.e, &want.e),
            (&got.beta0, &want.beta0),
            (&got.slope, &want.slope),
            (&got.mu0, &want.mu0),
            (&got.kink, &want.kink),
        ] {
            for (a, b) in g.iter().zip(w) {
                assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} vs {b}");
            }
        }
    }
}
