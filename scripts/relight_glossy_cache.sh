#!/usr/bin/env bash
# What the rotation cache and the view-dependent table cost in error and buy in time: the
# bunny on its ground plane at lat-long 128 x 256 under ENV, Phong 50 and Blinn-Phong 50 rotated
# by the Haar chain rule, against `relight reference` at the same resolution:
#   * Phong 50: no cache (every vertex's exact mirror direction), then 16 to 128 bins per axis;
#   * Blinn-Phong 50: no cache with 8 to 64 tabulated outgoing elevations (the table's step and
#     the column turn are then the only quantisations), then 64 and 128 normal bins, and
#     `direct` evaluation (no table, no rotation).
# Prints a Markdown report on standard output:
#   scripts/relight_glossy_cache.sh ENV.hdr > results/relight/glossy/cache.md
set -euo pipefail
cd "$(dirname "$0")/.."
env_map=${1:?usage: scripts/relight_glossy_cache.sh ENV.hdr}
res=128
# shellcheck source=scripts/timing.sh
source scripts/timing.sh
mesh=(testdata/meshes/bunny.ply --ground-plane)
view=(--env "$env_map" --width 320 --height 240)
"$hs" relight precompute "${mesh[@]}" --param latlong --resolution "$res" -o "$work/bunny.hsr" >&2
for brdf in phong:50 blinn:50; do
    "$hs" relight reference "${mesh[@]}" "${view[@]}" --resolution "$res" --brdf "$brdf" \
        --vertices "$work/${brdf/:/}-reference.npy" -o "$work/${brdf/:/}-reference.png" >&2
done

# One render: NAME, then the flags after the cache file; prints a table row.
row() {
    local name=$1 brdf=$2
    shift 2
    "$hs" relight render "$work/bunny.hsr" "${view[@]}" --brdf "$brdf" "$@" \
        --vertices "$work/$name.npy" -o "$work/$name.png" >"$work/$name.out"
    local error maps shading
    error=$("$hs" relight error "$work/${brdf/:/}-reference.npy" "$work/$name.npy" | relative_rms)
    maps=$(grep -oE "[0-9]+ maps rotated" "$work/$name.out" | grep -oE "^[0-9]+")
    shading=$(grep -oE "shading [0-9.]+ ms" "$work/$name.out" | grep -oE "[0-9.]+")
    echo "| $brdf | $* | $error | $maps | $shading |"
}

echo "# The rotation cache and the view-dependent table: error against time"
echo
echo "Made by \`scripts/relight_glossy_cache.sh $env_map\` on $(nproc) cores (load: \`$(uptime)\`):"
echo "the bunny on its ground plane, lat-long $res x $((2 * res)), every coefficient kept, the BRDF"
echo "rotated by \`haar\` unless the flags say otherwise. Error: RMS over the vertices relative to"
echo "the RMS of \`relight reference\` at the same resolution (\`haarshift relight error\`). Shading"
echo "includes every rotation the render makes (a cache starts empty in each command)."
echo
echo "| material | flags | error | maps rotated | shading ms |"
echo "|---|---|---|---|---|"
row phong-none phong:50
for bins in 16 32 64 128; do
    row "phong-$bins" phong:50 --rotation-cache "$bins"
done
for elevations in 8 16 32 64; do
    row "blinn-e$elevations" blinn:50 --elevations "$elevations"
done
for bins in 64 128; do
    row "blinn-$bins" blinn:50 --rotation-cache "$bins"
done
row blinn-direct blinn:50 --brdf-rotation direct
echo
echo "Load when it ended: \`$(uptime)\`"
