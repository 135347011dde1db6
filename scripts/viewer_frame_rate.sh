#!/usr/bin/env bash
# The viewer's frame rates on this machine, in headless Chromium with software WebGL sharing
# the cores with the server (viewer/examples/frame_rate.rs, one row per configuration):
#   the 85,860-vertex cubes scene (cube 6 x 64^2, 200 lighting and 420 visibility coefficients:
#   194 and 414 detail coefficients plus the 6 faces' scaling ones), Lambertian, the lighting
#   dragged and the camera orbited, and at 320 x 240; the bunny on its ground plane at lat-long
#   64, Lambertian and with Phong 50 (rotation cache 64; every coefficient, or 200 and 420), the
#   lighting dragged and the camera orbited; the bunny at cube 6 x 64^2, Lambertian; the bunny and
#   the ball (testdata/scenes/bunny_and_ball.json, a dynamic scene at lat-long 32: occlusion
#   fields; every coefficient, and scripts/dynamic.sh's budgets), the ball dragged across the
#   ground and the lighting dragged. Prints a Markdown report:
#   scripts/viewer_frame_rate.sh > results/viewer/frame_rate.md
# The caches are precomputed in a temporary directory (minutes for the cubes); WORK=DIR keeps
# and reuses them. ENV (first argument) is the lighting.
set -euo pipefail
cd "$(dirname "$0")/.."
env_map=${1:-testdata/envmaps/rooitou_park_1k.hdr}
work=${WORK:-$(mktemp -d)}
mkdir -p "$work" results/viewer
cargo build --release -q -p haarshift-cli -p haarshift-viewer --example frame_rate
bin=target/release/haarshift
rate=target/release/examples/frame_rate
[ -f "$work/cubes.hsr" ] || "$bin" relight precompute testdata/scenes/cubes.json --param cube \
    --resolution 64 --keep-visibility 414 -o "$work/cubes.hsr" >&2
[ -f "$work/bunny.hsr" ] || "$bin" relight precompute testdata/meshes/bunny.ply --ground-plane \
    --resolution 64 -o "$work/bunny.hsr" >&2
[ -f "$work/bunny-cube.hsr" ] || "$bin" relight precompute testdata/meshes/bunny.ply --ground-plane \
    --param cube --resolution 64 -o "$work/bunny-cube.hsr" >&2
start_load=$(uptime)
phong=(brdf=phong:50 rotation_cache=64)
budgets=(keep_light=194 keep_visibility=414)
fields=(keep_light=200 keep_visibility=70 keep_field=70)  # scripts/dynamic.sh's budgets
rows=(
    "$("$rate" "$work/cubes.hsr" "$env_map" label=cubes keep_light=194)"
    "$("$rate" "$work/cubes.hsr" "$env_map" label=cubes keep_light=194 drag=orbit)"
    "$("$rate" "$work/cubes.hsr" "$env_map" label=cubes keep_light=194 size=320x240)"
    "$("$rate" "$work/bunny.hsr" "$env_map" label=bunny)"
    "$("$rate" "$work/bunny.hsr" "$env_map" label=bunny "${phong[@]}")"
    "$("$rate" "$work/bunny.hsr" "$env_map" label=bunny "${phong[@]}" "${budgets[@]}")"
    "$("$rate" "$work/bunny.hsr" "$env_map" label=bunny "${phong[@]}" drag=orbit)"
    "$("$rate" "$work/bunny-cube.hsr" "$env_map" label=bunny "${budgets[@]}")"
    "$("$rate" testdata/scenes/bunny_and_ball.json "$env_map" label=bunny-and-ball drag=object:1)"
    "$("$rate" testdata/scenes/bunny_and_ball.json "$env_map" label=bunny-and-ball "${fields[@]}" drag=object:1)"
    "$("$rate" testdata/scenes/bunny_and_ball.json "$env_map" label=bunny-and-ball "${fields[@]}")"
    "$("$rate" "$work/cubes.hsr" "$env_map" label=cubes keep_light=194 screenshot=results/viewer/cubes.png)"
)
echo "# The viewer's frame rates"
echo
echo "Made by \`scripts/viewer_frame_rate.sh > results/viewer/frame_rate.md\` on $(nproc) cores"
echo "with $(chromium --version 2>/dev/null || echo chromium) headless (SwiftShader WebGL2), 640 x 480"
echo "unless the row says otherwise;"
echo "the lighting \`$env_map\`. Load when it started (\`uptime\`): \`$start_load\`"
echo
echo "Each row is one page and one drag of 50 mouse moves, one every 16 ms (a 60 Hz mouse),"
echo "4 pixels each: 2 degrees of lighting yaw, 1.6 degrees of camera orbit, or a dynamic scene's"
echo "object slid across the ground by 4 pixels' worth at the point looked at (the server then"
echo "sends the mesh's positions with the frame; *prepare* is placing the objects). *Server ms* are"
echo "medians over the frames computed during the drag, from the frames' headers: the lighting"
echo "rotated and encoded, the BRDF rotations, the shading (rotations included) and their sum."
echo "*Received/s* and *drawn/s* are the page's own counters over the drag's wall time, read over"
echo "the DevTools protocol; the server skips every state but the newest, so frames received"
echo "are fewer than states sent when a frame takes longer than a mouse move. *First frame* is"
echo "from opening the page to its first drawn frame (the shader's preparation and, for Phong,"
echo "the first rotations), seconds."
echo
echo "| scene | vertices | maps | BRDF | budgets | size | dragged | encode ms | BRDF rotations ms | shading ms | server ms | frames | received/s | drawn/s | first frame s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
