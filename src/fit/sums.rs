//! Per-point sums and rows of the global search, for data of any size.
//!
//! The search's cost is (cells) x (points) (see [`super::search`]): every cell bound, grid node
//! and grid row is a pass over the points. Small data (below [`PARALLEL_MIN_POINTS`]; the
//! shipped files have 120 points) are summed in one run on the calling thread. Large data are
//! cut into fixed chunks of [`CHUNK`] points summed on all cores (rayon), and the chunks' sums
//! are added in chunk order: the result depends on the chunk size, never on the number of
//! threads or their timing, so a fit is reproducible. A run is summed as its caller's `part`
//! sums it: in point order, or in four lanes where a pass says so (the power law's passes and
//! nodes, the separable cell bound's kernel; each lane in point order, the lanes added in
//! pairs), the same on every machine.
//! The reordering changes a sum of n positive terms by at most about n u relative (u = 1.1e-16:
//! 1e-11 for 100 000 points), far below the search's tolerance (1e-7 relative).

use rayon::prelude::*;
use std::ops::Range;

/// Fewer points than this are summed in point order on the calling thread.
pub const PARALLEL_MIN_POINTS: usize = 16_384;
/// Points per chunk of a parallel sum or row (fixed: the sums depend on it).
pub const CHUNK: usize = 4096;

/// Whether `n` points take the parallel path.
pub fn is_large(n: usize) -> bool {
    n >= PARALLEL_MIN_POINTS
}

/// The K sums over the points 0..n that `part` gives over a range of them: one call over
/// every point for small data, one per chunk for large data, the chunks' sums then added in
/// chunk order (see the module doc).
pub fn sum<const K: usize>(n: usize, part: impl Fn(Range<usize>) -> [f64; K] + Sync) -> [f64; K] {
    if !is_large(n) {
        return part(0..n);
    }
    let parts: Vec<[f64; K]> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| crate::cpu::fast(|| part(c * CHUNK..((c + 1) * CHUNK).min(n))))
        .collect();
    let mut s = [0.0; K];
    for p in parts {
        for k in 0..K {
            s[k] += p[k];
        }
    }
    s
}

/// `out[i] = f(i)` for every i (each value is computed alone, so the order does not matter; in
/// parallel for large data).
pub fn fill(out: &mut [f64], f: impl Fn(usize) -> f64 + Sync) {
    if !is_large(out.len()) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = f(i);
        }
        return;
    }
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, o)| {
        crate::cpu::fast(|| {
            for (j, x) in o.iter_mut().enumerate() {
                *x = f(c * CHUNK + j);
            }
        })
    });
}

/// `f(start, out[start..start + len])` over consecutive pieces covering `out`: the whole of it
/// for small data, chunks of [`CHUNK`] in parallel for large data (for evaluations that work on
/// several points at once; each value must depend on its point alone).
pub fn fill_chunks(out: &mut [f64], f: impl Fn(usize, &mut [f64]) + Sync) {
    if !is_large(out.len()) {
        f(0, out);
        return;
    }
    out.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, o)| crate::cpu::fast(|| f(c * CHUNK, o)));
}

thread_local! {
    /// Buffers [`with_scratch`] lends, kept by each thread between calls.
    static SCRATCH: std::cell::RefCell<Vec<Vec<f64>>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// `f` with K buffers of `len` values each, lent by the calling thread and kept for its next
/// call: buffer k set to `init[k]` everywhere, or with `None` holding whatever it held (finite
/// or not: for a buffer `f` writes in full before reading). Why: the per-chunk buffers of the
/// Jacobian and of the master curve's evaluations were allocated afresh, zeroed by the
/// allocator and freed at each chunk of each pass (a fifth of the exact Jacobian's time on
/// 100 000 points, page faults included); a thread's buffers are warm in its cache, and
/// filling those that are written anyway cost a tenth of the Jacobian again. A nested call
/// (from `f`, or from a task rayon runs on this thread meanwhile) finds the buffers lent and
/// makes its own.
pub fn with_scratch<const K: usize, R>(
    len: usize,
    init: [Option<f64>; K],
    f: impl FnOnce(&mut [Vec<f64>; K]) -> R,
) -> R {
    let mut bufs: [Vec<f64>; K] =
        SCRATCH.with(|s| std::array::from_fn(|_| s.borrow_mut().pop().unwrap_or_default()));
    for (b, v) in bufs.iter_mut().zip(init) {
        match v {
            Some(v) => {
                b.clear();
                b.resize(len, v);
            }
            None => b.resize(len, f64::NAN),
        }
    }
    let r = f(&mut bufs);
    SCRATCH.with(|s| s.borrow_mut().extend(bufs));
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_sums_are_in_point_order_and_large_ones_independent_of_the_threads() {
        // Terms whose sum depends on the order of the additions (1e16 + 1 - 1e16 ...).
        let term = |i: usize| {
            let x = if i % 3 == 0 {
                1e16
            } else {
                1.0 + i as f64 * 1e-3
            };
            [x, -x * 0.5]
        };
        let part = |r: Range<usize>| {
            let mut s = [0.0, 0.0];
            for i in r {
                let t = term(i);
                s[0] += t[0];
                s[1] += t[1];
            }
            s
        };
        let n = 1000;
        let mut s = [0.0, 0.0];
        for i in 0..n {
            let t = term(i);
            s[0] += t[0];
            s[1] += t[1];
        }
        assert_eq!(sum(n, part), s, "small data: the plain loop, bit for bit");
        // Large data: the same on one thread and on four (fixed chunks, ordered reduction).
        let n = 3 * PARALLEL_MIN_POINTS + 17;
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let four = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        let a = one.install(|| sum(n, part));
        let b = four.install(|| sum(n, part));
        assert_eq!(a, b);
        // Every point counted once (chunk tails included): integer terms sum exactly.
        let c = sum(n, |r| [r.map(|i| i as f64).sum::<f64>()]);
        assert_eq!(c[0], (n * (n - 1) / 2) as f64);
    }

    /// Lent buffers given a value hold it whatever the last call left in them, those without
    /// one the last values, and a nested call gets buffers of its own.
    #[test]
    fn scratch_buffers_start_at_their_values_and_nest() {
        with_scratch(100, [Some(1.0), Some(0.0)], |[a, b]| {
            a.fill(7.0);
            b.fill(8.0);
        });
        let seen = with_scratch(50, [Some(2.0), Some(-3.0)], |[a, b]| {
            let inner = with_scratch(10, [Some(4.0)], |[c]| {
                c[0] = 5.0;
                c.clone()
            });
            a[0] = 9.0;
            (a.clone(), b.clone(), inner)
        });
        assert_eq!(seen.0.len(), 50);
        assert_eq!(seen.0[0], 9.0);
        assert!(seen.0[1..].iter().all(|&x| x == 2.0));
        assert_eq!(seen.1, vec![-3.0; 50]);
        assert_eq!(seen.2[0], 5.0);
        assert!(seen.2[1..].iter().all(|&x| x == 4.0) && seen.2.len() == 10);
        // Without a value, the length is set and the values are left: the last call's two
        // buffers (in either order) where they were that long, NaN beyond.
        let (p, q) = with_scratch(60, [None, None], |[a, b]| (a.clone(), b.clone()));
        assert_eq!((p.len(), q.len()), (60, 60));
        let (p50, q50) = (p[..50].to_vec(), q[..50].to_vec());
        assert!(
            (p50 == seen.0 && q50 == seen.1) || (p50 == seen.1 && q50 == seen.0),
            "{p50:?} {q50:?}"
        );
        assert!(p[50..].iter().chain(&q[50..]).all(|x| x.is_nan()));
    }

    #[test]
    fn fill_is_elementwise_at_every_size() {
        for n in [5, PARALLEL_MIN_POINTS + 3] {
            let mut v = vec![0.0; n];
            fill(&mut v, |i| (i as f64).sqrt());
            assert!(v.iter().enumerate().all(|(i, x)| *x == (i as f64).sqrt()));
        }
    }
}
