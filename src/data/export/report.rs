//! The printed report of `restitution export`: the laws with their deviations, the constants per
//! pair, the recommendation and the friction.

use super::files::{Summary, sig};
use crate::data::fmt_num;
use crate::dem::law::{LawKind, SearchEnd};
use crate::fit::models::unit_after;
use std::fmt::Write as _;

/// The printed report: the laws with their deviations, per-pair constants, the recommendation.
pub fn report(s: &Summary) -> String {
    let tr = s.tr;
    let req = &tr.request;
    let mut o = String::new();
    let params: Vec<String> = req
        .curve
        .kind
        .params()
        .iter()
        .zip(&req.curve.params)
        .map(|(p, x)| format!("{} = {}{}", p.key, sig(*x, 5), unit_after(p.unit)))
        .collect();
    let _ = writeln!(
        o,
        "export of {}: model {} ({}), contact end {}",
        s.source,
        req.curve.kind.name(),
        params.join(", "),
        req.curve.rule.name()
    );
    let sizes: Vec<String> = req
        .scene
        .diameters_m
        .iter()
        .enumerate()
        .map(|(t, d)| format!("type {} = {} mm", t + 1, fmt_num(d * 1e3)))
        .collect();
    let _ = writeln!(
        o,
        "scene: {}{}",
        sizes.join(", "),
        if req.scene.wall { ", and walls" } else { "" }
    );
    match req.range {
        Some(r) => {
            let _ = writeln!(
                o,
                "speeds: {} to {} m/s, {} weight",
                fmt_num(r.lo_m_s),
                fmt_num(r.hi_m_s),
                req.weight.name()
            );
        }
        None => {
            let _ = writeln!(o, "speeds: any (the viscoelastic law is the fitted model)");
        }
    }
    let vm = &tr.viscoelastic;
    let _ = writeln!(
        o,
        "\nlaw            parameter                     largest deviation from the fitted e(v)"
    );
    if let Some(c) = &tr.constant {
        let dm = c.iter().map(|x| x.dev_mean).fold(0.0, f64::max);
        let dx = c.iter().map(|x| x.dev_minimax).fold(0.0, f64::max);
        let _ = writeln!(
            o,
            "constant e     one e per pair (below)        {} (weighted mean), {} (minimax)",
            sig(dm, 3),
            sig(dx, 3)
        );
    }
    if vm.exact {
        let _ = writeln!(
            o,
            "viscoelastic   eta = {:<22} 0 (the fitted model itself)",
            format!("{} kg/(s m)", sig(vm.eta_mean, 6))
        );
    } else {
        let _ = writeln!(
            o,
            "viscoelastic   eta = {:<22} {} (least squares); eta = {} gives {} (minimax)",
            format!("{} kg/(s m)", sig(vm.eta_mean, 5)),
            sig(vm.dev_mean, 3),
            sig(vm.eta_minimax, 5),
            sig(vm.dev_minimax, 3)
        );
        match vm.search_end {
            Some(SearchEnd::Lower) => {
                let _ = writeln!(
                    o,
                    "               (eta at the lower end of its search, kappa = 1e-7: the fitted \
                     e(v) is elastic to that level, and a smaller eta may be closer still)"
                );
            }
            Some(SearchEnd::Upper) => {
                let _ = writeln!(
                    o,
                    "               (eta at the upper end of its search, e ~ 1e-7 where least \
                     damped: a larger eta may be closer still)"
                );
            }
            None => {}
        }
    }
    if let Some(t) = &tr.table {
        let _ = writeln!(
            o,
            "table          {:<29} {} (linear in ln v)",
            format!("{} speeds", t.v_m_s.len()),
            sig(t.interpolation_dev, 3)
        );
    }
    if let Some(r) = &tr.recommendation {
        let _ = writeln!(
            o,
            "\nsimplest law within {}: {}",
            sig(r.tolerance, 3),
            match r.chosen {
                Some(LawKind::ConstantE) => "constant e (the minimax value per pair)".to_string(),
                Some(LawKind::Viscoelastic) => format!(
                    "the viscoelastic law (eta = {} kg/(s m), minimax)",
                    sig(vm.eta_minimax, 5)
                ),
                Some(LawKind::Table) => "the full model as a table".to_string(),
                None => "none (use a finer table: --table-points)".to_string(),
            }
        );
    }
    if let Some(c) = &tr.constant {
        let _ = writeln!(
            o,
            "\npair       e(lo)      e(hi)   e_mean  max_dev  e_minimax  max_dev  vm_dev{}",
            if s.constant_inputs.is_some() {
                "   LAMMPS cor  LAMMPS e if given e_mean"
            } else {
                ""
            }
        );
        for (p, (pair, c)) in tr.pairs.iter().zip(c).enumerate() {
            let extra = match s.constant_inputs {
                Some(inp) => format!(
                    "   {:>10}  {:>10}",
                    inp[p]
                        .lammps_cor
                        .map(|x| sig(x, 6))
                        .unwrap_or_else(|| "(none)".into()),
                    sig(inp[p].lammps_e_if_given_e, 6)
                ),
                None => String::new(),
            };
            let _ = writeln!(
                o,
                "{:<8} {:>8} {:>10} {:>8} {:>8} {:>10} {:>8} {:>7}{extra}",
                pair.label(),
                sig(c.e_lo, 4),
                sig(c.e_hi, 4),
                sig(c.e_mean, 4),
                sig(c.dev_mean, 2),
                sig(c.e_minimax, 4),
                sig(c.dev_minimax, 2),
                sig(vm.dev_mean_per_pair[p], 2),
            );
        }
    }
    if let Some(law) = s.lammps_law {
        let note = match law {
            super::lammps::LammpsLaw::Viscoelastic { note, .. }
            | super::lammps::LammpsLaw::Tsuji { note, .. } => note,
        };
        let _ = writeln!(
            o,
            "\nLAMMPS files (in.restitution, collide.in) carry {note}"
        );
    }
    if let Some(f) = s.friction {
        let _ = writeln!(
            o,
            "\nfriction: mu_0 = {}{} ({})",
            sig(f.mu0, 4),
            f.beta0
                .map(|b| format!(", beta_0 = {}", sig(b, 3)))
                .unwrap_or_default(),
            f.source
        );
    }
    if !s.files.is_empty() {
        let _ = writeln!(o, "\nwrote: {}", s.files.join(", "));
    }
    o
}
