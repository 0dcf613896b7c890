//! Valid CSV data as a sheet of text, and the mutations that make fuzz cases of it.

use rand::Rng;
use rand::rngs::StdRng;
use rand::seq::IndexedRandom;
use restitution::data::{CsvOut, Table};

/// Text that is not a plain finite number, or a number at the edges of f64.
pub const EXTREMES: &[&str] = &[
    "0",
    "-0",
    "-1",
    "-25.4",
    "1e-300",
    "-1e-300",
    "1e300",
    "-1e300",
    "5e-324",
    "2.2250738585072014e-308",
    "1.7976931348623157e308",
    "-1.7976931348623157e308",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "1e999",
    "",
    "abc",
    "0x10",
    "1_000",
    "1e-80",
    "1e80",
    "1e-7",
    "1e308",
    "+5",
    "1.5.2",
    "--3",
    "1e-20",
    "1e20",
];

/// Awkward ids: quotes, commas, line breaks, a leading `#`, non-ASCII.
pub const IDS: &[&str] = &[
    "a,b",
    "say \"hi\"",
    "two\nlines",
    "#3",
    "caf\u{e9}",
    "\"",
    ",",
    "x;y",
];

/// Marks a cell to be replaced by bytes that are not UTF-8 after serialising.
const NOT_UTF8: &str = "@@NOT_UTF8@@";
/// Marks a cell to be replaced by an unbalanced quote after serialising.
const OPEN_QUOTE: &str = "@@OPEN_QUOTE@@";

/// A CSV as header and rows of text, to mutate.
#[derive(Debug, Clone)]
pub struct Sheet {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
    pub comments: bool,
    pub crlf: bool,
    pub bom: bool,
    pub blank_lines: bool,
    pub latin1_comment: bool,
}

impl Sheet {
    pub fn parse(text: &str) -> Sheet {
        let t = Table::parse("base", text).expect("the base data are valid");
        let rows = t
            .rows
            .iter()
            .map(|r| {
                (0..t.headers.len())
                    .map(|c| t.field(r, c).to_string())
                    .collect()
            })
            .collect();
        Sheet {
            header: t.headers,
            rows,
            comments: false,
            crlf: false,
            bom: false,
            blank_lines: false,
            latin1_comment: false,
        }
    }

    pub fn col(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = CsvOut::new();
        if self.comments {
            out.comment("fuzz case, with a comment line");
        }
        out.record(&self.header);
        for (i, r) in self.rows.iter().enumerate() {
            out.record(r);
            if self.comments && i % 5 == 2 {
                out.comment("a comment between rows");
            }
        }
        let mut text = out.into_string();
        if self.blank_lines {
            text = text.replace('\n', "\n\n");
        }
        if self.crlf {
            text = text.replace('\n', "\r\n");
        }
        let mut bytes = Vec::new();
        if self.bom {
            bytes.extend_from_slice(b"\xEF\xBB\xBF");
        }
        if self.latin1_comment {
            bytes.extend_from_slice(b"# caf\xE9 (Latin-1)\n");
        }
        bytes.extend_from_slice(text.as_bytes());
        let bytes = replace(&bytes, NOT_UTF8.as_bytes(), b"1\xFF\xFE2");
        replace(&bytes, OPEN_QUOTE.as_bytes(), b"\"unbalanced")
    }
}

fn replace(hay: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(hay.len());
    let mut i = 0;
    while i < hay.len() {
        if hay[i..].starts_with(from) {
            out.extend_from_slice(to);
            i += from.len();
        } else {
            out.push(hay[i]);
            i += 1;
        }
    }
    out
}

/// One to three mutations of a valid sheet; returns their names.
pub fn mutate(sheet: &mut Sheet, rng: &mut StdRng, big_rows: bool) -> Vec<String> {
    let mut names = Vec::new();
    // A third of the cases keep the data valid (ids, comments, duplicates, perturbations), so
    // that results, not only errors, are checked.
    let benign = rng.random_bool(0.35);
    let k = rng.random_range(1..=3);
    for _ in 0..k {
        let ncol = sheet.header.len();
        let nrow = sheet.rows.len();
        if ncol == 0 {
            break;
        }
        let c = rng.random_range(0..ncol);
        let r = rng.random_range(0..nrow.max(1));
        let v = EXTREMES.choose(rng).expect("not empty").to_string();
        let what = if benign {
            *[53, 69, 72, 85, 95, 95].choose(rng).expect("not empty")
        } else {
            rng.random_range(0..100)
        };
        let name = match what {
            0..=24 => {
                if let Some(cell) = sheet.rows.get_mut(r).and_then(|row| row.get_mut(c)) {
                    *cell = v.clone();
                }
                format!("cell({}, {}) = {v:?}", r, sheet.header[c])
            }
            25..=39 => {
                for cell in sheet.rows.iter_mut().filter_map(|row| row.get_mut(c)) {
                    *cell = v.clone();
                }
                format!("column {} = {v:?}", sheet.header[c])
            }
            40..=47 => {
                let f: f64 = *[1e-300, 1e300, -1.0, 0.0, 1e-150, 1e150, 5e-324]
                    .choose(rng)
                    .expect("not empty");
                for cell in sheet.rows.iter_mut().filter_map(|row| row.get_mut(c)) {
                    if let Ok(x) = cell.parse::<f64>() {
                        *cell = format!("{}", x * f);
                    }
                }
                format!("column {} scaled by {f:e}", sheet.header[c])
            }
            48..=52 => {
                if let Some(first) = sheet.rows.first().cloned() {
                    sheet.rows.iter_mut().for_each(|row| *row = first.clone());
                }
                "every row the same".into()
            }
            53..=56 => {
                let extra: Vec<Vec<String>> = (0..nrow.min(20))
                    .map(|_| sheet.rows[rng.random_range(0..nrow)].clone())
                    .collect();
                sheet.rows.extend(extra);
                "duplicated rows".into()
            }
            57..=61 => {
                sheet.rows.truncate(1);
                "one row".into()
            }
            // (An earlier mutation may have left no rows to repeat.)
            62..=64 if big_rows && nrow > 0 => {
                let base = sheet.rows.clone();
                sheet.rows = (0..100_000).map(|i| base[i % base.len()].clone()).collect();
                "100 000 rows".into()
            }
            65..=68 => {
                if let Some(cell) = sheet.rows.get_mut(r).and_then(|row| row.get_mut(c)) {
                    *cell = NOT_UTF8.into();
                }
                format!("cell({}, {}) not UTF-8", r, sheet.header[c])
            }
            69..=71 => {
                sheet.latin1_comment = true;
                "Latin-1 comment".into()
            }
            72..=76 => {
                let col = sheet.col("collision").unwrap_or_else(|| {
                    sheet.header.insert(0, "id".into());
                    for row in &mut sheet.rows {
                        row.insert(0, String::new());
                    }
                    0
                });
                for (i, row) in sheet.rows.iter_mut().enumerate() {
                    if let Some(cell) = row.get_mut(col) {
                        *cell = format!("{}{i}", IDS[i % IDS.len()]);
                    }
                }
                "awkward ids".into()
            }
            77..=78 => {
                if let Some(cell) = sheet.rows.get_mut(r).and_then(|row| row.get_mut(c)) {
                    *cell = OPEN_QUOTE.into();
                }
                "unbalanced quote".into()
            }
            79..=80 => {
                let h = sheet.header.remove(c);
                for row in sheet.rows.iter_mut().filter(|row| c < row.len()) {
                    row.remove(c);
                }
                format!("column {h} dropped")
            }
            81 => {
                let h = sheet.header[c].clone();
                sheet.header[(c + 1) % ncol] = h.clone();
                format!("header names {h} twice")
            }
            82..=83 => {
                if let Some(row) = sheet.rows.get_mut(r) {
                    if rng.random_bool(0.5) {
                        row.push("1".into());
                    } else {
                        row.pop();
                    }
                }
                "a row with the wrong number of fields".into()
            }
            84 => {
                sheet.rows.clear();
                "header only".into()
            }
            85..=89 => {
                sheet.comments = true;
                sheet.blank_lines = rng.random_bool(0.5);
                sheet.crlf = rng.random_bool(0.5);
                sheet.bom = rng.random_bool(0.5);
                "comments, blank lines, CRLF, BOM".into()
            }
            _ => {
                // A number perturbed within its magnitude: still valid, a different data set.
                if let Some(cell) = sheet.rows.get_mut(r).and_then(|row| row.get_mut(c))
                    && let Ok(x) = cell.parse::<f64>()
                {
                    *cell = format!("{}", x * rng.random_range(0.5..1.5));
                }
                "a value perturbed".into()
            }
        };
        names.push(name);
    }
    names
}
