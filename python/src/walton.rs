//! `walton_fit`: the calls of `restitution walton fit` (src/cli/walton/): read the collisions,
//! measure them, fit Walton's operator, and the command's JSON document, built by the same
//! library function (`data::report::walton::to_json`).

use crate::{Failure, Outcome, Source, run_detached};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use restitution::data::report::walton::{Context, to_json};
use restitution::data::walton::{measure_records, momentum_warning, read_collisions};
use restitution::fit::walton::{self as wfit, FitOptions, Weights};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(walton_fit, m)?)?;
    Ok(())
}

/// Reads, measures and fits oblique collisions, as `restitution walton fit` does.
#[pyfunction]
#[pyo3(signature = (
    path=None, name=None, text=None, material=None, youngs_pa=None, poisson=None,
    density_kg_m3=None, inertia_k=restitution::models::walton::K_HOMOGENEOUS, weights="camera",
    bootstrap=2000, seed=1
))]
#[allow(clippy::too_many_arguments)]
fn walton_fit<'py>(
    py: Python<'py>,
    path: Option<std::path::PathBuf>,
    name: Option<String>,
    text: Option<String>,
    material: Option<&str>,
    youngs_pa: Option<f64>,
    poisson: Option<f64>,
    density_kg_m3: Option<f64>,
    inertia_k: f64,
    weights: &str,
    bootstrap: usize,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let material = crate::material(material, youngs_pa, poisson, density_kg_m3);
    let source = Source::new(path, name, text);
    let weights = match weights {
        "camera" => Ok(Weights::Camera),
        "equal" => Ok(Weights::Equal),
        w => Err(Failure::Input(format!(
            "weights '{w}': expected camera or equal"
        ))),
    };
    let (json, warnings) = run_detached(py, move || -> Outcome<(String, Vec<String>)> {
        let (material, weights) = (material?, weights?);
        if !restitution::models::walton::inertia_k_ok(inertia_k) {
            return Err(Failure::Input(format!(
                "inertia_k = {}: expected {}",
                restitution::data::fmt_num(inertia_k),
                restitution::models::walton::INERTIA_K_EXPECTED
            )));
        }
        if bootstrap == 1 {
            return Err(Failure::Input(
                "bootstrap = 1: expected 0 (no intervals) or at least 2 resamples".into(),
            ));
        }
        let table = source?.table()?;
        let (records, mut warnings) = read_collisions(&table, &material, inertia_k)?;
        let measured = measure_records(&table.path, &records)?;
        warnings.extend(momentum_warning(&table.path, &records, &measured));
        let options = FitOptions {
            inertia_k,
            weights,
            bootstrap,
            seed,
        };
        let fit = wfit::fit(&measured, &options)
            .map_err(|e| Failure::library(&format!("{}: cannot fit", table.path), &e))?;
        let ctx = Context::new(
            &table.path,
            &records,
            material,
            "restitution.walton_fit".into(),
        );
        Ok((to_json(&fit, &ctx), warnings))
    })?;
    let d = PyDict::new(py);
    d.set_item("json", json)?;
    d.set_item("input_warnings", warnings)?;
    Ok(d)
}
