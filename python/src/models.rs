//! e(v), e(kappa) and e(u): the calls of `restitution predict` (src/cli/predict.rs), looped over
//! arrays in Rust with the GIL released.

use crate::{Failure, Outcome, run_detached};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use restitution::data::fmt_num;
use restitution::fit::dataset::pair_contact;
use restitution::models::plastic;
use restitution::models::viscoelastic::{self, ContactEnd, Integrator, OdeSettings, VmMethod};
use restitution::predict as table;

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(e_of_kappa, m)?)?;
    m.add_function(wrap_pyfunction!(e_of_kappa_timed, m)?)?;
    m.add_function(wrap_pyfunction!(e_of_u, m)?)?;
    m.add_function(wrap_pyfunction!(predict, m)?)?;
    m.add("DEFAULT_TOL", OdeSettings::DEFAULT.rtol)?;
    Ok(())
}

pub(crate) fn contact_end(s: &str) -> Outcome<ContactEnd> {
    s.parse::<ContactEnd>()
        .map_err(|e| Failure::Input(format!("contact_end: {e}")))
}

/// The evaluation method of vm and the ODE settings of the columns that need the trajectory,
/// as `predict --method M --tol T` chooses them.
fn method(name: &str, tol: f64) -> Outcome<(VmMethod, OdeSettings)> {
    if let Err(why) = OdeSettings::check_tol(tol) {
        return Err(Failure::Input(format!("tol = {}: {why}", fmt_num(tol))));
    }
    let ode = match name {
        "master" => return Ok((VmMethod::Master, OdeSettings::DEFAULT)),
        "dop853" => OdeSettings::with_integrator(Integrator::Dop853, tol),
        "dopri5" => OdeSettings::with_integrator(Integrator::Dopri5, tol),
        _ => {
            return Err(Failure::Input(format!(
                "method '{name}': expected master, dop853 or dopri5"
            )));
        }
    };
    Ok((VmMethod::Ode(ode), ode))
}

/// The error for element `i` of an input array.
fn bad(name: &str, i: usize, value: f64, expected: &str) -> Failure {
    Failure::Input(format!(
        "{name}[{i}] = {}: expected {expected}",
        fmt_num(value)
    ))
}

/// Every value finite and accepted by `ok`, else an error naming the first bad one.
fn check(name: &str, values: &[f64], ok: impl Fn(f64) -> bool, expected: &str) -> Outcome<()> {
    match values.iter().position(|&v| !(v.is_finite() && ok(v))) {
        Some(i) => Err(bad(name, i, values[i], expected)),
        None => Ok(()),
    }
}

/// A copy of the input: the loop then runs without the GIL, and no Python thread can change the
/// numbers under it.
fn owned(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    match a.as_slice() {
        Ok(s) => s.to_vec(),
        Err(_) => a.as_array().iter().copied().collect(),
    }
}

/// e(kappa) of the viscoelastic model, elementwise.
#[pyfunction]
#[pyo3(signature = (kappa, contact_end="overlap", method="master", tol=OdeSettings::DEFAULT.rtol))]
fn e_of_kappa<'py>(
    py: Python<'py>,
    kappa: PyReadonlyArray1<'py, f64>,
    contact_end: &str,
    method: &str,
    tol: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    Ok(e_of_kappa_timed(py, kappa, contact_end, method, tol)?.0)
}

/// As [`e_of_kappa`], with the seconds spent in the library loop alone (for the speed
/// benchmark: the rest of the call is the cost of the Python layer).
#[pyfunction]
#[pyo3(signature = (kappa, contact_end="overlap", method="master", tol=OdeSettings::DEFAULT.rtol))]
fn e_of_kappa_timed<'py>(
    py: Python<'py>,
    kappa: PyReadonlyArray1<'py, f64>,
    contact_end: &str,
    method: &str,
    tol: f64,
) -> PyResult<(Bound<'py, PyArray1<f64>>, f64)> {
    let rule = self::contact_end(contact_end).map_err(|f| f.into_pyerr(py))?;
    let (method, _) = self::method(method, tol).map_err(|f| f.into_pyerr(py))?;
    map_chunked(py, &kappa, "kappa", move |k| {
        viscoelastic::restitution(k, rule, &method)
            .map(|r| r.e)
            .map_err(|e| Failure::library("", &e))
    })
}

/// e(u) of the plastic model (u = V/V_Y), elementwise.
#[pyfunction]
fn e_of_u<'py>(
    py: Python<'py>,
    u: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    Ok(map_chunked(py, &u, "u", |u| Ok(plastic::rebound_u(u).e))?.0)
}

/// Values per chunk of [`map_chunked`]: 256 kB of input, cache-resident.
const CHUNK: usize = 32 * 1024;

/// `f` of every element (each checked finite and >= 0 first), into a new numpy array, with the
/// seconds spent in the loops. The input is copied a chunk at a time, with the GIL held, into a
/// small buffer that the loop then reads with the GIL released: no Python thread can change the
/// numbers under the loop, and no copy of the whole array is made. The output array is new and
/// not yet visible to Python, so the loop may write it without the GIL.
fn map_chunked<'py>(
    py: Python<'py>,
    input: &PyReadonlyArray1<'py, f64>,
    name: &'static str,
    f: impl Fn(f64) -> Outcome<f64> + Sync,
) -> PyResult<(Bound<'py, PyArray1<f64>>, f64)> {
    let whole;
    let values = match input.as_slice() {
        Ok(s) => s,
        Err(_) => {
            whole = input.as_array().iter().copied().collect::<Vec<f64>>();
            &whole[..]
        }
    };
    let n = values.len();
    let out = PyArray1::<f64>::zeros(py, n, false);
    // SAFETY: `out` was created above and has not been handed to Python: nothing else can
    // read or write it while this slice lives.
    let out_slice = unsafe { out.as_slice_mut() }
        .map_err(|e| Failure::Panic(format!("a new array: {e}")).into_pyerr(py))?;
    let mut buf = vec![0.0; CHUNK.min(n)];
    let mut seconds = 0.0;
    for (start, dst) in (0..n).step_by(CHUNK).zip(out_slice.chunks_mut(CHUNK)) {
        let src = &mut buf[..dst.len()];
        src.copy_from_slice(&values[start..start + dst.len()]);
        let src = &*src;
        seconds += run_detached(py, || {
            let t = std::time::Instant::now();
            for (i, (&x, o)) in src.iter().zip(dst.iter_mut()).enumerate() {
                if !(x.is_finite() && x >= 0.0) {
                    return Err(bad(name, start + i, x, "a number >= 0"));
                }
                *o = f(x)?;
            }
            Ok(t.elapsed().as_secs_f64())
        })?;
    }
    Ok((out, seconds))
}

/// Named columns, in the order of `restitution predict --format csv`.
type Columns = Vec<(&'static str, Vec<f64>)>;

/// A column handed to Python.
type NamedArray<'py> = (&'static str, Bound<'py, PyArray1<f64>>);

/// Arguments of [`predict`] that describe the collision.
struct Geometry {
    d_mm: Option<f64>,
    d2_mm: Option<f64>,
    wall: bool,
    material: Outcome<restitution::contact::Material>,
}

impl Geometry {
    fn contact(self) -> Outcome<restitution::contact::Contact> {
        let material = self.material?;
        let d_mm = self
            .d_mm
            .ok_or_else(|| Failure::Input("d_mm is needed with v_m_s".into()))?;
        let d2 = match (self.d2_mm, self.wall) {
            (Some(_), true) => {
                return Err(Failure::Input(
                    "d2_mm and wall=True were both given: give one".into(),
                ));
            }
            // inf is a flat wall, as in the fit schema's d2_mm column.
            (Some(d2), false) if d2 > 0.0 => Some(d2),
            (Some(d2), false) => {
                return Err(Failure::Input(format!(
                    "d2_mm = {d2}: expected a diameter > 0 (mm), or inf for a flat wall"
                )));
            }
            (None, true) => Some(f64::INFINITY),
            (None, false) => None,
        };
        if !(d_mm.is_finite() && d_mm > 0.0) {
            return Err(Failure::Input(format!(
                "d_mm = {}: expected a diameter > 0 (mm)",
                fmt_num(d_mm)
            )));
        }
        // Named as the command line names it (`--d-mm 1e-300: ...`), in Python's words.
        let named = match (self.d2_mm, self.wall) {
            (Some(d2), _) => format!("d_mm = {}, d2_mm = {}", fmt_num(d_mm), fmt_num(d2)),
            (None, true) => format!("d_mm = {}, wall = True", fmt_num(d_mm)),
            (None, false) => format!("d_mm = {}", fmt_num(d_mm)),
        };
        pair_contact(material, d_mm, d2).map_err(|e| Failure::library(&named, &e))
    }
}

/// The table of `restitution predict`, as columns.
#[pyfunction]
#[pyo3(signature = (
    model, v_m_s=None, kappa=None, u=None, d_mm=None, d2_mm=None, wall=false, material=None,
    youngs_pa=None, poisson=None, density_kg_m3=None, eta=None, sigma_y_pa=None,
    contact_end="overlap", method="master", tol=OdeSettings::DEFAULT.rtol, full_output=false
))]
#[allow(clippy::too_many_arguments)]
fn predict<'py>(
    py: Python<'py>,
    model: &str,
    v_m_s: Option<PyReadonlyArray1<'py, f64>>,
    kappa: Option<PyReadonlyArray1<'py, f64>>,
    u: Option<PyReadonlyArray1<'py, f64>>,
    d_mm: Option<f64>,
    d2_mm: Option<f64>,
    wall: bool,
    material: Option<&str>,
    youngs_pa: Option<f64>,
    poisson: Option<f64>,
    density_kg_m3: Option<f64>,
    eta: Option<f64>,
    sigma_y_pa: Option<f64>,
    contact_end: &str,
    method: &str,
    tol: f64,
    full_output: bool,
) -> PyResult<Vec<NamedArray<'py>>> {
    let (v, kappa, u) = (
        v_m_s.as_ref().map(owned),
        kappa.as_ref().map(owned),
        u.as_ref().map(owned),
    );
    let model = model.to_string();
    let rule = crate::models::contact_end(contact_end);
    let method = self::method(method, tol);
    let geometry = Geometry {
        d_mm,
        d2_mm,
        wall,
        material: crate::material(material, youngs_pa, poisson, density_kg_m3),
    };
    let columns = run_detached(py, move || {
        let (rule, (method, ode)) = (rule?, method?);
        let given = [v.is_some(), kappa.is_some(), u.is_some()];
        if given.iter().filter(|g| **g).count() != 1 {
            return Err(Failure::Input(
                "give exactly one of v_m_s, kappa (vm) or u (pm)".into(),
            ));
        }
        match (model.as_str(), v, kappa, u) {
            ("vm", _, Some(k), _) => {
                check("kappa", &k, |k| k >= 0.0, "a number >= 0")?;
                columns(table::vm_dimensionless(
                    &k,
                    rule,
                    &method,
                    &ode,
                    full_output,
                ))
            }
            ("pm", _, _, Some(u)) => {
                check("u", &u, |u| u >= 0.0, "a number >= 0")?;
                columns(table::pm_dimensionless(&u))
            }
            ("vm", _, _, Some(_)) => {
                Err(Failure::Input("u is for model='pm'; vm takes kappa".into()))
            }
            ("pm", _, Some(_), _) => {
                Err(Failure::Input("kappa is for model='vm'; pm takes u".into()))
            }
            ("vm" | "pm", Some(v), _, _) => {
                check("v_m_s", &v, |v| v > 0.0, "a speed > 0 (m/s)")?;
                let contact = geometry.contact()?;
                if model == "vm" {
                    let eta = eta
                        .ok_or_else(|| Failure::Input("model='vm' needs eta (kg/(s m))".into()))?;
                    columns(table::vm_dimensional(
                        contact,
                        eta,
                        &v,
                        rule,
                        &method,
                        &ode,
                        full_output,
                    ))
                } else {
                    let sy = sigma_y_pa
                        .ok_or_else(|| Failure::Input("model='pm' needs sigma_y_pa (Pa)".into()))?;
                    columns(table::pm_dimensional(contact, sy, &v))
                }
            }
            (m, ..) => Err(Failure::Input(format!("model '{m}': expected vm or pm"))),
        }
    })?;
    let (columns, notes) = columns;
    for note in notes {
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &std::ffi::CString::new(note).unwrap_or_default(),
            1,
        )?;
    }
    Ok(columns
        .into_iter()
        .map(|(name, values)| (name, values.into_pyarray(py)))
        .collect())
}

/// The library's table as named columns (a cell the ODE could not give is NaN, with the note
/// that says why), or its failure as the Python error of the same one line.
fn columns(r: Result<table::Table, table::Failure>) -> Outcome<(Columns, Vec<String>)> {
    let t = r.map_err(|f| {
        if f.error.integration_failure().is_some() {
            Failure::Numerical(f.to_string())
        } else {
            Failure::Input(f.to_string())
        }
    })?;
    let cols = t
        .columns
        .iter()
        .enumerate()
        .map(|(j, &name)| {
            (
                name,
                t.rows.iter().map(|r| r[j].unwrap_or(f64::NAN)).collect(),
            )
        })
        .collect();
    Ok((cols, t.notes))
}
