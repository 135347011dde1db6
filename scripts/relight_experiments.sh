#!/usr/bin/env bash
# The relighting experiment's committed results: the default (quick) protocol into
# results/relight/experiments/ and the full protocol into results/relight/experiments/full/,
# each with the load of the machine before and after (the seconds columns move with it).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p haarshift-cli
hs=target/release/haarshift
run() {
    local out=$1
    shift
    mkdir -p "$out"
    echo "load before: $(uptime)" > "$out/load.txt"
    echo "+ haarshift $*" >&2
    /usr/bin/time -v "$hs" "$@" --out-dir "$out" --force 2> "$out/time.txt"
    echo "load after: $(uptime)" >> "$out/load.txt"
}
run results/relight/experiments experiment relight
if [[ "${1:-}" != "--quick-only" ]]; then
    run results/relight/experiments/full experiment relight --full
fi
