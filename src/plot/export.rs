//! `restitution export`'s laws.svg: the fitted e(v) of each pair over the scene's speed range
//! with the exported laws (constant e, the closest viscoelastic law), and their deviations from
//! the fitted curve with the tolerance band.

use super::{PlotError, PlotFailure};
use crate::dem::translate::Translation;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Speeds per curve (evenly spaced in ln v).
const SAMPLES: usize = 160;

struct Curve {
    label: String,
    colour: RGBColor,
    fitted: Vec<(f64, f64)>,
    vm: Vec<(f64, f64)>,
    constant: Option<f64>,
}

/// Log-axis tick labels at 1, 2 and 5 times a power of ten only (plotters offers every
/// integer multiple, whose labels collide near the top of each decade).
fn tick(v: &f64) -> String {
    let lead = *v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0].iter().any(|l| (lead - l).abs() < 1e-6) {
        crate::error::Num(*v).to_string()
    } else {
        String::new()
    }
}

fn err<E: std::fmt::Display>(e: E) -> PlotFailure {
    PlotFailure::backend(e)
}

/// Renders laws.svg (needs a speed range in the translation).
pub fn laws_svg(tr: &Translation, title: &str) -> Result<String, PlotError> {
    draw(tr, title).map_err(PlotError::of("laws.svg"))
}

fn draw(tr: &Translation, title: &str) -> Result<String, PlotFailure> {
    let range = tr
        .request
        .range
        .ok_or(PlotFailure::Missing("a speed range (--v-range)"))?;
    let grid = range.log_grid(SAMPLES);
    let eta = tr.viscoelastic.eta_mean;
    let mut curves = Vec::new();
    for (p, pair) in tr.pairs.iter().enumerate() {
        let mut fitted = Vec::new();
        let mut vm = Vec::new();
        for &v in &grid {
            fitted.push((v, tr.e_fitted(p, v)?));
            vm.push((v, tr.e_viscoelastic(p, v, eta)?));
        }
        curves.push(Curve {
            label: pair.label(),
            colour: super::colour(p),
            fitted,
            vm,
            constant: tr.constant.as_ref().map(|c| c[p].e_mean),
        });
    }
    let all = curves
        .iter()
        .flat_map(|c| c.fitted.iter().chain(&c.vm).map(|p| p.1).chain(c.constant));
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    let pad = 0.05 * (hi - lo).max(1e-3);
    let (y0, y1) = (lo - pad, (hi + pad).min(1.0 + pad));
    let devs = curves.iter().flat_map(|c| {
        let vm = c.vm.iter().zip(&c.fitted).map(|(a, b)| a.1 - b.1);
        let k = c
            .constant
            .map(|k| c.fitted.iter().map(move |b| k - b.1).collect::<Vec<_>>())
            .unwrap_or_default();
        vm.chain(k)
    });
    let tol = tr.recommendation.as_ref().map(|r| r.tolerance);
    let dmax = devs
        .fold(0.0f64, |a, d| a.max(d.abs()))
        .max(tol.unwrap_or(0.0))
        .max(1e-6)
        * 1.1;

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1300, 680)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (top, bottom) = root.split_vertically(610);
        let top = top.titled(title, ("sans-serif", 26)).map_err(err)?;
        let (left, right) = top.split_horizontally(650);
        let xr = (range.lo_m_s..range.hi_m_s).log_scale();
        // Enough decimals to tell the ticks apart (an e near 1 over a span of 1e-4 had printed
        // two ticks as "1.0"), and room for them beside the axis's name.
        let decimals = (-((y1 - y0) / 10.0).log10()).ceil().clamp(1.0, 15.0) as usize;
        let mut a = ChartBuilder::on(&left)
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(75 + 10 * decimals.saturating_sub(3) as u32)
            .caption("e(v): fitted and exported laws", ("sans-serif", 22))
            .build_cartesian_2d(xr.clone(), y0..y1)
            .map_err(err)?;
        a.configure_mesh()
            .x_labels(12)
            .x_label_formatter(&tick)
            .y_label_formatter(&|v| format!("{v:.decimals$}"))
            .x_desc("normal impact speed v (m/s)")
            .y_desc("e")
            .axis_desc_style(("sans-serif", 20))
            .label_style(("sans-serif", 17))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        for c in &curves {
            a.draw_series(LineSeries::new(c.fitted.clone(), c.colour.stroke_width(3)))
                .map_err(err)?;
            a.draw_series(DashedLineSeries::new(
                c.vm.clone(),
                10,
                6,
                c.colour.stroke_width(2),
            ))
            .map_err(err)?;
            if let Some(k) = c.constant {
                a.draw_series(DashedLineSeries::new(
                    [(range.lo_m_s, k), (range.hi_m_s, k)],
                    3,
                    5,
                    c.colour.stroke_width(2),
                ))
                .map_err(err)?;
            }
        }
        let mut b = ChartBuilder::on(&right)
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(85)
            .caption("deviation: law − fitted", ("sans-serif", 22))
            .build_cartesian_2d(xr, -dmax..dmax)
            .map_err(err)?;
        b.configure_mesh()
            .x_labels(12)
            .x_label_formatter(&tick)
            .x_desc("normal impact speed v (m/s)")
            .y_desc("e_law − e_fitted")
            // Ticks land a rounding away from 0 (printed 1.7e-18): snap them.
            .y_label_formatter(&|v| {
                let v = if v.abs() < 1e-9 * dmax { 0.0 } else { *v };
                if dmax >= 1e-3 {
                    format!("{v:.3}")
                } else {
                    format!("{v:.1e}")
                }
            })
            .axis_desc_style(("sans-serif", 20))
            .label_style(("sans-serif", 17))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        if let Some(t) = tol {
            b.draw_series(std::iter::once(Rectangle::new(
                [(range.lo_m_s, -t), (range.hi_m_s, t)],
                RGBColor(120, 120, 120).mix(0.2).filled(),
            )))
            .map_err(err)?;
        }
        b.draw_series(LineSeries::new(
            [(range.lo_m_s, 0.0), (range.hi_m_s, 0.0)],
            BLACK.mix(0.4).stroke_width(1),
        ))
        .map_err(err)?;
        for c in &curves {
            let d: Vec<(f64, f64)> =
                c.vm.iter()
                    .zip(&c.fitted)
                    .map(|(a, f)| (a.0, a.1 - f.1))
                    .collect();
            b.draw_series(DashedLineSeries::new(d, 10, 6, c.colour.stroke_width(2)))
                .map_err(err)?;
            if let Some(k) = c.constant {
                let d: Vec<(f64, f64)> = c.fitted.iter().map(|f| (f.0, k - f.1)).collect();
                b.draw_series(DashedLineSeries::new(d, 3, 5, c.colour.stroke_width(2)))
                    .map_err(err)?;
            }
        }
        legend_row(&bottom, &curves, eta, tol)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// The legend under both panels: line styles, then one colour per pair.
fn legend_row(
    area: &DrawingArea<SVGBackend, Shift>,
    curves: &[Curve],
    eta: f64,
    tol: Option<f64>,
) -> Result<(), PlotFailure> {
    let font = ("sans-serif", 18).into_font();
    let y = 18;
    let mut x = 20;
    let grey = BLACK.mix(0.7);
    let styles: [(&str, i32, i32); 3] = [
        ("fitted", 0, 0),
        ("viscoelastic law", 10, 6),
        ("constant e", 3, 5),
    ];
    for (name, dash, gap) in styles {
        let label = if name == "viscoelastic law" {
            format!("viscoelastic law (η = {} kg/(s m))", super::short(eta))
        } else {
            name.to_string()
        };
        if dash == 0 {
            area.draw(&PathElement::new(
                [(x, y), (x + 36, y)],
                grey.stroke_width(3),
            ))
            .map_err(err)?;
        } else {
            let mut s = x;
            while s < x + 36 {
                area.draw(&PathElement::new(
                    [(s, y), ((s + dash).min(x + 36), y)],
                    grey.stroke_width(2),
                ))
                .map_err(err)?;
                s += dash + gap;
            }
        }
        area.draw(&Text::new(label.clone(), (x + 44, y - 9), font.clone()))
            .map_err(err)?;
        x += 60 + 8 * label.chars().count() as i32;
    }
    if let Some(t) = tol {
        area.draw(&Rectangle::new(
            [(x, y - 8), (x + 30, y + 8)],
            RGBColor(120, 120, 120).mix(0.2).filled(),
        ))
        .map_err(err)?;
        let label = format!("tolerance ±{}", crate::error::Num(t));
        area.draw(&Text::new(label, (x + 38, y - 9), font.clone()))
            .map_err(err)?;
    }
    // Pairs on a second row (with many sizes they would run off a single one).
    let y = 48;
    let mut x = 20;
    area.draw(&Text::new("pairs:", (x, y - 9), font.clone()))
        .map_err(err)?;
    x += 60;
    for c in curves {
        area.draw(&PathElement::new(
            [(x, y), (x + 24, y)],
            c.colour.stroke_width(4),
        ))
        .map_err(err)?;
        area.draw(&Text::new(c.label.clone(), (x + 30, y - 9), font.clone()))
            .map_err(err)?;
        x += 40 + 9 * c.label.chars().count() as i32;
    }
    Ok(())
}
