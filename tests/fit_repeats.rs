//! Rows that share a pair geometry and a speed are fitted as one point (`FitData::merge_repeats`):
//! the fit must be the one of the rows as given. Checked against fits of data without repeats
//! (which are not merged), by two identities of weighted least squares:
//!
//! - every row written twice: the same parameters, chi2 doubled, twice the rows and dof = 2n - k,
//!   and the errors that take the error bars as exact (`stderr_abs`) smaller by sqrt(2) (J^T J
//!   doubles);
//! - every row split into two rows e - d and e + d with error sqrt(2) sigma: the same parameters
//!   as the original rows, chi2 larger by the constant sum (2 d^2 / (2 sigma^2)) = sum d^2/sigma^2.
//!
//! Tolerances: the parameters 4 sqrt(0.01 tau) of their standard error (tau the search's
//! tolerance in chi2; merged and unmerged runs take different floating-point paths to the same
//! minimum, and the two-parameter polishes stop where the Gauss-Newton step promises less than
//! 0.01 tau: each run's chi2 that close to the minimum, its parameters within sqrt(0.01 tau)
//! standard errors of it; two runs, and a factor 2 for the models' curvature); a parameter
//! without a standard error (a bound) 1e-7 relative; chi2 1e-9 relative (the minimum's value is
//! insensitive to first order in the parameters).

use restitution::contact::Material;
use restitution::fit::{FitData, FitOptions, ModelKind, Observation, fit};

/// The Fig. 7 data, keeping the first row of each (d, v_n): no repeats, so not merged.
fn fig7() -> FitData {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/fig7_nylon.csv");
    let m = Material::preset("nylon").unwrap();
    let all = restitution::data::fit_input::read_fit_csv(std::path::Path::new(path), m, false)
        .unwrap()
        .data;
    let mut obs: Vec<Observation> = Vec::new();
    for o in &all.obs {
        if !obs
            .iter()
            .any(|p| p.d_mm == o.d_mm && p.v_n_m_s == o.v_n_m_s)
        {
            obs.push(*o);
        }
    }
    assert!(obs.len() > 40, "{} distinct points", obs.len());
    FitData::new(m, obs).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

fn assert_same_params(a: &restitution::fit::FitResult, b: &restitution::fit::FitResult) {
    for (p, q) in a.params.iter().zip(&b.params) {
        // Each run's chi2 within 0.01 tau of the minimum, so its parameters within
        // sqrt(0.01 tau) standard errors (error bars as given); both runs, and a factor 2 for the
        // models' curvature.
        let tau = a.global.tolerance_chi2.max(b.global.tolerance_chi2);
        let close = match p.stderr_abs {
            Some(sd) => (p.best_fit - q.best_fit).abs() <= 4.0 * (0.01 * tau).sqrt() * sd,
            None => rel(p.best_fit, q.best_fit) < 1e-7,
        };
        assert!(
            close,
            "{} {}: {} vs {} (standard error {:?})",
            a.model.name(),
            p.key,
            p.best_fit,
            q.best_fit,
            p.stderr_abs
        );
    }
}

#[test]
fn every_row_twice() {
    let data = fig7();
    assert!(
        data.merge_repeats().is_none(),
        "the Fig. 7 data have no repeats"
    );
    let mut obs = data.obs.clone();
    obs.extend(data.obs.iter().copied());
    let twice = FitData::new(data.material, obs).unwrap();
    let m = twice.merge_repeats().expect("every row repeats");
    assert_eq!(m.data.len(), data.len());
    // Zero but for the rounding of the mean: w (e ulp)^2 ~ 1e3 * 1e-32 per row.
    assert!(m.chi2_offset < 1e-24, "{}", m.chi2_offset);
    for kind in ModelKind::ALL {
        let a = fit(&data, kind, &FitOptions::default()).unwrap();
        let b = fit(&twice, kind, &FitOptions::default()).unwrap();
        assert!(a.converged && b.converged, "{}", kind.name());
        assert_same_params(&a, &b);
        assert!(rel(b.chi2, 2.0 * a.chi2) < 1e-9, "{}", kind.name());
        assert_eq!(b.n, 2 * a.n);
        assert_eq!(b.dof, 2 * a.n - kind.n_params());
        for (p, q) in a.params.iter().zip(&b.params) {
            if let (Some(x), Some(y)) = (p.stderr_abs, q.stderr_abs) {
                // 1e-5: the Jacobian is a finite difference (step 1e-5) at minima 1e-7 apart.
                assert!(
                    rel(y * 2f64.sqrt(), x) < 1e-5,
                    "{} {}: {x} {y}",
                    kind.name(),
                    p.key
                );
            }
        }
        assert_eq!(b.predicted.len(), b.n);
        assert_eq!(&b.predicted[..a.n], &b.predicted[a.n..]);
        assert!(
            b.notes
                .iter()
                .any(|n| n.contains("distinct (d, d2, v_n) points")),
            "the merge is named: {:?}",
            b.notes
        );
    }
}

#[test]
fn split_rows_add_a_constant() {
    let data = fig7();
    let d = 0.013;
    let mut obs = Vec::new();
    let mut offset = 0.0;
    for o in &data.obs {
        let s = o.e_err.unwrap() * 2f64.sqrt();
        for sign in [-1.0, 1.0] {
            obs.push(Observation {
                e: o.e + sign * d,
                e_err: Some(s),
                ..*o
            });
        }
        offset += 2.0 * d * d / (s * s);
    }
    let split = FitData::new(data.material, obs).unwrap();
    for kind in [ModelKind::Vm, ModelKind::Min, ModelKind::PowerLaw] {
        let a = fit(&data, kind, &FitOptions::default()).unwrap();
        let b = fit(&split, kind, &FitOptions::default()).unwrap();
        assert_same_params(&a, &b);
        assert!(
            rel(b.chi2, a.chi2 + offset) < 1e-9,
            "{}: {} vs {} + {}",
            kind.name(),
            b.chi2,
            a.chi2,
            offset
        );
        // The rows' residuals, not the points': each row is d/s away from its point.
        let r = &b.normalized_residuals;
        assert!(
            rel(
                (r[1] - r[0]).abs(),
                2.0 * d / (data.obs[0].e_err.unwrap() * 2f64.sqrt())
            ) < 1e-9
        );
    }
}
