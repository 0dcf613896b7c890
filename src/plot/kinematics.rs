//! The camera study: relative scatter and bias of measured e against the normal impact speed,
//! one line per camera, solid for free quadratic fits, dashed for fixed-gravity fits.

use super::{PlotError, PlotFailure, log_axis};
use crate::experiment::StudyPoint;
use plotters::prelude::*;

/// Renders the camera study as an SVG string (two panels: scatter, bias).
pub fn camera_study_svg(points: &[StudyPoint], title: &str) -> Result<String, PlotError> {
    draw(points, title).map_err(PlotError::of("camera_study.svg"))
}

fn draw(points: &[StudyPoint], title: &str) -> Result<String, PlotFailure> {
    let mut cameras: Vec<&str> = Vec::new();
    for p in points {
        if !cameras.contains(&p.camera.as_str()) {
            cameras.push(&p.camera);
        }
    }
    let ok = |p: &&StudyPoint| p.scatter.is_finite() && p.scatter > 0.0;
    let v_min = points
        .iter()
        .map(|p| p.v_n_m_s)
        .fold(f64::INFINITY, f64::min);
    let v_max = points.iter().map(|p| p.v_n_m_s).fold(0.0, f64::max);
    let s_min = points
        .iter()
        .filter(ok)
        .map(|p| 100.0 * p.scatter)
        .fold(f64::INFINITY, f64::min);
    let s_max = points
        .iter()
        .filter(ok)
        .map(|p| 100.0 * p.scatter)
        .fold(0.0, f64::max);
    let b_abs = points
        .iter()
        .filter(ok)
        .map(|p| (100.0 * p.bias).abs())
        .fold(0.5, f64::max);
    let (Some(v_axis), Some(s_axis)) = (log_axis(v_min, v_max, 1.3), log_axis(s_min, s_max, 1.5))
    else {
        return Err(PlotFailure::NothingToDraw(
            "no measurable point in the camera study".into(),
        ));
    };
    // What the panels leave out, said under them: a field of view of 1e-6 m leaves two frames
    // per phase, free fits then measure nothing, and their lines had vanished without a word.
    let mut notes = Vec::new();
    for (fit, name) in [
        ("free", "free quadratic"),
        ("fixed_gravity", "fixed-gravity"),
    ] {
        if !points.iter().any(|p| p.fit == fit && ok(&p)) {
            notes.push(format!(
                "No {name} fit line: fewer than 2 collisions measured at every speed."
            ));
        }
    }
    let left_out = points.iter().filter(|p| !ok(p)).count();
    if left_out > 0 {
        notes.push(format!(
            "{left_out} of {} camera, fit and speed points left out: fewer than 2 collisions \
             measured (camera_study.csv counts them).",
            points.len()
        ));
    }
    let mut svg = String::new();
    {
        let height = 620 + 26 * notes.len() as u32 + if notes.is_empty() { 0 } else { 10 };
        let root = SVGBackend::with_string(&mut svg, (1300, height)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| PlotFailure::backend(e);
        root.fill(&WHITE).map_err(e)?;
        let (root, footer) = root.split_vertically(620);
        let root = root.titled(title, ("sans-serif", 26)).map_err(e)?;
        let (left, right) = root.split_horizontally(650);
        let x_range = (v_axis.0..v_axis.1).log_scale();
        let mut scatter = ChartBuilder::on(&left)
            .margin(15)
            .x_label_area_size(60)
            .y_label_area_size(80)
            .build_cartesian_2d(x_range.clone(), (s_axis.0..s_axis.1).log_scale())
            .map_err(e)?;
        scatter
            .configure_mesh()
            .x_desc("normal impact speed v_n (m/s)")
            .y_desc("scatter of e_measured / e_true (%)")
            .axis_desc_style(("sans-serif", 22))
            .label_style(("sans-serif", 18))
            .draw()
            .map_err(e)?;
        let mut bias = ChartBuilder::on(&right)
            .margin(15)
            .x_label_area_size(60)
            .y_label_area_size(80)
            .build_cartesian_2d(x_range, -1.2 * b_abs..1.2 * b_abs)
            .map_err(e)?;
        bias.configure_mesh()
            .x_desc("normal impact speed v_n (m/s)")
            .y_desc("bias of e_measured / e_true (%)")
            // Ticks land a rounding away from 0 and had printed "-0.0".
            .y_label_formatter(&|v| format!("{:.1}", if v.abs() < 1e-9 { 0.0 } else { *v }))
            .axis_desc_style(("sans-serif", 22))
            .label_style(("sans-serif", 18))
            .draw()
            .map_err(e)?;
        bias.draw_series(LineSeries::new(
            [(v_axis.0, 0.0), (v_axis.1, 0.0)],
            BLACK.mix(0.4),
        ))
        .map_err(e)?;
        for (i, cam) in cameras.iter().enumerate() {
            let colour = super::colour(i);
            for fit in ["free", "fixed_gravity"] {
                let series: Vec<&StudyPoint> = points
                    .iter()
                    .filter(|p| p.camera == *cam && p.fit == fit)
                    .filter(ok)
                    .collect();
                let s: Vec<(f64, f64)> = series
                    .iter()
                    .map(|p| (p.v_n_m_s, 100.0 * p.scatter))
                    .collect();
                let b: Vec<(f64, f64)> =
                    series.iter().map(|p| (p.v_n_m_s, 100.0 * p.bias)).collect();
                let style = colour.stroke_width(2);
                if fit == "free" {
                    scatter
                        .draw_series(LineSeries::new(s.clone(), style))
                        .map_err(e)?
                        .label(cam.to_string())
                        .legend(move |(x, y)| {
                            PathElement::new([(x, y), (x + 24, y)], colour.stroke_width(3))
                        });
                    bias.draw_series(LineSeries::new(b.clone(), style))
                        .map_err(e)?;
                } else {
                    scatter
                        .draw_series(DashedLineSeries::new(s.clone(), 8, 5, style))
                        .map_err(e)?;
                    bias.draw_series(DashedLineSeries::new(b.clone(), 8, 5, style))
                        .map_err(e)?;
                }
                scatter
                    .draw_series(
                        s.iter()
                            .map(|&(x, y)| Circle::new((x, y), 4, colour.filled())),
                    )
                    .map_err(e)?;
                bias.draw_series(
                    b.iter()
                        .map(|&(x, y)| Circle::new((x, y), 4, colour.filled())),
                )
                .map_err(e)?;
            }
        }
        // Legend entries for the line styles.
        scatter
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(e)?
            .label("solid: free quadratic fits")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 24, y)], BLACK.stroke_width(2)));
        scatter
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(e)?
            .label("dashed: fixed-gravity fits")
            .legend(|(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new([(0, 0), (7, 0)], BLACK.stroke_width(2))
                    + PathElement::new([(11, 0), (18, 0)], BLACK.stroke_width(2))
                    + PathElement::new([(22, 0), (26, 0)], BLACK.stroke_width(2))
            });
        super::legend(&mut scatter, SeriesLabelPosition::UpperRight, 17)?;
        for (k, note) in notes.iter().enumerate() {
            footer
                .draw(&Text::new(
                    note.clone(),
                    (20, 6 + 26 * k as i32),
                    ("sans-serif", 18).into_font(),
                ))
                .map_err(e)?;
        }
        root.present().map_err(e)?;
    }
    Ok(svg)
}
