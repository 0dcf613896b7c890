//! Figures of `restitution fit`: `fig7.svg` (the paper's Fig. 7 with the fitted models) and
//! `residuals.svg` (normalised residuals of every fitted model).

use super::{PlotError, PlotFailure};
use crate::fit::dataset::{FitData, Group};
use crate::fit::engine::FitSet;
use crate::fit::models::{ModelKind, predict_e};
use crate::fit::result::FitResult;
use crate::models::viscoelastic::{ContactEnd, VmMethod};
use plotters::coord::CoordTranslate;
use plotters::coord::Shift;
use plotters::element::{Circle, Cross, EmptyElement, PathElement, Rectangle, TriangleMarker};
use plotters::prelude::*;

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

/// Tick values for a log axis: 1, 2, 5 per decade over wide ranges; over less than a factor 3
/// (e on a log axis usually spans 0.7-1.1) evenly spaced round values, 4 to 10 of them.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if hi / lo < 3.0 {
        let raw = (hi - lo) / 6.0;
        let p = 10f64.powi(raw.log10().floor() as i32);
        let step = [1.0, 2.0, 5.0, 10.0]
            .iter()
            .map(|m| m * p)
            .find(|s| (hi - lo) / s <= 10.0)
            .unwrap_or(10.0 * p);
        let first = (lo / step).ceil() as i64;
        let last = (hi / step).floor() as i64;
        return (first..=last).map(|k| k as f64 * step).collect();
    }
    let mantissas: &[f64] = if hi / lo < 30.0 {
        &[1.0, 2.0, 3.0, 5.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    let mut out = Vec::new();
    let mut decade = 10f64.powi(lo.log10().floor() as i32);
    while decade <= hi {
        for &m in mantissas {
            let t = m * decade;
            if t >= lo && t <= hi {
                out.push(t);
            }
        }
        decade *= 10.0;
    }
    out
}

fn log_points(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| (lo.ln() + (hi.ln() - lo.ln()) * k as f64 / (n - 1) as f64).exp())
        .collect()
}

/// The model's e along `vs` for a group's pair, dropping points the axes cannot show.
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
    vs.iter()
        .filter_map(|&v| {
            predict_e(f.model, &contact, v, &p, rule, method)
                .ok()
                .filter(|e| *e >= y_range.0 && *e <= y_range.1)
                .map(|e| (v, e))
        })
        .collect()
}

fn short_value(x: f64) -> String {
    let a = x.abs();
    if (1e-2..1e4).contains(&a) {
        // Rounded to 1e-3 and printed shortest, so ticks read 0.92, not 0.9200000000000002.
        format!("{}", (x * 1e3).round() / 1e3)
    } else {
        format!("{x:.3e}")
    }
}

fn describe(f: &FitResult) -> String {
    let parts: Vec<String> = f
        .params
        .iter()
        .map(|p| {
            let unit = if p.unit == "1" {
                String::new()
            } else {
                format!(" {}", p.unit)
            };
            format!("{} = {}{unit}", p.key, short_value(p.best_fit))
        })
        .collect();
    parts.join(", ")
}

fn svg_err(e: impl std::fmt::Display) -> PlotFailure {
    PlotFailure::backend(e)
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
    let groups = data.groups();
    let (mut vlo, mut vhi) = (f64::INFINITY, 0.0f64);
    let (mut elo, mut ehi) = (f64::INFINITY, 0.0f64);
    for (i, o) in data.obs.iter().enumerate() {
        vlo = vlo.min(o.v_n_m_s);
        vhi = vhi.max(o.v_n_m_s);
        let s = o.e_err.unwrap_or(0.0);
        ehi = ehi.max(o.e + s);
        if o.e > 0.0 {
            elo = elo.min(if o.e - s > 0.0 { o.e - s } else { o.e });
        }
        let _ = i;
    }
    let x_range = (vlo / 1.25, vhi * 1.25);
    let ehi = ehi.max(1.0) * 1.03;
    let elo = (elo / 1.05).clamp(1e-4, 0.99);
    let y_range = (elo, ehi);
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
    let data_key: Vec<(Sample, String)> = groups
        .iter()
        .enumerate()
        .map(|(gi, g)| {
            (
                Sample::Marker(gi, colour(gi)),
                format!("data, {}", g.label()),
            )
        })
        .collect();
    let mut legend: Vec<(Sample, String)> = Vec::new();
    let combined = preferred
        .filter(|k| !matches!(k, ModelKind::Vm | ModelKind::Pm))
        .and_then(find);
    if let Some(f) = find(ModelKind::Vm) {
        legend.push((
            Sample::Line(RGBColor(90, 90, 90), 2),
            format!("VM{}, one per size: {}", tag(ModelKind::Vm), describe(f)),
        ));
    }
    if let Some(f) = find(ModelKind::Pm) {
        legend.push((
            Sample::Dashed(BLACK, 2),
            format!("PM{}: {}", tag(ModelKind::Pm), describe(f)),
        ));
    }
    if let Some(f) = combined {
        legend.push((
            Sample::Dashed(RGBColor(90, 90, 90), 4),
            format!(
                "{} (preferred), one per size: {}",
                f.model.name(),
                describe(f)
            ),
        ));
    }
    let legend_rows = legend.len().max(data_key.len()) as u32;
    let legend_h = 24 + legend_rows * 26;
    let height = 640 + legend_h;

    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (980, height)).into_drawing_area();
        root.fill(&WHITE).map_err(svg_err)?;
        let (top, bottom) = root.split_vertically(640);
        let mut chart = ChartBuilder::on(&top)
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
            .x_label_formatter(&|v| short_value(*v))
            .y_label_formatter(&|e| short_value(*e))
            .bold_line_style(RGBColor(225, 225, 225))
            .draw()
            .map_err(svg_err)?;

        // Model curves first, so the data stay on top.
        if let Some(f) = find(ModelKind::Vm) {
            for (gi, g) in groups.iter().enumerate() {
                let pts = curve(f, g, data, &vs, rule, method, y_range);
                chart
                    .draw_series(LineSeries::new(pts, colour(gi).stroke_width(2)))
                    .map_err(svg_err)?;
            }
        }
        if let Some(f) = find(ModelKind::Pm) {
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
        if let Some(f) = combined {
            for (gi, g) in groups.iter().enumerate() {
                let pts = curve(f, g, data, &vs, rule, method, y_range);
                chart
                    .draw_series(DashedLineSeries::new(pts, 6, 5, colour(gi).stroke_width(4)))
                    .map_err(svg_err)?;
            }
        }
        // Data with error bars.
        for (gi, g) in groups.iter().enumerate() {
            let c = colour(gi);
            chart
                .draw_series(g.indices.iter().filter_map(|&i| {
                    let o = data.obs[i];
                    let s = o.e_err?;
                    let lo = (o.e - s).max(y_range.0);
                    let hi = (o.e + s).min(y_range.1);
                    (o.e > 0.0).then(|| {
                        ErrorBar::new_vertical(o.v_n_m_s, lo, o.e, hi, c.stroke_width(1), 6)
                    })
                }))
                .map_err(svg_err)?;
            let pts: Vec<(f64, f64)> = g
                .indices
                .iter()
                .map(|&i| (data.obs[i].v_n_m_s, data.obs[i].e))
                .filter(|p| p.1 > 0.0)
                .collect();
            draw_markers(&mut chart, &pts, gi, 4, c)?;
        }
        draw_legend(&bottom, &[(40, data_key), (260, legend)], 16)?;
        root.present().map_err(svg_err)?;
    }
    Ok(buf)
}

/// `residuals.svg`: (e - model)/sigma against v_n for every fitted model, one panel each, with
/// the lines 0 and +-2.
pub fn residuals_svg(data: &FitData, set: &FitSet, title: &str) -> Result<String, PlotError> {
    draw_residuals(data, set, title).map_err(PlotError::of("residuals.svg"))
}

fn draw_residuals(data: &FitData, set: &FitSet, title: &str) -> Result<String, PlotFailure> {
    let groups = data.groups();
    let n = set.fits.len().max(1);
    let (mut vlo, mut vhi) = (f64::INFINITY, 0.0f64);
    for o in &data.obs {
        vlo = vlo.min(o.v_n_m_s);
        vhi = vhi.max(o.v_n_m_s);
    }
    let x_range = (vlo / 1.25, vhi * 1.25);
    let panel_h = 190u32;
    let mut buf = String::new();
    {
        let root =
            SVGBackend::with_string(&mut buf, (960, 100 + panel_h * n as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(svg_err)?;
        let root = root.titled(title, ("sans-serif", 22)).map_err(svg_err)?;
        let (key, body) = root.split_vertically(34);
        let columns: Vec<(i32, Vec<(Sample, String)>)> = groups
            .iter()
            .enumerate()
            .map(|(gi, g)| {
                (
                    90 + 220 * gi as i32,
                    vec![(Sample::Marker(gi, colour(gi)), g.label())],
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
            let lim = (rmax * 1.15).max(if data.weighted { 3.0 } else { 1e-3 });
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
            for (gi, g) in groups.iter().enumerate() {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside() {
        assert_eq!(log_ticks(0.45, 46.0), vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0]);
        let t = log_ticks(0.88, 1.03);
        assert!(t.len() >= 4 && t.len() <= 10, "{t:?}");
        assert!(t.iter().all(|&x| (0.88..=1.03).contains(&x)));
        assert_eq!(short_value(t[2]), "0.92");
    }
}
