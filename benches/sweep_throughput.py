#!/usr/bin/env python3
"""Throughput of `colcos sweep`: a 1,000-run case-II sweep (scenarios/case2_alarm.toml: a leader, three
followers and a predator, 30 s of simulated time each) on all cores, against one run alone.

  one run      wall time of a 50-run sweep on one thread / 50 (one run alone, start-up amortised)
  runs/s       1000 / wall time of the 1,000-run sweep on `cores` threads
  efficiency   (runs/s) x (one run) / cores: 1.0 when every core does runs and nothing else
  CPU per run  the parallel sweep's CPU time (user + sys) / 1000: equal to `one run` when running in
               parallel costs nothing extra. On a machine shared with other work the wall-clock
               efficiency falls while this does not, so both are printed, with the load average.

Usage: python3 benches/sweep_throughput.py [--cores N] [--bin PATH]
(default: all cores, and target/release/colcos built first)
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def sweep_file(path: Path, seeds: int) -> None:
    base = REPO / "scenarios" / "case2_alarm.toml"
    path.write_text(
        f'name = "bench"\nscenario = "{base}"\nduration = 30.0\nseeds = {seeds}\n'
        'metrics = ["s_mean", "s_final", "s_halve_time", "nn_distance"]\n'
    )


def timed(cmd: list[str]) -> tuple[float, float]:
    """Wall time and CPU time (user + sys) of a child process, s."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cores", type=int, default=os.cpu_count())
    ap.add_argument("--bin", default=None, help="a colcos binary (default: build target/release/colcos)")
    a = ap.parse_args()
    binary = a.bin
    if binary is None:
        subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=REPO, check=True)
        binary = str(REPO / "target" / "release" / "colcos")
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        sweep_file(d / "one.toml", 50)
        sweep_file(d / "many.toml", 1000)
        run = [binary, "sweep", "--quiet", "--out"]
        one_wall, _ = timed(run + [str(d / "one"), str(d / "one.toml"), "--threads", "1"])
        load0 = os.getloadavg()[0]
        wall, cpu = timed(run + [str(d / "many"), str(d / "many.toml"), "--threads", str(a.cores)])
        load1 = os.getloadavg()[0]
    one_ms = one_wall / 50 * 1e3
    cpu_ms = cpu / 1000 * 1e3
    rate = 1000 / wall
    print(
        f"one run alone: {one_ms:.2f} ms; 1,000 runs on {a.cores} threads: {wall:.2f} s, {rate:.1f} runs/s; "
        f"parallel efficiency {rate * one_ms / 1e3 / a.cores:.2f}; CPU per run {cpu_ms:.2f} ms "
        f"({one_ms / cpu_ms:.2f} x one run alone); load average {load0:.1f} -> {load1:.1f}"
    )


if __name__ == "__main__":
    main()
