//! `stability.svg`: the stability map, one row per method, setting and rule, coloured by outcome.

use super::{Area, err_str};
use crate::bench::BenchReport;
use crate::bench::stability::{Cell, Outcome};
use crate::plot::{PlotError, PlotFailure};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

fn outcome_color(o: Outcome) -> RGBColor {
    use crate::error::IntegrationFailure as F;
    match o {
        Outcome::Ok => RGBColor(200, 230, 200),
        Outcome::Inaccurate => RGBColor(230, 30, 30),
        Outcome::NotFinite => RGBColor(120, 0, 0),
        Outcome::Refused => RGBColor(200, 200, 200),
        Outcome::Failed(F::MaxSteps) => RGBColor(40, 80, 200),
        Outcome::Failed(F::StepSizeUnderflow) => RGBColor(0, 170, 200),
        Outcome::Failed(F::Stiffness) => RGBColor(150, 60, 170),
        Outcome::Failed(F::NonFinite) => RGBColor(250, 150, 0),
        Outcome::Failed(F::Unphysical) => RGBColor(240, 210, 0),
        Outcome::Failed(F::PhaseIncomplete) => RGBColor(140, 90, 40),
        Outcome::Failed(F::EventLocation) => RGBColor(230, 120, 180),
        Outcome::Failed(F::OutOfRange) => RGBColor(150, 190, 240),
        Outcome::Failed(F::Other) | Outcome::OtherError => RGBColor(90, 90, 90),
    }
}

fn outcome_label(o: Outcome) -> &'static str {
    use crate::error::IntegrationFailure as F;
    match o {
        Outcome::Ok => "ok (relative error <= 1e-6)",
        Outcome::Inaccurate => "WRONG NUMBER: error > 1e-6 (loose rows: 100 tol), no error value",
        Outcome::NotFinite => "WRONG NUMBER: NaN, no error value",
        Outcome::Refused => "refused: error bound above 1e-6 (error value)",
        Outcome::Failed(F::MaxSteps) => "no termination: step budget spent (error value)",
        Outcome::Failed(F::StepSizeUnderflow) => "step-size underflow (error value)",
        Outcome::Failed(F::Stiffness) => "stiffness detected (error value)",
        Outcome::Failed(F::NonFinite) => "state not finite (error value)",
        Outcome::Failed(F::Unphysical) => {
            "unphysical end: e outside (0, 1] or not separating (error value)"
        }
        Outcome::Failed(F::PhaseIncomplete) => "phase did not end (error value)",
        Outcome::Failed(F::EventLocation) => "event not located (error value)",
        Outcome::Failed(F::OutOfRange) => "beyond the checked kappa range (error value)",
        Outcome::Failed(F::Other) | Outcome::OtherError => "other error value",
    }
}

/// Row labels (method, setting, rule) in first-appearance order, and each cell's row.
fn map_rows(cells: &[&Cell]) -> Vec<String> {
    let mut rows: Vec<String> = Vec::new();
    for c in cells {
        let k = row_key(c);
        if !rows.contains(&k) {
            rows.push(k);
        }
    }
    rows
}

fn row_key(c: &Cell) -> String {
    let setting = if c.setting == "-" {
        String::new()
    } else {
        format!(" {}", c.setting)
    };
    let rule = if c.rule == "-" {
        String::new()
    } else {
        format!(" [{}]", c.rule)
    };
    let role = match c.role {
        crate::bench::stability::Role::Comparator => " (comparator)",
        crate::bench::stability::Role::Loose => " (loose: 100 tol)",
        crate::bench::stability::Role::Production => "",
    };
    format!("{}{setting}{rule}{role}", c.method)
}

/// The map's x coordinate: log10(x), compressed eightfold above 1e4, so that the dense grid up to
/// 1e4 stays readable next to the sparse one reaching f64::MAX.
fn squash(x: f64) -> f64 {
    let l = x.log10();
    if l <= SQUASH_FROM {
        l
    } else {
        SQUASH_FROM + (l - SQUASH_FROM) / SQUASH
    }
}

const SQUASH_FROM: f64 = 4.0;
const SQUASH: f64 = 8.0;

/// The decade shown at map coordinate c (inverse of [`squash`]), when it is a whole one.
fn unsquash_label(c: f64) -> String {
    let l = if c <= SQUASH_FROM {
        c
    } else {
        SQUASH_FROM + (c - SQUASH_FROM) * SQUASH
    };
    if (l - l.round()).abs() < 1e-6 {
        format!("1e{}", l.round() as i32)
    } else {
        String::new()
    }
}

/// Cell edges in map coordinates: midpoints between neighbouring grid values.
fn edges(xs: &[f64]) -> Vec<f64> {
    let l: Vec<f64> = xs.iter().map(|&x| squash(x)).collect();
    let mut e = Vec::with_capacity(l.len() + 1);
    for i in 0..=l.len() {
        let v = if i == 0 {
            l[0] - (l.get(1).map_or(0.5, |n| n - l[0])) / 2.0
        } else if i == l.len() {
            l[i - 1]
                + (l[i - 1] - l.get(i.wrapping_sub(2)).copied().unwrap_or(l[i - 1] - 1.0)) / 2.0
        } else {
            0.5 * (l[i - 1] + l[i])
        };
        e.push(v);
    }
    e
}

fn map_panel(
    area: &Area,
    title: &str,
    x_desc: &str,
    cells: &[&Cell],
    x_of: impl Fn(&Cell) -> f64,
    mark: Option<(f64, &str)>,
) -> Result<(), PlotFailure> {
    let rows = map_rows(cells);
    let mut xs: Vec<f64> = cells.iter().map(|c| x_of(c)).collect();
    xs.sort_by(|a, b| a.total_cmp(b));
    xs.dedup();
    let ed = edges(&xs);
    let n = rows.len() as f64;
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 24))
        .margin(10)
        .x_label_area_size(50)
        .y_label_area_size(420)
        .build_cartesian_2d(ed[0]..ed[ed.len() - 1], -0.5..(n - 0.5))
        .map_err(err_str)?;
    let labels = rows.clone();
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(x_desc)
        .axis_desc_style(("sans-serif", 20))
        .label_style(("sans-serif", 16))
        .x_labels(14)
        .x_label_formatter(&|v| unsquash_label(*v))
        .y_labels(rows.len())
        .y_label_formatter(&|v| {
            let i = v.round();
            if (v - i).abs() < 1e-9 && i >= 0.0 && (i as usize) < labels.len() {
                labels[labels.len() - 1 - i as usize].clone()
            } else {
                String::new()
            }
        })
        .draw()
        .map_err(err_str)?;
    chart
        .draw_series(cells.iter().map(|c| {
            let r = rows.iter().position(|k| *k == row_key(c)).unwrap_or(0);
            let y = (rows.len() - 1 - r) as f64;
            let i = xs.iter().position(|&x| x == x_of(c)).unwrap_or(0);
            Rectangle::new(
                [(ed[i], y - 0.45), (ed[i + 1], y + 0.45)],
                ShapeStyle::from(&outcome_color(c.outcome)).filled(),
            )
        }))
        .map_err(err_str)?;
    if let Some((x, text)) = mark {
        let lx = squash(x);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(lx, -0.5), (lx, n - 0.5)],
                6,
                4,
                ShapeStyle::from(&BLACK).stroke_width(2),
            ))
            .map_err(err_str)?;
        let style = ("sans-serif", 16)
            .into_font()
            .into_text_style(area)
            .pos(Pos::new(HPos::Right, VPos::Bottom));
        chart
            .draw_series(std::iter::once(Text::new(
                text.to_string(),
                (lx - 0.05, n - 0.5),
                style,
            )))
            .map_err(err_str)?;
    }
    Ok(())
}

/// `stability.svg`: for each method, setting and rule, the outcome at every kappa (top) and u
/// (bottom), coloured by how it failed.
pub fn stability_svg(report: &BenchReport) -> Result<String, PlotError> {
    draw(report).map_err(PlotError::of("stability.svg"))
}

fn draw(report: &BenchReport) -> Result<String, PlotFailure> {
    let vm: Vec<&Cell> = report.cells.iter().filter(|c| c.model == "vm").collect();
    let pm: Vec<&Cell> = report.cells.iter().filter(|c| c.model == "pm").collect();
    let n_vm = map_rows(&vm).len() as u32;
    let n_pm = map_rows(&pm).len() as u32;
    let row_px = 34;
    let vm_h = 100 + n_vm * row_px;
    let pm_h = 100 + n_pm * row_px;
    let present: Vec<Outcome> = Outcome::ALL
        .iter()
        .copied()
        .filter(|o| *o == Outcome::Ok || report.cells.iter().any(|c| c.outcome == *o))
        .collect();
    let legend_h = 40 + 30 * present.len().div_ceil(2) as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1600, vm_h + pm_h + legend_h + 50))
            .into_drawing_area();
        root.fill(&WHITE).map_err(err_str)?;
        let (title, rest) = root.split_vertically(50);
        title
            .titled(
                "Stability map: where each method fails, and how (threshold: relative error <= 1e-6 in e and in 1 - e)",
                ("sans-serif", 22),
            )
            .map_err(err_str)?;
        let (top, rest) = rest.split_vertically(vm_h);
        let (mid, bottom) = rest.split_vertically(pm_h);
        map_panel(
            &top,
            "viscoelastic model: dimensionless damping kappa",
            "kappa (dimensionless damping; log scale, compressed 8 times above 1e4)",
            &vm,
            |c| c.x,
            Some((
                10.0,
                "master curve: table below kappa = 10, large-kappa laws above",
            )),
        )?;
        map_panel(
            &mid,
            "plastic model: u = V/V_Y at the mpmath fixture's points (comparators are kept to show their failure)",
            "u - 1 (log scale, compressed 8 times above 1e4)",
            &pm,
            |c| c.x - 1.0,
            None,
        )?;
        // Legend: two columns of colour boxes.
        let cols = 2;
        for (i, o) in present.iter().enumerate() {
            let (col, row) = ((i % cols) as i32, (i / cols) as i32);
            let x = 80 + col * 760;
            let y = 15 + row * 30;
            bottom
                .draw(&Rectangle::new(
                    [(x, y), (x + 24, y + 20)],
                    ShapeStyle::from(&outcome_color(*o)).filled(),
                ))
                .map_err(err_str)?;
            bottom
                .draw(&Text::new(
                    outcome_label(*o).to_string(),
                    (x + 34, y + 2),
                    ("sans-serif", 18).into_font(),
                ))
                .map_err(err_str)?;
        }
        root.present().map_err(err_str)?;
    }
    Ok(svg)
}
