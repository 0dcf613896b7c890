//! `walton_fit`: the calls of `restitution walton fit` (src/cli/walton/): read the collisions,
//! measure them, fit Walton's operator. The CLI's JSON document is built inside src/cli and is
//! not reusable yet, so this returns the library's `WaltonFit` as a dict (same names where the
//! two share a number).

use crate::{Failure, Outcome, Source, run_detached};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use restitution::data::walton::{measure_records, read_collisions};
use restitution::fit::walton::{
    self as wfit, Bound as WBound, Estimate, FitOptions, WaltonFit, Weights,
};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(walton_fit, m)?)?;
    Ok(())
}

fn estimate<'py>(py: Python<'py>, e: &Estimate) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("value", e.value)?;
    d.set_item("stderr", e.stderr)?;
    d.set_item("ci95", e.ci95)?;
    d.set_item(
        "bound",
        e.bound.map(|b| match b {
            WBound::Lower => "lower",
        }),
    )?;
    Ok(d)
}

fn to_dict<'py>(
    py: Python<'py>,
    fit: &WaltonFit,
    path: &str,
    lines: &[usize],
    ids: &[Option<String>],
    warnings: &[String],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("path", path)?;
    d.set_item("inertia_k", fit.options.inertia_k)?;
    d.set_item("weights", fit.options.weights.as_str())?;
    let e = PyDict::new(py);
    e.set_item("value", fit.e.value)?;
    e.set_item("stderr", fit.e.stderr)?;
    e.set_item("ci95", fit.e.ci95)?;
    e.set_item("spread", fit.e.spread)?;
    e.set_item("min", fit.e.min)?;
    e.set_item("max", fit.e.max)?;
    d.set_item("e", e)?;
    d.set_item("beta0", estimate(py, &fit.beta0)?)?;
    d.set_item("mu0", estimate(py, &fit.mu0)?)?;
    d.set_item("slope", estimate(py, &fit.slope)?)?;
    d.set_item("psi_kink", estimate(py, &fit.kink_psi)?)?;
    // The critical angle exists only when the kink is determined.
    d.set_item("gamma0_deg", fit.converged.then(|| fit.gamma0_deg()))?;
    d.set_item("n", fit.n)?;
    d.set_item("n_sliding", fit.n_sliding)?;
    d.set_item("n_rolling", fit.n_rolling)?;
    d.set_item("n_head_on", fit.n_head_on)?;
    d.set_item(
        "impulse_ratio_sliding",
        fit.impulse_ratio_sliding.map(|(value, stderr)| {
            let r = PyDict::new(py);
            let _ = r.set_item("value", value);
            let _ = r.set_item("stderr", stderr);
            r
        }),
    )?;
    d.set_item("com_dv_rms_m_s", fit.com_dv_rms_m_s)?;
    d.set_item("residual_rms", fit.residual_rms)?;
    d.set_item("dof", fit.dof)?;
    let b = PyDict::new(py);
    b.set_item("resamples", fit.bootstrap.resamples)?;
    b.set_item("seed", fit.bootstrap.seed)?;
    b.set_item("failed", fit.bootstrap.failed)?;
    d.set_item("bootstrap", b)?;
    d.set_item("converged", fit.converged)?;
    d.set_item("message", &fit.message)?;
    d.set_item("input_warnings", warnings.to_vec())?;
    let c = &fit.collisions;
    let cols = PyDict::new(py);
    cols.set_item("line", lines.to_vec())?;
    cols.set_item("collision", ids.to_vec())?;
    cols.set_item("e", c.iter().map(|c| c.measured.e).collect::<Vec<_>>())?;
    cols.set_item(
        "beta",
        c.iter().map(|c| c.measured.beta).collect::<Vec<_>>(),
    )?;
    // psi = +inf for a head-on collision: None, as the CLI's null.
    cols.set_item(
        "psi",
        c.iter()
            .map(|c| Some(c.measured.psi).filter(|p| p.is_finite()))
            .collect::<Vec<_>>(),
    )?;
    cols.set_item(
        "v_n_m_s",
        c.iter().map(|c| c.measured.v_n_m_s).collect::<Vec<_>>(),
    )?;
    cols.set_item(
        "v_s_m_s",
        c.iter().map(|c| c.measured.v_s_m_s).collect::<Vec<_>>(),
    )?;
    cols.set_item(
        "impulse_ratio",
        c.iter()
            .map(|c| c.measured.impulse_ratio)
            .collect::<Vec<_>>(),
    )?;
    cols.set_item(
        "class",
        c.iter()
            .map(|c| c.kind.map(|k| k.as_str()).unwrap_or("head_on"))
            .collect::<Vec<_>>(),
    )?;
    cols.set_item("residual", c.iter().map(|c| c.residual).collect::<Vec<_>>())?;
    d.set_item("collisions", cols)?;
    Ok(d)
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
    type Done = (
        WaltonFit,
        String,
        Vec<usize>,
        Vec<Option<String>>,
        Vec<String>,
    );
    let (fit, path, lines, ids, warnings) = run_detached(py, move || -> Outcome<Done> {
        let (material, weights) = (material?, weights?);
        if bootstrap == 1 {
            return Err(Failure::Input(
                "bootstrap = 1: expected 0 (no intervals) or at least 2 resamples".into(),
            ));
        }
        let table = source?.table()?;
        let (records, warnings) = read_collisions(&table, &material, inertia_k)?;
        let measured = measure_records(&table.path, &records)?;
        let options = FitOptions {
            inertia_k,
            weights,
            bootstrap,
            seed,
        };
        let fit = wfit::fit(&measured, &options)
            .map_err(|e| Failure::library(&format!("{}: cannot fit", table.path), &e))?;
        Ok((
            fit,
            table.path.clone(),
            records.iter().map(|r| r.line).collect(),
            records.iter().map(|r| r.id.clone()).collect(),
            warnings,
        ))
    })?;
    to_dict(py, &fit, &path, &lines, &ids, &warnings)
}
