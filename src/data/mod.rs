//! CSV input with exact line numbers, validated numbers, and atomic output files.
//!
//! Every input schema of the toolkit (fit data, oblique collisions, tracks) is read through
//! [`Table`]: a header line, then rows; lines starting with `#` and blank lines are skipped but
//! counted, so an error names the line a user sees in an editor (the csv crate's own positions
//! miscount after comment and blank lines, so we split lines ourselves and let csv parse each).
//! Errors name the file, line, column and value: `data.csv:14: column 'e': '0,97' is not a number`.

pub mod frames;
pub mod images;
pub mod png;
pub mod tracks;

use std::fmt;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// An input error pointing at a place in a file.
#[derive(Debug, Clone, PartialEq)]
pub struct DataError {
    pub path: String,
    pub line: Option<usize>,
    pub column: Option<String>,
    pub message: String,
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(col) = &self.column {
            write!(f, ": column '{col}'")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for DataError {}

/// One data row and the 1-based line it came from.
#[derive(Debug, Clone)]
pub struct Row {
    pub line: usize,
    pub fields: Vec<String>,
}

/// A parsed CSV file: header names (trimmed) and data rows.
#[derive(Debug, Clone)]
pub struct Table {
    pub path: String,
    pub header_line: usize,
    pub headers: Vec<String>,
    pub rows: Vec<Row>,
}

fn parse_record(line: &str) -> Result<Vec<String>, String> {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(line.as_bytes());
    match rdr.records().next() {
        Some(Ok(rec)) => Ok(rec.iter().map(|f| f.trim().to_string()).collect()),
        Some(Err(e)) => Err(e.to_string()),
        None => Ok(Vec::new()),
    }
}

impl Table {
    /// Reads and splits a CSV file. Fails on an unreadable file, a missing header, a row with a
    /// different number of fields than the header, or a file without data rows.
    pub fn read(path: &Path) -> Result<Table, DataError> {
        let shown = path.display().to_string();
        let text = fs::read_to_string(path).map_err(|e| DataError {
            path: shown.clone(),
            line: None,
            column: None,
            message: format!("cannot read: {e}"),
        })?;
        Table::parse(&shown, &text)
    }

    /// As [`Table::read`], from text already in memory (`path` is only used in messages).
    pub fn parse(path: &str, text: &str) -> Result<Table, DataError> {
        let err = |line: Option<usize>, message: String| DataError {
            path: path.to_string(),
            line,
            column: None,
            message,
        };
        let mut header: Option<(usize, Vec<String>)> = None;
        let mut rows = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line_no = i + 1;
            let trimmed = raw.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            let fields = parse_record(raw).map_err(|m| err(Some(line_no), m))?;
            match &header {
                None => {
                    if let Some(dup) = fields
                        .iter()
                        .enumerate()
                        .find(|(j, f)| fields[..*j].contains(f))
                    {
                        return Err(err(
                            Some(line_no),
                            format!("header names column '{}' twice", dup.1),
                        ));
                    }
                    header = Some((line_no, fields));
                }
                Some((_, h)) => {
                    if fields.len() != h.len() {
                        return Err(err(
                            Some(line_no),
                            format!("has {} fields, the header has {}", fields.len(), h.len()),
                        ));
                    }
                    rows.push(Row {
                        line: line_no,
                        fields,
                    });
                }
            }
        }
        let (header_line, headers) =
            header.ok_or_else(|| err(None, "no header line (the file is empty)".into()))?;
        if rows.is_empty() {
            return Err(err(
                Some(header_line),
                "no data rows after the header".into(),
            ));
        }
        Ok(Table {
            path: path.to_string(),
            header_line,
            headers,
            rows,
        })
    }

    /// Index of a column, if present.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }

    /// Index of a required column, or an error naming it.
    pub fn require(&self, name: &str) -> Result<usize, DataError> {
        self.column(name).ok_or_else(|| DataError {
            path: self.path.clone(),
            line: Some(self.header_line),
            column: Some(name.to_string()),
            message: format!(
                "required column is missing (header has: {})",
                self.headers.join(",")
            ),
        })
    }

    /// An error about one cell.
    pub fn cell_error(&self, row: &Row, col: usize, message: impl Into<String>) -> DataError {
        DataError {
            path: self.path.clone(),
            line: Some(row.line),
            column: Some(self.headers[col].clone()),
            message: message.into(),
        }
    }

    /// A finite number from a cell ("inf" and "nan" are rejected).
    pub fn number(&self, row: &Row, col: usize) -> Result<f64, DataError> {
        let raw = &row.fields[col];
        match raw.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.cell_error(row, col, format!("'{raw}' is not a finite number"))),
            Err(_) => Err(self.cell_error(row, col, format!("'{raw}' is not a number"))),
        }
    }

    /// A finite number that must satisfy `ok`; `expected` describes the domain in the message.
    pub fn number_where(
        &self,
        row: &Row,
        col: usize,
        ok: impl Fn(f64) -> bool,
        expected: &str,
    ) -> Result<f64, DataError> {
        let v = self.number(row, col)?;
        if ok(v) {
            Ok(v)
        } else {
            Err(self.cell_error(
                row,
                col,
                format!("'{}' is out of range: expected {expected}", row.fields[col]),
            ))
        }
    }

    /// A positive number, or +infinity when the cell says `inf` (a flat wall's diameter).
    pub fn positive_or_inf(&self, row: &Row, col: usize) -> Result<f64, DataError> {
        let raw = row.fields[col].to_ascii_lowercase();
        if raw == "inf" || raw == "+inf" || raw == "infinity" {
            return Ok(f64::INFINITY);
        }
        self.number_where(
            row,
            col,
            |v| v > 0.0,
            "a number > 0, or inf for a flat wall",
        )
    }
}

/// Formats a number in shortest round-trip form (Rust's `{}`/`{:e}` print the fewest digits that
/// parse back to the same f64); exponent form outside [1e-4, 1e16).
pub fn fmt_num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Writes a file atomically: to a temporary name in the same directory, then rename, so that a
/// failure never leaves a half-written output behind. No fsync: the rename already guarantees
/// that a reader sees the old file or the whole new one; surviving a power cut is not worth the
/// 10-40 ms per file it costs on an ordinary disk.
pub fn write_atomic(path: &Path, contents: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into());
    let tmp: PathBuf = match dir {
        Some(d) => d.join(format!(".{name}.tmp{}", std::process::id())),
        None => PathBuf::from(format!(".{name}.tmp{}", std::process::id())),
    };
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(contents)?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Writes several files so that either all appear or none: each is written to a temporary name
/// first, and only when all have been written are they renamed into place (no fsync, as in
/// [`write_atomic`]).
pub fn write_all_atomic(files: &[(PathBuf, Vec<u8>)]) -> std::io::Result<()> {
    let mut temps = Vec::new();
    let pid = std::process::id();
    let result = (|| {
        for (path, contents) in files {
            let name = path.file_name().map(|n| n.to_string_lossy().to_string());
            let tmp = path.with_file_name(format!(".{}.tmp{pid}", name.unwrap_or_default()));
            temps.push(tmp.clone());
            let mut f = fs::File::create(&tmp)?;
            f.write_all(contents)?;
        }
        for ((path, _), tmp) in files.iter().zip(&temps) {
            fs::rename(tmp, path)?;
        }
        Ok(())
    })();
    if result.is_err() {
        for tmp in &temps {
            let _ = fs::remove_file(tmp);
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_numbers_count_comments_and_blanks() {
        let text = "# a comment\n\nd_mm,e\n# another\n1.0,0.5\n\n2.0,x\n";
        let t = Table::parse("f.csv", text).unwrap();
        assert_eq!(t.header_line, 3);
        assert_eq!(t.rows[0].line, 5);
        assert_eq!(t.rows[1].line, 7);
        let col = t.require("e").unwrap();
        let err = t.number(&t.rows[1], col).unwrap_err();
        assert_eq!(err.to_string(), "f.csv:7: column 'e': 'x' is not a number");
    }

    #[test]
    fn structural_errors() {
        assert!(Table::parse("f", "").is_err());
        assert!(
            Table::parse("f", "a,b\n")
                .unwrap_err()
                .message
                .contains("no data rows")
        );
        let e = Table::parse("f", "a,b\n1,2,3\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(Table::parse("f", "a,a\n1,2\n").is_err());
        let t = Table::parse("f", "a,b\n1,nan\n").unwrap();
        assert!(t.number(&t.rows[0], 1).is_err());
        let e = t.require("c").unwrap_err();
        assert!(e.to_string().contains("column 'c'"), "{e}");
    }

    #[test]
    fn shortest_round_trip() {
        for x in [0.1, 1e-8, 123456.789, 6.02e23, -3.5e-300, 0.97] {
            assert_eq!(fmt_num(x).parse::<f64>().unwrap(), x);
        }
        assert_eq!(fmt_num(0.1), "0.1");
        assert_eq!(fmt_num(1e-8), "1e-8");
    }
}
