#!/usr/bin/env bash
# CPU and wall time of `fit` on 100 000 rows, per model: the Fig. 7 data repeated (rows that
# share a pair geometry and a speed, merged exactly by the fit), and the same rows with every
# speed moved by up to 0.1% (100 000 distinct points; both written by scripts/big_fit_data.py:
# the certified search's cost grows with them; above 16384 points its sums run on both cores, so
# wall time depends on the machine's load). Quoted in the README (fuzzing; known limitations).
# With the first-order cell bounds alone the distinct-speed fits took 2.3 (vm) to 33 s
# (powerlaw) of CPU; with the second-order bounds (docs/physics.md §7.4) 0.4-5.9 s; with exact
# Jacobians (§7.5), warm-started profiles and e_vm eight points at a time 0.6-3.6 s; with line
# scans that skip what the bounds exclude and the cell bounds' per-point terms branch-free
# 0.4-2.7 s; with profile crossings that evaluate no point twice, the loops compiled also for
# AVX2 and FMA and Levenberg-Marquardt's fused residuals and Jacobian 0.35-2.3 s (user +
# system); with the master curve fed sorted kappas as vector operations and the sampled passes
# over a contiguous copy 0.3-1.6 s; with the cell bound's sums in registers, nodes summed four
# per vector lane, e_pm and the power law's exps four at a time and its linearised pass on
# 256-bit lanes 0.3-1.5 s. `--model all` (timed since the seventh session): the five fits
# side by side sharing one evaluator and its rows, 3.9-4.0 s of CPU and 2.15-2.19 s of wall
# time on a busy spell of the host (the build before: 5.0-5.2 s, 2.9-3.0 s in that spell);
# with the profiles' ends side by side and Levenberg-Marquardt's sums on both cores (eighth
# session) 3.7-4.0 s and 2.15-2.34 s in another slow spell (0.97 of the wall time before).
# Ninth session, on a faster host (2 Intel Xeon cores): 2.48 s and 1.31 s at its start; with
# first-order passes where the sample predicts them, the cell pass's sums in four lanes, the
# power law's nodes in two passes and the starting cells bounded by blocks 2.28-2.29 s and
# 1.21 s (per model 0.19-0.91 s). Thirteenth session: sizes.csv, 100 000 pairs of sizes each
# with its own kink of `min` (the polishes across kinks and the finishing rounds had taken 46 s).
#
# Usage: bash scripts/time_big_fit.sh [BINARY]   (default target/release/restitution)
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-target/release/restitution}
[ -x "$BIN" ] || cargo build --release --quiet
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 scripts/big_fit_data.py "$dir"
for data in repeated distinct sizes; do
    models="vm pm min product powerlaw all"
    # sizes.csv: the case of `min` with a kink per point (thirteenth session).
    [ "$data" = sizes ] && models="min all"
    for m in $models; do
        /usr/bin/time -f "$data $m: %U s user + %S s system, %e s wall" \
            "$BIN" fit "$dir/$data.csv" --material nylon --model "$m" > /dev/null 2> "$dir/err" || true
        tail -1 "$dir/err"
    done
done
# The same fit on one thread: its CPU against the two-thread run's shows what running on both
# cores costs beyond the work itself (twenty-sixth session: nothing measurable on a quiet host,
# about a tenth more CPU while the host was loaded).
RAYON_NUM_THREADS=1 /usr/bin/time -f "sizes all, one thread: %U s user + %S s system, %e s wall" \
    "$BIN" fit "$dir/sizes.csv" --material nylon --model all > /dev/null 2> "$dir/err" || true
tail -1 "$dir/err"
