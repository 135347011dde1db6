#!/usr/bin/env bash
# Reproduces results/dynamic/: the dynamic-scene experiment (quick protocol), the animations
# of a moving object casting its shadow, and the timing of the ~30,000-vertex speed scene.
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
# Speed: about 30,000 vertices, three objects, 200 / 70 / 70 kept coefficients; and one
# object's fields at seed 001's size (cube 6 x 64^2: 29,720 samples, 730 million rays).
timed speed relight scene testdata/scenes/speed_three_objects.json \
  --animate testdata/scenes/speed_path.json --keep-light 200 --keep-visibility 70 \
  --keep-field 70 --width 320 --height 240 -o "$work/speed.gif" --force
timed fields relight scene testdata/scenes/bunny.json --param cube --resolution 64 \
  --keep-field 120 -o "$work/bunny.png" --force
{
  echo "# Dynamic scenes: speed"
  echo
  echo "Written by \`scripts/dynamic.sh\` (each command under \`/usr/bin/time -v\`)."
  echo
  echo "| step | wall | CPU s | peak MiB | what it printed |"
  echo "|---|---|---|---|---|"
  step_row speed
  step_row fields
} > "$out/speed.md"
