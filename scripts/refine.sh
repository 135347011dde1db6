#!/usr/bin/env bash
# Vertices where the light needs them (issue 52): `relight precompute --refine` against
# denser ground grids, per pixel. Prints Markdown and writes the figure:
#   scripts/refine.sh > results/relight/refine.md
# The bunny on its ground plane under Rooitou Park, cube 6 x ${RESOLUTION}^2 (default 32),
# every coefficient kept: ground grids of 32^2, 64^2 and 128^2 cells (`--ground-cells`) and
# `--refine TOL` from the 32^2 grid at the tolerances $TOLERANCES (by transport, and by
# radiance under the map as probe: --refine-light), each capped at a quarter
# of the 128^2 grid's vertices (the goal's budget). Each is rendered (`relight render`, the
# default view, 640 x 480, black background) and compared per pixel with the truth: `relight
# reference` of a dense mesh of the same surface (the bunny midpoint-subdivided twice by
# scripts/subdivide_mesh.py, on a ${TRUTH_CELLS}^2 ground, default 256: about 1.5 pixels a
# cell in this view) with the lighting at lat-long ${TRUTH_RESOLUTION} x 2 x that (default
# 128), rendered in the same view; and, as a second truth that shares the runs' lighting
# texels, that dense mesh precomputed and rendered at cube 6 x ${RESOLUTION}^2 (about 1.7 GiB
# of cache at 32). Also writes results/relight/refine.png (scripts/refine_figure.py).
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/timing.sh
source scripts/timing.sh
resolution=${RESOLUTION:-32}
truth_cells=${TRUTH_CELLS:-256}
truth_resolution=${TRUTH_RESOLUTION:-128}
read -r -a tolerances <<<"${TOLERANCES:-0.4 0.2 0.1}"
mesh=testdata/meshes/bunny.ply
env=testdata/envmaps/rooitou_park_1k.hdr
view=(--env "$env" --background 0,0,0)
start_load=$(uptime)
python3 scripts/subdivide_mesh.py "$mesh" 2 "$work/truth.ply"
timed truth relight reference "$work/truth.ply" --ground-plane --ground-cells "$truth_cells" \
    --resolution "$truth_resolution" "${view[@]}" --vertices "$work/truth.npy" -o "$work/truth.exr"
# The second truth: the same dense mesh precomputed and rendered as the runs are (cube 6 x
# ${resolution}^2): what is left against it is the interpolation between vertices alone.
timed pre-dense relight precompute "$work/truth.ply" --ground-plane --ground-cells "$truth_cells" \
    --param cube --resolution "$resolution" --memory-limit 16GiB -o "$work/dense.hsr"
timed render-dense relight render "$work/dense.hsr" "${view[@]}" -o "$work/dense.exr"
rm "$work/dense.hsr"
# Vertices of the 128^2 grid's scene, and the goal's budget: a quarter of them.
objects=$(python3 -c 'import sys; d = open(sys.argv[1], "rb").read(); i = d.index(b"element vertex ")
print(d[i:].split()[2].decode())' "$mesh")
budget=$(((objects + 129 * 129) / 4))
runs=()
for cells in 32 64 128; do
    runs+=("grid-$cells")
    timed "pre-grid-$cells" relight precompute "$mesh" --ground-plane --ground-cells "$cells" \
        --param cube --resolution "$resolution" -o "$work/grid-$cells.hsr"
done
# Each tolerance twice: edges judged by their transport (refine-TOL), and by their radiance
# under the map itself as probe (probe-TOL, --refine-light).
refined=()
for tol in "${tolerances[@]}"; do
    refined+=("refine-$tol" "probe-$tol")
    timed "pre-refine-$tol" relight precompute "$mesh" --ground-plane --param cube \
        --resolution "$resolution" --refine "$tol" --max-vertices "$budget" \
        -o "$work/refine-$tol.hsr"
    timed "pre-probe-$tol" relight precompute "$mesh" --ground-plane --param cube \
        --resolution "$resolution" --refine "$tol" --max-vertices "$budget" \
        --refine-light "$env" -o "$work/probe-$tol.hsr"
done
runs+=("${refined[@]}")
# The probe's limit: the lighting turned by YAW (default 120 degrees) moves the sun and its
# shadow away from where probe-TOL refined; each mesh rendered so against a reference so.
turn=${YAW:-120}
timed truth-turned relight reference "$work/truth.ply" --ground-plane --ground-cells "$truth_cells" \
    --resolution "$truth_resolution" "${view[@]}" --yaw "$turn" --vertices "$work/truth-turned.npy" \
    -o "$work/truth-turned.exr"
for r in "${runs[@]}"; do
    timed "render-$r" relight render "$work/$r.hsr" "${view[@]}" -o "$work/$r.exr"
    "$hs" relight render "$work/$r.hsr" "${view[@]}" --yaw "$turn" -o "$work/$r-turned.exr" >&2
    rm "$work/$r.hsr"
done
# The vertex count a precomputation printed ("FILE: V vertices, ...": the last such line).
vertices() { grep -oE ': [0-9]+ vertices' "$work/pre-$1.out" | tail -1 | grep -oE '[0-9]+'; }
# The per-pixel relative RMS and the largest difference over the RMS, of run $2 against $1.
pixel_error() {
    "$hs" relight error "$work/$1.exr" "$work/$2.exr" | sed -E 's/.*relative RMS ([^,]+), largest ([^ ]+).*/\1 | \2/'
}
echo "# Vertices where the light needs them: refinement against denser grids, per pixel"
echo
echo "Made by \`scripts/refine.sh > results/relight/refine.md\` on $(nproc) cores;"
echo "load when it started (\`uptime\`): \`$start_load\`"
echo
echo "The bunny (\`testdata/meshes/bunny.ply\`, $objects vertices) on its ground plane under Rooitou"
echo "Park, precomputed at cube 6 x ${resolution}^2 with every coefficient kept, rendered by"
echo "\`relight render\` in the default view (640 x 480, black background). The truth is"
echo "\`relight reference\` of the same surface made dense (the bunny midpoint-subdivided twice by"
echo "\`scripts/subdivide_mesh.py\`, new normals the normalised sums of their edges' ends, on a"
echo "${truth_cells}^2-cell ground), the lighting at lat-long ${truth_resolution} x $((2 * truth_resolution)), rendered in the same"
echo "view: per-vertex shading at about a pixel and a half a ground cell is the per-pixel"
echo "picture. Errors are over every pixel and channel (\`relight error\` of the two EXR images):"
echo "\`sqrt(mean((render - truth)^2) / mean(truth^2))\`, and the largest difference over the"
echo "truth's RMS. The second truth is that dense mesh precomputed and rendered as the runs are"
echo "(cube 6 x ${resolution}^2, the same lighting's texels): against it only the interpolation"
echo "between vertices is left, against the reference also the lighting's discretisation (the dense"
echo "cube render is $(pixel_error truth dense | sed 's/ |.*//') from the reference, the floor of every run)."
echo "Refinement starts from the 32^2 grid, capped at \`--max-vertices $budget\`, a"
echo "quarter of the 128^2 grid's vertices, its edges judged by their transport (\`refine-TOL\`)"
echo "or by their radiance under Rooitou Park itself as probe (\`probe-TOL\`, \`--refine-light\`)."
echo "Precompute time is the command's wall clock"
echo "(refinement's rounds, splits and criterion included)."
echo
echo "| mesh | vertices | of them the ground's | precompute wall (m:ss) | CPU s | per-pixel relative RMS against the reference | largest / RMS | against the dense cube render | largest / RMS | what the precomputation reports |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for r in "${runs[@]}"; do
    report=$(tr '\n' ' ' <"$work/pre-$r.out" | sed "s|$work/||g; s/|/\\\\|/g; s/  */ /g")
    case $r in
    grid-*) ground=$(((${r#grid-} + 1) ** 2)) ;;
    *) ground=$(grep -oE '\(([0-9]+) of them the ground' "$work/pre-$r.out" | grep -oE '[0-9]+') ;;
    esac
    error=$(pixel_error truth "$r")
    echo "${error%% *}" >"$work/$r.error"
    echo "| $r | $(vertices "$r") | $ground | $(field "pre-$r" 'Elapsed (wall clock)') | $(cpu "pre-$r") | $error | $(pixel_error dense "$r") | $report |"
done
echo
goal=$(cat "$work/grid-128.error")
met=()
for r in "${refined[@]}"; do
    if python3 -c 'import sys; sys.exit(not float(sys.argv[1]) <= float(sys.argv[2]))' \
        "$(cat "$work/$r.error")" "$goal"; then
        met+=("$r")
    fi
done
echo "Where each refinement's new vertices went (from the 32^2 grid's $((objects + 33 * 33))):"
for r in "${refined[@]}"; do
    v=$(vertices "$r")
    g=$(grep -oE '\(([0-9]+) of them the ground' "$work/pre-$r.out" | grep -oE '[0-9]+')
    echo "$r: $((v - g - objects)) on the bunny, $((g - 33 * 33)) on the ground;"
done
echo
echo "Under the lighting turned by $turn degrees about +Y (the sun elsewhere, its shadow where the"
echo "probe did not refine), each mesh's per-pixel relative RMS against the reference so turned:"
echo
echo "| mesh | per-pixel relative RMS, lighting turned $turn degrees |"
echo "|---|---|"
for r in "${runs[@]}"; do
    echo "| $r | $(pixel_error truth-turned "$r-turned" | sed 's/ |.*//') |"
done
echo
if [ ${#met[@]} -gt 0 ]; then
    echo "**Goal met** by ${met[*]}: the 128^2 grid's error ($goal) or less with at most $budget vertices."
else
    echo "**Goal not met**: no tolerance reaches the 128^2 grid's error ($goal) within $budget vertices."
fi
echo
python3 scripts/refine_figure.py "$work" results/relight/refine.png dense "${runs[@]}"
echo
echo "Picture: \`refine.png\`, the bunny's shadow (the same crop of each image), then the"
echo "absolute error against the dense cube render, 4x: the interpolation between vertices."
echo
echo "Truth: $(tr '\n' ' ' <"$work/truth.out" | sed "s|$work/||g; s/  */ /g")"
echo
echo "Load when it ended: \`$(uptime)\`"
