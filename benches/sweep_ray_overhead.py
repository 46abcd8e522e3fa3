#!/usr/bin/env python3
"""Ray's overhead per run against the local backend, same machine, same sweep: a case-II sweep of N runs
(30 s each, scenarios/case2_alarm.toml) run by `colcos.sweep.run(backend="local")` on all cores, then on a
local Ray cluster of as many CPUs (started here, not counted) twice, then local again; the overhead is Ray's wall
time over the mean of the two local ones, minus one, for the first Ray sweep (which also starts Ray's
worker processes) and the second. Needs ray and pandas (the rllib venv of
python-tests/run.sh).

Usage: python3 benches/sweep_ray_overhead.py [--runs 1000] [--cpus N]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import ray

import colcos.sweep

REPO = Path(__file__).resolve().parent.parent


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=1000)
    ap.add_argument("--cpus", type=int, default=os.cpu_count())
    a = ap.parse_args()
    spec = {
        "name": "ray_overhead",
        "scenario": str(REPO / "scenarios" / "case2_alarm.toml"),
        "duration": 30.0,
        "seeds": a.runs,
        "metrics": ["s_mean", "s_final", "s_halve_time", "nn_distance"],
    }
    ray.init(num_cpus=a.cpus, include_dashboard=False, log_to_driver=False)
    with tempfile.TemporaryDirectory() as tmp:
        walls = {}
        # The first Ray sweep also starts the worker processes (Python and the package imported, once
        # per CPU): timed apart as "ray (cold)"; the sweeps after it find them running.
        for k, backend in enumerate(["local", "ray (cold)", "ray", "local"]):
            t0 = time.perf_counter()
            kind = backend.split()[0]
            colcos.sweep.run(spec, backend=kind, out=Path(tmp) / str(k), threads=None if kind == "local" else 1)
            walls.setdefault(backend, []).append(time.perf_counter() - t0)
    ray.shutdown()
    local = sum(walls["local"]) / len(walls["local"])
    for name in ("ray (cold)", "ray"):
        on_ray = walls[name][0]
        print(
            f"{a.runs} runs on {a.cpus} CPUs: local {', '.join(f'{w:.2f}' for w in walls['local'])} s, "
            f"{name} {on_ray:.2f} s: overhead {100 * (on_ray / local - 1):+.1f} % "
            f"({(on_ray - local) / a.runs * 1e3:+.2f} ms a run)"
        )


if __name__ == "__main__":
    main()
