//! `residuals.svg`: the normalised residuals of every fitted model.

use super::points::{BLOCK_PX, MAX_MARKERS, draw_density, one_per_pixel};
use super::{
    Sample, colour, describe, draw_legend, draw_markers, drawn_groups, log_ticks, svg_err,
};
use crate::fit::dataset::FitData;
use crate::fit::engine::FitSet;
use crate::plot::{PlotError, PlotFailure, log_axis, short};
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
    // The key: KEY_COLUMNS groups to a row, and a row for the density's note where a group has
    // enough points to need one (left empty where no panel drew one).
    const KEY_COLUMNS: usize = 4;
    const KEY_ROW: u32 = 25;
    let note_row = drawn.iter().any(|(g, _)| g.indices.len() > MAX_MARKERS);
    let key_rows = drawn.len().div_ceil(KEY_COLUMNS) as u32 + note_row as u32;
    let key_h = 34 + KEY_ROW * key_rows.saturating_sub(1);
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (960, 66 + key_h + panel_h * n as u32))
            .into_drawing_area();
        root.fill(&WHITE).map_err(svg_err)?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(svg_err)?;
        let (key, body) = root.split_vertically(key_h);
        let panels: Vec<DrawingArea<SVGBackend, Shift>> = body.split_evenly((n, 1));
        let ylabel = if data.weighted {
            "(e - model)/sigma_e"
        } else {
            "e - model"
        };
        let mut any_dense = false;
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
                        "{}: chi2/dof = {}, {}",
                        f.model.name(),
                        short(f.reduced_chi2),
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
                .x_label_formatter(&|v| short(*v))
                .y_labels(7)
                // Shortest form: a residual of 1e100 had printed its 101 digits.
                .y_label_formatter(&|r| {
                    if r.abs() < 1e4 {
                        format!("{}", (r * 100.0).round() / 100.0)
                    } else {
                        short(*r)
                    }
                })
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
                let shown = one_per_pixel(&chart, &pts);
                if shown.len() > MAX_MARKERS {
                    any_dense = true;
                    draw_density(&mut chart, &pts, c)?;
                } else {
                    draw_markers(&mut chart, &shown, gi, 3, c)?;
                }
            }
        }
        // The key last: it names the density where a panel drew one.
        let mut columns: Vec<(i32, Vec<(Sample, String)>)> = (0..KEY_COLUMNS.min(drawn.len()))
            .map(|c| (90 + 220 * c as i32, Vec::new()))
            .collect();
        for (gi, (_, label)) in drawn.iter().enumerate() {
            let sample = Sample::Marker(gi, colour(gi));
            columns[gi % KEY_COLUMNS].1.push((sample, label.clone()));
        }
        if any_dense {
            // Column 0 holds the first group of every row: the note goes on a row below them.
            columns[0].1.push((
                Sample::Text,
                format!(
                    "where over {MAX_MARKERS} positions: {BLOCK_PX} px squares shaded by log count"
                ),
            ));
        }
        draw_legend(&key, &columns, 15)?;
        root.present().map_err(svg_err)?;
    }
    Ok(buf)
}
