//! The I/O layer: CSV input with exact line numbers, validated numbers, CSV output through
//! `csv::Writer`, atomic output files, and the file schemas (fit data, tracks, oblique
//! collisions).
//!
//! Every input schema of the toolkit (fit data, oblique collisions, tracks) is read through
//! [`Table`]: a header line, then rows; lines starting with `#` and blank lines are skipped but
//! counted, so an error names the line a user sees in an editor (see `table.rs` for how the
//! lines are counted: the csv crate's own count is wrong after comment and blank lines).
//! Errors name the file, line, column and value: `data.csv:14: column 'e': '0,97' is not a number`.
//! Every CSV the toolkit writes goes through [`CsvOut`] (quoting by `csv::Writer`), with numbers
//! in shortest round-trip form ([`fmt_num`]), and every output file through [`write_atomic`] or
//! [`write_all_atomic`].

pub mod export;
pub mod fit_input;
pub mod frames;
pub mod images;
pub mod png;
pub mod report;
mod table;
pub mod tracks;
pub mod walton;
mod write;

pub use table::{Row, Table};
pub use write::{CsvOut, write_all_atomic, write_atomic};

use std::fmt;

/// How a message names an argument: `--v-range` on the command line, `v_range` in Python.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArgStyle {
    Flags,
    Keywords,
}

impl ArgStyle {
    /// The argument `key` (snake_case) as the user typed it.
    pub fn name(self, key: &str) -> String {
        match self {
            ArgStyle::Flags => format!("--{}", key.replace('_', "-")),
            ArgStyle::Keywords => key.to_string(),
        }
    }
}

/// An input error pointing at a place in a file, with the kind of failure as a field.
#[derive(Debug, Clone, PartialEq)]
pub struct DataError {
    pub path: String,
    pub line: Option<usize>,
    pub column: Option<String>,
    pub kind: DataFailure,
    pub message: String,
}

/// The kinds of [`DataError`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr, strum::Display)]
#[strum(serialize_all = "snake_case")]
pub enum DataFailure {
    /// The file or directory could not be read or written (the system's reason in the message).
    Io,
    /// The bytes are not the format: CSV structure, text that is not UTF-8, JSON syntax, an
    /// image that does not decode.
    Format,
    /// A column, field or file is missing, duplicated or empty.
    Schema,
    /// A value is not a number, is out of its range, or contradicts another.
    Value,
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

/// A cell's text as an error message shows it: on one line (line breaks and other control
/// characters escaped) and at most 40 characters (then `...`), so that one bad cell, however
/// long, is still one line of message.
pub fn shown(raw: &str) -> String {
    let mut out = String::new();
    for (i, c) in raw.chars().enumerate() {
        if i == 40 {
            out += "...";
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Formats a number in shortest round-trip form (Rust's `{}`/`{:e}` print the fewest digits that
/// parse back to the same f64); exponent form outside [1e-4, 1e16).
pub fn fmt_num(x: f64) -> String {
    crate::error::Num(x).to_string()
}

/// A number in a table's fixed-decimals column: `decimals` decimals, or exponent form (four
/// significant digits) from 1e7 on, where fixed decimals would print up to 300 digits (an absurd
/// `--s-subpixels 1e300` had made `kinematics` print a 300-digit e_eq8).
pub fn fixed(x: f64, decimals: usize) -> String {
    if x.is_finite() && x.abs() >= 1e7 {
        format!("{x:.3e}")
    } else {
        format!("{x:.decimals$}")
    }
}

/// A number for human eyes: 10 significant digits, exponent form when very small or large.
pub fn readable(x: f64) -> String {
    significant(x, 10)
}

/// `x` to `digits` significant digits (at least 1), trailing zeros dropped; exponent form
/// outside [1e-3, 1e7).
pub fn significant(x: f64, digits: usize) -> String {
    let a = x.abs();
    let digits = digits.max(1);
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e7).contains(&a) {
        let decimals = (digits as i32 - 1 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.*e}", digits - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_decimals_until_the_digits_run_away() {
        assert_eq!(fixed(0.89484, 4), "0.8948");
        assert_eq!(fixed(-1.5, 3), "-1.500");
        assert_eq!(fixed(9_999_999.0, 1), "9999999.0");
        assert_eq!(fixed(1e7, 1), "1.000e7");
        assert_eq!(fixed(-5.841417919e300, 4), "-5.841e300");
        assert_eq!(fixed(f64::NAN, 3), "NaN");
    }

    #[test]
    fn shortest_round_trip() {
        for x in [0.1, 1e-8, 123456.789, 6.02e23, -3.5e-300, 0.97] {
            assert_eq!(fmt_num(x).parse::<f64>().unwrap(), x);
        }
        assert_eq!(fmt_num(0.1), "0.1");
        assert_eq!(fmt_num(1e-8), "1e-8");
        // Subnormals and the ends of f64 too.
        for x in [5e-324, -2.2250738585072014e-308, f64::MAX, f64::MIN, -0.0] {
            assert_eq!(fmt_num(x).parse::<f64>().unwrap().to_bits(), x.to_bits());
        }
    }

    #[test]
    fn shown_text_is_one_short_line() {
        assert_eq!(shown("0,97"), "0,97");
        assert_eq!(shown("a\nb\r\t"), "a\\nb\\r\\t");
        let long = "x".repeat(100);
        assert_eq!(shown(&long), format!("{}...", "x".repeat(40)));
    }
}
