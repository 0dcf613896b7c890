//! The integrators' driver: one phase from s0 towards s1 by Dop853, Dopri5 (ode_solvers, sparse
//! output) or our fixed-step RK4, stopping where the phase's `accept` says.

use super::ode::{Phase, State, rhs};
use super::settings::{Integrator, OdeSettings};
use crate::error::{Error, IntegrationFailure, Num, Result};
use ode_solvers::dop_shared::IntegrationError;
use ode_solvers::{Dop853, Dopri5, OutputType};

fn integration_error(settings: &OdeSettings, kappa: f64, e: IntegrationError) -> Error {
    Error::Integration {
        method: settings.integrator.name(),
        kappa,
        kind: IntegrationFailure::from(&e),
        reason: e.to_string(),
    }
}

/// Integrates `phase` from (s0, y0) towards s1 until its `accept` stops it or s1 is reached.
/// Returns the last accepted point and the right-hand-side evaluations spent.
pub(crate) fn integrate(
    phase: &mut Phase,
    s0: f64,
    y0: State,
    s1: f64,
    settings: &OdeSettings,
) -> Result<(f64, State, u64)> {
    let kappa = phase.kappa;
    let n_stiff = if settings.stiffness_check {
        1000
    } else {
        u32::MAX
    };
    let h_max = (s1 - s0).abs();
    // Every phase variable is O(1) over a contact, so a first step of 0.05 (or the whole span of a
    // short refinement) is safe; the solver's own first guess starts near 1e-6 at r = 0, where the
    // right side vanishes, and wastes steps growing from there.
    let h0 = (s1 - s0).signum() * h_max.min(0.05);
    macro_rules! adaptive {
        ($solver:ident, $beta:expr) => {{
            let mut solver = $solver::from_param(
                &mut *phase,
                s0,
                s1,
                0.0,
                y0,
                settings.rtol,
                settings.atol,
                0.9,
                $beta,
                0.333,
                6.0,
                h_max,
                h0,
                settings.max_steps,
                n_stiff,
                OutputType::Sparse,
            );
            let stats = solver
                .integrate()
                .map_err(|e| integration_error(settings, kappa, e))?;
            let s = *solver
                .x_out()
                .last()
                .expect("solver output holds the start");
            let y = *solver
                .y_out()
                .last()
                .expect("solver output holds the start");
            Ok((s, y, stats.num_eval as u64))
        }};
    }
    match settings.integrator {
        // Hairer's recommended PI-controller betas: 0 for DOP853, 0.04 for DOPRI5.
        Integrator::Dop853 => adaptive!(Dop853, 0.0),
        Integrator::Dopri5 => adaptive!(Dopri5, 0.04),
        Integrator::Rk4 { h } => rk4(phase, s0, y0, s1, h, settings),
    }
}

/// Classical RK4 at fixed step: ceil(|s1 - s0|/h) equal steps that land exactly on s1.
fn rk4(
    phase: &mut Phase,
    s0: f64,
    y0: State,
    s1: f64,
    h: f64,
    settings: &OdeSettings,
) -> Result<(f64, State, u64)> {
    let kappa = phase.kappa;
    let var = phase.stage.var();
    let span = s1 - s0;
    let n = (span.abs() / h).ceil().max(1.0);
    let hh = span / n;
    let (mut s, mut y) = (s0, y0);
    let (mut k1, mut k2, mut k3, mut k4) = (
        State::zeros(),
        State::zeros(),
        State::zeros(),
        State::zeros(),
    );
    let mut evals = 0u64;
    let mut i = 0.0;
    while i < n {
        if phase.steps >= settings.max_steps as u64 {
            return Err(Error::Integration {
                method: "rk4",
                kappa,
                kind: IntegrationFailure::MaxSteps,
                reason: format!(
                    "stopped at {}: needs more than {} steps",
                    Num(s),
                    settings.max_steps
                ),
            });
        }
        rhs(kappa, var, &y, &mut k1);
        rhs(kappa, var, &(y + k1 * (0.5 * hh)), &mut k2);
        rhs(kappa, var, &(y + k2 * (0.5 * hh)), &mut k3);
        rhs(kappa, var, &(y + k3 * hh), &mut k4);
        evals += 4;
        y += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (hh / 6.0);
        i += 1.0;
        s = if i < n { s0 + i * hh } else { s1 };
        if !y.iter().all(|v| v.is_finite()) {
            return Err(Error::Integration {
                method: "rk4",
                kappa,
                kind: IntegrationFailure::NonFinite,
                reason: format!("non-finite state at {}: step {} too large", Num(s), Num(h)),
            });
        }
        if phase.accept(s, y) {
            break;
        }
    }
    Ok((s, y, evals))
}
