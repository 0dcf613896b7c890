//! `fig7.svg`: the paper's Fig. 7 with the fitted models.

use super::points::{MAX_MARKERS, density_note, draw_density, draw_error_bars, one_per_pixel};
use super::{
    Sample, colour, describe, draw_legend, draw_markers, drawn_groups, log_points, log_ticks,
    svg_err,
};
use crate::fit::dataset::{FitData, Group};
use crate::fit::engine::FitSet;
use crate::fit::models::{ModelKind, predict_e};
use crate::fit::result::{FitResult, ParamStatus};
use crate::models::viscoelastic::{ContactEnd, VmMethod};
use crate::plot::{PlotError, PlotFailure, log_axis, short};
use plotters::coord::Shift;
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::prelude::*;

/// The model's e along `vs` for a group's pair, dropping points the axes cannot show. Where a
/// parameter of the fit is not determined (its value is wherever the minimiser stopped on a
/// plateau), only the data's own speeds pin the curve: it is drawn across the group's speeds
/// alone (none where they are one speed). One speed at three sizes had shown the power law
/// preferred with e rising steeply with v, from its b at the edge of the search box.
fn curve(
    f: &FitResult,
    g: &Group,
    data: &FitData,
    vs: &[f64],
    rule: ContactEnd,
    method: &VmMethod,
    y_range: (f64, f64),
) -> Vec<(f64, f64)> {
    let contact = data.contacts[g.indices[0]];
    let p = f.best_fit_values();
    let along: Vec<f64> = match pinned_span(f, g, data) {
        None => vs.to_vec(),
        Some((lo, hi)) if hi > lo => std::iter::once(lo)
            .chain(vs.iter().copied().filter(|v| *v > lo && *v < hi))
            .chain(std::iter::once(hi))
            .collect(),
        Some(_) => Vec::new(),
    };
    along
        .into_iter()
        .filter_map(|v| {
            predict_e(f.model, &contact, v, &p, rule, method)
                .ok()
                .filter(|e| *e >= y_range.0 && *e <= y_range.1)
                .map(|e| (v, e))
        })
        .collect()
}

/// The group's range of speeds where a parameter of `f` is not determined (see [`curve`]).
fn pinned_span(f: &FitResult, g: &Group, data: &FitData) -> Option<(f64, f64)> {
    undetermined(f).then(|| {
        g.indices
            .iter()
            .map(|&i| data.obs[i].v_n_m_s)
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    })
}

fn undetermined(f: &FitResult) -> bool {
    f.params
        .iter()
        .any(|p| p.status == ParamStatus::Unconstrained)
}

/// The legend's row under a model drawn over the data's speeds only (see [`curve`]), if it is.
fn span_note(
    f: &FitResult,
    name: &str,
    groups: &[&Group],
    data: &FitData,
    merged: bool,
) -> Option<(Sample, String)> {
    if merged || !undetermined(f) {
        return None;
    }
    let one_speed = groups
        .iter()
        .all(|g| pinned_span(f, g, data).is_some_and(|(lo, hi)| hi <= lo));
    Some((
        Sample::Text,
        if one_speed {
            format!("{name} not drawn: a parameter is not determined, and the data have one speed")
        } else {
            format!("{name} over the data's speeds only: a parameter is not determined")
        },
    ))
}

/// The e axis: every positive e of the data (an e of 1e-300 had been drawn at the axis's floor,
/// 1e-4, as if it were 1e-4), 1 and at least down to 0.99, and the error bars' ends within a
/// decade of those; a longer bar runs to the frame (an e_err of 1e99 had stretched the axis to
/// 1e99, leaving every point on one line). e <= 0 has no place on it (the legend counts such
/// points).
fn e_axis(data: &FitData) -> (f64, f64) {
    let positive = || data.obs.iter().filter(|o| o.e > 0.0);
    let lowest = positive().map(|o| o.e).fold(0.99f64, f64::min);
    let highest = positive().map(|o| o.e).fold(1.0f64, f64::max);
    let (mut lo, mut hi) = (lowest, highest);
    for o in positive() {
        let s = o.e_err.unwrap_or(0.0);
        if o.e - s >= lowest / 10.0 {
            lo = lo.min(o.e - s);
        }
        if o.e + s <= highest * 10.0 && (o.e + s).is_finite() {
            hi = hi.max(o.e + s);
        }
    }
    // 0 < lo <= 0.99 < 1 <= hi < inf, so log_axis has an axis (a margin that would overflow
    // leaves that end at the data).
    log_axis(lo, hi, 1.04).unwrap_or((lo, hi))
}

/// `fig7.svg`: e against v_n on log-log axes. Data with error bars, one colour and marker per
/// pair geometry; the fitted VM curve for each geometry (solid); the PM curve (black, dash-dot;
/// one curve when every pair has the same V_Y, as identical spheres of one material do); the
/// preferred model when it is neither of those (dashed, per geometry).
pub fn fig7_svg(
    data: &FitData,
    set: &FitSet,
    rule: ContactEnd,
    method: &VmMethod,
    title: &str,
) -> Result<String, PlotError> {
    draw_fig7(data, set, rule, method, title).map_err(PlotError::of("fig7.svg"))
}

fn draw_fig7(
    data: &FitData,
    set: &FitSet,
    rule: ContactEnd,
    method: &VmMethod,
    title: &str,
) -> Result<String, PlotFailure> {
    let (drawn, merged) = drawn_groups(data);
    let groups: Vec<&Group> = drawn.iter().map(|(g, _)| g).collect();
    let (mut vlo, mut vhi) = (f64::INFINITY, 0.0f64);
    for o in &data.obs {
        vlo = vlo.min(o.v_n_m_s);
        vhi = vhi.max(o.v_n_m_s);
    }
    let x_range = log_axis(vlo, vhi, 1.25).ok_or_else(|| {
        PlotFailure::NothingToDraw("no speed that is a finite positive number".into())
    })?;
    let y_range = e_axis(data);
    let vs = log_points(x_range.0, x_range.1, 240);

    let find = |k: ModelKind| set.fits.iter().find(|f| f.model == k);
    let preferred = set.comparison.as_ref().and_then(|c| c.preferred);
    let tag = |k: ModelKind| {
        if Some(k) == preferred {
            " (preferred)"
        } else {
            ""
        }
    };
    let data_key: Vec<(Sample, String)> = drawn
        .iter()
        .enumerate()
        .map(|(gi, (_, label))| (Sample::Marker(gi, colour(gi)), format!("data, {label}")))
        .collect();
    // A curve per size (identical spheres) or pair only where they are drawn apart.
    let per_size = if merged {
        "curves left out"
    } else if drawn.iter().all(|(g, _)| g.d2_mm.is_none()) {
        "one per size"
    } else {
        "one per pair"
    };
    let mut legend: Vec<(Sample, String)> = Vec::new();
    let combined = preferred
        .filter(|k| !matches!(k, ModelKind::Vm | ModelKind::Pm))
        .and_then(find);
    if let Some(f) = find(ModelKind::Vm) {
        legend.push((
            Sample::Line(RGBColor(90, 90, 90), 2),
            format!("VM{}, {per_size}: {}", tag(ModelKind::Vm), describe(f)),
        ));
        legend.extend(span_note(f, "VM", &groups, data, merged));
    }
    if let Some(f) = find(ModelKind::Pm) {
        legend.push((
            Sample::Dashed(BLACK, 2),
            format!(
                "PM{}{}: {}",
                tag(ModelKind::Pm),
                if merged { ", curves left out" } else { "" },
                describe(f)
            ),
        ));
        legend.extend(span_note(f, "PM", &groups, data, merged));
    }
    if let Some(f) = combined {
        legend.push((
            Sample::Dashed(RGBColor(90, 90, 90), 4),
            format!(
                "{} (preferred), {per_size}: {}",
                f.model.name(),
                describe(f)
            ),
        ));
        legend.extend(span_note(f, f.model.name(), &groups, data, merged));
    }
    // e = 0 has no place on the log axis: the legend counts what the picture leaves out.
    let zeros = data.obs.iter().filter(|o| o.e <= 0.0).count();
    if zeros > 0 {
        legend.push((
            Sample::Text,
            format!(
                "{zeros} point{} with e = 0 not drawn (no place on a log axis)",
                if zeros == 1 { "" } else { "s" }
            ),
        ));
    }
    // Each group's points, one per pixel, and whether they are drawn as a density (points.rs):
    // the chart's pixels do not depend on the legend's height below it, so a scratch chart of
    // the same size tells, and its points are the ones the figure draws.
    let pts: Vec<Vec<(f64, f64)>> = groups
        .iter()
        .map(|g| {
            g.indices
                .iter()
                .map(|&i| (data.obs[i].v_n_m_s, data.obs[i].e))
                .filter(|p| p.1 > 0.0)
                .collect()
        })
        .collect();
    let shown: Vec<Vec<(f64, f64)>> = {
        let mut scratch = String::new();
        let area = SVGBackend::with_string(&mut scratch, (980, 640)).into_drawing_area();
        let chart = chart_on(&area, title, x_range, y_range)?;
        pts.iter().map(|p| one_per_pixel(&chart, p)).collect()
    };
    let dense: Vec<bool> = shown.iter().map(|s| s.len() > MAX_MARKERS).collect();
    let notes = dense.iter().filter(|&&d| d).count();
    let legend_rows = (legend.len() + notes).max(data_key.len()) as u32;
    let legend_h = 24 + legend_rows * 26;
    let height = 640 + legend_h;

    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (980, height)).into_drawing_area();
        root.fill(&WHITE).map_err(svg_err)?;
        let (top, bottom) = root.split_vertically(640);
        let mut chart = chart_on(&top, title, x_range, y_range)?;

        // Model curves first, so the data stay on top.
        if let Some(f) = find(ModelKind::Vm).filter(|_| !merged) {
            for (gi, g) in groups.iter().enumerate() {
                let pts = curve(f, g, data, &vs, rule, method, y_range);
                chart
                    .draw_series(LineSeries::new(pts, colour(gi).stroke_width(2)))
                    .map_err(svg_err)?;
            }
        }
        if let Some(f) = find(ModelKind::Pm).filter(|_| !merged) {
            let mut seen: Vec<f64> = Vec::new();
            for g in &groups {
                let vy = data.contacts[g.indices[0]].yield_velocity_m_s(f.best_fit_values()[0]);
                if seen.iter().any(|s| (s / vy - 1.0).abs() < 1e-9) {
                    continue;
                }
                seen.push(vy);
                let pts = curve(f, g, data, &vs, rule, method, y_range);
                chart
                    .draw_series(DashedLineSeries::new(pts, 10, 4, BLACK.stroke_width(2)))
                    .map_err(svg_err)?;
            }
        }
        if let Some(f) = combined.filter(|_| !merged) {
            for (gi, g) in groups.iter().enumerate() {
                let pts = curve(f, g, data, &vs, rule, method, y_range);
                chart
                    .draw_series(DashedLineSeries::new(pts, 6, 5, colour(gi).stroke_width(4)))
                    .map_err(svg_err)?;
            }
        }
        // Data with error bars, or as a density (points.rs).
        for (gi, g) in groups.iter().enumerate() {
            let c = colour(gi);
            if dense[gi] {
                let most = draw_density(&mut chart, &pts[gi], c)?;
                legend.push((Sample::Block(c), density_note(most)));
                continue;
            }
            let bars = g.indices.iter().filter_map(|&i| {
                let o = data.obs[i];
                let s = o.e_err?;
                let lo = (o.e - s).max(y_range.0);
                let hi = (o.e + s).min(y_range.1);
                (o.e > 0.0).then_some((o.v_n_m_s, lo, o.e, hi))
            });
            draw_error_bars(&mut chart, bars, c.stroke_width(1), 6)?;
            draw_markers(&mut chart, &shown[gi], gi, 4, c)?;
        }
        // The models' column starts past the longest data label (about half the font size per
        // character as drawn): "data, 6.35 mm on 25.4 mm" had run into its first line sample.
        let longest = data_key.iter().map(|(_, t)| t.chars().count()).max();
        let models_x = (80 + 8 * longest.unwrap_or(0) as i32 + 20).max(260);
        draw_legend(&bottom, &[(40, data_key), (models_x, legend)], 16)?;
        root.present().map_err(svg_err)?;
    }
    Ok(buf)
}

type LogAxis = WithKeyPoints<LogCoord<f64>>;

/// The figure's chart on `area` (its upper 640 pixels), axes and grid drawn.
fn chart_on<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, Shift>,
    title: &str,
    x_range: (f64, f64),
    y_range: (f64, f64),
) -> Result<ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogAxis, LogAxis>>, PlotFailure> {
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(58)
        .y_label_area_size(78)
        .build_cartesian_2d(
            (x_range.0..x_range.1)
                .log_scale()
                .with_key_points(log_ticks(x_range.0, x_range.1)),
            (y_range.0..y_range.1)
                .log_scale()
                .with_key_points(log_ticks(y_range.0, y_range.1)),
        )
        .map_err(svg_err)?;
    chart
        .configure_mesh()
        .x_desc("normal impact speed v_n (m/s)")
        .y_desc("coefficient of restitution e")
        .axis_desc_style(("sans-serif", 20))
        .label_style(("sans-serif", 16))
        .x_label_formatter(&|v| short(*v))
        .y_label_formatter(&|e| short(*e))
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()
        .map_err(svg_err)?;
    Ok(chart)
}
