#!/usr/bin/env bash
# The README's figures on the measurement chain (section "From video to parameters"):
# 1. Walton parameters through the whole chain: 30 seeded virtual oblique experiments (120
#    collisions at 1.5-2.5 m/s, incidences 5-80 degrees, truth beta_0 = 0.5, mu_0 = 0.175) through
#    simulate -> kinematics --fixed-gravity -> walton fit (500 bootstrap resamples): how often the
#    95% intervals cover the truth, and the mean of (estimate - truth) / stderr.
# 2. Fixed-gravity against free fits: the median |e - e_true| over 1000 simulated collisions, and
#    for each the standardised errors of e and the momentum-check scatter against its predictions.
# Output: reports/kinematics/chain_coverage.txt. Deterministic (every step is seeded).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
B=target/release/restitution
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
out=reports/kinematics/chain_coverage.txt
{
    echo "# made by scripts/chain_coverage.sh"
    echo "seed,beta0,beta0_ci95_lo,beta0_ci95_hi,beta0_stderr,mu0,mu0_ci95_lo,mu0_ci95_hi,mu0_stderr,converged"
    for seed in $(seq 1 30); do
        $B simulate --material nylon --out "$tmp/sim$seed" --seed "$seed" --n 120 --v-n-m-s 1.5,2.5 \
            --incidence-deg 5,80 --model vm --mu0 0.175 --beta0 0.5 > /dev/null
        $B kinematics "$tmp/sim$seed/tracks.csv" --material nylon --fixed-gravity \
            --out "$tmp/kin$seed" --format csv > /dev/null 2>&1
        $B walton fit "$tmp/kin$seed/walton_input.csv" --material nylon --format json \
            --bootstrap 500 > "$tmp/w$seed.json"
        python3 - "$seed" "$tmp/w$seed.json" <<'PY'
import json, sys
seed, path = sys.argv[1], sys.argv[2]
d = json.load(open(path))
def cells(p):
    ci = d[p]["ci95"] or [None, None]
    return [d[p]["value"], ci[0], ci[1], d[p]["stderr"]]
row = [seed] + cells("beta0") + cells("mu0") + [d["converged"]]
print(",".join("" if x is None else str(x) for x in row))
PY
    done
} > "$tmp/walton.csv"
python3 - "$tmp/walton.csv" > "$tmp/summary.txt" <<'PY'
import csv, sys
rows = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#")))
print(f"Walton parameters through the chain, {len(rows)} seeded experiments of 120 collisions:")
for p, truth in (("beta0", 0.5), ("mu0", 0.175)):
    # An interval counts only when it is shown and the fit converged (as tests/chain.rs counts).
    cov = sum(1 for r in rows if r["converged"] == "True" and r[p + "_ci95_lo"]
              and float(r[p + "_ci95_lo"]) <= truth <= float(r[p + "_ci95_hi"]))
    z = [(float(r[p]) - truth) / float(r[p + "_stderr"]) for r in rows if r[p + "_stderr"]]
    print(f"  {p}: 95% interval covers the truth {cov}/{len(rows)}; "
          f"mean (estimate - truth)/stderr = {sum(z) / len(z):+.2f}")
PY
$B simulate --material nylon --out "$tmp/g" --n 1000 --seed 3 > /dev/null
for fits in free fixed; do
    flag=""
    [ "$fits" = fixed ] && flag="--fixed-gravity"
    # Free fits skip the collisions with 2 frames in a phase (warnings, not shown here).
    $B kinematics "$tmp/g/tracks.csv" --material nylon $flag --out "$tmp/g_$fits" --format csv > /dev/null 2>&1
done
python3 - "$tmp" >> "$tmp/summary.txt" <<'PY'
import csv, sys
root = sys.argv[1]
def rows(path):
    return list(csv.DictReader(l for l in open(path) if not l.startswith("#")))
truth = {r["collision"]: float(r["e"]) for r in rows(f"{root}/g/truth.csv")}
e = {fits: {r["collision"]: float(r["e"]) for r in rows(f"{root}/g_{fits}/kinematics.csv")}
     for fits in ("free", "fixed")}
# The same collisions for both: those the free fits can measure (3 or more frames per phase).
both = sorted(set(e["free"]) & set(e["fixed"]))
def median_error(fits):
    errs = sorted(abs(e[fits][c] - truth[c]) for c in both)
    return errs[len(errs) // 2]
free, fixed = median_error("free"), median_error("fixed")
print(f"Fixed-gravity against free fits on the {len(both)} of 1000 simulated collisions (seed 3) "
      f"both measure: median |e - e_true| {fixed:.4f} against {free:.4f}, {free / fixed:.2f} times "
      f"smaller (fixed gravity alone also measures {len(e['fixed']) - len(both)} more)")
# The error estimates: standardised errors (e - e_true)/e_err, and the momentum check (pure
# measurement error) against what the fits' covariance (v_err_m_s) and Eq. (8) with the true s
# (eq8_dv_m_s) predict, as the rms of the ratios over both components.
def rms(v):
    return (sum(x * x for x in v) / len(v)) ** 0.5
for fits in ("free", "fixed"):
    k = rows(f"{root}/g_{fits}/kinematics.csv")
    z = [(float(r["e"]) - truth[r["collision"]]) / float(r["e_err"]) for r in k]
    m = sum(z) / len(z)
    sd = (sum((x - m) ** 2 for x in z) / (len(z) - 1)) ** 0.5
    dv = [(r, c) for r in k for c in ("momentum_dvx_m_s", "momentum_dvy_m_s")]
    cov = rms([float(r[c]) / float(r["v_err_m_s"]) for r, c in dv])
    eq8 = rms([float(r[c]) / float(r["eq8_dv_m_s"]) for r, c in dv])
    print(f"{fits} fits, {len(k)} collisions: (e - e_true)/e_err has sd {sd:.2f} and mean {m:+.2f}; "
          f"momentum-check scatter {cov:.2f} times the covariance's prediction, {eq8:.2f} times Eq. (8)'s")
PY
{
    echo "# made by scripts/chain_coverage.sh"
    cat "$tmp/summary.txt"
    echo
    echo "Per experiment (walton fit of the chain's walton_input.csv):"
    grep -v '^#' "$tmp/walton.csv"
} > "$out"
cat "$tmp/summary.txt"
