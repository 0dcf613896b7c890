//! `track`: the call of `restitution track` (src/cli/track.rs): the library's track job
//! (`data::frames::job`) over directories of frames, and its documents (the JSON of
//! `--format json`, tracks.csv, the printed summary, the files of `--out`).

use crate::{Failure, Outcome, run_detached};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use restitution::data::frames::job::{
    TrackJobError, TrackRequest, track_dirs, track_files, warnings,
};
use restitution::data::frames::{results_json_text, tracks_csv};
use restitution::data::report::track::to_table;
use restitution::data::{ArgStyle, write_all_atomic};
use std::path::PathBuf;

fn failure(e: TrackJobError) -> Failure {
    match e {
        TrackJobError::Data(d) => Failure::Data(d),
        // An overlay that cannot be drawn is not the caller's input.
        TrackJobError::Plot(p) => Failure::Numerical(p.to_string()),
        TrackJobError::Input(_) | TrackJobError::Tracking(_) => Failure::Input(e.to_string()),
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(track, m)?)?;
    Ok(())
}

struct Done {
    json: String,
    tracks_csv: String,
    table: String,
    warnings: Vec<String>,
}

/// Sphere centres and spins from directories of frames, as `restitution track` finds them.
#[pyfunction]
#[pyo3(signature = (dirs, fps, pixel_m=None, d_mm=None, out=None, strict=false))]
fn track<'py>(
    py: Python<'py>,
    dirs: Vec<PathBuf>,
    fps: f64,
    pixel_m: Option<f64>,
    d_mm: Option<Vec<f64>>,
    out: Option<PathBuf>,
    strict: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let done = run_detached(py, move || -> Outcome<Done> {
        let request = TrackRequest {
            style: ArgStyle::Keywords,
            fps,
            pixel_m,
            d_mm,
            strict,
        };
        let results = track_dirs(&dirs, &request, &|| {}).map_err(failure)?;
        if let Some(dir) = &out {
            let files: Vec<(PathBuf, Vec<u8>)> = track_files(&results)
                .map_err(failure)?
                .into_iter()
                .map(|(name, bytes)| (dir.join(name), bytes))
                .collect();
            std::fs::create_dir_all(dir).map_err(|e| {
                Failure::Input(format!(
                    "{}: cannot create the directory: {e}",
                    dir.display()
                ))
            })?;
            write_all_atomic(&files)
                .map_err(|e| Failure::Input(format!("{}: cannot write: {e}", dir.display())))?;
        }
        Ok(Done {
            json: results_json_text(&results),
            tracks_csv: tracks_csv(&results),
            table: to_table(&results),
            warnings: warnings(&results),
        })
    })?;
    let d = PyDict::new(py);
    d.set_item("json", done.json)?;
    d.set_item("tracks_csv", done.tracks_csv)?;
    d.set_item("table", done.table)?;
    d.set_item("warnings", done.warnings)?;
    Ok(d)
}
