#!/usr/bin/env bash
# The glossy relighting speed figures on this machine: the 85,860-vertex "cubes" scene of seed
# 002 (testdata/scenes/cubes.json) precomputed at lat-long 64 x 128 with every coefficient,
# shaded with Phong 50:
#   * without a rotation cache, every vertex's BRDF evaluated directly (`direct`) and rotated in
#     the Haar domain (`haar`): the cost of a new view when nothing is kept;
#   * with a 64 x 128-bin cache, filled ahead (every bin rotated once, timed on its own), then
#     four new views (the camera circling the scene, --orbit);
#   * the same four views with the cache filled as they need it.
# Each run under /usr/bin/time -v for its peak resident memory and CPU time. Prints a Markdown
# report on standard output:
#   scripts/relight_glossy_speed.sh > results/relight/glossy/speed.md
# ENV (first argument) is the lighting; the default is the committed 256 x 128 Rooitou Park.
set -euo pipefail
cd "$(dirname "$0")/.."
env_map=${1:-testdata/envmaps/rooitou_park_256x128.npy}
# shellcheck source=scripts/timing.sh
source scripts/timing.sh

view=(--env "$env_map" --brdf phong:50 --width 640 --height 480)
# Every coefficient of 8,192 texels: the precomputation's budget counts up to 11 GB for the
# 85,860 vertices (it peaks at 3.5 GiB, the transport being sparse), above the 4 GiB default.
precompute=(relight precompute testdata/scenes/cubes.json --param latlong --resolution 64
    --memory-limit 16GiB -o "$work/cubes.hsr")
direct=(relight render "$work/cubes.hsr" "${view[@]}" --brdf-rotation direct -o "$work/direct.png")
haar=(relight render "$work/cubes.hsr" "${view[@]}" --brdf-rotation haar -o "$work/haar.png")
warm=(relight animate "$work/cubes.hsr" "${view[@]}" --brdf-rotation haar --rotation-cache 64
    --fill-cache --orbit --frames 4 -o "$work/warm_%d.png")
cold=(relight animate "$work/cubes.hsr" "${view[@]}" --brdf-rotation haar --rotation-cache 64
    --orbit --frames 4 -o "$work/cold_%d.png")
start_load=$(uptime)
timed precompute "${precompute[@]}"
timed direct "${direct[@]}"
timed haar "${haar[@]}"
timed warm "${warm[@]}"
timed cold "${cold[@]}"

echo "# Glossy relighting speed: the 85,860-vertex cubes scene, Phong 50"
echo
echo "Made by \`scripts/relight_glossy_speed.sh > results/relight/glossy/speed.md\` on $(nproc) cores;"
echo "load when it started (\`uptime\`): \`$start_load\`"
echo
echo "Commands (the cache in a temporary directory):"
echo
echo '```'
for cmd in precompute direct haar warm cold; do
    declare -n args=$cmd
    echo "haarshift ${args[*]}" | sed "s|$work/||g"
done
echo '```'
echo
echo "| step | wall (m:ss) | CPU s (user + sys) | peak resident MiB | what the command reports |"
echo "|---|---|---|---|---|"
for step in precompute direct haar warm cold; do
    step_row "$step"
done
echo
echo "Load when it ended: \`$(uptime)\`"
echo
# What one BRDF copy per orientation costs at this resolution, f32.
texels=$((64 * 128))
echo "Memory, f32 maps of $texels texels ($((texels * 4 / 1024)) KiB each):"
echo
echo "| what is kept | maps | MiB |"
echo "|---|---|---|"
echo "| one local Phong lobe, rotated per vertex (no cache) | 1 | $(echo "scale=2; $texels * 4 / 1048576" | bc) |"
echo "| a Phong copy per mirror-direction bin (the 64 x 128 cache filled; Wang et al. 2006's one rotation per sampled direction) | $texels | $((texels * texels * 4 / 1048576)) |"
echo "| a Blinn-Phong copy per orientation: normal bin x 16 elevations x 128 azimuths (Ng et al. 2004's BRDF stored per orientation) | $((texels * 16 * 128)) | $((texels * 16 * 128 * texels * 4 / 1048576)) |"
