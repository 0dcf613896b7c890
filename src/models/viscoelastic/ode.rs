//! The dimensionless collision x'' = -x^(3/2) - kappa x^(1/2) x', x(0) = 0, x'(0) = 1, integrated
//! in phases (docs/physics.md §2).
//!
//! **Method.** The right side contains x^(1/2), so the solution is not analytic in t where x = 0:
//! it has t^(5/2) terms at the start and (t_end - t)^(5/2) terms at the overlap-rule end, and a
//! Runge-Kutta method in t loses its order there. We therefore change the independent variable:
//! - loading (x' > 1/2): r = x^(1/2), with dp/dr = -2 r^2 (r^2 + kappa p)/p, dt/dr = 2r/p;
//! - around the turning point: time t, where x is bounded away from 0;
//! - unloading (x below its value at the first switch): r again, integrated down to r = 0.
//!
//! In r the solution is analytic at both ends (p is bounded away from 0 there), so the methods keep
//! their order and the overlap-rule end is exactly r = 0: no event needs locating. The switches
//! happen at accepted steps, so they introduce no error. The events that do need locating are
//! found on re-integrations from the last accepted step before the event: the force-rule end
//! x + kappa p = 0 and the turning point p = 0 by safeguarded Newton steps (Illinois regula falsi,
//! Dowell & Jarratt 1971, as the fallback), the force maximum, whose derivative is not at hand, by
//! Illinois regula falsi alone (`events::locate`).
//!
//! For relative accuracy of 1 - e as kappa -> 0 the dissipated work is integrated as a third
//! component, J = int x^(1/2) x'^2 dt (dJ/dr = 2 r^2 p), and e comes from the energy balance
//! e^2 = 1 - 2 kappa J - (4/5) x_end^(5/2) whenever e > 1/2 (below that, e = -p_end directly, which
//! keeps the relative accuracy of a tiny e at large kappa).

use super::events::{Bracket, EVENTS, Event, event_value, force, locate};
use super::settings::{OdeSettings, Rebound, check_ode_range};
pub(super) use super::stepper::integrate;
use super::{ContactEnd, Restitution};
use crate::error::{Error, IntegrationFailure, Num, Result, non_negative};
use nalgebra::Vector4;
use ode_solvers::System;

// The fourth component carries the independent variable, so that the system is autonomous:
// ode_solvers 0.6's Dop853 tableau has c_12 = 0 where DOP853 needs c_12 = 1, which silently
// degrades it to first order on non-autonomous systems (found here: with r explicit in the right
// side it needed 1e5 steps at tol 1e-10 and missed 1e-9 accuracy).
pub(super) type State = Vector4<f64>;

// Switch from r to t once the loading speed has dropped to this fraction of V: p is then far
// enough from 0 that the r-formulation stays smooth, and x far enough from 0 for the t-one.
const P_SWITCH: f64 = 0.5;
// x never exceeds the undamped maximum (5/4)^(2/5) = 1.0933, so r never exceeds 1.0456.
const R_LIMIT: f64 = 1.05;
// Keeps the r-formulation finite if a trial stage lands on p = 0 (the step is then rejected).
const P_FLOOR: f64 = 1e-200;
const SLOPE_CAP: f64 = 1e150;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Stage {
    Loading,
    Turning,
    Unloading,
    /// Plain integration between two points, for event refinement.
    Probe(Var),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Var {
    Root,
    Time,
}

impl Stage {
    pub(super) fn var(self) -> Var {
        match self {
            Stage::Loading | Stage::Unloading => Var::Root,
            Stage::Turning => Var::Time,
            Stage::Probe(v) => v,
        }
    }
}

/// (x, p) from the state of a phase: in r the state is (p, t, J), in t it is (x, p, J).
pub(super) fn x_p(var: Var, s: f64, y: &State) -> (f64, f64) {
    match var {
        Var::Root => (s * s, y[0]),
        Var::Time => (y[0], y[1]),
    }
}

fn time_of(var: Var, s: f64, y: &State) -> f64 {
    match var {
        Var::Root => y[1],
        Var::Time => s,
    }
}

/// One phase of the integration, seen by the solver through `&mut Phase` so that the caller can
/// read back what `solout` recorded.
pub(super) struct Phase {
    pub(super) kappa: f64,
    pub(super) stage: Stage,
    pub(super) rule: ContactEnd,
    /// Turning stage stops once p < 0 and x <= this.
    pub(super) x_switch: f64,
    pub(super) prev: (f64, State),
    pub(super) brackets: [Option<Bracket>; 3],
    pub(super) stopped: bool,
    pub(super) steps: u64,
}

impl Phase {
    pub(super) fn new(kappa: f64, stage: Stage, rule: ContactEnd, s0: f64, y0: State) -> Self {
        Phase {
            kappa,
            stage,
            rule,
            x_switch: 0.0,
            prev: (s0, y0),
            brackets: [None; 3],
            stopped: false,
            steps: 0,
        }
    }

    /// Called at every accepted step; returns true to stop the phase.
    pub(super) fn accept(&mut self, s: f64, y: State) -> bool {
        self.steps += 1;
        if let Stage::Probe(_) = self.stage {
            return false;
        }
        let var = self.stage.var();
        let (x0, p0) = x_p(var, self.prev.0, &self.prev.1);
        let (x1, p1) = x_p(var, s, &y);
        for ev in EVENTS {
            let slot = &mut self.brackets[ev as usize];
            if slot.is_none()
                && event_value(ev, self.kappa, x0, p0) > 0.0
                && event_value(ev, self.kappa, x1, p1) <= 0.0
            {
                *slot = Some(Bracket {
                    s0: self.prev.0,
                    y0: self.prev.1,
                    s1: s,
                    y1: y,
                });
            }
        }
        self.prev = (s, y);
        let force_end =
            self.rule == ContactEnd::Force && self.brackets[Event::ForceZero as usize].is_some();
        self.stopped = match self.stage {
            Stage::Loading => p1 <= P_SWITCH,
            Stage::Turning => force_end || (p1 < 0.0 && x1 <= self.x_switch),
            Stage::Unloading => force_end,
            Stage::Probe(_) => false,
        };
        self.stopped
    }
}

pub(super) fn rhs(kappa: f64, var: Var, y: &State, dy: &mut State) {
    match var {
        Var::Root => {
            let r = y[3];
            let p = if y[0].abs() < P_FLOOR {
                P_FLOOR.copysign(y[0])
            } else {
                y[0]
            };
            let r2 = r * r;
            dy[0] = (-2.0 * r2 * (r2 + kappa * p) / p).clamp(-SLOPE_CAP, SLOPE_CAP);
            dy[1] = (2.0 * r / p).clamp(-SLOPE_CAP, SLOPE_CAP);
            dy[2] = 2.0 * r2 * p;
            dy[3] = 1.0;
        }
        Var::Time => {
            // Runge-Kutta stages may step past x = 0: clamp before the square root.
            let x = y[0].max(0.0);
            let p = y[1];
            let sx = x.sqrt();
            dy[0] = p;
            dy[1] = -sx * (x + kappa * p);
            dy[2] = sx * p * p;
            dy[3] = 1.0;
        }
    }
}

impl System<f64, State> for &mut Phase {
    fn system(&self, _s: f64, y: &State, dy: &mut State) {
        rhs(self.kappa, self.stage.var(), y, dy);
    }

    fn solout(&mut self, s: f64, y: &State, _dy: &State) -> bool {
        self.accept(s, *y)
    }
}

/// e and the other collision figures for dimensionless damping `kappa` (docs/physics.md §2).
pub fn rebound(kappa: f64, rule: ContactEnd, settings: &OdeSettings) -> Result<Rebound> {
    solve(kappa, rule, settings, true)
}

/// e alone by the ODE: as [`rebound`] but without locating the overlap and force maxima
/// (about half the right-hand-side evaluations).
pub fn restitution_ode(
    kappa: f64,
    rule: ContactEnd,
    settings: &OdeSettings,
) -> Result<Restitution> {
    let r = solve(kappa, rule, settings, false)?;
    Ok(Restitution {
        e: r.e,
        one_minus_e: r.one_minus_e,
        rhs_evals: r.rhs_evals,
    })
}

fn solve(kappa: f64, rule: ContactEnd, settings: &OdeSettings, extrema: bool) -> Result<Rebound> {
    non_negative("dimensionless damping kappa", kappa)?;
    check_ode_range(kappa, rule, settings)?;
    let mut evals = 0u64;
    let mut steps = 0u64;
    let mut x_max = f64::NAN;
    let mut force_max = f64::NAN;
    let mut end: Option<(Var, f64, State)> = None;

    let mut note_events = |phase: &Phase, evals: &mut u64| -> Result<Option<(f64, State)>> {
        let var = phase.stage.var();
        if !extrema {
            // Only the force-rule end below.
        } else if let Some(b) = &phase.brackets[Event::Turning as usize] {
            let (s, y, n) = locate(kappa, var, Event::Turning, b, settings)?;
            *evals += n;
            x_max = x_p(var, s, &y).0;
        }
        // The force maximum is the first fall of dF/dt while the force is compressive. Later
        // phases see dF/dt fall again in the overlap rule's attractive tail (and in rounding
        // noise as x -> 0): such a bracket once overwrote the maximum with -8.5e-9 at kappa =
        // 1000 and failed to converge at kappa = 150-500.
        if let (true, true, Some(b)) = (
            extrema,
            force_max.is_nan(),
            &phase.brackets[Event::ForceMax as usize],
        ) {
            let (x0, p0) = x_p(var, b.s0, &b.y0);
            if event_value(Event::ForceZero, kappa, x0, p0) > 0.0 {
                let (s, y, n) = locate(kappa, var, Event::ForceMax, b, settings)?;
                *evals += n;
                let (x, p) = x_p(var, s, &y);
                force_max = force(kappa, x, p);
            }
        }
        if let (ContactEnd::Force, Some(b)) = (rule, &phase.brackets[Event::ForceZero as usize]) {
            let (s, y, n) = locate(kappa, var, Event::ForceZero, b, settings)?;
            *evals += n;
            return Ok(Some((s, y)));
        }
        Ok(None)
    };

    // Loading, in r from 0.
    let y0 = State::new(1.0, 0.0, 0.0, 0.0);
    let mut a = Phase::new(kappa, Stage::Loading, rule, 0.0, y0);
    let (r_a, y_a, n) = integrate(&mut a, 0.0, y0, R_LIMIT, settings)?;
    evals += n;
    steps += a.steps;
    if !a.stopped {
        return Err(Error::Integration {
            method: settings.integrator.name(),
            kappa,
            kind: IntegrationFailure::PhaseIncomplete,
            reason: "loading phase did not slow down as it must".into(),
        });
    }
    note_events(&a, &mut evals)?;

    // Around the turning point, in t.
    let x_a = r_a * r_a;
    let t_a = y_a[1];
    let yb0 = State::new(x_a, y_a[0], y_a[2], t_a);
    let t_limit = t_a + 100.0 * (1.0 + kappa);
    let mut b = Phase::new(kappa, Stage::Turning, rule, t_a, yb0);
    b.x_switch = x_a;
    let (t_b, y_b, n) = integrate(&mut b, t_a, yb0, t_limit, settings)?;
    evals += n;
    steps += b.steps;
    if !b.stopped {
        return Err(Error::Integration {
            method: settings.integrator.name(),
            kappa,
            kind: IntegrationFailure::PhaseIncomplete,
            reason: format!("no rebound within t = {} (dimensionless)", Num(t_limit)),
        });
    }
    if let Some((s, y)) = note_events(&b, &mut evals)? {
        end = Some((Var::Time, s, y));
    }

    if end.is_none() {
        // Unloading, in r down to 0 (the overlap-rule end).
        let r_c = y_b[0].max(0.0).sqrt();
        let yc0 = State::new(y_b[1], t_b, y_b[2], r_c);
        let mut c = Phase::new(kappa, Stage::Unloading, rule, r_c, yc0);
        let (r_end, y_end, n) = integrate(&mut c, r_c, yc0, 0.0, settings)?;
        evals += n;
        steps += c.steps;
        end = match note_events(&c, &mut evals)? {
            Some((s, y)) => Some((Var::Root, s, y)),
            None if rule == ContactEnd::Overlap || kappa == 0.0 => Some((Var::Root, r_end, y_end)),
            None => {
                return Err(Error::Integration {
                    method: settings.integrator.name(),
                    kappa,
                    kind: IntegrationFailure::PhaseIncomplete,
                    reason: "force never returned to zero before separation".into(),
                });
            }
        };
    }

    let (var, s, y) = end.expect("every path sets the end of contact");
    if extrema && !(x_max.is_finite() && force_max.is_finite()) {
        return Err(Error::Integration {
            method: settings.integrator.name(),
            kappa,
            kind: IntegrationFailure::EventLocation,
            reason: format!(
                "the maximum overlap ({}) or force ({}) was not bracketed by the steps",
                Num(x_max),
                Num(force_max)
            ),
        });
    }
    let (x_end, p_end) = x_p(var, s, &y);
    // The bodies separate at the end of contact, so p_end < 0 always (overlap rule: p = -e; force
    // rule: p = -x/kappa). p_end >= 0 means the integration went unstable in the slow unloading
    // tail (fixed-step RK4, or loose tolerances at large kappa), and e from the energy balance
    // below would be a wrong number near 0.5 (found by the bench's stability probe).
    if p_end.is_nan() || p_end >= 0.0 {
        return Err(Error::Integration {
            method: settings.integrator.name(),
            kappa,
            kind: IntegrationFailure::Unphysical,
            reason: format!("not separating at the end of contact (p = {})", Num(p_end)),
        });
    }
    let x_end = if var == Var::Root && rule == ContactEnd::Overlap {
        0.0
    } else {
        x_end
    };
    let j = y[2];
    // Energy balance: p_end^2/2 + (2/5) x_end^(5/2) = 1/2 - kappa J.
    let one_minus_e2 = 2.0 * kappa * j + 0.8 * x_end.powf(2.5);
    // A trajectory that dissipated more than the impact energy, or whose final speed disagrees
    // grossly with the energy it kept, is not a solution (coarse fixed-step RK4 at kappa ~ 10
    // returned e = 0.02-0.23 against 1e-6 this way; found by the bench's probe). Accurate runs
    // agree to about the tolerance; 1e-6 and 1e-3 leave room for deliberately coarse settings.
    let e2_energy = 1.0 - one_minus_e2;
    if e2_energy < -1e-6 || (e2_energy > 0.25 && (e2_energy.sqrt() + p_end).abs() > 1e-3) {
        return Err(Error::Integration {
            method: settings.integrator.name(),
            kappa,
            kind: IntegrationFailure::Unphysical,
            reason: format!(
                "energy balance violated (e from the energy {}, from the speed {})",
                Num(e2_energy.max(0.0).sqrt()),
                Num(-p_end)
            ),
        });
    }
    // e2_energy >= -1e-6 here; below 0 it is rounding of a complete dissipation, and that case
    // takes the e = -p_end branch below, so the max hides nothing.
    let e_energy = e2_energy.max(0.0).sqrt();
    let (e, one_minus_e) = if e_energy > 0.5 {
        (e_energy, one_minus_e2 / (1.0 + e_energy))
    } else {
        (-p_end, 1.0 + p_end)
    };
    if !(e.is_finite() && e > 0.0 && e <= 1.0) {
        return Err(Error::Integration {
            method: settings.integrator.name(),
            kappa,
            kind: IntegrationFailure::Unphysical,
            reason: format!("e = {} outside (0, 1]", Num(e)),
        });
    }
    Ok(Rebound {
        e,
        one_minus_e,
        tau_contact: time_of(var, s, &y),
        x_max,
        force_max,
        x_end,
        rhs_evals: evals,
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::viscoelastic::settings::ODE_KAPPA_MAX_OVERLAP;

    #[test]
    fn hertz_limit_is_elastic() {
        // kappa = 0: e = 1 exactly, and the Hertz contact time and maximum overlap are known in
        // closed form: x_max = (5/4)^(2/5), tau = 3.2180654597190430845 (docs/physics.md §2). The
        // trajectory is accurate to about the tolerance, so these get 10 tol.
        let tol = 10.0 * OdeSettings::DEFAULT.rtol;
        for rule in ContactEnd::ALL {
            let r = rebound(0.0, rule, &OdeSettings::DEFAULT).unwrap();
            assert!((r.e - 1.0).abs() < 1e-14, "{rule}: {r:?}");
            assert!((r.tau_contact - 3.2180654597190430845).abs() < tol, "{r:?}");
            assert!((r.x_max - 1.25f64.powf(0.4)).abs() < tol, "{r:?}");
            assert!((r.force_max - 1.25f64.powf(0.6)).abs() < tol, "{r:?}");
        }
    }

    #[test]
    fn small_kappa_slope_is_ramirez_c1() {
        // 1 - e = C1 kappa - C2 kappa^2 + O(kappa^3) (Ramirez et al. 1999), overlap rule.
        let c1 = 1.15344885809528879913;
        let c2 = 0.6 * c1 * c1;
        for kappa in [1e-8, 1e-6, 1e-4] {
            let r = rebound(kappa, ContactEnd::Overlap, &OdeSettings::DEFAULT).unwrap();
            let series = c1 * kappa - c2 * kappa * kappa;
            // Truncation O(kappa^3) plus the 1e-8 relative accuracy bar.
            let tol = 1e-8 * series + 2.0 * kappa.powi(3);
            assert!(
                (r.one_minus_e - series).abs() < tol,
                "{kappa}: {r:?} vs {series}"
            );
        }
    }

    #[test]
    fn force_rule_ends_no_later_and_bounces_more() {
        for kappa in [1e-3, 0.1, 1.0, 10.0] {
            let o = rebound(kappa, ContactEnd::Overlap, &OdeSettings::DEFAULT).unwrap();
            let f = rebound(kappa, ContactEnd::Force, &OdeSettings::DEFAULT).unwrap();
            assert!(
                f.e >= o.e && f.tau_contact < o.tau_contact,
                "{kappa}: {o:?} {f:?}"
            );
            assert!(f.x_end > 0.0);
            assert!(
                (f.x_end + kappa * -f.e).abs() < 1e-9,
                "force zero at the end: {f:?}"
            );
        }
    }

    #[test]
    fn overlap_rule_extrema_are_the_force_rules() {
        // Both rules follow one trajectory until the force first returns to zero, and the
        // maximum overlap (p = 0, where F = x^(3/2) > 0) and the maximum force come before it:
        // the two rules' extrema must agree to the integration's tolerance (1e-9 relative: a
        // hundred times rtol = 1e-11 through the event location). The overlap rule's long
        // attractive tail once replaced the force maximum by a later spurious one.
        for kappa in [0.01, 0.5, 5.0, 150.0, 250.0, 1000.0, 1999.0] {
            let o = rebound(kappa, ContactEnd::Overlap, &OdeSettings::DEFAULT).unwrap();
            let f = rebound(kappa, ContactEnd::Force, &OdeSettings::DEFAULT).unwrap();
            for (a, b, what) in [
                (o.x_max, f.x_max, "x_max"),
                (o.force_max, f.force_max, "force_max"),
            ] {
                assert!(
                    (a / b - 1.0).abs() < 1e-9,
                    "kappa {kappa} {what}: {a} vs {b}"
                );
            }
        }
    }

    #[test]
    fn rejects_bad_kappa() {
        for k in [-1.0, f64::NAN, f64::INFINITY] {
            assert!(rebound(k, ContactEnd::Overlap, &OdeSettings::DEFAULT).is_err());
        }
    }

    #[test]
    fn refuses_kappa_beyond_its_checked_range() {
        for (rule, k) in [
            (ContactEnd::Overlap, 2.0 * ODE_KAPPA_MAX_OVERLAP),
            (ContactEnd::Force, 1e30),
            (ContactEnd::Overlap, f64::MAX),
        ] {
            let err = rebound(k, rule, &OdeSettings::DEFAULT).unwrap_err();
            assert_eq!(
                err.integration_failure(),
                Some(IntegrationFailure::OutOfRange),
                "{err}"
            );
        }
    }
}
