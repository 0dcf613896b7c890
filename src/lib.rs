//! `restitution`: the coefficient of restitution of colliding spheres after Labous, Rosato & Dave,
//! Phys. Rev. E 56, 5717 (1997). Physics modules are pure: no CLI, plotting or I/O.
//!
//! e(v) of two identical 12.7 mm nylon spheres at 2 m/s, from the viscoelastic model (Eqs. 9-10,
//! damping eta) and the plastic model (Eqs. 12-18, yield stress sigma_y):
//!
//! ```
//! use restitution::contact::{Material, Pair, Sphere};
//! use restitution::models::plastic::Plastic;
//! use restitution::models::viscoelastic::{self, ContactEnd, OdeSettings, Viscoelastic, VmMethod};
//!
//! let nylon = Material::preset("nylon").expect("a preset");
//! let contact = Pair::identical(Sphere::new(12.7e-3, nylon)?).try_contact()?;
//! let kappa = Viscoelastic::new(contact, 190.0)?.try_kappa(2.0)?;
//! let e_vm = viscoelastic::restitution(kappa, ContactEnd::Overlap, &VmMethod::Master)?.e;
//! let e_pm = Plastic::new(contact, 4.0e7)?.rebound(2.0)?.e;
//! // e_vm = 0.946 from the master curve; the ODE (Dop853, tolerance 1e-11) agrees.
//! let ode = VmMethod::Ode(OdeSettings::DEFAULT);
//! let e_ode = viscoelastic::restitution(kappa, ContactEnd::Overlap, &ode)?.e;
//! assert!((e_vm - e_ode).abs() < 1e-9 && (e_vm - 0.946).abs() < 5e-4);
//! // 2 m/s is below this pair's yield speed (6.3 m/s): the plastic model is elastic there.
//! assert_eq!(e_pm, 1.0);
//! # Ok::<(), restitution::Error>(())
//! ```
//!
//! Layers: the core above is always built; the features `io` (file formats, reports and the
//! bench: `data`, `bench`), `plot` (SVG figures: `plot`) and `cli` (the command line; the
//! default) add the rest. A Rust program that needs e(v) alone depends on
//! `restitution = { version = "0.1", default-features = false }`.

#[cfg(feature = "io")]
pub mod bench;
pub mod contact;
pub mod cpu;
#[cfg(feature = "io")]
pub mod data;
pub mod dem;
pub mod error;
pub mod experiment;
pub mod fit;
pub mod frames;
pub mod kinematics;
pub mod models;
#[cfg(feature = "plot")]
pub mod plot;
pub mod predict;
pub mod synthetic;

pub use error::{Error, Result};
