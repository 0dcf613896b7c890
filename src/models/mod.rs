//! The physics: each equation of the paper lives in exactly one of these modules.

pub mod fp;
pub mod plastic;
pub mod viscoelastic;
pub mod walton;
