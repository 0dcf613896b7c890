//! Renders fits for people: the table printed by `restitution fit` and `params.md`. Each value is
//! rounded to the precision of its error (two significant digits); the fit's warnings are listed
//! under the tables (`warnings: none` when there are none), so a reader cannot miss them.

use super::fit::{ReportContext, vm_method_name};
use crate::data::fmt_num;
use crate::fit::compare::PREFERENCE_RULE;
use crate::fit::engine::FitSet;
use crate::fit::models::{ModelKind, POWERLAW_D_REF_MM, POWERLAW_V_REF_M_S};
use crate::fit::result::{ParamEstimate, ParamStatus};

/// Decimal exponent used to print a value (engineering style only outside [1e-3, 1e5)).
fn exponent_of(x: f64) -> i32 {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() || (1e-3..1e5).contains(&a) {
        0
    } else {
        a.log10().floor() as i32
    }
}

/// Digits after the point that show `err` with two significant digits (4 significant digits of
/// the value when there is no error).
fn decimals_for(value: f64, err: Option<f64>) -> usize {
    match err.filter(|e| e.is_finite() && *e > 0.0) {
        Some(e) => (1 - e.log10().floor() as i32).clamp(0, 12) as usize,
        None => {
            let a = value.abs();
            if a == 0.0 || !a.is_finite() {
                3
            } else {
                (3 - a.log10().floor() as i32).clamp(0, 12) as usize
            }
        }
    }
}

/// A way to print the numbers of one parameter: a common power of ten and decimals.
#[derive(Clone, Copy)]
struct Style {
    exp: i32,
    dec: usize,
}

impl Style {
    fn of(value: f64, err: Option<f64>) -> Style {
        let exp = exponent_of(value);
        let s = 10f64.powi(exp);
        Style {
            exp,
            dec: decimals_for(value / s, err.map(|e| e / s)),
        }
    }
    fn show(&self, x: f64) -> String {
        let scaled = x / 10f64.powi(self.exp);
        let dec = self.dec;
        if self.exp == 0 {
            format!("{scaled:.dec$}")
        } else {
            format!("{scaled:.dec$}e{}", self.exp)
        }
    }
}

/// Value, stderr, stderr_abs and interval of a parameter as printed in the human tables.
struct Shown {
    value: String,
    stderr: String,
    stderr_abs: String,
    ci: String,
}

fn show_param(p: &ParamEstimate) -> Shown {
    // A bound is shown at its own scale (the best fit of an undetermined parameter is arbitrary).
    let anchor = match p.status {
        ParamStatus::LowerBound => p.ci95.0.unwrap_or(p.best_fit),
        ParamStatus::UpperBound => p.ci95.1.unwrap_or(p.best_fit),
        _ => p.best_fit,
    };
    let style = Style::of(anchor, p.stderr);
    let o = |x: Option<f64>| x.map(|v| style.show(v)).unwrap_or_default();
    // An error in the value's power of ten, with at least two significant digits of its own.
    let err = |e: Option<f64>| {
        e.filter(|e| e.is_finite() && *e > 0.0)
            .map(|e| {
                let scaled = e / 10f64.powi(style.exp);
                if scaled < 1e-10 {
                    // Too small to show in the value's power of ten: its own exponent.
                    return format!("{e:.1e}");
                }
                let own = decimals_for(1.0, Some(scaled));
                Style {
                    exp: style.exp,
                    dec: style.dec.max(own),
                }
                .show(e)
            })
            .unwrap_or_default()
    };
    let end = |x: Option<f64>| x.map(|v| style.show(v)).unwrap_or_else(|| "-".into());
    let value = match p.status {
        ParamStatus::Estimate | ParamStatus::IntervalLost => o(p.value),
        ParamStatus::LowerBound => format!("> {}", o(p.ci95.0)),
        ParamStatus::UpperBound => format!("< {}", o(p.ci95.1)),
        ParamStatus::Unconstrained => "not determined".into(),
    };
    let ci = match p.status {
        ParamStatus::Unconstrained => "-".into(),
        _ => format!("[{}, {}]", end(p.ci95.0), end(p.ci95.1)),
    };
    Shown {
        value,
        stderr: err(p.stderr),
        stderr_abs: err(p.stderr_abs),
        ci,
    }
}

/// Shortest round-trip, in exponent form from 1e5 up (3.5e8 rather than 350000000).
fn plain(x: f64) -> String {
    if x.abs() >= 1e5 && x.is_finite() {
        format!("{x:e}")
    } else {
        fmt_num(x)
    }
}

/// Sizes or pairs the header names before it gives only their count.
const MAX_SIZES_LISTED: usize = 8;

fn header_lines(ctx: &ReportContext) -> Vec<String> {
    // Identical spheres by their diameters; otherwise each pair as measured (a list of sizes
    // would hide that 10 mm met 20 mm, or a wall). A line, not a page: 100 000 rows of distinct
    // sizes listed them all.
    // Only the listed items are formatted (formatting 100 000 labels to print 8 was 7% of a
    // `vm` fit of 100 000 rows of distinct sizes).
    let listed = |n: usize, item: &dyn Fn(usize) -> String| {
        let shown: Vec<String> = (0..n.min(MAX_SIZES_LISTED)).map(item).collect();
        if n <= MAX_SIZES_LISTED {
            shown.join(", ")
        } else {
            format!("{}, ... ({n} in all)", shown.join(", "))
        }
    };
    let sizes = if ctx.data.identical_pairs() {
        let d = ctx.data.diameters_mm();
        format!("d = {} mm", listed(d.len(), &|i| fmt_num(d[i])))
    } else {
        let groups = ctx.data.groups();
        format!("pairs: {}", listed(groups.len(), &|i| groups[i].label()))
    };
    let m = ctx.data.material;
    vec![
        format!(
            "{}: {} points, {sizes}; errors of e: {}",
            ctx.path,
            ctx.data.len(),
            ctx.error_source
        ),
        format!(
            "material: Y = {} Pa, nu = {}, rho = {} kg/m^3; contact end: {}; e_vm by {}",
            plain(m.youngs_pa),
            plain(m.poisson),
            plain(m.density_kg_m3),
            ctx.rule.name(),
            vm_method_name(ctx.vm_method)
        ),
    ]
}

fn aligned(rows: &[Vec<String>], right: &[bool]) -> String {
    let ncol = rows.iter().map(|r| r.len()).max().unwrap_or(0);
    let widths: Vec<usize> = (0..ncol)
        .map(|j| {
            rows.iter()
                .map(|r| r.get(j).map_or(0, |c| c.chars().count()))
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut s = String::new();
    for r in rows {
        let cells: Vec<String> = r
            .iter()
            .enumerate()
            .map(|(j, c)| {
                let w = widths[j];
                if right.get(j).copied().unwrap_or(false) {
                    format!("{c:>w$}")
                } else {
                    format!("{c:<w$}")
                }
            })
            .collect();
        s += cells.join("  ").trim_end();
        s += "\n";
    }
    s
}

fn short(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        format!("{x:.prec$e}", prec = digits.saturating_sub(1))
    } else {
        let dec = if a == 0.0 {
            digits - 1
        } else {
            (digits as i32 - 1 - a.log10().floor() as i32).clamp(0, 12) as usize
        };
        format!("{x:.dec$}")
    }
}

fn param_rows(set: &FitSet) -> Vec<Vec<String>> {
    let mut rows = vec![vec![
        "model".to_string(),
        "parameter".into(),
        "value".into(),
        "stderr".into(),
        "stderr_abs".into(),
        "95% interval (profile)".into(),
        "unit".into(),
    ]];
    for f in &set.fits {
        let mut first = true;
        for (p, derived) in f
            .params
            .iter()
            .map(|p| (p, false))
            .chain(f.derived.iter().map(|p| (p, true)))
        {
            let s = show_param(p);
            rows.push(vec![
                if first {
                    f.model.name().into()
                } else {
                    String::new()
                },
                if derived {
                    format!("{} (derived)", p.key)
                } else {
                    p.key.into()
                },
                s.value,
                s.stderr,
                s.stderr_abs,
                s.ci,
                p.unit.into(),
            ]);
            first = false;
        }
    }
    rows
}

fn comparison_rows(set: &FitSet) -> Vec<Vec<String>> {
    let mut rows = vec![vec![
        "model".to_string(),
        "k".into(),
        "chi2".into(),
        "dof".into(),
        "chi2/dof".into(),
        "AIC".into(),
        "BIC".into(),
        "dAIC".into(),
        "weight".into(),
        "converged".into(),
        "evals".into(),
    ]];
    let comp = set.comparison.as_ref();
    for (i, f) in set.fits.iter().enumerate() {
        let row = comp.map(|c| &c.rows[i]);
        rows.push(vec![
            f.model.name().into(),
            f.k().to_string(),
            short(f.chi2, 5),
            f.dof.to_string(),
            short(f.reduced_chi2, 4),
            short(f.aic, 5),
            short(f.bic, 5),
            row.map(|r| short(r.delta_aic, 4)).unwrap_or_default(),
            row.map(|r| short(r.akaike_weight, 3)).unwrap_or_default(),
            if f.converged { "yes" } else { "NO" }.into(),
            (f.evaluations + f.profile_evaluations).to_string(),
        ]);
    }
    rows
}

fn correlation_lines(set: &FitSet) -> Vec<String> {
    let mut out = Vec::new();
    for f in &set.fits {
        let k = f.params.len();
        let mut parts = Vec::new();
        for i in 0..k {
            for j in i + 1..k {
                let c = f.correlation[i][j];
                parts.push(format!(
                    "{}~{} {}",
                    f.params[i].key,
                    f.params[j].key,
                    if c.is_finite() {
                        format!("{:.3}", c + 0.0)
                    } else {
                        "-".into()
                    }
                ));
            }
        }
        if !parts.is_empty() {
            out.push(format!("{}: {}", f.model.name(), parts.join(", ")));
        }
    }
    out
}

fn preferred_line(set: &FitSet) -> Option<String> {
    let c = set.comparison.as_ref()?;
    let name = c.preferred.map_or("none", |m| m.name());
    let why = c.unranked.as_deref().unwrap_or(PREFERENCE_RULE);
    // The best description of the data need not be a law to use: data at one speed fit the
    // power law best with A and b determined only together, and `export` refuses it.
    let undetermined: Vec<&str> = c
        .preferred
        .and_then(|m| set.fits.iter().find(|f| f.model == m))
        .map(|f| {
            f.params
                .iter()
                .filter(|p| p.status == ParamStatus::Unconstrained)
                .map(|p| p.key)
                .collect()
        })
        .unwrap_or_default();
    let caveat = if undetermined.is_empty() {
        String::new()
    } else {
        format!(
            "; its {} not determined by these data, so it cannot be exported as a law",
            match undetermined[..] {
                [one] => format!("{one} is"),
                _ => format!("{} are", undetermined.join(", ")),
            }
        )
    };
    Some(format!("preferred model: {name} ({why}){caveat}"))
}

fn note_lines(set: &FitSet) -> Vec<String> {
    let mut out = Vec::new();
    for k in &set.skipped {
        out.push(format!(
            "{}: not fitted: {} parameters need more than {} points",
            k.name(),
            k.n_params(),
            set.fits.first().map_or(0, |f| f.n)
        ));
    }
    for f in &set.fits {
        for n in &f.notes {
            out.push(format!("{}: {n}", f.model.name()));
        }
        let g = &f.global;
        if g.certified {
            // Where cells were left at the resolution the bounds do not cover them: said so.
            let region = if g.fine_cells == 0 {
                "anywhere in the search box".to_string()
            } else {
                format!(
                    "in the search box outside {} cell{} of a fraction of a standard error \
                     around the minima, where it rests on the local polishes",
                    g.fine_cells,
                    if g.fine_cells == 1 { "" } else { "s" }
                )
            };
            out.push(format!(
                "{}: global minimum certified: no chi2 below it by more than {} {region} ({} \
                 cell{}, {} polish{})",
                f.model.name(),
                short(g.gap_chi2, 2),
                g.cells,
                if g.cells == 1 { "" } else { "s" },
                g.polishes,
                if g.polishes == 1 { "" } else { "es" }
            ));
        }
        if f.model == ModelKind::PowerLaw {
            out.push(format!(
                "powerlaw: d is 4 R~ (the diameter for identical spheres), d_ref = {} mm, v_ref = {} m/s",
                POWERLAW_D_REF_MM, POWERLAW_V_REF_M_S
            ));
        }
    }
    out
}

/// Every fit's warnings, one line each ("model: text").
fn warning_lines(set: &FitSet) -> Vec<String> {
    set.fits
        .iter()
        .flat_map(|f| {
            f.warnings
                .iter()
                .map(move |w| format!("{}: {w}", f.model.name()))
        })
        .collect()
}

/// The readable table printed on stdout.
pub fn to_table(ctx: &ReportContext, set: &FitSet) -> String {
    let mut s = header_lines(ctx).join("\n") + "\n\n";
    s += &aligned(
        &param_rows(set),
        &[false, false, true, true, true, false, false],
    );
    s += "\n";
    s += &aligned(
        &comparison_rows(set),
        &[
            false, true, true, true, true, true, true, true, true, false, true,
        ],
    );
    if let Some(p) = preferred_line(set) {
        s += &format!("\n{p}\n");
    }
    let corr = correlation_lines(set);
    if !corr.is_empty() {
        s += &format!("correlations: {}\n", corr.join("; "));
    }
    let warnings = warning_lines(set);
    if warnings.is_empty() {
        s += "warnings: none\n";
    } else {
        s += "warnings:\n";
        for w in warnings {
            s += &format!("  {w}\n");
        }
    }
    let notes = note_lines(set);
    if !notes.is_empty() {
        s += "notes:\n";
        for n in notes {
            s += &format!("  {n}\n");
        }
    }
    s
}

fn md_table(rows: &[Vec<String>]) -> String {
    let mut s = String::new();
    for (i, r) in rows.iter().enumerate() {
        s += &format!("| {} |\n", r.join(" | "));
        if i == 0 {
            s += &format!("|{}\n", "---|".repeat(r.len()));
        }
    }
    s
}

/// `params.md`: the parameter and comparison tables in Markdown.
pub fn to_markdown(ctx: &ReportContext, set: &FitSet) -> String {
    let mut s = format!("# Fit of `{}`\n\n", ctx.path);
    for l in header_lines(ctx) {
        s += &format!("{l}\n\n");
    }
    s += "## Parameters\n\n";
    s += "`stderr` is `stderr_abs` (the error bars taken as exact) times sqrt(s), and the 95% \
          interval is where the profile chi2 stays within the fit's `ci95_delta_chi2` = 3.84 s of \
          its minimum, with the same s = max(1, chi2/dof) (chi2/dof for unweighted data). \
          `> x` and `< x` are 95% bounds of parameters the data do not determine on the other \
          side.\n\n";
    let rows: Vec<Vec<String>> = param_rows(set)
        .into_iter()
        .map(|r| r.into_iter().map(|c| c.replace('|', "\\|")).collect())
        .collect();
    s += &md_table(&rows);
    s += "\n## Model comparison\n\n";
    s += &md_table(&comparison_rows(set));
    if let Some(p) = preferred_line(set) {
        s += &format!("\n**{p}**\n");
    }
    let corr = correlation_lines(set);
    if !corr.is_empty() {
        s += "\n## Correlations\n\n";
        for c in corr {
            s += &format!("- {c}\n");
        }
    }
    s += "\n## Warnings\n\n";
    let warnings = warning_lines(set);
    if warnings.is_empty() {
        s += "none\n";
    }
    for w in warnings {
        s += &format!("- {w}\n");
    }
    let notes = note_lines(set);
    if !notes.is_empty() {
        s += "\n## Notes\n\n";
        for n in notes {
            s += &format!("- {n}\n");
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_rounded_to_their_errors() {
        let s = Style::of(190.5451, Some(3.30196));
        assert_eq!(s.show(190.5451), "190.5");
        assert_eq!(s.show(3.30196), "3.3");
        let s = Style::of(4.022204e7, Some(1.326e5));
        assert_eq!(s.show(4.022204e7), "4.022e7");
        assert_eq!(s.show(1.326e5), "0.013e7");
        let s = Style::of(1.9817e-6, Some(3.43e-8));
        assert_eq!(s.show(1.9817e-6), "1.982e-6");
        // No error: four significant digits.
        assert_eq!(Style::of(0.43404, None).show(0.43404), "0.4340");
        assert_eq!(short(693.4012, 5), "693.40");
        assert_eq!(short(6e-128, 3), "6.00e-128");
    }
}
