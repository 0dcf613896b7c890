//! The contacts of a simulated scene: one atom type per sphere size, every pair of types, and the
//! sphere-wall contacts.

use crate::contact::{Contact, Material, Pair, Sphere};
use crate::error::{Error, Result};

/// Most sphere sizes a scene may have: 32 types make 528 pairs, already more than anyone writes
/// by hand; beyond that the engine needs a size distribution, which one eta cannot give (module
/// note of [`super::engines`]).
pub const MAX_SIZES: usize = 32;

/// A scene: one material, the sphere diameters (one engine atom type each, in the order given),
/// and whether spheres also hit flat walls of the same material.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub material: Material,
    pub diameters_m: Vec<f64>,
    pub wall: bool,
}

/// One contact of a scene: types `i` and `j` (0-based; `j` = None for the wall) and its Hertz
/// quantities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScenePair {
    pub i: usize,
    pub j: Option<usize>,
    pub d_i_m: f64,
    pub d_j_m: Option<f64>,
    pub contact: Contact,
}

impl Scene {
    /// Validates the diameters (1 to [`MAX_SIZES`], each from 1 um to 10 m, no repeats).
    pub fn new(material: Material, diameters_m: Vec<f64>, wall: bool) -> Result<Self> {
        if diameters_m.is_empty() || diameters_m.len() > MAX_SIZES {
            return Err(Error::InvalidParameter {
                name: "number of sphere sizes",
                value: diameters_m.len() as f64,
                expected: "1 to 32 sizes",
            });
        }
        for (k, &d) in diameters_m.iter().enumerate() {
            Sphere::new(d, material)?;
            // Hertz contacts of DEM spheres; far outside, K, m_red and kappa over- or underflow.
            if !(1e-6..=10.0).contains(&d) {
                return Err(Error::InvalidParameter {
                    name: "sphere diameter (m)",
                    value: d,
                    expected: "a diameter from 1e-6 to 10 m",
                });
            }
            if diameters_m[..k].contains(&d) {
                return Err(Error::InvalidParameter {
                    name: "sphere diameter (m), given twice",
                    value: d,
                    expected: "each size once",
                });
            }
        }
        Ok(Scene {
            material,
            diameters_m,
            wall,
        })
    }

    /// Every pair of types i <= j, then each type on the wall.
    pub fn pairs(&self) -> Vec<ScenePair> {
        let m = self.material;
        let sphere = |d: f64| Sphere {
            d_m: d,
            material: m,
        };
        let n = self.diameters_m.len();
        let mut out = Vec::new();
        for i in 0..n {
            for j in i..n {
                let (di, dj) = (self.diameters_m[i], self.diameters_m[j]);
                out.push(ScenePair {
                    i,
                    j: Some(j),
                    d_i_m: di,
                    d_j_m: Some(dj),
                    contact: Pair::unequal(sphere(di), sphere(dj)).contact(),
                });
            }
        }
        if self.wall {
            for (i, &d) in self.diameters_m.iter().enumerate() {
                out.push(ScenePair {
                    i,
                    j: None,
                    d_i_m: d,
                    d_j_m: None,
                    contact: Pair::on_wall(sphere(d), m).contact(),
                });
            }
        }
        out
    }
}

impl ScenePair {
    /// "1-2" for types 1 and 2, "1-wall" for type 1 on the wall (1-based, as engines number them).
    pub fn label(&self) -> String {
        match self.j {
            Some(j) => format!("{}-{}", self.i + 1, j + 1),
            None => format!("{}-wall", self.i + 1),
        }
    }
}
