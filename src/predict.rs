//! The table of `restitution predict` and of Python's `predict`: e with 1 - e and the model's
//! other figures at each input value, built here once so that every front end prints the same
//! numbers and names the same input when one fails.
//!
//! Columns: the input (`v_m_s`, `kappa` or `u`), `e`, `one_minus_e`, then per model
//! `kappa, contact_time_s, max_overlap_m, max_force_n` (vm with speeds), `u, v_yield_m_s` (pm with
//! speeds) or the dimensionless `tau_contact, x_max, force_max` (vm with kappa). e is a number
//! for every finite kappa and u (docs/physics.md §2.6-2.7, §3); the contact time and extrema
//! come from the ODE, which covers kappa up to its checked range: beyond it those cells are
//! `None`, with a note saying why. Any other failure, and any figure that overflows, is a
//! [`Failure`] naming the input value it is about.

use crate::contact::Contact;
use crate::error::{Error, IntegrationFailure};
use crate::models::plastic::{self, Plastic};
use crate::models::viscoelastic::{self, ContactEnd, OdeSettings, Viscoelastic, VmMethod};

/// The input a failure is about, by its key (`v_m_s`: the CLI's `--v-m-s`, Python's `v_m_s=`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub enum Input {
    VMS,
    Kappa,
    U,
    Eta,
    SigmaYPa,
}

impl Input {
    /// `v_m_s`, `kappa`, `u`, `eta`, `sigma_y_pa`.
    pub fn key(self) -> &'static str {
        match self {
            Input::VMS => "v_m_s",
            other => other.into(),
        }
    }
}

/// An input value the models could not turn into numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{} = {}: {error}", .input.key(), crate::error::Num(*.value))]
pub struct Failure {
    pub input: Input,
    pub value: f64,
    pub error: Error,
}

/// Column names and rows (`None`: not available, see `notes`).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub columns: Vec<&'static str>,
    pub rows: Vec<Vec<Option<f64>>>,
    pub notes: Vec<String>,
}

impl Table {
    fn new(columns: Vec<&'static str>) -> Table {
        Table {
            columns,
            rows: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// Adds a row, refusing a figure that is not finite (an overflow of an absurd input must be
    /// an error, never `inf` printed as if it were a number).
    fn push(&mut self, input: Input, value: f64, row: Vec<Option<f64>>) -> Result<(), Failure> {
        if let Some((name, x)) = self
            .columns
            .iter()
            .zip(&row)
            .find_map(|(c, x)| x.filter(|x| !x.is_finite()).map(|x| (*c, x)))
        {
            return Err(Failure {
                input,
                value,
                error: Error::InvalidParameter {
                    name,
                    value: x,
                    expected: "a finite number (the input is beyond the range of f64 here)",
                },
            });
        }
        self.rows.push(row);
        Ok(())
    }
}

fn fail(input: Input, value: f64) -> impl Fn(Error) -> Failure {
    move |error| Failure {
        input,
        value,
        error,
    }
}

/// The ODE's extra figures, or `None` with a note when kappa is beyond the ODE's checked range;
/// any other ODE failure is a failure of the input.
fn extrema<T>(
    kappa: f64,
    result: crate::Result<T>,
    notes: &mut Vec<String>,
    on: impl Fn(Error) -> Failure,
) -> Result<Option<T>, Failure> {
    match result {
        Ok(r) => Ok(Some(r)),
        Err(e) if e.integration_failure() == Some(IntegrationFailure::OutOfRange) => {
            notes.push(format!(
                "kappa = {}: contact time and extrema left empty: {e}",
                crate::error::Num(kappa)
            ));
            Ok(None)
        }
        Err(e) => Err(on(e)),
    }
}

/// e(kappa) of the viscoelastic model, with the dimensionless contact time, maximum overlap and
/// maximum force from the ODE when `extrema` is set.
pub fn vm_dimensionless(
    kappa: &[f64],
    rule: ContactEnd,
    method: &VmMethod,
    ode: &OdeSettings,
    extrema_too: bool,
) -> Result<Table, Failure> {
    let mut columns = vec!["kappa", "e", "one_minus_e"];
    if extrema_too {
        columns.extend(["tau_contact", "x_max", "force_max"]);
    }
    let mut t = Table::new(columns);
    for &k in kappa {
        let on = fail(Input::Kappa, k);
        let e = viscoelastic::restitution(k, rule, method).map_err(&on)?;
        let mut row = vec![Some(k), Some(e.e), Some(e.one_minus_e)];
        if extrema_too {
            let r = extrema(k, viscoelastic::rebound(k, rule, ode), &mut t.notes, &on)?;
            row.extend([
                r.map(|r| r.tau_contact),
                r.map(|r| r.x_max),
                r.map(|r| r.force_max),
            ]);
        }
        t.push(Input::Kappa, k, row)?;
    }
    Ok(t)
}

/// e(u) of the plastic model, u = V/V_Y.
pub fn pm_dimensionless(u: &[f64]) -> Result<Table, Failure> {
    let mut t = Table::new(vec!["u", "e", "one_minus_e"]);
    for &u in u {
        let r = plastic::try_rebound_u(u).map_err(fail(Input::U, u))?;
        t.push(Input::U, u, vec![Some(u), Some(r.e), Some(r.one_minus_e)])?;
    }
    Ok(t)
}

/// e(v) of the viscoelastic model for one contact and damping eta (kg/(s m)), with kappa and,
/// when `extrema` is set, the contact time (s), maximum overlap (m) and force (N) from the ODE.
#[allow(clippy::too_many_arguments)]
pub fn vm_dimensional(
    contact: Contact,
    eta: f64,
    v_m_s: &[f64],
    rule: ContactEnd,
    method: &VmMethod,
    ode: &OdeSettings,
    extrema_too: bool,
) -> Result<Table, Failure> {
    let model = Viscoelastic::new(contact, eta).map_err(fail(Input::Eta, eta))?;
    let mut columns = vec!["v_m_s", "e", "one_minus_e", "kappa"];
    if extrema_too {
        columns.extend(["contact_time_s", "max_overlap_m", "max_force_n"]);
    }
    let mut t = Table::new(columns);
    for &v in v_m_s {
        let on = fail(Input::VMS, v);
        let kappa = model.try_kappa(v).map_err(&on)?;
        let e = viscoelastic::restitution(kappa, rule, method).map_err(&on)?;
        let mut row = vec![Some(v), Some(e.e), Some(e.one_minus_e), Some(kappa)];
        if extrema_too {
            let i = extrema(kappa, model.impact(v, rule, ode), &mut t.notes, &on)?;
            row.extend([
                i.map(|i| i.contact_time_s),
                i.map(|i| i.max_overlap_m),
                i.map(|i| i.max_force_n),
            ]);
        }
        t.push(Input::VMS, v, row)?;
    }
    Ok(t)
}

/// e(v) of the plastic model for one contact and yield stress sigma_y (Pa), with u = v/V_Y and
/// V_Y (m/s).
pub fn pm_dimensional(contact: Contact, sigma_y_pa: f64, v_m_s: &[f64]) -> Result<Table, Failure> {
    let model = Plastic::new(contact, sigma_y_pa).map_err(fail(Input::SigmaYPa, sigma_y_pa))?;
    let vy = model.yield_velocity_m_s();
    let mut t = Table::new(vec!["v_m_s", "e", "one_minus_e", "u", "v_yield_m_s"]);
    for &v in v_m_s {
        let u = model.u(v).map_err(fail(Input::VMS, v))?;
        let r = plastic::try_rebound_u(u).map_err(fail(Input::VMS, v))?;
        t.push(
            Input::VMS,
            v,
            vec![Some(v), Some(r.e), Some(r.one_minus_e), Some(u), Some(vy)],
        )?;
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{Material, Pair, Sphere};

    fn nylon_pair(d_m: f64) -> Contact {
        let m = Material::preset("nylon").unwrap();
        Pair::identical(Sphere::new(d_m, m).unwrap()).contact()
    }

    #[test]
    fn known_values_and_columns() {
        // kappa = 0 is elastic (e = 1 exactly); u <= 1 does not yield (e = 1 exactly,
        // docs/physics.md §3); the Hertz contact time of the dimensionless ODE is
        // 3.2180654597190430845 (tools/reference/README.md), to the ODE's tolerance.
        let ode = OdeSettings::DEFAULT;
        let t =
            vm_dimensionless(&[0.0], ContactEnd::Overlap, &VmMethod::Master, &ode, true).unwrap();
        assert_eq!(
            t.columns,
            [
                "kappa",
                "e",
                "one_minus_e",
                "tau_contact",
                "x_max",
                "force_max"
            ]
        );
        assert_eq!(t.rows[0][1], Some(1.0));
        assert!((t.rows[0][3].unwrap() - 3.2180654597190430845).abs() < 1e-9);
        let t = pm_dimensionless(&[0.5]).unwrap();
        assert_eq!(t.rows[0][1], Some(1.0));
    }

    #[test]
    fn failures_name_the_input() {
        let c = nylon_pair(0.0254);
        // eta = 1e300 at 1e308 m/s: kappa overflows.
        let ode = OdeSettings::DEFAULT;
        let err = vm_dimensional(
            c,
            1e300,
            &[2.0, 1e308],
            ContactEnd::Force,
            &VmMethod::Master,
            &ode,
            true,
        )
        .unwrap_err();
        assert_eq!((err.input, err.value), (Input::VMS, 1e308), "{err}");
        assert!(err.to_string().starts_with("v_m_s = 1e308: kappa"), "{err}");
        let err = vm_dimensional(
            c,
            -1.0,
            &[2.0],
            ContactEnd::Force,
            &VmMethod::Master,
            &ode,
            false,
        )
        .unwrap_err();
        assert_eq!(err.input, Input::Eta, "{err}");
        let err = pm_dimensional(c, 0.0, &[2.0]).unwrap_err();
        assert_eq!(err.input, Input::SigmaYPa, "{err}");
        // eta = 0 at f64::MAX: e = 1 but the maximum force overflows; an error, not inf.
        let err = vm_dimensional(
            c,
            0.0,
            &[f64::MAX],
            ContactEnd::Force,
            &VmMethod::Master,
            &ode,
            true,
        )
        .unwrap_err();
        assert_eq!(err.input, Input::VMS, "{err}");
    }
}
