//! The tracks schema: sphere centres per video frame, grouped by collision.
//!
//! Columns (header, any order): `collision` (an id), `t_s`, `x1_m,y1_m,x2_m,y2_m` (centres),
//! `d1_mm,d2_mm`; optional `phase` (`pre`/`post`; when absent the split is found from the
//! tracks), optional spins measured from markers `w1z_rad_s,w2z_rad_s` (before) and
//! `w1z_post_rad_s,w2z_post_rad_s` (after), constant within a collision. An empty spin cell
//! (a sphere whose spin was not measured) is read as NaN: the kinematics takes it as 0 and says
//! so ([`crate::kinematics::batch`]).

use super::{CsvOut, DataError, DataFailure, Table, fmt_num, shown};
use crate::kinematics::Frame;
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// The frames of one collision, sorted by time.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionTrack {
    pub id: String,
    pub first_line: usize,
    pub d1_m: f64,
    pub d2_m: f64,
    pub frames: Vec<Frame>,
    /// Index of the first post-collision frame, when the file labels phases.
    pub split: Option<usize>,
    /// Spins about z, rad/s: [sphere 1 pre, sphere 2 pre, sphere 1 post, sphere 2 post].
    pub spins_rad_s: Option<[f64; 4]>,
}

impl CollisionTrack {
    /// This collision as an input of the library's batch measurement.
    pub fn input(&self) -> crate::kinematics::batch::CollisionInput<'_> {
        crate::kinematics::batch::CollisionInput {
            frames: &self.frames,
            split: self.split,
            d1_m: self.d1_m,
            d2_m: self.d2_m,
            spins_rad_s: self.spins_rad_s,
        }
    }
}

const SPIN_COLUMNS: [&str; 4] = ["w1z_rad_s", "w2z_rad_s", "w1z_post_rad_s", "w2z_post_rad_s"];

/// Reads and validates a tracks file.
pub fn read_tracks(path: &Path) -> Result<Vec<CollisionTrack>, DataError> {
    parse_tracks(&Table::read(path)?)
}

/// Validates a tracks table (see the module doc for the columns).
pub fn parse_tracks(table: &Table) -> Result<Vec<CollisionTrack>, DataError> {
    let id_col = table.require("collision")?;
    let t_col = table.require("t_s")?;
    let pos = [
        table.require("x1_m")?,
        table.require("y1_m")?,
        table.require("x2_m")?,
        table.require("y2_m")?,
    ];
    let d1_col = table.require("d1_mm")?;
    let d2_col = table.require("d2_mm")?;
    let phase_col = table.column("phase");
    let spin_cols: Vec<Option<usize>> = SPIN_COLUMNS.iter().map(|c| table.column(c)).collect();
    let positive = |v: f64| v > 0.0;

    struct Acc {
        track: CollisionTrack,
        phases: Vec<(bool, usize)>,
        /// The times seen, as bits of t + 0.0 (so that -0 and 0 are one time).
        times: HashSet<u64>,
    }
    // Hashed look-ups keep a file of 100 000 rows linear, whether it has one collision or many.
    let mut accs: Vec<Acc> = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    for row in &table.rows {
        let id = table.field(row, id_col).to_string();
        if id.is_empty() {
            return Err(table.cell_error(row, id_col, "empty collision id"));
        }
        let t = table.number(row, t_col)?;
        let mut p = [0.0; 4];
        for (k, &c) in pos.iter().enumerate() {
            p[k] = table.number(row, c)?;
        }
        let d1 = table.number_where(row, d1_col, positive, "a diameter > 0 (mm)")? * 1e-3;
        let d2 = table.number_where(row, d2_col, positive, "a diameter > 0 (mm)")? * 1e-3;
        let post = match phase_col {
            None => None,
            Some(c) => match table.field(row, c) {
                "pre" => Some(false),
                "post" => Some(true),
                other => {
                    return Err(table.cell_error(
                        row,
                        c,
                        format!("'{}' is not a phase: expected pre or post", shown(other)),
                    ));
                }
            },
        };
        let mut spins = [f64::NAN; 4];
        let mut have_spins = false;
        for (k, c) in spin_cols.iter().enumerate() {
            if let Some(c) = c.filter(|&c| !table.field(row, c).is_empty()) {
                spins[k] = table.number(row, c)?;
                have_spins = true;
            }
        }
        let i = match index.get(&id) {
            Some(&i) => i,
            None => {
                index.insert(id.clone(), accs.len());
                accs.push(Acc {
                    track: CollisionTrack {
                        id: id.clone(),
                        first_line: row.line,
                        d1_m: d1,
                        d2_m: d2,
                        frames: Vec::new(),
                        split: None,
                        spins_rad_s: None,
                    },
                    phases: Vec::new(),
                    times: HashSet::new(),
                });
                accs.len() - 1
            }
        };
        let acc = &mut accs[i];
        // A collision is one pair of spheres: its diameters cannot change between frames.
        for (col, got, first) in [(d1_col, d1, acc.track.d1_m), (d2_col, d2, acc.track.d2_m)] {
            if got != first {
                return Err(table.cell_error(
                    row,
                    col,
                    format!(
                        "'{}' differs from the collision's first row (line {})",
                        table.shown(row, col),
                        acc.track.first_line
                    ),
                ));
            }
        }
        if have_spins && acc.track.spins_rad_s.is_none() {
            acc.track.spins_rad_s = Some(spins);
        }
        if !acc.times.insert((t + 0.0).to_bits()) {
            return Err(table.cell_error(
                row,
                t_col,
                format!(
                    "time {} appears twice in collision '{}'",
                    table.shown(row, t_col),
                    shown(&id)
                ),
            ));
        }
        if let Some(post) = post {
            acc.phases.push((post, row.line));
        }
        acc.track.frames.push(Frame {
            t_s: t,
            r1_m: [p[0], p[1]],
            r2_m: [p[2], p[3]],
        });
    }

    let mut out = Vec::new();
    for mut acc in accs {
        let mut order: Vec<usize> = (0..acc.track.frames.len()).collect();
        order.sort_by(|&a, &b| acc.track.frames[a].t_s.total_cmp(&acc.track.frames[b].t_s));
        acc.track.frames = order.iter().map(|&k| acc.track.frames[k]).collect();
        if !acc.phases.is_empty() {
            let phases: Vec<(bool, usize)> = order.iter().map(|&k| acc.phases[k]).collect();
            let split = phases.iter().position(|p| p.0).unwrap_or(phases.len());
            if let Some(bad) = phases[split..].iter().find(|p| !p.0) {
                return Err(DataError {
                    path: table.path.clone(),
                    line: Some(bad.1),
                    column: Some("phase".into()),
                    kind: DataFailure::Value,
                    message: format!(
                        "a 'pre' frame comes after a 'post' frame in collision '{}'",
                        shown(&acc.track.id)
                    ),
                });
            }
            acc.track.split = Some(split);
        }
        out.push(acc.track);
    }
    Ok(out)
}

/// Writes tracks in this schema (with `phase` when every track knows its split, and the spin
/// columns when any track has spins; a NaN spin, one not measured, is an empty cell). Numbers
/// in shortest round-trip form; csv::Writer quotes ids that need it.
pub fn write_tracks(tracks: &[CollisionTrack]) -> String {
    let phases = tracks.iter().all(|t| t.split.is_some());
    let spins = tracks.iter().any(|t| t.spins_rad_s.is_some());
    let mut header: Vec<&str> = vec![
        "collision",
        "t_s",
        "x1_m",
        "y1_m",
        "x2_m",
        "y2_m",
        "d1_mm",
        "d2_mm",
    ];
    if phases {
        header.push("phase");
    }
    if spins {
        header.extend(SPIN_COLUMNS);
    }
    let mut out = CsvOut::new();
    out.record(&header);
    for t in tracks {
        for (k, f) in t.frames.iter().enumerate() {
            let mut row = vec![
                t.id.clone(),
                fmt_num(f.t_s),
                fmt_num(f.r1_m[0]),
                fmt_num(f.r1_m[1]),
                fmt_num(f.r2_m[0]),
                fmt_num(f.r2_m[1]),
                fmt_num(t.d1_m * 1e3),
                fmt_num(t.d2_m * 1e3),
            ];
            if let (true, Some(split)) = (phases, t.split) {
                row.push(if k < split { "pre" } else { "post" }.to_string());
            }
            if spins {
                row.extend(t.spins_rad_s.unwrap_or([f64::NAN; 4]).map(|w| {
                    if w.is_nan() {
                        String::new()
                    } else {
                        fmt_num(w)
                    }
                }));
            }
            out.record(&row);
        }
    }
    out.into_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "collision,t_s,x1_m,y1_m,x2_m,y2_m,d1_mm,d2_mm,phase\n";

    #[test]
    fn groups_sorts_and_splits() {
        let text = format!(
            "{HEAD}a,0.002,0,0,1,0,25.4,25.4,post\na,0.001,0,0,1,0,25.4,25.4,pre\n# c\nb,0.0,0,0,1,0,12.7,12.7,pre\n"
        );
        let t = parse_tracks(&Table::parse("t.csv", &text).unwrap()).unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t[0].frames[0].t_s, 0.001);
        assert_eq!(t[0].split, Some(1));
        assert_eq!(t[1].first_line, 5);
        assert_eq!(t[1].d1_m, 0.0127);
    }

    #[test]
    fn write_then_read_round_trips() {
        let text =
            format!("{HEAD}a,0.002,0,0.1,1,0,25.4,25.4,post\na,0.001,0,0,1,0.3,25.4,25.4,pre\n");
        let mut t = parse_tracks(&Table::parse("t.csv", &text).unwrap()).unwrap();
        t[0].spins_rad_s = Some([1.0, 2.0, 3.0, -4.5]);
        let again = parse_tracks(&Table::parse("u.csv", &write_tracks(&t)).unwrap()).unwrap();
        assert_eq!(again[0].frames, t[0].frames);
        assert_eq!(again[0].split, t[0].split);
        assert_eq!(again[0].spins_rad_s, t[0].spins_rad_s);
        assert_eq!(again[0].d1_m, t[0].d1_m);
        // An unmeasured spin is written empty and read back as NaN; an id with a comma is quoted.
        t[0].spins_rad_s = Some([1.0, f64::NAN, 3.0, -4.5]);
        t[0].id = "a,b".into();
        let text = write_tracks(&t);
        assert!(text.contains("\"a,b\""), "{text}");
        let again = parse_tracks(&Table::parse("u.csv", &text).unwrap()).unwrap();
        assert_eq!(again[0].id, "a,b");
        let w = again[0].spins_rad_s.unwrap();
        assert!(
            w[1].is_nan() && [w[0], w[2], w[3]] == [1.0, 3.0, -4.5],
            "{w:?}"
        );
    }

    #[test]
    fn errors_name_line_and_column() {
        let bad = [
            (
                format!("{HEAD}a,0.1,0,0,1,0,25.4,25.4,during\n"),
                "t.csv:2: column 'phase'",
            ),
            (
                format!("{HEAD}a,0.1,0,0,1,0,25.4,25.4,pre\na,0.1,0,0,1,0,25.4,25.4,post\n"),
                "t.csv:3: column 't_s'",
            ),
            (
                format!("{HEAD}a,0.1,0,0,1,0,25.4,25.4,pre\na,0.2,0,0,1,0,12.7,25.4,post\n"),
                "t.csv:3: column 'd1_mm'",
            ),
            (
                format!("{HEAD}a,0.2,0,0,1,0,25.4,25.4,pre\na,0.1,0,0,1,0,25.4,25.4,post\n"),
                "t.csv:2: column 'phase'",
            ),
            (
                format!("{HEAD}a,0.1,0,x,1,0,25.4,25.4,pre\n"),
                "t.csv:2: column 'y1_m'",
            ),
            (
                format!("{HEAD}a,0.1,0,0,1,0,-1,25.4,pre\n"),
                "t.csv:2: column 'd1_mm'",
            ),
        ];
        for (text, want) in bad {
            let e = parse_tracks(&Table::parse("t.csv", &text).unwrap())
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(want), "{e}");
        }
    }
}
