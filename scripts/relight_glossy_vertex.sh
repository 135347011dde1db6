#!/usr/bin/env bash
# The glossy vertex's cost against a baseline binary, both measured in one run: the bunny on
# its ground plane (1,839 glossy vertices) at lat-long 64 x 128, every coefficient kept, under
# the committed 256 x 128 Rooitou Park, Phong 50 rotated by `haar`, 320 x 240. The figure is
# each render's own "shading" (the triple products and, without a cache, every vertex's
# rotation; not the file's loading or the rasteriser), divided by the glossy vertices:
#   * no rotation cache: every vertex rotates its own BRDF map;
#   * a 64 x 128-bin cache filled ahead (--fill-cache): the shading blends cached bins.
# The baseline (A) and this tree's binary (B) run in turn, A B A B ..., RUNS times each, with
# two threads and with one (RAYON_NUM_THREADS=1); medians and their ratio A / B. Then how far
# the two binaries' per-vertex radiance is apart, and each one's error against
# `relight reference` at the same resolution (`haarshift relight error`).
#
# The baseline binary is built from a commit in a worktree of its own:
#   git worktree add /tmp/base COMMIT
#   cargo build --release -p haarshift-cli --manifest-path /tmp/base/Cargo.toml
#   scripts/relight_glossy_vertex.sh /tmp/base/target/release/haarshift COMMIT \
#       > results/relight/glossy/vertex.md
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:?usage: scripts/relight_glossy_vertex.sh BASELINE_BINARY BASELINE_COMMIT [RUNS]}
commit=${2:?usage: scripts/relight_glossy_vertex.sh BASELINE_BINARY BASELINE_COMMIT [RUNS]}
runs=${3:-5}
env_map=testdata/envmaps/rooitou_park_256x128.npy
# shellcheck source=scripts/timing.sh
source scripts/timing.sh
mesh=(testdata/meshes/bunny.ply --ground-plane)
view=(--env "$env_map" --brdf phong:50 --width 320 --height 240)
"$hs" relight precompute "${mesh[@]}" --param latlong --resolution 64 -o "$work/bunny.hsr" >&2
glossy=$("$hs" relight render "$work/bunny.hsr" "${view[@]}" -o "$work/count.png" |
    grep -oE "no rotation cache: [0-9]+ maps" | grep -oE "[0-9]+")

# One render by BINARY (A or B) with THREADS (2 or 1) and the flags after; prints its shading
# milliseconds and keeps its per-vertex radiance as $work/BINARY-FLAGS.npy.
shading() {
    local which=$1 threads=$2 binary=$hs
    shift 2
    [ "$which" = A ] && binary=$base
    local name
    name="$which$(echo "$*" | tr -dc 'a-z0-9')"
    RAYON_NUM_THREADS=$threads "$binary" relight render "$work/bunny.hsr" "${view[@]}" "$@" \
        --vertices "$work/$name.npy" -o "$work/$name.png" --force |
        grep -oE "shading [0-9.]+ ms" | grep -oE "[0-9.]+"
}
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
per_vertex() { echo "scale=1; $1 * 1000 / $glossy" | bc; }

start_load=$(uptime)
rows=()
for cache in "" "--rotation-cache 64 --fill-cache"; do
    for threads in 2 1; do
        a=() b=()
        for _ in $(seq "$runs"); do
            # shellcheck disable=SC2086 # the flags are words
            a+=("$(shading A "$threads" $cache)")
            # shellcheck disable=SC2086
            b+=("$(shading B "$threads" $cache)")
        done
        ma=$(printf '%s\n' "${a[@]}" | median)
        mb=$(printf '%s\n' "${b[@]}" | median)
        rows+=("| ${cache:-no cache} | $threads | ${a[*]} | ${b[*]} | $(per_vertex "$ma") | $(per_vertex "$mb") | $(echo "scale=2; $ma / $mb" | bc) |")
    done
done
end_load=$(uptime)

"$hs" relight reference "${mesh[@]}" --env "$env_map" --brdf phong:50 --width 320 --height 240 \
    --resolution 64 --vertices "$work/reference.npy" -o "$work/reference.png" >&2
error() { echo "$(basename "$1") against $("$hs" relight error "$1" "$2" | sed "s|$work/||g")"; }

echo "# The glossy vertex: baseline $commit against this tree"
echo
echo "Made by \`scripts/relight_glossy_vertex.sh BASELINE $commit $runs\` on $(nproc) cores: the bunny"
echo "on its ground plane, lat-long 64 x 128, every coefficient, Phong 50 rotated by \`haar\`,"
echo "$glossy glossy vertices. A is the baseline binary (commit $commit), B this tree's; they ran"
echo "in turn, $runs times each. Shading is each render's own figure (ms; rotations included"
echo "without a cache); per vertex, the median divided by the glossy vertices."
echo
echo "Load when it started (\`uptime\`): \`$start_load\`; when the timing ended: \`$end_load\`"
echo
echo "Commands:"
echo
echo '```'
echo "haarshift relight precompute ${mesh[*]} --param latlong --resolution 64 -o bunny.hsr"
echo "RAYON_NUM_THREADS=T haarshift relight render bunny.hsr ${view[*]} [--rotation-cache 64 --fill-cache] --vertices OUT.npy -o OUT.png"
echo '```'
echo
echo "| cache | threads | A shading ms | B shading ms | A us / vertex | B us / vertex | A / B |"
echo "|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "Accuracy (\`haarshift relight error WANT GOT\`: RMS of the difference over the vertices"
echo "relative to WANT's RMS, and the largest difference relative to it):"
echo
echo '```'
error "$work/A.npy" "$work/B.npy"
error "$work/Arotationcache64fillcache.npy" "$work/Brotationcache64fillcache.npy"
for which in A B; do
    error "$work/reference.npy" "$work/$which.npy"
    error "$work/reference.npy" "$work/${which}rotationcache64fillcache.npy"
done
echo '```'
