//! The overlay figure of `track`, after the paper's Fig. 5: the grey frame with the edge points
//! the fits used (and those they rejected), the fitted circles, their centres (stars) and the
//! markers. Axes in pixels, x right, y up. The frame is embedded as a PNG (given already
//! encoded, so this module needs no image codec).

use super::{PlotError, PlotFailure};
use crate::frames::track::FrameResult;
use plotters::prelude::*;

fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Renders the overlay as SVG. `png` is the frame (width x height pixels) encoded as PNG.
pub fn overlay_svg(
    png: &[u8],
    width: usize,
    height: usize,
    frame: &FrameResult,
    title: &str,
) -> Result<String, PlotError> {
    draw(png, width, height, frame, title).map_err(PlotError::of(format!("the overlay: {title}")))
}

fn draw(
    png: &[u8],
    width: usize,
    height: usize,
    frame: &FrameResult,
    title: &str,
) -> Result<String, PlotFailure> {
    let (w, h) = (width as f64, height as f64);
    // Screen pixels per image pixel: the larger side about 720 px.
    let k = 720.0 / w.max(h);
    let (pw, ph) = ((w * k).round() as u32, (h * k).round() as u32);
    let (left, bottom, top, right) = (70u32, 55u32, 50u32, 190u32);
    let mut svg = String::new();
    let area;
    {
        let root = SVGBackend::with_string(&mut svg, (pw + left + right, ph + bottom + top))
            .into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| PlotFailure::backend(e);
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin_right(right)
            .x_label_area_size(bottom)
            .y_label_area_size(left)
            .build_cartesian_2d(0.0..w, 0.0..h)
            .map_err(e)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x (pixels)")
            .y_desc("y (pixels)")
            .axis_desc_style(("sans-serif", 18))
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(e)?;
        area = chart.plotting_area().get_pixel_range();
        let used = RGBColor(0, 200, 80);
        let rejected = RGBColor(230, 40, 40);
        let marker = RGBColor(255, 190, 0);
        for (s, obs) in frame.spheres.iter().enumerate() {
            let Some(o) = obs else { continue };
            let (inl, outl): (Vec<_>, Vec<_>) =
                o.edges.iter().zip(&o.inliers).partition(|(_, used)| **used);
            chart
                .draw_series(
                    inl.iter()
                        .map(|(p, _)| Circle::new((p[0], p[1]), 1, used.filled())),
                )
                .map_err(e)?;
            chart
                .draw_series(
                    outl.iter()
                        .map(|(p, _)| Cross::new((p[0], p[1]), 3, rejected.stroke_width(1))),
                )
                .map_err(e)?;
            chart
                .draw_series(
                    o.markers
                        .iter()
                        .map(|m| Circle::new((m[0], m[1]), 5, marker.stroke_width(2))),
                )
                .map_err(e)?;
            let circle: Vec<(f64, f64)> = (0..=180)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / 180.0;
                    (o.x_px + o.r_px * a.cos(), o.y_px + o.r_px * a.sin())
                })
                .collect();
            chart
                .draw_series(LineSeries::new(circle, super::colour(s).stroke_width(2)))
                .map_err(e)?;
            // A star at the centre: black strokes under white ones, visible on any sphere.
            let arm = 9.0 / k;
            let star: Vec<PathElement<(f64, f64)>> = [(BLACK, 4), (WHITE, 2)]
                .iter()
                .flat_map(|&(colour, width)| {
                    (0..3).map(move |i| {
                        let a = std::f64::consts::PI * (0.5 + i as f64 / 3.0);
                        PathElement::new(
                            vec![
                                (o.x_px - arm * a.cos(), o.y_px - arm * a.sin()),
                                (o.x_px + arm * a.cos(), o.y_px + arm * a.sin()),
                            ],
                            colour.stroke_width(width),
                        )
                    })
                })
                .collect();
            chart.draw_series(star).map_err(e)?;
        }
        // The legend, drawn by hand to the right of the frame (plotters places series labels
        // inside the plotting area, over the image).
        let x0 = area.0.end + 20;
        let mut y = area.1.start + 10;
        let font = ("sans-serif", 15).into_font();
        let mut entry = |text: String, glyph: &dyn Fn(i32, i32) -> Result<(), PlotFailure>| {
            glyph(x0 + 8, y)?;
            root.draw(&Text::new(text, (x0 + 24, y - 7), font.clone()))
                .map_err(e)?;
            y += 24;
            Ok::<(), PlotFailure>(())
        };
        for (s, obs) in frame.spheres.iter().enumerate() {
            let Some(o) = obs else { continue };
            let c = super::colour(s);
            entry(
                format!("sphere {}: r = {:.2} px", s + 1, o.r_px),
                &|x, y| {
                    root.draw(&PathElement::new(
                        vec![(x - 8, y), (x + 8, y)],
                        c.stroke_width(2),
                    ))
                    .map_err(e)
                },
            )?;
            entry(
                format!("  {} edge points, {}", o.n_edge, o.radius_mode.name()),
                &|_, _| Ok(()),
            )?;
        }
        entry("edge points used".into(), &|x, y| {
            root.draw(&Circle::new((x, y), 3, used.filled())).map_err(e)
        })?;
        entry("edge points rejected".into(), &|x, y| {
            root.draw(&Cross::new((x, y), 4, rejected.stroke_width(1)))
                .map_err(e)
        })?;
        entry("markers".into(), &|x, y| {
            root.draw(&Circle::new((x, y), 5, marker.stroke_width(2)))
                .map_err(e)
        })?;
        entry("centres".into(), &|x, y| {
            for (colour, width) in [(BLACK, 4), (WHITE, 2)] {
                for i in 0..3 {
                    let a = std::f64::consts::PI * (0.5 + i as f64 / 3.0);
                    let (dx, dy) = ((8.0 * a.cos()) as i32, (8.0 * a.sin()) as i32);
                    root.draw(&PathElement::new(
                        vec![(x - dx, y - dy), (x + dx, y + dy)],
                        colour.stroke_width(width),
                    ))
                    .map_err(e)?;
                }
            }
            Ok(())
        })?;
        root.present().map_err(e)?;
    }
    // The frame goes right after the background rectangle, under everything else.
    let at = svg
        .find("<rect")
        .and_then(|i| svg[i..].find("/>").map(|j| i + j + 2))
        .ok_or(PlotFailure::Backend(
            "the SVG has no background rectangle to put the frame on".into(),
        ))?;
    let image = format!(
        "\n<image x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" preserveAspectRatio=\"none\" style=\"image-rendering:pixelated\" href=\"data:image/png;base64,{}\"/>",
        area.0.start,
        area.1.start,
        area.0.end - area.0.start,
        area.1.end - area.1.start,
        base64(png)
    );
    svg.insert_str(at, &image);
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::base64;

    #[test]
    fn base64_known_answers() {
        // RFC 4648, section 10.
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }
}
