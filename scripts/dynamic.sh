#!/usr/bin/env bash
# Reproduces results/dynamic/: the dynamic-scene experiment (quick protocol), the animations
# of a moving object casting its shadow, and the frames of the table scene (Haar and reference).
# The speed figures are scripts/dynamic_speed.sh's.
# Usage: scripts/dynamic.sh   (from the repository root; minutes on two cores)
set -euo pipefail
source "$(dirname "$0")/timing.sh"
out=results/dynamic
mkdir -p "$out"
"$hs" experiment dynamic --out-dir "$out" --force
"$hs" relight scene testdata/scenes/bunny_and_ball.json --animate testdata/scenes/ball_path.json \
  --keep-light 200 --keep-visibility 70 --keep-field 70 --width 480 --height 360 \
  -o "$out/bunny_ball.gif" --force > "$out/bunny_ball.txt"
"$hs" relight scene testdata/scenes/table_and_chair.json --animate testdata/scenes/chair_path.json \
  --keep-light 200 --keep-visibility 70 --keep-field 70 --width 480 --height 360 \
  -o "$out/table_chair.gif" --force > "$out/table_chair.txt"
for method in haar reference; do
  "$hs" relight scene testdata/scenes/table_and_chair.json --method "$method" \
    -o "$out/table_chair_$method.png" --force >> "$out/table_chair.txt"
done
