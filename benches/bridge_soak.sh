#!/usr/bin/env bash
# Soak test of the live loop: `colcos twin` plays a hundred robots (scenarios/rig_100.toml: three
# grid pheromones on the 4K panel), `colcos bridge` drives them over loopback (SwarmCon TCP poses in,
# UDP radio frames out, the twin reading its colours from the bridge's frame stream) for a set time,
# then the bridge's summary.json gives the loop's ticks, overruns and its worst and 99th-percentile
# tick. Not in CI (ten minutes by default).
#
#   bash benches/bridge_soak.sh [--duration S] [--scenario FILE] [--out DIR] [--port-base P]
#                               [--bridge-args "ARGS"]   (e.g. "--frame-width 1920 --frame-rate 50")
#
# Uses target/release/colcos (built with `cargo build --release` if missing). The bridge serves the
# twin its frames at its defaults (960 px, 25 Hz); the LCD window (--display) is not part of the soak.
set -euo pipefail
cd "$(dirname "$0")/.."

duration=600
scenario=scenarios/rig_100.toml
out=runs/bridge_soak
port=7660
bridge_args=""
while [ $# -gt 0 ]; do
    case "$1" in
        --duration) duration="$2"; shift 2 ;;
        --scenario) scenario="$2"; shift 2 ;;
        --out) out="$2"; shift 2 ;;
        --port-base) port="$2"; shift 2 ;;
        --bridge-args) bridge_args="$2"; shift 2 ;;
        -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
        *) echo "bridge_soak.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
    esac
done
case "$duration" in
    ''|*[!0-9.]*) echo "bridge_soak.sh: --duration must be a number of seconds, got '$duration'" >&2; exit 2 ;;
esac
case "$port" in
    ''|*[!0-9]*) echo "bridge_soak.sh: --port-base must be a port number, got '$port'" >&2; exit 2 ;;
esac
[ -f "$scenario" ] || { echo "bridge_soak.sh: no scenario file '$scenario'" >&2; exit 2; }

bin=target/release/colcos
[ -x "$bin" ] || cargo build --release --bin colcos
mkdir -p "$out"
tracker="127.0.0.1:$port"
robots="udp://127.0.0.1:$((port + 1))"
frames="127.0.0.1:$((port + 2))"

# The twin outlives the bridge by a margin, and is stopped when the bridge is done.
"$bin" twin "$scenario" --tracker "$tracker" --robots "$robots" --frames "$frames" \
    --duration "$(python3 -c "print($duration + 30)")" > "$out/twin.log" 2>&1 &
twin=$!
trap 'kill "$twin" 2>/dev/null || true' EXIT
# It prints its tracker address once it serves.
for _ in $(seq 100); do
    grep -qs '^tracker: ' "$out/twin.log" && break
    kill -0 "$twin" 2>/dev/null || { echo "the twin exited:" >&2; cat "$out/twin.log" >&2; exit 1; }
    sleep 0.2
done
grep -q '^tracker: ' "$out/twin.log" || { echo "the twin did not start:" >&2; cat "$out/twin.log" >&2; exit 1; }

started=$(date -u +%Y-%m-%dT%H:%M:%SZ)
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
"$bin" bridge "$scenario" --tracker "swarmcon://$tracker" --robots "$robots" --frames "$frames" \
    --duration "$duration" --quiet --out "$out/bridge" $bridge_args > "$out/bridge.log" 2>&1 \
    || { echo "the bridge failed:" >&2; tail -20 "$out/bridge.log" >&2; exit 1; }
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
kill "$twin" 2>/dev/null || true
wait "$twin" 2>/dev/null || true

cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')
python3 - "$out/bridge/summary.json" "$scenario" "$duration" "$started" "$cpu" "$(nproc)" \
    "$load_before" "$load_after" <<'EOF'
import json, sys
path, scenario, duration, started, cpu, cores, before, after = sys.argv[1:]
s = json.load(open(path))
ticks = s["ticks"]
print(f"bridge soak: {scenario}, {float(duration):g} s from {started}, {cpu} ({cores} cores)")
print(f"  load average before {before}, after {after}")
print(f"  ticks {ticks} in {s['seconds']:.1f} s ({ticks / max(s['seconds'], 1e-9):.2f} Hz)")
print(f"  overruns {s['overruns']} ({100 * s['overruns'] / max(ticks, 1):.3f}% of ticks)")
print(f"  tick work: worst {s['worst_tick_ms']:.2f} ms, 99th percentile {s['p99_tick_ms']:.2f} ms (budget 20 ms)")
print(f"  commands sent {s['commands_sent']}, pose blocks {s['pose_blocks']}, stops {len(s['stops'])}, "
      f"silent robots {len(s['silent_robots'])}")
EOF
