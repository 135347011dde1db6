#!/usr/bin/env bash
# The bytes of the scene caches (.hsr) that `relight precompute` and `relight merge` write,
# pinned: writes every cache of testdata/cache_hashes.args with BINARY into OUTDIR (absent or
# empty) and prints one line per cache, `SHA256  NAME`, as sha256sum does:
#   scripts/cache_hashes.sh target/release/haarshift /tmp/caches
# The caches cover mesh files (PLY, OBJ + MTL, glTF, .glb, a glTF node hierarchy), scene files
# (generators; a mesh with an environment and a camera), spherical harmonics, the direction
# order, refinement (by transport and by a light), shards and their merge, and bounces sharded
# with --bounce-from, all with haarshift's own packet tracer (specified to the bit), at
# resolutions small enough for the whole set to take a few seconds. Each was checked to write
# the same bytes twice and with RAYON_NUM_THREADS=1.
#
# testdata/cache_hashes.sha256 holds the hashes and cli/tests/cli/cache_hashes.rs checks them
# (both read the arguments from testdata/cache_hashes.args, the one list of them). After a
# change that is meant to change a cache's bytes, regenerate them:
#   scripts/cache_hashes.sh target/release/haarshift "$(mktemp -d)" > testdata/cache_hashes.sha256
# and say in CHANGELOG.md which caches changed and why. Any other change leaves them alone;
# `cd OUTDIR && sha256sum -c .../testdata/cache_hashes.sha256` names the caches that differ.
set -euo pipefail
if [[ $# -ne 2 ]]; then
    echo "usage: $0 BINARY OUTDIR" >&2
    exit 2
fi
binary=$(realpath "$1")
mkdir -p "$2"
outdir=$(realpath "$2")
if [[ -n $(ls -A "$outdir") ]]; then
    echo "$0: $outdir is not empty" >&2
    exit 1
fi
# The arguments name testdata/ from the root: a scene file's environment is recorded by the
# path it was reached by.
cd "$(dirname "$0")/.."
while read -r name line; do
    [[ -z $name || $name == \#* ]] && continue
    read -r -a args <<<"$line"
    args=("${args[@]//\{out\}/$outdir}")
    # The command's report goes to stderr: stdout is the hashes alone.
    "$binary" "${args[@]}" -o "$outdir/$name" >&2
    (cd "$outdir" && sha256sum "$name")
done <testdata/cache_hashes.args
