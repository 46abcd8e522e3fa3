#!/usr/bin/env bash
# Throughput of `colcos sweep`: a 1,000-run case-II sweep (scenarios/case2_alarm.toml: a leader, three
# followers and a predator, 30 s of simulated time each) on all cores, against one run alone.
#   runs/s      = 1000 / wall time of the sweep (all cores)
#   one run     = wall time of a 50-run sweep on one thread / 50 (one run alone, start-up amortised)
#   efficiency  = (runs/s) x (one run) / cores   (1.0: every core busy with runs, nothing else)
# Usage: bash benches/sweep_throughput.sh [cores]   (cores: default nproc; the sweep uses that many threads)
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cores="${1:-$(nproc)}"
cd "$repo"
cargo build --release --quiet
bin="$repo/target/release/colcos"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
sweep() { # seeds file
    cat > "$2" <<TOML
name = "bench"
scenario = "$repo/scenarios/case2_alarm.toml"
duration = 30.0
seeds = $1
metrics = ["s_mean", "s_final", "s_halve_time", "nn_distance"]
TOML
}
now() { date +%s.%N; }
sweep 50 "$work/one.toml"
sweep 1000 "$work/many.toml"
t0=$(now); "$bin" sweep "$work/one.toml" --out "$work/one" --threads 1 --quiet > /dev/null; t1=$(now)
"$bin" sweep "$work/many.toml" --out "$work/many" --threads "$cores" --quiet > /dev/null; t2=$(now)
python3 - "$t0" "$t1" "$t2" "$cores" <<'PY'
import sys
t0, t1, t2, cores = map(float, sys.argv[1:5])
one = (t1 - t0) / 50
rate = 1000 / (t2 - t1)
print(f"one run alone: {one * 1000:.2f} ms; 1,000 runs on {cores:.0f} cores: {t2 - t1:.2f} s, "
      f"{rate:.1f} runs/s; parallel efficiency {rate * one / cores:.2f}")
PY
