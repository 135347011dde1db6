#!/usr/bin/env bash
# Rendering a cache larger than memory: a synthetic scene of 1,007,154 vertices (the cubes
# generator with 37 x 37 cubes), precomputed at cube 6 x 8^2 with every coefficient kept,
# then rendered while scripts/peak_memory.py samples the render's anonymous resident memory
# (RssAnon) every millisecond. The cache's transport is read in place from the memory-mapped
# file, so RssAnon should stay under the mesh (positions, normals, triangles, albedo) plus
# 256 MiB whatever the transport's size; VmHWM (ru_maxrss) also counts the file's pages the
# render touched, which the kernel may drop again. For contrast, the same render with
# `--depth 2`, which re-truncates the transport into a copy. Prints Markdown:
#   scripts/scale_render_memory.sh > results/scale/render_memory.md
# RESOLUTION (default 8) sets the cube face side, COUNT (default 37) the cubes per row.
set -euo pipefail
cd "$(dirname "$0")/.."
resolution=${RESOLUTION:-8}
count=${COUNT:-37}
# shellcheck source=scripts/timing.sh
source scripts/timing.sh
cp "$hs" "$work/haarshift"
hs=$work/haarshift
env=testdata/envmaps/rooitou_park_256x128.npy
cat >"$work/many_cubes.json" <<EOF
{ "objects": [ { "generator": { "cubes": { "count": $count, "cells": 10, "distance": 1.5 } } } ],
  "camera": { "position": [0.0, 40.0, 120.0], "look_at": [0.0, 20.0, 0.0], "fov": 45 } }
EOF
start_load=$(uptime)
timed precompute relight precompute "$work/many_cubes.json" --param cube \
    --resolution "$resolution" --memory-limit 64GiB \
    -o "$work/many_cubes.hsr"
bytes=$(stat -c %s "$work/many_cubes.hsr")
# One render under the sampler: its JSON line, then what haarshift printed.
measure() {
    local name=$1
    shift
    echo "+ haarshift $*" >&2
    python3 scripts/peak_memory.py -- "$hs" "$@" >"$work/$name.json" 2>"$work/$name.err"
    cat "$work/$name.err" >&2
}
json() { python3 -c "import json, sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$work/$1.json" "$2"; }
mib() { echo "scale=1; $1 / 1048576" | bc; }
measure mapped relight render "$work/many_cubes.hsr" --env "$env" -o "$work/frame.png"
measure copied relight render "$work/many_cubes.hsr" --env "$env" --depth 2 -o "$work/frame2.png"
vertices=$(sed -nE 's/.*image of ([0-9]+) vertices.*/\1/p' "$work/mapped.json" "$work/mapped.err" | head -1)
triangles=$(sed -nE 's/.* ([0-9]+) triangles.*/\1/p' "$work/precompute.out" | head -1)
# The mesh as a render holds it: positions and normals (f64 x 3 each), albedo (f32 x 3 read,
# f64 x 3 prepared), triangles (u32 x 3).
mesh=$((vertices * (24 + 24 + 12 + 24) + triangles * 12))
bound=$((mesh + 256 * 1048576))
row() {
    local anon
    anon=$(json "$1" rss_anon_peak)
    local within=no
    [ "$anon" -le "$bound" ] && within=yes
    echo "| $2 | $(mib "$anon") | $(mib "$(json "$1" rss_file_peak)") | $(mib "$(json "$1" max_rss)") | $(json "$1" samples) | $within |"
}
echo "# Rendering a cache larger than memory"
echo
echo "Made by \`scripts/scale_render_memory.sh > results/scale/render_memory.md\` on $(nproc) cores;"
echo "load when it started (\`uptime\`): \`$start_load\`"
echo
echo "The cubes generator with $count x $count cubes: $vertices vertices, $triangles triangles,"
echo "precomputed with \`relight precompute SCENE --param cube --resolution $resolution\` (every coefficient kept)"
echo "($(field precompute 'Elapsed (wall clock)') wall, $(cpu precompute) CPU s, peak resident $(peak_mib precompute) MiB). It printed:"
echo
echo '```text'
sed "s|$work/||g" "$work/precompute.out"
echo '```'
echo
echo "The cache is $bytes bytes ($(mib "$bytes") MiB). The mesh as a render holds it (positions and"
echo "normals f64, albedo f32 read and f64 prepared, triangles u32) is $(mib "$mesh") MiB, so the bound is"
echo "$(mib "$bound") MiB. \`relight render CACHE --env $env -o frame.png\` (640 x 480), RssAnon"
echo "sampled every millisecond by \`scripts/peak_memory.py\`, VmHWM the child's \`ru_maxrss\`:"
echo
echo "| render | RssAnon peak MiB | RssFile peak MiB | VmHWM MiB | samples | RssAnon within the mesh + 256 MiB |"
echo "|---|---|---|---|---|---|"
row mapped "as stored: the transport read in place from the mapped file"
row copied "\`--depth 2\`: the transport re-truncated into memory"
echo
echo "What the first render printed:"
echo
echo '```text'
sed "s|$work/||g" "$work/mapped.err"
echo '```'
echo
echo "Load when it ended: \`$(uptime)\`"
