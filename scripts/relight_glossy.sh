#!/usr/bin/env bash
# Glossy renders of a scene under one or more environment maps: Phong 10, 50 and 200 and
# Blinn-Phong 50, the BRDF rotated into each vertex's frame by the Haar chain rule and by
# bilinear (spatial) rotation, each against `relight reference` (the BRDF evaluated per texel,
# no rotation) at the same lat-long resolution.
#   scripts/relight_glossy.sh SCENE ENV.hdr [ENV.hdr ...]
# SCENE is `bunny` (testdata/meshes/bunny.ply on its ground plane, which stays Lambertian) or a
# scene file (testdata/scenes/cylinder_and_bump.json: Vollick and Lessig's procedural scene, all glossy).
# Writes results/relight/glossy/NAME/ENV/*.png and results/relight/glossy/NAME/errors.md (NAME:
# `bunny` or the scene file's stem, ENV: the map's file stem); for the bunny also a glossy
# turntable under the first map, results/relight/glossy/turntable.gif.
# The errors are RMS over the vertices relative to the reference's RMS radiance
# (`haarshift relight error` over the .npy files the commands write). RESOLUTION (default 128)
# and BINS (default 128) are the lat-long height and the rotation cache's bins per axis.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:?usage: scripts/relight_glossy.sh SCENE ENV.hdr [ENV.hdr ...]}
shift
[ $# -gt 0 ] || { echo "usage: scripts/relight_glossy.sh SCENE ENV.hdr [ENV.hdr ...]" >&2; exit 2; }
res=${RESOLUTION:-128}
bins=${BINS:-128}
# shellcheck source=scripts/timing.sh
source scripts/timing.sh
if [ "$scene" = bunny ]; then
    name=bunny
    input=(testdata/meshes/bunny.ply --ground-plane)
else
    name=$(basename "$scene" .json)
    input=("$scene")
fi
out=results/relight/glossy/$name
mkdir -p "$out"
run() { echo "+ haarshift $*" >&2; "$hs" "$@" >>"$work/log" 2>&1; }
run relight precompute "${input[@]}" --param latlong --resolution "$res" -o "$work/scene.hsr"
view=(--width 320 --height 240)
materials=(phong:10 phong:50 phong:200 blinn:50)
envs=()
for env_map in "$@"; do
    env_name=$(basename "${env_map%.*}")
    envs+=("$env_name")
    mkdir -p "$out/$env_name"
    for brdf in "${materials[@]}"; do
        m=${brdf/:/}
        run relight reference "${input[@]}" --env "$env_map" --resolution "$res" --brdf "$brdf" \
            "${view[@]}" --vertices "$work/$env_name-$m-reference.npy" \
            -o "$out/$env_name/$m-reference.png" --force
        for rotation in haar spatial; do
            run relight render "$work/scene.hsr" --env "$env_map" --brdf "$brdf" \
                --brdf-rotation "$rotation" --rotation-cache "$bins" "${view[@]}" \
                --vertices "$work/$env_name-$m-$rotation.npy" \
                -o "$out/$env_name/$m-$rotation.png" --force
        done
    done
done
if [ "$name" = bunny ]; then
    run relight animate "$work/scene.hsr" --env "$1" --brdf phong:50 --rotation-cache "$bins" \
        "${view[@]}" --frames 24 -o results/relight/glossy/turntable.gif --force
fi
{
    echo "# Glossy $name: the BRDF rotated in the Haar domain and spatially, against the reference"
    echo
    echo "\`scripts/relight_glossy.sh\` ($name): lat-long $res x $((2 * res)), rotation cache $bins x $((2 * bins))"
    echo "bins, every coefficient kept; error = RMS over the vertices of (render - reference) / RMS"
    echo "of the reference (\`haarshift relight error\`). The renders are in the folder of each map."
    echo
    echo "| map | material | haar | spatial |"
    echo "|---|---|---|---|"
    for env_name in "${envs[@]}"; do
        for brdf in "${materials[@]}"; do
            m=${brdf/:/}
            p=$work/$env_name-$m
            errors=$("$hs" relight error "$p-reference.npy" "$p-haar.npy" "$p-spatial.npy" | relative_rms)
            echo "| $env_name | $m | $(echo "$errors" | sed -n 1p) | $(echo "$errors" | sed -n 2p) |"
        done
    done
    echo
    echo "What the commands reported:"
    echo
} >"$out/errors.md"
grep -E "image of|shading [0-9]|^frame [01]:" "$work/log" | sed 's/^/    /' >>"$out/errors.md"
cat "$out/errors.md"
