#!/usr/bin/env bash
# The two loop orders of the visibility precomputation timed on one scene: vertex-major (rays
# through the BVH) and direction-major (Microsoft 2003: a 2048 x 2048 shadow buffer per direction),
# each under /usr/bin/time -v for its CPU time and peak resident memory. Prints Markdown:
#   scripts/relight_orders.sh > results/relight/orders.md
# SCENE (first argument) is a mesh or scene file; the default is the bunny (its ground plane
# added). Their agreement (at most 1 % of pairs differ, each within 2 shadow-map texels of a
# silhouette) is a test: relight::visibility::tests.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-testdata/meshes/bunny.ply}
# shellcheck source=scripts/timing.sh
source scripts/timing.sh
start_load=$(uptime)
for order in vertex direction; do
    args=(relight precompute "$scene" --ground-plane --param cube --resolution 32 --order "$order"
        -o "$work/$order.hsr")
    echo "+ haarshift ${args[*]}" >&2
    /usr/bin/time -v "$hs" "${args[@]}" >"$work/$order.out" 2>"$work/$order.time"
done
echo "# The two precomputation orders"
echo
echo "Made by \`scripts/relight_orders.sh > results/relight/orders.md\` on $(nproc) cores;"
echo "load when it started (\`uptime\`): \`$start_load\`"
echo
echo "| order | command | wall (m:ss) | CPU s (user + sys) | peak resident MiB | what the command reports |"
echo "|---|---|---|---|---|---|"
for order in vertex direction; do
    cpu=$(echo "$(field "$order" 'User time') + $(field "$order" 'System time')" | bc)
    peak=$(echo "scale=1; $(field "$order" 'Maximum resident set size') / 1024" | bc)
    report=$(tr '\n' ' ' <"$work/$order.out" | sed "s|$work/||g; s/|/\\\\|/g; s/  */ /g")
    echo "| $order | \`haarshift relight precompute $scene --ground-plane --param cube --resolution 32 --order $order\` | $(field "$order" 'Elapsed (wall clock)') | $cpu | $peak | $report |"
done
echo
echo "Load when it ended: \`$(uptime)\`"
