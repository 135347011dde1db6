#!/usr/bin/env bash
# The relighting speed figures on this machine: the 85,860-vertex "cubes" scene of Vollick and Lessig
# (testdata/scenes/cubes.json) precomputed at cube 6 x 64^2, then one render (new lighting,
# fixed view, Lambertian) and eight animation frames, keeping 200 lighting and 420 visibility
# coefficients in all (194 and
# 414 detail coefficients, plus the 6 faces' scaling coefficients: Sun 2006's 70 per cube face),
# each run under /usr/bin/time -v for its peak resident memory and CPU time. Prints a Markdown
# report on standard output:
#   scripts/relight_speed.sh > results/relight/speed.md
# ENV (first argument) is the lighting; the default is the committed 256 x 128 Rooitou Park.
set -euo pipefail
cd "$(dirname "$0")/.."
env_map=${1:-testdata/envmaps/rooitou_park_256x128.npy}

# shellcheck source=scripts/timing.sh
source scripts/timing.sh

precompute=(relight precompute testdata/scenes/cubes.json --param cube --resolution 64 --keep-visibility 414
    -o "$work/cubes.hsr")
render=(relight render "$work/cubes.hsr" --env "$env_map" --yaw 30 --keep-light 194
    --keep-visibility 414 -o "$work/cubes.png" --width 640 --height 480)
# Eight frames of the lighting turning about Y by 45 degrees (whole columns of the working
# map): the per-frame cost of a new lighting once the transport and the cube's conversion
# table are prepared.
animate=(relight animate "$work/cubes.hsr" --env "$env_map" --frames 8 --keep-light 194
    --keep-visibility 414 -o "$work/frame_%03d.png" --width 640 --height 480)
start_load=$(uptime)
timed precompute "${precompute[@]}"
timed render "${render[@]}"
timed animate "${animate[@]}"

echo "# Relighting speed: the 85,860-vertex cubes scene"
echo
echo "Made by \`scripts/relight_speed.sh > results/relight/speed.md\` on $(nproc) cores;"
echo "load when it started (\`uptime\`): \`$start_load\`"

echo
echo "Commands (the cache in a temporary directory):"
echo
echo '```'
echo "haarshift ${precompute[*]}" | sed "s|$work/||g"
echo "haarshift ${render[*]}" | sed "s|$work/||g"
echo "haarshift ${animate[*]}" | sed "s|$work/||g"
echo '```'
echo
echo "| step | wall (m:ss) | CPU s (user + sys) | peak resident MiB | what the command reports |"
echo "|---|---|---|---|---|"
for step in precompute render animate; do
    step_row "$step"
done
echo
echo "Load when it ended: \`$(uptime)\`"
echo
echo "Seeds, for scale: 002 (Matlab) 5.8 min for 85,860 vertices at 64^2; 001 under 10 s a frame for"
echo "180,000 vertices; Ng et al. 2004: 3-5 s for 300,000 vertices at 6 x 64^2."

