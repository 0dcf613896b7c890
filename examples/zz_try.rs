use restitution::contact::Material;
use restitution::fit::{self, FitOptions, ModelKind, input};
fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or("data/fig7_nylon.csv".into());
    let inp = input::read_fit_csv(
        std::path::Path::new(&path),
        Material::preset("nylon").unwrap(),
        false,
    )
    .unwrap();
    for w in &inp.warnings {
        eprintln!("warning: {w}");
    }
    let opts = FitOptions::default();
    for kind in ModelKind::ALL {
        let t = std::time::Instant::now();
        let r = fit::fit(&inp.data, kind, &opts).unwrap();
        let dt = t.elapsed();
        println!(
            "{kind}: chi2={:.3} red={:.3} aic={:.2} conv={} evals={} prof={} t={:?}",
            r.chi2, r.reduced_chi2, r.aic, r.converged, r.evaluations, r.profile_evaluations, dt
        );
        for p in &r.params {
            println!(
                "   {} {:?} best={:.6e} val={:?} se={:?} se_abs={:?} ci={:?}",
                p.key, p.status, p.best_fit, p.value, p.stderr, p.stderr_abs, p.ci95
            );
        }
        for p in &r.derived {
            println!(
                "   derived {} {:?} {:?} {:?}",
                p.key, p.value, p.stderr, p.ci95
            );
        }
        println!("   corr {:?} notes {:?}", r.correlation, r.notes);
    }
}
