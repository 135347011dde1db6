# What the speed scripts share (sourced from the repository's root, not run): the release
# binary built and named $hs, a scratch directory $work removed on exit, and each command run
# under /usr/bin/time -v, its standard output in $work/NAME.out and time's report in
# $work/NAME.time.
cargo build --release -p haarshift-cli >&2
hs=target/release/haarshift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Runs `haarshift ARGS` as step NAME.
timed() {
    local name=$1
    shift
    echo "+ haarshift $*" >&2
    /usr/bin/time -v "$hs" "$@" >"$work/$name.out" 2>"$work/$name.time"
    cat "$work/$name.out" >&2
}
# A field of /usr/bin/time -v's report of step NAME.
field() { grep -F "$2" "$work/$1.time" | sed 's/.*: //'; }
# CPU seconds (user + system) of step NAME.
cpu() { echo "$(field "$1" 'User time') + $(field "$1" 'System time')" | bc; }
# Peak resident memory of step NAME, MiB.
peak_mib() { echo "scale=1; $(field "$1" 'Maximum resident set size') / 1024" | bc; }
# One Markdown table row of step NAME: wall, CPU, peak memory and what it printed.
step_row() {
    local report
    report=$(tr '\n' ' ' <"$work/$1.out" | sed "s|$work/||g; s/|/\\\\|/g; s/  */ /g")
    echo "| $1 | $(field "$1" 'Elapsed (wall clock)') | $(cpu "$1") | $(peak_mib "$1") | $report |"
}
# The relative RMS figures of `haarshift relight error`'s lines on standard input, one a line.
relative_rms() { sed -E 's/.*: relative RMS ([^,]+),.*/\1/'; }
