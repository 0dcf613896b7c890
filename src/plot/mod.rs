//! All figures, as SVG through plotters' SVG backend (no system fonts: text stays SVG `<text>`).
//! One submodule per figure family; they take plain numbers, never read files.
//!
//! plotters' SVG font sizes come out smaller than asked, so sizes here are chosen by looking at
//! the rendered figures, not by the nominal point size.
use plotters::chart::{ChartContext, SeriesLabelPosition};
use plotters::coord::CoordTranslate;
use plotters::prelude::DrawingBackend;
use plotters::style::{BLACK, Color, RGBColor, WHITE};

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

#[cfg(feature = "io")]
pub mod bench;
/// Draws a chart's legend in the house style: a nearly opaque white box with a grey border, at
/// `position`, labels at `font_px` (nominal; see the module note on SVG font sizes).
pub fn legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    font_px: u32,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(position)
        .label_font(("sans-serif", font_px))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.5))
        .draw()
        .map_err(|e| format!("drawing a legend: {e}"))
}

pub mod export;
pub mod fit;
pub mod frames;
pub mod frames_accuracy;
pub mod kinematics;
pub mod walton;
