//! `track`'s printed summary: per collision the scale, the diameters, one line per frame
//! (centres, radii and fit residuals in pixels, or why the frame was left out) and the spins.

use crate::data::readable;
use crate::frames::spin::Spin;
use crate::frames::track::CollisionResult;
use std::fmt::Write;

/// The summary `restitution track` prints (`--format table`).
pub fn to_table(results: &[CollisionResult]) -> String {
    let mut out = String::new();
    for r in results {
        let scale = match (r.scale.from_diameters, r.scale.err_m) {
            (true, Some(e)) => format!(
                "{} +- {} m/pixel (from the diameters, {} fits)",
                readable(r.scale.pixel_m),
                readable(e),
                r.scale.n_fits
            ),
            (true, None) => format!(
                "{} m/pixel (from the diameters, 1 fit: no uncertainty)",
                readable(r.scale.pixel_m)
            ),
            (false, _) => format!("{} m/pixel (given)", readable(r.scale.pixel_m)),
        };
        let _ = writeln!(
            out,
            "collision {}: {} frames, {} used, {} x {} pixels; scale {scale}",
            r.id,
            r.frames.len(),
            r.tracks.len(),
            r.width,
            r.height
        );
        let d = match r.d_err_m {
            Some(e) => format!(
                "d1 = {} +- {} mm, d2 = {} +- {} mm (measured)",
                readable(r.d_m[0] * 1e3),
                readable(e[0] * 1e3),
                readable(r.d_m[1] * 1e3),
                readable(e[1] * 1e3)
            ),
            None => format!(
                "d1 = {} mm, d2 = {} mm",
                readable(r.d_m[0] * 1e3),
                readable(r.d_m[1] * 1e3)
            ),
        };
        let _ = writeln!(out, "{d}");
        let _ = writeln!(
            out,
            "{:>6} {:>9} {:>10} {:>10} {:>8} {:>8} {:>10} {:>10} {:>8} {:>8}  note",
            "frame",
            "t_s",
            "x1_px",
            "y1_px",
            "r1_px",
            "res1_px",
            "x2_px",
            "y2_px",
            "r2_px",
            "res2_px"
        );
        for f in &r.frames {
            let cell = |k: usize| match &f.spheres[k] {
                Some(o) => format!(
                    "{:>10.3} {:>10.3} {:>8.3} {:>8.3}",
                    o.x_px, o.y_px, o.r_px, o.rms_px
                ),
                None => format!("{:>10} {:>10} {:>8} {:>8}", "-", "-", "-", "-"),
            };
            let _ = writeln!(
                out,
                "{:>6} {:>9} {} {}  {}",
                f.meta.number,
                readable(f.t_s),
                cell(0),
                cell(1).trim_start(),
                f.note
                    .as_deref()
                    .unwrap_or(if f.used { "" } else { "left out" })
            );
        }
        for (k, phases) in r.spins.iter().enumerate() {
            for (p, s) in phases.iter().enumerate() {
                let phase = if p == 0 { "before" } else { "after" };
                let text = match s {
                    Spin::Full {
                        w_rad_s,
                        err_rad_s,
                        pairs,
                    } => format!(
                        "w = ({}, {}, {}) rad/s{} from {}",
                        readable(w_rad_s[0]),
                        readable(w_rad_s[1]),
                        readable(w_rad_s[2]),
                        // One pair has no scatter to give an error: said, not left blank.
                        err_rad_s
                            .map(|e| format!(
                                " +- ({}, {}, {})",
                                readable(e[0]),
                                readable(e[1]),
                                readable(e[2])
                            ))
                            .unwrap_or_else(|| " (error unknown: one pair has no scatter)".into()),
                        frame_pairs(*pairs)
                    ),
                    Spin::ZOnly {
                        wz_rad_s, pairs, ..
                    } => format!(
                        "w_z = {} rad/s from {} (one marker: assumes the axis is the camera axis)",
                        readable(*wz_rad_s),
                        frame_pairs(*pairs)
                    ),
                    Spin::None { reason } => format!("no spin: {reason}"),
                };
                let _ = writeln!(out, "sphere {} {phase}: {text}", k + 1);
            }
        }
        let _ = writeln!(out);
    }
    out
}

fn frame_pairs(n: usize) -> String {
    format!("{n} frame pair{}", if n == 1 { "" } else { "s" })
}
