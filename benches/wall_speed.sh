#!/usr/bin/env bash
# Wall-time (and CPU-time) agent-steps/s of two builds of `throughput` (an older commit's and this one's), run
# alternately so that both see the same load, for the disc solver and rapier; prints every run and
# the medians. The machine's own thread count unless RAYON_NUM_THREADS says otherwise.
#
#   bash benches/wall_speed.sh OLD_BIN NEW_BIN [--worlds N] [--steps N] [--runs N]
#
# Build an older commit in its own checkout and target directory (two checkouts must not share
# one), e.g.:
#   git worktree add ../base 488ea55
#   (cd ../base && CARGO_TARGET_DIR=../base-target cargo build --release -p colcos-env --example throughput)
#   bash benches/wall_speed.sh ../base-target/release/examples/throughput target/release/examples/throughput
set -euo pipefail
cd "$(dirname "$0")/.."

[ $# -ge 2 ] || { sed -n '2,12p' "$0"; exit 2; }
old="$1"
new="$2"
shift 2
worlds=1024
steps=300
runs=3
while [ $# -gt 0 ]; do
    case "$1" in
        --worlds) worlds="$2"; shift 2 ;;
        --steps) steps="$2"; shift 2 ;;
        --runs) runs="$2"; shift 2 ;;
        *) echo "wall_speed.sh: unknown argument '$1'" >&2; exit 2 ;;
    esac
done

# Agent-steps per second of wall time, and per second of CPU time (user + system, from
# /usr/bin/time): on a machine shared with other jobs the wall time scatters with their load, the CPU
# time much less.
cpu_file=$(mktemp)
trap 'rm -f "$cpu_file"' EXIT
rate() {
    local out
    out=$(/usr/bin/time -f '%U %S' -o "$cpu_file" "$1" aggregation "$worlds" "$steps" - "$2")
    local agents
    agents=$(grep -o 'worlds x [0-9]* agents' <<<"$out" | grep -o '[0-9]* agents' | grep -o '[0-9]*')
    local per_cpu
    per_cpu=$(awk -v n=$((worlds * agents * steps)) '{ printf "%.0f", n / ($1 + $2) }' "$cpu_file")
    echo "$(grep -o '[0-9]* agent-steps/s' <<<"$out" | grep -o '^[0-9]*')/$per_cpu"
}
median() { tr ' ' '\n' | grep . | sort -n | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "throughput aggregation $worlds $steps, $runs runs each, alternated; $(nproc) cores"
for physics in discs rapier; do
    o=""
    n=""
    for _ in $(seq "$runs"); do
        o="$o $(rate "$old" "$physics")"
        n="$n $(rate "$new" "$physics")"
    done
    echo "$physics old (wall/cpu):$o"
    echo "$physics new (wall/cpu):$n"
    for k in 1 2; do
        what=$([ $k = 1 ] && echo "agent-steps/s of wall time" || echo "agent-steps per CPU-second")
        mo=$(echo "$o" | tr ' ' '\n' | grep . | cut -d/ -f$k | tr '\n' ' ' | median)
        mn=$(echo "$n" | tr ' ' '\n' | grep . | cut -d/ -f$k | tr '\n' ' ' | median)
        awk -v p="$physics" -v w="$what" -v a="$mo" -v b="$mn" \
            'BEGIN { printf "%s median %s: old %.0f, new %.0f, new/old %.3f\n", p, w, a, b, b / a }'
    done
done
