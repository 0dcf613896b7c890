//! The Fig. 6 fit: e, beta_0 and mu_0 of Walton's operator from measured oblique collisions
//! (docs/physics.md §4).
//!
//! Each collision, measured by [`walton::measure`], gives e_i (Eq. 4), beta_i (Eq. 5) and
//! psi_i = -v_n/|v_s|. Walton's Eq. (7) says beta(psi) = min(-1 + s psi, beta_0) with
//! s = mu_0 (1 + 1/K)(1 + e): a hinge through (0, -1) whose kink psi* = (1 + beta_0)/s separates
//! sliding (psi < psi*) from rolling (psi >= psi*) collisions. [`fit_hinge`] finds the global
//! least-squares hinge exactly (no starting guess: see its doc); [`fit`] adds e, mu_0 =
//! s/((1 + 1/K)(1 + e)), standard errors, seeded bootstrap 95% intervals and the classification.
//!
//! Elsewhere: the CSV schema of `restitution walton fit` in `data::walton` (the I/O layer), the
//! synthetic Fig. 6 experiment in `synthetic`.
//!
//! [`walton::measure`]: crate::models::walton::measure

mod bootstrap;
mod fit;
mod hinge;

pub use fit::{
    BootstrapInfo, Bound, Classified, EStats, Estimate, FitOptions, WaltonFit, Weights, fit,
};
pub use hinge::{HingeFit, HingeShape, fit_hinge};

use crate::models::walton::State;

/// One measured oblique collision: the kinematics before and after, as read from a `walton fit`
/// CSV (`data::walton`), made by the synthetic generator (`synthetic`) or by `kinematics`.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionRecord {
    /// 1-based line in the file (0 for records not read from a file).
    pub line: usize,
    /// The `collision` column, if any.
    pub id: Option<String>,
    pub pre: State,
    pub post: State,
}
