#!/usr/bin/env bash
# Glossy renders of the bunny on its ground plane: Phong 10, 50 and 200 and Blinn-Phong 50, the
# BRDF rotated into each vertex's frame by the Haar chain rule and by bilinear (spatial)
# rotation, each against `relight reference` (the BRDF evaluated per texel, no rotation) at the
# same lat-long resolution; and a glossy turntable. Writes PNGs, errors.md and turntable.gif:
#   scripts/relight_glossy.sh ENV.hdr [OUT_DIR]      (default OUT_DIR: results/relight/glossy)
# The errors are RMS over the vertices relative to the reference's RMS radiance (numpy reads
# the .npy files the commands write).
set -euo pipefail
cd "$(dirname "$0")/.."
env_map=${1:?usage: scripts/relight_glossy.sh ENV.hdr [OUT_DIR]}
out=${2:-results/relight/glossy}
res=${RESOLUTION:-128}
bins=${BINS:-128}
cargo build --release -p haarshift-cli >&2
hs=target/release/haarshift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
mesh=testdata/meshes/bunny.ply
run() { echo "+ haarshift $*" >&2; "$hs" "$@" >>"$work/log" 2>&1; }
run relight precompute "$mesh" --ground-plane --param latlong --resolution "$res" -o "$work/bunny.hsr"
view=(--width 320 --height 240)
for brdf in phong:10 phong:50 phong:200 blinn:50; do
    name=${brdf/:/}
    run relight reference "$mesh" --ground-plane --env "$env_map" --resolution "$res" --brdf "$brdf" \
        "${view[@]}" --vertices "$work/$name-reference.npy" -o "$out/$name-reference.png" --force
    for rotation in haar spatial; do
        run relight render "$work/bunny.hsr" --env "$env_map" --brdf "$brdf" --brdf-rotation "$rotation" \
            --rotation-cache "$bins" "${view[@]}" --vertices "$work/$name-$rotation.npy" \
            -o "$out/$name-$rotation.png" --force
    done
done
run relight animate "$work/bunny.hsr" --env "$env_map" --brdf phong:50 --rotation-cache "$bins" \
    "${view[@]}" --frames 24 -o "$out/turntable.gif" --force
python3 - "$work" "$env_map" "$res" "$bins" >"$out/errors.md" <<'PY'
import sys, numpy as np
work, env, res, bins = sys.argv[1:]
print("# Glossy bunny: the BRDF rotated in the Haar domain and spatially, against the reference\n")
print(f"`scripts/relight_glossy.sh {env}`: lat-long {res} x {2*int(res)}, rotation cache {bins} x {2*int(bins)} bins,")
print("every coefficient kept; error = RMS over the vertices of (render - reference) / RMS of the reference.\n")
print("| material | haar | spatial |")
print("|---|---|---|")
for name in ["phong10", "phong50", "phong200", "blinn50"]:
    ref = np.load(f"{work}/{name}-reference.npy").astype(np.float64)
    rms = np.sqrt((ref ** 2).mean())
    cells = []
    for rot in ["haar", "spatial"]:
        got = np.load(f"{work}/{name}-{rot}.npy").astype(np.float64)
        cells.append(f"{np.sqrt(((got - ref) ** 2).mean()) / rms:.2e}")
    print(f"| {name} | {cells[0]} | {cells[1]} |")
PY
grep -E "image of|shading [0-9]|^frame [01]:" "$work/log" | sed 's/^/    /' >>"$out/errors.md"
cat "$out/errors.md"
