//! Fitting measured coefficients of restitution: models, least squares, comparison, reports.

pub mod compare;
pub mod dataset;
pub mod engine;
pub mod input;
pub mod lsq;
pub mod models;
pub mod report;
pub mod walton;

pub use compare::{Comparison, ComparisonRow, compare};
pub use dataset::{FitData, Group, Observation};
pub use engine::{FitOptions, FitResult, FitSet, ParamEstimate, ParamStatus, fit, fit_all};
pub use models::ModelKind;
