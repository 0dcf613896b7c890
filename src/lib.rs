//! `restitution`: the coefficient of restitution of colliding spheres after Labous, Rosato & Dave,
//! Phys. Rev. E 56, 5717 (1997). Physics modules are pure: no CLI, plotting or I/O.

pub mod bench;
pub mod contact;
pub mod data;
pub mod dem;
pub mod error;
pub mod experiment;
pub mod fit;
pub mod frames;
pub mod kinematics;
pub mod models;
pub mod plot;
pub mod predict;
pub mod synthetic;

pub use error::{Error, Result};
