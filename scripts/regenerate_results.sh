#!/usr/bin/env bash
# Regenerates every committed report under results/ with the current code: each experiment
# writes its CSV, JSON, Markdown table and plots into its own directory, replacing the old ones.
# The seconds and peak-memory columns are wall time and heap on the machine that runs this;
# the error columns do not depend on it.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p haarshift-cli
hs=target/release/haarshift
run() { echo "+ haarshift $*" >&2; "$hs" "$@"; }

# Alnasser 2008's Table 2.2, with the crops before and after the cycle (Figs. 2.4-2.5).
run experiment rotation-cycle --crops --out-dir results/rotation-cycle --force
# Retained Haar at h = 3 equals nearest neighbour on an 8x finer grid (tested): Alnasser 2008's
# Table 2.2 figures for its method are what this reaches on camera.
run experiment rotation-cycle testdata/camera.png --methods nearest --supersample 3 \
    --out-dir results/rotation-cycle-camera-s3 --force
# Alnasser 2008's Table 3.1: fractional steps, and steps that are multiples of 1/8 (where retained
# Haar at h = 3 moves whole fine samples, so the chain equals the single shift).
run experiment shift-chain --out-dir results/shift-chain --force
run experiment shift-chain --dx 7.5 --dy -4.5 --steps 12 --retained-precision 3 \
    --out-dir results/shift-chain-dyadic --force
run experiment tradeoff --out-dir results/tradeoff --force
run experiment stability --out-dir results/stability --force
run experiment sphere --out-dir results/sphere --force
# Dynamic scenes: occlusion fields and just-in-time transfer against ray casting (the
# animations and the speed table are scripts/dynamic.sh's and scripts/dynamic_speed.sh's).
run experiment dynamic --out-dir results/dynamic --force
# Relighting methods against the ray-cast truth over the sources' axes (quick protocol, a few
# minutes; scripts/relight_experiments.sh also runs the full one).
run experiment relight --out-dir results/relight/experiments --force
