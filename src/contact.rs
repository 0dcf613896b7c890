//! Materials, collision pairs and the derived Hertz contact quantities (docs/physics.md §1).
//!
//! Everything downstream is built on four numbers of a [`Contact`]: the effective modulus E*,
//! the effective radius R~, the reduced mass m_red and the Hertz stiffness K = (4/3) E* R~^(1/2).
//! Identical spheres, unequal spheres and a sphere on a flat wall differ only in how these are
//! formed, so every model works for all three.
//!
//! **Range.** Every derived quantity (E*, R~, m_red, K, kappa, V_Y) is either a normal, finite,
//! positive f64 or an [`Error::OutOfRange`] naming the inputs it came from: the `try_` methods
//! check; the plain ones (kept for callers that validated their inputs) do not.

use crate::error::{Error, Num, Result, in_range, positive};
use crate::models::fp;
use std::f64::consts::PI;

/// An isotropic elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub youngs_pa: f64,
    pub poisson: f64,
    pub density_kg_m3: f64,
}

/// Named materials. `nylon` is the paper's (Labous et al. 1997, Sec. IV); the others are typical
/// handbook values, given so that a user can try the tool on a familiar material.
pub const PRESETS: &[(&str, Material)] = &[
    (
        "nylon",
        Material {
            youngs_pa: 3.5e8,
            poisson: 0.3,
            density_kg_m3: 1140.0,
        },
    ),
    (
        "steel",
        Material {
            youngs_pa: 2.1e11,
            poisson: 0.29,
            density_kg_m3: 7850.0,
        },
    ),
    (
        "glass",
        Material {
            youngs_pa: 6.3e10,
            poisson: 0.23,
            density_kg_m3: 2500.0,
        },
    ),
    (
        "aluminium",
        Material {
            youngs_pa: 7.0e10,
            poisson: 0.33,
            density_kg_m3: 2700.0,
        },
    ),
];

impl Material {
    /// Validates and builds a material: Y > 0, rho > 0, -1 < nu < 0.5, all finite.
    pub fn new(youngs_pa: f64, poisson: f64, density_kg_m3: f64) -> Result<Self> {
        positive("Young's modulus (Pa)", youngs_pa)?;
        positive("density (kg/m^3)", density_kg_m3)?;
        if !(poisson.is_finite() && poisson > -1.0 && poisson < 0.5) {
            return Err(Error::InvalidParameter {
                name: "Poisson ratio",
                value: poisson,
                expected: "a number in (-1, 0.5)",
            });
        }
        Ok(Material {
            youngs_pa,
            poisson,
            density_kg_m3,
        })
    }

    /// Looks up a preset by name (case-insensitive).
    pub fn preset(name: &str) -> Option<Self> {
        PRESETS
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, m)| *m)
    }

    /// The paper's modulus E = Y / (3 (1 - nu^2)) (text below Eq. 10).
    pub fn paper_modulus_pa(&self) -> f64 {
        self.youngs_pa / (3.0 * (1.0 - self.poisson * self.poisson))
    }

    /// Compliance (1 - nu^2)/Y, this material's share of 1/E*.
    fn compliance(&self) -> f64 {
        (1.0 - self.poisson * self.poisson) / self.youngs_pa
    }
}

/// A homogeneous sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub d_m: f64,
    pub material: Material,
}

impl Sphere {
    pub fn new(d_m: f64, material: Material) -> Result<Self> {
        positive("diameter (m)", d_m)?;
        Ok(Sphere { d_m, material })
    }

    pub fn radius_m(&self) -> f64 {
        0.5 * self.d_m
    }

    /// m = (pi/6) d^3 rho.
    pub fn mass_kg(&self) -> f64 {
        PI / 6.0 * self.d_m.powi(3) * self.material.density_kg_m3
    }
}

/// What the first sphere hits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Partner {
    Sphere(Sphere),
    /// A flat, immovable wall of the given material.
    Wall(Material),
}

/// A colliding pair: identical spheres, unequal spheres, or a sphere on a wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair {
    pub sphere: Sphere,
    pub partner: Partner,
}

impl Pair {
    pub fn identical(sphere: Sphere) -> Self {
        Pair {
            sphere,
            partner: Partner::Sphere(sphere),
        }
    }

    pub fn unequal(first: Sphere, second: Sphere) -> Self {
        Pair {
            sphere: first,
            partner: Partner::Sphere(second),
        }
    }

    pub fn on_wall(sphere: Sphere, wall: Material) -> Self {
        Pair {
            sphere,
            partner: Partner::Wall(wall),
        }
    }

    /// The derived contact quantities of this pair, each checked to be a normal, finite, positive
    /// f64 (a 1e-110 m sphere has mass 0 in f64; a subnormal modulus makes E* infinite).
    pub fn try_contact(&self) -> Result<Contact> {
        let c = self.contact();
        let describe = || self.describe();
        in_range("E* (Pa)", c.e_star_pa, describe)?;
        in_range("R~ (m)", c.r_eff_m, describe)?;
        in_range("m_red (kg)", c.m_red_kg, describe)?;
        in_range("K = (4/3) E* R~^(1/2) (N/m^1.5)", c.hertz_k(), describe)?;
        Ok(c)
    }

    /// The inputs, for error messages.
    fn describe(&self) -> String {
        let m = |m: &Material| {
            format!(
                "Y = {} Pa, nu = {}, rho = {} kg/m^3",
                Num(m.youngs_pa),
                Num(m.poisson),
                Num(m.density_kg_m3)
            )
        };
        let s1 = &self.sphere;
        let first = format!("d = {} m, {}", Num(s1.d_m), m(&s1.material));
        match &self.partner {
            Partner::Sphere(s2) if s2 == s1 => format!("identical spheres of {first}"),
            Partner::Sphere(s2) => format!(
                "spheres of {first} and d2 = {} m, {}",
                Num(s2.d_m),
                m(&s2.material)
            ),
            Partner::Wall(w) => format!("a sphere of {first} on a wall of {}", m(w)),
        }
    }

    /// The derived contact quantities of this pair, unchecked (see [`Pair::try_contact`]).
    pub fn contact(&self) -> Contact {
        let s1 = &self.sphere;
        let (inv_r2, compliance2, inv_m2) = match &self.partner {
            Partner::Sphere(s2) => (
                1.0 / s2.radius_m(),
                s2.material.compliance(),
                1.0 / s2.mass_kg(),
            ),
            Partner::Wall(w) => (0.0, w.compliance(), 0.0),
        };
        let e_star_pa = 1.0 / (s1.material.compliance() + compliance2);
        let r_eff_m = 1.0 / (1.0 / s1.radius_m() + inv_r2);
        let m_red_kg = 1.0 / (1.0 / s1.mass_kg() + inv_m2);
        Contact {
            e_star_pa,
            r_eff_m,
            m_red_kg,
        }
    }
}

/// The Hertz contact of a pair (docs/physics.md §1). SI units throughout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// 1/E* = (1 - nu_1^2)/Y_1 + (1 - nu_2^2)/Y_2.
    pub e_star_pa: f64,
    /// 1/R~ = 1/R_1 + 1/R_2 (wall: R~ = R_1).
    pub r_eff_m: f64,
    /// m_red = m_1 m_2/(m_1 + m_2) (wall: m_1).
    pub m_red_kg: f64,
}

impl Contact {
    /// A contact from its three numbers, each checked to be a normal, finite, positive f64.
    pub fn new(e_star_pa: f64, r_eff_m: f64, m_red_kg: f64) -> Result<Contact> {
        positive("E* (Pa)", e_star_pa)?;
        positive("R~ (m)", r_eff_m)?;
        positive("m_red (kg)", m_red_kg)?;
        let c = Contact {
            e_star_pa,
            r_eff_m,
            m_red_kg,
        };
        let describe = || c.describe();
        for (name, v) in [
            ("E* (Pa)", e_star_pa),
            ("R~ (m)", r_eff_m),
            ("m_red (kg)", m_red_kg),
            ("K = (4/3) E* R~^(1/2) (N/m^1.5)", c.hertz_k()),
        ] {
            in_range(name, v, describe)?;
        }
        Ok(c)
    }

    fn describe(&self) -> String {
        format!(
            "E* = {} Pa, R~ = {} m, m_red = {} kg",
            Num(self.e_star_pa),
            Num(self.r_eff_m),
            Num(self.m_red_kg)
        )
    }

    /// Hertz stiffness K in P_el = K delta^(3/2): K = (4/3) E* R~^(1/2) (Eq. B1 for identical spheres,
    /// where it equals E d^(1/2) with the paper's E).
    pub fn hertz_k(&self) -> f64 {
        4.0 / 3.0 * self.e_star_pa * self.r_eff_m.sqrt()
    }

    /// Elastic force P_el(delta) = K delta^(3/2), newtons.
    pub fn hertz_force_n(&self, delta_m: f64) -> f64 {
        self.hertz_k() * delta_m.max(0.0).powf(1.5)
    }

    /// Damping coefficient C of the viscoelastic force C delta^(1/2) delta_dot (Eq. 9):
    /// C = 4 eta R~^(1/2), which is the paper's 2 eta d^(1/2) for identical spheres (R~ = d/4).
    pub fn damping_c(&self, eta: f64) -> f64 {
        4.0 * eta * self.r_eff_m.sqrt()
    }

    /// Brilliantov et al.'s dissipative constant A = 2C/(3K), seconds (docs/physics.md §2).
    pub fn brilliantov_a_s(&self, eta: f64) -> f64 {
        2.0 * self.damping_c(eta) / (3.0 * self.hertz_k())
    }

    /// Inverse of [`Contact::brilliantov_a_s`]: eta = 3 K A / (2 C/eta).
    pub fn eta_from_brilliantov_a(&self, a_s: f64) -> f64 {
        3.0 * self.hertz_k() * a_s / (2.0 * 4.0 * self.r_eff_m.sqrt())
    }

    /// Time scale of the dimensionless master equation, T = k^(-2/5) V^(-1/5), k = K/m_red.
    pub fn time_scale_s(&self, v_m_s: f64) -> f64 {
        let k = self.hertz_k() / self.m_red_kg;
        k.powf(-0.4) * v_m_s.powf(-0.2)
    }

    /// Dimensionless damping kappa = c k^(-3/5) V^(1/5) with c = C/m_red, k = K/m_red
    /// (docs/physics.md §2; the paper's Eq. 11 prints the powers of rho and E inverted).
    pub fn kappa(&self, eta: f64, v_m_s: f64) -> f64 {
        let k = self.hertz_k() / self.m_red_kg;
        let c = self.damping_c(eta) / self.m_red_kg;
        c * k.powf(-0.6) * v_m_s.powf(0.2)
    }

    /// [`Contact::kappa`], checked: eta >= 0 and v > 0 finite, and kappa a finite f64 that is 0
    /// (eta = 0) or normal; otherwise an error naming eta, v and the contact.
    pub fn try_kappa(&self, eta: f64, v_m_s: f64) -> Result<f64> {
        crate::error::non_negative("damping eta (kg/(s m))", eta)?;
        positive("impact speed (m/s)", v_m_s)?;
        // kappa is linear in eta: check the per-unit-eta factor, then the product.
        let per_eta = self.kappa(1.0, v_m_s);
        let cause = || {
            format!(
                "eta = {} kg/(s m), v = {} m/s, {}",
                Num(eta),
                Num(v_m_s),
                self.describe()
            )
        };
        in_range("kappa per unit eta (s m/kg)", per_eta, cause)?;
        if eta == 0.0 {
            return Ok(0.0);
        }
        in_range("kappa", eta * per_eta, cause)
    }

    /// [`Contact::time_scale_s`], checked.
    pub fn try_time_scale_s(&self, v_m_s: f64) -> Result<f64> {
        positive("impact speed (m/s)", v_m_s)?;
        in_range("time scale T (s)", self.time_scale_s(v_m_s), || {
            format!("v = {} m/s, {}", Num(v_m_s), self.describe())
        })
    }

    /// The eta that gives dimensionless damping `kappa` at impact speed `v_m_s` (inverse of [`Contact::kappa`]).
    pub fn eta_for_kappa(&self, kappa: f64, v_m_s: f64) -> f64 {
        kappa / self.kappa(1.0, v_m_s)
    }

    /// Overlap at which the Hertz centre pressure 3P/(2 pi a^2) reaches sigma_y:
    /// delta_y = (pi sigma_y / (2 E*))^2 R~ (Eq. B2 for identical spheres).
    pub fn yield_overlap_m(&self, sigma_y_pa: f64) -> f64 {
        (PI * sigma_y_pa / (2.0 * self.e_star_pa)).powi(2) * self.r_eff_m
    }

    /// Elastic work up to yield, W_y = (2/5) K delta_y^(5/2) (the paper's Appendix B;
    /// docs/physics.md §3).
    pub fn yield_work_j(&self, sigma_y_pa: f64) -> f64 {
        0.4 * self.hertz_k() * self.yield_overlap_m(sigma_y_pa).powf(2.5)
    }

    /// Impact speed at which yield starts, from W_y = (1/2) m_red V_Y^2; equals Eq. (15) for
    /// identical spheres. Unchecked: see [`Contact::try_yield_velocity_m_s`].
    pub fn yield_velocity_m_s(&self, sigma_y_pa: f64) -> f64 {
        (2.0 * self.yield_work_j(sigma_y_pa) / self.m_red_kg).sqrt()
    }

    /// V_Y, checked: sigma_y > 0 finite, and V_Y a normal, finite f64, else an error naming
    /// sigma_y and the contact (sigma_y = 1e-130 Pa gives V_Y ~ 1e-345 m/s: underflow, not 0).
    ///
    /// V_Y ~ sigma_y^(5/2) exactly, so V_Y(sigma_y) = V_Y(4^j sigma_y) 2^(-5j): with j chosen so
    /// that pi 4^j sigma_y/(2 E*) is near 1, no intermediate (delta_y, delta_y^(5/2), W_y)
    /// under- or overflows unless V_Y itself does, and the power of two is applied once, exactly
    /// or with the one rounding of a subnormal result.
    pub fn try_yield_velocity_m_s(&self, sigma_y_pa: f64) -> Result<f64> {
        positive("yield stress sigma_y (Pa)", sigma_y_pa)?;
        let cause = || format!("sigma_y = {} Pa, {}", Num(sigma_y_pa), self.describe());
        let ratio = PI * sigma_y_pa / (2.0 * self.e_star_pa);
        let j = if ratio.is_finite() && ratio > 0.0 {
            (-0.5 * ratio.log2()).round() as i32
        } else {
            0
        };
        // 4^j sigma_y: exact (a power of two), and normal: the ratio is then near 1.
        let scaled_sigma = fp::scale2(sigma_y_pa, 2 * j);
        let v_scaled = self.yield_velocity_m_s(scaled_sigma);
        let v = if v_scaled.is_finite() && v_scaled >= f64::MIN_POSITIVE {
            fp::scale2(v_scaled, -5 * j)
        } else {
            v_scaled
        };
        in_range("V_Y (m/s)", v, cause)
    }

    /// The sigma_y that makes V_Y equal `v_yield_m_s` (V_Y grows like sigma_y^(5/2)).
    pub fn sigma_y_for_yield_velocity(&self, v_yield_m_s: f64) -> f64 {
        (v_yield_m_s / self.yield_velocity_m_s(1.0)).powf(0.4)
    }

    /// Slope of the linear (perfectly plastic) loading branch, s = pi sigma_y R~ (Eq. 12).
    pub fn plastic_slope_n_m(&self, sigma_y_pa: f64) -> f64 {
        PI * sigma_y_pa * self.r_eff_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nylon_pair(d_m: f64) -> Pair {
        Pair::identical(Sphere::new(d_m, Material::preset("nylon").unwrap()).unwrap())
    }

    #[test]
    fn identical_spheres_reproduce_the_papers_forms() {
        // Paper: P_el = E d^2 (delta/d)^(3/2) (Eq. B1), so K = E d^(1/2); damping 2 eta d^(1/2).
        let d = 0.0254;
        let c = nylon_pair(d).contact();
        let e = Material::preset("nylon").unwrap().paper_modulus_pa();
        assert!((c.hertz_k() / (e * d.sqrt()) - 1.0).abs() < 1e-14);
        assert!((c.damping_c(190.0) / (2.0 * 190.0 * d.sqrt()) - 1.0).abs() < 1e-14);
        // a^2 = R delta / 2 with R the sphere radius.
        assert!((c.r_eff_m / (0.5 * d / 2.0) - 1.0).abs() < 1e-15);
        // Eq. (B2): delta_y = (pi^2/18)(sigma_y/E)^2 R.
        let sy = 4.0e7;
        let b2 = PI * PI / 18.0 * (sy / e).powi(2) * (d / 2.0);
        assert!((c.yield_overlap_m(sy) / b2 - 1.0).abs() < 1e-14);
        // Eq. (15): V_Y = (1/(9 sqrt 10)) (pi^4 sigma_y^5 / (rho E^4))^(1/2).
        let rho = 1140.0;
        let eq15 = (PI.powi(4) * sy.powi(5) / (rho * e.powi(4))).sqrt() / (9.0 * 10f64.sqrt());
        assert!((c.yield_velocity_m_s(sy) / eq15 - 1.0).abs() < 1e-13);
        // Eq. (12): slope (1/2) pi sigma_y R.
        assert!((c.plastic_slope_n_m(sy) / (0.5 * PI * sy * d / 2.0) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn paper_yield_velocity_is_6_32_m_s() {
        // docs/physics.md §3: Eq. (15) with the paper's nylon numbers gives 6.3233 m/s (not "about 9").
        let v = nylon_pair(0.0254).contact().yield_velocity_m_s(4.0e7);
        assert!((v - 6.3233).abs() < 5e-5, "{v}");
        // Size independent.
        let v2 = nylon_pair(0.00635).contact().yield_velocity_m_s(4.0e7);
        assert!((v2 / v - 1.0).abs() < 1e-13);
    }

    #[test]
    fn wall_is_the_limit_of_a_huge_sphere() {
        let m = Material::preset("nylon").unwrap();
        let s = Sphere::new(0.01, m).unwrap();
        let wall = Pair::on_wall(s, m).contact();
        let big = Pair::unequal(s, Sphere::new(1e4, m).unwrap()).contact();
        assert!((big.r_eff_m / wall.r_eff_m - 1.0).abs() < 1e-5);
        assert!((big.m_red_kg / wall.m_red_kg - 1.0).abs() < 1e-15);
        assert_eq!(big.e_star_pa, wall.e_star_pa);
        // Wall: R~ = R_1, m_red = m_1.
        assert_eq!(wall.r_eff_m, 0.005);
        assert_eq!(wall.m_red_kg, s.mass_kg());
    }

    #[test]
    fn kappa_inverse_and_scaling() {
        let c = nylon_pair(0.0127).contact();
        let k = c.kappa(190.0, 2.0);
        assert!((c.eta_for_kappa(k, 2.0) / 190.0 - 1.0).abs() < 1e-14);
        // kappa ~ V^(1/5).
        assert!((c.kappa(190.0, 64.0) / k - 32f64.powf(0.2)).abs() < 1e-13);
        let a = c.brilliantov_a_s(190.0);
        assert!((c.eta_from_brilliantov_a(a) / 190.0 - 1.0).abs() < 1e-14);
        // A = 4 eta / (3 E) for identical spheres.
        let e = Material::preset("nylon").unwrap().paper_modulus_pa();
        assert!((a / (4.0 * 190.0 / (3.0 * e)) - 1.0).abs() < 1e-14);
    }

    #[test]
    fn constructors_reject_bad_values() {
        assert!(Material::new(0.0, 0.3, 1000.0).is_err());
        assert!(Material::new(f64::NAN, 0.3, 1000.0).is_err());
        assert!(Material::new(1e9, 0.5, 1000.0).is_err());
        assert!(Material::new(1e9, -1.0, 1000.0).is_err());
        assert!(Material::new(1e9, 0.3, f64::INFINITY).is_err());
        assert!(Material::new(1e9, 0.3, -1.0).is_err());
        let m = Material::preset("NYLON").unwrap();
        assert!(Sphere::new(0.0, m).is_err());
        assert!(Sphere::new(-0.01, m).is_err());
        assert!(Sphere::new(f64::NAN, m).is_err());
        assert!(Material::preset("unobtainium").is_none());
    }
}
