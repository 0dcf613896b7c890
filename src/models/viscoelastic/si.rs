//! The viscoelastic model in SI units: a contact with damping eta, impact speed in m/s.

use super::settings::{OdeSettings, Rebound};
use super::{ContactEnd, rebound};
use crate::contact::Contact;
use crate::error::{Result, non_negative};

/// A viscoelastic contact with damping eta (kg s^-1 m^-1), in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viscoelastic {
    pub contact: Contact,
    pub eta: f64,
}

/// A dimensional collision of the viscoelastic model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impact {
    pub kappa: f64,
    pub e: f64,
    pub contact_time_s: f64,
    pub max_overlap_m: f64,
    pub max_force_n: f64,
    pub dimensionless: Rebound,
}

impl Viscoelastic {
    pub fn new(contact: Contact, eta: f64) -> Result<Self> {
        non_negative("damping eta (kg/(s m))", eta)?;
        Ok(Viscoelastic { contact, eta })
    }

    pub fn kappa(&self, v_m_s: f64) -> f64 {
        self.contact.kappa(self.eta, v_m_s)
    }

    /// kappa at `v_m_s`, checked: a finite f64, 0 or normal, else an error naming eta and v.
    pub fn try_kappa(&self, v_m_s: f64) -> Result<f64> {
        self.contact.try_kappa(self.eta, v_m_s)
    }

    /// Integrates one collision at normal impact speed `v_m_s` and converts back to SI units.
    pub fn impact(&self, v_m_s: f64, rule: ContactEnd, settings: &OdeSettings) -> Result<Impact> {
        let kappa = self.try_kappa(v_m_s)?;
        let r = rebound(kappa, rule, settings)?;
        let t = self.contact.try_time_scale_s(v_m_s)?;
        let l = v_m_s * t;
        Ok(Impact {
            kappa,
            e: r.e,
            contact_time_s: r.tau_contact * t,
            max_overlap_m: r.x_max * l,
            max_force_n: r.force_max * self.contact.m_red_kg * l / (t * t),
            dimensionless: r,
        })
    }
}
