//! Measured coefficients of restitution, ready for fitting: one [`Observation`] per collision,
//! with the Hertz contact of its pair derived once (docs/physics.md §1).
//!
//! Pure data: no file reading here (that is the I/O layer's `data::fit_input`), so that the kinematics pipeline and
//! the benchmarks can build a [`FitData`] from numbers they already hold.

use super::objective::{ERROR_PER_ACCURACY, MASTER_ACCURACY};
use crate::contact::{Contact, Material, Pair, Sphere};
use crate::error::{Error, Result};

/// A hash map keyed by numbers' bits, with a fast fixed-seed hash (std's SipHash guards against
/// chosen keys, which a data file cannot exploit here; it cost more than the merge itself).
type BitsMap<K, V> = std::collections::HashMap<K, V, foldhash::fast::FixedState>;

/// One measured collision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Diameter of the (first) sphere, mm.
    pub d_mm: f64,
    /// Diameter of the second sphere, mm: `None` for identical spheres, `Some(f64::INFINITY)` for
    /// a flat wall (of the same material).
    pub d2_mm: Option<f64>,
    /// Normal impact speed, m/s.
    pub v_n_m_s: f64,
    /// Measured coefficient of restitution.
    pub e: f64,
    /// One-sigma error of `e`; `None` when the data carry no error information.
    pub e_err: Option<f64>,
}

/// A group of observations of one pair geometry (one colour and marker in the figures).
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    pub d_mm: f64,
    pub d2_mm: Option<f64>,
    /// Row indices into [`FitData::obs`].
    pub indices: Vec<usize>,
}

impl Group {
    /// "6.35 mm", "12.7 mm on wall", "6.35 mm on 25.4 mm".
    pub fn label(&self) -> String {
        match self.d2_mm {
            None => format!("{} mm", self.d_mm),
            Some(d2) if d2.is_infinite() => format!("{} mm on wall", self.d_mm),
            Some(d2) => format!("{} mm on {} mm", self.d_mm, d2),
        }
    }
}

/// The data of a fit: the material, the observations, and each observation's contact.
#[derive(Debug, Clone)]
pub struct FitData {
    pub material: Material,
    pub obs: Vec<Observation>,
    /// Contact of each observation's pair (same order as `obs`).
    pub contacts: Vec<Contact>,
    /// True when every observation has an error; false when none has (unweighted fit).
    pub weighted: bool,
}

/// `x > 0` fails, NaN included.
fn not_positive(x: f64) -> bool {
    x.is_nan() || x <= 0.0
}

fn bad(name: &'static str, value: f64, expected: &'static str) -> Error {
    Error::InvalidParameter {
        name,
        value,
        expected,
    }
}

/// The contact of a pair of the given material (docs/physics.md §1): identical spheres, unequal
/// spheres, or a sphere on a wall when `d2_mm` is infinite.
pub fn pair_contact(material: Material, d_mm: f64, d2_mm: Option<f64>) -> Result<Contact> {
    let s1 = Sphere::new(d_mm * 1e-3, material)?;
    let pair = match d2_mm {
        None => Pair::identical(s1),
        Some(d2) if d2 == f64::INFINITY => Pair::on_wall(s1, material),
        Some(d2) => Pair::unequal(s1, Sphere::new(d2 * 1e-3, material)?),
    };
    pair.try_contact()
}

/// The smallest error of e a row may have: [`super::objective::ERROR_PER_ACCURACY`] times the
/// accuracy of e computed with the master curve, 5e-11 (see there why).
pub const E_ERR_MIN: f64 = ERROR_PER_ACCURACY * MASTER_ACCURACY;

/// The largest error of e a row may have. The search weighs each point by 1/sigma^2 and the
/// polishes by its residual divided by sigma: beyond about 1e154, 1/sigma^2 underflows to 0, and
/// the two disagreed (a row with e = 1e300 and sigma_e = 1.1e299 added 81 to the polishes' chi2
/// and nothing to the search's). 1e100 keeps every weight a normal double, far beyond any
/// measurement of e.
pub const E_ERR_MAX: f64 = 1e100;

impl FitData {
    /// Validates the observations (d > 0, v_n > 0, e >= 0 finite, e_err from [`E_ERR_MIN`] to
    /// [`E_ERR_MAX`], either every row has an error or none has) and derives each pair's
    /// contact.
    pub fn new(material: Material, obs: Vec<Observation>) -> Result<FitData> {
        if obs.is_empty() {
            return Err(bad("number of observations", 0.0, "at least one"));
        }
        let with_err = obs.iter().filter(|o| o.e_err.is_some()).count();
        if with_err != 0 && with_err != obs.len() {
            return Err(bad(
                "number of observations with an error",
                with_err as f64,
                "all or none",
            ));
        }
        let check = |o: &Observation| -> Result<Contact> {
            if !(o.v_n_m_s.is_finite() && o.v_n_m_s > 0.0) {
                return Err(bad("v_n (m/s)", o.v_n_m_s, "a finite number > 0"));
            }
            if !(o.e.is_finite() && o.e >= 0.0) {
                return Err(bad("e", o.e, "a finite number >= 0"));
            }
            if let Some(s) = o.e_err
                && !(E_ERR_MIN..=E_ERR_MAX).contains(&s)
            {
                return Err(bad(
                    "e_err",
                    s,
                    "a number from 5e-11 (1000 times the accuracy e is computed to: below it the \
                     residual would be rounding) to 1e100 (beyond it the weight 1/e_err^2 \
                     underflows)",
                ));
            }
            if let Some(d2) = o.d2_mm
                && not_positive(d2)
            {
                return Err(bad("d2 (mm)", d2, "a number > 0, or infinity for a wall"));
            }
            pair_contact(material, o.d_mm, o.d2_mm)
        };
        // Large data on all cores (the fit's start is serial); the first failing row's error
        // either way (rayon's own collect into a Result would return whichever it met first).
        let contacts = if super::sums::is_large(obs.len()) {
            use rayon::prelude::*;
            let each: Vec<Result<Contact>> = obs.par_iter().map(check).collect();
            each.into_iter().collect::<Result<Vec<_>>>()?
        } else {
            obs.iter().map(check).collect::<Result<Vec<_>>>()?
        };
        Ok(FitData {
            material,
            obs,
            contacts,
            weighted: with_err != 0,
        })
    }

    pub fn len(&self) -> usize {
        self.obs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.obs.is_empty()
    }

    /// The sigma of row `i` in chi2: its error, or 1 for an unweighted fit.
    pub fn sigma(&self, i: usize) -> f64 {
        self.obs[i].e_err.unwrap_or(1.0)
    }

    /// The distinct pair geometries, in order of first appearance sorted by diameter.
    pub fn groups(&self) -> Vec<Group> {
        // Indexed by the diameters' bits (diameters are finite and > 0, or a wall's inf, so equal
        // bits are equal values): a search through the groups so far made 100 000 rows of
        // distinct sizes take seconds.
        let mut groups: Vec<Group> = Vec::new();
        let mut index: BitsMap<(u64, Option<u64>), usize> = BitsMap::default();
        for (i, o) in self.obs.iter().enumerate() {
            let key = (o.d_mm.to_bits(), o.d2_mm.map(f64::to_bits));
            match index.get(&key) {
                Some(&g) => groups[g].indices.push(i),
                None => {
                    index.insert(key, groups.len());
                    groups.push(Group {
                        d_mm: o.d_mm,
                        d2_mm: o.d2_mm,
                        indices: vec![i],
                    });
                }
            }
        }
        groups.sort_by(|a, b| {
            a.d_mm
                .total_cmp(&b.d_mm)
                .then(a.d2_mm.unwrap_or(0.0).total_cmp(&b.d2_mm.unwrap_or(0.0)))
        });
        groups
    }

    /// Distinct diameters of every sphere of the pairs (the second sphere's too: a wall is not a
    /// sphere), ascending, mm: the sizes a simulation of the measured scene holds.
    pub fn diameters_mm(&self) -> Vec<f64> {
        let mut d: Vec<f64> = self
            .obs
            .iter()
            .flat_map(|o| [Some(o.d_mm), o.d2_mm.filter(|d2| d2.is_finite())])
            .flatten()
            .collect();
        d.sort_by(f64::total_cmp);
        d.dedup();
        d
    }

    /// Whether some rows are a sphere on a wall.
    pub fn on_wall(&self) -> bool {
        self.obs
            .iter()
            .any(|o| o.d2_mm.is_some_and(f64::is_infinite))
    }

    /// Whether every row is a pair of identical spheres.
    pub fn identical_pairs(&self) -> bool {
        self.obs
            .iter()
            .all(|o| o.d2_mm.is_none_or(|d2| d2 == o.d_mm))
    }
}

/// The data with every set of rows that share a pair geometry and a speed merged into one point
/// (see [`FitData::merge_repeats`]).
#[derive(Debug, Clone)]
pub struct Merged {
    /// One observation per distinct (d, d2, v_n): e is the rows' weighted mean and e_err
    /// 1/sqrt(sum of weights); `weighted` is that of the rows.
    pub data: FitData,
    /// Rows before merging.
    pub rows: usize,
    /// sum_i w_i (e_i - e_mean)^2 over the rows, the part of chi2 no parameter can change.
    pub chi2_offset: f64,
    /// The merged point of each row.
    pub point_of_row: Vec<usize>,
    /// The first row of each merged point (to name it in messages).
    pub first_row: Vec<usize>,
}

/// What makes two rows repeats: the same pair geometry and speed, to the bit (a wall, no second
/// size, differs from every second size).
fn repeat_key(o: &Observation) -> [u64; 4] {
    [
        o.d_mm.to_bits(),
        u64::from(o.d2_mm.is_some()),
        o.d2_mm.map_or(0, f64::to_bits),
        o.v_n_m_s.to_bits(),
    ]
}

/// Whether no two rows share a pair geometry and a speed (to the bit), from the rows' keys
/// sorted: large files of measured speeds usually have no repeats, and a sort (on all cores for
/// large data) finds that in a few milliseconds on 100 000 rows, where filling the merge's hash
/// map (5 MB, a cache miss per row) took 10 to 35 on the fit's serial start.
fn all_distinct(obs: &[Observation]) -> bool {
    let mut keys: Vec<[u64; 4]> = obs.iter().map(repeat_key).collect();
    if super::sums::is_large(keys.len()) {
        use rayon::prelude::*;
        keys.par_sort_unstable();
    } else {
        keys.sort_unstable();
    }
    keys.windows(2).all(|w| w[0] != w[1])
}

impl FitData {
    /// Merges rows that share a pair geometry and a speed, or `None` when no two rows do (or when
    /// the merged weights would not be finite: the rows are then fitted as they are).
    ///
    /// Exact, because sigma does not depend on the parameters: for rows i of one point, with
    /// w_i = 1/sigma_i^2, W = sum w_i and the weighted mean m,
    /// sum w_i (e_i - f)^2 = W (m - f)^2 + sum w_i (e_i - m)^2, so chi2 over the rows is chi2
    /// over the merged points (sigma = 1/sqrt(W)) plus a constant: the same minimum, Jacobian
    /// products, profiles and differences of chi2. Repeated launches at one nominal speed make
    /// such data; so do files of repeated rows, which would otherwise cost the fit their count.
    pub fn merge_repeats(&self) -> Option<Merged> {
        if all_distinct(&self.obs) {
            return None;
        }
        // Sized for every row at once: growing by rehashing cost more than the merge itself.
        let mut index: BitsMap<_, usize> =
            BitsMap::with_capacity_and_hasher(self.obs.len(), Default::default());
        let mut point_of_row = Vec::with_capacity(self.obs.len());
        let mut first_row = Vec::new();
        for (i, o) in self.obs.iter().enumerate() {
            let next = first_row.len();
            let p = *index.entry(repeat_key(o)).or_insert(next);
            if p == next {
                first_row.push(i);
            }
            point_of_row.push(p);
        }
        let m = first_row.len();
        if m == self.obs.len() {
            return None;
        }
        let mut w_sum = vec![0.0; m];
        let mut we_sum = vec![0.0; m];
        for (i, &p) in point_of_row.iter().enumerate() {
            let w = self.sigma(i).powi(-2);
            w_sum[p] += w;
            we_sum[p] += w * self.obs[i].e;
        }
        let mean: Vec<f64> = (0..m).map(|p| we_sum[p] / w_sum[p]).collect();
        let mut chi2_offset = 0.0;
        for (i, &p) in point_of_row.iter().enumerate() {
            chi2_offset += self.sigma(i).powi(-2) * (self.obs[i].e - mean[p]).powi(2);
        }
        let sigma: Vec<f64> = w_sum.iter().map(|w| w.sqrt().recip()).collect();
        let finite = |x: &f64| x.is_finite();
        if !(mean.iter().all(finite)
            && sigma.iter().all(|s| s.is_finite() && *s > 0.0)
            && chi2_offset.is_finite())
        {
            return None;
        }
        let obs = (0..m)
            .map(|p| Observation {
                e: mean[p],
                e_err: Some(sigma[p]),
                ..self.obs[first_row[p]]
            })
            .collect();
        let contacts = first_row.iter().map(|&i| self.contacts[i]).collect();
        Some(Merged {
            data: FitData {
                material: self.material,
                obs,
                contacts,
                weighted: self.weighted,
            },
            rows: self.obs.len(),
            chi2_offset,
            point_of_row,
            first_row,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obs(d_mm: f64, e_err: Option<f64>) -> Observation {
        Observation {
            d_mm,
            d2_mm: None,
            v_n_m_s: 1.0,
            e: 0.9,
            e_err,
        }
    }

    /// The sorted keys' test of repeats agrees with the merge's own: a repeat anywhere in the
    /// rows (and of a pair's second size), on small and large data; a wall (no second size)
    /// is not the pair with any second size.
    #[test]
    fn repeats_are_found_wherever_they_are() {
        let m = Material::preset("nylon").unwrap();
        for n in [5, super::super::sums::PARALLEL_MIN_POINTS + 7] {
            let rows = |k: usize| {
                let mut o = obs(1.0 + (k % 3) as f64, Some(0.01));
                o.v_n_m_s = 1.0 + k as f64 * 1e-3;
                o.d2_mm = (k % 2 == 0).then_some(4.0);
                o
            };
            let mut v: Vec<Observation> = (0..n).map(rows).collect();
            assert!(all_distinct(&v), "{n}");
            assert!(
                FitData::new(m, v.clone())
                    .unwrap()
                    .merge_repeats()
                    .is_none()
            );
            // The same point again far from the first (e differs: still a repeat).
            let mut again = v[1];
            again.e = 0.5;
            v.insert(n - 2, again);
            assert!(!all_distinct(&v), "{n}");
            let merged = FitData::new(m, v.clone()).unwrap().merge_repeats().unwrap();
            assert_eq!(merged.data.len(), n);
            // Only the second size differs: distinct.
            v.remove(n - 2);
            let mut other = v[1];
            other.d2_mm = Some(4.0);
            assert_ne!(other.d2_mm, v[1].d2_mm);
            v.push(other);
            assert!(all_distinct(&v), "{n}");
        }
    }

    /// Large data are checked on all cores, and the error is still the first failing row's.
    #[test]
    fn the_first_bad_row_is_reported_at_every_size() {
        let m = Material::preset("nylon").unwrap();
        for n in [10, super::super::sums::PARALLEL_MIN_POINTS + 3] {
            let mut v: Vec<Observation> = (0..n).map(|_| obs(1.0, None)).collect();
            v[n - 1].e = -1.0;
            v[n / 2].v_n_m_s = f64::NAN;
            let e = FitData::new(m, v.clone()).unwrap_err().to_string();
            assert!(e.starts_with("invalid v_n (m/s) = NaN"), "{n}: {e}");
            v[n / 2].v_n_m_s = 1.0;
            let e = FitData::new(m, v).unwrap_err().to_string();
            assert!(e.starts_with("invalid e = -1"), "{n}: {e}");
        }
    }

    #[test]
    fn validates_and_groups() {
        let m = Material::preset("nylon").unwrap();
        assert!(FitData::new(m, vec![]).is_err());
        assert!(FitData::new(m, vec![obs(1.0, Some(0.1)), obs(2.0, None)]).is_err());
        assert!(FitData::new(m, vec![obs(1.0, Some(0.0))]).is_err());
        assert!(FitData::new(m, vec![obs(-1.0, None)]).is_err());
        let mut wall = obs(2.0, None);
        wall.d2_mm = Some(f64::INFINITY);
        let d = FitData::new(
            m,
            vec![obs(2.0, None), obs(1.0, None), wall, obs(2.0, None)],
        )
        .unwrap();
        assert!(!d.weighted);
        let g = d.groups();
        assert_eq!(g.len(), 3);
        assert_eq!(g[0].label(), "1 mm");
        assert_eq!(g[1].indices, vec![0, 3]);
        assert_eq!(g[2].label(), "2 mm on wall");
        assert_eq!(d.diameters_mm(), vec![1.0, 2.0]);
        assert!(d.on_wall() && !d.identical_pairs());
        // The second sphere of an unequal pair is a size of the scene too.
        let mut unequal = obs(1.0, None);
        unequal.d2_mm = Some(3.0);
        let u = FitData::new(m, vec![unequal, obs(1.0, None)]).unwrap();
        assert_eq!(u.diameters_mm(), vec![1.0, 3.0]);
        assert!(!u.on_wall() && !u.identical_pairs());
        let mut same = obs(2.0, None);
        same.d2_mm = Some(2.0);
        assert!(
            FitData::new(m, vec![same, obs(1.0, None)])
                .unwrap()
                .identical_pairs()
        );
        // A wall's contact has R~ = R_1 (docs/physics.md §1).
        assert_eq!(d.contacts[2].r_eff_m, 1e-3);
    }
}
