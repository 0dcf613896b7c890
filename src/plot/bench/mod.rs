//! Figures of `restitution bench`: the work-precision chart (four panels) and the stability map.

use crate::bench::fit_accuracy::FitMethodRow;

use crate::bench::{BenchReport, WpRow};
use crate::plot::{PlotError, PlotFailure};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type LogLog = Cartesian2d<
    plotters::coord::combinators::LogCoord<f64>,
    plotters::coord::combinators::LogCoord<f64>,
>;
type LogChart<'a> = ChartContext<'a, SVGBackend<'a>, LogLog>;

/// Errors below this are drawn at it (log axes have no zero).
const ERROR_FLOOR: f64 = 1e-17;
/// Relative errors above this (no correct digit left) are drawn at it.
const REL_ERROR_CAP: f64 = 10.0;

/// Each method's colour, from the figures' shared palette ([`super::PALETTE`]); the reference-
/// grade methods (master curve, plastic closed form) in black, as the models are elsewhere.
fn method_color(method: &str) -> RGBColor {
    use super::PALETTE as P;
    match method {
        "dop853" | "quadrature" => P[0],
        "dopri5" | "naive q" => P[1],
        "rk4" => P[2],
        "pade" => P[3],
        "series" => P[4],
        "dop853+extrema" => P[5],
        "master" | "closed form" => BLACK,
        _ => RGBColor(100, 100, 100),
    }
}

fn floor(e: f64) -> f64 {
    e.max(ERROR_FLOOR)
}

fn err_str<E: std::fmt::Debug>(e: E) -> PlotFailure {
    PlotFailure::Backend(format!("{e:?}"))
}

/// Methods in the order of first appearance.
fn methods_of<'a>(rows: impl Iterator<Item = &'a WpRow>) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for r in rows {
        if !v.contains(&r.method) {
            v.push(r.method.clone());
        }
    }
    v
}

/// A line (or a single point) per method: the points sorted by x.
fn draw_lines<X: Fn(&WpRow) -> f64, Y: Fn(&WpRow) -> f64>(
    chart: &mut LogChart,
    rows: &[&WpRow],
    x: X,
    y: Y,
    dashed: bool,
    label_suffix: &str,
) -> Result<(), PlotFailure> {
    for m in methods_of(rows.iter().copied()) {
        let color = method_color(&m);
        let mut pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.method == m)
            .map(|r| (x(r), floor(y(r))))
            .filter(|(a, b)| a.is_finite() && *a > 0.0 && b.is_finite())
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        if pts.is_empty() {
            continue;
        }
        let style = ShapeStyle::from(&color).stroke_width(2);
        let label = format!("{m}{label_suffix}");
        if dashed {
            chart
                .draw_series(DashedLineSeries::new(pts.clone(), 8, 5, style))
                .map_err(err_str)?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], style));
            chart
                .draw_series(
                    pts.iter()
                        .map(|&p| TriangleMarker::new(p, 5, ShapeStyle::from(&color).filled())),
                )
                .map_err(err_str)?;
        } else {
            chart
                .draw_series(LineSeries::new(pts.clone(), style))
                .map_err(err_str)?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
            chart
                .draw_series(
                    pts.iter()
                        .map(|&p| Circle::new(p, 4, ShapeStyle::from(&color).filled())),
                )
                .map_err(err_str)?;
        }
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn log_panel<'a>(
    area: &Area<'a>,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    x: (f64, f64),
    y: (f64, f64),
) -> Result<LogChart<'a>, PlotFailure> {
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 26))
        .margin(12)
        .x_label_area_size(55)
        .y_label_area_size(85)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(err_str)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .axis_desc_style(("sans-serif", 22))
        .label_style(("sans-serif", 18))
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(err_str)?;
    Ok(chart)
}

fn range_of(vals: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (1e-3, 1e3);
    }
    (lo / pad, hi * pad)
}

/// `work_precision.svg`: (a) vm error in e against time per evaluation, (b) against right-hand-side
/// evaluations, (c) pm relative errors against time, (d) RK4's error against its step.
pub fn work_precision_svg(report: &BenchReport) -> Result<String, PlotError> {
    draw_work_precision(report).map_err(PlotError::of("work_precision.svg"))
}

fn draw_work_precision(report: &BenchReport) -> Result<String, PlotFailure> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1600, 1250)).into_drawing_area();
        root.fill(&WHITE).map_err(err_str)?;
        let (title, body) = root.split_vertically(50);
        title
            .titled(
                "Work-precision: every way restitution computes e (settings with any failed point left out; errors below 1e-17 drawn at 1e-17)",
                ("sans-serif", 22),
            )
            .map_err(err_str)?;
        let panels = body.split_evenly((2, 2));

        let vm: Vec<&WpRow> = report
            .rows
            .iter()
            .filter(|r| r.model == "vm" && r.rule == "all" && r.failed == 0)
            .collect();
        let y_vm = (
            ERROR_FLOOR / 3.0,
            range_of(vm.iter().map(|r| r.error), 3.0).1.max(1.0),
        );
        // (a)
        let x_a = range_of(vm.iter().map(|r| r.ns_per_eval), 3.0);
        let mut a = log_panel(
            &panels[0],
            "(a) viscoelastic: error vs time (kappa 1e-4..5, both rules)",
            "time per evaluation (ns)",
            "max |error in e|",
            x_a,
            y_vm,
        )?;
        draw_lines(&mut a, &vm, |r| r.ns_per_eval, |r| r.error, false, "")?;
        // The approximations' settings are not a monotone knob: name each point.
        for (i, r) in vm
            .iter()
            .filter(|r| r.method == "series" || r.method == "pade")
            .enumerate()
        {
            // Rotate the label around the point (above right, left, below right) so that
            // neighbouring points' labels do not overlap.
            let (h, v, text) = match i % 3 {
                0 => (HPos::Left, VPos::Bottom, format!(" {}", r.setting)),
                1 => (HPos::Right, VPos::Center, format!("{}  ", r.setting)),
                _ => (HPos::Left, VPos::Top, format!(" {}", r.setting)),
            };
            let style = ("sans-serif", 15)
                .into_font()
                .into_text_style(&panels[0])
                .pos(Pos::new(h, v));
            a.draw_series(std::iter::once(Text::new(
                text,
                (r.ns_per_eval, floor(r.error)),
                style,
            )))
            .map_err(err_str)?;
        }
        super::legend(&mut a, SeriesLabelPosition::LowerMiddle, 17)?;

        // (b)
        let ode: Vec<&WpRow> = vm.iter().copied().filter(|r| r.rhs_evals > 0.0).collect();
        let x_b = range_of(ode.iter().map(|r| r.rhs_evals), 1.5);
        let mut b = log_panel(
            &panels[1],
            "(b) viscoelastic ODE: error vs right-hand-side evaluations",
            "right-hand-side evaluations per e",
            "max |error in e|",
            x_b,
            y_vm,
        )?;
        draw_lines(&mut b, &ode, |r| r.rhs_evals, |r| r.error, false, "")?;
        super::legend(&mut b, SeriesLabelPosition::UpperMiddle, 17)?;

        // (c)
        let pm: Vec<&WpRow> = report
            .rows
            .iter()
            .filter(|r| r.model == "pm" && r.failed == 0)
            .collect();
        let x_c = range_of(pm.iter().map(|r| r.ns_per_eval), 2.0);
        let y_c = (ERROR_FLOOR / 3.0, REL_ERROR_CAP * 1e4);
        let mut c = log_panel(
            &panels[2],
            "(c) plastic: error vs time (u in (1, 1e12]; above 10 drawn at 10)",
            "time per evaluation (ns)",
            "max relative error",
            x_c,
            y_c,
        )?;
        let cap = |x: f64| if x.is_nan() { x } else { x.min(REL_ERROR_CAP) };
        draw_lines(
            &mut c,
            &pm,
            |r| r.ns_per_eval,
            |r| cap(r.error_rel_e),
            false,
            ": e",
        )?;
        draw_lines(
            &mut c,
            &pm,
            |r| r.ns_per_eval,
            |r| cap(r.error_rel_one_minus_e),
            true,
            ": 1 - e",
        )?;
        super::legend(&mut c, SeriesLabelPosition::UpperRight, 17)?;

        // (d)
        let rk4: Vec<&WpRow> = report
            .rows
            .iter()
            .filter(|r| r.method == "rk4" && (r.rule == "overlap" || r.rule == "force"))
            .filter(|r| r.failed == 0)
            .collect();
        let x_d = range_of(rk4.iter().map(|r| r.knob), 1.5);
        let y_d = range_of(rk4.iter().map(|r| floor(r.error)), 5.0);
        let mut d = log_panel(
            &panels[3],
            "(d) fixed-step RK4 in the r/t/r variables: error vs step",
            "step h (r or t units)",
            "max |error in e|",
            x_d,
            y_d,
        )?;
        for (rule, color, dashed) in [
            ("overlap", super::PALETTE[2], false),
            ("force", RGBColor(0, 100, 75), true),
        ] {
            let mut pts: Vec<(f64, f64)> = rk4
                .iter()
                .filter(|r| r.rule == rule)
                .map(|r| (r.knob, floor(r.error)))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let slope = report
                .rk4_order
                .iter()
                .find(|o| o.0 == rule)
                .map_or("-".to_string(), |o| format!("{:.2}", o.1));
            let style = ShapeStyle::from(&color).stroke_width(2);
            let label = format!("rk4, {rule} rule: fitted slope {slope}");
            if dashed {
                d.draw_series(DashedLineSeries::new(pts.clone(), 8, 5, style))
                    .map_err(err_str)?
                    .label(label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], style));
            } else {
                d.draw_series(LineSeries::new(pts.clone(), style))
                    .map_err(err_str)?
                    .label(label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
            }
            d.draw_series(
                pts.iter()
                    .map(|&p| Circle::new(p, 4, ShapeStyle::from(&color).filled())),
            )
            .map_err(err_str)?;
        }
        // Slope-4 guide: through the overlap-rule point nearest the middle step, 3x above it.
        let h_mid = (x_d.0 * x_d.1).sqrt();
        let anchor = rk4
            .iter()
            .filter(|r| r.rule == "overlap" && r.error > 0.0)
            .min_by(|a, b| {
                (a.knob / h_mid)
                    .ln()
                    .abs()
                    .total_cmp(&(b.knob / h_mid).ln().abs())
            });
        if let Some(a) = anchor {
            let guide: Vec<(f64, f64)> = (0..=20)
                .map(|i| x_d.0 * (x_d.1 / x_d.0).powf(i as f64 / 20.0))
                .map(|h| (h, 3.0 * a.error * (h / a.knob).powi(4)))
                .filter(|p| p.1 > y_d.0 && p.1 < y_d.1)
                .collect();
            let gstyle = ShapeStyle::from(&RGBColor(120, 120, 120)).stroke_width(1);
            d.draw_series(DashedLineSeries::new(guide, 4, 4, gstyle))
                .map_err(err_str)?
                .label("slope 4")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], gstyle));
        }
        super::legend(&mut d, SeriesLabelPosition::LowerRight, 17)?;
        root.present().map_err(err_str)?;
    }
    Ok(svg)
}

mod map;
pub use map::stability_svg;

/// Title, y label, y value, reference line and its label of a fit-accuracy panel.
type PanelSpec = (
    &'static str,
    &'static str,
    fn(&FitMethodRow) -> f64,
    f64,
    String,
);

/// `fit_accuracy.svg`: (a) the fitted eta's error and (b) the model error over the data, against
/// the fit's wall time, per evaluation method; the default (cheapest method whose model error is
/// below 1% of the smallest error bar) ringed.
pub fn fit_accuracy_svg(report: &BenchReport) -> Result<String, PlotError> {
    draw_fit_accuracy(report).map_err(PlotError::of("fit_accuracy.svg"))
}

fn draw_fit_accuracy(report: &BenchReport) -> Result<String, PlotFailure> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1600, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(err_str)?;
        let Some(f) = &report.fit else {
            root.titled("no fit data set given", ("sans-serif", 22))
                .map_err(err_str)?;
            root.present().map_err(err_str)?;
            drop(root);
            return Ok(svg);
        };
        let (title, body) = root.split_vertically(50);
        title
            .titled(
                &format!(
                    "What accuracy a fit needs: model vm on the example data ({} points) per evaluation method, against the fit at ODE tol 1e-15 (failed fits left out: fit_accuracy.csv)",
                    f.n_points
                ),
                ("sans-serif", 22),
            )
            .map_err(err_str)?;
        let panels = body.split_evenly((1, 2));
        let ok: Vec<(usize, &FitMethodRow)> = f
            .rows
            .iter()
            .enumerate()
            .filter(|(_, r)| r.failure.is_none())
            .collect();
        let x = range_of(ok.iter().map(|(_, r)| r.fit_ms), 2.0);
        for (panel, which) in panels.iter().zip([0, 1]) {
            let (title, y_desc, y_of, line, line_label): PanelSpec = if which == 0 {
                (
                    "(a) fitted eta: relative error vs fit time",
                    "|eta - eta_ref| / eta_ref",
                    |r| r.eta_rel_error,
                    f.eta_ref_stderr / f.eta_ref,
                    "eta's own standard error (the data's limit)".to_string(),
                )
            } else {
                (
                    "(b) model error over the data vs fit time",
                    "max |e - e_ref| over the data",
                    |r| r.model_error,
                    f.threshold,
                    format!(
                        "{} x smallest error bar = {:.1e}",
                        crate::bench::fit_accuracy::SIGMA_FRACTION,
                        f.threshold
                    ),
                )
            };
            let y = (
                ERROR_FLOOR / 3.0,
                range_of(ok.iter().map(|(_, r)| y_of(r)).chain([line]), 10.0).1,
            );
            let mut chart = log_panel(panel, title, "fit wall time (ms)", y_desc, x, y)?;
            let rows: Vec<WpRow> = ok
                .iter()
                .map(|(_, r)| WpRow {
                    model: "vm",
                    method: r.method.clone(),
                    setting: r.setting.clone(),
                    knob: r.knob,
                    rule: "overlap".into(),
                    error: y_of(r),
                    error_rel_e: f64::NAN,
                    error_rel_one_minus_e: f64::NAN,
                    ns_per_eval: r.fit_ms,
                    rhs_evals: f64::NAN,
                    points: 0,
                    failed: 0,
                })
                .collect();
            let refs: Vec<&WpRow> = rows.iter().collect();
            draw_lines(&mut chart, &refs, |r| r.ns_per_eval, |r| r.error, false, "")?;
            let gstyle = ShapeStyle::from(&RGBColor(120, 120, 120)).stroke_width(2);
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x.0, line), (x.1, line)],
                    8,
                    5,
                    gstyle,
                ))
                .map_err(err_str)?
                .label(line_label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], gstyle));
            if let Some(d) = f.default_row.map(|i| &f.rows[i]) {
                let p = (d.fit_ms, floor(y_of(d)));
                chart
                    .draw_series(std::iter::once(Circle::new(
                        p,
                        11,
                        ShapeStyle::from(&BLACK).stroke_width(2),
                    )))
                    .map_err(err_str)?;
                let style = ("sans-serif", 17)
                    .into_font()
                    .into_text_style(panel)
                    .pos(Pos::new(HPos::Left, VPos::Bottom));
                chart
                    .draw_series(std::iter::once(Text::new(
                        format!("  default: {} {}", d.method, d.setting),
                        p,
                        style,
                    )))
                    .map_err(err_str)?;
            }
            super::legend(&mut chart, SeriesLabelPosition::LowerRight, 17)?;
        }
        root.present().map_err(err_str)?;
    }
    Ok(svg)
}
