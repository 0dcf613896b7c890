//! Python bindings of the `restitution` library (the `restitution._restitution` extension).
//!
//! Thin on purpose: every function here parses its arguments, calls the same public library
//! functions as the command line's `run` functions (src/cli/), and converts the result, so the
//! numbers are the CLI's by construction. The pure-Python package (`restitution/__init__.py`)
//! adds the documented, numpy-style API on top.
//!
//! Errors: a library `Error` or `DataError` becomes `InputError` (a `ValueError`) or, for a
//! numerical failure, `NumericalError` (a `RuntimeError`), with the library's one-line message.
//! Work runs with the GIL released and inside `catch_unwind`, so a bug that panics surfaces as a
//! `RuntimeError` naming it, never as an abort of the interpreter.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use restitution::contact::{Material, PRESETS};
use restitution::data::DataError;
use std::panic::{AssertUnwindSafe, catch_unwind};

mod bench;
mod export;
mod fit;
mod kinematics;
mod models;
mod track;
mod walton;

create_exception!(
    _restitution,
    InputError,
    PyValueError,
    "Bad input: a value out of its domain, or a file or table that cannot be read (attributes \
     `path`, `line`, `column`, `detail` name the place when there is one)."
);
create_exception!(
    _restitution,
    NumericalError,
    PyRuntimeError,
    "A numerical method gave up (an ODE integration that failed, a fit that could not be done)."
);

/// A failure on the Rust side, converted to a Python exception once the GIL is held again.
#[derive(Debug)]
pub(crate) enum Failure {
    /// Bad input with a one-line message.
    Input(String),
    /// Bad input in a file or table: the place and the message.
    Data(DataError),
    /// A numerical method gave up.
    Numerical(String),
    /// A panic: a bug, reported as such.
    Panic(String),
}

impl Failure {
    /// A library error: a numerical failure when it is an integration failure, else bad input.
    pub(crate) fn library(context: &str, e: &restitution::Error) -> Failure {
        let msg = if context.is_empty() {
            e.to_string()
        } else {
            format!("{context}: {e}")
        };
        if e.integration_failure().is_some() {
            Failure::Numerical(msg)
        } else {
            Failure::Input(msg)
        }
    }

    pub(crate) fn into_pyerr(self, py: Python<'_>) -> PyErr {
        match self {
            Failure::Input(m) => InputError::new_err(m),
            Failure::Numerical(m) => NumericalError::new_err(m),
            Failure::Panic(m) => PyRuntimeError::new_err(format!(
                "internal error (a bug in restitution, please report it): {m}"
            )),
            Failure::Data(d) => {
                let err = InputError::new_err(d.to_string());
                let v = err.value(py);
                // Attributes for callers that re-locate the message (rows of a DataFrame).
                let _ = v.setattr("path", d.path.clone());
                let _ = v.setattr("line", d.line);
                let _ = v.setattr("column", d.column.clone());
                let _ = v.setattr("detail", d.message.clone());
                let _ = v.setattr("kind", d.kind.to_string());
                err
            }
        }
    }
}

impl From<DataError> for Failure {
    fn from(d: DataError) -> Self {
        Failure::Data(d)
    }
}

pub(crate) type Outcome<T> = Result<T, Failure>;

/// Runs `work` with the GIL released and any panic caught, then converts a failure.
pub(crate) fn run_detached<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> Outcome<T> + Send,
) -> PyResult<T> {
    let result = py.detach(move || match catch_unwind(AssertUnwindSafe(work)) {
        Ok(r) => r,
        Err(payload) => Err(Failure::Panic(panic_message(payload.as_ref()))),
    });
    result.map_err(|f| f.into_pyerr(py))
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".into()
    }
}

/// A material from a preset name or the three constants (the CLI's material flags).
pub(crate) fn material(
    name: Option<&str>,
    youngs_pa: Option<f64>,
    poisson: Option<f64>,
    density_kg_m3: Option<f64>,
) -> Outcome<Material> {
    let constants = [youngs_pa, poisson, density_kg_m3];
    if let Some(name) = name {
        if constants.iter().any(Option::is_some) {
            return Err(Failure::Input(format!(
                "material '{name}' and youngs_pa/poisson/density_kg_m3 were both given: give one"
            )));
        }
        return Material::preset(name).ok_or_else(|| {
            let names: Vec<&str> = PRESETS.iter().map(|(n, _)| *n).collect();
            Failure::Input(format!(
                "material '{name}' is not a preset: expected one of {}",
                names.join(", ")
            ))
        });
    }
    match constants {
        [Some(y), Some(nu), Some(rho)] => {
            Material::new(y, nu, rho).map_err(|e| Failure::library("", &e))
        }
        _ => Err(Failure::Input(
            "a material is needed: material=NAME, or all of youngs_pa, poisson and density_kg_m3"
                .into(),
        )),
    }
}

/// A table source: a file path, or CSV text in memory with the name used in messages.
pub(crate) enum Source {
    Path(std::path::PathBuf),
    Text { name: String, text: String },
}

impl Source {
    pub(crate) fn new(
        path: Option<std::path::PathBuf>,
        name: Option<String>,
        text: Option<String>,
    ) -> Outcome<Source> {
        match (path, text) {
            (Some(p), None) => Ok(Source::Path(p)),
            (None, Some(text)) => Ok(Source::Text {
                name: name.unwrap_or_else(|| "<data>".into()),
                text,
            }),
            _ => Err(Failure::Input("give a path or CSV text, not both".into())),
        }
    }

    pub(crate) fn table(&self) -> Outcome<restitution::data::Table> {
        Ok(match self {
            Source::Path(p) => restitution::data::Table::read(p)?,
            Source::Text { name, text } => restitution::data::Table::parse(name, text)?,
        })
    }
}

/// The names of the material presets.
#[pyfunction]
fn material_presets() -> Vec<&'static str> {
    PRESETS.iter().map(|(n, _)| *n).collect()
}

/// Panics on purpose, inside the guard every entry point uses.
#[pyfunction]
fn _panic_for_test(py: Python<'_>) -> PyResult<()> {
    // Exercises the panic guard: the test suite checks that a panic becomes a RuntimeError.
    run_detached(py, || -> Outcome<()> {
        panic!("deliberate panic (test of the guard)")
    })
}

#[pymodule]
fn _restitution(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    m.add_function(wrap_pyfunction!(material_presets, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    models::register(m)?;
    bench::register(m)?;
    fit::register(m)?;
    walton::register(m)?;
    kinematics::register(m)?;
    export::register(m)?;
    track::register(m)?;
    Ok(())
}
