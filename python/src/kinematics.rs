//! `kinematics`: the call of `restitution kinematics` (src/cli/kinematics.rs): read the tracks
//! and run the library's whole pass (`data::report::kinematics::measure_tracks`: noise pooled
//! over every collision, then each measured), and its JSON document, built by the same library
//! function as the command line's (`kinematics_json`).

use crate::{Failure, Outcome, Source, run_detached};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use restitution::data::fmt_num;
use restitution::data::report::kinematics::{Measured, Row, kinematics_json, measure_tracks};
use restitution::data::tracks::parse_tracks;
use restitution::experiment::Camera;
use restitution::kinematics::batch::BatchOptions;
use restitution::kinematics::{Eq8Inputs, FitKind, G_EXPECTED, G_STANDARD_M_S2, g_ok};
use restitution::models::walton::{INERTIA_K_EXPECTED, K_HOMOGENEOUS, inertia_k_ok};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(kinematics, m)?)?;
    m.add("G_STANDARD_M_S2", G_STANDARD_M_S2)?;
    m.add("K_HOMOGENEOUS", K_HOMOGENEOUS)?;
    // The CLI's camera defaults (the paper's), for the Python signature.
    let camera = PyDict::new(m.py());
    camera.set_item("s_subpixels", Camera::PAPER.s_subpixels)?;
    camera.set_item("fov_m", Camera::PAPER.fov_x_m)?;
    camera.set_item("pixels_x", Camera::PAPER.pixels_x)?;
    camera.set_item("subpixel_expansion", Camera::PAPER.subpixel_expansion)?;
    m.add("PAPER_CAMERA", camera)?;
    Ok(())
}

struct Done {
    measured: Measured,
    subpixel_m: f64,
    /// The command line's `--format json` document.
    json: String,
}

/// Velocities, e, beta and psi from tracked centres, as `restitution kinematics` computes them.
#[pyfunction]
#[pyo3(signature = (
    path=None, name=None, text=None, material=None, youngs_pa=None, poisson=None,
    density_kg_m3=None, fixed_gravity=false, g_m_s2=G_STANDARD_M_S2, inertia_k=K_HOMOGENEOUS,
    s_subpixels=Camera::PAPER.s_subpixels, subpixel_m=None, fov_m=Camera::PAPER.fov_x_m,
    pixels_x=Camera::PAPER.pixels_x, subpixel_expansion=Camera::PAPER.subpixel_expansion,
    strict=false
))]
#[allow(clippy::too_many_arguments)]
fn kinematics<'py>(
    py: Python<'py>,
    path: Option<std::path::PathBuf>,
    name: Option<String>,
    text: Option<String>,
    material: Option<&str>,
    youngs_pa: Option<f64>,
    poisson: Option<f64>,
    density_kg_m3: Option<f64>,
    fixed_gravity: bool,
    g_m_s2: f64,
    inertia_k: f64,
    s_subpixels: f64,
    subpixel_m: Option<f64>,
    fov_m: f64,
    pixels_x: u32,
    subpixel_expansion: f64,
    strict: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let material = crate::material(material, youngs_pa, poisson, density_kg_m3);
    let source = Source::new(path, name, text);
    let done = run_detached(py, move || -> Outcome<Done> {
        let material = material?;
        for (arg, v) in [
            ("s_subpixels", s_subpixels),
            ("fov_m", fov_m),
            ("subpixel_expansion", subpixel_expansion),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Failure::Input(format!(
                    "{arg} = {}: expected a number > 0",
                    fmt_num(v)
                )));
            }
        }
        if !inertia_k_ok(inertia_k) {
            return Err(Failure::Input(format!(
                "inertia_k = {}: expected {INERTIA_K_EXPECTED}",
                fmt_num(inertia_k)
            )));
        }
        if !g_ok(g_m_s2) {
            return Err(Failure::Input(format!(
                "g_m_s2 = {}: expected {G_EXPECTED}",
                fmt_num(g_m_s2)
            )));
        }
        if pixels_x == 0 {
            return Err(Failure::Input(
                "pixels_x = 0: expected a pixel count > 0".into(),
            ));
        }
        let subpixel_m = match subpixel_m {
            Some(p) if p.is_finite() && p > 0.0 => p,
            Some(p) => {
                return Err(Failure::Input(format!(
                    "subpixel_m = {}: expected a size > 0 (m)",
                    fmt_num(p)
                )));
            }
            None => Camera {
                fov_x_m: fov_m,
                pixels_x,
                subpixel_expansion,
                ..Camera::PAPER
            }
            .subpixel_m(),
        };
        let eq8 = Eq8Inputs {
            s_subpixels,
            subpixel_m,
        };
        let kind = if fixed_gravity {
            FitKind::FixedGravity { g_m_s2 }
        } else {
            FitKind::Free
        };
        let table = source?.table()?;
        let tracks = parse_tracks(&table)?;
        let options = BatchOptions {
            material,
            inertia_k,
            kind,
            eq8,
        };
        let measured = measure_tracks(&table.path, &tracks, &options);
        if let Some(why) = measured.refusal(&table.path, strict) {
            return Err(Failure::Input(why));
        }
        let json = kinematics_json(&measured);
        Ok(Done {
            measured,
            subpixel_m,
            json,
        })
    })?;
    to_dict(py, &done)
}

fn to_dict<'py>(py: Python<'py>, done: &Done) -> PyResult<Bound<'py, PyDict>> {
    let m = &done.measured;
    let rows = &m.rows;
    let col = |f: &dyn Fn(&Row) -> f64| rows.iter().map(f).collect::<Vec<f64>>();
    let c = PyDict::new(py);
    c.set_item(
        "collision",
        rows.iter().map(|r| r.id.clone()).collect::<Vec<_>>(),
    )?;
    c.set_item("t_c_s", col(&|r| r.m.kinematics.t_c_s))?;
    c.set_item(
        "time_rule",
        rows.iter()
            .map(|r| r.m.kinematics.time_rule.name())
            .collect::<Vec<_>>(),
    )?;
    c.set_item(
        "n_pre",
        rows.iter()
            .map(|r| r.m.kinematics.n_pre)
            .collect::<Vec<_>>(),
    )?;
    c.set_item(
        "n_post",
        rows.iter()
            .map(|r| r.m.kinematics.n_post)
            .collect::<Vec<_>>(),
    )?;
    // Velocities [1 pre, 2 pre, 1 post, 2 post] and their standard errors.
    let names = ["v1{}_m_s", "v2{}_m_s", "v1{}_post_m_s", "v2{}_post_m_s"];
    for (i, pattern) in names.iter().enumerate() {
        for (axis, k) in [("x", 0), ("y", 1)] {
            let name = pattern.replace("{}", axis);
            c.set_item(name.as_str(), col(&|r| r.m.kinematics.v_m_s[i][k]))?;
            let err = name.replace("_m_s", "_err_m_s");
            c.set_item(err.as_str(), col(&|r| r.m.v_err_m_s[i][k]))?;
        }
    }
    c.set_item("sigma_pos_m", col(&|r| r.m.sigma_pos_m))?;
    c.set_item("v_n_m_s", col(&|r| r.m.measured.v_n_m_s))?;
    c.set_item("v_n_err_m_s", col(&|r| r.m.v_n_err_m_s))?;
    c.set_item("e", col(&|r| r.m.measured.e))?;
    c.set_item("e_err", col(&|r| r.m.e_err))?;
    c.set_item("e_err_eq8", col(&|r| r.m.e_err_eq8))?;
    c.set_item("eq8_dv_m_s", col(&|r| r.m.eq8_dv_m_s))?;
    c.set_item(
        "beta",
        rows.iter().map(|r| r.m.measured.beta).collect::<Vec<_>>(),
    )?;
    c.set_item("psi", col(&|r| r.m.measured.psi))?;
    let dv = |r: &Row| r.m.measured.com_velocity_change_m_s;
    c.set_item(
        "momentum_dvx_m_s",
        rows.iter().map(|r| dv(r).map(|v| v.x)).collect::<Vec<_>>(),
    )?;
    c.set_item(
        "momentum_dvy_m_s",
        rows.iter().map(|r| dv(r).map(|v| v.y)).collect::<Vec<_>>(),
    )?;
    c.set_item("d1_mm", col(&|r| r.d1_mm))?;
    c.set_item("d2_mm", col(&|r| r.d2_mm))?;
    let d = PyDict::new(py);
    d.set_item("columns", c)?;
    d.set_item("sigma_pos_m", m.sigma_pos_m)?;
    d.set_item("subpixel_m", done.subpixel_m)?;
    d.set_item("skipped", m.skipped.clone())?;
    d.set_item("unmeasured_spins", m.unmeasured_spins.clone())?;
    d.set_item("fits_meet", m.fits_meet.clone())?;
    d.set_item("json", done.json.clone())?;
    Ok(d)
}
