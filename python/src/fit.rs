//! `fit`: the calls of `restitution fit` (src/cli/fit.rs): read and validate the data with the
//! CLI's reader, `fit_all`, then the library's report and figures from the same `FitSet`.

use crate::{Failure, Outcome, Source, run_detached};
use pyo3::prelude::*;
use restitution::data::fit_input::{FitInput, parse_fit_csv, read_fit_csv};
use restitution::data::report::fit::{self as report, ReportContext};
use restitution::data::report::fit_text as report_text;
use restitution::fit::{FitOptions, FitSet, ModelKind, fit_all};
use restitution::models::viscoelastic::{ContactEnd, OdeSettings, VmMethod};
use restitution::plot::fit::{fig7_svg, residuals_svg};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_class::<Fitted>()?;
    Ok(())
}

/// A finished fit: the input as read, the options and the library's `FitSet`. Every rendering
/// (JSON, table, Markdown, CSV, figures) is the library's, from these.
#[pyclass(frozen, module = "restitution._restitution")]
pub(crate) struct Fitted {
    input: FitInput,
    rule: ContactEnd,
    vm_method: VmMethod,
    set: FitSet,
    /// Seconds spent reading and fitting (for the speed benchmark's overhead measurement).
    #[pyo3(get)]
    rust_seconds: f64,
}

impl Fitted {
    fn ctx(&self) -> ReportContext<'_> {
        ReportContext {
            path: &self.input.path,
            data: &self.input.data,
            error_source: self.input.error_source.describe(),
            rule: self.rule,
            vm_method: &self.vm_method,
        }
    }
}

#[pymethods]
impl Fitted {
    /// The `restitution fit --format json` document, as JSON text.
    fn json(&self) -> String {
        report::to_json(&self.ctx(), &self.set).to_string()
    }

    /// The human table `restitution fit` prints.
    fn table_text(&self) -> String {
        report_text::to_table(&self.ctx(), &self.set)
    }

    /// params.md of `restitution fit --out`.
    fn markdown(&self) -> String {
        report_text::to_markdown(&self.ctx(), &self.set)
    }

    /// params.csv of `restitution fit --out` (and `--format csv`).
    fn csv(&self) -> String {
        report::to_csv(&self.ctx(), &self.set)
    }

    /// fig7.svg of `restitution fit --out`, with the given title.
    fn fig7_svg(&self, py: Python<'_>, title: &str) -> PyResult<String> {
        let title = title.to_string();
        run_detached(py, || {
            fig7_svg(
                &self.input.data,
                &self.set,
                self.rule,
                &self.vm_method,
                &title,
            )
            .map_err(|e| Failure::Numerical(e.to_string()))
        })
    }

    /// residuals.svg of `restitution fit --out`, with the given title.
    fn residuals_svg(&self, py: Python<'_>, title: &str) -> PyResult<String> {
        let title = title.to_string();
        run_detached(py, || {
            residuals_svg(&self.input.data, &self.set, &title)
                .map_err(|e| Failure::Numerical(e.to_string()))
        })
    }

    /// Suspicious values of the input (e > 1, tiny diameters), one line per kind.
    fn input_warnings(&self) -> Vec<String> {
        self.input.warnings.iter().map(|w| w.to_string()).collect()
    }
}

fn models(name: &str) -> Outcome<Vec<ModelKind>> {
    Ok(match name {
        "vm" => vec![ModelKind::Vm],
        "pm" => vec![ModelKind::Pm],
        "min" => vec![ModelKind::Min],
        "product" => vec![ModelKind::Product],
        "powerlaw" => vec![ModelKind::PowerLaw],
        "all" => ModelKind::ALL.to_vec(),
        _ => {
            return Err(Failure::Input(format!(
                "model '{name}': expected vm, pm, min, product, powerlaw or all"
            )));
        }
    })
}

/// Reads the data (a file, or CSV text made from a table) and fits, as `restitution fit` does.
#[pyfunction]
#[pyo3(signature = (
    path=None, name=None, text=None, material=None, youngs_pa=None, poisson=None,
    density_kg_m3=None, model="all", contact_end="overlap", exact=false, strict=false
))]
#[allow(clippy::too_many_arguments)]
fn fit(
    py: Python<'_>,
    path: Option<std::path::PathBuf>,
    name: Option<String>,
    text: Option<String>,
    material: Option<&str>,
    youngs_pa: Option<f64>,
    poisson: Option<f64>,
    density_kg_m3: Option<f64>,
    model: &str,
    contact_end: &str,
    exact: bool,
    strict: bool,
) -> PyResult<Fitted> {
    let material = crate::material(material, youngs_pa, poisson, density_kg_m3);
    let kinds = models(model);
    let rule = crate::models::contact_end(contact_end);
    let source = Source::new(path, name, text);
    run_detached(py, move || {
        let start = std::time::Instant::now();
        let (material, kinds, rule) = (material?, kinds?, rule?);
        let input = match source? {
            Source::Path(p) => read_fit_csv(&p, material, strict)?,
            Source::Text { name, text } => parse_fit_csv(&name, &text, material, strict)?,
        };
        let vm_method = if exact {
            VmMethod::Ode(OdeSettings::DEFAULT)
        } else {
            VmMethod::Master
        };
        let options = FitOptions {
            rule,
            vm_method,
            ..FitOptions::default()
        };
        let set = fit_all(&input.data, &kinds, &options)
            .map_err(|e| Failure::library(&format!("{}: fit failed", input.path), &e))?;
        Ok(Fitted {
            input,
            rule,
            vm_method,
            set,
            rust_seconds: start.elapsed().as_secs_f64(),
        })
    })
}
