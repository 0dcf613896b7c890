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
    /// Why the fit is not determined, for the legend (None: converged).
    pub not_determined: Option<&'static str>,
}

/// The corner of the plot where the legend covers the fewest points, the hinge's line counting a
/// tenth of a point per sample (the lower right unless another covers fewer), and how many
/// points it covers there. Its size: `rows`
/// entries of 25 px and 10 px per character of the longest label `chars`, plus the sample and
/// margins, on the plot's 785 x 490 px. Ten near-head-on collisions had one of their points
/// under the legend, fixed in the lower right, where the plateau's noise scattered below -1.
fn legend_corner(
    points: &[Fig6Point],
    hinge: &[(f64, f64); 3],
    (x_max, y_min, y_max): (f64, f64, f64),
    (rows, chars): (usize, usize),
) -> (SeriesLabelPosition, usize) {
    let w = ((10 * chars + 80) as f64 / 785.0).min(1.0) * x_max;
    let h = legend_height(rows) * (y_max - y_min);
    let line = hinge.windows(2).flat_map(|s| {
        (0..=20).map(move |k| {
            let t = f64::from(k) / 20.0;
            (
                s[0].0 + t * (s[1].0 - s[0].0),
                s[0].1 + t * (s[1].1 - s[0].1),
            )
        })
    });
    // (points hidden, line samples hidden)
    let cost = |right: bool, upper: bool| {
        let inside = |(x, y): (f64, f64)| {
            let xs = if right { x >= x_max - w } else { x <= w };
            let ys = if upper {
                y >= y_max - h
            } else {
                y <= y_min + h
            };
            xs && ys && x <= x_max
        };
        let hidden = points.iter().filter(|p| inside((p.psi, p.beta))).count();
        (hidden, line.clone().filter(|&p| inside(p)).count())
    };
    let score = |(points, samples): (usize, usize)| points as f64 + 0.1 * samples as f64;
    [
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerLeft, false, false),
        (SeriesLabelPosition::UpperRight, true, true),
    ]
    .into_iter()
    .map(|(pos, right, upper)| (pos, cost(right, upper)))
    .fold(
        None::<(SeriesLabelPosition, (usize, usize))>,
        |best, (pos, c)| match best {
            Some((_, b)) if score(b) <= score(c) => best,
            _ => Some((pos, c)),
        },
    )
    .map_or(
        (SeriesLabelPosition::LowerRight, 0),
        |(pos, (points, _))| (pos, points),
    )
}

/// The legend's height with `rows` entries, as a fraction of the plot's (25 px per row and
/// margins, on 490 px).
fn legend_height(rows: usize) -> f64 {
    ((25 * rows + 30) as f64 / 490.0).min(0.5)
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
    let kink = fit.kink_psi.min(x_max);
    let hinge = [
        (0.0, -1.0),
        (kink, -1.0 + fit.slope * kink),
        (x_max, (-1.0 + fit.slope * x_max).min(fit.beta0)),
    ];
    let label = match fit.not_determined {
        None => format!(
            "fit: β₀ = {}, μ₀ = {}, e = {}",
            super::short(fit.beta0),
            super::short(fit.mu0),
            super::short(fit.e)
        ),
        Some(why) => format!("fit (not determined: {why})"),
    };
    let label_chars = label.chars().count();
    let band = fit.beta0_ci95.is_some() && fit.not_determined.is_none();
    let legend_size = (3 + usize::from(band), label_chars);
    // Where every corner would hide a point, the axis reaches down by the legend's height: it
    // then sits below the data (which stay above the old y_min) and the hinge (above -1).
    let (mut corner, covered) = legend_corner(points, &hinge, (x_max, y_min, y_max), legend_size);
    let y_min = if covered > 0 {
        let frac = legend_height(legend_size.0);
        corner = SeriesLabelPosition::LowerRight;
        y_min - frac / (1.0 - frac) * (y_max - y_min)
    } else {
        y_min
    };
    // Betas near +-f64::MAX (a tangential speed of 1e-160 m/s before and 1e148 after) make the
    // axis's span infinite, and the axis's ticks never ended.
    if !(y_max - y_min).is_finite() {
        return Err(PlotFailure::NothingToDraw(format!(
            "betas from {} to {}: a span beyond the range of a double",
            crate::error::Num(y_min),
            crate::error::Num(y_max)
        )));
    }

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
            // Beyond 1e4 in shortest form: betas of 1e300 had printed 301 digits.
            .y_label_formatter(&|v| match v.abs() {
                a if a < 1e-9 => "0.0".to_string(),
                a if a < 1e4 => format!("{v:.1}"),
                _ => super::short(*v),
            })
            .axis_desc_style(("sans-serif", 22))
            .label_style(("sans-serif", 18))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(e)?;
        // beta_0's 95% interval along the plateau.
        if let Some((lo, hi)) = fit.beta0_ci95
            && fit.not_determined.is_none()
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
        if fit.not_determined.is_none() && fit.kink_psi < x_max {
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
        chart
            .draw_series(LineSeries::new(hinge, BLACK.stroke_width(2)))
            .map_err(e)?
            .label(label)
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        super::legend(&mut chart, corner, 19)?;
        root.present().map_err(e)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(psi: f64, beta: f64) -> Fig6Point {
        Fig6Point {
            psi,
            beta,
            sliding: false,
        }
    }

    /// Known answers on a plot of psi in [0, 10], beta in [-1.5, 1.5] with the paper's hinge
    /// (kink at psi 3, plateau 0.5): the legend of 3 rows and a 30-character label takes the
    /// right 48% (380 px of 785) and the lower 21% (105 px of 490) in the lower right.
    #[test]
    fn the_legend_goes_where_it_hides_no_point() {
        let hinge = [(0.0, -1.0), (3.0, 0.5), (10.0, 0.5)];
        let range = (10.0, -1.5, 1.5);
        let size = (3, 30);
        // Nothing in the lower right: it stays there.
        let (pos, covered) = legend_corner(&[at(1.0, 0.0), at(8.0, 0.5)], &hinge, range, size);
        assert!(matches!(pos, SeriesLabelPosition::LowerRight) && covered == 0);
        // A point there: the upper left, which hides neither a point nor the line, instead.
        let (pos, covered) = legend_corner(&[at(8.0, -1.3)], &hinge, range, size);
        assert!(matches!(pos, SeriesLabelPosition::UpperLeft) && covered == 0);
        // A point in every corner: one is covered wherever it goes (the axis then makes room).
        let corners = [at(9.0, -1.4), at(0.5, 1.4), at(0.5, -1.4), at(9.0, 1.4)];
        let (_, covered) = legend_corner(&corners, &hinge, range, size);
        assert_eq!(covered, 1);
        // The figure then reaches down by the legend's height: from -1.45 to about -2.2, so a
        // tick at -2.0 appears; with the lower right free it does not.
        let fit = Fig6Fit {
            slope: 0.5,
            beta0: 0.5,
            kink_psi: 3.0,
            beta0_ci95: None,
            mu0: 0.1,
            e: 0.9,
            not_determined: None,
        };
        let svg = fig6_svg(&corners, &fit, "t").unwrap();
        assert!(svg.contains("\n-2.0\n"), "no tick at -2.0");
        let free = [at(0.5, -1.4), at(0.5, 1.4), at(9.0, 1.4)];
        let svg = fig6_svg(&free, &fit, "t").unwrap();
        assert!(!svg.contains("\n-2.0\n") && svg.contains("\n-1.0\n"));
    }

    /// Betas of +-1e308 span more than a double: an error in bounded time (the axis's ticks had
    /// never ended); +-1e300 still draw.
    #[test]
    fn betas_beyond_a_doubles_span_are_an_error_not_a_hang() {
        let fit = Fig6Fit {
            slope: 0.5,
            beta0: 0.5,
            kink_psi: 3.0,
            beta0_ci95: None,
            mu0: 0.1,
            e: 0.9,
            not_determined: Some("a branch has no data"),
        };
        for (b, ok) in [(1e300, true), (1e308, false)] {
            let pts = [at(9.0, -b), at(9.5, b), at(0.5, b), at(0.5, -b)];
            let r = fig6_svg(&pts, &fit, "t");
            assert_eq!(r.is_ok(), ok, "{b}: {:?}", r.err().map(|e| e.to_string()));
        }
    }
}
