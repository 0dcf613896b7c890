//! Is the fit's minimum global? Seeded synthetic data sets, each fitted by every model and
//! compared with an independent exhaustive reference.
//!
//! ```text
//! cargo run --release --example fit_global            # the full run (400 data sets)
//! cargo run --release --example fit_global -- 0 40    # seeds 0..40 only
//! cargo run --release --example fit_global -- --dumped DIR
//! ```
//!
//! `--dumped DIR` checks data files instead: the `fit` cases the fuzzer wrote with `--dump DIR`
//! (`DIR/case-I/args.txt` and the file it names), each read as the command line would read it
//! (its material flags, `--contact-end` and `--strict`); files it refuses, and cases with
//! `--exact`, are skipped. The fuzzer's inputs are far from the synthetic sets: a few rows,
//! speeds of 1e-300 or 1e300 m/s, duplicated rows, extreme materials and error bars.
//!
//! **Data sets** (seed s, rand's StdRng): a material (nu uniform in 0.2-0.49, rho log-uniform in
//! 900-8000 kg/m^3, Y log-uniform in 1e8-2e11 Pa), one to four diameters (1-50 mm) as identical
//! pairs, spheres on a wall or unequal pairs, a speed range (lower end 0.05-2 m/s, 5-300 times
//! wider), 8-40 points per size at log-uniform speeds, a truth drawn from `vm`, `pm`, `min`,
//! `product`, `powerlaw` and two laws the fit does not offer: additive energy losses
//! 1 - e^2 = (1 - e_vm^2) + (1 - e_pm^2) and a two-exponent power law 1 - e = c1 v^p + c2 v^q.
//! Noise: Gaussian with sigma_e = level (constant), level (1 - e) + 1e-4 (relative to the
//! dissipation) or the paper's camera model 2 e Delta v / v, the level log-uniform over 2.5
//! decades; one set in eight without errors (an unweighted fit).
//!
//! **Reference** (independent of the fit's search and polish; only the model functions of the
//! library are shared): the model's search box as the fit's documentation defines it,
//! recomputed here from the contact functions; a dense grid in the log parameters (4000 points
//! for one parameter, 400 x 300 for two, 48 x 64 x 64 for the power law's (ln A, a, b)); from
//! every grid-local minimum (ties broken by position) argmin's Nelder-Mead on chi2 computed
//! point by point with `predict_e`. The reference chi2 is the lowest of all.
//!
//! **Pass**: the fit's chi2 is at most the reference's times (1 + 1e-6), plus the rounding of
//! chi2 itself (eight ulps in every residual: it matters only for chi2 near 0, a few rows the
//! model goes through); a fit that returns an error fails. Also counted: false certificates, a
//! certified fit above the reference by more than the gap it states (plus that rounding)
//! without fine cells (a certificate with fine cells leaves them to the polishes and says so:
//! a fit short there is counted apart). Reported too: fits not
//! certified global, fits not converged.

mod cases;
mod reference;

use cases::Case;
use reference::Outcome;
use restitution::models::viscoelastic::ContactEnd;

fn main() {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, dir] = raw.as_slice()
        && flag == "--dumped"
    {
        return dumped(std::path::Path::new(dir));
    }
    let args: Vec<u64> = raw
        .iter()
        .map(|a| a.parse().expect("seed numbers"))
        .collect();
    let (from, to) = match args.as_slice() {
        [a, b] => (*a, *b),
        _ => (0, 400),
    };
    let seeds: Vec<u64> = (from..to).collect();
    let results = in_threads(seeds, |seed| {
        let case = cases::make_case(seed);
        let out = reference::check(&case);
        (case, out)
    });
    report(&results, &format!("seeds {from}..{to}"));
}

/// The `fit` cases of a fuzzer's dump (see the module doc): each case's number stands for the
/// seed in the report.
fn dumped(dir: &std::path::Path) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| {
        eprintln!("fit_global: --dumped {}: {e}", dir.display());
        std::process::exit(2)
    });
    let mut found: Vec<(u64, std::path::PathBuf)> = entries
        .filter_map(|e| {
            let p = e.ok()?.path();
            let i = p
                .file_name()?
                .to_str()?
                .strip_prefix("case-")?
                .parse()
                .ok()?;
            Some((i, p))
        })
        .collect();
    found.sort();
    let cases: Vec<Case> = found.iter().filter_map(|(i, p)| read_case(*i, p)).collect();
    println!(
        "{} of {} cases are fits of data the command line reads",
        cases.len(),
        found.len()
    );
    let results = in_threads(cases, |case| {
        let out = reference::check_data(case.seed, case.truth, &case.data, case.rule);
        (case, out)
    });
    report(
        &results,
        &format!("{} fuzz cases of {}", results.len(), dir.display()),
    );
}

fn read_case(i: u64, dir: &std::path::Path) -> Option<Case> {
    let text = std::fs::read_to_string(dir.join("args.txt")).ok()?;
    let args: Vec<&str> = text.lines().collect();
    if args.first() != Some(&"fit") || args.contains(&"--exact") {
        return None;
    }
    let value = |flag: &str| {
        args.iter()
            .position(|a| *a == flag)
            .and_then(|k| args.get(k + 1).copied())
    };
    let rule = match value("--contact-end") {
        None | Some("overlap") => ContactEnd::Overlap,
        Some("force") => ContactEnd::Force,
        Some(_) => return None,
    };
    let material = match value("--material") {
        Some(name) => restitution::contact::Material::preset(name)?,
        None => restitution::contact::Material::new(
            value("--youngs-pa")?.parse().ok()?,
            value("--poisson")?.parse().ok()?,
            value("--density-kg-m3")?.parse().ok()?,
        )
        .ok()?,
    };
    let file = dir.join(args.get(1)?.replace("{dir}/", ""));
    let input =
        restitution::data::fit_input::read_fit_csv(&file, material, args.contains(&"--strict"))
            .ok()?;
    Some(Case {
        seed: i,
        truth: cases::Truth::File,
        rule,
        data: input.data,
        description: format!("{}", dir.display()),
    })
}

/// `work` on every item, on two threads (items dealt alternately), results in the threads'
/// order.
fn in_threads<T: Send, R: Send>(items: Vec<T>, work: impl Fn(T) -> R + Sync) -> Vec<R> {
    let threads = 2;
    let mut shares: Vec<Vec<T>> = (0..threads).map(|_| Vec::new()).collect();
    for (k, item) in items.into_iter().enumerate() {
        shares[k % threads].push(item);
    }
    let work = &work;
    std::thread::scope(|s| {
        let handles: Vec<_> = shares
            .into_iter()
            .map(|mine| s.spawn(move || mine.into_iter().map(work).collect::<Vec<R>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("worker"))
            .collect()
    })
}

fn report(results: &[(Case, Vec<Outcome>)], what: &str) {
    let mut total = 0;
    let mut failed = 0;
    let mut refused = 0;
    let mut within_gap = 0;
    let mut false_certificates = 0;
    let mut short = 0;
    let mut uncertified = 0;
    let mut unconverged = 0;
    let mut per_model = std::collections::BTreeMap::new();
    let mut per_truth = std::collections::BTreeMap::new();
    for (case, outs) in results {
        *per_truth.entry(case.truth.name()).or_insert(0) += 1;
        for o in outs {
            total += 1;
            let e = per_model.entry(o.kind.name()).or_insert((0, 0));
            e.0 += 1;
            if !o.certificate_holds() {
                false_certificates += 1;
                println!(
                    "CERT seed {} fit {}: fit chi2 {:e} reference {:e}, certified gap {:e}, {} fine cells {}",
                    o.seed, o.kind, o.fit_chi2, o.ref_chi2, o.gap, o.fine_cells, case.description
                );
            }
            if !o.pass() {
                failed += 1;
                e.1 += 1;
                refused += o.error.is_some() as usize;
                let explained = o.within_gap();
                short += o.short_in_fine_cells() as usize;
                within_gap += explained as usize;
                println!(
                    "FAIL seed {} truth {} fit {}: fit chi2 {:e} reference {:e} ({}){} {}",
                    o.seed,
                    o.truth.name(),
                    o.kind,
                    o.fit_chi2,
                    o.ref_chi2,
                    o.error.as_deref().unwrap_or("-"),
                    if explained {
                        format!(" within the certified gap {:e}", o.gap)
                    } else {
                        String::new()
                    },
                    case.description
                );
            }
            uncertified += !o.certified as usize;
            unconverged += !o.converged as usize;
            if o.pass() && !(o.certified && o.converged) {
                println!(
                    "note seed {} fit {}: certified {} converged {} (fit {} reference {})",
                    o.seed, o.kind, o.certified, o.converged, o.fit_chi2, o.ref_chi2
                );
            }
        }
    }
    println!(
        "fit_global: {} data sets ({what}), {total} fits: {failed} above the \
         reference by more than 1e-6 relative and the rounding ({refused} of them refused with an error, \
         {within_gap} within the gap their certificate states, {short} inside the fine cells it \
         leaves to the polishes); {false_certificates} false certificates; {uncertified} not \
         certified global, {unconverged} not converged",
        results.len()
    );
    println!("truths: {per_truth:?}");
    for (k, (n, f)) in per_model {
        println!("  {k}: {n} fits, {f} failures");
    }
}
