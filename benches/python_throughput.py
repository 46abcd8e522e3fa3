"""colcos against its peers, side by side in one run: agent-steps per second with random actions.

    python benches/python_throughput.py            # everything (needs vmas, mpe2, torch)
    python benches/python_throughput.py --quick    # fewer steps
    python benches/python_throughput.py --python-task   # only the Rust / Python aggregation pair

Rows: colcos batched core (aggregation with 4 learning followers + leader + predator per world, the
task's scenario with one more follower, so 4 agents as in VMAS's rows) at 1 / 32 / 1,024 worlds with
rapier (the default contact solver) and at 32 / 1,024 worlds with the disc solver; colcos
parallel_env through the PettingZoo dict API (same scenario); the same 1,024 worlds with the task
written in Python (`examples/tasks/aggregation.py`, same scenario), right after the Rust task's row,
and its ratio to it (target >= 0.5; the two taken in turn, medians of 7 each); VMAS navigation and
dispersion (4 agents, CPU torch) at 1 / 32 / 1,024 worlds; mpe2 simple_spread_v3 at 3 and 50 agents.
Random actions are drawn before timing from a small pool, identically for every library, so the
figures measure the environments. Each figure is the median of 3 repetitions.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Callable

import numpy as np

REPS = 3
PAIRED_REPS = 7  # the Rust / Python task pair: repetitions of each, in turn
TARGET_BATCHED = 1_000_000  # agent-steps/s, 1,024 worlds, 2 cores
TARGET_DICT = 100_000
TARGET_PYTHON_TASK = 0.5  # the Python task's agent-steps/s over the Rust task's, same run
PYTHON_TASK = "colcos VecEnv (rapier), Python task"

# The aggregation task's own scenario with four learning followers instead of three.
_SCENARIO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "env", "scenarios", "aggregation.toml")
with open(_SCENARIO) as f:
    FOUR_AGENTS = f.read().replace('count = 3\nrole = "follower"', 'count = 4\nrole = "follower"')
assert 'count = 4\nrole = "follower"' in FOUR_AGENTS, "aggregation.toml changed: update the bench"


def median_rate(run: Callable[[], tuple[int, float]]) -> float:
    rates = []
    for _ in range(REPS):
        agent_steps, secs = run()
        rates.append(agent_steps / secs)
    return statistics.median(rates)


def python_aggregation() -> object:
    """The `aggregation` task written in Python (examples/tasks/aggregation.py)."""
    import importlib.util

    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "tasks", "aggregation.py")
    sys.path.insert(0, os.path.dirname(path))  # for the examples' shared `_common`
    spec = importlib.util.spec_from_file_location("bench_aggregation", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.Aggregation()


def colcos_runner(
    num_envs: int, steps: int, threads: int | None, physics: str, task: object = "aggregation"
) -> Callable[[], tuple[int, float]]:
    """A warmed-up batch of `task` and one repetition of `steps` steps of it."""
    from colcos.vector import VecEnv

    v = VecEnv(task, num_envs=num_envs, num_threads=threads, max_cycles=500, scenario=FOUR_AGENTS, physics=physics)
    rng = np.random.default_rng(0)
    pool = [rng.uniform(-1, 1, (num_envs, v.num_agents, 2)).astype(np.float32) for _ in range(8)]
    v.reset(seed=0)
    for a in pool:  # warm-up
        v.step(a)

    def run() -> tuple[int, float]:
        t = time.perf_counter()
        for k in range(steps):
            v.step(pool[k % 8])
        return steps * num_envs * v.num_agents, time.perf_counter() - t

    return run


def colcos_batched(num_envs: int, steps: int, threads: int | None, physics: str) -> float:
    return median_rate(colcos_runner(num_envs, steps, threads, physics))


def rust_and_python_task(num_envs: int, steps: int, threads: int | None) -> tuple[float, float]:
    """The Rust `aggregation` and its Python re-write, repetitions taken in turn (so that a busy
    spell of a shared machine weighs on both): their median rates."""
    runs = [colcos_runner(num_envs, steps, threads, "rapier", task) for task in ("aggregation", python_aggregation())]
    rates: list[list[float]] = [[], []]
    for _ in range(PAIRED_REPS):
        for run, out in zip(runs, rates, strict=True):
            n, secs = run()
            out.append(n / secs)
    return statistics.median(rates[0]), statistics.median(rates[1])


def pettingzoo_dict(make: Callable[[], object], steps: int) -> float:
    env = make()
    env.reset(seed=0)
    agents = list(env.possible_agents)
    rng = np.random.default_rng(0)
    pool = []
    for _ in range(16):
        acts = {}
        for a in agents:
            space = env.action_space(a)
            space.seed(int(rng.integers(1 << 30)))
            acts[a] = space.sample()
        pool.append(acts)

    def run() -> tuple[int, float]:
        env.reset(seed=0)
        n = 0
        t = time.perf_counter()
        for k in range(steps):
            live = env.agents
            if not live:
                env.reset()
                live = env.agents
            acts = pool[k % 16]
            env.step({a: acts[a] for a in live})
            n += len(live)
        return n, time.perf_counter() - t

    return median_rate(run)


def vmas_rate(scenario: str, num_envs: int, steps: int) -> float:
    import torch
    import vmas

    env = vmas.make_env(scenario=scenario, num_envs=num_envs, device="cpu", continuous_actions=True, n_agents=4, seed=0)
    env.reset()
    g = torch.Generator().manual_seed(0)
    pool = [[torch.rand(num_envs, env.get_agent_action_size(a), generator=g) * 2 - 1 for a in env.agents] for _ in range(8)]

    def run() -> tuple[int, float]:
        t = time.perf_counter()
        for k in range(steps):
            env.step(pool[k % 8])
        return steps * num_envs * len(env.agents), time.perf_counter() - t

    return median_rate(run)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--threads", type=int, default=None, help="colcos worker threads (default: all cores)")
    p.add_argument("--python-task", action="store_true", help="only the Rust / Python aggregation rows")
    args = p.parse_args()
    scale = 0.25 if args.quick else 1.0
    s = lambda n: max(10, int(n * scale))  # noqa: E731
    rows: list[tuple[str, str, float | None]] = []

    def rate(lib: str, setup: str) -> float | None:
        return next((r for l_, s_, r in rows if l_ == lib and s_ == setup), None)

    def add(lib: str, setup: str, fn: Callable[[], float]) -> None:
        try:
            rate = fn()
        except Exception as e:  # a peer that is not installed is reported, not fatal
            print(f"  {lib} {setup}: skipped ({type(e).__name__}: {e})", file=sys.stderr)
            rate = None
        rows.append((lib, setup, rate))
        print(f"  {lib:<28} {setup:<34} {rate if rate is None else f'{rate:>14,.0f}'}", flush=True)

    print(f"cores: {os.cpu_count()}, python {sys.version.split()[0]}")
    import colcos

    def python_task_ratio() -> None:
        rust = rate("colcos VecEnv (rapier)", "aggregation, 4 agents, 1024 worlds")
        py = rate(PYTHON_TASK, "aggregation, 4 agents, 1024 worlds")
        if rust and py:
            verdict = "met" if py / rust >= TARGET_PYTHON_TASK else "NOT met"
            print(f"aggregation written in Python: {py / rust:.2f}x the Rust task's agent-steps/s at 1,024 worlds, "
                  f"target >= {TARGET_PYTHON_TASK}: {verdict}")

    every = [(1, 4000), (32, 1000), (1024, 100)]
    for physics, sizes in (("rapier", every), ("discs", [(32, 1000), (1024, 100)])):
        for e, n in sizes:
            if args.python_task and (physics, e) != ("rapier", 1024):
                continue
            setup = f"aggregation, 4 agents, {e} worlds"
            if (physics, e) != ("rapier", 1024):
                add(f"colcos VecEnv ({physics})", setup, lambda e=e, n=n, ph=physics: colcos_batched(e, s(n), args.threads, ph))
                continue
            rust_rate, python_rate = rust_and_python_task(e, s(n), args.threads)
            add(f"colcos VecEnv ({physics})", setup, lambda r=rust_rate: r)
            add(PYTHON_TASK, setup, lambda r=python_rate: r)
    if args.python_task:
        python_task_ratio()
        return
    add(
        "colcos parallel_env (dict)",
        "aggregation, 4 agents",
        lambda: pettingzoo_dict(lambda: colcos.parallel_env(task="aggregation", max_cycles=500, scenario=FOUR_AGENTS), s(4000)),
    )
    for scen in ("navigation", "dispersion"):
        for e, n in [(1, 300), (32, 300), (1024, 100)]:
            add(f"VMAS {scen}", f"4 agents, {e} worlds", lambda scen=scen, e=e, n=n: vmas_rate(scen, e, s(n)))
    for agents, n in [(3, 2000), (50, 100)]:

        def mpe(agents: int = agents, n: int = n) -> float:
            from mpe2 import simple_spread_v3

            return pettingzoo_dict(lambda: simple_spread_v3.parallel_env(N=agents, max_cycles=25), s(n))

        add("mpe2 simple_spread_v3", f"{agents} agents (parallel dict API)", mpe)

    print("\n| library | setup | agent-steps/s |")
    print("| --- | --- | ---: |")
    for lib, setup, r in rows:
        print(f"| {lib} | {setup} | {'n/a' if r is None else f'{r:,.0f}'} |")
    def against_target(name: str, ours: float | None, target: int) -> None:
        if ours:
            verdict = "met" if ours >= target else "NOT met"
            print(f"colcos {name}: {ours:,.0f} agent-steps/s, target {target:,}: {verdict} ({ours / target:.2f}x)")

    ours_dict = rate("colcos parallel_env (dict)", "aggregation, 4 agents")
    for physics in ("rapier", "discs"):
        ours = rate(f"colcos VecEnv ({physics})", "aggregation, 4 agents, 1024 worlds")
        against_target(f"batched ({physics}), 1,024 worlds", ours, TARGET_BATCHED)
    against_target("parallel_env dict", ours_dict, TARGET_DICT)
    python_task_ratio()
    print("\nratios (colcos / peer, same number of worlds):")
    for lib, setup, r in rows:
        if r is None or lib.startswith("colcos"):
            continue
        if lib.startswith("mpe2"):
            if ours_dict:
                print(f"  parallel_env vs {lib}, {setup}: {ours_dict / r:6.2f}x")
            continue
        worlds = setup.split(", ")[-1]
        for physics in ("rapier", "discs"):
            ours = rate(f"colcos VecEnv ({physics})", f"aggregation, 4 agents, {worlds}")
            if ours:
                print(f"  {physics} vs {lib}, {setup}: {ours / r:6.2f}x")


if __name__ == "__main__":
    main()
