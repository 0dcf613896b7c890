//! Event location on the integrated trajectory: the turning point, the force maximum and the
//! force-rule end of contact, each a sign change of an event function of (x, p) bracketed by two
//! accepted steps and refined by `locate`.

use super::ContactEnd;
use super::ode::{Phase, Stage, State, Var, integrate, rhs, x_p};
use super::settings::{Integrator, OdeSettings};
use crate::error::{Error, IntegrationFailure, Num, Result};

/// Iteration cap of `locate`. Newton converges in 3-6 steps and the Illinois fallback in
/// about 10-30 (measured on the bench's chart); 100 leaves a wide margin and bounds the cost of
/// a pathological bracket at 100 short re-integrations.
pub const LOCATE_MAX_ITERATIONS: usize = 100;

#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub(super) enum Event {
    /// p = 0: maximum overlap.
    Turning = 0,
    /// dF/dt = 0: maximum force.
    ForceMax = 1,
    /// x + kappa p = 0: the force-rule end.
    ForceZero = 2,
}

pub(super) const EVENTS: [Event; 3] = [Event::Turning, Event::ForceMax, Event::ForceZero];

/// Event functions of (x, p); each crosses from > 0 to <= 0 once per contact.
pub(super) fn event_value(ev: Event, kappa: f64, x: f64, p: f64) -> f64 {
    match ev {
        Event::Turning => p,
        // 2 x^(1/2) dF/dt with F = x^(1/2) (x + kappa p) and p' = -x^(1/2) (x + kappa p).
        Event::ForceMax => {
            p * (3.0 * x + kappa * p) - 2.0 * kappa * x * x.max(0.0).sqrt() * (x + kappa * p)
        }
        Event::ForceZero => x + kappa * p,
    }
}

pub(super) fn force(kappa: f64, x: f64, p: f64) -> f64 {
    x.max(0.0).sqrt() * (x + kappa * p)
}

#[derive(Debug, Clone, Copy)]
pub(super) struct Bracket {
    pub(super) s0: f64,
    pub(super) y0: State,
    pub(super) s1: f64,
    pub(super) y1: State,
}

impl Event {
    fn name(self) -> &'static str {
        self.into()
    }
}

/// Root of the event function on a bracket, by safeguarded Newton on re-integrations from the
/// bracket's left end: the event's derivative along the solution comes from the right side, so
/// each step costs one short integration and converges quadratically (plain regula falsi needed
/// ~30 steps for the force-rule end at small kappa, where g = r^2 + kappa p is convex). Steps
/// that would leave the bracket fall back to Illinois regula falsi (Dowell & Jarratt 1971), and
/// the force maximum, whose derivative is not at hand, uses Illinois throughout.
/// Returns the state at the root and the evaluations spent, or an [`IntegrationFailure::EventLocation`]
/// error when [`LOCATE_MAX_ITERATIONS`] steps or a NaN stop it first (it never returns an
/// unconverged point as if it were the root).
pub(super) fn locate(
    kappa: f64,
    var: Var,
    ev: Event,
    b: &Bracket,
    settings: &OdeSettings,
) -> Result<(f64, State, u64)> {
    let g = |s: f64, y: &State| {
        let (x, p) = x_p(var, s, y);
        event_value(ev, kappa, x, p)
    };
    // dg/ds along the solution, where the event's formula makes it cheap.
    let slope = |s: f64, y: &State| -> Option<f64> {
        let mut dy = State::zeros();
        rhs(kappa, var, y, &mut dy);
        let (dx, dp) = match var {
            Var::Root => (2.0 * s, dy[0]),
            Var::Time => (dy[0], dy[1]),
        };
        match ev {
            Event::Turning => Some(dp),
            Event::ForceZero => Some(dx + kappa * dp),
            Event::ForceMax => None,
        }
    };
    let (mut a, mut fa) = (b.s0, g(b.s0, &b.y0));
    let (mut c, mut fc) = (b.s1, g(b.s1, &b.y1));
    let mut best = if fa.abs() < fc.abs() {
        (b.s0, b.y0, fa)
    } else {
        (b.s1, b.y1, fc)
    };
    let mut evals = 0;
    let mut side = 0i8;
    // The bracket is resolved once it is rounding-small against its own first width: near the
    // force-rule end in the root variable s (x = s^2) the root sits at s ~ (kappa e)^(1/2), and
    // Newton on g = s^2 + kappa p only halves s there, so a floor relative to s itself (or to
    // 1e-300) took ~170 halvings for kappa = 1e-100 and ran out of iterations; a point within
    // 4 eps of the first width changes x, p and the time below their rounding.
    let width0 = (b.s1 - b.s0).abs();
    // A converged point must be a root of the probed trajectory, not just the end of a collapsed
    // bracket: the bracket's ends come from accepted steps, and a re-integration that does not
    // reproduce the sign change (a coarse setting) would otherwise collapse onto a point where g
    // is far from 0. The allowance covers the setting's own noise between probes.
    let g_scale = fa.abs().max(fc.abs());
    let noise = match settings.integrator {
        Integrator::Rk4 { h } => h * h,
        _ => 100.0 * settings.rtol,
    };
    let allowed = g_scale * noise.max(1e-6);
    let finish = |best: (f64, State, f64), evals: u64| -> Result<(f64, State, u64)> {
        if best.2.abs() <= allowed {
            Ok((best.0, best.1, evals))
        } else {
            Err(locate_error(
                settings,
                kappa,
                ev,
                format!(
                    "the bracket collapsed at {} where the event function is {} (allowed {}): the re-integrated trajectory does not cross the event",
                    Num(best.0),
                    Num(best.2),
                    Num(allowed)
                ),
            ))
        }
    };
    for _ in 0..LOCATE_MAX_ITERATIONS {
        if best.2 == 0.0 || (c - a).abs() <= 4.0 * f64::EPSILON * c.abs().max(a.abs()).max(width0) {
            return finish(best, evals);
        }
        let inside = |s: f64| s.is_finite() && (s - a) * (s - c) < 0.0;
        let newton = slope(best.0, &best.1).map(|d| best.0 - best.2 / d);
        let s = match newton {
            Some(s) if inside(s) => s,
            _ => {
                let s = (a * fc - c * fa) / (fc - fa);
                if inside(s) { s } else { 0.5 * (a + c) }
            }
        };
        // Converged when the next point is the current one to rounding (and integrating over a
        // span of rounding size would be a step-size underflow).
        if (s - best.0).abs() <= 16.0 * f64::EPSILON * s.abs().max(best.0.abs()) {
            return finish(best, evals);
        }
        // Always from the bracket's left end, so that every probe samples one and the same
        // trajectory (probes chained from the last point drift apart at loose tolerances, and
        // the bracket logic then locks onto a spurious sign change).
        let mut probe = Phase::new(kappa, Stage::Probe(var), ContactEnd::Overlap, b.s0, b.y0);
        let (_, y, n) = integrate(&mut probe, b.s0, b.y0, s, settings)?;
        evals += n;
        let fs = g(s, &y);
        if !fs.is_finite() {
            return Err(locate_error(
                settings,
                kappa,
                ev,
                format!("the event function is {fs} at {}", Num(s)),
            ));
        }
        best = (s, y, fs);
        if fs > 0.0 {
            a = s;
            fa = fs;
            if side == -1 {
                fc *= 0.5;
            }
            side = -1;
        } else {
            c = s;
            fc = fs;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    Err(locate_error(
        settings,
        kappa,
        ev,
        format!(
            "no convergence in {LOCATE_MAX_ITERATIONS} steps (bracket [{}, {}], event function {} at the best point)",
            Num(a),
            Num(c),
            Num(best.2)
        ),
    ))
}

fn locate_error(settings: &OdeSettings, kappa: f64, ev: Event, detail: String) -> Error {
    Error::Integration {
        method: settings.integrator.name(),
        kappa,
        kind: IntegrationFailure::EventLocation,
        reason: format!("locating the {} event: {detail}", ev.name()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bracket of the turning point at kappa = 0 (p = 0 at x = (5/4)^(2/5)), integrated in t.
    fn hertz_bracket() -> Bracket {
        // At t = 0.9 the undamped contact is still loading; at t = 2.0 it is unloading (the turning
        // point is at half the Hertz time, 1.609).
        let y0 = hertz_state(0.9);
        let y1 = hertz_state(2.0);
        Bracket {
            s0: 0.9,
            y0,
            s1: 2.0,
            y1,
        }
    }

    /// The undamped (kappa = 0) state at time t, from the default ODE in t (x, p, J = 0, t).
    fn hertz_state(t: f64) -> State {
        // Start from the series x = t - t^(7/2)/(3.5 * 2.5) ... at t0 = 1e-3, then integrate.
        let t0: f64 = 1e-3;
        let x0 = t0 - (4.0 / 35.0) * t0.powf(3.5);
        let p0 = 1.0 - 0.4 * t0.powf(2.5);
        let y0 = State::new(x0, p0, 0.0, t0);
        let mut ph = Phase::new(0.0, Stage::Probe(Var::Time), ContactEnd::Overlap, t0, y0);
        let settings = OdeSettings {
            rtol: 1e-14,
            atol: 1e-14,
            ..OdeSettings::DEFAULT
        };
        integrate(&mut ph, t0, y0, t, &settings).unwrap().1
    }

    #[test]
    fn locates_the_hertz_turning_point() {
        // Known answer: x_max = (5/4)^(2/5) at t = tau/2 = 1.60903272985952154 (Hertz,
        // tools/reference/README.md). 1e-11 is a few times the tolerance of the re-integrations.
        let b = hertz_bracket();
        let (s, y, _) = locate(0.0, Var::Time, Event::Turning, &b, &OdeSettings::DEFAULT).unwrap();
        assert!((s - 3.2180654597190430845 / 2.0).abs() < 1e-10, "{s}");
        assert!((y[0] - 1.25f64.powf(0.4)).abs() < 1e-11, "{y:?}");
    }

    #[test]
    fn gives_up_with_an_error_not_its_best_point() {
        // A bracket whose ends do not bracket a sign change of the turning event for this
        // trajectory (both ends loading; the right end's p is faked) has no root: the locator
        // must fail with EventLocation, never return a point with p = 0.4 as if it were the root.
        let b = Bracket {
            s0: 0.5,
            y0: hertz_state(0.5),
            s1: 0.9,
            y1: {
                let mut y = hertz_state(0.9);
                y[1] = -1e-3; // a fake sign change: the trajectory itself has p > 0 there
                y
            },
        };
        match locate(0.0, Var::Time, Event::Turning, &b, &OdeSettings::DEFAULT) {
            Ok((s, y, _)) => panic!("returned {s}, {y:?} for a bracket without a root"),
            Err(e) => assert_eq!(
                e.integration_failure(),
                Some(IntegrationFailure::EventLocation),
                "{e}"
            ),
        }
    }
}
