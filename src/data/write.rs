//! Output: CSV text through `csv::Writer`, and files written all or nothing.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// CSV text built with `csv::Writer` (fields with a comma, quote or line break are quoted), plus
/// `#` comment lines, which the toolkit's reader skips.
///
/// A first field that starts with `#` (after blanks) would read back as a comment line, so such
/// a record is written with every field quoted. The reader trims blanks around fields, so text
/// with leading or trailing blanks does not round-trip; nothing else is lost.
pub struct CsvOut {
    w: csv::Writer<Vec<u8>>,
}

impl Default for CsvOut {
    fn default() -> Self {
        Self::new()
    }
}

const IN_MEMORY: &str = "writing CSV into memory cannot fail";

fn writer(buf: Vec<u8>, style: csv::QuoteStyle) -> csv::Writer<Vec<u8>> {
    csv::WriterBuilder::new()
        .flexible(true)
        .quote_style(style)
        .from_writer(buf)
}

impl CsvOut {
    pub fn new() -> Self {
        CsvOut {
            w: writer(Vec::new(), csv::QuoteStyle::Necessary),
        }
    }

    /// Takes the bytes written so far out of the writer (to append to them by other means).
    fn take(&mut self) -> Vec<u8> {
        let w = std::mem::replace(&mut self.w, writer(Vec::new(), csv::QuoteStyle::Necessary));
        w.into_inner().expect(IN_MEMORY)
    }

    /// A `# text` line; line breaks in `text` become spaces, so the comment stays one line.
    pub fn comment(&mut self, text: &str) {
        let mut out = self.take();
        out.extend_from_slice(b"# ");
        out.extend(text.bytes().map(|b| match b {
            b'\n' | b'\r' => b' ',
            b => b,
        }));
        out.push(b'\n');
        self.w = writer(out, csv::QuoteStyle::Necessary);
    }

    /// One record.
    pub fn record<I, T>(&mut self, fields: I)
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        let fields: Vec<T> = fields.into_iter().collect();
        let first = fields.first().map(|f| f.as_ref().trim_ascii_start());
        if first.is_some_and(|f| f.first() == Some(&b'#')) {
            let mut quoted = writer(self.take(), csv::QuoteStyle::Always);
            quoted.write_record(&fields).expect(IN_MEMORY);
            let out = quoted.into_inner().expect(IN_MEMORY);
            self.w = writer(out, csv::QuoteStyle::Necessary);
        } else {
            self.w.write_record(&fields).expect(IN_MEMORY);
        }
    }

    /// The text written so far.
    pub fn into_string(mut self) -> String {
        let bytes = self.take();
        // Every field came in as bytes of Rust strings (UTF-8), and csv only adds ASCII.
        String::from_utf8(bytes).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into())
    }
}

fn temp_name(path: &Path, tag: &str) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into());
    path.with_file_name(format!(".{name}.{tag}{}", std::process::id()))
}

/// Writes a file atomically: to a temporary name in the same directory, then rename, so that a
/// failure never leaves a half-written output behind. No fsync: the rename already guarantees
/// that a reader sees the old file or the whole new one; surviving a power cut is not worth the
/// 10-40 ms per file it costs on an ordinary disk.
pub fn write_atomic(path: &Path, contents: &[u8]) -> std::io::Result<()> {
    write_all_atomic(&[(path.to_path_buf(), contents.to_vec())])
}

/// Writes several files so that either all appear or none: each is written to a temporary name
/// first; only when all have been written are they renamed into place, and if a rename fails the
/// files already replaced are put back as they were (no fsync, as in [`write_atomic`]).
pub fn write_all_atomic(files: &[(PathBuf, Vec<u8>)]) -> std::io::Result<()> {
    let mut temps: Vec<PathBuf> = Vec::new();
    let written = (|| {
        for (path, contents) in files {
            let tmp = temp_name(path, "tmp");
            temps.push(tmp.clone());
            let mut f = fs::File::create(&tmp)?;
            f.write_all(contents)?;
        }
        Ok(())
    })();
    if let Err(e) = written {
        for tmp in &temps {
            let _ = fs::remove_file(tmp);
        }
        return Err(e);
    }
    // (target, backup of the file it replaced, if any), for the rollback.
    let mut done: Vec<(&Path, Option<PathBuf>)> = Vec::new();
    let mut result = Ok(());
    for ((path, _), tmp) in files.iter().zip(&temps) {
        let backup = if path.exists() {
            let b = temp_name(path, "old");
            if let Err(e) = fs::rename(path, &b) {
                result = Err(e);
                break;
            }
            Some(b)
        } else {
            None
        };
        if let Err(e) = fs::rename(tmp, path) {
            if let Some(b) = &backup {
                let _ = fs::rename(b, path);
            }
            result = Err(e);
            break;
        }
        done.push((path, backup));
    }
    if result.is_err() {
        for (path, backup) in done.iter().rev() {
            match backup {
                Some(b) => {
                    let _ = fs::rename(b, path);
                }
                None => {
                    let _ = fs::remove_file(path);
                }
            }
        }
        for tmp in &temps {
            let _ = fs::remove_file(tmp);
        }
    } else {
        for (_, backup) in &done {
            if let Some(b) = backup {
                let _ = fs::remove_file(b);
            }
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Table;

    #[test]
    fn csv_out_round_trips_awkward_text_through_the_reader() {
        let ids = [
            "plain",
            "a,b",
            "say \"hi\"",
            "two\nlines",
            "#not a comment",
            "  #indented",
            "",
            "caf\u{e9}",
        ];
        let mut out = CsvOut::new();
        out.comment("made by a test\nwith a line break");
        out.record(["id", "v"]);
        for (i, id) in ids.iter().enumerate() {
            out.record([id.to_string(), i.to_string()]);
        }
        let text = out.into_string();
        let t = Table::parse("t.csv", &text).unwrap();
        assert_eq!(t.header_line, 2, "{text}");
        assert_eq!(t.rows.len(), ids.len(), "{text}");
        for (i, (row, id)) in t.rows.iter().zip(ids).enumerate() {
            // The reader trims blanks around a field.
            assert_eq!(t.field(row, 0), id.trim(), "{text}");
            assert_eq!(t.field(row, 1), i.to_string());
        }
    }

    #[test]
    fn all_or_nothing() {
        let dir = std::env::temp_dir().join(format!("restitution-atomic-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let a = dir.join("a.txt");
        fs::write(&a, "old").unwrap();
        // The second file cannot be written (no such directory): a.txt keeps its old text and
        // no temporary file is left.
        let blocked = dir.join("missing").join("b.txt");
        let files = vec![(a.clone(), b"new".to_vec()), (blocked, b"x".to_vec())];
        assert!(write_all_atomic(&files).is_err());
        assert_eq!(fs::read_to_string(&a).unwrap(), "old");
        let left: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left.len(), 1, "temporary files left behind: {left:?}");
        write_all_atomic(&[(a.clone(), b"new".to_vec())]).unwrap();
        assert_eq!(fs::read_to_string(&a).unwrap(), "new");
        fs::remove_dir_all(&dir).unwrap();
    }
}
