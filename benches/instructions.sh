#!/usr/bin/env bash
# Instructions per agent-step of the batched environment on one thread: callgrind
# counts every instruction of `throughput aggregation WORLDS STEPS - PHYSICS` (build and reset
# included, as the reference figures do), divided by the agent-steps (worlds x agents x steps), for the
# disc solver and rapier. Instruction counts do not depend on the machine's load, so this is the
# figure to compare commits by; wall time is in benches/wall_speed.sh.
#
#   bash benches/instructions.sh [--worlds N] [--steps N] [--bin PATH] [--keep DIR]
#
# Uses target/release/examples/throughput (built with `cargo build --release -p colcos-env --example
# throughput` if missing; --bin names another build, e.g. an older commit's). Needs valgrind. Takes
# about 20 s per solver at the defaults. --keep DIR keeps the callgrind files (callgrind_annotate
# FILE for the profile).
set -euo pipefail
cd "$(dirname "$0")/.."

worlds=128
steps=300
bin=target/release/examples/throughput
keep=""
while [ $# -gt 0 ]; do
    case "$1" in
        --worlds) worlds="$2"; shift 2 ;;
        --steps) steps="$2"; shift 2 ;;
        --bin) bin="$2"; shift 2 ;;
        --keep) keep="$2"; shift 2 ;;
        -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
        *) echo "instructions.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
    esac
done
command -v valgrind >/dev/null || { echo "instructions.sh: valgrind is not installed" >&2; exit 1; }
if [ ! -x "$bin" ]; then
    cargo build --release -p colcos-env --example throughput
fi
dir=${keep:-$(mktemp -d)}
mkdir -p "$dir"

# Instructions per agent-step before this work (488ea55, measured by this script on a 2-core x86 VM,
# 2026-11-27; fa963ea on a 16-core Xeon counted 9.4 k / 11.6 k) and the targets.
declare -A floor=([discs]=9529 [rapier]=11724)
declare -A bar=([discs]=3200 [rapier]=4000)

printf '%-7s %14s %12s %14s %10s %8s\n' physics instructions agent-steps "per agent-step" "vs before" "vs bar"
for physics in discs rapier; do
    out="$dir/callgrind.$physics.out"
    log=$(RAYON_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="$out" \
        "$bin" aggregation "$worlds" "$steps" - "$physics" 2>&1)
    total=$(grep -o 'Collected : [0-9]*' <<<"$log" | grep -o '[0-9]*$')
    agents=$(grep -o 'worlds x [0-9]* agents' <<<"$log" | grep -o '[0-9]* agents' | grep -o '[0-9]*')
    if [ -z "$total" ] || [ -z "$agents" ]; then
        echo "instructions.sh: no count for $physics:" >&2
        echo "$log" | tail -5 >&2
        exit 1
    fi
    agent_steps=$((worlds * agents * steps))
    awk -v p="$physics" -v t="$total" -v a="$agent_steps" -v f="${floor[$physics]}" -v b="${bar[$physics]}" \
        'BEGIN { per = t / a; printf "%-7s %14d %12d %14.0f %9.3fx %7.2fx\n", p, t, a, per, per / f, per / b }'
done
echo "(vs before: ratio to 9,529 discs / 11,724 rapier at 488ea55; vs target: to 3.2 k / 4.0 k; lower is better)"
[ -n "$keep" ] || rm -rf "$dir"
