//! The oblique-collision CSV schema of `restitution walton fit`: reading ([`read_collisions`]),
//! measuring with line numbers in the errors ([`measure_records`]) and writing
//! ([`write_collisions`]), so that every producer of such data (the generator, the kinematics
//! command) writes exactly what the fit reads.

use super::{CsvOut, DataError, DataFailure, Table, fmt_num};
use crate::contact::{Material, Sphere};
use crate::fit::walton::CollisionRecord;
use crate::models::walton::{self, Body, Measured, State, Target};
use nalgebra::Vector3;

/// Columns of one sphere: position (3), velocity (3), spin (3) before; velocity and spin after.
fn sphere_columns(i: u8) -> [String; 15] {
    [
        format!("x{i}_m"),
        format!("y{i}_m"),
        format!("z{i}_m"),
        format!("v{i}x_m_s"),
        format!("v{i}y_m_s"),
        format!("v{i}z_m_s"),
        format!("w{i}x_rad_s"),
        format!("w{i}y_rad_s"),
        format!("w{i}z_rad_s"),
        format!("v{i}x_post_m_s"),
        format!("v{i}y_post_m_s"),
        format!("v{i}z_post_m_s"),
        format!("w{i}x_post_rad_s"),
        format!("w{i}y_post_rad_s"),
        format!("w{i}z_post_rad_s"),
    ]
}

/// Indices into [`sphere_columns`] that are required (the in-plane set: positions, velocities and z spins); the others
/// (z, v_z, w_x, w_y) are optional and default to 0.
const REQUIRED: [usize; 8] = [0, 1, 3, 4, 8, 9, 10, 14];

/// A centre distance is accepted when within this factor of the touching distance: it catches
/// positions in millimetres or centres not at contact, while allowing tracking noise (a pixel
/// is a few per cent of a diameter in the paper's images).
const CONTACT_DISTANCE_TOLERANCE: f64 = 0.25;

/// Reads the collisions of a `walton fit` CSV (schema: `restitution walton fit --help`).
/// Masses come from the diameters and `material` ([`Sphere::mass_kg`]); both spheres get inertia factor
/// `inertia_k`. Returns the records and warnings (unknown columns, 3-D columns without their
/// pre/post partner). Errors name the file, line, column and value.
pub fn read_collisions(
    table: &Table,
    material: &Material,
    inertia_k: f64,
) -> Result<(Vec<CollisionRecord>, Vec<String>), DataError> {
    let d1c = table.require("d1_mm")?;
    let d2c = table.require("d2_mm")?;
    let c1 = sphere_columns(1);
    let c2 = sphere_columns(2);
    let idx1: Vec<Option<usize>> = c1.iter().map(|c| table.column(c)).collect();
    let idx2: Vec<Option<usize>> = c2.iter().map(|c| table.column(c)).collect();
    for &j in &REQUIRED {
        table.require(&c1[j])?;
    }
    // Sphere 2's position is needed for walls too (the contact point).
    table.require(&c2[0])?;
    table.require(&c2[1])?;
    let id_col = table.column("collision");
    let mut warnings = Vec::new();
    for h in &table.headers {
        let known =
            h == "d1_mm" || h == "d2_mm" || h == "collision" || c1.contains(h) || c2.contains(h);
        if !known {
            warnings.push(format!(
                "{}:{}: ignoring unknown column '{}'",
                table.path,
                table.header_line,
                super::shown(h)
            ));
        }
    }
    for (cols, idx) in [(&c1, &idx1), (&c2, &idx2)] {
        // Pre velocity/spin j (3..9) pairs with post j + 6.
        for j in [5, 6, 7] {
            if idx[j].is_some() != idx[j + 6].is_some() {
                let (have, missing) = if idx[j].is_some() {
                    (&cols[j], &cols[j + 6])
                } else {
                    (&cols[j + 6], &cols[j])
                };
                warnings.push(format!(
                    "{}:{}: column '{have}' without '{missing}': the missing one is taken as 0",
                    table.path, table.header_line
                ));
            }
        }
    }
    let mut records = Vec::with_capacity(table.rows.len());
    for row in &table.rows {
        let d1_mm = table.number_where(row, d1c, |v| v > 0.0, "a diameter > 0 (mm)")?;
        let d2_mm = table.positive_or_inf(row, d2c)?;
        let wall = d2_mm.is_infinite();
        let read = |idx: &[Option<usize>], names: &[String; 15], j: usize, zero_ok: bool| match idx
            [j]
        {
            None if REQUIRED.contains(&j) && !zero_ok => Err(DataError {
                path: table.path.clone(),
                line: Some(row.line),
                column: Some(names[j].clone()),
                kind: DataFailure::Schema,
                message: format!(
                    "required column is missing (needed for a sphere-sphere collision, d2_mm = {})",
                    table.shown(row, d2c)
                ),
            }),
            None => Ok(0.0),
            Some(c) if zero_ok && table.field(row, c).is_empty() => Ok(0.0),
            Some(c) => table.number(row, c),
        };
        let mut v1 = [0.0; 15];
        let mut v2 = [0.0; 15];
        for j in 0..15 {
            v1[j] = read(&idx1, &c1, j, false)?;
            // For a wall, only the contact point (positions) is read; motion must be absent or 0.
            let position = j < 3;
            v2[j] = read(&idx2, &c2, j, wall && !position)?;
            if wall && !position && v2[j] != 0.0 {
                let c = idx2[j].expect("a nonzero value came from a column");
                return Err(table.cell_error(
                    row,
                    c,
                    format!(
                        "'{}': a wall (d2_mm = inf) is at rest; leave its velocity and spin columns empty or 0",
                        table.shown(row, c)
                    ),
                ));
            }
        }
        let vec3 = |v: &[f64; 15], j: usize| Vector3::new(v[j], v[j + 1], v[j + 2]);
        let d1 = d1_mm * 1e-3;
        // Diameters were checked > 0 above, so the sphere is valid.
        let mass = |d: f64| {
            Sphere::new(d, *material)
                .map(|s| s.mass_kg())
                .unwrap_or(f64::NAN)
        };
        let body = |v: &[f64; 15], d: f64, post: bool| Body {
            position_m: vec3(v, 0),
            velocity_m_s: vec3(v, if post { 9 } else { 3 }),
            spin_rad_s: vec3(v, if post { 12 } else { 6 }),
            d_m: d,
            mass_kg: mass(d),
            inertia_k,
        };
        let (pre, post) = if wall {
            let p = vec3(&v2, 0);
            (
                State::on_wall(body(&v1, d1, false), p),
                State::on_wall(body(&v1, d1, true), p),
            )
        } else {
            let d2 = d2_mm * 1e-3;
            (
                State::pair(body(&v1, d1, false), body(&v2, d2, false)),
                State::pair(body(&v1, d1, true), body(&v2, d2, true)),
            )
        };
        let touching = if wall {
            0.5 * d1
        } else {
            0.5 * (d1 + d2_mm * 1e-3)
        };
        let other = match pre.target {
            Target::Sphere(b) => b.position_m,
            Target::Wall { contact_point_m } => contact_point_m,
        };
        let dist = (pre.sphere.position_m - other).norm();
        let off = (dist / touching - 1.0).abs();
        if off.is_nan() || off > CONTACT_DISTANCE_TOLERANCE {
            let what = if wall {
                "centre to wall contact point (x2_m, y2_m) is"
            } else {
                "centres are"
            };
            return Err(DataError {
                path: table.path.clone(),
                line: Some(row.line),
                column: Some("x1_m".into()),
                kind: DataFailure::Value,
                message: format!(
                    "{what} {} m apart, but touching needs {} m from the diameters (within {}%): positions must be in metres, at contact",
                    fmt_num(dist),
                    fmt_num(touching),
                    CONTACT_DISTANCE_TOLERANCE * 100.0
                ),
            });
        }
        records.push(CollisionRecord {
            line: row.line,
            id: id_col.map(|c| table.field(row, c).to_string()),
            pre,
            post,
        });
    }
    Ok((records, warnings))
}

/// Measures every record ([`walton::measure`]); an error names the record's line.
pub fn measure_records(
    path: &str,
    records: &[CollisionRecord],
) -> Result<Vec<Measured>, DataError> {
    records
        .iter()
        .map(|r| {
            let err = |message: String| DataError {
                path: path.to_string(),
                line: Some(r.line),
                column: None,
                kind: DataFailure::Value,
                message,
            };
            let frame = r.pre.contact().map_err(|e| err(e.to_string()))?;
            let approach = frame.v_rel_m_s.dot(&frame.normal);
            if approach.is_nan() || approach >= 0.0 {
                return Err(err(format!(
                    "the spheres are not approaching before the collision: (v1 - v2) . n = {} m/s, expected < 0 (n points from sphere 2 to sphere 1; check the velocity signs and the pre/post columns)",
                    fmt_num(approach)
                )));
            }
            let m = walton::measure(&r.pre, &r.post).map_err(|e| err(e.to_string()))?;
            // The fit weights by squared speeds and sums over collisions: each must stay finite.
            let speeds = [m.v_n_m_s, m.v_s_m_s];
            if !m.e.is_finite() || speeds.iter().any(|v| !(v * v * 1e6).is_finite()) {
                return Err(err(format!(
                    "out of range: v_n = {} m/s, |v_s| = {} m/s, e = {} (squares of speeds must stay finite)",
                    fmt_num(m.v_n_m_s),
                    fmt_num(m.v_s_m_s),
                    fmt_num(m.e)
                )));
            }
            Ok(m)
        })
        .collect()
}

/// One warning for the collisions whose centre of mass changes velocity by more than the
/// collision's own speed (|v_c| before: v_n and |v_s| combined), naming the first by its line and
/// counting the others; None when there are none (walls have no such check). Measured velocities
/// conserve momentum to their noise (the Fig. 6 data: 0.06 m/s at 4 m/s), so a change as large
/// as the speed itself is a mistyped velocity: one at 1e40 m/s had been fitted into e = 7e37,
/// with nothing naming the row. `measured` is `records` measured ([`measure_records`]).
pub fn momentum_warning(
    path: &str,
    records: &[CollisionRecord],
    measured: &[Measured],
) -> Option<String> {
    let mut off = records.iter().zip(measured).filter_map(|(r, m)| {
        let dv = m.com_velocity_change_m_s?.norm();
        let speed = m.v_n_m_s.hypot(m.v_s_m_s);
        (dv > speed).then_some((r, dv, speed))
    });
    let (r, dv, speed) = off.next()?;
    let more = off.count();
    let id = r.id.as_deref().map_or(String::new(), |id| {
        format!(" collision '{}':", super::shown(id))
    });
    Some(format!(
        "{path}:{}:{id} the centre of mass's velocity changes by {} m/s, more than the collision's speed {} m/s: momentum is not conserved (a mistyped velocity?){}",
        r.line,
        fmt_num(dv),
        fmt_num(speed),
        if more > 0 {
            format!(" (and {more} more collisions like it)")
        } else {
            String::new()
        }
    ))
}

/// Writes records in the `walton fit` CSV schema: the in-plane columns, plus the out-of-plane
/// ones when any record has a nonzero z component, position or in-plane spin. A `collision` id
/// column is written when any record has an id. Numbers in shortest round-trip form.
pub fn write_collisions(records: &[CollisionRecord]) -> String {
    let flat = |r: &CollisionRecord| -> ([f64; 15], [f64; 15], f64, f64) {
        let pack = |pre: &Body, post: &Body| {
            let mut v = [0.0; 15];
            for (j, x) in pre
                .position_m
                .iter()
                .chain(pre.velocity_m_s.iter())
                .chain(pre.spin_rad_s.iter())
                .chain(post.velocity_m_s.iter())
                .chain(post.spin_rad_s.iter())
                .enumerate()
            {
                v[j] = *x;
            }
            v
        };
        let v1 = pack(&r.pre.sphere, &r.post.sphere);
        match (&r.pre.target, &r.post.target) {
            (Target::Sphere(a), Target::Sphere(b)) => (v1, pack(a, b), r.pre.sphere.d_m, a.d_m),
            (Target::Wall { contact_point_m }, _) | (_, Target::Wall { contact_point_m }) => {
                let mut v2 = [0.0; 15];
                v2[..3].copy_from_slice(contact_point_m.as_slice());
                (v1, v2, r.pre.sphere.d_m, f64::INFINITY)
            }
        }
    };
    let rows: Vec<_> = records.iter().map(flat).collect();
    let three_d = rows.iter().any(|(a, b, ..)| {
        (0..15)
            .filter(|j| !REQUIRED.contains(j))
            .any(|j| a[j] != 0.0 || b[j] != 0.0)
    });
    let cols: Vec<usize> = (0..15)
        .filter(|j| three_d || REQUIRED.contains(j))
        .collect();
    let with_id = records.iter().any(|r| r.id.is_some());
    let (c1, c2) = (sphere_columns(1), sphere_columns(2));
    let mut header: Vec<String> = Vec::new();
    if with_id {
        header.push("collision".into());
    }
    header.push("d1_mm".into());
    header.push("d2_mm".into());
    // The schema's order: positions (sphere 1, sphere 2), motion before (1, 2), after (1, 2).
    let groups: [(bool, std::ops::Range<usize>); 6] = [
        (true, 0..3),
        (false, 0..3),
        (true, 3..9),
        (false, 3..9),
        (true, 9..15),
        (false, 9..15),
    ];
    for (first, range) in &groups {
        let c = if *first { &c1 } else { &c2 };
        for &j in cols.iter().filter(|j| range.contains(j)) {
            header.push(c[j].clone());
        }
    }
    let mut out = CsvOut::new();
    out.record(&header);
    for (r, (a, b, d1, d2)) in records.iter().zip(&rows) {
        let mut cells: Vec<String> = Vec::new();
        if with_id {
            cells.push(r.id.clone().unwrap_or_default());
        }
        cells.push(fmt_num(d1 * 1e3));
        cells.push(if d2.is_infinite() {
            "inf".into()
        } else {
            fmt_num(d2 * 1e3)
        });
        for (first, range) in &groups {
            let v = if *first { a } else { b };
            for &j in cols.iter().filter(|j| range.contains(j)) {
                cells.push(fmt_num(v[j]));
            }
        }
        out.record(&cells);
    }
    out.into_string()
}
