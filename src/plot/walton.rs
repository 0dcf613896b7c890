//! The paper's Fig. 6: tangential restitution beta against psi = -v_n/|v_s| (the cotangent of
//! the angle of incidence), with the fitted Walton hinge beta = min(-1 + s psi, beta_0).

use super::{PlotError, PlotFailure};
use plotters::prelude::*;

/// One measured collision on the figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fig6Point {
    pub psi: f64,
    pub beta: f64,
    /// Classed sliding (on the line) rather than rolling (on the plateau).
    pub sliding: bool,
}

/// The fitted hinge and what the legend says about it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fig6Fit {
    pub slope: f64,
    pub beta0: f64,
    pub kink_psi: f64,
    /// 95% interval of beta_0, drawn as a band along the plateau.
    pub beta0_ci95: Option<(f64, f64)>,
    pub mu0: f64,
    pub e: f64,
    /// False when the fit did not determine both branches (the legend says so).
    pub converged: bool,
}

const SLIDING: RGBColor = RGBColor(31, 119, 180);
const ROLLING: RGBColor = RGBColor(214, 95, 14);

/// Renders Fig. 6 as an SVG string. The psi axis ends just past the data unless a few
/// near-head-on collisions (psi far beyond the rest) would squeeze everything else into the left
/// edge: then it ends past the 95th percentile and the caption counts the points not shown.
pub fn fig6_svg(points: &[Fig6Point], fit: &Fig6Fit, title: &str) -> Result<String, PlotError> {
    draw(points, fit, title).map_err(PlotError::of("fig6.svg"))
}

fn draw(points: &[Fig6Point], fit: &Fig6Fit, title: &str) -> Result<String, PlotFailure> {
    let mut psis: Vec<f64> = points
        .iter()
        .map(|p| p.psi)
        .filter(|x| x.is_finite())
        .collect();
    psis.sort_by(f64::total_cmp);
    let max_psi = psis.last().copied().unwrap_or(1.0).max(fit.kink_psi);
    let p95 = psis
        .get(((psis.len() as f64 - 1.0) * 0.95).round() as usize)
        .copied()
        .unwrap_or(max_psi)
        .max(fit.kink_psi);
    let x_max = if max_psi > 3.0 * p95 {
        1.1 * p95
    } else {
        1.05 * max_psi
    };
    let x_max = if x_max.is_finite() && x_max > 0.0 {
        x_max
    } else {
        1.0
    };
    let hidden = points.iter().filter(|p| p.psi > x_max).count();
    let betas = points.iter().map(|p| p.beta).filter(|b| b.is_finite());
    let y_min = betas.clone().fold(-1.05f64, |a, b| a.min(b - 0.05));
    let y_max = betas.fold(fit.beta0.max(0.9) + 0.1, |a, b| a.max(b + 0.05));

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 620)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| PlotFailure::backend(e);
        root.fill(&WHITE).map_err(e)?;
        let caption = if hidden > 0 {
            format!("{title} ({hidden} collisions with ψ > {x_max:.2} not shown)")
        } else {
            title.to_string()
        };
        let mut chart = ChartBuilder::on(&root)
            .caption(caption, ("sans-serif", 26))
            .margin(20)
            .x_label_area_size(60)
            .y_label_area_size(75)
            .build_cartesian_2d(0.0..x_max, y_min..y_max)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("ψ = −v_n / |v_s|   (cotangent of the angle of incidence)")
            .y_desc("β   (tangential restitution)")
            // Ticks like -1.0 + 5 * 0.2 land a rounding away from 0 and would print "-0.0".
            .y_label_formatter(&|v| format!("{:.1}", if v.abs() < 1e-9 { 0.0 } else { *v }))
            .axis_desc_style(("sans-serif", 22))
            .label_style(("sans-serif", 18))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(e)?;
        // beta_0's 95% interval along the plateau.
        if let Some((lo, hi)) = fit.beta0_ci95
            && fit.converged
        {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(fit.kink_psi.min(x_max), lo), (x_max, hi)],
                    RGBColor(120, 120, 120).mix(0.3).filled(),
                )))
                .map_err(e)?
                .label("β₀ 95% interval")
                .legend(|(x, y)| {
                    Rectangle::new(
                        [(x, y - 6), (x + 20, y + 6)],
                        RGBColor(120, 120, 120).mix(0.3).filled(),
                    )
                });
        }
        // Reference line beta = 0 and the kink.
        chart
            .draw_series(LineSeries::new(
                [(0.0, 0.0), (x_max, 0.0)],
                BLACK.mix(0.3).stroke_width(1),
            ))
            .map_err(e)?;
        if fit.converged && fit.kink_psi < x_max {
            chart
                .draw_series(DashedLineSeries::new(
                    [(fit.kink_psi, y_min), (fit.kink_psi, fit.beta0)],
                    6,
                    4,
                    BLACK.mix(0.6).stroke_width(1),
                ))
                .map_err(e)?;
        }
        let sliding: Vec<&Fig6Point> = points.iter().filter(|p| p.sliding).collect();
        let rolling: Vec<&Fig6Point> = points.iter().filter(|p| !p.sliding).collect();
        chart
            .draw_series(
                sliding
                    .iter()
                    .filter(|p| p.psi <= x_max)
                    .map(|p| Circle::new((p.psi, p.beta), 5, SLIDING.filled())),
            )
            .map_err(e)?
            .label(format!("sliding ({})", sliding.len()))
            .legend(|(x, y)| Circle::new((x + 10, y), 5, SLIDING.filled()));
        chart
            .draw_series(
                rolling
                    .iter()
                    .filter(|p| p.psi <= x_max)
                    .map(|p| TriangleMarker::new((p.psi, p.beta), 7, ROLLING.filled())),
            )
            .map_err(e)?
            .label(format!("rolling ({})", rolling.len()))
            .legend(|(x, y)| TriangleMarker::new((x + 10, y), 7, ROLLING.filled()));
        let kink = fit.kink_psi.min(x_max);
        let hinge = [
            (0.0, -1.0),
            (kink, -1.0 + fit.slope * kink),
            (x_max, (-1.0 + fit.slope * x_max).min(fit.beta0)),
        ];
        let label = if fit.converged {
            format!(
                "fit: β₀ = {:.3}, μ₀ = {:.4}, e = {:.3}",
                fit.beta0, fit.mu0, fit.e
            )
        } else {
            "fit (not determined: a branch has no data)".to_string()
        };
        chart
            .draw_series(LineSeries::new(hinge, BLACK.stroke_width(2)))
            .map_err(e)?
            .label(label)
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        super::legend(&mut chart, SeriesLabelPosition::LowerRight, 19)?;
        root.present().map_err(e)?;
    }
    Ok(svg)
}
