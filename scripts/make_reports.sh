#!/usr/bin/env bash
# Regenerates every committed data set and report from the committed generators and the tool.
# Deterministic (all seeded): running it on a clean checkout reproduces the files bit for bit,
# except timings in reports/bench and the ms-per-fit lines of reports/walton/coverage.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
B=target/release/restitution

# Fit: Fig. 7-like data, then the fit of all models.
cargo run --release --quiet --example gen_fig7_data
$B fit data/fig7_nylon.csv --material nylon --out reports/fit > /dev/null

# Walton: synthetic oblique collisions like Fig. 6, then the hinge fit.
cargo run --release --quiet --example gen_oblique_collisions
$B walton fit data/oblique_collisions.csv --material nylon --out reports/walton > /dev/null
# Coverage and scatter of the Walton fit over 1000 seeded repetitions, both weightings (about 10 s;
# the ms-per-fit lines are timings and vary).
cargo run --release --quiet --example walton_coverage -- 1000 1000 60 > reports/walton/coverage.txt

# Kinematics: two virtual experiments through the whole chain, and the camera study.
$B simulate --material nylon --out data/virtual/normal --n 150 --seed 1 --d-mm 12.7 \
    --v-n-m-s 0.5,25 --incidence-deg 0,30 --model product --eta 190 --sigma-y-pa 4e7 > /dev/null
$B kinematics data/virtual/normal/tracks.csv --material nylon --fixed-gravity \
    --out reports/kinematics/normal > /dev/null
$B fit reports/kinematics/normal/fit_input.csv --material nylon --model all \
    --out reports/kinematics/normal/fit > /dev/null
$B simulate --material nylon --out data/virtual/oblique --n 120 --seed 1 \
    --v-n-m-s 1.5,2.5 --incidence-deg 5,80 --model vm > /dev/null
$B kinematics data/virtual/oblique/tracks.csv --material nylon --fixed-gravity \
    --out reports/kinematics/oblique > /dev/null
$B walton fit reports/kinematics/oblique/walton_input.csv --material nylon \
    --out reports/kinematics/oblique/walton > /dev/null
$B simulate --material nylon --camera-study --incidence-deg 0,45 --out reports/kinematics > /dev/null
# The chain's coverage of beta_0 and mu_0 over 30 experiments, fixed-gravity against free fits.
bash scripts/chain_coverage.sh > /dev/null

# From video frames: a rendered collision tracked (frames in target/, not committed).
cargo run --release --quiet --example track_demo -- target/frames > /dev/null
$B track target/frames/shot_7 --fps 1000 --d-mm 12.7 --out reports/track > /dev/null
# How honest track's spin errors are, over 100 rendered collisions (about 15 s).
bash scripts/spin_coverage.sh > /dev/null

# Bench: work-precision chart, stability map, fit accuracy, targets (timings vary by machine).
$B bench --out reports/bench > /dev/null

# Export (DEM): the shipped fits as engine inputs. With lmp (LAMMPS) on PATH the LAMMPS exports
# are run through it (--verify, about 15 s each); report.txt holds what the command printed.
VERIFY=""
if command -v lmp > /dev/null 2>&1; then VERIFY="--verify"; fi
mkdir -p reports/export/lammps_vm reports/export/lammps_min reports/export/lammps_force \
    reports/export/constant_e reports/export/table
$B export reports/fit/params.json --engine lammps --model vm --walton reports/walton/walton.json \
    --wall --out reports/export/lammps_vm $VERIFY > reports/export/lammps_vm/report.txt
$B export reports/fit/params.json --engine lammps --v-range 0.5,40 --tolerance 0.01 \
    --walton reports/walton/walton.json --out reports/export/lammps_min > reports/export/lammps_min/report.txt
$B export reports/fit/params.json --engine constant-e --v-range 0.5,2 --tolerance 0.02 \
    --walton reports/walton/walton.json --out reports/export/constant_e $VERIFY > reports/export/constant_e/report.txt
$B export --engine lammps --material nylon --d-mm 6.35,25.4 --wall --eta 2000 --contact-end force \
    --speeds 0.5,3,20 --out reports/export/lammps_force $VERIFY > reports/export/lammps_force/report.txt
$B export reports/fit/params.json --engine table --v-range 0.5,40 --walton reports/walton/walton.json \
    --out reports/export/table > reports/export/table/report.txt
cargo run --release --quiet --example tsuji_accuracy > reports/export/tsuji_accuracy.txt
# Frames: accuracy of the frame pipeline on rendered frames (6.5 min of CPU on 2 cores).
cargo run --release --quiet --example frames_accuracy > /dev/null
