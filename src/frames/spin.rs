//! Spins from markers (the paper's Sec. III; docs/physics.md §8): markers lifted onto the
//! visible hemisphere, matched between frames, the rotation of each frame pair by least squares
//! (Kabsch/Wahba), and one spin per phase (the paper takes it constant before and after the
//! collision).
//!
//! Axes: x right, y up, z towards the camera (right-handed), so w_z > 0 is counter-clockwise as
//! seen in the image. Projection is orthographic (the spheres are small against the camera
//! distance), so a marker at image offset (dx, dy) from the centre sits at
//! (dx, dy, sqrt(R^2 - dx^2 - dy^2)) on the sphere.

use nalgebra::{Matrix3, Rotation3, Vector3};

/// The rotation R minimising sum |R a_i - b_i|^2 over proper rotations (Wahba's problem), by the
/// SVD of H = sum a_i b_i^T with the determinant correction (Kabsch 1976, Acta Cryst. A32, 922;
/// Umeyama 1991). Needs two non-parallel pairs; `None` otherwise.
///
/// A note on checking: nalgebra's `angle_to` goes through acos and resolves only ~1e-8 near
/// zero; the tests compare matrices instead.
pub fn kabsch(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> Option<Rotation3<f64>> {
    if a.len() != b.len() || a.len() < 2 {
        return None;
    }
    let mut h = Matrix3::zeros();
    for (p, q) in a.iter().zip(b) {
        h += p * q.transpose();
    }
    if a.len() == 2 {
        // Two pairs leave H of rank 2 and its third singular vectors to rounding; the cross
        // products are a third pair that a rotation also carries over, and make H full rank.
        h += a[0].cross(&a[1]) * b[0].cross(&b[1]).transpose();
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    // Two pairs give rank 2: fine (the third axis follows); rank below 2 is underdetermined.
    let mut sv: Vec<f64> = svd.singular_values.iter().copied().collect();
    sv.sort_by(|x, y| y.total_cmp(x));
    if sv[1].is_nan() || sv[1] <= 1e-9 * sv[0].max(1e-300) {
        return None;
    }
    let v = vt.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    r.iter()
        .all(|x| x.is_finite())
        .then(|| Rotation3::from_matrix_unchecked(r))
}

/// Markers of one sphere in one frame: time and unit vectors on the sphere.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerFrame {
    pub t_s: f64,
    pub dirs: Vec<Vector3<f64>>,
}

/// Lifts image markers (pixels, y up) of a disc (centre, radius) onto the unit sphere. Markers
/// beyond `max_frac` of the radius are dropped: near the limb z is ill-determined.
pub fn lift(
    centre: [f64; 2],
    radius: f64,
    markers: &[[f64; 2]],
    max_frac: f64,
) -> Vec<Vector3<f64>> {
    markers
        .iter()
        .filter_map(|m| {
            let (dx, dy) = ((m[0] - centre[0]) / radius, (m[1] - centre[1]) / radius);
            let rho2 = dx * dx + dy * dy;
            (rho2 < max_frac * max_frac).then(|| Vector3::new(dx, dy, (1.0 - rho2).sqrt()))
        })
        .collect()
}

/// A rotation found between two frames.
#[derive(Debug, Clone, PartialEq)]
pub struct PairRotation {
    pub rotation: Rotation3<f64>,
    /// Markers matched.
    pub matched: usize,
    /// Rms angle between the rotated and the observed markers, radians.
    pub rms_rad: f64,
}

fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// One-to-one matches (greedy by angle) of R a_i to b_j within `tol` radians.
fn matches(
    r: &Rotation3<f64>,
    a: &[Vector3<f64>],
    b: &[Vector3<f64>],
    tol: f64,
) -> Vec<(usize, usize, f64)> {
    let mut cand: Vec<(usize, usize, f64)> = Vec::new();
    for (i, p) in a.iter().enumerate() {
        let q = r * p;
        for (j, bj) in b.iter().enumerate() {
            let d = angle(&q, bj);
            if d < tol {
                cand.push((i, j, d));
            }
        }
    }
    cand.sort_by(|x, y| x.2.total_cmp(&y.2));
    let (mut ua, mut ub) = (vec![false; a.len()], vec![false; b.len()]);
    let mut out = Vec::new();
    for (i, j, d) in cand {
        if !ua[i] && !ub[j] {
            ua[i] = true;
            ub[j] = true;
            out.push((i, j, d));
        }
    }
    out
}

/// The rotation carrying the markers `a` of one frame to the markers `b` of the next, with the
/// correspondence unknown: every pairing of two markers in `a` with two in `b` whose angular
/// separations agree within `2 tol` is a hypothesis (Kabsch on the two pairs); each is scored by
/// how many markers it matches within `tol`, refined by Kabsch on its matches, and the one
/// matching most wins, ties going to the rotation closest to `prior` (the previous pair's, or
/// the identity) and then to the smaller residual. Needs 2 matched markers; `None` otherwise.
/// Rotations beyond about 60 degrees per frame pair are not resolvable by any such matching
/// when the markers are 60 degrees apart: the frame rate must keep up with the spin.
pub fn pair_rotation(
    a: &[Vector3<f64>],
    b: &[Vector3<f64>],
    prior: &Rotation3<f64>,
    tol: f64,
) -> Option<PairRotation> {
    if a.len() < 2 || b.len() < 2 {
        return None;
    }
    let mut hyps: Vec<Rotation3<f64>> = vec![*prior];
    for i1 in 0..a.len() {
        for i2 in i1 + 1..a.len() {
            let sa = angle(&a[i1], &a[i2]);
            for j1 in 0..b.len() {
                for j2 in 0..b.len() {
                    if j1 == j2 || (angle(&b[j1], &b[j2]) - sa).abs() > 2.0 * tol {
                        continue;
                    }
                    if let Some(r) = kabsch(&[a[i1], a[i2]], &[b[j1], b[j2]]) {
                        hyps.push(r);
                    }
                }
            }
        }
    }
    let mut best: Option<(usize, f64, f64, Rotation3<f64>)> = None;
    for r0 in hyps {
        let mut r = r0;
        let mut m = matches(&r, a, b, tol);
        // Two refinements: Kabsch on the matches, then match again.
        for _ in 0..2 {
            if m.len() < 2 {
                break;
            }
            let pa: Vec<_> = m.iter().map(|x| a[x.0]).collect();
            let pb: Vec<_> = m.iter().map(|x| b[x.1]).collect();
            match kabsch(&pa, &pb) {
                Some(rr) => r = rr,
                None => break,
            }
            m = matches(&r, a, b, tol);
        }
        if m.len() < 2 {
            continue;
        }
        let rms = (m.iter().map(|x| x.2 * x.2).sum::<f64>() / m.len() as f64).sqrt();
        let dist = r.angle_to(prior);
        let better = match &best {
            None => true,
            Some((n, d, e, _)) => {
                m.len() > *n
                    || (m.len() == *n
                        && (dist < d - 1e-6 || ((dist - d).abs() <= 1e-6 && rms < *e)))
            }
        };
        if better {
            best = Some((m.len(), dist, rms, r));
        }
    }
    best.map(|(n, _, rms, r)| PairRotation {
        rotation: r,
        matched: n,
        rms_rad: rms,
    })
}

/// The spin of one sphere in one phase.
#[derive(Debug, Clone, PartialEq)]
pub enum Spin {
    /// The full vector from 3-D rotations (two or more markers matched per frame pair).
    Full {
        w_rad_s: [f64; 3],
        /// Standard error from the scatter of the frame pairs (needs two pairs).
        err_rad_s: Option<[f64; 3]>,
        pairs: usize,
    },
    /// w_z only, from one marker's turn about the centre: assumes the spin axis is the camera
    /// axis (the only reading a single marker allows).
    ZOnly {
        wz_rad_s: f64,
        err_rad_s: Option<f64>,
        pairs: usize,
    },
    /// Not measured, and why.
    None { reason: String },
}

impl Spin {
    pub fn wz(&self) -> Option<f64> {
        match self {
            Spin::Full { w_rad_s, .. } => Some(w_rad_s[2]),
            Spin::ZOnly { wz_rad_s, .. } => Some(*wz_rad_s),
            Spin::None { .. } => None,
        }
    }
}

/// Mean and standard error of per-pair rates weighted by the pair durations.
fn weighted(rates: &[(f64, f64)]) -> (f64, Option<f64>) {
    let tw: f64 = rates.iter().map(|r| r.1).sum();
    let mean = rates.iter().map(|r| r.0 * r.1).sum::<f64>() / tw;
    if rates.len() < 2 {
        return (mean, None);
    }
    let var = rates
        .iter()
        .map(|r| r.1 * (r.0 - mean).powi(2))
        .sum::<f64>()
        / tw;
    (mean, Some((var / (rates.len() - 1) as f64).sqrt()))
}

/// The spin over one phase from consecutive frames of one sphere (sorted by time): the mean
/// rotation vector per unit time, sum theta_k / sum dt_k, over the frame pairs whose rotation
/// was found. `tol` is the matching tolerance, radians. Falls back to w_z from single markers
/// (flagged) only when no pair has two markers matched.
pub fn phase_spin(frames: &[MarkerFrame], tol: f64) -> Spin {
    if frames.len() < 2 {
        return Spin::None {
            reason: format!("{} frame(s) in the phase, a spin needs 2", frames.len()),
        };
    }
    if frames.iter().all(|f| f.dirs.is_empty()) {
        return Spin::None {
            reason: "no markers found on this sphere".into(),
        };
    }
    let mut full: Vec<([f64; 3], f64)> = Vec::new();
    let mut zonly: Vec<(f64, f64)> = Vec::new();
    let mut prior = Rotation3::identity();
    for w in frames.windows(2) {
        let dt = w[1].t_s - w[0].t_s;
        if dt.is_nan() || dt <= 0.0 {
            continue;
        }
        if let Some(p) = pair_rotation(&w[0].dirs, &w[1].dirs, &prior, tol) {
            let th = p.rotation.scaled_axis();
            full.push(([th.x, th.y, th.z], dt));
            prior = p.rotation;
        } else if w[0].dirs.len() == 1 && w[1].dirs.len() == 1 {
            let (p, q) = (w[0].dirs[0], w[1].dirs[0]);
            let turn = (p.x * q.y - p.y * q.x).atan2(p.x * q.x + p.y * q.y);
            // Beyond 60 degrees per pair a single marker cannot be followed.
            if turn.abs() < 60f64.to_radians() {
                zonly.push((turn / dt, dt));
            }
        }
    }
    if !full.is_empty() {
        let mut w = [0.0; 3];
        let mut err = Some([0.0; 3]);
        for k in 0..3 {
            let rates: Vec<(f64, f64)> = full.iter().map(|(th, dt)| (th[k] / dt, *dt)).collect();
            let (m, e) = weighted(&rates);
            w[k] = m;
            match (e, err.as_mut()) {
                (Some(e), Some(v)) => v[k] = e,
                _ => err = None,
            }
        }
        return Spin::Full {
            w_rad_s: w,
            err_rad_s: err,
            pairs: full.len(),
        };
    }
    if !zonly.is_empty() {
        let (m, e) = weighted(&zonly);
        return Spin::ZOnly {
            wz_rad_s: m,
            err_rad_s: e,
            pairs: zonly.len(),
        };
    }
    Spin::None {
        reason: "markers could not be matched between frames".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Unit;

    fn dirs() -> Vec<Vector3<f64>> {
        [
            (0.3, 0.2),
            (-0.4, 0.1),
            (0.1, -0.5),
            (-0.2, -0.3),
            (0.5, 0.45),
        ]
        .iter()
        .map(|&(x, y)| Vector3::new(x, y, (1.0f64 - x * x - y * y).sqrt()))
        .collect()
    }

    // A known rotation: Kabsch must return it to rounding (1e-12 on unit vectors).
    #[test]
    fn kabsch_recovers_a_known_rotation() {
        let axis = Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
        let r = Rotation3::from_axis_angle(&axis, 0.37);
        let a = dirs();
        let b: Vec<_> = a.iter().map(|p| r * p).collect();
        let got = kabsch(&a, &b).unwrap();
        assert!((got.matrix() - r.matrix()).norm() < 1e-12);
        // Two pairs suffice.
        let got2 = kabsch(&a[..2], &b[..2]).unwrap();
        assert!((got2.matrix() - r.matrix()).norm() < 1e-12);
        // Parallel pairs do not.
        assert!(kabsch(&[a[0], a[0]], &[b[0], b[0]]).is_none());
    }

    #[test]
    fn matching_with_unknown_order_and_a_missing_marker() {
        let axis = Unit::new_normalize(Vector3::new(0.1, 0.2, 1.0));
        let r = Rotation3::from_axis_angle(&axis, 0.2);
        let a = dirs();
        // b: rotated, shuffled, one marker gone (over the limb), one new one appeared.
        let mut b: Vec<_> = a.iter().skip(1).map(|p| r * p).collect();
        b.reverse();
        b.push(Vector3::new(-0.6, 0.6, (1.0f64 - 0.72).sqrt()));
        let p = pair_rotation(&a, &b, &Rotation3::identity(), 0.03).unwrap();
        assert_eq!(p.matched, 4);
        assert!((p.rotation.matrix() - r.matrix()).norm() < 1e-12);
    }

    // A constant spin w over frames at unequal intervals: the phase spin is w to rounding.
    #[test]
    fn phase_spin_of_a_steady_rotation() {
        let w = Vector3::new(12.0, -30.0, 55.0);
        let a = dirs();
        let times = [0.0, 0.001, 0.002, 0.004, 0.005];
        let frames: Vec<MarkerFrame> = times
            .iter()
            .map(|&t| MarkerFrame {
                t_s: t,
                dirs: a
                    .iter()
                    .map(|p| Rotation3::from_scaled_axis(w * t) * p)
                    .collect(),
            })
            .collect();
        match phase_spin(&frames, 0.05) {
            Spin::Full {
                w_rad_s,
                err_rad_s,
                pairs,
            } => {
                assert_eq!(pairs, 4);
                for k in 0..3 {
                    assert!((w_rad_s[k] - w[k]).abs() < 1e-8, "{w_rad_s:?}");
                    assert!(err_rad_s.unwrap()[k] < 1e-8);
                }
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn single_markers_give_z_only_and_none_says_why() {
        let wz = 40.0;
        let frames: Vec<MarkerFrame> = (0..4)
            .map(|k| {
                let t = k as f64 * 0.001;
                let ang = 0.3 + wz * t;
                MarkerFrame {
                    t_s: t,
                    dirs: vec![Vector3::new(
                        0.5 * ang.cos(),
                        0.5 * ang.sin(),
                        0.75f64.sqrt(),
                    )],
                }
            })
            .collect();
        match phase_spin(&frames, 0.05) {
            Spin::ZOnly { wz_rad_s, .. } => assert!((wz_rad_s - wz).abs() < 1e-9),
            other => panic!("{other:?}"),
        }
        let empty = vec![
            MarkerFrame {
                t_s: 0.0,
                dirs: vec![]
            };
            3
        ];
        assert!(matches!(phase_spin(&empty, 0.05), Spin::None { .. }));
        assert!(matches!(phase_spin(&frames[..1], 0.05), Spin::None { .. }));
    }

    #[test]
    fn lift_puts_markers_on_the_unit_sphere() {
        let v = lift(
            [10.0, 20.0],
            5.0,
            &[[12.0, 21.5], [10.0, 20.0], [14.9, 20.0]],
            0.9,
        );
        assert_eq!(v.len(), 2);
        assert!((v[0] - Vector3::new(0.4, 0.3, 0.75f64.sqrt())).norm() < 1e-12);
        assert!((v[1] - Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
    }
}
