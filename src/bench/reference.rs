//! Reference values for the bench: the mpmath fixtures (compiled in, so the bench needs no files at
//! run time) and, between their points, the ODE at its tightest setting, itself checked against them.

use crate::data::{DataError, Table};
use crate::error::Result;
use crate::models::viscoelastic::{ContactEnd, OdeSettings, restitution_ode};

const VM_REFERENCE: &str = include_str!("../../tests/fixtures/vm_reference.csv");
const VM_SERIES: &str = include_str!("../../tests/fixtures/vm_series.csv");
const PM_REFERENCE: &str = include_str!("../../tests/fixtures/pm_reference.csv");

/// One viscoelastic reference point (mpmath Taylor integration, 25 digits; tools/reference/).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VmRef {
    pub rule: ContactEnd,
    pub kappa: f64,
    pub e: f64,
    pub one_minus_e: f64,
}

/// One plastic reference point (mpmath closed form at 50 digits, checked against the dimensional
/// work balance at 90 digits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PmRef {
    pub u: f64,
    pub e: f64,
    pub one_minus_e: f64,
}

fn parse_vm(text: &str) -> std::result::Result<Vec<VmRef>, DataError> {
    let t = Table::parse("tests/fixtures/vm_reference.csv", text)?;
    let (cr, ck, ce, co) = (
        t.require("rule")?,
        t.require("kappa")?,
        t.require("e")?,
        t.require("one_minus_e")?,
    );
    t.rows
        .iter()
        .map(|row| {
            let rule = t
                .field(row, cr)
                .parse::<ContactEnd>()
                .map_err(|m| t.cell_error(row, cr, m))?;
            Ok(VmRef {
                rule,
                kappa: t.number(row, ck)?,
                e: t.number(row, ce)?,
                one_minus_e: t.number(row, co)?,
            })
        })
        .collect()
}

/// The viscoelastic fixture, both rules, kappa in [1e-8, 100].
pub fn vm_fixture() -> Vec<VmRef> {
    parse_vm(VM_REFERENCE).expect("the compiled-in vm_reference.csv parses (tests check it)")
}

/// The plastic fixture, u in [0.5, 1e12].
pub fn pm_fixture() -> Vec<PmRef> {
    let t = Table::parse("tests/fixtures/pm_reference.csv", PM_REFERENCE)
        .expect("the compiled-in pm_reference.csv parses");
    let (cu, ce, co) = (
        t.require("u").expect("column u"),
        t.require("e").expect("column e"),
        t.require("one_minus_e").expect("column one_minus_e"),
    );
    t.rows
        .iter()
        .map(|row| PmRef {
            u: t.number(row, cu).expect("numeric u"),
            e: t.number(row, ce).expect("numeric e"),
            one_minus_e: t.number(row, co).expect("numeric 1 - e"),
        })
        .collect()
}

/// A named constant of `tests/fixtures/vm_series.csv`.
pub fn series_constant(name: &str) -> Option<f64> {
    let t = Table::parse("tests/fixtures/vm_series.csv", VM_SERIES).ok()?;
    let (cn, cv) = (t.column("name")?, t.column("value")?);
    t.rows
        .iter()
        .find(|r| t.field(r, cn) == name)
        .and_then(|r| t.number(r, cv).ok())
}

/// lim e kappa^5 of the overlap rule (mpmath; exponentially small corrections, relative spread
/// below 4e-36 over kappa in [10, 100]).
pub fn overlap_large_kappa_a() -> f64 {
    series_constant("overlap_large_kappa_a").expect("vm_series.csv names overlap_large_kappa_a")
}

/// Where a dense reference value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RefSource {
    /// A large-kappa law (docs/physics.md §2): the overlap rule's e = A kappa^-5 (kappa >= 10),
    /// the force rule's three-term law (kappa > 1e4), both evaluated here in logarithms, a code
    /// path independent of the library's double-double evaluation, with the constants of the
    /// mpmath fixtures.
    Asymptote,
    /// The ODE at [`OdeSettings::REFERENCE`] (Dop853, rtol = atol = 1e-15).
    OdeReference,
}

/// e by a large-kappa law in logarithms: relative error about 1e-16 times ln of the result
/// (under 1e-13 down to the subnormals), plenty for the map's 1e-6.
fn law_by_logs(kappa: f64, rule: ContactEnd) -> f64 {
    let ln_k = kappa.ln();
    match rule {
        ContactEnd::Overlap => (overlap_large_kappa_a().ln() - 5.0 * ln_k).exp(),
        ContactEnd::Force => {
            let xi_m = 1.5f64.powf(2.0 / 3.0);
            let lam = xi_m.sqrt();
            let ln_eps = -5.0 / 3.0 * ln_k;
            let eps = ln_eps.exp();
            let h = xi_m * (1.0 + 2.0 / lam * eps * ln_eps + 1.654_680_456_256_096_6 * eps);
            (h.ln() + ln_eps).exp()
        }
    }
}

/// e and 1 - e at any kappa >= 0: the large-kappa laws where they hold to far below the map's
/// threshold (overlap kappa >= 10: 3.5e-36; force kappa > 1e4: 4.8e-12), evaluated by
/// `law_by_logs`; otherwise the ODE at its tightest setting (checked against the fixture by
/// [`check_ode_reference`]).
pub fn vm_dense_reference(kappa: f64, rule: ContactEnd) -> Result<(f64, f64, RefSource)> {
    let law_from = match rule {
        ContactEnd::Overlap => 10.0,
        ContactEnd::Force => 1e4 * (1.0 + 1e-9),
    };
    if kappa >= law_from {
        let e = law_by_logs(kappa, rule);
        return Ok((e, 1.0 - e, RefSource::Asymptote));
    }
    let r = restitution_ode(kappa, rule, &OdeSettings::REFERENCE)?;
    Ok((r.e, r.one_minus_e, RefSource::OdeReference))
}

/// How far the dense reference is from the mpmath fixture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceCheck {
    /// max |e - e_mpmath| of the ODE at its tightest setting over the fixture.
    pub ode_max_abs_e: f64,
    /// max relative error of its 1 - e.
    pub ode_max_rel_one_minus_e: f64,
    /// max relative error of e = A kappa^-5 against the fixture (overlap, kappa >= 10).
    pub asymptote_max_rel_e: f64,
    pub points: usize,
}

/// Compares the dense reference's two sources with every fixture point.
pub fn check_ode_reference() -> Result<ReferenceCheck> {
    let mut c = ReferenceCheck {
        ode_max_abs_e: 0.0,
        ode_max_rel_one_minus_e: 0.0,
        asymptote_max_rel_e: 0.0,
        points: 0,
    };
    for r in vm_fixture() {
        let o = restitution_ode(r.kappa, r.rule, &OdeSettings::REFERENCE)?;
        c.ode_max_abs_e = c.ode_max_abs_e.max((o.e - r.e).abs());
        c.ode_max_rel_one_minus_e = c
            .ode_max_rel_one_minus_e
            .max(((o.one_minus_e - r.one_minus_e) / r.one_minus_e).abs());
        if r.rule == ContactEnd::Overlap && r.kappa >= 10.0 {
            let a = overlap_large_kappa_a() * r.kappa.powi(-5);
            c.asymptote_max_rel_e = c.asymptote_max_rel_e.max(((a - r.e) / r.e).abs());
        }
        c.points += 1;
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixtures_parse() {
        let vm = vm_fixture();
        assert_eq!(vm.len(), 46);
        assert!(vm.iter().all(|r| (r.e + r.one_minus_e - 1.0).abs() < 1e-15));
        assert_eq!(pm_fixture().len(), 180);
        // 5.1583817042676852164 (tools/reference/README.md).
        assert_eq!(overlap_large_kappa_a(), 5.158_381_704_267_685);
        assert!(series_constant("no such name").is_none());
    }
}
