//! The pixel size and the spheres' diameters of a collision: short arcs refitted with the radius
//! held, then the scale from the known diameters or the diameters from the known scale (the
//! parent module's doc gives the procedure).

use super::*;

/// Refits short arcs with a held radius and finds the pixel size. See the module doc.
pub(super) fn refit_and_scale(
    frames: &mut [FrameResult],
    s: &TrackSettings,
    warnings: &mut Vec<String>,
) -> Result<Scale, TrackError> {
    let radii: [Vec<f64>; 2] = std::array::from_fn(|k| {
        frames
            .iter()
            .filter_map(|f| {
                f.spheres[k]
                    .as_ref()
                    .filter(|o| well_seen(o, s))
                    .map(|o| o.r_px)
            })
            .collect()
    });
    let measured: [Option<f64>; 2] =
        std::array::from_fn(|k| (!radii[k].is_empty()).then(|| median(&mut radii[k].clone())));
    let nominal: [Option<f64>; 2] = std::array::from_fn(|k| match (s.d_m, s.pixel_m) {
        (Some(d), Some(p)) => Some(d[k] / p / 2.0),
        _ => None,
    });
    for f in frames.iter_mut() {
        for k in 0..2 {
            let Some(o) = f.spheres[k].as_mut() else {
                continue;
            };
            if o.coverage_deg >= s.free_coverage_deg {
                continue;
            }
            let Some(r) = measured[k].or(nominal[k]) else {
                warnings.push(format!(
                    "{}: sphere {}: edge seen over {:.0} degrees only and no known radius (give --d-mm and --pixel-m): free fit kept",
                    f.meta.name,
                    k + 1,
                    o.coverage_deg
                ));
                continue;
            };
            match fit_robust(&o.edges, Some(r), 3.0, 0.1, 8) {
                Ok(rf) => {
                    let c = rf.fit.circle;
                    o.x_px = c.cx;
                    o.y_px = c.cy;
                    o.r_px = c.r;
                    o.rms_px = rf.fit.rms;
                    o.centre_err_px = rf.fit.centre_err;
                    o.n_edge = rf.n_used;
                    o.coverage_deg = coverage_deg(
                        &c,
                        o.edges
                            .iter()
                            .zip(&rf.inliers)
                            .filter(|x| *x.1)
                            .map(|x| *x.0),
                    );
                    o.inliers = rf.inliers;
                    o.radius_mode = RadiusMode::Fixed;
                }
                Err(e) => {
                    let why = format!("sphere {}: fit with the radius held failed: {e}", k + 1);
                    if s.strict {
                        return Err(err(Some(&f.meta.name), why));
                    }
                    warnings.push(format!("{}: {why}; sphere left out", f.meta.name));
                    f.spheres[k] = None;
                }
            }
        }
    }
    if let Some(p) = s.pixel_m {
        return Ok(Scale {
            pixel_m: p,
            err_m: None,
            from_diameters: false,
            n_fits: 0,
        });
    }
    let d = s
        .d_m
        .ok_or_else(|| err(None, "the scale needs the pixel size or the diameters"))?;
    let samples: Vec<f64> = (0..2)
        .flat_map(|k| radii[k].iter().map(move |r| d[k] / (2.0 * r)))
        .collect();
    if samples.is_empty() {
        return Err(err(
            None,
            format!(
                "no frame shows {:.0} degrees of a sphere's edge inside the image, so the pixel size cannot be measured from the diameters: give --pixel-m",
                s.free_coverage_deg
            ),
        ));
    }
    let (m, e) = mean_err(&samples);
    Ok(Scale {
        pixel_m: m,
        err_m: e,
        from_diameters: true,
        n_fits: samples.len(),
    })
}

fn mean_err(v: &[f64]) -> (f64, Option<f64>) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (m, None);
    }
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, Some((var / n).sqrt()))
}

pub(super) fn diameters(
    frames: &[FrameResult],
    s: &TrackSettings,
    scale: &Scale,
    id: &str,
) -> Result<([f64; 2], Option<[f64; 2]>), TrackError> {
    if let Some(d) = s.d_m {
        return Ok((d, None));
    }
    let mut d = [0.0; 2];
    let mut e = [0.0; 2];
    for k in 0..2 {
        let r: Vec<f64> = frames
            .iter()
            .filter_map(|f| {
                f.spheres[k]
                    .as_ref()
                    .filter(|o| well_seen(o, s))
                    .map(|o| o.r_px)
            })
            .collect();
        if r.is_empty() {
            return Err(err(
                Some(id),
                format!(
                    "sphere {}'s diameter cannot be measured: no frame shows {:.0} degrees of its edge inside the image (give --d-mm)",
                    k + 1,
                    s.free_coverage_deg
                ),
            ));
        }
        let (m, se) = mean_err(&r);
        d[k] = 2.0 * m * scale.pixel_m;
        e[k] = 2.0 * se.unwrap_or(f64::NAN) * scale.pixel_m;
    }
    Ok((d, e.iter().all(|x| x.is_finite()).then_some(e)))
}
