//! Monte Carlo study of the Walton fit on the paper-like synthetic experiment
//! (`SyntheticSpec::paper`): bias, scatter and 95%-interval coverage of beta_0 and mu_0 for each
//! weighting, and how often the standard errors match the observed scatter.
//!
//! Run: `cargo run --release --example walton_coverage [REPETITIONS] [BOOTSTRAP] [N]`
//! (defaults 400, 1000, 60). The README's coverage figures come from this program.

use restitution::data::walton::measure_records;
use restitution::fit::walton::{FitOptions, Weights, fit};
use restitution::synthetic::{SyntheticSpec, synthetic_collisions};

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("integer arguments"))
        .collect();
    let reps = *args.first().unwrap_or(&400);
    let boot = *args.get(1).unwrap_or(&1000);
    let mut spec = SyntheticSpec::paper();
    spec.n = *args.get(2).unwrap_or(&60);
    let truth = spec.params;
    println!(
        "{reps} data sets of {} collisions, {boot} bootstrap resamples each; truth beta0 = {}, mu0 = {}, e = {}",
        spec.n, truth.beta0, truth.mu0, truth.e
    );
    println!(
        "weights  param   mean      sd(fit)   mean stderr  coverage(ci95)  coverage(+-1.96 se)  not converged"
    );
    for weights in [Weights::Camera, Weights::Equal] {
        // name, truth, estimates, stderrs, covered by ci95, covered by +-1.96 stderr
        type Row = (&'static str, f64, Vec<f64>, Vec<f64>, usize, usize);
        let mut rows: Vec<Row> = vec![
            ("beta0", truth.beta0, vec![], vec![], 0, 0),
            ("mu0", truth.mu0, vec![], vec![], 0, 0),
            ("e", truth.e, vec![], vec![], 0, 0),
        ];
        let mut failed = 0;
        let t0 = std::time::Instant::now();
        for rep in 0..reps {
            let (_, measured) = synthetic_collisions(&spec, 10_000 + rep as u64).unwrap();
            let m = measure_records("synthetic", &measured).unwrap();
            let options = FitOptions {
                weights,
                bootstrap: boot,
                seed: rep as u64,
                ..FitOptions::default()
            };
            let f = fit(&m, &options).unwrap();
            if !f.converged {
                failed += 1;
                continue;
            }
            let est = [
                (f.beta0.value, f.beta0.stderr, f.beta0.ci95),
                (f.mu0.value, f.mu0.stderr, f.mu0.ci95),
                (f.e.value, Some(f.e.stderr), f.e.ci95),
            ];
            for (row, (v, se, ci)) in rows.iter_mut().zip(est) {
                row.2.push(v);
                row.3.push(se.unwrap_or(f64::NAN));
                if let Some((lo, hi)) = ci
                    && lo <= row.1
                    && row.1 <= hi
                {
                    row.4 += 1;
                }
                if let Some(se) = se
                    && (v - row.1).abs() <= 1.96 * se
                {
                    row.5 += 1;
                }
            }
        }
        let secs = t0.elapsed().as_secs_f64();
        for (name, _, vals, ses, cov, cov_se) in &rows {
            let n = vals.len() as f64;
            let mean = vals.iter().sum::<f64>() / n;
            let sd = (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let mse = ses.iter().sum::<f64>() / n;
            println!(
                "{:<8} {:<7} {:<9.5} {:<9.5} {:<12.5} {:<15.3} {:<20.3} {}",
                weights.as_str(),
                name,
                mean,
                sd,
                mse,
                *cov as f64 / n,
                *cov_se as f64 / n,
                failed
            );
        }
        println!(
            "  ({:.2} ms per fit including bootstrap)",
            1e3 * secs / reps as f64
        );
    }
}
