#!/usr/bin/env bash
# What `--precision q16` (the Lambertian transport in 16 bits a coefficient with a scale per
# vertex) costs in accuracy, per map: the bunny on its ground plane (testdata/scenes/bunny.json)
# precomputed at lat-long 64 and at cube 32, every coefficient stored, rendered under the four
# 1k maps with every coefficient and with the viewer's budgets (--keep-light 200
# --keep-visibility 420), in f32 and q16, each against the reference (--basis reference, the
# same lighting) and q16 against f32. Prints a Markdown report on standard output:
#   scripts/relight_quantised.sh > results/relight/quantised.md
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/timing.sh
source scripts/timing.sh

maps=(rooitou_park st_fagans_interior studio_small_03 venice_sunset)
budgets=("every coefficient|" "200 / 420|--keep-light 200 --keep-visibility 420")
rows=()
for param in "latlong 64" "cube 32"; do
    set -- $param
    cache="$work/bunny-$1$2.hsr"
    timed "precompute-$1$2" relight precompute testdata/scenes/bunny.json --param "$1" \
        --resolution "$2" -o "$cache"
    for map in "${maps[@]}"; do
        env_map="testdata/envmaps/${map}_1k.hdr"
        view=(--env "$env_map" --width 64 --height 48)
        timed reference relight render "$cache" "${view[@]}" --basis reference --force \
            --vertices "$work/reference.npy" -o "$work/reference.png"
        for budget in "${budgets[@]}"; do
            label=${budget%%|*}
            read -r -a flags <<<"${budget#*|}"
            for precision in f32 q16; do
                timed "$precision" relight render "$cache" "${view[@]}" "${flags[@]}" \
                    --precision "$precision" --force --vertices "$work/$precision.npy" \
                    -o "$work/$precision.png"
            done
            errors=($("$hs" relight error "$work/reference.npy" "$work/f32.npy" "$work/q16.npy" |
                relative_rms))
            apart=$("$hs" relight error "$work/f32.npy" "$work/q16.npy" | relative_rms)
            rows+=("| $1 $2 | $map | $label | ${errors[0]} | ${errors[1]} | $apart |")
        done
    done
done

echo "# The quantised transport's error, per map"
echo
echo "Made by \`scripts/relight_quantised.sh > results/relight/quantised.md\`."
echo
echo "The bunny on its ground plane (\`testdata/scenes/bunny.json\`, 2,928 vertices), every"
echo "coefficient stored, rendered under each 1k map with \`--precision f32\` (exact: the stored"
echo "coefficients as they are) and \`--precision q16\` (each vertex's coefficients as 16-bit"
echo "integers times a per-vertex scale, half the bytes a frame reads), each against"
echo "\`--basis reference\` (direct quadrature with ray casting, the same lighting). Errors are the RMS"
echo "over vertices and channels relative to the reference's RMS (\`relight error\`); the last column"
echo "is q16 against f32: what quantising adds."
echo
echo "| map | lighting | coefficients (light / visibility) | f32 vs reference | q16 vs reference | q16 vs f32 |"
echo "|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
