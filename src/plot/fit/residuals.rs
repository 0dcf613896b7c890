//! `residuals.svg`: the normalised residuals of every fitted model.

use super::{
    Sample, colour, describe, draw_legend, draw_markers, drawn_groups, log_ticks, short_value,
    svg_err,
};
use crate::fit::dataset::FitData;
use crate::fit::engine::FitSet;
use crate::plot::{PlotError, PlotFailure, log_axis};
use plotters::coord::Shift;
use plotters::prelude::*;

/// `residuals.svg`: (e - model)/sigma against v_n for every fitted model, one panel each, with
/// the lines 0 and +-2.
pub fn residuals_svg(data: &FitData, set: &FitSet, title: &str) -> Result<String, PlotError> {
    draw_residuals(data, set, title).map_err(PlotError::of("residuals.svg"))
}

fn draw_residuals(data: &FitData, set: &FitSet, title: &str) -> Result<String, PlotFailure> {
    let (drawn, _) = drawn_groups(data);
    let n = set.fits.len().max(1);
    let (mut vlo, mut vhi) = (f64::INFINITY, 0.0f64);
    for o in &data.obs {
        vlo = vlo.min(o.v_n_m_s);
        vhi = vhi.max(o.v_n_m_s);
    }
    let x_range = log_axis(vlo, vhi, 1.25).ok_or_else(|| {
        PlotFailure::NothingToDraw("no speed that is a finite positive number".into())
    })?;
    let panel_h = 190u32;
    let mut buf = String::new();
    {
        let root =
            SVGBackend::with_string(&mut buf, (960, 100 + panel_h * n as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(svg_err)?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(svg_err)?;
        let (key, body) = root.split_vertically(34);
        let columns: Vec<(i32, Vec<(Sample, String)>)> = drawn
            .iter()
            .enumerate()
            .map(|(gi, (_, label))| {
                (
                    90 + 220 * gi as i32,
                    vec![(Sample::Marker(gi, colour(gi)), label.clone())],
                )
            })
            .collect();
        draw_legend(&key, &columns, 15)?;
        let panels: Vec<DrawingArea<SVGBackend, Shift>> = body.split_evenly((n, 1));
        let ylabel = if data.weighted {
            "(e - model)/sigma_e"
        } else {
            "e - model"
        };
        for (f, area) in set.fits.iter().zip(panels.iter()) {
            let rmax = f
                .normalized_residuals
                .iter()
                .fold(0.0f64, |m, r| m.max(r.abs()));
            // At most 1e300: the axis's span must be a finite number.
            let lim = (rmax * 1.15)
                .max(if data.weighted { 3.0 } else { 1e-3 })
                .min(1e300);
            let mut chart = ChartBuilder::on(area)
                .caption(
                    format!(
                        "{}: chi2/dof = {:.3}, {}",
                        f.model.name(),
                        f.reduced_chi2,
                        describe(f)
                    ),
                    ("sans-serif", 17),
                )
                .margin(8)
                .x_label_area_size(40)
                .y_label_area_size(78)
                .build_cartesian_2d(
                    (x_range.0..x_range.1)
                        .log_scale()
                        .with_key_points(log_ticks(x_range.0, x_range.1)),
                    -lim..lim,
                )
                .map_err(svg_err)?;
            chart
                .configure_mesh()
                .x_desc("normal impact speed v_n (m/s)")
                .y_desc(ylabel)
                .axis_desc_style(("sans-serif", 16))
                .label_style(("sans-serif", 14))
                .x_label_formatter(&|v| short_value(*v))
                .y_labels(7)
                .y_label_formatter(&|r| format!("{}", (r * 100.0).round() / 100.0))
                .light_line_style(WHITE)
                .bold_line_style(RGBColor(225, 225, 225))
                .draw()
                .map_err(svg_err)?;
            chart
                .draw_series(LineSeries::new(
                    vec![(x_range.0, 0.0), (x_range.1, 0.0)],
                    BLACK.stroke_width(1),
                ))
                .map_err(svg_err)?;
            if data.weighted {
                for y in [-2.0, 2.0] {
                    chart
                        .draw_series(DashedLineSeries::new(
                            vec![(x_range.0, y), (x_range.1, y)],
                            6,
                            4,
                            RGBColor(120, 120, 120).stroke_width(1),
                        ))
                        .map_err(svg_err)?;
                }
            }
            for (gi, (g, _)) in drawn.iter().enumerate() {
                let c = colour(gi);
                let pts: Vec<(f64, f64)> = g
                    .indices
                    .iter()
                    .map(|&i| {
                        (
                            data.obs[i].v_n_m_s,
                            f.normalized_residuals[i].clamp(-lim, lim),
                        )
                    })
                    .collect();
                draw_markers(&mut chart, &pts, gi, 3, c)?;
            }
        }
        root.present().map_err(svg_err)?;
    }
    Ok(buf)
}
