#!/usr/bin/env bash
# Regenerates every committed data set and report from the committed generators and the tool.
# Deterministic (all seeded): running it on a clean checkout reproduces the files bit for bit,
# except timings in reports/bench.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
B=target/release/restitution

# Fit (issue 3): Fig. 7-like data, then the fit of all models.
cargo run --release --quiet --example gen_fig7_data
$B fit data/fig7_nylon.csv --material nylon --out reports/fit > /dev/null

# Walton (issue 5): synthetic oblique collisions like Fig. 6, then the hinge fit.
cargo run --release --quiet --example gen_oblique_collisions
$B walton fit data/oblique_collisions.csv --material nylon --out reports/walton > /dev/null

# Kinematics (issue 6): two virtual experiments through the whole chain, and the camera study.
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

# From video frames: a rendered collision tracked (frames in target/, not committed).
cargo run --release --quiet --example track_demo -- target/frames > /dev/null
$B track target/frames/shot_7 --fps 1000 --d-mm 12.7 --out reports/track > /dev/null

# Bench (issue 4): work-precision chart, stability map, fit accuracy, targets (timings vary by machine).
$B bench --out reports/bench > /dev/null

# Frames (issue "Frames", item 6): accuracy of the frame pipeline on rendered frames (10-15 min on 2 cores).
cargo run --release --quiet --example frames_accuracy > /dev/null
