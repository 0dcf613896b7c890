//! Laws an engine can take, fitted to the toolkit's e(v) over a scene's speed range
//! (docs/physics.md §9): a constant e per pair, the viscoelastic law with one best eta, and the full
//! model as a table; and the simplest of them that stays within a tolerance.

use super::range::{SpeedRange, Weight, max_abs, max_of, mean, nodes};
use crate::contact::Contact;
use crate::error::{Error, Result};
use crate::fit::models::{ModelKind, e_vm, predict_e};
use crate::fit::scalar::brent_minimize;
use crate::models::viscoelastic::master::KAPPA_MAX;
use crate::models::viscoelastic::{ContactEnd, VmMethod};

/// A fitted e(v): one of the fit's models with its parameters (SI units, in the order of
/// [`ModelKind::params`]) and the contact-end rule it was fitted with.
#[derive(Debug, Clone, PartialEq)]
pub struct FittedCurve {
    pub kind: ModelKind,
    pub params: Vec<f64>,
    pub rule: ContactEnd,
}

impl FittedCurve {
    /// Checks the parameter count and that eta and sigma_y (and the power law's A) are positive
    /// and finite.
    pub fn new(kind: ModelKind, params: Vec<f64>, rule: ContactEnd) -> Result<Self> {
        if params.len() != kind.n_params() {
            return Err(Error::InvalidParameter {
                name: "number of model parameters",
                value: params.len() as f64,
                expected: "as many as the model has",
            });
        }
        for (spec, &x) in kind.params().iter().zip(&params) {
            let ok = x.is_finite() && (!spec.log || x > 0.0);
            if !ok {
                return Err(Error::InvalidParameter {
                    name: "model parameter",
                    value: x,
                    expected: "a finite number (> 0 for eta, sigma_y and A)",
                });
            }
        }
        Ok(FittedCurve { kind, params, rule })
    }

    /// The damping eta of the model's viscoelastic part, if it has one.
    pub fn eta(&self) -> Option<f64> {
        match self.kind {
            ModelKind::Vm | ModelKind::Min | ModelKind::Product => Some(self.params[0]),
            _ => None,
        }
    }

    /// The yield stress of the model's plastic part, if it has one.
    pub fn sigma_y(&self) -> Option<f64> {
        match self.kind {
            ModelKind::Pm => Some(self.params[0]),
            ModelKind::Min | ModelKind::Product => Some(self.params[1]),
            _ => None,
        }
    }

    /// e at impact speed `v_m_s` for the pair `contact` (master curve for the viscoelastic part).
    /// An e outside (0, 1] (a power law extrapolated too far) is an error naming the speed.
    pub fn e(&self, contact: &Contact, v_m_s: f64) -> Result<f64> {
        let e = predict_e(
            self.kind,
            contact,
            v_m_s,
            &self.params,
            self.rule,
            &VmMethod::Master,
        )?;
        if e.is_finite() && e > 0.0 && e <= 1.0 {
            Ok(e)
        } else {
            Err(Error::InvalidParameter {
                name: "fitted e at speed (m/s)",
                value: v_m_s,
                expected: "a speed where the fitted model gives e in (0, 1]",
            })
        }
    }

    /// Speeds in the range where e(v) is not smooth, for the quadrature's panel edges: the yield
    /// speed of a plastic part (e leaves 1 there), and for `min` the switch from the viscoelastic
    /// to the plastic branch (located by bisection to 1e-14 in ln v after a 400-point scan).
    pub fn kinks(&self, contact: &Contact, range: &SpeedRange) -> Result<Vec<f64>> {
        let mut out = Vec::new();
        if let Some(sy) = self.sigma_y() {
            out.push(contact.try_yield_velocity_m_s(sy)?);
        }
        if self.kind == ModelKind::Min {
            let (eta, sy) = (self.params[0], self.params[1]);
            let diff = |v: f64| -> Result<f64> {
                Ok(e_vm(contact, v, eta, self.rule, &VmMethod::Master)?
                    - crate::fit::models::e_pm(contact, v, sy)?)
            };
            let grid = range.log_grid(400);
            let mut prev = (grid[0], diff(grid[0])?);
            for &v in &grid[1..] {
                let d = diff(v)?;
                if (d > 0.0) != (prev.1 > 0.0) {
                    let (mut a, mut b) = (prev.0.ln(), v.ln());
                    let da = prev.1;
                    for _ in 0..200 {
                        if b - a <= 1e-14 * (1.0 + a.abs()) {
                            break;
                        }
                        let m = 0.5 * (a + b);
                        let dm = diff(m.exp())?;
                        if (dm > 0.0) == (da > 0.0) {
                            a = m;
                        } else {
                            b = m;
                        }
                    }
                    out.push((0.5 * (a + b)).exp());
                }
                prev = (v, d);
            }
        }
        Ok(out)
    }
}

/// The best constant e of one pair over the range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantE {
    /// The weighted mean of e(v): the constant closest to e(v) in the weighted least-squares
    /// sense.
    pub e_mean: f64,
    /// Largest |e_mean - e(v)| over the range.
    pub dev_mean: f64,
    /// (max e + min e)/2: the constant with the smallest largest deviation.
    pub e_minimax: f64,
    /// Its largest deviation, (max e - min e)/2.
    pub dev_minimax: f64,
    /// e(v) at the two ends of the range.
    pub e_lo: f64,
    pub e_hi: f64,
}

/// The best constant e for one pair; see [`ConstantE`].
pub fn constant_e(
    curve: &FittedCurve,
    contact: &Contact,
    range: &SpeedRange,
    weight: Weight,
) -> Result<ConstantE> {
    let breaks = curve.kinks(contact, range)?;
    let f = |v: f64| curve.e(contact, v);
    let e_mean = mean(f, range, weight, &breaks)?;
    let (e_max, _) = max_of(f, range)?;
    let (neg_min, _) = max_of(|v| Ok(-f(v)?), range)?;
    let e_min = -neg_min;
    let (dev_mean, _) = max_abs(|v| Ok(f(v)? - e_mean), range)?;
    Ok(ConstantE {
        e_mean,
        dev_mean,
        e_minimax: 0.5 * (e_max + e_min),
        dev_minimax: 0.5 * (e_max - e_min),
        e_lo: f(range.lo_m_s)?,
        e_hi: f(range.hi_m_s)?,
    })
}

/// The viscoelastic law (one eta for every pair) closest to the fitted curve over the range.
#[derive(Debug, Clone, PartialEq)]
pub struct ViscoelasticFit {
    /// eta minimising the sum over pairs of the weighted mean of (e_vm - e_fit)^2.
    pub eta_mean: f64,
    /// Largest |e_vm(eta_mean) - e_fit| over pairs and speeds.
    pub dev_mean: f64,
    /// eta minimising the largest deviation over pairs and speeds.
    pub eta_minimax: f64,
    pub dev_minimax: f64,
    /// Largest deviation per pair (order of the pairs given), at eta_mean.
    pub dev_mean_per_pair: Vec<f64>,
    /// True when the curve is itself viscoelastic, so that the law is exact (eta = the fitted eta).
    pub exact: bool,
    /// Both minimisations met their tolerance.
    pub converged: bool,
    /// Where a minimisation ended at an end of its search in eta (see [`SearchEnd`]): its eta is
    /// then that end, not a minimum.
    pub search_end: Option<SearchEnd>,
}

/// An end of [`viscoelastic_fit`]'s search in eta.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchEnd {
    /// kappa = 1e-7 at the most damped point: the fitted e(v) is elastic to about that level
    /// over the range, and a smaller eta may be closer still (eta = 0 is no law to export).
    Lower,
    /// kappa = 30 at the least damped point (or 100 anywhere): e is ~1e-7 there; the fitted
    /// e(v) is so lossy that a larger eta may be closer still.
    Upper,
}

impl SearchEnd {
    pub fn name(self) -> &'static str {
        match self {
            SearchEnd::Lower => "lower",
            SearchEnd::Upper => "upper",
        }
    }
}

/// Grid points in ln eta before the Brent polish.
const ETA_SCAN: usize = 61;

/// The closest viscoelastic law; see [`ViscoelasticFit`].
///
/// **Method**: each objective is scanned on `ETA_SCAN` values of ln eta spanning the dampings
/// for which kappa runs from 1e-7 (e = 1 - 1e-7) to 30 (e ~ 1e-7) somewhere in the scene (capped
/// at kappa = 100 everywhere), then
/// polished by Brent's method (argmin) between the neighbours of the best grid point. The
/// least-squares objective uses the quadrature nodes of [`super::range::nodes`]; the minimax one
/// a 200-point grid in ln v per pair, and its reported deviation is then re-measured with
/// [`super::range::max_abs`]. The result is the global minimum over the scan's resolution: both
/// objectives are unimodal in eta in every case tried, but that is not proven.
pub fn viscoelastic_fit(
    curve: &FittedCurve,
    pairs: &[Contact],
    range: &SpeedRange,
    weight: Weight,
) -> Result<ViscoelasticFit> {
    if pairs.is_empty() {
        return Err(Error::InvalidParameter {
            name: "number of pairs",
            value: 0.0,
            expected: "at least one pair",
        });
    }
    let rule = curve.rule;
    let ev = |c: &Contact, v: f64, eta: f64| e_vm(c, v, eta, rule, &VmMethod::Master);
    if curve.kind == ModelKind::Vm {
        let eta = curve.params[0];
        return Ok(ViscoelasticFit {
            eta_mean: eta,
            dev_mean: 0.0,
            eta_minimax: eta,
            dev_minimax: 0.0,
            dev_mean_per_pair: vec![0.0; pairs.len()],
            exact: true,
            converged: true,
            search_end: None,
        });
    }
    // Fitted e cached at the nodes of each pair.
    let mut ls_nodes = Vec::new();
    let mut mm_nodes = Vec::new();
    for c in pairs {
        let breaks = curve.kinks(c, range)?;
        let mut pts = Vec::new();
        for (v, w) in nodes(range, weight, &breaks) {
            pts.push((v, w, curve.e(c, v)?));
        }
        ls_nodes.push(pts);
        let mut grid = Vec::new();
        for v in range.log_grid(200) {
            grid.push((v, curve.e(c, v)?));
        }
        mm_nodes.push(grid);
    }
    let ls = |ln_eta: f64| -> Result<f64> {
        let eta = ln_eta.exp();
        let mut s = 0.0;
        for (c, pts) in pairs.iter().zip(&ls_nodes) {
            for &(v, w, e) in pts {
                let d = ev(c, v, eta)? - e;
                s += w * d * d;
            }
        }
        Ok(s)
    };
    let mm = |ln_eta: f64| -> Result<f64> {
        let eta = ln_eta.exp();
        let mut m: f64 = 0.0;
        for (c, pts) in pairs.iter().zip(&mm_nodes) {
            for &(v, e) in pts {
                m = m.max((ev(c, v, eta)? - e).abs());
            }
        }
        Ok(m)
    };
    // Damping bounds: kappa = eta * kappa(1, v) grows with v; span every pair and the range.
    let per_eta: Vec<f64> = pairs
        .iter()
        .flat_map(|c| [c.kappa(1.0, range.lo_m_s), c.kappa(1.0, range.hi_m_s)])
        .collect();
    let k_min = per_eta.iter().cloned().fold(f64::INFINITY, f64::min);
    let k_max = per_eta.iter().cloned().fold(0.0, f64::max);
    // Upper end: kappa = 30 at the least damped point (e ~ 1e-7 there), but never beyond the
    // master curve's kappa <= 100 anywhere (beyond it e falls back to the ODE, 1000 times slower,
    // for dampings that leave e < 1e-5 at that point and so can never be the best law).
    let (a, b) = (
        (1e-7 / k_max).ln(),
        (30.0 / k_min).min(KAPPA_MAX / k_max).ln(),
    );
    let mut converged = true;
    let mut search_end = None;
    let mut minimise = |f: &dyn Fn(f64) -> Result<f64>| -> Result<f64> {
        let grid: Vec<f64> = (0..ETA_SCAN)
            .map(|i| a + (b - a) * i as f64 / (ETA_SCAN - 1) as f64)
            .collect();
        let mut best = (0, f64::INFINITY);
        for (i, &x) in grid.iter().enumerate() {
            let y = f(x)?;
            if y < best.1 {
                best = (i, y);
            }
        }
        let lo = grid[best.0.saturating_sub(1)];
        let hi = grid[(best.0 + 1).min(ETA_SCAN - 1)];
        let m = brent_minimize(f, lo, hi, 1e-12)?;
        converged &= m.converged;
        let x = if m.fx <= best.1 { m.x } else { grid[best.0] };
        // Brent's tolerance in ln eta is 1.5e-8: within a hundred of it of an end is that end.
        if x - a < 1e-6 {
            search_end = Some(SearchEnd::Lower);
        } else if b - x < 1e-6 {
            search_end = Some(SearchEnd::Upper);
        }
        Ok(x)
    };
    let eta_mean = minimise(&ls)?.exp();
    let eta_minimax = minimise(&mm)?.exp();
    let dev = |eta: f64, c: &Contact| -> Result<f64> {
        Ok(max_abs(|v| Ok(ev(c, v, eta)? - curve.e(c, v)?), range)?.0)
    };
    let mut dev_mean_per_pair = Vec::new();
    let (mut dev_mean, mut dev_minimax) = (0.0f64, 0.0f64);
    for c in pairs {
        let d = dev(eta_mean, c)?;
        dev_mean_per_pair.push(d);
        dev_mean = dev_mean.max(d);
        dev_minimax = dev_minimax.max(dev(eta_minimax, c)?);
    }
    // The minimax search works on a 200-point grid and stops at Brent's tolerance (1.5e-8 in
    // ln eta); when the least-squares eta does better on the refined deviation (as when the
    // curve is viscoelastic over the whole range and both deviations are ~1e-10), it is the
    // better minimax answer.
    let (eta_minimax, dev_minimax) = if dev_mean < dev_minimax {
        (eta_mean, dev_mean)
    } else {
        (eta_minimax, dev_minimax)
    };
    Ok(ViscoelasticFit {
        eta_mean,
        dev_mean,
        eta_minimax,
        dev_minimax,
        dev_mean_per_pair,
        exact: false,
        converged,
        search_end,
    })
}

/// e(v) of every pair on a grid, for event-driven codes.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Speeds evenly spaced in ln v over the range, m/s.
    pub v_m_s: Vec<f64>,
    /// e per pair (order of the pairs given), then per speed.
    pub e: Vec<Vec<f64>>,
    /// Largest |e(v) - table(v)| over pairs and the range, with the table interpolated linearly
    /// in ln v.
    pub interpolation_dev: f64,
}

impl Table {
    /// The table's e for pair `p` at speed v: linear in ln v between grid points, the end values
    /// outside the range.
    pub fn interpolate(&self, p: usize, v: f64) -> f64 {
        let g = &self.v_m_s;
        let e = &self.e[p];
        if v <= g[0] {
            return e[0];
        }
        let i = g.partition_point(|&x| x < v).min(g.len() - 1);
        let (v0, v1) = (g[i - 1], g[i]);
        let t = (v / v0).ln() / (v1 / v0).ln();
        e[i - 1] + t * (e[i] - e[i - 1])
    }
}

/// The fitted curve tabulated on `points` >= 2 speeds; see [`Table`].
pub fn table(
    curve: &FittedCurve,
    pairs: &[Contact],
    range: &SpeedRange,
    points: usize,
) -> Result<Table> {
    let v_m_s = range.log_grid(points.max(2));
    let mut e = Vec::new();
    for c in pairs {
        let mut row = Vec::new();
        for &v in &v_m_s {
            row.push(curve.e(c, v)?);
        }
        e.push(row);
    }
    let mut t = Table {
        v_m_s,
        e,
        interpolation_dev: 0.0,
    };
    let mut dev = 0.0f64;
    for (p, c) in pairs.iter().enumerate() {
        let (d, _) = max_abs(|v| Ok(curve.e(c, v)? - t.interpolate(p, v)), range)?;
        dev = dev.max(d);
    }
    t.interpolation_dev = dev;
    Ok(t)
}

/// The kinds of law, simplest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::IntoStaticStr)]
#[strum(serialize_all = "kebab-case")]
pub enum LawKind {
    /// One e per pair, whatever the speed.
    ConstantE,
    /// Hertz with viscoelastic damping, one eta (LAMMPS `damping viscoelastic`).
    Viscoelastic,
    /// The fitted model itself, tabulated.
    Table,
}

impl LawKind {
    pub const ALL: [LawKind; 3] = [LawKind::ConstantE, LawKind::Viscoelastic, LawKind::Table];

    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// The simplest law within a tolerance of the fitted curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Recommendation {
    pub tolerance: f64,
    /// Every law with its largest deviation (the best that law can do: minimax constant and
    /// minimax eta; the table as interpolated).
    pub deviations: Vec<(LawKind, f64)>,
    /// The first law, simplest first, whose deviation is <= tolerance; `None` if none is.
    pub chosen: Option<LawKind>,
}

/// Picks the simplest law within `tolerance` (> 0, finite) of the fitted curve.
pub fn recommend(tolerance: f64, deviations: &[(LawKind, f64)]) -> Result<Recommendation> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(Error::InvalidParameter {
            name: "tolerance",
            value: tolerance,
            expected: "a finite number > 0",
        });
    }
    let mut devs = deviations.to_vec();
    devs.sort_by_key(|(k, _)| LawKind::ALL.iter().position(|x| x == k));
    let chosen = devs.iter().find(|(_, d)| *d <= tolerance).map(|(k, _)| *k);
    Ok(Recommendation {
        tolerance,
        deviations: devs,
        chosen,
    })
}
