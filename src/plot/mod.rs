//! All figures, as SVG through plotters' SVG backend (no system fonts: text stays SVG <text>).
//! One submodule per figure family; they take plain numbers, never read files.
//!
//! plotters' SVG font sizes come out smaller than asked, so sizes here are chosen by looking at
//! the rendered figures, not by the nominal point size.
pub mod fit;
pub mod kinematics;
pub mod walton;
