#!/usr/bin/env bash
# What a user who adds only the core crate compiles: for each git revision given (default: the
# commit before the split into crates, and HEAD), the crates in `cargo tree -p haarshift -e
# normal` (distinct name and version, the package itself included) and the wall time of a clean
# `cargo build --release -p haarshift` in a fresh target directory, the registry already
# downloaded (`cargo fetch`: network time is not build time). Run on an otherwise idle machine;
# prints a Markdown table.
#
#   bash scripts/build_cost.sh [REV ...] > results/build/table.md
set -euo pipefail
cd "$(dirname "$0")/.."
revs=("$@")
[ ${#revs[@]} -gt 0 ] || revs=(3ec9b9f3 HEAD)
work=$(mktemp -d)
trap 'for r in "${revs[@]}"; do git worktree remove --force "$work/$r" 2>/dev/null || true; done; rm -rf "$work"' EXIT
echo "| revision | crates in the core's tree | clean release build of the core: wall (s) | CPU, user + system (s) | listed dependencies in the tree |"
echo "|---|---|---|---|---|"
for rev in "${revs[@]}"; do
    git worktree add -q --detach "$work/$rev" "$rev"
    (
        cd "$work/$rev"
        cargo fetch -q
        crates=$(cargo tree -p haarshift -e normal --prefix none | sed 's/ (\*)//; s/ (proc-macro)//' | sort -u)
        count=$(echo "$crates" | wc -l)
        listed=$(echo "$crates" | awk '{print $1}' | { grep -xE 'gltf|gltf-json|obvhs|glam|libloading|plotters|csv|ply-rs-bw|data-encoding' || true; } | tr '\n' ' ')
        # Wall, user and system seconds of the whole build (cargo and every rustc it runs).
        read -r wall user sys < <(CARGO_TARGET_DIR="$work/target-$rev" /usr/bin/time -f '%e %U %S' \
            cargo build -q --release -p haarshift 2>&1 >/dev/null | tail -n 1)
        printf '| %s (`%s`) | %s | %.1f | %.1f | %s |\n' "$rev" "$(git rev-parse --short HEAD)" \
            "$count" "$wall" "$(echo "$user + $sys" | bc)" "${listed:-none}"
    )
done
