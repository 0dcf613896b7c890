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
//! plastic points the fixture's u in (1, 1e12] (the map takes all of it, to f64::MAX). The stability map's dense kappa grid uses
//! [`reference::vm_dense_reference`] (the ODE at 1e-15, checked against the fixture in the report).
//!
//! **Time** is wall-clock per evaluation, warm, the minimum over repeated batches
//! ([`timing`]); rhs_evals counts right-hand-side calls of the ODE (integrand calls for the
//! quadrature), including those spent locating events.

pub mod fit_accuracy;
pub mod methods;
pub mod output;
pub mod quadrature;
pub mod reference;
pub mod stability;
pub mod timing;
pub mod work_precision;

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
use std::hint::black_box;
use std::time::Duration;
pub use timing::TimingPlan;
pub use work_precision::{WpPoint, WpRow, fit_order};

/// The chart's kappa range (a representative set: kappa 1e-4..5).
pub const CHART_KAPPA_MIN: f64 = 1e-4;
pub const CHART_KAPPA_MAX: f64 = 5.0;
/// The chart's largest u (the plastic fixture goes on to f64::MAX for the stability map).
pub const CHART_U_MAX: f64 = 1e12;
/// The dense part of the stability map's kappa grid ends at 10^this (the default-setting
/// candidates are checked on it up to 100); the map itself goes on, every second decade, to 1e300
/// and f64::MAX ([`stability::kappa_grid_wide`]).
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
        // Fixed-step RK4 has no error control: with the map's relative criterion on e it returns
        // e = 1e-6..1e-7 (kappa 18-32, overlap rule) with relative errors above 1e-6. It is kept
        // to show its order and breakdowns, not offered as a way to compute e (the CLI has no
        // RK4), so it is a comparator.
        (
            VmSpec::Ode(OdeSettings::with_integrator(
                Integrator::Rk4 { h: MAP_RK4_STEP },
                0.0,
            )),
            Role::Comparator,
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

/// A candidate default ODE setting, checked against the default's accuracy target over kappa in [1e-8, 100].
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
    /// The accuracy target for the default (README, "Speed against accuracy"): |error in e| <= 1e-10, relative error of 1 - e <= 1e-8.
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
    // The chart and its timings keep u in (1, 1e12] (where the comparators are defined); the
    // stability map takes the whole fixture, up to f64::MAX.
    let pm_all: Vec<PmRef> = pm_fixture();
    let pm_refs: Vec<PmRef> = pm_all
        .iter()
        .copied()
        .filter(|r| r.u <= CHART_U_MAX)
        .collect();
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
    let map_kappas = stability::kappa_grid_wide(cfg.map_per_decade());
    let mut cells = stability::vm_map(&vm_map_specs(), &map_kappas)?;
    cells.extend(stability::pm_map(&pm_map_specs(), &pm_all));

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

/// Cheaper settings than the default, each checked against the default's accuracy target over
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
