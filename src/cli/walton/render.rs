//! The figure's points of `restitution walton fit` (the documents are the library's:
//! `restitution::data::report::walton`).

use restitution::fit::walton::WaltonFit;
use restitution::plot::walton::{Fig6Fit, Fig6Point};

pub(super) fn fig6_points(fit: &WaltonFit) -> Vec<Fig6Point> {
    fit.collisions
        .iter()
        .filter_map(|c| {
            c.measured.beta.map(|beta| Fig6Point {
                psi: c.measured.psi,
                beta,
                sliding: c.kind == Some(restitution::models::walton::ContactKind::Sliding),
            })
        })
        .collect()
}

pub(super) fn fig6_fit(fit: &WaltonFit) -> Fig6Fit {
    Fig6Fit {
        slope: fit.slope.value,
        beta0: fit.beta0.value,
        kink_psi: fit.kink_psi.value,
        beta0_ci95: fit.beta0.ci95,
        mu0: fit.mu0.value,
        e: fit.e.value,
        not_determined: (!fit.converged).then_some(if fit.plateau_outside() {
            "β₀ outside [−1, 1]: noise"
        } else {
            "a branch has no data"
        }),
    }
}
