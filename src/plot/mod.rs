//! All figures, as SVG through plotters' SVG backend (no system fonts: text stays SVG <text>).
//! One submodule per figure family; they take plain numbers, never read files.
//!
//! plotters' SVG font sizes come out smaller than asked, so sizes here are chosen by looking at
//! the rendered figures, not by the nominal point size.
use plotters::style::RGBColor;

/// Okabe & Ito's colour-blind-safe palette (without black and yellow, which carry the models and
/// vanish on white), shared by every figure so that series look alike across them.
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// The palette's colour for series number `i` (cycling).
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

pub mod bench;
pub mod fit;
pub mod kinematics;
pub mod walton;
