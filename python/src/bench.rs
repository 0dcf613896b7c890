//! Baselines for `python/bench/bench_speed.py`: the library calls of `e_of_kappa` and `fit`
//! timed inside the extension, without the Python layer, so the benchmark can alternate them
//! with the Python calls and compare pairs measured under the same machine load.

use crate::{Failure, Outcome, run_detached};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use restitution::contact::Material;
use restitution::data::fit_input::read_fit_csv;
use restitution::data::report::fit::{self as report, ReportContext};
use restitution::fit::{FitOptions, ModelKind, fit_all};
use restitution::models::viscoelastic::{ContactEnd, VmMethod, restitution as e_vm};
use std::hint::black_box;
use std::time::Instant;

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(_bench_loop_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(_bench_fit_seconds, m)?)?;
    Ok(())
}

/// Seconds of the plain library loop `restitution(kappa, Overlap, Master)` over a copy of
/// `kappa`, collected into a Vec (the copy is made before the clock starts).
#[pyfunction]
fn _bench_loop_seconds(py: Python<'_>, kappa: PyReadonlyArray1<'_, f64>) -> PyResult<f64> {
    let kappa = kappa.as_array().to_vec();
    run_detached(py, move || {
        let t = Instant::now();
        let e = kappa
            .iter()
            .map(|&k| e_vm(k, ContactEnd::Overlap, &VmMethod::Master).map(|r| r.e))
            .collect::<Result<Vec<f64>, _>>()
            .map_err(|e| Failure::library("", &e))?;
        black_box(e);
        Ok(t.elapsed().as_secs_f64())
    })
}

/// Seconds to read `path`, fit (`model`: "all" or "vm") and render the JSON document, nylon,
/// default options: what `restitution fit --format json` computes.
#[pyfunction]
fn _bench_fit_seconds(py: Python<'_>, path: std::path::PathBuf, model: &str) -> PyResult<f64> {
    let kinds = match model {
        "all" => ModelKind::ALL.to_vec(),
        _ => vec![ModelKind::Vm],
    };
    run_detached(py, move || -> Outcome<f64> {
        let t = Instant::now();
        let nylon = Material::preset("nylon").expect("a preset");
        let input = read_fit_csv(&path, nylon, false)?;
        let options = FitOptions::default();
        let set = fit_all(&input.data, &kinds, &options).map_err(|e| Failure::library("", &e))?;
        let ctx = ReportContext {
            path: &input.path,
            data: &input.data,
            error_source: input.error_source.describe(),
            rule: options.rule,
            vm_method: &options.vm_method,
        };
        black_box(report::to_json(&ctx, &set).to_string());
        Ok(t.elapsed().as_secs_f64())
    })
}
