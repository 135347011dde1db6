#!/usr/bin/env bash
# The rasteriser's speed against a baseline commit, in one run: the per-frame "rasterisation"
# times that `relight animate` prints (the image half of a frame: the triangles, the
# environment behind, the planes), 640 x 480, for the bunny with its ground plane
# (testdata/meshes/bunny.ply --ground-plane, 5,722 triangles, cube 32) and the cubes scene
# (testdata/scenes/cubes.json, 146,058 triangles; cube 8: the transport's resolution does not
# change the image half), behind the 256 x 128 and the 1024 x 512 Rooitou Park, the lighting
# turned by whole columns (yaw in steps of 45 degrees), by general rotations (the same with
# pitch 20) and the camera circling (--orbit: a new camera every frame). The two binaries run
# in turn, ROUNDS times each; the ratio is baseline / this checkout of the medians over every
# frame but the first (which prepares what the others reuse; listed apart). Prints Markdown:
#   scripts/raster_speed.sh [BASELINE_COMMIT] > results/render/raster_speed.md
# The baseline is built in a worktree under target/raster-baseline (once; later runs reuse it).
set -euo pipefail
cd "$(dirname "$0")/.."
base_commit=${1:-028db339}
rounds=${ROUNDS:-3}

# shellcheck source=scripts/timing.sh
source scripts/timing.sh
base_dir=target/raster-baseline
if [ ! -x "$base_dir/bin/haarshift" ] || [ "$(cat "$base_dir/commit" 2>/dev/null)" != "$base_commit" ]; then
    rm -rf "$base_dir/src"
    mkdir -p "$base_dir"
    git worktree add --force --detach "$base_dir/src" "$base_commit" >&2
    cargo build --release -p haarshift-cli --manifest-path "$base_dir/src/Cargo.toml" \
        --target-dir "$base_dir/target" >&2
    mkdir -p "$base_dir/bin"
    cp "$base_dir/target/release/haarshift" "$base_dir/bin/haarshift"
    git worktree remove --force "$base_dir/src"
    echo "$base_commit" >"$base_dir/commit"
fi
base="$base_dir/bin/haarshift"

start_load=$(uptime)
"$hs" relight precompute testdata/meshes/bunny.ply --ground-plane --param cube --resolution 32 \
    -o "$work/bunny.hsr" >&2
"$hs" relight precompute testdata/scenes/cubes.json --param cube --resolution 8 \
    -o "$work/cubes.hsr" >&2

maps=(testdata/envmaps/rooitou_park_256x128.npy testdata/envmaps/rooitou_park_1k.hdr)
turns=("yaw" "yaw, pitch 20" "orbit")
turn_flags=("" "--pitch 20" "--orbit")
# Frame times of one run: "FRAME MS" lines.
# shellcheck disable=SC2086 # $4: the turn's flags, split into words
frame_times() {
    "$1" relight animate "$2" --env "$3" $4 --frames 8 --width 640 --height 480 \
        -o "$work/frame_%d.png" --force |
        sed -nE 's/^frame ([0-9]+):.*rasterisation ([0-9.]+) ms$/\1 \2/p'
}
median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
range() { sort -g | awk 'NR == 1 {lo = $1} {hi = $1} END {printf "%s-%s", lo, hi}'; }

rows=()
for scene in bunny cubes; do
    for map in "${maps[@]}"; do
        for t in 0 1 2; do
            : >"$work/base.txt"
            : >"$work/new.txt"
            for _ in $(seq "$rounds"); do
                frame_times "$base" "$work/$scene.hsr" "$map" "${turn_flags[$t]}" >>"$work/base.txt"
                frame_times "$hs" "$work/$scene.hsr" "$map" "${turn_flags[$t]}" >>"$work/new.txt"
            done
            b=$(awk '$1 > 0 {print $2}' "$work/base.txt" | median)
            n=$(awk '$1 > 0 {print $2}' "$work/new.txt" | median)
            b0=$(awk '$1 == 0 {print $2}' "$work/base.txt" | median)
            n0=$(awk '$1 == 0 {print $2}' "$work/new.txt" | median)
            ratio=$(echo "scale=1; $b / $n" | bc)
            rows+=("| $scene | $(basename "$map") | ${turns[$t]} | $b ($(awk '$1 > 0 {print $2}' "$work/base.txt" | range)) | $n ($(awk '$1 > 0 {print $2}' "$work/new.txt" | range)) | **$ratio** | $b0 / $n0 |")
        done
    done
done

echo "# Rasteriser speed: 640 x 480 frames, baseline $base_commit against $(git rev-parse --short HEAD)"
echo
echo "Made by \`scripts/raster_speed.sh $base_commit > results/render/raster_speed.md\` on $(nproc) cores"
echo "(ROUNDS=$rounds runs of 8 frames for each binary, in turn); load when it started (\`uptime\`):"
echo "\`$start_load\`"
echo
echo "Each figure is the \"rasterisation\" time \`relight animate\` prints for a frame (ms): median"
echo "(min-max) over frames 1 to 7 of every run. Frame 0's median is listed apart: it also makes"
echo "what later frames reuse (the background's copy of the map; with this checkout, each pixel's"
echo "place in it). Commands (caches in a temporary directory; FLAGS: none, \`--pitch 20\`, \`--orbit\`):"
echo
echo '```'
echo "haarshift relight precompute testdata/meshes/bunny.ply --ground-plane --param cube --resolution 32 -o bunny.hsr"
echo "haarshift relight precompute testdata/scenes/cubes.json --param cube --resolution 8 -o cubes.hsr"
echo "haarshift relight animate SCENE.hsr --env MAP FLAGS --frames 8 --width 640 --height 480 -o frame_%d.png"
echo '```'
echo
echo "| scene | environment | turn | baseline ms | this ms | ratio | frame 0: baseline / this ms |"
echo "|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "Load when it ended: \`$(uptime)\`"
