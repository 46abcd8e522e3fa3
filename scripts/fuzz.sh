#!/usr/bin/env bash
# Fuzzes the input parsers with cargo-fuzz (libFuzzer): the SwarmCon tracker stream, the Colias serial
# frames, the JSON pose datagrams, scenario files and the command line. Not part of CI.
#
#   bash scripts/fuzz.sh [RUNS] [SECONDS]    # each target: RUNS executions (default 200000), at most
#                                            # SECONDS s (default 300), whichever comes first
#   FUZZ_TARGETS="udp_pose scenario" bash scripts/fuzz.sh 10000    # some targets only
#
# Needs `cargo install cargo-fuzz`. cargo-fuzz passes nightly-only flags (-Zsanitizer=address);
# RUSTC_BOOTSTRAP=1 lets the stable toolchain accept them. Builds into fuzz/target (its own workspace);
# corpora grow in fuzz/corpus/<target>, crashes land in fuzz/artifacts/<target> (both git-ignored).
# Replay a crash: RUSTC_BOOTSTRAP=1 cargo fuzz run -O <target> fuzz/artifacts/<target>/<file>
set -uo pipefail
runs=${1:-200000}
seconds=${2:-300}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root/fuzz" || exit 1
export RUSTC_BOOTSTRAP=1
command -v cargo-fuzz >/dev/null || { echo "cargo-fuzz is not installed: cargo install cargo-fuzz" >&2; exit 1; }
cargo fuzz build -O || exit 1
bin_dir=target/$(rustc -vV | sed -n 's/^host: //p')/release
targets=${FUZZ_TARGETS:-$(cargo fuzz list)}
mkdir -p logs
summary=()
failed=0
for t in $targets; do
    mkdir -p "corpus/$t" "artifacts/$t"
    [ -d "seeds/$t" ] && cp -n seeds/"$t"/* "corpus/$t/" 2>/dev/null
    if [ "$t" = scenario ]; then
        for f in "$root"/scenarios/*.toml "$root"/env/scenarios/*.toml; do
            cp -n "$f" "corpus/$t/$(basename "$(dirname "$f")")_$(basename "$f")"
        done
    fi
    before=$(ls "artifacts/$t" | wc -l)
    log="logs/$t.log"
    start=$(date +%s.%N)
    # -rss_limit_mb: a scenario may validly hold a few hundred MB of fields; one worker (2-core CI).
    # The binary built above, run directly: `cargo fuzz run` would rebuild whatever changed since.
    "$bin_dir/$t" "corpus/$t" -artifact_prefix="artifacts/$t/" -runs="$runs" -max_total_time="$seconds" \
        -timeout=20 -rss_limit_mb=4096 -max_len=65536 -print_final_stats=1 >"$log" 2>&1
    rc=$?
    secs=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
    crashes=$(( $(ls "artifacts/$t" | wc -l) - before ))
    [ "$rc" -ne 0 ] && failed=1
    summary+=("$(printf '%-16s %10s execs %8.1f s  %s crash(es)  exit %s  (%s)' "$t" "${execs:-?}" "$secs" "$crashes" "$rc" "$log")")
done
echo
echo "cargo fuzz, $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, runs=$runs, max $seconds s each:"
printf '%s\n' "${summary[@]}"
exit $failed
