#!/usr/bin/env bash
# Reproduces results/relight/bake_threejs.png and bake_threejs.md: the bunny on its ground
# plane (cube 6 x 32^2) baked by `relight bake` under Rooitou Park (1k), validated by the
# Khronos glTF Validator and shown by three.js alone (tools/bake-threejs) in headless
# Chromium, beside haarshift's own render of the same radiance.
# Needs node, npm and chromium (apt-get install nodejs npm chromium); installs the two tools'
# npm packages (npm ci) when absent.
# Usage: scripts/bake_threejs.sh   (from the repository's root; about a minute on two cores)
set -euo pipefail
hs=${HAARSHIFT:-target/release/haarshift}
[ -x "$hs" ] || { cargo build --release -p haarshift-cli >&2; hs=target/release/haarshift; }
for tool in tools/gltf-validate tools/bake-threejs; do
    [ -d "$tool/node_modules" ] || (cd "$tool" && npm ci --no-audit --no-fund >&2)
done
out=results/relight
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
env=testdata/envmaps/rooitou_park_1k.hdr
"$hs" relight precompute testdata/meshes/bunny.ply --ground-plane --param cube --resolution 32 \
    -o "$work/bunny.hsr" >"$work/precompute.txt"
"$hs" relight bake "$work/bunny.hsr" --env "$env" --yaw 120 -o "$work/bunny.glb" >"$work/bake.txt"
node tools/gltf-validate/validate.mjs "$work/bunny.glb" >"$work/validation.json"
node tools/bake-threejs/shoot.mjs "$work/bunny.glb" "$out/bake_threejs.png" 640 480 >"$work/page.json"
# haarshift's own rasterisation of the same radiance, from the same side.
"$hs" relight render "$work/bunny.hsr" --env "$env" --yaw 120 --background 0.0144,0.0144,0.0144 \
    -o "$out/bake_haarshift.png" --force >"$work/render.txt"
strip() { sed "s|$work/||g" "$1"; }
{
    echo "# A baked glTF in three.js"
    echo
    echo "Made by \`scripts/bake_threejs.sh\`: the bunny on its ground plane, precomputed at cube"
    echo "6 x 32^2, baked by \`relight bake\` under Rooitou Park (1k, yaw 120 degrees, exposure 0) into"
    echo "\`bunny.glb\`; the Khronos glTF Validator's report of that file; the page"
    echo "\`tools/bake-threejs\` (three.js's GLTFLoader alone, no haarshift code) in headless"
    echo "Chromium: \`bake_threejs.png\`. Beside it \`bake_haarshift.png\`, \`relight render\` of the same"
    echo "radiance over the page's background colour (#202020 is sRGB 32, linear 0.0144), from the"
    echo "same camera (the page frames the model as \`relight render\`'s default camera does)."
    echo
    echo '```'
    strip "$work/precompute.txt"
    strip "$work/bake.txt"
    echo '```'
    echo
    echo "The validator's report (errors, warnings, infos, hints and every message):"
    echo
    echo '```json'
    strip "$work/validation.json"
    echo '```'
    echo
    echo "What three.js made of the file (material, vertex colours, vertex count, the asset's extras):"
    echo
    echo '```json'
    strip "$work/page.json"
    echo '```'
} >"$out/bake_threejs.md"
echo "wrote $out/bake_threejs.png, $out/bake_haarshift.png and $out/bake_threejs.md" >&2
