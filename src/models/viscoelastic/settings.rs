//! Integrator settings of the viscoelastic ODE and the figures of one integrated collision.

use crate::error::{Error, IntegrationFailure, Num, Result};

/// The ODE integrator.
#[derive(Debug, Clone, Copy, PartialEq, strum::IntoStaticStr)]
#[strum(serialize_all = "lowercase")]
pub enum Integrator {
    /// Dormand-Prince 8(5,3) (Hairer, Norsett & Wanner, Solving ODEs I, 1993).
    Dop853,
    /// Dormand-Prince 5(4).
    Dopri5,
    /// Classical fourth-order Runge-Kutta with a fixed step `h` in each phase's variable.
    Rk4 { h: f64 },
}

impl Integrator {
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Integrator and its accuracy knobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdeSettings {
    pub integrator: Integrator,
    /// Relative and absolute tolerance of the adaptive methods (all state components are O(1)).
    pub rtol: f64,
    pub atol: f64,
    /// Steps allowed per phase before giving up with an error.
    pub max_steps: u32,
    /// Let the adaptive methods' stiffness detector abort the run (off by default: at large kappa
    /// the unloading tail is mildly stiff, and the explicit methods still finish correctly).
    pub stiffness_check: bool,
}

impl OdeSettings {
    /// The default: Dop853 at rtol = atol = 1e-11, the cheapest tolerance that meets
    /// |error in e| <= 1e-10 and a relative error of 1 - e <= 1e-8 over kappa in [1e-8, 100], both
    /// rules, with a wide margin (measured 2.8e-12 and 9.0e-12: `restitution bench`'s candidates;
    /// 1e-10 also passes, with a margin of only 3.4; 1e-12 costs 23% more for accuracy nobody asked
    /// for). Checked in tests/viscoelastic.rs against the mpmath values.
    pub const DEFAULT: OdeSettings = OdeSettings {
        integrator: Integrator::Dop853,
        rtol: 1e-11,
        atol: 1e-11,
        max_steps: 200_000,
        stiffness_check: false,
    };

    /// The tightest setting, used to generate the master curve.
    pub const REFERENCE: OdeSettings = OdeSettings {
        integrator: Integrator::Dop853,
        rtol: Self::TOL_MIN,
        atol: Self::TOL_MIN,
        max_steps: 2_000_000,
        stiffness_check: false,
    };

    /// The tightest tolerance a caller may ask of the adaptive methods:
    /// [`OdeSettings::REFERENCE`]'s, the tightest the toolkit checks (see
    /// [`OdeSettings::check_tol`]).
    pub const TOL_MIN: f64 = 1e-15;

    /// Why `tol` cannot be the tolerance of the adaptive methods, if it cannot: it must lie in
    /// [TOL_MIN, 1). Below TOL_MIN a double cannot meet it (unit roundoff 1.1e-16), and the
    /// integrators then fail in ways that name the collision rather than the tolerance: at
    /// kappa = 0.07, Dop853 ran out of its 200 000 steps at 1e-25 and its step size underflowed
    /// at 1e-200 (from 1e-22 to 1e-15 it finished, though no double is that accurate).
    /// Known answer: tests/viscoelastic.rs, both integrators at TOL_MIN against mpmath.
    pub fn check_tol(tol: f64) -> std::result::Result<(), String> {
        if tol.is_finite() && (Self::TOL_MIN..1.0).contains(&tol) {
            Ok(())
        } else {
            Err(format!("expected a number in [{:e}, 1)", Self::TOL_MIN))
        }
    }

    pub fn with_integrator(integrator: Integrator, tol: f64) -> Self {
        OdeSettings {
            integrator,
            rtol: tol,
            atol: tol,
            ..Self::DEFAULT
        }
    }
}

impl Default for OdeSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The outcome of one dimensionless collision (all quantities in the master-curve units:
/// lengths in L = V T, times in T = k^(-2/5) V^(-1/5), forces in m_red L / T^2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rebound {
    pub e: f64,
    /// 1 - e with its own relative accuracy (not computed as 1 - e when e is close to 1).
    pub one_minus_e: f64,
    pub tau_contact: f64,
    pub x_max: f64,
    pub force_max: f64,
    /// Overlap at the end of contact (0 for the overlap rule).
    pub x_end: f64,
    pub rhs_evals: u64,
    pub steps: u64,
}

/// Largest kappa at which the ODE runs, per rule: the range where its accuracy has been checked
/// against the mpmath fixtures (tests/viscoelastic.rs). Beyond it the tolerances, which are
/// absolute (every state component is O(1) at small kappa), no longer resolve e (~ 5.16 kappa^-5
/// for the overlap rule, ~ 1.31 kappa^(-5/3) for the force rule): at kappa = 1e12 the force rule's
/// e came out 2.5e-6 wrong at the default tolerance, and above 1e15 the integration breaks down.
/// The overlap rule also needs ~kappa^(5/3) steps (its slow unloading is stiff) and exhausts the
/// default step budget near kappa = 3000 (2000 needs about 115000 of the 200000 steps at the
/// default tolerance). The master curve covers every kappa
/// ([`super::master::restitution_master`]).
pub const ODE_KAPPA_MAX_OVERLAP: f64 = 2000.0;
/// See [`ODE_KAPPA_MAX_OVERLAP`].
pub const ODE_KAPPA_MAX_FORCE: f64 = 1e8;

/// The ODE's kappa limit for `rule`.
pub fn ode_kappa_max(rule: super::ContactEnd) -> f64 {
    match rule {
        super::ContactEnd::Overlap => ODE_KAPPA_MAX_OVERLAP,
        super::ContactEnd::Force => ODE_KAPPA_MAX_FORCE,
    }
}

/// An error unless kappa is within the ODE's checked range for `rule`.
pub(super) fn check_ode_range(
    kappa: f64,
    rule: super::ContactEnd,
    settings: &OdeSettings,
) -> Result<()> {
    let max = ode_kappa_max(rule);
    if kappa > max {
        return Err(Error::Integration {
            method: settings.integrator.name(),
            kappa,
            kind: IntegrationFailure::OutOfRange,
            reason: format!(
                "kappa above {} is beyond the ODE's checked range for the {rule} rule (its absolute tolerances do not resolve e there); the master curve covers every kappa",
                Num(max)
            ),
        });
    }
    Ok(())
}
