"""What pheromone actions and tasks written in Python cost, side by side in one run, at 1,024 worlds.

    python benches/tasks_speed.py            # 1,024 worlds, 100 steps a repetition
    python benches/tasks_speed.py --quick    # fewer steps

Rows (agent-steps per second, median of 5 repetitions, the same random actions for every row):
- `trail`, its agents' red trail a scripted `deposits` rule (the built-in task);
- `trail`, the same trail as `deposit_actions` laid at a constant half of twice the rate: the same
  deposits, chosen by the agents; the ratio to the row above is the pheromone actions' cost
  (target: at most 10 % slower);
- every built-in task written in Python (`examples/tasks/`: `trail`, `foraging`, `aggregation`,
  `colony`, `coverage`, `alarm`), each right after the Rust task (target: at least 50 % of the
  Rust task's agent-steps/s).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import pathlib
import statistics
import sys
import time

import numpy as np

import colcos

REPS = 5
TASKS = ("trail", "foraging", "aggregation", "colony", "coverage", "alarm")
ROOT = pathlib.Path(__file__).resolve().parents[1]
SCRIPTED = 'deposits = [{ pheromone = "red", kernel = { shape = "disc", radius = 0.008 }, rate = 3.0 }]'
CHOSEN = 'deposit_actions = [{ pheromone = "red", kernel = { shape = "disc", radius = 0.008 }, max_rate = 6.0 }]'


def _example(name: str, cls: str) -> colcos.Task:
    sys.path.insert(0, str(ROOT / "examples" / "tasks"))  # for their shared `_common`
    spec = importlib.util.spec_from_file_location(f"bench_{name}", ROOT / "examples" / "tasks" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return getattr(module, cls)()


def rate(task: str | colcos.Task, worlds: int, steps: int, scenario: str | None = None, lay: float | None = None) -> float:
    env = colcos.vector.VecEnv(task, num_envs=worlds, max_cycles=500, scenario=scenario)
    rng = np.random.default_rng(0)
    width = env.single_action_space.shape[0]
    pool = []
    for _ in range(8):
        a = np.empty((worlds, env.num_agents, width), np.float32)
        a[..., :2] = rng.uniform(-1, 1, (worlds, env.num_agents, 2))
        if lay is not None:
            a[..., 2:] = lay
        pool.append(a)
    env.reset(seed=0)
    for a in pool:  # warm-up
        env.step(a)
    rates = []
    for _ in range(REPS):
        t = time.perf_counter()
        for k in range(steps):
            env.step(pool[k % 8])
        rates.append(steps * worlds * env.num_agents / (time.perf_counter() - t))
    return statistics.median(rates)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--worlds", type=int, default=1024)
    args = p.parse_args()
    steps = 25 if args.quick else 100
    e = args.worlds
    trail = colcos.default_scenario("trail")
    assert SCRIPTED in trail, "the trail scenario changed: update the bench"
    print(f"cores: {os.cpu_count()}, python {sys.version.split()[0]}, {e} worlds, {steps} steps x {REPS}")
    rows = {
        "trail, scripted deposits": rate("trail", e, steps),
        "trail, deposit actions": rate("trail", e, steps, scenario=trail.replace(SCRIPTED, CHOSEN), lay=0.5),
    }
    for task in TASKS:
        rows[f"{task} (Rust)"] = rate(task, e, steps, lay=0.5)
        rows[f"{task} (Python task)"] = rate(_example(task, task.capitalize()), e, steps, lay=0.5)
    print("\n| setup | agent-steps/s |")
    print("| --- | ---: |")
    for name, r in rows.items():
        print(f"| {name} | {r:,.0f} |")
    cost = 1.0 - rows["trail, deposit actions"] / rows["trail, scripted deposits"]
    print(f"\npheromone actions' cost: {100 * cost:.1f} % of a batched trail step (target <= 10 %)")
    for task in TASKS:
        ratio = rows[f"{task} (Python task)"] / rows[f"{task} (Rust)"]
        print(f"{task} written in Python: {ratio:.2f}x the Rust task's agent-steps/s (target >= 0.50)")


if __name__ == "__main__":
    main()
