//! The input schema of `restitution fit`: a CSV of measured e against normal impact speed.
//!
//! Columns, in any order (others are ignored): `d_mm` (required), `v_n_m_s` (required), `e`
//! (required), `e_err` (optional, absolute one-sigma error of e), `v_err_m_s` (optional, the
//! speed error Delta v; used as sigma_e = 2 e Delta v / v_n, the paper's error model below Fig. 7,
//! when `e_err` is absent), `d2_mm` (optional second diameter; `inf` for a flat wall; absent
//! means identical spheres). Lines starting with `#` and blank lines are skipped; errors name the
//! file, line, column and value ([`Table`] counts the lines itself).
//!
//! Suspicious values are warnings, one line per kind with the first occurrence and a count:
//! e > 1 (possible within the errors of a real measurement, so such rows are kept) and a
//! diameter below 0.1 mm (probably metres). `strict` turns them into errors.

use super::{DataError, DataFailure, Row, Table};
use crate::contact::Material;
use crate::error::Num;
use crate::fit::dataset::{E_ERR_MAX, E_ERR_MIN, FitData, Observation};
use crate::fit::sums;
use std::path::Path;

/// Where the errors of e came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorSource {
    /// The `e_err` column.
    EErr,
    /// The `v_err_m_s` column through sigma_e = 2 e v_err / v_n.
    VErr,
    /// No error columns: an unweighted fit.
    None,
}

impl ErrorSource {
    pub fn describe(self) -> &'static str {
        match self {
            ErrorSource::EErr => "e_err",
            ErrorSource::VErr => "v_err_m_s (sigma_e = 2 e v_err / v_n)",
            ErrorSource::None => "none (unweighted fit)",
        }
    }
}

/// A parsed fit input.
#[derive(Debug, Clone)]
pub struct FitInput {
    pub path: String,
    pub data: FitData,
    /// The line of each observation in the file.
    pub lines: Vec<usize>,
    pub error_source: ErrorSource,
    /// Suspicious values, one per kind (first occurrence; the message counts the others).
    pub warnings: Vec<DataError>,
}

/// Reads and validates a fit input file.
pub fn read_fit_csv(path: &Path, material: Material, strict: bool) -> Result<FitInput, DataError> {
    let table = Table::read(path)?;
    from_table(&table, material, strict)
}

/// As [`read_fit_csv`], from text in memory (`name` is used in messages).
pub fn parse_fit_csv(
    name: &str,
    text: &str,
    material: Material,
    strict: bool,
) -> Result<FitInput, DataError> {
    let table = Table::parse(name, text)?;
    from_table(&table, material, strict)
}

/// The observations of some consecutive rows, what they raised, and the error that stopped
/// them (if one did).
struct Part {
    obs: Vec<Observation>,
    tiny: Suspicion,
    above_one: Suspicion,
    error: Option<DataError>,
}

/// A suspicious value seen in some rows: the first one and how many.
struct Suspicion {
    first: Option<DataError>,
    count: usize,
}

impl Suspicion {
    fn new() -> Self {
        Suspicion {
            first: None,
            count: 0,
        }
    }
    /// One more row; its message is made only for the first (a file of 100 000 rows may have
    /// thousands of them).
    fn note(&mut self, err: impl FnOnce() -> DataError) {
        self.count += 1;
        if self.first.is_none() {
            self.first = Some(err());
        }
    }
    /// The rows of `later` (after these) too.
    fn join(&mut self, later: Suspicion) {
        self.count += later.count;
        if self.first.is_none() {
            self.first = later.first;
        }
    }
    fn finish(self) -> Option<DataError> {
        self.first.map(|mut e| {
            if self.count > 1 {
                e.message += &format!(" (and {} more rows like it)", self.count - 1);
            }
            e
        })
    }
}

fn from_table(table: &Table, material: Material, strict: bool) -> Result<FitInput, DataError> {
    let c_d = table.require("d_mm")?;
    let c_v = table.require("v_n_m_s")?;
    let c_e = table.require("e")?;
    let c_eerr = table.column("e_err");
    let c_verr = table.column("v_err_m_s");
    let c_d2 = table.column("d2_mm");
    let error_source = match (c_eerr, c_verr) {
        (Some(_), _) => ErrorSource::EErr,
        (None, Some(_)) => ErrorSource::VErr,
        (None, None) => ErrorSource::None,
    };
    let strict_or = |s: &mut Suspicion, err: &dyn Fn() -> DataError| -> Result<(), DataError> {
        if strict {
            let mut err = err();
            err.message += " (an error with --strict)";
            Err(err)
        } else {
            s.note(err);
            Ok(())
        }
    };
    // A diameter below 0.1 mm in column `c` (named `key`).
    let in_metres = |tiny: &mut Suspicion, row: &Row, c: usize, key: &str| {
        strict_or(tiny, &|| {
            let msg = format!(
                "'{}' is below 0.1 mm: is the diameter in metres? ({key} is millimetres)",
                table.shown(row, c)
            );
            table.cell_error(row, c, msg)
        })
    };
    let observe = |row: &Row, tiny: &mut Suspicion, above_one: &mut Suspicion| {
        let d_mm = table.number_where(row, c_d, |x| x > 0.0, "a diameter > 0 (mm)")?;
        if d_mm < 0.1 {
            in_metres(tiny, row, c_d, "d_mm")?;
        }
        let d2_mm = match c_d2 {
            Some(c) => {
                let d2 = table.positive_or_inf(row, c)?;
                if d2 < 0.1 {
                    in_metres(tiny, row, c, "d2_mm")?;
                }
                Some(d2)
            }
            None => None,
        };
        let v = table.number_where(row, c_v, |x| x > 0.0, "a speed > 0 (m/s)")?;
        let e = table.number_where(row, c_e, |x| x >= 0.0, "e >= 0")?;
        if e > 1.0 {
            strict_or(above_one, &|| {
                let msg = format!(
                    "'{}' is above 1 (kept: possible within the errors of a measurement)",
                    table.shown(row, c_e)
                );
                table.cell_error(row, c_e, msg)
            })?;
        }
        let e_err = match (c_eerr, c_verr) {
            (Some(c), _) => Some(table.number_where(
                row,
                c,
                |x| (E_ERR_MIN..=E_ERR_MAX).contains(&x),
                "an error from 5e-11 (1000 times the accuracy e is computed to) to 1e100 (beyond, \
                 its weight 1/e_err^2 underflows)",
            )?),
            (None, Some(c)) => {
                let dv = table.number_where(row, c, |x| x > 0.0, "a speed error > 0 (m/s)")?;
                let s = 2.0 * e * dv / v;
                if !(E_ERR_MIN..=E_ERR_MAX).contains(&s) {
                    return Err(table.cell_error(
                        row,
                        c_e,
                        format!(
                            "'{}' gives sigma_e = 2 e v_err / v_n = {}{}: give an e_err column",
                            table.shown(row, c_e),
                            Num(s),
                            if s.is_finite() && s > E_ERR_MAX {
                                ", above 1e100 (its weight 1/sigma_e^2 would underflow)"
                            } else if s.is_finite() && s > 0.0 {
                                ", below 5e-11 (1000 times the accuracy e is computed to)"
                            } else {
                                ""
                            }
                        ),
                    ));
                }
                Some(s)
            }
            (None, None) => None,
        };
        Ok(Observation {
            d_mm,
            d2_mm,
            v_n_m_s: v,
            e,
            e_err,
        })
    };
    // Rows in order, up to the first error (a part of the file, or all of it).
    let part = |rows: &[Row]| {
        let mut p = Part {
            obs: Vec::with_capacity(rows.len()),
            tiny: Suspicion::new(),
            above_one: Suspicion::new(),
            error: None,
        };
        for row in rows {
            match observe(row, &mut p.tiny, &mut p.above_one) {
                Ok(o) => p.obs.push(o),
                Err(e) => {
                    p.error = Some(e);
                    break;
                }
            }
        }
        p
    };
    // Large files in parts on all cores (the fit's start is serial), joined in row order: the
    // first error in the file, each suspicion's first row and count, as row by row.
    let parts = if sums::is_large(table.rows.len()) {
        use rayon::prelude::*;
        table.rows.par_chunks(sums::CHUNK).map(part).collect()
    } else {
        vec![part(&table.rows)]
    };
    let (mut tiny, mut above_one) = (Suspicion::new(), Suspicion::new());
    let mut obs = Vec::with_capacity(table.rows.len());
    for p in parts {
        obs.extend(p.obs);
        tiny.join(p.tiny);
        above_one.join(p.above_one);
        if let Some(e) = p.error {
            return Err(e);
        }
    }
    let lines = table.rows.iter().map(|r| r.line).collect();
    let data = FitData::new(material, obs).map_err(|e| DataError {
        path: table.path.clone(),
        line: None,
        column: None,
        kind: DataFailure::Value,
        message: e.to_string(),
    })?;
    let warnings = [tiny.finish(), above_one.finish()]
        .into_iter()
        .flatten()
        .collect();
    Ok(FitInput {
        path: table.path.clone(),
        data,
        lines,
        error_source,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nylon() -> Material {
        Material::preset("nylon").unwrap()
    }

    /// A large file is converted in parts on all cores, with the answers of a row by row
    /// pass: every row in order, the first error (not one from a later part), each suspicion's
    /// first row and count across the parts, and under --strict the first suspicious row.
    #[test]
    fn large_files_read_as_row_by_row() {
        let n = sums::PARALLEL_MIN_POINTS + 2 * sums::CHUNK + 5;
        let text = |bad: &[usize]| {
            let mut t = String::from("d_mm,v_n_m_s,e\n");
            for i in 0..n {
                let e = match i {
                    _ if bad.contains(&i) => "x".to_string(),
                    100 | 5000 | 19_000 => "1.25".to_string(),
                    _ => format!("0.{}", 5 + i % 4),
                };
                t += &format!("10,{},{e}\n", 1.0 + i as f64 * 1e-4);
            }
            t
        };
        // Line of row i: the header is line 1.
        let line = |i: usize| i + 2;
        let inp = parse_fit_csv("f.csv", &text(&[]), nylon(), false).unwrap();
        assert_eq!(inp.data.len(), n);
        assert_eq!(inp.lines, (0..n).map(line).collect::<Vec<_>>());
        assert!((0..n).all(|i| inp.data.obs[i].v_n_m_s == 1.0 + i as f64 * 1e-4));
        assert_eq!(inp.warnings.len(), 1);
        assert_eq!(
            inp.warnings[0].to_string(),
            format!(
                "f.csv:{}: column 'e': '1.25' is above 1 (kept: possible within the errors of \
                 a measurement) (and 2 more rows like it)",
                line(100)
            )
        );
        // Errors in two parts: the earlier one.
        let first = sums::PARALLEL_MIN_POINTS + 3;
        let bad = [first + sums::CHUNK, first];
        let e = parse_fit_csv("f.csv", &text(&bad), nylon(), false).unwrap_err();
        assert_eq!(e.line, Some(line(first)), "{e}");
        // --strict: the first row above 1, before either error.
        let e = parse_fit_csv("f.csv", &text(&bad), nylon(), true).unwrap_err();
        assert_eq!(e.line, Some(line(100)), "{e}");
        assert!(e.to_string().ends_with("(an error with --strict)"), "{e}");
    }

    #[test]
    fn columns_in_any_order_and_the_papers_error_model() {
        let text =
            "# c\nextra,e,v_n_m_s,v_err_m_s,d_mm\nx,0.9,2.0,0.04,12.7\n\ny,1.02,1.0,0.04,6.35\n";
        let inp = parse_fit_csv("f.csv", text, nylon(), false).unwrap();
        assert_eq!(inp.lines, vec![3, 5]);
        assert_eq!(inp.error_source, ErrorSource::VErr);
        // sigma_e = 2 e Delta v / v_n.
        assert!((inp.data.obs[0].e_err.unwrap() - 2.0 * 0.9 * 0.04 / 2.0).abs() < 1e-15);
        assert_eq!(inp.warnings.len(), 1);
        assert_eq!(
            inp.warnings[0].to_string(),
            "f.csv:5: column 'e': '1.02' is above 1 (kept: possible within the errors of a measurement)"
        );
        let err = parse_fit_csv("f.csv", text, nylon(), true).unwrap_err();
        assert_eq!(err.line, Some(5));
        assert!(err.to_string().contains("--strict"), "{err}");
    }

    #[test]
    fn errors_outside_the_accepted_range_name_their_cell() {
        // Given, and derived from v_err for an e of 1e-20: each below 5e-11.
        let text = "d_mm,v_n_m_s,e,e_err\n12.7,1.0,0.9,0.01\n12.7,2.0,0.8,1e-12\n";
        let err = parse_fit_csv("f.csv", text, nylon(), false).unwrap_err();
        assert_eq!(
            err.to_string(),
            "f.csv:3: column 'e_err': '1e-12' is out of range: expected an error from 5e-11 \
             (1000 times the accuracy e is computed to) to 1e100 (beyond, its weight 1/e_err^2 \
             underflows)"
        );
        let text = "d_mm,v_n_m_s,e,v_err_m_s\n12.7,1.0,0.9,0.04\n12.7,1.0,1e-20,0.5\n";
        let err = parse_fit_csv("f.csv", text, nylon(), false).unwrap_err();
        assert_eq!(
            err.to_string(),
            "f.csv:3: column 'e': '1e-20' gives sigma_e = 2 e v_err / v_n = 1e-20, below 5e-11 \
             (1000 times the accuracy e is computed to): give an e_err column"
        );
        // At the floor and the ceiling (the messages quote them): accepted.
        assert_eq!((E_ERR_MIN, E_ERR_MAX), (5e-11, 1e100));
        let text =
            "d_mm,v_n_m_s,e,e_err\n12.7,1.0,0.9,0.01\n12.7,2.0,0.8,5e-11\n12.7,3.0,0.8,1e100\n";
        assert!(parse_fit_csv("f.csv", text, nylon(), false).is_ok());
        // Above the ceiling, given or derived (fuzzed `fit`, seed 604, case 1309: e = 1e300).
        let text = "d_mm,v_n_m_s,e,e_err\n12.7,1.0,0.9,0.01\n12.7,2.0,0.8,2e100\n";
        let err = parse_fit_csv("f.csv", text, nylon(), false).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("f.csv:3: column 'e_err': '2e100' is out of range"),
            "{err}"
        );
        let text = "d_mm,v_n_m_s,e,v_err_m_s\n12.7,1.0,0.9,0.04\n12.7,0.651,1e300,0.0362\n";
        let err = parse_fit_csv("f.csv", text, nylon(), false).unwrap_err();
        assert_eq!(
            err.to_string(),
            "f.csv:3: column 'e': '1e300' gives sigma_e = 2 e v_err / v_n = 1.1121351766513058e299, \
             above 1e100 (its weight 1/sigma_e^2 would underflow): give an e_err column"
        );
    }

    #[test]
    fn wall_and_unweighted() {
        let text =
            "d_mm,d2_mm,v_n_m_s,e\n12.7,inf,1.0,0.95\n12.7,25.4,1.0,0.95\n0.0127,inf,1,0.9\n";
        let inp = parse_fit_csv("w.csv", text, nylon(), false).unwrap();
        assert_eq!(inp.error_source, ErrorSource::None);
        assert!(!inp.data.weighted);
        assert_eq!(inp.data.obs[0].d2_mm, Some(f64::INFINITY));
        assert_eq!(inp.warnings.len(), 1);
        assert!(
            inp.warnings[0]
                .to_string()
                .starts_with("w.csv:4: column 'd_mm'")
        );
    }
}
