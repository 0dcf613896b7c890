//! The fit's hot loops on large data, compiled twice: for the baseline x86-64 the binary
//! targets, and for processors with AVX2 and FMA (chosen at run time), where the four-lane
//! arithmetic of the cell bounds and the evaluations get twice the register width.
//!
//! The results are the same to the last bit: Rust never fuses a multiply and an add on its own
//! (only `mul_add` fuses, and it rounds once with the instruction or without it), and a wider
//! register changes no operation's rounding. `tests/fit_large.rs` fits the same data both ways
//! and compares the bits; [`set_baseline_only`] is the switch it uses.

use std::sync::atomic::{AtomicBool, Ordering};

static BASELINE_ONLY: AtomicBool = AtomicBool::new(false);

/// Runs every later [`fast`] call on the baseline code (`true`) or lets it use AVX2 and FMA
/// where the processor has them (`false`, the default).
pub fn set_baseline_only(on: bool) {
    BASELINE_ONLY.store(on, Ordering::Relaxed);
}

/// Whether [`fast`] uses the AVX2 and FMA code: the processor has both (std caches the answer)
/// and [`set_baseline_only`] has not switched them off.
#[inline]
pub fn uses_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        !BASELINE_ONLY.load(Ordering::Relaxed)
            && std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `f()`, compiled with AVX2 and FMA when [`uses_avx2_fma`] (`f` is a closure called once from
/// the wrapper, so it is inlined there and its body is compiled for the wider registers; what it
/// calls without inlining keeps the baseline code). A body the compiler will not inline (too
/// large, or a closure called from several places) runs as baseline code, which a profile shows
/// outside `avx2_fma`: such a body gets its own `#[target_feature]` copy behind
/// [`uses_avx2_fma`], as the master curve's evaluations have
/// ([`crate::models::viscoelastic::master::e_master_in_place`]), or through the crate's
/// `wide_copy!` macro, as the separable cell bound's pass and node sums do.
#[inline]
pub fn fast<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if uses_avx2_fma() {
        // SAFETY: the processor has the features the wrapper is compiled for.
        return unsafe { avx2_fma(f) };
    }
    f()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn avx2_fma<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Defines `fn $inner<consts>(args) -> R { body }` (`#[inline(always)]`) and `fn $name` with
/// the same signature, which calls it through a copy of its own compiled for AVX2 and FMA where
/// [`uses_avx2_fma`], else as it is: one signature for both. Why: a closure handed to [`fast`]
/// that the inliner leaves out of its wrapper runs as baseline code, and which ones it leaves
/// out moves with unrelated changes (the separable cell bound's pass and node sums each ran so,
/// a tenth of a fit); a `#[target_feature]` function of its own always has the features. The
/// same operations either way, so the same bits (see the module doc).
macro_rules! wide_copy {
    ($(#[$m:meta])* fn $name:ident;
     $(#[$im:meta])* fn $inner:ident<$(const $c:ident: $ct:ty),*>($($a:ident: $t:ty),* $(,)?)
        -> $r:ty $body:block) => {
        $(#[$im])*
        #[inline(always)]
        fn $inner<$(const $c: $ct),*>($($a: $t),*) -> $r $body

        $(#[$m])*
        fn $name<$(const $c: $ct),*>($($a: $t),*) -> $r {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                unsafe fn copy<$(const $c: $ct),*>($($a: $t),*) -> $r {
                    $inner::<$($c),*>($($a),*)
                }
                if $crate::cpu::uses_avx2_fma() {
                    // SAFETY: the processor has the features the copy is compiled for.
                    return unsafe { copy::<$($c),*>($($a),*) };
                }
            }
            $inner::<$($c),*>($($a),*)
        }
    };
}
pub(crate) use wide_copy;
