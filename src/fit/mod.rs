//! Fitting measured coefficients of restitution: models, least squares, a certified global
//! search, uncertainties, comparison, reports.

pub mod beyond;
pub mod bnb;
pub mod compare;
pub mod covariance;
pub mod dataset;
pub mod engine;
pub mod kinks;
pub mod landscape;
pub mod lsq;
pub mod models;
pub mod objective;
pub mod polish;
pub mod powerlaw;
pub mod profile;
pub mod qp;
pub mod result;
pub mod scalar;
pub mod search;
pub mod slice;
pub mod sums;
pub mod vexp;
pub mod walton;

pub use compare::{Comparison, ComparisonRow, compare};
pub use dataset::{FitData, Group, Observation};
pub use engine::{FitOptions, FitSet, fit, fit_all};
pub use models::ModelKind;
pub use result::{FitResult, GlobalSearch, ParamEstimate, ParamStatus};
