//! The work-precision sweep: for each method and setting, the error against the reference and the
//! cost (time and right-hand-side or integrand evaluations) per evaluation.

use super::methods::{PmSpec, VmSpec};
use super::reference::{PmRef, VmRef};
use super::timing::{TimingPlan, ns_per_eval};
use crate::models::viscoelastic::ContactEnd;
use std::hint::black_box;

/// One point of the chart: a method at one setting, for one rule (or `all` of its rules).
#[derive(Debug, Clone, PartialEq)]
pub struct WpRow {
    /// `vm` or `pm`.
    pub model: &'static str,
    pub method: String,
    pub setting: String,
    /// The knob as a number (tolerance, RK4 step, series order, Pade degree, quadrature nodes).
    pub knob: f64,
    /// `overlap`, `force`, `all` (the aggregate over the rules the method applies to) or `-` (pm).
    pub rule: String,
    /// max |e - e_ref| over the points that did not fail.
    pub error: f64,
    /// max |e - e_ref| / e_ref.
    pub error_rel_e: f64,
    /// max |(1 - e) - (1 - e)_ref| / (1 - e)_ref.
    pub error_rel_one_minus_e: f64,
    /// Minimum over repeated batches of the mean time per evaluation (see [`super::timing`]).
    pub ns_per_eval: f64,
    /// Mean right-hand-side (vm) or integrand (pm quadrature) evaluations per evaluation.
    pub rhs_evals: f64,
    pub points: usize,
    /// Points where the method returned an error value.
    pub failed: usize,
}

/// The error of one evaluation (for `work_precision_points.csv`).
#[derive(Debug, Clone, PartialEq)]
pub struct WpPoint {
    pub model: &'static str,
    pub method: String,
    pub setting: String,
    pub rule: String,
    /// kappa (vm) or u (pm).
    pub x: f64,
    pub e: f64,
    pub e_ref: f64,
    pub abs_error: f64,
    pub rel_error_one_minus_e: f64,
    pub rhs_evals: f64,
    /// The error value's message, if the method failed.
    pub failure: Option<String>,
}

impl WpPoint {
    /// A chart point from one evaluation, `(e, 1 - e, rhs evaluations)`, or its error value,
    /// against the reference `(x, e_ref, 1 - e_ref)`.
    fn new(
        model: &'static str,
        (method, setting): (String, String),
        rule: &str,
        (x, e_ref, ome_ref): (f64, f64, f64),
        got: crate::Result<(f64, f64, f64)>,
    ) -> Self {
        let (e, abs_error, rel_error_one_minus_e, rhs_evals, failure) = match got {
            Ok((e, ome, evals)) => (e, (e - e_ref).abs(), rel(ome, ome_ref), evals, None),
            Err(err) => (
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                Some(err.to_string()),
            ),
        };
        WpPoint {
            model,
            method,
            setting,
            rule: rule.into(),
            x,
            e,
            e_ref,
            abs_error,
            rel_error_one_minus_e,
            rhs_evals,
            failure,
        }
    }
}

struct Acc {
    error: f64,
    rel_e: f64,
    rel_ome: f64,
    evals: f64,
    ok: usize,
    failed: usize,
}

impl Acc {
    fn new() -> Self {
        Acc {
            error: 0.0,
            rel_e: 0.0,
            rel_ome: 0.0,
            evals: 0.0,
            ok: 0,
            failed: 0,
        }
    }

    fn add(&mut self, p: &WpPoint) {
        if p.failure.is_some() {
            self.failed += 1;
            return;
        }
        // NaN never compares greater: a NaN result must still show.
        let worse = |acc: f64, x: f64| {
            if x.is_nan() {
                f64::INFINITY
            } else {
                acc.max(x)
            }
        };
        self.error = worse(self.error, p.abs_error);
        self.rel_e = worse(self.rel_e, p.abs_error / p.e_ref.abs());
        self.rel_ome = worse(self.rel_ome, p.rel_error_one_minus_e);
        self.evals += p.rhs_evals;
        self.ok += 1;
    }
}

fn rel(got: f64, want: f64) -> f64 {
    if got == want {
        0.0
    } else {
        ((got - want) / want).abs()
    }
}

/// The chart's rows and points for one viscoelastic method and setting, per rule and `all`.
pub fn vm_rows(spec: &VmSpec, refs: &[VmRef], plan: &TimingPlan) -> (Vec<WpRow>, Vec<WpPoint>) {
    let mut rows = Vec::new();
    let mut points = Vec::new();
    let mut all = Acc::new();
    let mut all_ns = 0.0;
    let mut all_n = 0usize;
    for rule in ContactEnd::ALL {
        if !spec.applies(rule) {
            continue;
        }
        let set: Vec<&VmRef> = refs.iter().filter(|r| r.rule == rule).collect();
        if set.is_empty() {
            continue;
        }
        let mut acc = Acc::new();
        for r in &set {
            let got = spec.eval(r.kappa, rule);
            let p = WpPoint::new(
                "vm",
                (spec.method(), spec.setting()),
                rule.name(),
                (r.kappa, r.e, r.one_minus_e),
                got.map(|g| (g.e, g.one_minus_e, g.rhs_evals as f64)),
            );
            acc.add(&p);
            all.add(&p);
            points.push(p);
        }
        let ns = ns_per_eval(plan, set.len(), || {
            set.iter()
                .map(|r| {
                    spec.eval(black_box(r.kappa), rule)
                        .map_or(0.0, |x| x.e + x.one_minus_e)
                })
                .sum::<f64>()
        });
        all_ns += ns * set.len() as f64;
        all_n += set.len();
        rows.push(row(
            "vm",
            spec.method(),
            spec.setting(),
            spec.knob(),
            rule.name(),
            &acc,
            ns,
        ));
    }
    if all_n > 0 {
        let ns = all_ns / all_n as f64;
        rows.push(row(
            "vm",
            spec.method(),
            spec.setting(),
            spec.knob(),
            "all",
            &all,
            ns,
        ));
    }
    (rows, points)
}

fn row(
    model: &'static str,
    method: String,
    setting: String,
    knob: f64,
    rule: &str,
    acc: &Acc,
    ns: f64,
) -> WpRow {
    WpRow {
        model,
        method,
        setting,
        knob,
        rule: rule.into(),
        error: acc.error,
        error_rel_e: acc.rel_e,
        error_rel_one_minus_e: acc.rel_ome,
        ns_per_eval: ns,
        rhs_evals: if acc.ok > 0 {
            acc.evals / acc.ok as f64
        } else {
            f64::NAN
        },
        points: acc.ok + acc.failed,
        failed: acc.failed,
    }
}

/// The chart's row and points for one plastic method (over the reference points with u > 1).
pub fn pm_rows(spec: &PmSpec, refs: &[PmRef], plan: &TimingPlan) -> (WpRow, Vec<WpPoint>) {
    let set: Vec<&PmRef> = refs.iter().filter(|r| r.u > 1.0).collect();
    let mut acc = Acc::new();
    let mut points = Vec::new();
    for r in &set {
        let got = spec.eval(r.u);
        let p = WpPoint::new(
            "pm",
            (spec.method(), spec.setting()),
            "-",
            (r.u, r.e, r.one_minus_e),
            got.map(|g| (g.e, g.one_minus_e, g.evals as f64)),
        );
        acc.add(&p);
        points.push(p);
    }
    let ns = ns_per_eval(plan, set.len(), || {
        set.iter()
            .map(|r| {
                spec.eval(black_box(r.u))
                    .map_or(0.0, |x| x.e + x.one_minus_e)
            })
            .sum::<f64>()
    });
    (
        row(
            "pm",
            spec.method(),
            spec.setting(),
            spec.knob(),
            "-",
            &acc,
            ns,
        ),
        points,
    )
}

/// Least-squares slope of log(error) against log(h) over the points with error in
/// [`ORDER_FIT_MIN_ERROR`, `ORDER_FIT_MAX_ERROR`] (above round-off, inside the asymptotic range);
/// `None` with fewer than three such points. Returns (slope, points used).
pub fn fit_order(h_and_error: &[(f64, f64)]) -> Option<(f64, usize)> {
    let pts: Vec<(f64, f64)> = h_and_error
        .iter()
        .filter(|(h, e)| {
            *h > 0.0 && e.is_finite() && (ORDER_FIT_MIN_ERROR..=ORDER_FIT_MAX_ERROR).contains(e)
        })
        .map(|(h, e)| (h.ln(), e.ln()))
        .collect();
    if pts.len() < 3 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    Some((sxy / sxx, pts.len()))
}

/// Errors below this are dominated by rounding and the reference's own 1e-15-level errors.
pub const ORDER_FIT_MIN_ERROR: f64 = 1e-13;
/// Errors above this are outside the asymptotic range of the step-size expansion (measured: the
/// local slopes of RK4 are 5.5 to 4.4 above it, 4.0 to 4.2 below).
pub const ORDER_FIT_MAX_ERROR: f64 = 1e-7;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_order_recovers_a_known_slope() {
        let pts: Vec<(f64, f64)> = (0..8)
            .map(|k| {
                let h = 0.1 / 2f64.powi(k);
                (h, 3.0 * h.powi(4))
            })
            .collect();
        let (slope, used) = fit_order(&pts).unwrap();
        assert!((slope - 4.0).abs() < 1e-12, "{slope}");
        assert!(used >= 3);
        assert!(fit_order(&pts[..1]).is_none());
    }
}
