//! Moved to the I/O layer: [`crate::data::fit_input`]. This re-export keeps the old path working
//! for the modules that still use it (`cli::fit`, `cli::bench`, `benches/fit.rs`,
//! `tests/bench_methods.rs`); new code should import from `data::fit_input`.

pub use crate::data::fit_input::*;
