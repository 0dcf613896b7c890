//! Many collisions of one camera measured together: the position noise pooled over all of them,
//! then every collision measured with it (docs/physics.md §5.3).
//!
//! **Why pool**: the noise is the camera's, the same for every collision, and a fit of 10 frames
//! estimates it poorly on its own; the residuals of all fits together estimate it well. Without
//! residual degrees of freedom at all (3 frames a phase with free fits) the camera's stated
//! accuracy s x subpixel stands in, as in [`measure_collision`].
//!
//! A collision that cannot be measured (too few frames, receding spheres) is listed in
//! [`Batch::skipped`] with its error, not dropped silently; a spin that was not measured (NaN)
//! enters Walton's measurement as 0 and is listed in [`Batch::unmeasured_spins`].

use super::{Eq8Inputs, FitKind, Frame, Measurement, analyse, measure_collision, split_at_contact};
use crate::contact::Material;
use crate::error::Error;

/// The spin columns of the tracks schema, in the order of a collision's `spins_rad_s`.
pub const SPIN_NAMES: [&str; 4] = ["w1z_rad_s", "w2z_rad_s", "w1z_post_rad_s", "w2z_post_rad_s"];

/// One collision's tracks.
#[derive(Debug, Clone, Copy)]
pub struct CollisionInput<'a> {
    /// Frames sorted by time.
    pub frames: &'a [Frame],
    /// Index of the first post-collision frame when known; found from the tracks otherwise.
    pub split: Option<usize>,
    pub d1_m: f64,
    pub d2_m: f64,
    /// Spins about z from markers [1 pre, 2 pre, 1 post, 2 post], rad/s; NaN where not measured.
    pub spins_rad_s: Option<[f64; 4]>,
}

/// What is the same for every collision of the batch.
#[derive(Debug, Clone, Copy)]
pub struct BatchOptions {
    pub material: Material,
    /// Inertia factor K = 4I/(m d^2).
    pub inertia_k: f64,
    pub kind: FitKind,
    pub eq8: Eq8Inputs,
}

/// The measurements of a batch; indices refer to the input slice.
#[derive(Debug, Clone)]
pub struct Batch {
    pub measured: Vec<(usize, Measurement)>,
    pub skipped: Vec<(usize, Error)>,
    /// The pooled position noise used for every error, m.
    pub sigma_pos_m: f64,
    /// Collisions with spins given but some not measured, and which (names of [`SPIN_NAMES`]).
    pub unmeasured_spins: Vec<(usize, Vec<&'static str>)>,
}

/// Measures every collision with one pooled noise estimate (see the module doc).
pub fn measure_batch(inputs: &[CollisionInput], options: &BatchOptions) -> Batch {
    let kind = options.kind;
    let mut splits = Vec::with_capacity(inputs.len());
    let mut skipped = Vec::new();
    let (mut rss, mut dof) = (0.0, 0usize);
    for (i, c) in inputs.iter().enumerate() {
        let split = c
            .split
            .map(Ok)
            .unwrap_or_else(|| split_at_contact(c.frames, kind));
        match split.and_then(|s| analyse(c.frames, s, c.d1_m, c.d2_m, kind).map(|k| (s, k))) {
            Ok((s, k)) => {
                rss += k.rss_m2;
                dof += k.dof;
                splits.push(Some(s));
            }
            Err(e) => {
                skipped.push((i, e));
                splits.push(None);
            }
        }
    }
    let sigma = if dof > 0 {
        (rss / dof as f64).sqrt()
    } else {
        options.eq8.s_subpixels * options.eq8.subpixel_m
    };
    let mut measured = Vec::new();
    let mut unmeasured_spins = Vec::new();
    for (i, (c, split)) in inputs.iter().zip(&splits).enumerate() {
        let Some(split) = *split else { continue };
        let spins = c.spins_rad_s.unwrap_or([0.0; 4]);
        let missing: Vec<&'static str> = (0..4)
            .filter(|&k| spins[k].is_nan())
            .map(|k| SPIN_NAMES[k])
            .collect();
        match measure_collision(
            c.frames,
            split,
            c.d1_m,
            c.d2_m,
            &options.material,
            options.inertia_k,
            spins.map(|w| if w.is_nan() { 0.0 } else { w }),
            kind,
            &options.eq8,
            Some(sigma),
        ) {
            Ok(m) => {
                if !missing.is_empty() {
                    unmeasured_spins.push((i, missing));
                }
                measured.push((i, m));
            }
            Err(e) => skipped.push((i, e)),
        }
    }
    skipped.sort_by_key(|(i, _)| *i);
    Batch {
        measured,
        skipped,
        sigma_pos_m: sigma,
        unmeasured_spins,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    /// Two spheres of 10 mm approaching head-on at 1 m/s each and separating at 0.8 m/s each
    /// (e = 0.8 by construction), touching at t = 0, sampled every ms without noise.
    fn head_on() -> Vec<Frame> {
        (-10..=10)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let x = if t < 0.0 { -t } else { 0.8 * t };
                Frame {
                    t_s: t,
                    r1_m: [-0.005 - x, 0.0],
                    r2_m: [0.005 + x, 0.0],
                }
            })
            .collect()
    }

    #[test]
    fn pooled_batch_measures_e_and_lists_what_it_could_not() {
        let frames = head_on();
        let few = &frames[..2];
        let m = Material::preset("nylon").unwrap();
        let inputs = [
            CollisionInput {
                frames: &frames,
                split: None,
                d1_m: 0.01,
                d2_m: 0.01,
                spins_rad_s: Some([1.0, f64::NAN, 2.0, f64::NAN]),
            },
            CollisionInput {
                frames: few,
                split: None,
                d1_m: 0.01,
                d2_m: 0.01,
                spins_rad_s: None,
            },
        ];
        let options = BatchOptions {
            material: m,
            inertia_k: 0.4,
            kind: FitKind::Free,
            eq8: Eq8Inputs {
                s_subpixels: 2.0,
                subpixel_m: 1e-4,
            },
        };
        let b = measure_batch(&inputs, &options);
        assert_eq!(b.measured.len(), 1);
        // Straight-line tracks: the quadratic fits are exact, so e is 0.8 to rounding.
        assert!(
            (b.measured[0].1.measured.e - 0.8).abs() < 1e-9,
            "{:?}",
            b.measured[0].1.measured
        );
        assert_eq!(b.skipped.len(), 1);
        assert_eq!(b.skipped[0].0, 1);
        assert_eq!(
            b.unmeasured_spins,
            vec![(0, vec!["w2z_rad_s", "w2z_post_rad_s"])]
        );
    }
}
