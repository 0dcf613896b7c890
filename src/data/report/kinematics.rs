//! The documents of `restitution kinematics`: `kinematics.csv` (one row per measured collision),
//! its JSON form, and `fit_input.csv` (the `restitution fit` schema), built by the library; and
//! the pass that measures a tracks file for them ([`measure_tracks`]).

use crate::data::tracks::CollisionTrack;
use crate::data::{CsvOut, fmt_num};
use crate::fit::walton::CollisionRecord;
use crate::kinematics::batch::{BatchOptions, CollisionInput, measure_batch};
use crate::kinematics::{Measurement, TimeRule};

/// The columns of `kinematics.csv` (and the keys of each JSON record).
pub const COLUMNS: [&str; 27] = [
    "collision",
    "t_c_s",
    "time_rule",
    "n_pre",
    "n_post",
    "v1x_m_s",
    "v1y_m_s",
    "v2x_m_s",
    "v2y_m_s",
    "v1x_post_m_s",
    "v1y_post_m_s",
    "v2x_post_m_s",
    "v2y_post_m_s",
    "v_err_m_s",
    "sigma_pos_m",
    "v_n_m_s",
    "v_n_err_m_s",
    "e",
    "e_err",
    "e_err_eq8",
    "eq8_dv_m_s",
    "beta",
    "psi",
    "momentum_dvx_m_s",
    "momentum_dvy_m_s",
    "d1_mm",
    "d2_mm",
];

#[derive(Debug, Clone)]
pub struct Row {
    pub id: String,
    pub d1_mm: f64,
    pub d2_mm: f64,
    pub m: Measurement,
}

impl Row {
    pub fn cells(&self) -> Vec<String> {
        let k = &self.m.kinematics;
        let me = &self.m.measured;
        let v_err = self
            .m
            .v_err_m_s
            .iter()
            .map(|v| v.norm_squared())
            .sum::<f64>()
            / 8.0;
        let mut c = vec![
            self.id.clone(),
            fmt_num(k.t_c_s),
            k.time_rule.name().into(),
            k.n_pre.to_string(),
            k.n_post.to_string(),
        ];
        for v in &k.v_m_s {
            c.push(fmt_num(v.x));
            c.push(fmt_num(v.y));
        }
        for x in [
            v_err.sqrt(),
            self.m.sigma_pos_m,
            me.v_n_m_s,
            self.m.v_n_err_m_s,
            me.e,
            self.m.e_err,
            self.m.e_err_eq8,
            self.m.eq8_dv_m_s,
        ] {
            c.push(fmt_num(x));
        }
        c.push(me.beta.map(fmt_num).unwrap_or_default());
        // Head-on (no tangential velocity): psi is infinite, left empty like beta.
        c.push(if me.psi.is_finite() {
            fmt_num(me.psi)
        } else {
            String::new()
        });
        // No momentum check (a wall has no second momentum): empty, not a 0 that reads as a
        // perfect check.
        let dv = me.com_velocity_change_m_s;
        c.push(dv.map(|v| fmt_num(v.x)).unwrap_or_default());
        c.push(dv.map(|v| fmt_num(v.y)).unwrap_or_default());
        c.push(fmt_num(self.d1_mm));
        c.push(fmt_num(self.d2_mm));
        c
    }
}

/// `kinematics.csv`: a `# comment` line when given, the header, a row per collision.
pub fn kinematics_csv(rows: &[Row], comment: Option<&str>) -> String {
    let mut out = CsvOut::new();
    if let Some(c) = comment {
        out.comment(c);
    }
    out.record(COLUMNS);
    for r in rows {
        out.record(r.cells());
    }
    out.into_string()
}

/// `fit_input.csv`: d_mm, d2_mm, v_n_m_s, e, e_err of each collision, after a `# comment`.
pub fn fit_input_csv(rows: &[Row], comment: &str) -> String {
    let mut out = CsvOut::new();
    out.comment(comment);
    out.record(["d_mm", "d2_mm", "v_n_m_s", "e", "e_err"]);
    for r in rows {
        out.record([
            fmt_num(r.d1_mm),
            fmt_num(r.d2_mm),
            fmt_num(r.m.measured.v_n_m_s),
            fmt_num(r.m.measured.e),
            fmt_num(r.m.e_err),
        ]);
    }
    out.into_string()
}

/// The JSON document: `collisions`, one record per measured collision with the CSV's columns
/// as keys (numbers as numbers, empty cells as null, the id and the time rule as strings); and
/// what a reader of those records must also know, as the command's warnings say it: `skipped`,
/// the collisions that could not be measured (often the fast ones, so the records span a
/// narrower range of speeds than was filmed), and `unmeasured_spins`, the collisions whose
/// empty spin cells were taken as 0 in beta and psi. (A bare list of records, as before, left
/// both out: a program reading it could not tell a campaign measured whole from one with
/// collisions missing.)
pub fn kinematics_json(m: &Measured) -> String {
    let list: Vec<serde_json::Value> = m
        .rows
        .iter()
        .map(|r| {
            let map: serde_json::Map<String, serde_json::Value> = COLUMNS
                .iter()
                .zip(r.cells())
                .map(|(c, v)| {
                    let val = match v.parse::<f64>() {
                        Ok(x) if *c != "collision" && *c != "time_rule" => serde_json::json!(x),
                        _ if v.is_empty() => serde_json::Value::Null,
                        _ => serde_json::json!(v),
                    };
                    (c.to_string(), val)
                })
                .collect();
            serde_json::Value::Object(map)
        })
        .collect();
    let doc = serde_json::json!({
        "collisions": list,
        "skipped": m.skipped,
        "unmeasured_spins": m.unmeasured_spins,
    });
    serde_json::to_string_pretty(&doc).expect("JSON values serialise") + "\n"
}

/// The whole `kinematics` pass over a tracks file, as the command line and Python run it: every
/// collision measured with the noise pooled over all of them ([`measure_batch`]), the rows in
/// the file's order, and every collision that could not be measured named with its place.
#[derive(Debug)]
pub struct Measured {
    pub rows: Vec<Row>,
    /// Each measured collision as an oblique-collision record (walton_input.csv).
    pub records: Vec<CollisionRecord>,
    /// The position noise pooled over every collision, m.
    pub sigma_pos_m: f64,
    /// `FILE:LINE: collision 'ID': why`, in the file's order.
    pub skipped: Vec<String>,
    /// `FILE:LINE: collision 'ID': w1z_rad_s, ... not measured (empty): taken as 0 in beta and
    /// psi`.
    pub unmeasured_spins: Vec<String>,
    /// Ids of the collisions whose time is where the pre- and post-collision fits meet (they
    /// never reach contact distance on the pre-collision fits).
    pub fits_meet: Vec<String>,
}

impl Measured {
    /// The error line of a run that cannot go on, if it cannot: with `strict`, the first
    /// collision skipped; without, where no collision of `shown` could be measured, that, with
    /// the first one's reason (the others' may differ: the first alone read as the reason for
    /// all of them).
    pub fn refusal(&self, shown: &str, strict: bool) -> Option<String> {
        let first = self.skipped.first()?;
        if strict || self.rows.is_empty() && self.skipped.len() == 1 {
            return Some(first.clone());
        }
        self.rows.is_empty().then(|| {
            format!(
                "none of the {} collisions of {shown} could be measured; the first: {first}",
                self.skipped.len()
            )
        })
    }
}

/// Measures every collision of `tracks` (read from `shown`). A collision whose numbers
/// overflow (absurd magnitudes in the tracks or options) is skipped like an unmeasurable one,
/// never reported as NaN or inf.
pub fn measure_tracks(shown: &str, tracks: &[CollisionTrack], options: &BatchOptions) -> Measured {
    let place = |t: &CollisionTrack| {
        format!(
            "{shown}:{}: collision '{}'",
            t.first_line,
            crate::data::shown(&t.id)
        )
    };
    let inputs: Vec<CollisionInput> = tracks.iter().map(|t| t.input()).collect();
    let batch = measure_batch(&inputs, options);
    let mut skipped: Vec<(usize, String)> = batch
        .skipped
        .iter()
        .map(|(i, e)| (*i, format!("{}: {e}", place(&tracks[*i]))))
        .collect();
    let unmeasured_spins = batch
        .unmeasured_spins
        .iter()
        .map(|(i, names)| {
            format!(
                "{}: {} not measured (empty): taken as 0 in beta and psi",
                place(&tracks[*i]),
                names.join(", ")
            )
        })
        .collect();
    let mut rows = Vec::new();
    let mut records = Vec::new();
    for (i, m) in batch.measured {
        let t = &tracks[i];
        let row = Row {
            id: t.id.clone(),
            d1_mm: t.d1_m * 1e3,
            d2_mm: t.d2_m * 1e3,
            m,
        };
        if let Some((col, v)) = COLUMNS
            .iter()
            .zip(row.cells())
            .find(|(c, v)| **c != "collision" && (v == "NaN" || v.ends_with("inf")))
        {
            skipped.push((
                i,
                format!(
                    "{}: {col} = {v} (the tracks or flags are out of range)",
                    place(t)
                ),
            ));
            continue;
        }
        records.push(CollisionRecord {
            line: t.first_line,
            id: Some(t.id.clone()),
            pre: row.m.pre,
            post: row.m.post,
        });
        rows.push(row);
    }
    skipped.sort_by_key(|(i, _)| *i);
    let fits_meet = rows
        .iter()
        .filter(|r| r.m.kinematics.time_rule != TimeRule::ContactDistance)
        .map(|r| r.id.clone())
        .collect();
    Measured {
        rows,
        records,
        sigma_pos_m: batch.sigma_pos_m,
        skipped: skipped.into_iter().map(|(_, s)| s).collect(),
        unmeasured_spins,
        fits_meet,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::kinematics::{Eq8Inputs, FitKind};

    #[test]
    fn a_missing_momentum_check_is_empty_not_zero() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/data/virtual/normal/tracks.csv"
        );
        let tracks = crate::data::tracks::read_tracks(std::path::Path::new(path)).unwrap();
        let options = BatchOptions {
            material: Material::preset("nylon").unwrap(),
            inertia_k: 0.4,
            kind: FitKind::FixedGravity {
                g_m_s2: crate::kinematics::G_STANDARD_M_S2,
            },
            eq8: Eq8Inputs {
                s_subpixels: 2.0,
                subpixel_m: 6.25e-5,
            },
        };
        let mut m = measure_tracks("tracks.csv", &tracks, &options);
        assert!(m.skipped.is_empty(), "{:?}", m.skipped);
        let col = |name: &str| COLUMNS.iter().position(|c| *c == name).unwrap();
        let (x, y) = (col("momentum_dvx_m_s"), col("momentum_dvy_m_s"));
        // A pair has its check (measured, so not exactly 0)...
        let cells = m.rows[0].cells();
        assert!(cells[x].parse::<f64>().unwrap() != 0.0, "{}", cells[x]);
        // ...a collision without one (a wall's) shows an empty cell and a JSON null, never a 0
        // that reads as a perfect check.
        m.rows[0].m.measured.com_velocity_change_m_s = None;
        let cells = m.rows[0].cells();
        assert_eq!((cells[x].as_str(), cells[y].as_str()), ("", ""));
        let doc: serde_json::Value = serde_json::from_str(&kinematics_json(&m)).unwrap();
        assert!(doc["collisions"][0]["momentum_dvx_m_s"].is_null(), "{doc}");
        assert!(doc["collisions"][0]["e"].is_number(), "{doc}");
    }
}
