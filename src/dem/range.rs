//! A scene's range of impact speeds, its weight, and the two operations every law translation
//! needs on a curve over that range: the weighted mean and the largest absolute value.

use crate::error::{Error, Result};

/// The normal impact speeds a scene produces, lo < hi, in m/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedRange {
    pub lo_m_s: f64,
    pub hi_m_s: f64,
}

impl SpeedRange {
    /// Validates 0 < lo < hi, both finite. The upper end is capped at 1e6 m/s and the ratio at
    /// 1e12 only in the sense that wider ranges are rejected: no contact model here means anything
    /// beyond them, and the quadrature below is sized for ranges of up to 12 decades.
    pub fn new(lo_m_s: f64, hi_m_s: f64) -> Result<Self> {
        let bad = |value, expected| Error::InvalidParameter {
            name: "speed range (m/s)",
            value,
            expected,
        };
        if !(lo_m_s.is_finite() && lo_m_s > 0.0) {
            return Err(bad(lo_m_s, "a lower end > 0"));
        }
        if !(hi_m_s.is_finite() && hi_m_s > lo_m_s) {
            return Err(bad(hi_m_s, "an upper end above the lower end"));
        }
        if hi_m_s > 1e6 || hi_m_s / lo_m_s > 1e12 {
            return Err(bad(hi_m_s, "at most 1e6 m/s and 12 decades"));
        }
        Ok(SpeedRange { lo_m_s, hi_m_s })
    }

    /// `n` >= 2 speeds spaced evenly in ln v from lo to hi (both included, exactly).
    pub fn log_grid(&self, n: usize) -> Vec<f64> {
        let n = n.max(2);
        let (a, b) = (self.lo_m_s.ln(), self.hi_m_s.ln());
        (0..n)
            .map(|i| match i {
                0 => self.lo_m_s,
                _ if i == n - 1 => self.hi_m_s,
                _ => (a + (b - a) * i as f64 / (n - 1) as f64).exp(),
            })
            .collect()
    }
}

/// How the speeds of a scene are distributed over its range, for the weighted means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, strum::IntoStaticStr)]
#[strum(serialize_all = "kebab-case")]
pub enum Weight {
    /// Uniform in ln v: every decade of speed counts the same (the default: granular flows span
    /// decades of collision speed and nothing singles out one of them).
    #[default]
    LogUniform,
    /// Uniform in v.
    Uniform,
}

impl Weight {
    pub fn name(self) -> &'static str {
        self.into()
    }

    fn to_u(self, v: f64) -> f64 {
        match self {
            Weight::LogUniform => v.ln(),
            Weight::Uniform => v,
        }
    }

    fn to_v(self, u: f64) -> f64 {
        match self {
            Weight::LogUniform => u.exp(),
            Weight::Uniform => u,
        }
    }
}

/// Abscissae and weights of the 8-point Gauss-Legendre rule on [-1, 1] (Abramowitz & Stegun,
/// Table 25.4; exact for polynomials of degree <= 15).
const GL8: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362_0),
    (0.525_532_409_916_329_0, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// Panels per quadrature between breakpoints. With 8 nodes each, a curve as smooth as e(v) of
/// these models is integrated to rounding (tests: exact on polynomials; min/pm kinks are handled
/// by breakpoints, so no panel straddles one).
const PANELS: usize = 48;

/// The weighted quadrature nodes of a range: speeds and weights summing to 1, from composite
/// 8-point Gauss-Legendre in the weight's variable (ln v or v), with panel edges at every
/// breakpoint inside the range (places where the curve has a kink, so that no panel holds one).
pub fn nodes(range: &SpeedRange, weight: Weight, breaks: &[f64]) -> Vec<(f64, f64)> {
    let (ua, ub) = (weight.to_u(range.lo_m_s), weight.to_u(range.hi_m_s));
    let mut edges = vec![ua];
    let mut inner: Vec<f64> = breaks
        .iter()
        .filter(|b| b.is_finite() && **b > range.lo_m_s && **b < range.hi_m_s)
        .map(|&b| weight.to_u(b))
        .collect();
    inner.sort_by(f64::total_cmp);
    edges.extend(inner);
    edges.push(ub);
    let total = ub - ua;
    let mut out = Vec::new();
    for w in edges.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let h = (b - a) / PANELS as f64;
        for k in 0..PANELS {
            let mid = a + (k as f64 + 0.5) * h;
            for &(x, wt) in &GL8 {
                for sign in [-1.0, 1.0] {
                    let u = mid + sign * x * 0.5 * h;
                    out.push((weight.to_v(u), wt * 0.5 * h / total));
                }
            }
        }
    }
    out
}

/// The weighted mean of f over the range (see [`nodes`]).
pub fn mean(
    f: impl Fn(f64) -> Result<f64>,
    range: &SpeedRange,
    weight: Weight,
    breaks: &[f64],
) -> Result<f64> {
    let mut s = 0.0;
    for (v, w) in nodes(range, weight, breaks) {
        s += w * f(v)?;
    }
    Ok(s)
}

/// Samples of the maximum search, spaced evenly in ln v.
const SAMPLES: usize = 400;

/// The largest value of f on the range and where it is, in m/s.
///
/// **Method**: f at `SAMPLES` speeds evenly spaced in ln v (ends included), then golden-section
/// search for the maximum between the neighbours of the best sample (at most 100 steps, to a
/// relative width of 1e-12 in ln v). Finds the global maximum whenever f is unimodal between
/// neighbouring samples, which holds for the smooth, monotone or single-kinked curves of the
/// contact models (a curve with features narrower than 1/400 of the range could hide one).
/// A NaN from f is an error.
pub fn max_of(f: impl Fn(f64) -> Result<f64>, range: &SpeedRange) -> Result<(f64, f64)> {
    let grid = range.log_grid(SAMPLES);
    let mut vals = Vec::with_capacity(grid.len());
    for &v in &grid {
        let y = f(v)?;
        if y.is_nan() {
            return Err(Error::InvalidParameter {
                name: "curve value at speed (m/s)",
                value: v,
                expected: "a number (the curve gave NaN)",
            });
        }
        vals.push(y);
    }
    let (mut i_best, mut best) = (0, vals[0]);
    for (i, &y) in vals.iter().enumerate() {
        if y > best {
            i_best = i;
            best = y;
        }
    }
    let mut arg = grid[i_best];
    let lo = grid[i_best.saturating_sub(1)].ln();
    let hi = grid[(i_best + 1).min(grid.len() - 1)].ln();
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (lo, hi);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let mut fc = f(c.exp())?;
    let mut fd = f(d.exp())?;
    for _ in 0..100 {
        if (b - a).abs() <= 1e-12 * (1.0 + a.abs()) {
            break;
        }
        if fc.is_nan() || fd.is_nan() {
            return Err(Error::InvalidParameter {
                name: "curve value at speed (m/s)",
                value: c.exp(),
                expected: "a number (the curve gave NaN)",
            });
        }
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c.exp())?;
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d.exp())?;
        }
    }
    for (u, y) in [(c, fc), (d, fd)] {
        if y > best {
            best = y;
            arg = u.exp();
        }
    }
    Ok((best, arg))
}

/// The largest |f| on the range and where it is; see [`max_of`].
pub fn max_abs(f: impl Fn(f64) -> Result<f64>, range: &SpeedRange) -> Result<(f64, f64)> {
    max_of(|v| Ok(f(v)?.abs()), range)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrature_is_exact_on_polynomials_and_sums_weights_to_one() {
        let r = SpeedRange::new(0.5, 40.0).unwrap();
        for w in [Weight::LogUniform, Weight::Uniform] {
            let total: f64 = nodes(&r, w, &[2.0, 7.0]).iter().map(|n| n.1).sum();
            assert!((total - 1.0).abs() < 1e-14, "{total}");
        }
        // Uniform weight: mean of v^3 = (b^4 - a^4)/(4 (b - a)); degree 3 is integrated exactly.
        let m = mean(|v| Ok(v.powi(3)), &r, Weight::Uniform, &[]).unwrap();
        let exact = (40f64.powi(4) - 0.5f64.powi(4)) / (4.0 * 39.5);
        assert!((m / exact - 1.0).abs() < 1e-14);
        // Log-uniform weight: mean of v = (b - a)/ln(b/a); ln v is the variable, e^u is smooth.
        let m = mean(Ok, &r, Weight::LogUniform, &[3.0]).unwrap();
        let exact = 39.5 / 80f64.ln();
        assert!((m / exact - 1.0).abs() < 1e-14);
    }

    #[test]
    fn breakpoints_make_kinks_exact() {
        // min(v, k) over [1, 4], uniform: (1/3)(int_1^k v dv + k (4 - k)), with k = 2.01 inside a
        // panel (2 itself is a panel edge).
        let k = 2.01;
        let exact = ((k * k - 1.0) / 2.0 + k * (4.0 - k)) / 3.0;
        let r = SpeedRange::new(1.0, 4.0).unwrap();
        let m = mean(|v| Ok(v.min(k)), &r, Weight::Uniform, &[k]).unwrap();
        // (768 nodes summed: rounding of a few 1e-16 each.)
        assert!((m - exact).abs() < 1e-14);
        let loose = mean(|v| Ok(v.min(k)), &r, Weight::Uniform, &[]).unwrap();
        assert!(
            (loose - exact).abs() > 1e-9,
            "without the break the kink costs accuracy: {}",
            loose - exact
        );
    }

    #[test]
    fn maximum_between_samples_is_refined() {
        let r = SpeedRange::new(0.1, 100.0).unwrap();
        // A peak at v = 3.3 (between samples): -(ln v - ln 3.3)^2.
        let (m, at) = max_of(|v| Ok(1.0 - (v.ln() - 3.3f64.ln()).powi(2)), &r).unwrap();
        assert!(
            (m - 1.0).abs() < 1e-15 && (at / 3.3 - 1.0).abs() < 1e-6,
            "{m} {at}"
        );
        let (m, at) = max_abs(|v| Ok(v - 50.0), &r).unwrap();
        assert!(
            (m - 50.0).abs() < 1e-12 && (at - 100.0).abs() < 1e-9,
            "{m} {at}"
        );
        assert!(max_of(|_| Ok(f64::NAN), &r).is_err());
    }

    #[test]
    fn bad_ranges() {
        for (a, b) in [
            (0.0, 1.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (f64::NAN, 1.0),
            (1.0, f64::INFINITY),
        ] {
            assert!(SpeedRange::new(a, b).is_err(), "{a} {b}");
        }
        assert!(SpeedRange::new(1e-300, 1.0).is_err());
        let g = SpeedRange::new(1.0, 100.0).unwrap().log_grid(3);
        assert_eq!(g[0], 1.0);
        assert!((g[1] - 10.0).abs() < 1e-13);
        assert_eq!(g[2], 100.0);
    }
}
