#!/usr/bin/env bash
# Writes the section "Occlusion fields on disk" of results/dynamic/speed.md (replacing it, the
# rest of the file kept): the bunny's fields at Sun 2006's size (cube 6 x 64^2, 29,720
# samples, 730 million rays, 120 coefficients a map) built and written to a field file by one
# `relight scene --fields-dir` run, then loaded by the same command run again.
# Usage: scripts/dynamic_fields.sh   (from the repository's root; about 90 s on two cores;
# scripts/dynamic_speed.sh runs it last)
set -euo pipefail
source "$(dirname "$0")/timing.sh"
out=results/dynamic/speed.md
args=(relight scene testdata/scenes/bunny.json --param cube --resolution 64 --keep-field 120
  --fields-dir "$work/fields" -o "$work/bunny.png" --force)
load_write=$(cut -d' ' -f1-3 /proc/loadavg)
timed fields_write "${args[@]}"
load_read=$(cut -d' ' -f1-3 /proc/loadavg)
timed fields_load "${args[@]}"
size=$(stat -c %s "$work/fields/bunny.hsf")
kept=$(sed '/^## Occlusion fields on disk/,$d' "$out")
{
  echo "$kept"
  echo
  echo "## Occlusion fields on disk"
  echo
  echo "Written by \`scripts/dynamic_fields.sh\`: \`haarshift ${args[*]//$work\//}\` run twice; the first"
  echo "run builds the fields and writes \`bunny.hsf\` ($size bytes), the second loads it."
  echo "Load averages (1, 5, 15 min) before the runs: $load_write; $load_read."
  echo
  echo "| step | wall | CPU s | peak MiB | what it printed |"
  echo "|---|---|---|---|---|"
  step_row fields_write
  step_row fields_load
} > "$work/speed.md"
mv "$work/speed.md" "$out"
