//! The CSV reader every input schema goes through: one `csv::Reader` over the whole file, with
//! line numbers kept exact by our own count.
//!
//! The csv crate's own line counter is wrong after comment and blank lines, so each record's line
//! is found from its byte offset instead: csv reports the offset where it started looking for the
//! record (after the previous one), we skip what csv skips before a record (line terminators, and
//! comment lines starting with `#` in the first column), and count the line breaks (`\n`, `\r\n`
//! or a lone `\r`) before the record's first byte. A record that spans lines (a quoted field with
//! a line break in it) is reported at the line where it starts.
//!
//! Also skipped: lines that are blank or whose first non-blank character is `#`, although csv
//! parses them as records. If such a line opens a quote that csv carries onto the next lines, the
//! reader restarts on the following line, so that a comment can never swallow data.

use super::{DataError, DataFailure, shown};
use std::fs;
use std::path::Path;

/// The message of an empty cell where a number is required (a missing value: an empty field in
/// a file, NaN or None in a table the Python package writes).
pub const EMPTY_CELL: &str = "empty (a missing value): a number is required";

/// One data row and the 1-based line it came from; its fields are the table's
/// ([`Table::field`]).
#[derive(Debug, Clone)]
pub struct Row {
    pub line: usize,
    /// Index of its first field among the table's.
    first: usize,
}

/// A parsed CSV file: header names (trimmed) and data rows.
#[derive(Debug, Clone)]
pub struct Table {
    pub path: String,
    pub header_line: usize,
    pub headers: Vec<String>,
    pub rows: Vec<Row>,
    /// Every data field, trimmed, one after another (row by row), and where each ends in
    /// `text`: three allocations for the whole file, where a record per row cost three per row
    /// (more than csv's own parsing on 100 000 rows, and as much again to free them).
    text: String,
    ends: Vec<usize>,
}

/// Counts line breaks in `b` the way an editor numbers lines: `\n`, `\r\n` and a lone `\r`.
/// `prev_cr` says whether the byte before `b` was `\r` (so a leading `\n` completes a `\r\n`).
fn count_breaks(b: &[u8], prev_cr: bool) -> usize {
    // Only the terminators matter: each `\r` is a break, and each `\n` unless a `\r` is
    // right before it (SIMD search: a record's bytes are mostly not terminators).
    memchr::memchr2_iter(b'\n', b'\r', b)
        .filter(|&k| b[k] == b'\r' || !(if k == 0 { prev_cr } else { b[k - 1] == b'\r' }))
        .count()
}

/// The first byte of the record csv found by searching from `from`: past the line terminators and
/// the first-column `#` comment lines that csv skips before a record (a comment ends at `\n`).
fn record_start(b: &[u8], mut p: usize) -> usize {
    while p < b.len() {
        match b[p] {
            b'\n' | b'\r' => p += 1,
            b'#' => {
                p = match memchr::memchr(b'\n', &b[p..]) {
                    Some(k) => p + k + 1,
                    None => b.len(),
                }
            }
            _ => break,
        }
    }
    p
}

/// End of the physical line starting at `p` (index of its terminator) and start of the next.
fn line_end(b: &[u8], p: usize) -> (usize, usize) {
    match memchr::memchr2(b'\n', b'\r', &b[p..]) {
        None => (b.len(), b.len()),
        Some(k) => {
            let e = p + k;
            let next = if b[e] == b'\r' && b.get(e + 1) == Some(&b'\n') {
                e + 2
            } else {
                e + 1
            };
            (e, next)
        }
    }
}

fn reader(bytes: &[u8]) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .comment(Some(b'#'))
        .from_reader(bytes)
}

/// Field `j` of `rec`, trimmed, as text; an error names the line, the column and the bytes.
fn field_text(
    path: &str,
    line: usize,
    column: Option<&str>,
    j: usize,
    raw: &[u8],
) -> Result<String, DataError> {
    match std::str::from_utf8(raw) {
        Ok(s) => Ok(s.trim().to_string()),
        Err(e) => Err(not_utf8(path, line, column, j, raw, e)),
    }
}

/// The error for field `j`, whose bytes `raw` are not UTF-8.
fn not_utf8(
    path: &str,
    line: usize,
    column: Option<&str>,
    j: usize,
    raw: &[u8],
    e: std::str::Utf8Error,
) -> DataError {
    let bad = raw[e.valid_up_to()];
    DataError {
        path: path.to_string(),
        line: Some(line),
        column: Some(column.map_or_else(|| format!("field {}", j + 1), str::to_string)),
        kind: DataFailure::Format,
        message: format!(
            "'{}' is not UTF-8 text (byte 0x{bad:02X}): save the file as UTF-8",
            shown(String::from_utf8_lossy(raw).trim())
        ),
    }
}

impl Table {
    /// Reads and splits a CSV file. Fails on an unreadable file, a missing header, a row with a
    /// different number of fields than the header, text that is not UTF-8 (outside comments),
    /// or a file without data rows.
    pub fn read(path: &Path) -> Result<Table, DataError> {
        let shown = path.display().to_string();
        let bytes = fs::read(path).map_err(|e| DataError {
            path: shown.clone(),
            line: None,
            column: None,
            kind: DataFailure::Io,
            message: format!("cannot read: {e}"),
        })?;
        Table::parse_bytes(&shown, &bytes)
    }

    /// As [`Table::read`], from text already in memory (`path` is only used in messages).
    pub fn parse(path: &str, text: &str) -> Result<Table, DataError> {
        Table::parse_bytes(path, text.as_bytes())
    }

    /// As [`Table::read`], from bytes in memory (`path` is only used in messages).
    pub fn parse_bytes(path: &str, bytes: &[u8]) -> Result<Table, DataError> {
        let err = |line: Option<usize>, kind: DataFailure, message: String| DataError {
            path: path.to_string(),
            line,
            column: None,
            kind,
            message,
        };
        // A byte-order mark (as some spreadsheets write) is not part of the first header name.
        let bom = if bytes.starts_with(b"\xEF\xBB\xBF") {
            3
        } else {
            0
        };
        let mut header: Option<(usize, Vec<String>)> = None;
        let mut rows = Vec::new();
        let mut text = String::with_capacity(bytes.len());
        let mut ends = Vec::new();
        // Line breaks are counted incrementally: `line` is the line of byte `counted`.
        let (mut counted, mut line) = (0usize, 1usize);
        let mut base = bom;
        let mut rdr = reader(&bytes[base..]);
        let mut rec = csv::ByteRecord::new();
        loop {
            let from = rdr.position().byte() as usize + base;
            let more = rdr.read_byte_record(&mut rec).map_err(|e| {
                err(
                    Some(line),
                    DataFailure::Format,
                    format!("cannot parse: {e}"),
                )
            })?;
            if !more {
                break;
            }
            let start = record_start(bytes, from);
            line += count_breaks(
                &bytes[counted..start],
                counted > 0 && bytes[counted - 1] == b'\r',
            );
            counted = start;
            let (eol, next) = line_end(bytes, start);
            let first = bytes[start..eol].trim_ascii_start();
            if first.is_empty() || first[0] == b'#' {
                // A blank line, or a comment after leading blanks: not a record. If csv carried an
                // opened quote past this line, start again on the next line.
                let end = rdr.position().byte() as usize + base;
                if end > next {
                    base = next;
                    rdr = reader(&bytes[base..]);
                }
                continue;
            }
            match &header {
                None => {
                    let fields = (0..rec.len())
                        .map(|j| field_text(path, line, None, j, &rec[j]))
                        .collect::<Result<Vec<_>, _>>()?;
                    if let Some(dup) = fields
                        .iter()
                        .enumerate()
                        .find(|(j, f)| fields[..*j].contains(f))
                    {
                        return Err(err(
                            Some(line),
                            DataFailure::Schema,
                            format!("header names column '{}' twice", shown(dup.1)),
                        ));
                    }
                    header = Some((line, fields));
                }
                Some((_, h)) => {
                    if rec.len() != h.len() {
                        return Err(err(
                            Some(line),
                            DataFailure::Format,
                            format!("has {} fields, the header has {}", rec.len(), h.len()),
                        ));
                    }
                    let first = ends.len();
                    for j in 0..rec.len() {
                        match std::str::from_utf8(&rec[j]) {
                            Ok(field) => {
                                text.push_str(field.trim());
                                ends.push(text.len());
                            }
                            Err(e) => {
                                return Err(not_utf8(path, line, Some(&h[j]), j, &rec[j], e));
                            }
                        }
                    }
                    rows.push(Row { line, first });
                }
            }
        }
        let (header_line, headers) = header.ok_or_else(|| {
            err(
                None,
                DataFailure::Schema,
                "no header line (the file is empty)".into(),
            )
        })?;
        if rows.is_empty() {
            return Err(err(
                Some(header_line),
                DataFailure::Schema,
                "no data rows after the header".into(),
            ));
        }
        Ok(Table {
            path: path.to_string(),
            header_line,
            headers,
            rows,
            text,
            ends,
        })
    }

    /// The text of a cell, trimmed.
    pub fn field(&self, row: &Row, col: usize) -> &str {
        let k = row.first + col;
        let start = if k == 0 { 0 } else { self.ends[k - 1] };
        &self.text[start..self.ends[k]]
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
            kind: DataFailure::Schema,
            message: format!(
                "required column is missing (header has: {})",
                shown(&self.headers.join(","))
            ),
        })
    }

    /// An error about one cell.
    pub fn cell_error(&self, row: &Row, col: usize, message: impl Into<String>) -> DataError {
        DataError {
            path: self.path.clone(),
            line: Some(row.line),
            column: Some(self.headers[col].clone()),
            kind: DataFailure::Value,
            message: message.into(),
        }
    }

    /// The text of a cell as messages show it ([`shown`]).
    pub fn shown(&self, row: &Row, col: usize) -> String {
        shown(self.field(row, col))
    }

    /// A finite number from a cell ("inf" and "nan" are rejected; an empty cell is `EMPTY_CELL`).
    pub fn number(&self, row: &Row, col: usize) -> Result<f64, DataError> {
        let raw = self.field(row, col);
        let text = || self.shown(row, col);
        match raw.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            // "'' is not a number" read as if the reader had lost the value.
            Err(_) if raw.is_empty() => Err(self.cell_error(row, col, EMPTY_CELL)),
            Ok(_) => Err(self.cell_error(row, col, format!("'{}' is not a finite number", text()))),
            Err(_) if raw.contains('\n') => Err(self.cell_error(
                row,
                col,
                format!(
                    "'{}' is not a number: a quoted field runs over {} lines (is a closing quote missing?)",
                    text(),
                    raw.lines().count()
                ),
            )),
            Err(_) => Err(self.cell_error(row, col, format!("'{}' is not a number", text()))),
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
                format!(
                    "'{}' is out of range: expected {expected}",
                    self.shown(row, col)
                ),
            ))
        }
    }

    /// A positive number, or +infinity when the cell says `inf` (a flat wall's diameter).
    pub fn positive_or_inf(&self, row: &Row, col: usize) -> Result<f64, DataError> {
        let raw = self.field(row, col);
        if ["inf", "+inf", "infinity"]
            .iter()
            .any(|w| raw.eq_ignore_ascii_case(w))
        {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(text: &str) -> (usize, Vec<usize>) {
        let t = Table::parse("f.csv", text).unwrap();
        (t.header_line, t.rows.iter().map(|r| r.line).collect())
    }

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

    /// An empty cell says so: "'' is not a number" read as if the reader had lost the value.
    #[test]
    fn an_empty_cell_is_named_empty() {
        let t = Table::parse("f.csv", "d_mm,e\n1.0,\n2.0, \n").unwrap();
        let col = t.require("e").unwrap();
        for (row, line) in t.rows.iter().zip([2, 3]) {
            let err = t.number(row, col).unwrap_err();
            assert_eq!(
                err.to_string(),
                format!("f.csv:{line}: column 'e': empty (a missing value): a number is required")
            );
        }
    }

    #[test]
    fn line_numbers_after_every_kind_of_skipped_line() {
        // Indented comments, whitespace-only lines, runs of blank lines, a comment at the end.
        assert_eq!(
            lines("\n\n  # c\na,b\n   \n\t\n1,2\n#x\n\n\n3,4\n# end"),
            (4, vec![7, 11])
        );
        // CRLF and lone CR line ends count once each.
        assert_eq!(
            lines("# c\r\na,b\r\n\r\n1,2\r\n3,4\r5,6\n"),
            (2, vec![4, 5, 6])
        );
        // A quoted field with line breaks: the record is at the line where it starts, and the
        // lines it spans are counted for the next records.
        let t = Table::parse("f.csv", "id,v\n\"a\nb\n# not a comment\",1\n# c\n\"x\",2\n").unwrap();
        assert_eq!(t.header_line, 1);
        assert_eq!(t.rows[0].line, 2);
        assert_eq!(t.field(&t.rows[0], 0), "a\nb\n# not a comment");
        assert_eq!(t.rows[1].line, 6);
        // A comment that opens a quote does not swallow the following data.
        let t = Table::parse("f.csv", "a,b\n  # x,\"unbalanced\n1,2\n3,4\n").unwrap();
        assert_eq!(t.rows.len(), 2);
        assert_eq!(t.rows[0].line, 3);
        assert_eq!([t.field(&t.rows[0], 0), t.field(&t.rows[0], 1)], ["1", "2"]);
        assert_eq!(t.rows[1].line, 4);
        // Quotes, commas and doubled quotes in a field; a byte-order mark before the header.
        let t = Table::parse("f.csv", "\u{feff}id,v\n\"a, \"\"b\"\"\",1\n").unwrap();
        assert_eq!(t.headers, ["id", "v"]);
        assert_eq!(t.field(&t.rows[0], 0), "a, \"b\"");
    }

    #[test]
    fn line_numbers_agree_with_a_plain_count_on_many_lines() {
        // 1000 data lines with a comment or blank line after every 7th: each row's line is the
        // position of its text in the file, found by a plain search.
        let mut text = String::from("# head\nk,v\n");
        for i in 0..1000 {
            text += &format!("{i},{}\n", i * 2);
            if i % 7 == 0 {
                text += if i % 2 == 0 { "# note\n" } else { "\n" };
            }
        }
        let t = Table::parse("f.csv", &text).unwrap();
        let plain: Vec<usize> = text
            .lines()
            .enumerate()
            .filter(|(_, l)| l.chars().next().is_some_and(|c| c.is_ascii_digit()))
            .map(|(i, _)| i + 1)
            .collect();
        assert_eq!(t.rows.iter().map(|r| r.line).collect::<Vec<_>>(), plain);
    }

    #[test]
    fn not_utf8_is_an_error_with_line_and_column_but_comments_may_be_anything() {
        let bytes = b"# caf\xE9\nid,v\nok,1\nx\xFFy,2\n";
        let e = Table::parse_bytes("f.csv", bytes).unwrap_err();
        assert_eq!(e.line, Some(4));
        assert_eq!(e.column.as_deref(), Some("id"));
        assert!(e.message.contains("0xFF"), "{e}");
        let t = Table::parse_bytes("f.csv", b"# caf\xE9\nid,v\nok,1\n").unwrap();
        assert_eq!(t.rows[0].line, 3);
    }

    /// Each row's fields are its own (the table keeps every field in one text): empty ones,
    /// blanks trimmed, a skipped line between rows.
    #[test]
    fn every_row_reads_its_own_fields() {
        let t = Table::parse("f.csv", "a,b,c\n1, two ,\n\n,x,3.5\n  y ,,z\n").unwrap();
        let all: Vec<Vec<&str>> = t
            .rows
            .iter()
            .map(|r| (0..3).map(|c| t.field(r, c)).collect())
            .collect();
        assert_eq!(
            all,
            [["1", "two", ""], ["", "x", "3.5"], ["y", "", "z"]].map(|r| r.to_vec())
        );
        assert_eq!(t.rows.iter().map(|r| r.line).collect::<Vec<_>>(), [2, 4, 5]);
    }

    #[test]
    fn structural_errors() {
        assert!(Table::parse("f", "").is_err());
        assert!(Table::parse("f", "# only\n\n").is_err());
        assert!(
            Table::parse("f", "a,b\n")
                .unwrap_err()
                .message
                .contains("no data rows")
        );
        let e = Table::parse("f", "a,b\n# c\n1,2,3\n").unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(Table::parse("f", "a,a\n1,2\n").is_err());
        let t = Table::parse("f", "a,b\n1,nan\n").unwrap();
        assert!(t.number(&t.rows[0], 1).is_err());
        let e = t.require("c").unwrap_err();
        assert!(e.to_string().contains("column 'c'"), "{e}");
    }

    #[test]
    fn each_failure_has_its_kind() {
        let kind = |r: Result<Table, DataError>| r.unwrap_err().kind;
        let missing = Path::new("/nonexistent/restitution-test/f.csv");
        assert_eq!(kind(Table::read(missing)), DataFailure::Io);
        assert_eq!(
            kind(Table::parse_bytes("f", b"id\nx\xFF\n")),
            DataFailure::Format
        );
        assert_eq!(kind(Table::parse("f", "a,b\n1,2,3\n")), DataFailure::Format);
        assert_eq!(kind(Table::parse("f", "a,a\n1,2\n")), DataFailure::Schema);
        assert_eq!(kind(Table::parse("f", "a,b\n")), DataFailure::Schema);
        let t = Table::parse("f", "a,b\n1,x\n").unwrap();
        assert_eq!(t.require("c").unwrap_err().kind, DataFailure::Schema);
        assert_eq!(
            t.number(&t.rows[0], 1).unwrap_err().kind,
            DataFailure::Value
        );
        assert_eq!(DataFailure::Value.to_string(), "value");
    }
}
