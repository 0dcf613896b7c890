//! Handing a fitted contact law to simulation engines (docs/physics.md §9): pure numbers, no
//! files (those are `crate::data::export`'s).
//!
//! - [`damped`]: e of Hertz contacts with the dashpots DEM engines use: the viscoelastic one of
//!   Eqs. 9-10 and Tsuji's, whose e does not depend on the speed;
//! - [`engines`]: LAMMPS's and LIGGGHTS's parameters from the toolkit's contact quantities;
//! - [`range`], [`law`]: laws fitted to e(v) over a scene's speed range (constant e, one best eta,
//!   a table) with their largest deviations, and the simplest law within a tolerance;
//! - [`scene`], [`translate`]: the contacts of a scene and everything exported for it.

pub mod damped;
pub mod engines;
pub mod law;
pub mod range;
pub mod scene;
pub mod translate;

/// First-order Richardson extrapolation to a zero time step: from e at step h (`e_h`) and at h/2
/// (`e_half`), 2 e_half - e_h removes an error proportional to h. LAMMPS's velocity Verlet
/// evaluates the damping force with the half-step velocity, which makes its error in e first
/// order (measured: (e - e_0) h^-1 constant to 1% over h = T/2000 .. T/16000 once the phase of the
/// contact start relative to the steps is averaged out; tests/lammps.rs).
pub fn richardson_first_order(e_h: f64, e_half: f64) -> f64 {
    2.0 * e_half - e_h
}
