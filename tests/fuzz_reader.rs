//! Property tests of the CSV reader and writer: total on any bytes, exact line numbers after
//! comments, blank lines and quoted line breaks, and numbers in shortest round-trip form.

use proptest::prelude::*;
use restitution::data::{CsvOut, Table, fmt_num};

/// A text field: anything, but weighted towards what CSV must quote.
fn field() -> impl Strategy<Value = String> {
    prop_oneof![
        "[a-z0-9 ,\"#\n\r;.-]{0,12}",
        any::<String>(),
        Just("#".to_string()),
        Just(String::new()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Whatever the bytes, the reader returns a table or an error; it never panics.
    #[test]
    fn reader_is_total(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        let _ = Table::parse_bytes("f.csv", &bytes);
    }

    /// Records written by CsvOut, with comment and blank lines between them, read back with the
    /// same fields (trimmed) and at the lines where they were written.
    #[test]
    fn written_records_read_back_at_their_lines(
        rows in prop::collection::vec(prop::collection::vec(field(), 3), 1..20),
        gaps in prop::collection::vec(0u8..5, 20),
    ) {
        let mut out = CsvOut::new();
        out.record(["a", "b", "c"]);
        let mut text_so_far = out.into_string();
        let mut lines = Vec::new();
        for (i, r) in rows.iter().enumerate() {
            match gaps[i] {
                1 => text_so_far += "# a comment, with \"quotes\n",
                2 => text_so_far += "\n",
                3 => text_so_far += "   \t\n",
                4 => text_so_far += "  # indented,\"opening a quote\n",
                _ => {}
            }
            // The record starts on the line after everything written so far.
            let line = 1 + text_so_far.matches('\n').count()
                + text_so_far.matches('\r').count()
                - text_so_far.matches("\r\n").count();
            let mut w = CsvOut::new();
            w.record(r);
            lines.push((line, r.clone()));
            text_so_far += &w.into_string();
        }
        match Table::parse("f.csv", &text_so_far) {
            Ok(t) => {
                prop_assert_eq!(t.rows.len(), lines.len(), "{:?}", text_so_far);
                for (row, (line, fields)) in t.rows.iter().zip(&lines) {
                    prop_assert_eq!(row.line, *line, "{:?}", text_so_far);
                    let want: Vec<String> = fields.iter().map(|f| f.trim().to_string()).collect();
                    let got: Vec<String> =
                        (0..t.headers.len()).map(|c| t.field(row, c).to_string()).collect();
                    prop_assert_eq!(&got, &want);
                }
            }
            Err(e) => prop_assert!(lines.is_empty(), "{}: {:?}", e, text_so_far),
        }
    }

    /// Numbers are written in shortest round-trip form: parsing gives the same f64 back.
    #[test]
    fn numbers_round_trip(x in any::<f64>().prop_filter("finite", |x| x.is_finite())) {
        let s = fmt_num(x);
        prop_assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{}", s);
    }
}
