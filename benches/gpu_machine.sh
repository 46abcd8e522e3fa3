#!/usr/bin/env bash
# Everything a GPU machine should measure, in one go (a few minutes once built; no network needed):
#   1. the GPU field bench (`gpu/benches/gpu_field.rs`): 4K x 3 pheromones and a 1,024-world batch,
#      GPU against the CPU backend;
#   2. the vector env (`env/benches/gpu_vec_env.rs`), task `trail`, at 1,024 / 4,096 / 16,384 worlds:
#      the CPU backend on 1 thread and on every core, the resident GPU batch (`backend = "gpu"`), every
#      GPU/CPU ratio, and what `auto` picks at each size;
#   3. VMAS (navigation, 4 agents) on the GPU at 1,024 / 16,384 / 65,536 worlds, only where
#      `import vmas, torch` works (VMAS is pure Python: its wheel and gym's can be installed offline).
#
#   bash benches/gpu_machine.sh [--worlds 1024,4096,16384] [--vmas-worlds 1024,16384,65536]
#                               [--steps 20] [--no-build] [--bin DIR]
#
# Builds with `cargo bench --no-run --offline` first (skipped by --no-build, e.g. with a target/
# copied from a machine with network; --bin DIR takes the two bench binaries from DIR instead, for a
# machine without Rust); the figures go to stdout and to target/gpu_machine.txt.
set -euo pipefail
cd "$(dirname "$0")/.."

worlds=1024,4096,16384
vmas_worlds=1024,16384,65536
steps=20
build=1
bin_dir=
while [ $# -gt 0 ]; do
    case "$1" in
        --worlds) worlds="$2"; shift 2 ;;
        --vmas-worlds) vmas_worlds="$2"; shift 2 ;;
        --steps) steps="$2"; shift 2 ;;
        --no-build) build=0; shift ;;
        --bin) bin_dir="$2"; build=0; shift 2 ;;
        *) echo "gpu_machine.sh: unknown argument '$1'" >&2; exit 2 ;;
    esac
done
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
mkdir -p target
out=target/gpu_machine.txt

# The newest bench binary of a name (cargo names them `<name>-<hash>`).
bench_bin() {
    ls -t "${bin_dir:-target/release/deps}"/"$1"-* 2>/dev/null | grep -v '\.d$' | head -1
}

{
    echo "== $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, $(uname -m)"
    command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader || true
    if [ "$build" = 1 ]; then
        cargo bench --offline -p colcos-gpu --bench gpu_field --no-run 2>&1 | tail -2
        cargo bench --offline -p colcos-env --features gpu --bench gpu_vec_env --no-run 2>&1 | tail -2
    fi
    field=$(bench_bin gpu_field)
    vec=$(bench_bin gpu_vec_env)
    [ -x "$field" ] && [ -x "$vec" ] || { echo "bench binaries missing: build them (drop --no-build)"; exit 1; }

    echo "== GPU field bench ($field)"
    # Each part reports its failure and the script goes on to the next.
    time "$field" --bench || echo "the GPU field bench failed (exit $?)"

    echo "== vector env, task trail: CPU backend (1 thread, all cores) and the GPU batch, $steps steps a figure"
    time COLCOS_BENCH_WORLDS="$worlds" COLCOS_BENCH_THREADS=1,all COLCOS_BENCH_STEPS="$steps" "$vec" --bench ||
        echo "the vector env bench failed (exit $?)"

    if python3 -c 'import vmas, torch' 2>/dev/null; then
        echo "== VMAS navigation, 4 agents, random actions"
        python3 - "$vmas_worlds" "$steps" <<'EOF' || echo "the VMAS part failed"
import sys, time
import torch, vmas
device = "cuda" if torch.cuda.is_available() else "cpu"
for n in [int(w) for w in sys.argv[1].split(",")]:
    env = vmas.make_env(scenario="navigation", num_envs=n, device=device, continuous_actions=True, n_agents=4, seed=0)
    env.reset()
    acts = [torch.rand(n, env.get_agent_action_size(a), device=device) * 2 - 1 for a in env.agents]
    for _ in range(3):
        env.step(acts)
    steps = int(sys.argv[2])
    if device == "cuda":
        torch.cuda.synchronize()
    t = time.perf_counter()
    for _ in range(steps):
        env.step(acts)
    if device == "cuda":
        torch.cuda.synchronize()
    rate = steps * n * len(env.agents) / (time.perf_counter() - t)
    print(f"{n:>6} worlds  VMAS navigation ({device})          {rate:>12.0f} agent-steps/s")
EOF
    else
        echo "== VMAS: not importable here, no VMAS rows"
    fi
} 2>&1 | tee "$out"
