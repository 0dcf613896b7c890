//! `camera_study.csv` of `restitution simulate --camera-study`: one row per camera, fit and speed.

use crate::data::{CsvOut, fmt_num};
use crate::experiment::StudyPoint;

/// The study's points as CSV: `camera,fit,v_n_m_s,simulated,measured,bias,scatter`. A point
/// without measured collisions has no bias or scatter: those cells are empty (`measured` says
/// why), never NaN.
pub fn camera_study_csv(points: &[StudyPoint]) -> String {
    let mut csv = CsvOut::new();
    csv.record([
        "camera",
        "fit",
        "v_n_m_s",
        "simulated",
        "measured",
        "bias",
        "scatter",
    ]);
    let finite = |x: f64| {
        if x.is_finite() {
            fmt_num(x)
        } else {
            String::new()
        }
    };
    for p in points {
        csv.record([
            p.camera.to_string(),
            p.fit.to_string(),
            fmt_num(p.v_n_m_s),
            p.simulated.to_string(),
            p.measured.to_string(),
            finite(p.bias),
            finite(p.scatter),
        ]);
    }
    csv.into_string()
}
