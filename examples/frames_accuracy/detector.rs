//! The project's detector (`frames::detect`), as a method of the study: one call per frame,
//! default settings plus the known radii (the diameters are known in the experiment), found
//! spheres matched to the hints by nearest centre.

use super::Found;
use restitution::frames::GrayImage;
use restitution::frames::detect::{DetectSettings, detect_frame};

pub fn detector(img: &GrayImage, hints: &[[f64; 2]], radii: &[f64]) -> Vec<Option<Found>> {
    let settings = DetectSettings {
        known_radii_px: radii.to_vec(),
        ..DetectSettings::default()
    };
    let Ok(det) = detect_frame(img, &settings) else {
        return vec![None; hints.len()];
    };
    hints
        .iter()
        .zip(radii)
        .map(|(h, r)| {
            det.spheres
                .iter()
                .enumerate()
                .map(|(i, s)| ((s.circle.cx - h[0]).hypot(s.circle.cy - h[1]), i))
                .filter(|(d, _)| *d < 0.5 * r)
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, i)| {
                    let s = &det.spheres[i];
                    Found {
                        centre: [s.circle.cx, s.circle.cy],
                        radius: s.circle.r,
                        markers: det
                            .markers
                            .get(i)
                            .map(|ms| ms.iter().map(|m| [m.u, m.v]).collect())
                            .unwrap_or_default(),
                    }
                })
        })
        .collect()
}
