//! Wall-clock time per evaluation, measured warm: one untimed pass first, then `repeats` timed
//! batches of whole passes over the points, each batch long enough to dwarf the clock's resolution.
//! Callers pass their inputs through `black_box` and return every output (e and 1 - e), so that
//! nothing is hoisted out of the loop or dropped as unused.
//! The figure reported is the **minimum** over the batches of (batch time / evaluations): noise on
//! a shared machine only ever adds time, so the minimum is the least disturbed estimate.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// How long and how often to measure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimingPlan {
    pub repeats: usize,
    /// Each batch repeats the pass until it lasts at least this long.
    pub min_batch: Duration,
}

/// Nanoseconds per evaluation of `pass`, which evaluates `evals_per_pass` points and returns
/// something that depends on all of them (kept alive with `black_box`).
pub fn ns_per_eval<T>(
    plan: &TimingPlan,
    evals_per_pass: usize,
    mut pass: impl FnMut() -> T,
) -> f64 {
    assert!(evals_per_pass > 0);
    let t0 = Instant::now();
    black_box(pass());
    let once = t0.elapsed().max(Duration::from_nanos(1));
    let passes = (plan.min_batch.as_nanos() / once.as_nanos()).clamp(1, 10_000_000) as usize;
    let mut best = f64::INFINITY;
    for _ in 0..plan.repeats.max(1) {
        let t = Instant::now();
        for _ in 0..passes {
            black_box(pass());
        }
        let ns = t.elapsed().as_nanos() as f64 / (passes * evals_per_pass) as f64;
        best = best.min(ns);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measures_something_positive_and_finite() {
        // Only sanity (no timing assertions in tests): a positive, finite figure.
        let plan = TimingPlan {
            repeats: 2,
            min_batch: Duration::from_micros(200),
        };
        let xs: Vec<f64> = (0..16).map(|i| i as f64).collect();
        let ns = ns_per_eval(&plan, xs.len(), || xs.iter().map(|x| x.sqrt()).sum::<f64>());
        assert!(ns.is_finite() && ns > 0.0);
    }
}
