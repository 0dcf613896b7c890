//! What `restitution bench` writes: the CSV files (through `csv::Writer`) and `summary.md`.

use super::reference::vm_fixture;
use super::stability::{self, Cell, Role};
use super::{
    BenchReport, CHART_KAPPA_MAX, CHART_KAPPA_MIN, MAP_MAX_DECADE, PointTiming, VmSpec, WpRow,
    fit_accuracy, work_precision,
};
use crate::data::fmt_num;
use crate::models::viscoelastic::OdeSettings;
use std::fmt::Write as _;

/// A number for CSV: shortest round-trip, empty for NaN.
fn csv_num(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        fmt_num(x)
    }
}

/// A CSV document from a header line and rows, written by `csv::Writer` (which quotes fields
/// that need it).
fn to_csv(header: &str, rows: &[Vec<String>]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let cols: Vec<&str> = header.split(',').collect();
    // Writing to a Vec cannot fail, and every row has the header's length by construction.
    w.write_record(&cols).expect("write to memory");
    for r in rows {
        w.write_record(r).expect("write to memory");
    }
    String::from_utf8(w.into_inner().expect("flush to memory")).expect("UTF-8 fields")
}

impl BenchReport {
    /// `work_precision.csv`.
    pub fn work_precision_csv(&self) -> String {
        let header = "model,method,setting,knob,rule,error,error_rel_e,error_rel_one_minus_e,ns_per_eval,rhs_evals,points,failed";
        let mut rows: Vec<Vec<String>> = Vec::new();
        for r in &self.rows {
            rows.push(vec![
                (r.model).to_string(),
                (r.method).to_string(),
                (r.setting).to_string(),
                csv_num(r.knob),
                (r.rule).to_string(),
                csv_num(r.error),
                csv_num(r.error_rel_e),
                csv_num(r.error_rel_one_minus_e),
                csv_num(r.ns_per_eval),
                csv_num(r.rhs_evals),
                (r.points).to_string(),
                (r.failed).to_string(),
            ]);
        }
        to_csv(header, &rows)
    }

    /// `work_precision_points.csv`: the error of every evaluation behind the chart.
    pub fn points_csv(&self) -> String {
        let header =
            "model,method,setting,rule,x,e,e_ref,abs_error,rel_error_one_minus_e,rhs_evals,failure";
        let mut rows: Vec<Vec<String>> = Vec::new();
        for p in &self.points {
            rows.push(vec![
                (p.model).to_string(),
                (p.method).to_string(),
                (p.setting).to_string(),
                (p.rule).to_string(),
                csv_num(p.x),
                csv_num(p.e),
                csv_num(p.e_ref),
                csv_num(p.abs_error),
                csv_num(p.rel_error_one_minus_e),
                csv_num(p.rhs_evals),
                (p.failure.as_deref().unwrap_or("")).to_string(),
            ]);
        }
        to_csv(header, &rows)
    }

    /// `stability.csv`.
    pub fn stability_csv(&self) -> String {
        let header = "model,method,setting,role,rule,x_name,x,outcome,error,detail";
        let mut rows: Vec<Vec<String>> = Vec::new();
        for c in &self.cells {
            rows.push(vec![
                (c.model).to_string(),
                (c.method).to_string(),
                (c.setting).to_string(),
                <&str>::from(c.role).to_string(),
                (c.rule).to_string(),
                (if c.model == "vm" { "kappa" } else { "u" }).to_string(),
                csv_num(c.x),
                (c.outcome.name()).to_string(),
                csv_num(c.error),
                (c.detail).to_string(),
            ]);
        }
        to_csv(header, &rows)
    }

    /// `fit_accuracy.csv`: one row per evaluation method (header only without a data set).
    pub fn fit_accuracy_csv(&self) -> String {
        let header = "method,setting,knob,eta,eta_rel_error,fit_ms,evaluations,model_error,threshold,meets,default,converged,failure";
        let mut rows: Vec<Vec<String>> = Vec::new();
        if let Some(f) = &self.fit {
            for (i, r) in f.rows.iter().enumerate() {
                rows.push(vec![
                    (r.method).to_string(),
                    (r.setting).to_string(),
                    csv_num(r.knob),
                    csv_num(r.eta),
                    csv_num(r.eta_rel_error),
                    csv_num(r.fit_ms),
                    (r.evaluations).to_string(),
                    csv_num(r.model_error),
                    csv_num(f.threshold),
                    (r.meets).to_string(),
                    (f.default_row == Some(i)).to_string(),
                    (r.converged).to_string(),
                    (r.failure.as_deref().unwrap_or("")).to_string(),
                ]);
            }
        }
        to_csv(header, &rows)
    }

    /// `timing_per_point.csv`.
    pub fn per_point_csv(&self) -> String {
        let header = "model,method,rule,x,ns_per_eval";
        let mut rows: Vec<Vec<String>> = Vec::new();
        for p in &self.per_point {
            rows.push(vec![
                (p.model).to_string(),
                (p.method).to_string(),
                (p.rule).to_string(),
                csv_num(p.x),
                csv_num(p.ns_per_eval),
            ]);
        }
        to_csv(header, &rows)
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
                // A "no" says why: the fit failed, or it was not converged (its search could
                // not certify the minimum within the model's stated accuracy), or the model
                // error is above the rule's threshold.
                let note = if f.default_row == Some(i) {
                    "**default: cheapest that meets the rule**".to_string()
                } else if let Some(why) = &r.failure {
                    why.clone()
                } else if !r.converged {
                    "fit not converged (the minimum not certified global)".to_string()
                } else if !r.meets {
                    "model error above the threshold".to_string()
                } else {
                    String::new()
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
            "\n## Stability map (threshold {} relative in e and in 1 - e; kappa 1e-8..1e{} at {} per decade, then every second decade to 1e300 and f64::MAX; u in (1, f64::MAX])\n",
            stability::MAP_TOL,
            MAP_MAX_DECADE,
            self.config.map_per_decade()
        );
        let silent: Vec<&Cell> = self
            .cells
            .iter()
            .filter(|c| c.role == Role::Production && c.outcome.is_silent_failure())
            .collect();
        let _ = writeln!(
            s,
            "Cells where a production method returned a wrong number without an error value: {}. The comparators (fixed-step RK4, quadrature, naive q) and the loose settings (held to 100 x their tolerance) are kept to show their failures.\n",
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
