#!/usr/bin/env bash
# Interreflected light (issue 51) measured against its two truths. Prints Markdown:
#   scripts/bounces.sh > results/relight/bounces.md
# Scenes: the bunny on its ground plane and the bunny in an open box
# (testdata/scenes/bunny_in_box.json), under the four 1k maps of testdata/envmaps/. For each:
# the path tracer (`relight reference --path-trace`, depth 3) is the truth; against it the
# relative RMS error over vertices of the pixel-domain gather (`relight reference --bounces B`)
# and of the Haar render of a cache precomputed with `--bounces B` (all coefficients kept,
# cube 6 x 16^2 by default: RESOLUTION=N to change), B = 0 (direct only) to 3; precompute time
# and peak memory for each B; frame time with bounces on and off (`relight render
# --direct-only`); the speed target's ratio, `--bounces 1` against direct precomputation of
# the bunny on its ground at cube 6 x 32^2 and of the cubes scene at cube 6 x 64^2; how far
# caches cast by Embree and by our packets differ; and, where the build has `--ground-cells`, the
# gather's difference from the path tracer as the ground gets denser. Also writes the picture
# triple results/relight/bounces_{direct,bounced,paths}.png (the bunny in the box, Rooitou
# Park). Low resolutions and PATHS=256 keep the run to minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/timing.sh
source scripts/timing.sh
paths=${PATHS:-256}
resolution=${RESOLUTION:-16}
maps=(rooitou_park_1k st_fagans_interior_1k studio_small_03_1k venice_sunset_1k)
declare -A scene_args=(
    [bunny]="testdata/meshes/bunny.ply --ground-plane"
    [box]="testdata/scenes/bunny_in_box.json"
)
start_load=$(uptime)
# Relative RMS of A against TRUTH, two (V, 3) .npy files.
rel() {
    python3 -c 'import numpy as np, sys
a, t = np.load(sys.argv[1]).astype(float), np.load(sys.argv[2]).astype(float)
print(f"{np.sqrt(np.mean((a - t) ** 2) / np.mean(t ** 2)):.4f}")' "$1" "$2"
}
# The same, less the path tracer's own noise: sqrt(max(0, mean((a - t)^2) - mean(se^2)) /
# mean(t^2)) with SE its (V, 3) standard errors. The expected squared difference from a noisy
# truth is the squared bias plus the noise's variance, so this estimates the bias alone.
bias() {
    python3 -c 'import numpy as np, sys
a, t, s = (np.load(p).astype(float) for p in sys.argv[1:4])
print(f"{np.sqrt(max(0.0, np.mean((a - t) ** 2) - np.mean(s ** 2)) / np.mean(t ** 2)):.4f}")' "$1" "$2" "$3"
}
for s in bunny box; do
    # shellcheck disable=SC2086
    read -r -a sa <<<"${scene_args[$s]}"
    for b in 0 1 2 3; do
        timed "pre-$s-$b" relight precompute "${sa[@]}" --param cube --resolution $resolution \
            --bounces $b -o "$work/$s-$b.hsr"
    done
    for m in "${maps[@]}"; do
        env=testdata/envmaps/$m.hdr
        timed "pt-$s-$m" relight reference "${sa[@]}" --env "$env" --resolution $resolution \
            --path-trace "$paths" --bounces 3 --seed 1 --stderr "$work/se-$s-$m.npy" \
            --vertices "$work/pt-$s-$m.npy"
        for b in 0 1 2 3; do
            timed "gather-$s-$m-$b" relight reference "${sa[@]}" --env "$env" \
                --resolution $resolution --bounces $b --vertices "$work/gather-$s-$m-$b.npy"
            timed "render-$s-$m-$b" relight render "$work/$s-$b.hsr" --env "$env" \
                --vertices "$work/haar-$s-$m-$b.npy" --width 64 --height 48 -o "$work/r.png" --force
        done
        timed "direct-only-$s-$m" relight render "$work/$s-3.hsr" --env "$env" --direct-only \
            --vertices "$work/haar-direct-$s-$m.npy" --width 64 --height 48 -o "$work/r.png" --force
    done
done
echo "# Interreflected light against two truths"
echo
echo "Made by \`scripts/bounces.sh > results/relight/bounces.md\` on $(nproc) cores;"
echo "load when it started (\`uptime\`): \`$start_load\`"
echo
echo "The truth is the path tracer (\`relight reference --path-trace $paths --bounces 3 --seed 1\`:"
echo "$paths cosine-weighted paths a vertex, depth 3, the environment downsampled to"
echo "$resolution x $((2 * resolution))). Errors are relative RMS over vertices and channels,"
echo "\`sqrt(mean((x - truth)^2) / mean(truth^2))\`; \`gather B\` is \`relight reference --bounces B\`"
echo "(the pixel-domain gather over the $resolution x $((2 * resolution)) texel rays), \`Haar B\` the render"
echo "of a cache precomputed with \`--bounces B\` at cube 6 x ${resolution}^2, every coefficient kept."
echo "Under a sun (Rooitou Park, the studio) $paths cosine-weighted paths leave the truth itself"
echo "noisy, its standard error near the differences measured; the second table takes that noise out,"
echo "\`sqrt(max(0, mean((x - truth)^2) - mean(se^2)) / mean(truth^2))\` with \`se\` the path"
echo "tracer's standard error per vertex and channel (the squared difference from a noisy truth is"
echo "the squared bias plus the noise's variance): what is left is the method's own error."
echo
echo "| scene | map | path tracer's RMS standard error / RMS radiance | gather 0 (direct only) | gather 1 | gather 2 | gather 3 | Haar 0 | Haar 1 | Haar 2 | Haar 3 |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for s in bunny box; do
    for m in "${maps[@]}"; do
        se=$(python3 -c 'import numpy as np, sys
s, t = np.load(sys.argv[1]).astype(float), np.load(sys.argv[2]).astype(float)
print(f"{np.sqrt(np.mean(s ** 2) / np.mean(t ** 2)):.4f}")' "$work/se-$s-$m.npy" "$work/pt-$s-$m.npy")
        row="| $s | $m | $se"
        for b in 0 1 2 3; do row+=" | $(rel "$work/gather-$s-$m-$b.npy" "$work/pt-$s-$m.npy")"; done
        for b in 0 1 2 3; do row+=" | $(rel "$work/haar-$s-$m-$b.npy" "$work/pt-$s-$m.npy")"; done
        echo "$row |"
    done
done
echo
echo "Less the path tracer's noise:"
echo
echo "| scene | map | gather 0 (direct only) | gather 1 | gather 2 | gather 3 | Haar 0 | Haar 1 | Haar 2 | Haar 3 |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for s in bunny box; do
    for m in "${maps[@]}"; do
        row="| $s | $m"
        for kind in gather haar; do
            for b in 0 1 2 3; do
                row+=" | $(bias "$work/$kind-$s-$m-$b.npy" "$work/pt-$s-$m.npy" "$work/se-$s-$m.npy")"
            done
        done
        echo "$row |"
    done
done
echo
echo "## Precomputation for each B (cube 6 x ${resolution}^2)"
echo
echo "| step | wall (m:ss) | CPU s | peak resident MiB | what it reports |"
echo "|---|---|---|---|---|"
for s in bunny box; do for b in 0 1 2 3; do step_row "pre-$s-$b"; done; done
echo
echo "## Frame time, bounces on and off (a cache of 3 bounces; Rooitou Park)"
echo
echo "| step | wall (m:ss) | CPU s | peak resident MiB | what it reports |"
echo "|---|---|---|---|---|"
for s in bunny box; do
    step_row "render-$s-rooitou_park_1k-3"
    step_row "direct-only-$s-rooitou_park_1k"
done
echo
echo "## Speed: one bounce against the direct precomputation (bunny on its ground, cube 6 x 32^2)"
echo
echo "Five pairs run in turn, direct then one bounce, each writing a new file: the machine's"
echo "speed drifts between runs, so the target is judged on the median of the pairs' ratios."
echo
echo "| step | wall (m:ss) | CPU s | peak resident MiB | what it reports |"
echo "|---|---|---|---|---|"
for i in 1 2 3 4 5; do
    for b in 0 1; do
        rm -f "$work/speed-$b.hsr"
        timed "speed-$b-$i" relight precompute testdata/meshes/bunny.ply --ground-plane --param cube \
            --resolution 32 --bounces $b -o "$work/speed-$b.hsr"
        step_row "speed-$b-$i"
    done
done
seconds() { python3 -c 'import sys; h, m, s = ([0, 0] + sys.argv[1].split(":"))[-3:]; print(3600 * float(h) + 60 * float(m) + float(s))' "$1"; }
# The speed target's lines for RUNS pairs of steps NAME-0-i (direct) and NAME-1-i (one
# bounce): the median of the pairs' wall-time ratios, their range, and the first pair's peaks.
ratio() {
    local i walls=()
    for i in $(seq 1 "$2"); do
        walls+=("$(seconds "$(field "$1-0-$i" 'Elapsed (wall clock)')")")
        walls+=("$(seconds "$(field "$1-1-$i" 'Elapsed (wall clock)')")")
    done
    echo
    python3 -c 'import statistics, sys
w = [float(x) for x in sys.argv[1:]]
r = sorted(b / a for a, b in zip(w[0::2], w[1::2]))
spread = f"the median of {len(r)} pairs; {r[0]:.2f}x to {r[-1]:.2f}x" if len(r) > 1 else "one pair"
print(f"Wall time of `--bounces 1` over the direct run'"'"'s: {statistics.median(r):.2f}x ({spread})")' "${walls[@]}"
    echo "(target at most 3x); peak memory $(peak_mib "$1-1-1") MiB against $(peak_mib "$1-0-1") MiB."
}
ratio speed 5
echo
echo "## Speed: one bounce on the 85,860-vertex cubes scene (cube 6 x 64^2, 414 coefficients a vertex)"
echo
echo "Every coefficient kept, this scene's direct cache alone is 4.6 GiB at an 11.7 GiB peak; as in"
echo "[speed.md](speed.md), each vertex keeps its 414 largest (seed 002's truncation), and so does"
echo "each bounce's sum."
echo
echo "| step | wall (m:ss) | CPU s | peak resident MiB | what it reports |"
echo "|---|---|---|---|---|"
for b in 0 1; do
    timed "cubes-$b-1" relight precompute testdata/scenes/cubes.json --param cube --resolution 64 \
        --keep-visibility 414 --bounces $b -o "$work/cubes-$b.hsr"
    rm "$work/cubes-$b.hsr"
    step_row "cubes-$b-1"
done
ratio cubes 1
echo
echo "## Embree against our packets (the bunny in the box, 2 bounces, cube 6 x ${resolution}^2)"
echo
echo "Relative RMS (and the largest difference over the RMS) of the radiance over vertices, Rooitou"
echo "Park. The difference is not the bounces': direct light alone differs as much. It comes from the"
echo "box's corner columns and floor edges, where a vertex's origin, offset along its wall's normal,"
echo "lies in the plane of the wall it meets: every ray meets that wall at t = 0 to within f32"
echo "rounding; Embree counts those hits (the vertex is black), our packets here do not (it sees out)."
echo "Neither is the light there; see the module docs of \`relight::precompute::raycast\`."
echo
echo "| what | relative RMS | largest / RMS |"
echo "|---|---|---|"
env=testdata/envmaps/rooitou_park_1k.hdr
for t in embree packets; do
    timed "tracer-$t" relight precompute testdata/scenes/bunny_in_box.json --param cube \
        --resolution "$resolution" --bounces 2 --ray-tracer "$t" -o "$work/tracer-$t.hsr"
    for only in "" --direct-only; do
        # shellcheck disable=SC2086
        "$hs" relight render "$work/tracer-$t.hsr" --env "$env" $only --width 64 --height 48 \
            --vertices "$work/tracer-$t${only}.npy" -o "$work/r.png" --force >&2
    done
done
difference() {
    python3 -c 'import numpy as np, sys
a, b = (np.load(p).astype(float) for p in sys.argv[1:3])
rms = np.sqrt(np.mean(b ** 2))
print(f"{np.sqrt(np.mean((a - b) ** 2)) / rms:.2e} | {np.abs(a - b).max() / rms:.2e}")' "$1" "$2"
}
echo "| direct light alone | $(difference "$work/tracer-packets--direct-only.npy" "$work/tracer-embree--direct-only.npy") |"
echo "| with 2 bounces | $(difference "$work/tracer-packets.npy" "$work/tracer-embree.npy") |"
echo
echo "## The gather against the path tracer as the ground gets denser (bunny, Rooitou Park, 1 bounce)"
echo
if "$hs" relight reference --help | grep -q -- --ground-cells; then
    echo "| ground cells a side | vertices | gather 1 against path tracer (depth 1) | less the path tracer's noise | path tracer's RMS standard error / RMS |"
    echo "|---|---|---|---|---|"
    env=testdata/envmaps/rooitou_park_1k.hdr
    for g in 16 32 64 128; do
        a=(relight reference testdata/meshes/bunny.ply --ground-plane --ground-cells "$g" --env "$env" --resolution $resolution)
        "$hs" "${a[@]}" --bounces 1 --vertices "$work/g-$g.npy" >&2
        "$hs" "${a[@]}" --bounces 1 --path-trace "$paths" --seed 1 --stderr "$work/gse-$g.npy" \
            --vertices "$work/gpt-$g.npy" >&2
        v=$(python3 -c 'import numpy as np, sys; print(np.load(sys.argv[1]).shape[0])' "$work/g-$g.npy")
        se=$(python3 -c 'import numpy as np, sys
s, t = np.load(sys.argv[1]).astype(float), np.load(sys.argv[2]).astype(float)
print(f"{np.sqrt(np.mean(s ** 2) / np.mean(t ** 2)):.4f}")' "$work/gse-$g.npy" "$work/gpt-$g.npy")
        echo "| $g | $v | $(rel "$work/g-$g.npy" "$work/gpt-$g.npy") | $(bias "$work/g-$g.npy" "$work/gpt-$g.npy" "$work/gse-$g.npy") | $se |"
    done
else
    echo "Not measured: this build has no \`--ground-cells\`."
fi
# The picture triple: the bunny in the box under Rooitou Park, one view.
env=testdata/envmaps/rooitou_park_1k.hdr
"$hs" relight render "$work/box-3.hsr" --env "$env" --direct-only -o results/relight/bounces_direct.png --force >&2
"$hs" relight render "$work/box-3.hsr" --env "$env" -o results/relight/bounces_bounced.png --force >&2
"$hs" relight reference testdata/scenes/bunny_in_box.json --env "$env" --resolution $resolution \
    --path-trace "$paths" --bounces 3 --seed 1 --vertices "$work/triple.npy" \
    -o results/relight/bounces_paths.png --force >&2
echo
echo "Pictures: \`bounces_direct.png\` (direct only), \`bounces_bounced.png\` (3 bounces),"
echo "\`bounces_paths.png\` (the path tracer), the bunny in the box under Rooitou Park."
echo
echo "Load when it ended: \`$(uptime)\`"
