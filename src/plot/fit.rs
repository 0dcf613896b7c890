//! Figures of `restitution fit`: `fig7.svg` (the paper's Fig. 7 with the fitted models) and
//! `residuals.svg` (normalised residuals of every fitted model).

mod fig7;
mod points;
mod residuals;

pub use fig7::fig7_svg;
pub use residuals::residuals_svg;

use super::{PlotFailure, short};
use crate::fit::dataset::{FitData, Group};
use crate::fit::result::{FitResult, ParamStatus};
use plotters::coord::CoordTranslate;
use plotters::coord::Shift;
use plotters::element::{Circle, Cross, EmptyElement, PathElement, Rectangle, TriangleMarker};
use plotters::prelude::*;

/// Pair geometries drawn each in its own colour at most; beyond, the points are one group.
const MAX_GROUPS_DRAWN: usize = 8;

/// The data's pair geometries as the figures draw them, with their labels, and whether they
/// were merged: each on its own, or, beyond MAX_GROUPS_DRAWN, every point in one group labelled
/// with their count ("100000 geometries"; 100 000 rows of distinct sizes made a legend of 100 000 rows, a curve per
/// size, and 19 s of `fit --out`).
fn drawn_groups(data: &FitData) -> (Vec<(Group, String)>, bool) {
    let groups = data.groups();
    if groups.len() <= MAX_GROUPS_DRAWN {
        return (
            groups
                .into_iter()
                .map(|g| {
                    let label = g.label();
                    (g, label)
                })
                .collect(),
            false,
        );
    }
    let all = Group {
        d_mm: groups[0].d_mm,
        d2_mm: groups[0].d2_mm,
        indices: (0..data.len()).collect(),
    };
    (vec![(all, format!("{} geometries", groups.len()))], true)
}

fn colour(g: usize) -> RGBColor {
    super::colour(g)
}

/// Draws points with group `g`'s marker: filled circle, triangle, square, cross, hollow circle,
/// hollow square (one match arm per type: plotters needs a concrete element type per series).
fn draw_markers<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    pts: &[(f64, f64)],
    g: usize,
    size: i32,
    c: RGBColor,
) -> Result<(), PlotFailure>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let filled = c.filled();
    let open = c.stroke_width(2);
    let sq = [(-size, -size), (size, size)];
    let it = pts.iter().copied();
    match g % 6 {
        0 => chart
            .draw_series(it.map(|p| Circle::new(p, size, filled)))
            .map(|_| ()),
        1 => chart
            .draw_series(it.map(|p| TriangleMarker::new(p, size + 1, filled)))
            .map(|_| ()),
        2 => chart
            .draw_series(it.map(|p| EmptyElement::at(p) + Rectangle::new(sq, filled)))
            .map(|_| ()),
        3 => chart
            .draw_series(it.map(|p| Cross::new(p, size, open)))
            .map(|_| ()),
        4 => chart
            .draw_series(it.map(|p| Circle::new(p, size, open)))
            .map(|_| ()),
        _ => chart
            .draw_series(it.map(|p| EmptyElement::at(p) + Rectangle::new(sq, open)))
            .map(|_| ()),
    }
    .map_err(svg_err)
}

/// A legend entry drawn outside the plot, so that it never covers data.
enum Sample {
    Line(RGBColor, u32),
    Dashed(RGBColor, u32),
    Marker(usize, RGBColor),
    /// A filled square: data drawn as a density.
    Block(RGBColor),
    /// No sample: the text alone.
    Text,
}

/// Draws legend entries on `area` (pixel coordinates): column `c` starts at `x0[c]`; entries
/// and lists its entries top down.
fn draw_legend(
    area: &DrawingArea<SVGBackend, Shift>,
    columns: &[(i32, Vec<(Sample, String)>)],
    font: u32,
) -> Result<(), PlotFailure> {
    let row_h = font as i32 + 10;
    let placed = columns.iter().flat_map(|(x0, entries)| {
        entries
            .iter()
            .enumerate()
            .map(move |(r, e)| (*x0, 14 + r as i32 * row_h, e))
    });
    for (x, y, (sample, text)) in placed {
        match sample {
            Sample::Line(c, w) => {
                area.draw(&PathElement::new(
                    vec![(x, y), (x + 30, y)],
                    c.stroke_width(*w),
                ))
                .map_err(svg_err)?;
            }
            Sample::Dashed(c, w) => {
                for k in 0..3 {
                    let x0 = x + k * 12;
                    area.draw(&PathElement::new(
                        vec![(x0, y), (x0 + 7, y)],
                        c.stroke_width(*w),
                    ))
                    .map_err(svg_err)?;
                }
            }
            Sample::Marker(g, c) => {
                let at = (x + 15, y);
                let (filled, open) = (c.filled(), c.stroke_width(2));
                let sq = [(-4, -4), (4, 4)];
                match g % 6 {
                    0 => area.draw(&Circle::new(at, 4, filled)),
                    1 => area.draw(&TriangleMarker::new(at, 5, filled)),
                    2 => area.draw(&(EmptyElement::at(at) + Rectangle::new(sq, filled))),
                    3 => area.draw(&Cross::new(at, 4, open)),
                    4 => area.draw(&Circle::new(at, 4, open)),
                    _ => area.draw(&(EmptyElement::at(at) + Rectangle::new(sq, open))),
                }
                .map_err(svg_err)?;
            }
            Sample::Block(c) => {
                area.draw(&Rectangle::new(
                    [(x + 9, y - 6), (x + 21, y + 6)],
                    c.filled(),
                ))
                .map_err(svg_err)?;
            }
            Sample::Text => {}
        }
        area.draw(&Text::new(
            text.clone(),
            (x + 40, y - (font as i32) / 2),
            ("sans-serif", font).into_font(),
        ))
        .map_err(svg_err)?;
    }
    Ok(())
}

/// Tick values for a log axis: 1, 2, 5 per decade over up to three decades, the powers of ten
/// over more, and over more than MAX_LABELS decades every 2nd, 5th, 10th, ... power (exponents
/// a multiple of it); over less than a factor 3 (e on a log axis usually spans 0.7-1.1) evenly
/// spaced round values, 4 to 10 of them. None for a range that is not finite, positive and
/// increasing ([`crate::plot::log_axis`] gives none such), and none below 1e-307 (the decades
/// are powers of ten, which underflow beyond).
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    // A label such as "2.5e-7" in the 16 px font is about 60 px wide and the figures' axes are
    // about 880 px long: 1, 2, 5 in each of eight decades (25 labels) had run into each other.
    const MAX_LABELS: i32 = 10;
    if !(lo > 0.0 && lo < hi && hi.is_finite()) {
        return Vec::new();
    }
    if hi / lo < 3.0 {
        let raw = (hi - lo) / 6.0;
        let p = 10f64.powi(raw.log10().floor() as i32);
        // A range of a few subnormals: its ends.
        if !(p > 0.0 && p.is_finite()) {
            return vec![lo, hi];
        }
        let step = [1.0, 2.0, 5.0, 10.0]
            .iter()
            .map(|m| m * p)
            .find(|s| (hi - lo) / s <= 10.0)
            .unwrap_or(10.0 * p);
        let first = (lo / step).ceil() as i64;
        let last = (hi / step).floor() as i64;
        return (first..=last).map(|k| k as f64 * step).collect();
    }
    // Decade by decade from the one below lo (but not below 1e-307: a decade that underflows to 0
    // would never grow), so at most about 615 of them.
    let first = (lo.log10().floor() as i32).max(-307);
    let last = hi.log10().ceil() as i32;
    let decades = last - first;
    let mantissas: &[f64] = if hi / lo < 30.0 {
        &[1.0, 2.0, 3.0, 5.0]
    } else if hi / lo <= 1e3 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let every = [1, 2, 5, 10, 20, 50, 100, 200]
        .into_iter()
        .find(|k| decades <= MAX_LABELS * k)
        .unwrap_or(500);
    let mut out = Vec::new();
    for exponent in (first..=last).filter(|x| x.rem_euclid(every) == 0) {
        // Parsed, not powi: 10^-200 rounded as the literal 1e-200 is.
        let decade: f64 = format!("1e{exponent}").parse().unwrap_or(0.0);
        for &m in mantissas {
            let t = m * decade;
            if t >= lo && t <= hi {
                out.push(t);
            }
        }
    }
    out
}

fn log_points(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| (lo.ln() + (hi.ln() - lo.ln()) * k as f64 / (n - 1) as f64).exp())
        .collect()
}

/// The fit's parameters as the tables show them: a value, a 95% bound, or "not determined" (the
/// minimiser's end on a plateau is arbitrary: printed as a value it read as a result; Fig. 7
/// draws such a fit over the data's own speeds only, where the data pin it).
fn describe(f: &FitResult) -> String {
    let parts: Vec<String> = f
        .params
        .iter()
        .map(|p| {
            let unit = crate::fit::models::unit_after(p.unit);
            let shown = |rel: &str, x: Option<f64>| match x {
                Some(x) => format!("{} {rel} {}{unit}", p.key, short(x)),
                None => format!("{} not determined", p.key),
            };
            match p.status {
                ParamStatus::Estimate | ParamStatus::IntervalLost => shown("=", Some(p.best_fit)),
                ParamStatus::LowerBound => shown(">", p.ci95.0),
                ParamStatus::UpperBound => shown("<", p.ci95.1),
                ParamStatus::Unconstrained => shown("", None),
            }
        })
        .collect();
    parts.join(", ")
}

fn svg_err(e: impl std::fmt::Display) -> PlotFailure {
    PlotFailure::backend(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside() {
        assert_eq!(log_ticks(0.45, 46.0), vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0]);
        let t = log_ticks(0.88, 1.03);
        assert!(t.len() >= 4 && t.len() <= 10, "{t:?}");
        assert!(t.iter().all(|&x| (0.88..=1.03).contains(&x)));
        assert_eq!(short(t[2]), "0.92");
    }

    #[test]
    fn ticks_end_and_stay_inside_at_the_extremes_of_f64() {
        // An infinite end made the decade loop run forever (fit --out with v_n = f64::MAX: the
        // axis's margin overflowed); a decade that underflows to 0 never grows.
        for (lo, hi) in [
            (1.0, f64::INFINITY),
            (0.0, 1.0),
            (f64::NAN, 1.0),
            (2.0, 1.0),
            (1.0, 1.0),
        ] {
            assert!(log_ticks(lo, hi).is_empty(), "{lo} {hi}");
        }
        let max = f64::MAX;
        for (lo, hi) in [
            (max / 1.25, max),
            (5e-324, 1e-320),
            (5e-324, 1e-300),
            (5e-324, max),
            (1e-320, 1.0),
            (5e-324, 1e-323),
        ] {
            let t = log_ticks(lo, hi);
            assert!(t.len() <= 100, "{lo} {hi}: {} ticks", t.len());
            assert!(t.iter().all(|&x| lo <= x && x <= hi), "{lo} {hi}: {t:?}");
        }
        // Wide ranges keep some of their decades' 1s, no more labels than fit along the axis.
        let t = log_ticks(5e-324, max);
        assert!((5..=11).contains(&t.len()), "{t:?}");
        assert_eq!(t[1], 1e-200, "{t:?}");
    }

    #[test]
    fn wide_axes_keep_their_labels_apart() {
        // Eight decades of speeds printed 25 labels on top of each other.
        assert_eq!(
            log_ticks(1e-3, 1e5),
            vec![1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5]
        );
        assert_eq!(log_ticks(8e-6, 1.2e5), vec![1e-4, 1e-2, 1.0, 100.0, 1e4]);
        assert_eq!(
            log_ticks(0.05, 20.0),
            vec![0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0]
        );
        let labels: Vec<String> = [1e-5, 2.5e-7, 0.92, 2236.423, 1e6, -0.0012346, 0.0]
            .iter()
            .map(|&x| short(x))
            .collect();
        assert_eq!(
            labels,
            ["1e-5", "2.5e-7", "0.92", "2236", "1e6", "-0.001235", "0"]
        );
    }
}
