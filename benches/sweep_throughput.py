#!/usr/bin/env python3
"""Throughput of `colcos sweep`: a 1,000-run case-II sweep (scenarios/case2_alarm.toml: a leader, three
followers and a predator, 30 s of simulated time each) on all cores, against one run alone.

  one run      wall time of a 50-run sweep on one thread / 50 (one run alone, start-up amortised)
  runs/s       1000 / wall time of the 1,000-run sweep on `cores` threads
  efficiency   (runs/s) x (one run) / cores: 1.0 when every core does runs and nothing else
  CPU per run  the parallel sweep's CPU time (user + sys) / 1000: equal to `one run` when running in
               parallel costs nothing extra. On a machine shared with other work the wall-clock
               efficiency falls while this does not, so both are printed, with the load average.
  floor        the machine's own scaling, measured in the same run: `cores` independent one-thread
               sweep processes of 1000 / cores runs each, started together. A VM whose cores share
               one physical core, or a machine busy with other work, caps this below 1; the sweep's
               efficiency over the floor's is what the runner itself loses.

Each measurement is repeated `--repeat` times, interleaved; medians are printed.

Usage: python3 benches/sweep_throughput.py [--cores N] [--repeat K] [--bin PATH]
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


def processes_at_once(cmds: list[list[str]]) -> float:
    """Wall time of child processes started together, s."""
    t0 = time.perf_counter()
    children = [subprocess.Popen(c, stdout=subprocess.DEVNULL) for c in cmds]
    for child in children:
        if child.wait() != 0:
            raise SystemExit(f"{child.args} failed")
    return time.perf_counter() - t0


def median(xs: list[float]) -> float:
    return sorted(xs)[len(xs) // 2]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cores", type=int, default=os.cpu_count())
    ap.add_argument("--repeat", type=int, default=3)
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
        share = 1000 // a.cores
        for k in range(a.cores):
            sweep_file(d / f"part{k}.toml", share)
        ones, walls, cpus, floors, loads = [], [], [], [], []
        for r in range(a.repeat):
            ones.append(timed(run + [str(d / f"one{r}"), str(d / "one.toml"), "--threads", "1"])[0] / 50)
            loads.append(os.getloadavg()[0])
            wall, cpu = timed(run + [str(d / f"many{r}"), str(d / "many.toml"), "--threads", str(a.cores)])
            walls.append(wall)
            cpus.append(cpu)
            parts = [run + [str(d / f"part{k}_{r}"), str(d / f"part{k}.toml"), "--threads", "1"] for k in range(a.cores)]
            floors.append(processes_at_once(parts) / (share * a.cores) * 1000)
    one_ms, wall, cpu_ms, floor = median(ones) * 1e3, median(walls), median(cpus), median(floors)
    rate = 1000 / wall
    efficiency = rate * one_ms / 1e3 / a.cores
    floor_efficiency = 1000 / floor * one_ms / 1e3 / a.cores
    print(
        f"one run alone: {one_ms:.2f} ms; 1,000 runs on {a.cores} threads: {wall:.2f} s, {rate:.1f} runs/s; "
        f"parallel efficiency {efficiency:.2f}; floor ({a.cores} independent processes) {floor_efficiency:.2f}; "
        f"sweep / floor {efficiency / floor_efficiency:.2f}; CPU per run {cpu_ms:.2f} ms "
        f"({one_ms / cpu_ms:.2f} x one run alone); load average {median(loads):.1f} (medians of {a.repeat})"
    )

if __name__ == "__main__":
    main()
