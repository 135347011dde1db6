#!/usr/bin/env bash
# The README's two commands on a machine without the optional components, then with them:
# writes results/fresh-machine/{without,with}.log and prints a summary of each run (exit codes,
# test counts, the skip lines). Run as root from the repository's root; it removes and
# reinstalls Debian packages and runs `cargo clean` before each round:
#   bash scripts/fresh_machine.sh
# Takes about twenty minutes a round on two cores (a build from nothing, then every test).
set -uo pipefail
cd "$(dirname "$0")/.."
out=results/fresh-machine
mkdir -p "$out"
optional=(libembree3-3 libembree-dev chromium slurmctld slurmd slurm-client munge)

round() {
    local name=$1 log="$out/$1.log"
    : >"$log"
    {
        echo "# $(date -u +%FT%TZ) on $(uname -srm), $(nproc) cores; $2"
        for p in "${optional[@]}"; do
            printf '# %-14s %s\n' "$p" "$(dpkg-query -W -f='${Status} ${Version}' "$p" 2>/dev/null || echo 'not installed')"
        done
        echo "# HAARSHIFT_REQUIRE=${HAARSHIFT_REQUIRE:-}"
        cargo --version
        cargo clean 2>&1
        for command in "cargo run --release -p haarshift-cli -- experiment rotation-cycle" \
                       "cargo test --workspace --release"; do
            echo "\$ $command"
            start=$SECONDS
            $command 2>&1
            echo "# exit $? after $((SECONDS - start)) s: $command"
        done
        echo "\$ python3 -m pip install ./python[test] && python3 -m pytest -q python/tests"
        start=$SECONDS
        python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore "./python[test]" 2>&1 \
            && python3 -m pytest -q python/tests 2>&1
        echo "# exit $? after $((SECONDS - start)) s: pip install and pytest"
    } >>"$log"
    echo "== $name: $2"
    grep -E '^# exit' "$log"
    awk '/^test result:/ { p += $4; f += $6; i += $8 } END { printf "cargo test: %d passed, %d failed, %d ignored\n", p, f, i }' "$log"
    echo "skip lines: $(grep -c '^skipped:' "$log")"
    grep -E '^skipped:' "$log"
    grep -E '^SKIPPED|[0-9]+ passed' "$log" | tail -n 12
}

DEBIAN_FRONTEND=noninteractive apt-get remove -y -qq "${optional[@]}" >/dev/null 2>&1
round without "the optional components removed (apt-get remove ${optional[*]})"
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    libembree3-3 chromium slurm-wlm munge >/dev/null 2>&1
HAARSHIFT_REQUIRE=chromium,embree,slurm round with "reinstalled (apt-get install libembree3-3 chromium slurm-wlm munge), every component required"
