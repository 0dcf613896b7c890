//! The data on the fit's figures: markers and error bars drawn once per pixel position, and a
//! group whose markers land on more than [`MAX_MARKERS`] pixel positions drawn as a density.
//!
//! plotters places every element on whole pixels, so two points that land on the same pixel
//! give the same SVG element: drawing it once leaves the picture as it was (100 000 rows
//! repeating 120 measurements drew 100 000 markers, 45 MB of SVG and a second of CPU, for 120
//! visible ones). Markers on more than MAX_MARKERS positions are an opaque blob that no reader
//! can count and no viewer renders quickly (100 000 rows of distinct sizes: 45 MB, 12 s to
//! rasterise), so such a group is drawn as squares of BLOCK_PX pixels shaded by the log of the
//! number of points in each, and its error bars are left out; the legend says both.

use super::svg_err;
use crate::plot::PlotFailure;
use plotters::coord::CoordTranslate;
use plotters::element::{ErrorBar, Rectangle};
use plotters::prelude::*;
use std::collections::HashSet;

/// Marker positions (whole pixels) of a group drawn at most; beyond, it is a density.
pub const MAX_MARKERS: usize = 5000;

/// The side of a density square, in pixels.
pub const BLOCK_PX: i32 = 4;

/// `pts` with every point after the first that lands on the same pixel left out.
pub fn one_per_pixel<'a, DB, CT>(
    chart: &ChartContext<'a, DB, CT>,
    pts: &[(f64, f64)],
) -> Vec<(f64, f64)>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let area = chart.plotting_area();
    let mut seen = HashSet::new();
    pts.iter()
        .copied()
        .filter(|p| seen.insert(area.map_coordinate(p)))
        .collect()
}

/// Vertical error bars (x, lo, y, hi) with whiskers `width` pixels wide, each pixel position
/// drawn once.
pub fn draw_error_bars<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    bars: impl Iterator<Item = (f64, f64, f64, f64)>,
    style: ShapeStyle,
    width: u32,
) -> Result<(), PlotFailure>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let area = chart.plotting_area();
    let mut seen = HashSet::new();
    let kept: Vec<_> = bars
        .filter(|&(x, lo, y, hi)| {
            let at = |y| area.map_coordinate(&(x, y));
            seen.insert((at(lo), at(y), at(hi)))
        })
        .collect();
    chart
        .draw_series(
            kept.into_iter()
                .map(|(x, lo, y, hi)| ErrorBar::new_vertical(x, lo, y, hi, style, width)),
        )
        .map(|_| ())
        .map_err(svg_err)
}

/// Draws `pts` as squares of BLOCK_PX pixels (from the plotting area's corner) in colour `c`,
/// opacity growing with the log of the points in each (0.2 for one point, 1 for the most);
/// points outside the plotting area are not counted. Returns the most points in one square (0
/// when none was inside).
pub fn draw_density<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    pts: &[(f64, f64)],
    c: RGBColor,
) -> Result<usize, PlotFailure>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let area = chart.plotting_area();
    let (xs, ys) = area.get_pixel_range();
    let mut counts: std::collections::BTreeMap<(i32, i32), usize> = Default::default();
    for p in pts {
        let (x, y) = area.map_coordinate(p);
        if xs.contains(&x) && ys.contains(&y) {
            let block = ((x - xs.start) / BLOCK_PX, (y - ys.start) / BLOCK_PX);
            *counts.entry(block).or_default() += 1;
        }
    }
    let most = counts.values().copied().max().unwrap_or(0);
    let pixels = area.strip_coord_spec();
    let span = (most as f64).ln();
    for (&(bx, by), &n) in &counts {
        let opacity = if span > 0.0 {
            0.2 + 0.8 * (n as f64).ln() / span
        } else {
            1.0
        };
        let (x0, y0) = (bx * BLOCK_PX, by * BLOCK_PX);
        pixels
            .draw(&Rectangle::new(
                [(x0, y0), (x0 + BLOCK_PX, y0 + BLOCK_PX)],
                c.mix(opacity).filled(),
            ))
            .map_err(svg_err)?;
    }
    Ok(most)
}

/// The legend's words for a group drawn as a density whose fullest square holds `most` points.
pub fn density_note(most: usize) -> String {
    format!(
        "data as density: {BLOCK_PX} px squares shaded by log count (1 to {most} points); \
         error bars left out"
    )
}
