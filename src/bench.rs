//! Speed against accuracy for every way the toolkit computes e: the measurement harness behind
//! `restitution bench` (work-precision chart, stability map, targets).
//!
//! **What is measured.** For the viscoelastic model: the ODE ([`VmSpec::Ode`], e alone, and
//! [`VmSpec::OdeExtrema`], with contact time and extrema) with Dop853 and Dopri5 over tolerances and
//! classical RK4 over step sizes, the master-curve table, the small-kappa series and the Pade
//! approximants ([`crate::models::viscoelastic::series`]); for the plastic model: the closed form,
//! the naive q formula, and quadrature of the work integrals ([`quadrature`]).
//!
//! **Against what.** The mpmath fixtures (25 and 30 digits, tools/reference/), compiled in: the
//! chart's viscoelastic points are the fixture's kappa in [1e-4, 5] for both rules (16 each), the
//! plastic points the fixture's u in (1, 1e12] (18). The stability map's dense kappa grid uses
//! [`reference::vm_dense_reference`] (the ODE at 1e-15, checked against the fixture in the report).
//!
//! **Time** is wall-clock per evaluation, warm, the minimum over repeated batches
//! ([`timing`]); rhs_evals counts right-hand-side calls of the ODE (integrand calls for the
//! quadrature), including those spent locating events.

pub mod fit_accuracy;
pub mod methods;
pub mod quadrature;
pub mod reference;
pub mod stability;
pub mod timing;
pub mod work_precision;

use crate::data::fmt_num;
use crate::error::Result;
use crate::fit::FitData;
use crate::models::viscoelastic::VmMethod;
use crate::models::viscoelastic::series::{Approximation, Pade, Series};
use crate::models::viscoelastic::{ContactEnd, Integrator, OdeSettings};
use fit_accuracy::FitAccuracy;
pub use methods::{PmResult, PmSpec, VmSpec};
use quadrature::WorkQuadrature;
use reference::{PmRef, ReferenceCheck, VmRef, pm_fixture, vm_dense_reference, vm_fixture};
use stability::{Cell, Role};
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Duration;
pub use timing::TimingPlan;
pub use work_precision::{WpPoint, WpRow, fit_order};

/// The chart's kappa range (the representative set).
pub const CHART_KAPPA_MIN: f64 = 1e-4;
pub const CHART_KAPPA_MAX: f64 = 5.0;
/// The stability map's kappa grid ends at 10^this (the issue asks up to 100; the grid goes on to
/// show where the methods break down).
pub const MAP_MAX_DECADE: i32 = 4;
/// The stability map's quadrature rule.
pub const MAP_QUADRATURE_NODES: usize = 64;
/// The stability map's RK4 step.
pub const MAP_RK4_STEP: f64 = 1e-3;

/// How thoroughly to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BenchConfig {
    /// Fewer settings, points and repeats: the whole bench in well under a minute.
    pub quick: bool,
}

impl BenchConfig {
    /// Tolerances of the adaptive integrators (always including the default's 1e-12).
    pub fn tolerances(&self) -> Vec<f64> {
        let exps: Vec<i32> = if self.quick {
            vec![3, 5, 7, 9, 11, 12, 13]
        } else {
            (3..=13).collect()
        };
        exps.iter()
            .map(|k| format!("1e-{k}").parse().expect("a literal"))
            .collect()
    }

    /// Fixed RK4 steps: 0.05 halved repeatedly.
    pub fn rk4_steps(&self) -> Vec<f64> {
        let ks: Vec<i32> = if self.quick {
            vec![0, 2, 4, 6]
        } else {
            (0..=7).collect()
        };
        ks.iter().map(|&k| 0.05 / 2f64.powi(k)).collect()
    }

    pub fn quadrature_nodes(&self) -> Vec<usize> {
        if self.quick {
            vec![2, 8, 32, 128]
        } else {
            vec![1, 2, 4, 8, 16, 32, 64, 128]
        }
    }

    pub fn timing(&self) -> TimingPlan {
        if self.quick {
            TimingPlan {
                repeats: 7,
                min_batch: Duration::from_millis(1),
            }
        } else {
            // Many short batches rather than a few long ones: on a shared machine the minimum
            // then more likely comes from a batch nothing else interrupted.
            TimingPlan {
                repeats: 25,
                min_batch: Duration::from_millis(3),
            }
        }
    }

    /// The evaluation methods of the fit-accuracy comparison.
    pub fn fit_methods(&self) -> Vec<VmMethod> {
        let dop853: Vec<f64> = if self.quick {
            vec![1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
        } else {
            (3..=12).map(|k| 10f64.powi(-k)).collect()
        };
        let dopri5: Vec<f64> = if self.quick {
            vec![1e-6, 1e-9, 1e-12]
        } else {
            (3..=12).map(|k| 10f64.powi(-k)).collect()
        };
        let rk4: Vec<f64> = if self.quick {
            vec![0.0125]
        } else {
            vec![0.05, 0.0125, 0.003125]
        };
        let mut v = vec![VmMethod::Master];
        let ode = |i: Integrator, t: f64| VmMethod::Ode(OdeSettings::with_integrator(i, t));
        v.extend(dop853.iter().map(|&t| ode(Integrator::Dop853, t)));
        v.extend(dopri5.iter().map(|&t| ode(Integrator::Dopri5, t)));
        v.extend(rk4.iter().map(|&h| ode(Integrator::Rk4 { h }, 0.0)));
        v
    }

    /// Repeats of each fit (the fastest counts).
    pub fn fit_repeats(&self) -> usize {
        if self.quick { 1 } else { 3 }
    }

    /// Stability-map points per decade of kappa.
    pub fn map_per_decade(&self) -> usize {
        // Dense enough to catch the isolated kappa where fixed-step RK4 goes unstable in the
        // unloading tail (found at 24 per decade: kappa = 75, 147, 421 for h = 1e-3).
        if self.quick { 4 } else { 12 }
    }
}

/// Every viscoelastic method and setting on the chart.
pub fn vm_chart_specs(cfg: &BenchConfig) -> Vec<VmSpec> {
    let mut v = Vec::new();
    for tol in cfg.tolerances() {
        v.push(VmSpec::Ode(OdeSettings::with_integrator(
            Integrator::Dop853,
            tol,
        )));
    }
    for tol in cfg.tolerances() {
        v.push(VmSpec::OdeExtrema(OdeSettings::with_integrator(
            Integrator::Dop853,
            tol,
        )));
    }
    for tol in cfg.tolerances() {
        v.push(VmSpec::Ode(OdeSettings::with_integrator(
            Integrator::Dopri5,
            tol,
        )));
    }
    for h in cfg.rk4_steps() {
        v.push(VmSpec::Ode(OdeSettings::with_integrator(
            Integrator::Rk4 { h },
            0.0,
        )));
    }
    v.push(VmSpec::Master);
    for s in Series::ALL {
        v.push(VmSpec::Approx(Approximation::Series(s)));
    }
    for p in Pade::ALL {
        v.push(VmSpec::Approx(Approximation::Pade(p)));
    }
    v
}

/// Every plastic method and setting on the chart.
pub fn pm_chart_specs(cfg: &BenchConfig) -> Vec<PmSpec> {
    let mut v = vec![PmSpec::ClosedForm, PmSpec::Naive];
    for n in cfg.quadrature_nodes() {
        v.push(PmSpec::Quadrature(WorkQuadrature::new(n)));
    }
    v
}

/// The stability map's viscoelastic methods: each at the setting a user would pick for accuracy.
pub fn vm_map_specs() -> Vec<(VmSpec, Role)> {
    let stiff = OdeSettings {
        stiffness_check: true,
        ..OdeSettings::DEFAULT
    };
    let p = Role::Production;
    vec![
        (VmSpec::Master, p),
        (VmSpec::Ode(OdeSettings::DEFAULT), p),
        (VmSpec::Ode(stiff), p),
        (
            VmSpec::Ode(OdeSettings::with_integrator(Integrator::Dopri5, 1e-12)),
            p,
        ),
        (
            VmSpec::Ode(OdeSettings::with_integrator(
                Integrator::Rk4 { h: MAP_RK4_STEP },
                0.0,
            )),
            p,
        ),
        (
            VmSpec::Ode(OdeSettings::with_integrator(Integrator::Dop853, 1e-3)),
            Role::Loose,
        ),
        (
            VmSpec::Ode(OdeSettings::with_integrator(Integrator::Dopri5, 1e-3)),
            Role::Loose,
        ),
        (
            VmSpec::Checked(Approximation::Series(Series::Order2), stability::MAP_TOL),
            p,
        ),
        (
            VmSpec::Checked(Approximation::Series(Series::Order3), stability::MAP_TOL),
            p,
        ),
        (
            VmSpec::Checked(
                Approximation::Pade(Pade::MullerPoeschel14),
                stability::MAP_TOL,
            ),
            p,
        ),
        (
            VmSpec::Checked(Approximation::Pade(Pade::Ours15), stability::MAP_TOL),
            p,
        ),
    ]
}

/// The stability map's plastic methods.
pub fn pm_map_specs() -> Vec<(PmSpec, Role)> {
    vec![
        (PmSpec::ClosedForm, Role::Production),
        (
            PmSpec::Quadrature(WorkQuadrature::new(MAP_QUADRATURE_NODES)),
            Role::Comparator,
        ),
        (PmSpec::Naive, Role::Comparator),
    ]
}

/// The chart's viscoelastic reference points: fixture kappa in [CHART_KAPPA_MIN, CHART_KAPPA_MAX].
pub fn chart_vm_points() -> Vec<VmRef> {
    vm_fixture()
        .into_iter()
        .filter(|r| (CHART_KAPPA_MIN..=CHART_KAPPA_MAX).contains(&r.kappa))
        .collect()
}

/// A candidate default ODE setting, checked against the bar over kappa in [1e-8, 100].
#[derive(Debug, Clone, PartialEq)]
pub struct OdeCandidate {
    pub spec: VmSpec,
    /// max |error in e| over the fixture and the dense grid (kappa <= 100), both rules.
    pub max_abs_e: f64,
    /// max relative error of 1 - e, same points.
    pub max_rel_one_minus_e: f64,
    pub failed: usize,
    pub points: usize,
    /// Mean time per evaluation over the chart's kappa set, both rules.
    pub ns_per_eval: f64,
    pub rhs_evals: f64,
}

impl OdeCandidate {
    /// The bar for the default: |error in e| <= 1e-10, relative error of 1 - e <= 1e-8.
    pub fn meets_bar(&self) -> bool {
        self.failed == 0 && self.max_abs_e <= 1e-10 && self.max_rel_one_minus_e <= 1e-8
    }
}

/// Everything `restitution bench` reports.
#[derive(Debug, Clone)]
pub struct BenchReport {
    pub config: BenchConfig,
    pub rows: Vec<WpRow>,
    pub points: Vec<WpPoint>,
    pub cells: Vec<Cell>,
    pub reference_check: ReferenceCheck,
    /// Fitted convergence order of RK4 per rule: (rule, slope, points used).
    pub rk4_order: Vec<(String, f64, usize)>,
    pub candidates: Vec<OdeCandidate>,
    /// The targets' methods timed point by point (the chart's figures are means over points).
    pub per_point: Vec<PointTiming>,
    /// What accuracy a fit needs (when a data set was given).
    pub fit: Option<FitAccuracy>,
}

/// The time of one method at one point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointTiming {
    pub model: &'static str,
    pub method: String,
    /// `overlap`, `force` or `-`.
    pub rule: String,
    /// kappa or u.
    pub x: f64,
    pub ns_per_eval: f64,
}

/// Times the targets' methods (master curve, default ODE, plastic closed form) at each chart point.
pub fn per_point_timing(
    vm_refs: &[VmRef],
    pm_refs: &[PmRef],
    plan: &TimingPlan,
) -> Vec<PointTiming> {
    let mut out = Vec::new();
    for spec in [VmSpec::Master, VmSpec::Ode(OdeSettings::DEFAULT)] {
        for r in vm_refs {
            let ns = timing::ns_per_eval(plan, 1, || {
                spec.eval(black_box(r.kappa), r.rule)
                    .map_or(0.0, |x| x.e + x.one_minus_e)
            });
            out.push(PointTiming {
                model: "vm",
                method: format!("{} {}", spec.method(), spec.setting()),
                rule: r.rule.name().into(),
                x: r.kappa,
                ns_per_eval: ns,
            });
        }
    }
    for r in pm_refs.iter().filter(|r| r.u > 1.0) {
        let ns = timing::ns_per_eval(plan, 1, || {
            PmSpec::ClosedForm
                .eval(black_box(r.u))
                .map_or(0.0, |x| x.e + x.one_minus_e)
        });
        out.push(PointTiming {
            model: "pm",
            method: PmSpec::ClosedForm.method(),
            rule: "-".into(),
            x: r.u,
            ns_per_eval: ns,
        });
    }
    out
}

/// Runs the whole bench; with `fit_data`, also the fit-accuracy comparison on it (overlap rule).
/// Fails only if a reference value (or the reference fit) cannot be computed.
pub fn run(cfg: &BenchConfig, fit_data: Option<&FitData>) -> Result<BenchReport> {
    let plan = cfg.timing();
    let vm_refs = chart_vm_points();
    let mut rows = Vec::new();
    let mut points = Vec::new();
    for spec in vm_chart_specs(cfg) {
        let (r, p) = work_precision::vm_rows(&spec, &vm_refs, &plan);
        rows.extend(r);
        points.extend(p);
    }
    let pm_refs: Vec<PmRef> = pm_fixture();
    for spec in pm_chart_specs(cfg) {
        let (r, p) = work_precision::pm_rows(&spec, &pm_refs, &plan);
        rows.push(r);
        points.extend(p);
    }
    let rk4_order = ContactEnd::ALL
        .iter()
        .filter_map(|rule| {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.method == "rk4" && r.rule == rule.name() && r.failed == 0)
                .map(|r| (r.knob, r.error))
                .collect();
            fit_order(&pts).map(|(s, n)| (rule.name().to_string(), s, n))
        })
        .collect();

    let kappas = stability::kappa_grid(cfg.map_per_decade(), MAP_MAX_DECADE);
    let mut cells = stability::vm_map(&vm_map_specs(), &kappas)?;
    cells.extend(stability::pm_map(&pm_map_specs(), &pm_refs));

    let reference_check = reference::check_ode_reference()?;
    let candidates = ode_candidates(&kappas, &vm_refs, &plan)?;
    let per_point = per_point_timing(&vm_refs, &pm_refs, &plan);
    let fit = match fit_data {
        Some(data) => Some(fit_accuracy::fit_accuracy(
            data,
            ContactEnd::Overlap,
            &cfg.fit_methods(),
            &TimingPlan {
                repeats: cfg.fit_repeats(),
                min_batch: Duration::ZERO,
            },
        )?),
        None => None,
    };
    Ok(BenchReport {
        config: *cfg,
        rows,
        points,
        cells,
        reference_check,
        rk4_order,
        candidates,
        per_point,
        fit,
    })
}

/// Cheaper settings than the default, each checked against the bar for the default over
/// the fixture and the dense kappa grid up to 100, both rules.
pub fn ode_candidates(
    kappas: &[f64],
    chart_refs: &[VmRef],
    plan: &TimingPlan,
) -> Result<Vec<OdeCandidate>> {
    let mut specs = vec![VmSpec::Ode(OdeSettings::DEFAULT)];
    for tol in [1e-9, 1e-10, 1e-11, 1e-12]
        .into_iter()
        .filter(|&t| t != OdeSettings::DEFAULT.rtol)
    {
        specs.push(VmSpec::Ode(OdeSettings::with_integrator(
            Integrator::Dop853,
            tol,
        )));
    }
    let mut dense: Vec<VmRef> = Vec::new();
    for rule in ContactEnd::ALL {
        for &kappa in kappas.iter().filter(|&&k| k <= 100.0) {
            let (e, one_minus_e, _) = vm_dense_reference(kappa, rule)?;
            dense.push(VmRef {
                rule,
                kappa,
                e,
                one_minus_e,
            });
        }
    }
    let mut all_points = vm_fixture();
    all_points.extend(dense);
    let mut out = Vec::new();
    for spec in specs {
        let mut c = OdeCandidate {
            spec,
            max_abs_e: 0.0,
            max_rel_one_minus_e: 0.0,
            failed: 0,
            points: all_points.len(),
            ns_per_eval: 0.0,
            rhs_evals: 0.0,
        };
        for r in &all_points {
            match spec.eval(r.kappa, r.rule) {
                Ok(got) => {
                    c.max_abs_e = c.max_abs_e.max((got.e - r.e).abs());
                    c.max_rel_one_minus_e = c
                        .max_rel_one_minus_e
                        .max(((got.one_minus_e - r.one_minus_e) / r.one_minus_e).abs());
                }
                Err(_) => c.failed += 1,
            }
        }
        let (rows, _) = work_precision::vm_rows(&spec, chart_refs, plan);
        if let Some(all) = rows.iter().find(|r| r.rule == "all") {
            c.ns_per_eval = all.ns_per_eval;
            c.rhs_evals = all.rhs_evals;
        }
        out.push(c);
    }
    Ok(out)
}

/// A number for CSV: shortest round-trip, empty for NaN.
fn csv_num(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        fmt_num(x)
    }
}

/// Quotes a CSV field when needed.
fn csv_text(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

impl BenchReport {
    /// `work_precision.csv`.
    pub fn work_precision_csv(&self) -> String {
        let mut s = String::from(
            "model,method,setting,knob,rule,error,error_rel_e,error_rel_one_minus_e,ns_per_eval,rhs_evals,points,failed\n",
        );
        for r in &self.rows {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{},{},{},{},{}",
                r.model,
                csv_text(&r.method),
                csv_text(&r.setting),
                csv_num(r.knob),
                r.rule,
                csv_num(r.error),
                csv_num(r.error_rel_e),
                csv_num(r.error_rel_one_minus_e),
                csv_num(r.ns_per_eval),
                csv_num(r.rhs_evals),
                r.points,
                r.failed
            );
        }
        s
    }

    /// `work_precision_points.csv`: the error of every evaluation behind the chart.
    pub fn points_csv(&self) -> String {
        let mut s = String::from(
            "model,method,setting,rule,x,e,e_ref,abs_error,rel_error_one_minus_e,rhs_evals,failure\n",
        );
        for p in &self.points {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{},{},{},{}",
                p.model,
                csv_text(&p.method),
                csv_text(&p.setting),
                p.rule,
                csv_num(p.x),
                csv_num(p.e),
                csv_num(p.e_ref),
                csv_num(p.abs_error),
                csv_num(p.rel_error_one_minus_e),
                csv_num(p.rhs_evals),
                csv_text(p.failure.as_deref().unwrap_or(""))
            );
        }
        s
    }

    /// `stability.csv`.
    pub fn stability_csv(&self) -> String {
        let mut s = String::from("model,method,setting,role,rule,x_name,x,outcome,error,detail\n");
        for c in &self.cells {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{},{},{}",
                c.model,
                csv_text(&c.method),
                csv_text(&c.setting),
                match c.role {
                    Role::Production => "production",
                    Role::Comparator => "comparator",
                    Role::Loose => "loose",
                },
                c.rule,
                if c.model == "vm" { "kappa" } else { "u" },
                csv_num(c.x),
                c.outcome.name(),
                csv_num(c.error),
                csv_text(&c.detail)
            );
        }
        s
    }

    /// `fit_accuracy.csv`: one row per evaluation method (header only without a data set).
    pub fn fit_accuracy_csv(&self) -> String {
        let mut s = String::from(
            "method,setting,knob,eta,eta_rel_error,fit_ms,evaluations,model_error,threshold,meets,default,converged,failure\n",
        );
        if let Some(f) = &self.fit {
            for (i, r) in f.rows.iter().enumerate() {
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    csv_text(&r.method),
                    csv_text(&r.setting),
                    csv_num(r.knob),
                    csv_num(r.eta),
                    csv_num(r.eta_rel_error),
                    csv_num(r.fit_ms),
                    r.evaluations,
                    csv_num(r.model_error),
                    csv_num(f.threshold),
                    r.meets,
                    f.default_row == Some(i),
                    r.converged,
                    csv_text(r.failure.as_deref().unwrap_or(""))
                );
            }
        }
        s
    }

    /// `timing_per_point.csv`.
    pub fn per_point_csv(&self) -> String {
        let mut s = String::from("model,method,rule,x,ns_per_eval\n");
        for p in &self.per_point {
            let _ = writeln!(
                s,
                "{},{},{},{},{}",
                p.model,
                csv_text(&p.method),
                p.rule,
                csv_num(p.x),
                csv_num(p.ns_per_eval)
            );
        }
        s
    }

    /// The fastest and the slowest point of a method.
    pub fn point_range(&self, method: &str) -> Option<(&PointTiming, &PointTiming)> {
        let pts = || self.per_point.iter().filter(|p| p.method == method);
        let lo = pts().min_by(|a, b| a.ns_per_eval.total_cmp(&b.ns_per_eval))?;
        let hi = pts().max_by(|a, b| a.ns_per_eval.total_cmp(&b.ns_per_eval))?;
        Some((lo, hi))
    }

    /// The row of `method` at `setting` for `rule`.
    pub fn row(&self, model: &str, method: &str, setting: &str, rule: &str) -> Option<&WpRow> {
        self.rows.iter().find(|r| {
            r.model == model && r.method == method && r.setting == setting && r.rule == rule
        })
    }
}

/// One non-`ok` outcome of a map row: (outcome, count, smallest x, largest x).
pub type OutcomeSpan = (stability::Outcome, usize, f64, f64);

/// For each map row (method, setting, rule), its non-`ok` outcomes.
pub fn map_failures(cells: &[Cell]) -> Vec<(String, Vec<OutcomeSpan>)> {
    let mut keys: Vec<String> = Vec::new();
    let key = |c: &Cell| {
        let mut k = format!("{} {}", c.model, c.method);
        if c.setting != "-" {
            k.push_str(&format!(" {}", c.setting));
        }
        if c.rule != "-" {
            k.push_str(&format!(" [{}]", c.rule));
        }
        k
    };
    for c in cells {
        let k = key(c);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|k| {
            let mut out: Vec<OutcomeSpan> = Vec::new();
            for c in cells
                .iter()
                .filter(|c| key(c) == k && c.outcome != stability::Outcome::Ok)
            {
                match out.iter_mut().find(|o| o.0 == c.outcome) {
                    Some(o) => {
                        o.1 += 1;
                        o.2 = o.2.min(c.x);
                        o.3 = o.3.max(c.x);
                    }
                    None => out.push((c.outcome, 1, c.x, c.x)),
                }
            }
            (k, out)
        })
        .collect()
}

fn sci(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.2e}")
    }
}

impl BenchReport {
    /// Slopes of log(error) against log(h) between successive RK4 steps for `rule`, labelled by
    /// the smaller step.
    pub fn rk4_local_slopes(&self, rule: &str) -> Vec<(f64, f64)> {
        let mut pts: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter(|r| r.method == "rk4" && r.rule == rule && r.failed == 0 && r.error > 0.0)
            .map(|r| (r.knob, r.error))
            .collect();
        pts.sort_by(|a, b| b.0.total_cmp(&a.0));
        pts.windows(2)
            .map(|w| (w[1].0, (w[0].1 / w[1].1).ln() / (w[0].0 / w[1].0).ln()))
            .collect()
    }

    /// The largest |error in e| of the master curve over the whole fixture (kappa 1e-8 to 100).
    pub fn master_full_range_error(&self) -> f64 {
        vm_fixture()
            .iter()
            .map(|r| match VmSpec::Master.eval(r.kappa, r.rule) {
                Ok(x) => (x.e - r.e).abs(),
                Err(_) => f64::INFINITY,
            })
            .fold(0.0, f64::max)
    }

    /// `summary.md`: the targets, the fitted RK4 order, the reference check, the default-setting
    /// candidates and the stability map's failures. `machine` describes where it ran.
    pub fn summary_markdown(&self, machine: &str) -> String {
        let mut s = String::new();
        let mode = if self.config.quick { "quick" } else { "full" };
        let _ = writeln!(s, "# restitution bench ({mode})\n");
        let _ = writeln!(s, "Machine: {machine}\n");
        let _ = writeln!(
            s,
            "Time: wall clock per evaluation, warm, minimum over {} batches of at least {} ms; \
             vm over the fixture's kappa in [{}, {}] (both rules), pm over its u in (1, 1e12].\n",
            self.config.timing().repeats,
            self.config.timing().min_batch.as_millis(),
            CHART_KAPPA_MIN,
            CHART_KAPPA_MAX
        );
        let _ = writeln!(s, "## Targets\n");
        let _ = writeln!(
            s,
            "| target | mean over the points | slowest point | accuracy | met on the mean | met at every point |\n|---|---|---|---|---|---|"
        );
        let yes = |b: bool| if b { "yes" } else { "no" };
        let slowest = |method: &str, scale: f64, unit: &str| -> (f64, String) {
            match self.point_range(method) {
                Some((_, hi)) => {
                    let rule = if hi.rule == "-" {
                        String::new()
                    } else {
                        format!(", {}", hi.rule)
                    };
                    let x = if hi.model == "pm" { "u" } else { "kappa" };
                    (
                        hi.ns_per_eval,
                        format!(
                            "{:.2} {unit} ({x} = {}{rule})",
                            hi.ns_per_eval / scale,
                            fmt_num(hi.x)
                        ),
                    )
                }
                None => (f64::NAN, "-".into()),
            }
        };
        if let Some(m) = self.row("vm", "master", "table", "all") {
            let full = self.master_full_range_error();
            let accurate = m.error <= 1e-12 && full <= 1e-12;
            let (worst, text) = slowest("master table", 1.0, "ns");
            let _ = writeln!(
                s,
                "| master curve < 100 ns/eval at error <= 1e-12 | {:.1} ns | {text} | {} (kappa 1e-8..100: {}) | {} | {} |",
                m.ns_per_eval,
                sci(m.error),
                sci(full),
                yes(accurate && m.ns_per_eval < 100.0),
                yes(accurate && worst < 100.0)
            );
        }
        let default_tol = fmt_num(OdeSettings::DEFAULT.rtol);
        let default_setting = format!("tol={default_tol}");
        let default_method = format!("dop853 {default_setting}");
        if let Some(d) = self.row("vm", "dop853", &default_setting, "all") {
            let full = self.candidates.first().map_or(f64::NAN, |c| c.max_abs_e);
            let accurate = d.error <= 1e-10 && full <= 1e-10;
            let (worst, text) = slowest(&default_method, 1e3, "us");
            let _ = writeln!(
                s,
                "| default ODE (Dop853, tol {default_tol}, e only) < 20 us/eval at error <= 1e-10 | {:.2} us ({:.0} rhs evals) | {text} | {} (kappa 1e-8..100: {}) | {} | {} |",
                d.ns_per_eval / 1e3,
                d.rhs_evals,
                sci(d.error),
                sci(full),
                yes(accurate && d.ns_per_eval < 20_000.0),
                yes(accurate && worst < 20_000.0)
            );
        }
        if let Some(dx) = self.row("vm", "dop853+extrema", &default_setting, "all") {
            let _ = writeln!(
                s,
                "| (the same through `rebound`, with contact time, maximum overlap and force) | {:.2} us ({:.0} rhs evals) | - | {} | {} | - |",
                dx.ns_per_eval / 1e3,
                dx.rhs_evals,
                sci(dx.error),
                yes(dx.ns_per_eval < 20_000.0)
            );
        }
        if let Some(p) = self.row("pm", "closed form", "-", "-") {
            let ulp_e = p.error_rel_e / f64::EPSILON;
            let ulp_ome = p.error_rel_one_minus_e / f64::EPSILON;
            let (worst, text) = slowest("closed form", 1.0, "ns");
            let _ = writeln!(
                s,
                "| plastic closed form (e and 1 - e) < 30 ns/eval at relative error <= 4 ulp | {:.1} ns | {text} | e {:.2} ulp, 1 - e {:.2} ulp | {} | {} |",
                p.ns_per_eval,
                ulp_e,
                ulp_ome,
                yes(ulp_e <= 4.0 && p.ns_per_eval < 30.0),
                yes(ulp_e <= 4.0 && worst < 30.0)
            );
        }
        let _ = writeln!(
            s,
            "\nPer point (each chart point timed alone; the table's figures are the means):\n"
        );
        for (method, unit, scale) in [
            ("master table", "ns", 1.0),
            (default_method.as_str(), "us", 1e3),
            ("closed form", "ns", 1.0),
        ] {
            if let Some((lo, hi)) = self.point_range(method) {
                let x = if method == "closed form" {
                    "u"
                } else {
                    "kappa"
                };
                let rule = |r: &str| {
                    if r == "-" {
                        String::new()
                    } else {
                        format!(", {r}")
                    }
                };
                let _ = writeln!(
                    s,
                    "- {method}: {:.2} {unit} ({x} = {}{}) to {:.2} {unit} ({x} = {}{})",
                    lo.ns_per_eval / scale,
                    fmt_num(lo.x),
                    rule(&lo.rule),
                    hi.ns_per_eval / scale,
                    fmt_num(hi.x),
                    rule(&hi.rule)
                );
            }
        }
        let _ = writeln!(s, "\n## Achieved order of fixed-step RK4\n");
        for (rule, slope, n) in &self.rk4_order {
            let _ = writeln!(
                s,
                "- {rule} rule: fitted slope of log(error) against log(h) = {slope:.3} ({n} steps with error in [{:e}, {:e}]); local slopes from the largest step down: {}",
                work_precision::ORDER_FIT_MIN_ERROR,
                work_precision::ORDER_FIT_MAX_ERROR,
                self.rk4_local_slopes(rule)
                    .iter()
                    .map(|(h, sl)| format!("{sl:.2} (h={})", fmt_num(*h)))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        let rc = &self.reference_check;
        let _ = writeln!(s, "\n## Reference check\n");
        let _ = writeln!(
            s,
            "The dense reference (ODE at tol 1e-15) against the mpmath fixture, {} points: max |error in e| {}, max relative error of 1 - e {}; the overlap law A kappa^-5 (kappa >= 10) against it: {} relative.",
            rc.points,
            sci(rc.ode_max_abs_e),
            sci(rc.ode_max_rel_one_minus_e),
            sci(rc.asymptote_max_rel_e)
        );
        let _ = writeln!(
            s,
            "\n## Default ODE setting candidates\n\nBar: |error in e| <= 1e-10 and relative error of 1 - e <= 1e-8 over the fixture and the map's kappa grid up to 100, both rules.\n"
        );
        let _ = writeln!(
            s,
            "| setting | max abs error e | max rel error 1-e | failed | us/eval | rhs evals | meets bar |\n|---|---|---|---|---|---|---|"
        );
        for c in &self.candidates {
            let _ = writeln!(
                s,
                "| {} {} | {} | {} | {} | {:.2} | {:.0} | {} |",
                c.spec.method(),
                c.spec.setting(),
                sci(c.max_abs_e),
                sci(c.max_rel_one_minus_e),
                c.failed,
                c.ns_per_eval / 1e3,
                c.rhs_evals,
                if c.meets_bar() { "yes" } else { "no" }
            );
        }
        if let Some(f) = &self.fit {
            let _ = writeln!(s, "\n## What accuracy a fit needs\n");
            let _ = writeln!(
                s,
                "Model `vm` (overlap rule) fitted to the example data set ({} points, kappa {}..{} at the fitted eta), each evaluation method against the fit with the ODE at tol 1e-15 (eta = {} kg/(s m), standard error {} = {} relative; {:.0} ms). Rule: model error (max |e - e_ref| over the data) <= {} x the smallest error bar ({}) = {}.\n",
                f.n_points,
                sci(f.kappa_range.0),
                sci(f.kappa_range.1),
                fmt_num(f.eta_ref),
                sci(f.eta_ref_stderr),
                sci(f.eta_ref_stderr / f.eta_ref),
                f.reference_fit_ms,
                fit_accuracy::SIGMA_FRACTION,
                sci(f.min_sigma),
                sci(f.threshold)
            );
            let _ = writeln!(
                s,
                "| method | setting | eta rel. error | fit ms | model error | meets | note |\n|---|---|---|---|---|---|---|"
            );
            for (i, r) in f.rows.iter().enumerate() {
                let note = if f.default_row == Some(i) {
                    "**default: cheapest that meets the rule**".to_string()
                } else {
                    r.failure.clone().unwrap_or_default()
                };
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {:.2} | {} | {} | {} |",
                    r.method,
                    r.setting,
                    sci(r.eta_rel_error),
                    r.fit_ms,
                    sci(r.model_error),
                    if r.meets { "yes" } else { "no" },
                    note.replace('|', "/")
                );
            }
        }
        let _ = writeln!(
            s,
            "\n## Stability map (threshold {}; kappa 1e-8..1e{}, u in (1, 1e12])\n",
            stability::MAP_TOL,
            MAP_MAX_DECADE
        );
        let silent: Vec<&Cell> = self
            .cells
            .iter()
            .filter(|c| c.role != Role::Comparator && c.outcome.is_silent_failure())
            .collect();
        let _ = writeln!(
            s,
            "Cells where a production method (or a loose setting, held to 100 x its tolerance) returned a wrong number without an error value: {}. The comparators (quadrature, naive q) are kept to show their failure.\n",
            silent.len()
        );
        for (k, fails) in map_failures(&self.cells) {
            if fails.is_empty() {
                let _ = writeln!(s, "- {k}: ok everywhere");
            } else {
                // Plastic cells are located by u - 1 (they crowd at u = 1).
                let (shift, var) = if k.starts_with("pm") {
                    (1.0, "u - 1")
                } else {
                    (0.0, "kappa")
                };
                let parts: Vec<String> = fails
                    .iter()
                    .map(|(o, n, lo, hi)| {
                        format!(
                            "{} x{} ({var} = {}..{})",
                            o.name(),
                            n,
                            sci(lo - shift),
                            sci(hi - shift)
                        )
                    })
                    .collect();
                let _ = writeln!(s, "- {k}: {}", parts.join(", "));
            }
        }
        s
    }
}
