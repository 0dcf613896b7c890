//! The LAMMPS round trip: runs `lmp` on collide.in over a ladder of time steps, averages the
//! phases, extrapolates to a zero step and compares with the toolkit (docs/physics.md §9).

use super::RunFailure;
use super::lammps::LammpsFiles;
use crate::data::fmt_num;
use crate::data::write_all_atomic;
use crate::dem::richardson_first_order;
use crate::dem::translate::{Collision, Translation};
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// One collision's check: LAMMPS's e (phase mean) at each rung of the step ladder, the
/// extrapolation to a zero step, and the toolkit's e.
#[derive(Debug, Clone, PartialEq)]
pub struct VerifyRow {
    pub pair: String,
    pub v_m_s: f64,
    pub e_toolkit: f64,
    /// (steps per shortest contact, mean e over the phases).
    pub rungs: Vec<(u32, f64)>,
    /// Richardson extrapolation from the two finest rungs.
    pub e_extrapolated: f64,
    /// How much the extrapolation moved between the last two pairs of rungs (an error estimate;
    /// 0 with only two rungs).
    pub extrapolation_change: f64,
}

impl VerifyRow {
    pub fn difference(&self) -> f64 {
        self.e_extrapolated - self.e_toolkit
    }
}

/// Runs `lmp` on DIR/collide.in with `-var steps N`, returning its standard output.
pub fn run_lmp(dir: &Path, steps: u32) -> Result<String, RunFailure> {
    let out = Command::new("lmp")
        .current_dir(dir)
        .args([
            "-nocite",
            "-log",
            "none",
            "-echo",
            "none",
            "-in",
            "collide.in",
        ])
        .args(["-var", "steps", &steps.to_string()])
        .output()
        .map_err(|e| {
            if e.kind() == std::io::ErrorKind::NotFound {
                RunFailure::NotOnPath
            } else {
                RunFailure::CannotStart(e.to_string())
            }
        })?;
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    if !out.status.success() {
        let error_line = text
            .lines()
            .chain(String::from_utf8_lossy(&out.stderr).lines())
            .find(|l| l.contains("ERROR"))
            .unwrap_or("no ERROR line")
            .to_string();
        return Err(RunFailure::Failed {
            dir: dir.display().to_string(),
            status: out.status.to_string(),
            error_line,
        });
    }
    Ok(text)
}

/// The phase means per (pair, speed) from collide.in's output, checking that every collision
/// ended (positive gap) and printed a number.
pub fn parse_collide_output(text: &str) -> Result<BTreeMap<(String, String), f64>, RunFailure> {
    let mut sums: BTreeMap<(String, String), (f64, usize)> = BTreeMap::new();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("restitution-e ") else {
            continue;
        };
        let kv: BTreeMap<&str, &str> = rest
            .split_whitespace()
            .filter_map(|w| w.split_once('='))
            .collect();
        let get = |k: &str| {
            kv.get(k).copied().ok_or_else(|| RunFailure::MissingField {
                field: k.to_string(),
                line: line.to_string(),
            })
        };
        let not_a_number = |what| RunFailure::NotANumber {
            what,
            line: line.to_string(),
        };
        let e: f64 = get("e")?.parse().map_err(|_| not_a_number("e"))?;
        let gap: f64 = get("gap_m")?.parse().map_err(|_| not_a_number("gap"))?;
        if !e.is_finite() {
            return Err(RunFailure::NonFiniteE {
                e,
                line: line.to_string(),
            });
        }
        if gap.is_nan() || gap <= 0.0 {
            return Err(RunFailure::NotEnded {
                gap_m: gap,
                line: line.to_string(),
            });
        }
        let entry = sums
            .entry((get("pair")?.to_string(), get("v_m_s")?.to_string()))
            .or_insert((0.0, 0));
        entry.0 += e;
        entry.1 += 1;
    }
    if sums.is_empty() {
        return Err(RunFailure::NoOutput);
    }
    Ok(sums
        .into_iter()
        .map(|(k, (s, n))| (k, s / n as f64))
        .collect())
}

/// The round trip: runs collide.in at every rung of `ladder` (steps per shortest contact, each
/// twice the previous) and compares the extrapolated e with the toolkit's.
pub fn verify(
    dir: &Path,
    tr: &Translation,
    collisions: &[Collision],
    ladder: &[u32],
) -> Result<Vec<VerifyRow>, RunFailure> {
    if ladder.len() < 2 || ladder.windows(2).any(|w| w[1] != 2 * w[0]) {
        return Err(RunFailure::Ladder);
    }
    let mut runs = Vec::new();
    for &n in ladder {
        runs.push((n, parse_collide_output(&run_lmp(dir, n)?)?));
    }
    let mut rows = Vec::new();
    for col in collisions {
        let key = (tr.pairs[col.pair].label(), fmt_num(col.v_m_s));
        let mut rungs = Vec::new();
        for (n, means) in &runs {
            let e = means
                .get(&key)
                .ok_or_else(|| RunFailure::MissingCollision {
                    pair: key.0.clone(),
                    v_m_s: key.1.clone(),
                })?;
            rungs.push((*n, *e));
        }
        let k = rungs.len();
        let last = richardson_first_order(rungs[k - 2].1, rungs[k - 1].1);
        let change = if k >= 3 {
            (last - richardson_first_order(rungs[k - 3].1, rungs[k - 2].1)).abs()
        } else {
            0.0
        };
        rows.push(VerifyRow {
            pair: key.0,
            v_m_s: col.v_m_s,
            e_toolkit: col.e,
            rungs,
            e_extrapolated: last,
            extrapolation_change: change,
        });
    }
    Ok(rows)
}

/// [`verify`] in a private temporary directory that is removed afterwards, so that a
/// verification leaves nothing behind (the caller writes its own outputs only when it passes).
pub fn verify_files(
    tr: &Translation,
    lf: &LammpsFiles,
    ladder: &[u32],
) -> Result<Vec<VerifyRow>, RunFailure> {
    // Unique per process and call: verifications may run concurrently (threads, tests).
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "restitution-verify-{}-{}",
        std::process::id(),
        CALLS.fetch_add(1, Ordering::SeqCst)
    ));
    let scratch_failure = |action, e: std::io::Error| RunFailure::Scratch {
        dir: dir.display().to_string(),
        action,
        reason: e.to_string(),
    };
    std::fs::create_dir_all(&dir).map_err(|e| scratch_failure("create the directory", e))?;
    let scratch = [
        (
            dir.join("in.restitution"),
            lf.in_restitution.clone().into_bytes(),
        ),
        (dir.join("collide.in"), lf.collide_in.clone().into_bytes()),
    ];
    let result = write_all_atomic(&scratch)
        .map_err(|e| scratch_failure("write", e))
        .and_then(|_| verify(&dir, tr, &lf.collisions, ladder));
    let _ = std::fs::remove_dir_all(&dir);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collide_output_is_averaged_and_checked() {
        let ok = "noise\nrestitution-e pair=1-2 v_m_s=2 phase=0 e=0.5 gap_m=1e-3\n\
                  restitution-e pair=1-2 v_m_s=2 phase=1 e=0.7 gap_m=2e-3\n\
                  restitution-e-mean pair=1-2 v_m_s=2 e=0.6 toolkit_e=0.6\n";
        let m = parse_collide_output(ok).unwrap();
        assert_eq!(m[&("1-2".to_string(), "2".to_string())], 0.6);
        let bad = [
            "restitution-e pair=1-1 v_m_s=2 phase=0 e=0.5 gap_m=-1e-6",
            "restitution-e pair=1-1 v_m_s=2 phase=0 e=nan gap_m=1e-6",
            "restitution-e pair=1-1 v_m_s=2 phase=0 e=x gap_m=1e-6",
            "restitution-e pair=1-1 v_m_s=2 phase=0 gap_m=1e-6",
            "nothing here",
        ]
        .map(|text| parse_collide_output(text).unwrap_err());
        assert!(matches!(&bad[0], RunFailure::NotEnded { gap_m, .. } if *gap_m == -1e-6));
        assert!(matches!(&bad[1], RunFailure::NonFiniteE { e, .. } if e.is_nan()));
        assert!(matches!(&bad[2], RunFailure::NotANumber { what: "e", .. }));
        assert!(matches!(&bad[3], RunFailure::MissingField { field, .. } if field == "e"));
        assert_eq!(bad[4], RunFailure::NoOutput);
    }
}
