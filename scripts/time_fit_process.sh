#!/usr/bin/env bash
# CPU time of the main job as a whole process: `fit --model vm` on data/fig7_nylon.csv against a
# bare `restitution --version` (process start, argument parsing, exit), each run N times in a
# shell loop under /usr/bin/time; prints the CPU per run and the difference; then the whole
# `fit --model all --out DIR` (five models, tables and figures). Run several times
# on a quiet machine and quote medians: single runs vary by tens of per cent on a shared one.
#
# Usage: bash scripts/time_fit_process.sh [BINARY] [N]   (default target/release/restitution, 200)
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-target/release/restitution}
N=${2:-200}
[ -x "$BIN" ] || cargo build --release --quiet
cpu() { # seconds of user + system CPU for N runs of the given command
    /usr/bin/time -f "%U %S" bash -c 'for ((i = 0; i < '"$N"'; i++)); do "$@" > /dev/null 2>&1; done' _ "$@" 2>&1 \
        | tail -1 | awk '{print $1 + $2}'
}
fit=$(cpu "$BIN" fit data/fig7_nylon.csv --material nylon --model vm)
ver=$(cpu "$BIN" --version)
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
all=$(cpu "$BIN" fit data/fig7_nylon.csv --material nylon --model all --out "$out")
awk -v f="$fit" -v v="$ver" -v a="$all" -v n="$N" 'BEGIN {
    printf "fit --model vm: %.3f ms CPU per process; --version: %.3f ms; difference %.3f ms; ratio %.2f\n",
        1000 * f / n, 1000 * v / n, 1000 * (f - v) / n, f / v
    printf "fit --model all --out DIR: %.3f ms CPU per process (target 25 ms)\n", 1000 * a / n }'
