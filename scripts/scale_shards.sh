#!/usr/bin/env bash
# Sharding costs nothing: the cubes scene (85,860 vertices) at cube 6 x 64^2, 420 detail
# coefficients kept a vertex, precomputed unsharded, then in 1, 2, 4 and 8 shards run one after another on this machine, each shard
# under /usr/bin/time -v; the shards of each count merged (timed) and compared byte for byte
# with the unsharded cache. Prints Markdown:
#   scripts/scale_shards.sh > results/scale/shards.md
# RESOLUTION (default 64) sets the cube face side.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=testdata/scenes/cubes.json
resolution=${RESOLUTION:-64}
# shellcheck source=scripts/timing.sh
source scripts/timing.sh
# A copy, so that a build during the run does not swap the binary under it.
cp "$hs" "$work/haarshift"
hs=$work/haarshift
start_load=$(uptime)
options=(--param cube --resolution "$resolution" --keep-visibility 420)
timed whole relight precompute "$scene" "${options[@]}" -o "$work/whole.hsr"
rows=()
for count in 1 2 4 8; do
    cpu_sum=0 wall_sum=0 peak=0
    parts=()
    for ((i = 0; i < count; i++)); do
        name=n$count-$i
        timed "$name" relight precompute "$scene" "${options[@]}" --shard "$i/$count" \
            -o "$work/$name.hsr"
        cpu_sum=$(echo "$cpu_sum + $(cpu "$name")" | bc)
        wall=$(field "$name" 'Elapsed (wall clock)')
        wall_sum=$(echo "$wall_sum + $(echo "$wall" | awk -F: '{ s = 0; for (k = 1; k <= NF; k++) s = s * 60 + $k; print s }')" | bc)
        peak=$(echo "if ($(peak_mib "$name") > $peak) $(peak_mib "$name") else $peak" | bc)
        parts+=("$work/$name.hsr")
    done
    timed "merge$count" relight merge "${parts[@]}" -o "$work/merged$count.hsr"
    same=no
    cmp -s "$work/merged$count.hsr" "$work/whole.hsr" && same=yes
    rm -f "${parts[@]}" "$work/merged$count.hsr"
    ratio=$(printf "%.3f" "$(echo "scale=3; $cpu_sum / $(cpu whole)" | bc)")
    rows+=("| $count | $cpu_sum | $ratio | $wall_sum | $peak | $(field "merge$count" 'Elapsed (wall clock)') | $(cpu "merge$count") | $(peak_mib "merge$count") | $same |")
done
bytes=$(stat -c %s "$work/whole.hsr")
echo "# Sharded precomputation: what it costs"
echo
echo "Made by \`scripts/scale_shards.sh > results/scale/shards.md\` on $(nproc) cores;"
echo "load when it started (\`uptime\`): \`$start_load\`"
echo
echo "\`haarshift relight precompute $scene ${options[*]}\`: unsharded, $(field whole 'Elapsed (wall clock)') wall,"
echo "$(cpu whole) CPU s, peak resident $(peak_mib whole) MiB, cache $bytes bytes. It printed:"
echo
echo '```text'
sed "s|$work/||g" "$work/whole.out"
echo '```'
echo
echo "Then the same with \`--shard I/N\` for every I, the shards run one after another, and"
echo "\`relight merge\` of the N shards. CPU is user + system seconds summed over the shards;"
echo "the ratio is to the unsharded run's CPU time."
echo
echo "| shards N | CPU s, all shards | ratio to unsharded | wall s, all shards | largest shard peak MiB | merge wall (m:ss) | merge CPU s | merge peak MiB | merged == unsharded bytes |"
echo "|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "Load when it ended: \`$(uptime)\`"
