#!/usr/bin/env bash
# Reproduces results/dynamic/speed.md: a scene of about 30,000 vertices and three objects
# played along a path (a small object moves, a large one moves, the lighting turns) with
# looked-up occlusion maps truncated before and after the blend; the same scene glossy (Phong
# 40) with the ball moving, the lighting turning and the eye orbiting; and one object's fields
# at Sun 2006's size.
# Usage: scripts/dynamic_speed.sh   (from the repository root; about seven minutes on two cores)
set -euo pipefail
source "$(dirname "$0")/timing.sh"
out=results/dynamic
mkdir -p "$out"
# Speed: about 30,000 vertices, three objects, 200 / 70 / 70 kept coefficients; and one
# object's fields at Sun 2006's size (cube 6 x 64^2: 29,720 samples, 730 million rays).
for truncate in before after; do
  timed "speed_$truncate" relight scene testdata/scenes/speed_three_objects.json \
    --animate testdata/scenes/speed_path.json --keep-light 200 --keep-visibility 70 \
    --keep-field 70 --truncate "$truncate" --width 320 --height 240 -o "$work/speed.gif" --force
done
timed glossy relight scene testdata/scenes/speed_three_objects.json \
  --animate testdata/scenes/speed_glossy_path.json --brdf phong:40 --keep-light 200 \
  --keep-visibility 70 --keep-field 70 --width 320 --height 240 -o "$work/glossy.gif" --force
timed fields relight scene testdata/scenes/bunny.json --param cube --resolution 64 \
  --keep-field 120 -o "$work/bunny.png" --force
{
  echo "# Dynamic scenes: speed"
  echo
  echo "Written by \`scripts/dynamic_speed.sh\` (each command under \`/usr/bin/time -v\`)."
  echo
  echo "| step | wall | CPU s | peak MiB | what it printed |"
  echo "|---|---|---|---|---|"
  step_row speed_before
  step_row speed_after
  step_row glossy
  step_row fields
} > "$out/speed.md"
# The same fields written to a field file and loaded from it (its own section of speed.md).
"$(dirname "$0")/dynamic_fields.sh"
