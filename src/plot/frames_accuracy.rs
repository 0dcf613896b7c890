//! The frame-pipeline accuracy figure: panels of an error against one condition (noise, sphere
//! size, blur, speed), one line per method, with horizontal reference levels (the paper's half
//! pixel, the aims).

use super::{PlotError, PlotFailure};
use plotters::prelude::*;

/// One line of a panel: a label and its (x, y) points (y > 0; log axes).
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// One panel: axes descriptions, whether x is logarithmic, the lines and the reference levels.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub log_x: bool,
    pub lines: Vec<Line>,
    pub references: Vec<(String, f64)>,
}

/// An axis number: at most 3 significant digits, no trailing zeros.
fn fmt_axis(x: f64) -> String {
    let s = format!("{:.3}", x);
    let s = if x.abs() >= 1.0 {
        format!("{:.1}", x)
    } else {
        s
    };
    let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s
    }
}

/// Renders panels in a grid of `columns` as one SVG; every y axis is logarithmic. Series with the
/// same label have the same colour in every panel.
pub fn accuracy_svg(panels: &[Panel], columns: usize, title: &str) -> Result<String, PlotError> {
    draw(panels, columns, title).map_err(PlotError::of("the accuracy figure"))
}

fn draw(panels: &[Panel], columns: usize, title: &str) -> Result<String, PlotFailure> {
    let columns = columns.max(1);
    let rows = panels.len().div_ceil(columns);
    let mut labels: Vec<&str> = Vec::new();
    for p in panels {
        for l in &p.lines {
            if !labels.contains(&l.label.as_str()) {
                labels.push(&l.label);
            }
        }
    }
    let mut svg = String::new();
    {
        let (w, h) = (640 * columns as u32, 60 + 470 * rows as u32);
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| PlotFailure::backend(e);
        root.fill(&WHITE).map_err(e)?;
        let root = root.titled(title, ("sans-serif", 26)).map_err(e)?;
        let areas = root.split_evenly((rows, columns));
        for (panel, area) in panels.iter().zip(areas.iter()) {
            let ys: Vec<f64> = panel
                .lines
                .iter()
                .flat_map(|l| l.points.iter().map(|p| p.1))
                .chain(panel.references.iter().map(|r| r.1))
                .filter(|y| y.is_finite() && *y > 0.0)
                .collect();
            let xs: Vec<f64> = panel
                .lines
                .iter()
                .flat_map(|l| l.points.iter().map(|p| p.0))
                .filter(|x| x.is_finite() && (!panel.log_x || *x > 0.0))
                .collect();
            if ys.is_empty() || xs.is_empty() {
                return Err(PlotFailure::NothingToDraw(format!(
                    "panel '{}' has no finite point",
                    panel.title
                )));
            }
            let (y0, y1) = ys
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(a, b), &y| (a.min(y), b.max(y)));
            let (x0, x1) = xs
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                    (a.min(x), b.max(x))
                });
            let y_range = (y0 / 2.0..y1 * 2.0).log_scale();
            let mut chart_builder = ChartBuilder::on(area);
            chart_builder
                .margin(12)
                .caption(&panel.title, ("sans-serif", 21))
                .x_label_area_size(55)
                .y_label_area_size(75);
            // The two axis kinds have different types; draw through one closure-free macro-like
            // duplication rather than boxing the coordinate system.
            macro_rules! draw {
                ($chart:expr, $xl:expr, $xh:expr) => {{
                    let mut chart = $chart;
                    chart
                        .configure_mesh()
                        .x_labels(6)
                        .y_labels(6)
                        .x_label_formatter(&|x| format!("{}", fmt_axis(*x)))
                        .y_label_formatter(&|y| format!("{}", fmt_axis(*y)))
                        .x_desc(panel.x_desc.as_str())
                        .y_desc(panel.y_desc.as_str())
                        .axis_desc_style(("sans-serif", 19))
                        .label_style(("sans-serif", 16))
                        .draw()
                        .map_err(e)?;
                    for (label, y) in &panel.references {
                        let y = *y;
                        chart
                            .draw_series(DashedLineSeries::new(
                                [($xl, y), ($xh, y)],
                                6,
                                4,
                                BLACK.mix(0.6).stroke_width(1),
                            ))
                            .map_err(e)?;
                        chart
                            .draw_series(std::iter::once(Text::new(
                                label.clone(),
                                ($xl, y * 1.12),
                                ("sans-serif", 15).into_font().color(&BLACK.mix(0.75)),
                            )))
                            .map_err(e)?;
                    }
                    for line in &panel.lines {
                        let i = labels.iter().position(|l| *l == line.label).unwrap_or(0);
                        let colour = super::colour(i);
                        let pts: Vec<(f64, f64)> = line
                            .points
                            .iter()
                            .copied()
                            .filter(|(x, y)| {
                                y.is_finite()
                                    && *y > 0.0
                                    && x.is_finite()
                                    && (!panel.log_x || *x > 0.0)
                            })
                            .collect();
                        chart
                            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                            .map_err(e)?
                            .label(line.label.clone())
                            .legend(move |(x, y)| {
                                PathElement::new([(x, y), (x + 24, y)], colour.stroke_width(3))
                            });
                        chart
                            .draw_series(
                                pts.iter()
                                    .map(|&(x, y)| Circle::new((x, y), 4, colour.filled())),
                            )
                            .map_err(e)?;
                    }
                    super::legend(&mut chart, SeriesLabelPosition::UpperRight, 15)?;
                }};
            }
            if panel.log_x {
                let (xl, xh) = (x0 / 1.3, x1 * 1.3);
                draw!(
                    chart_builder
                        .build_cartesian_2d((xl..xh).log_scale(), y_range)
                        .map_err(e)?,
                    xl,
                    xh
                );
            } else {
                let pad = 0.06 * (x1 - x0).max(1e-9);
                let (xl, xh) = (x0 - pad, x1 + pad);
                draw!(
                    chart_builder
                        .build_cartesian_2d(xl..xh, y_range)
                        .map_err(e)?,
                    xl,
                    xh
                );
            }
        }
        root.present().map_err(e)?;
    }
    Ok(svg)
}
