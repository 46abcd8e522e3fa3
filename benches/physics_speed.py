"""rapier against the disc solver, side by side in one run: the batched `aggregation` task at 32 and
1,024 worlds (agent-steps/s, random actions) and the 10,000-robot swarm step (ms), repeated, medians
and ratios printed against the speed bars.

    cargo build --release -p colcos-env --example throughput
    cargo build --release --example profile_swarm
    python3 benches/physics_speed.py [--reps 5] [--steps 300]

Runs are interleaved (rapier, discs, rapier, ...) so that load from elsewhere on a shared machine falls
on both solvers alike; the medians of the repeats are reported.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
THROUGHPUT = os.path.join(ROOT, "target", "release", "examples", "throughput")
PROFILE = os.path.join(ROOT, "target", "release", "examples", "profile_swarm")
TARGET_BATCHED = 1_000_000  # agent-steps/s, rapier, 1,024 worlds, 2 cores
TARGET_RATIO = 1.5  # rapier at most this much slower than the disc solver
TARGET_SWARM_MS = 6.7  # 10,000 robots: 3x real time at dt = 20 ms


def batched(worlds: int, steps: int, physics: str) -> float:
    out = subprocess.run(
        [THROUGHPUT, "aggregation", str(worlds), str(steps), "-", physics],
        cwd=os.path.join(ROOT, "env"),
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    m = re.search(r"\): (\d+) agent-steps/s", out)
    if not m:
        sys.exit(f"unexpected throughput output: {out!r}")
    return float(m.group(1))


def swarm(steps: int) -> dict[str, float]:
    out = subprocess.run(
        [PROFILE, "bench: 10,000"],
        cwd=ROOT,
        check=True,
        capture_output=True,
        text=True,
        env={**os.environ, "PROFILE_STEPS": str(steps)},
    ).stdout
    found = dict(re.findall(r"bench: 10,000 robots, (\w+)\s+([\d.]+) ms wall", out))
    if set(found) != {"rapier", "discs"}:
        sys.exit(f"unexpected profile_swarm output: {out!r}")
    return {k: float(v) for k, v in found.items()}


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument(
        "--steps",
        type=int,
        default=300,
        help="steps per batched run at 1,024 worlds (x32 at 32 worlds)",
    )
    ap.add_argument("--swarm-steps", type=int, default=40)
    args = ap.parse_args()
    for exe in (THROUGHPUT, PROFILE):
        if not os.path.exists(exe):
            sys.exit(f"{exe} is missing: build it first (see the docstring)")

    rates: dict[tuple[int, str], list[float]] = {}
    swarm_ms: dict[str, list[float]] = {"rapier": [], "discs": []}
    for rep in range(args.reps):
        for worlds, steps in ((32, args.steps * 32), (1024, args.steps)):
            for physics in ("rapier", "discs"):
                rates.setdefault((worlds, physics), []).append(
                    batched(worlds, steps, physics)
                )
        for k, v in swarm(args.swarm_steps).items():
            swarm_ms[k].append(v)
        print(f"rep {rep + 1}/{args.reps} done", file=sys.stderr)

    med = {k: statistics.median(v) for k, v in rates.items()}
    print(
        f"\n| aggregation, agent-steps/s (median of {args.reps}) | rapier | discs | discs / rapier |"
    )
    print("| --- | --- | --- | --- |")
    for worlds in (32, 1024):
        r, d = med[(worlds, "rapier")], med[(worlds, "discs")]
        print(f"| {worlds:,} worlds | {r:,.0f} | {d:,.0f} | {d / r:.2f} |")
    s_r, s_d = (
        statistics.median(swarm_ms["rapier"]),
        statistics.median(swarm_ms["discs"]),
    )
    print(
        f"\n| 10,000 robots, ms a step (median of {args.reps}) | rapier | discs | rapier / discs |"
    )
    print("| --- | --- | --- | --- |")
    print(
        f"| whole step (dt 20 ms) | {s_r:.2f} ({20 / s_r:.2f}x real time) | {s_d:.2f} ({20 / s_d:.2f}x) | {s_r / s_d:.2f} |"
    )

    # The ratios of each repeat's back-to-back runs, then their median: steadier than a ratio of
    # medians when the machine changes speed between repeats.
    def paired(a: list[float], b: list[float]) -> float:
        return statistics.median(x / y for x, y in zip(a, b))

    ratio_1024 = paired(rates[(1024, "discs")], rates[(1024, "rapier")])
    ratio_swarm = paired(swarm_ms["rapier"], swarm_ms["discs"])
    ratio_worlds = paired(rates[(1024, "discs")], rates[(32, "discs")])
    r1024 = med[(1024, "rapier")]
    print("\nbars:")
    print(
        f"  rapier, 1,024 worlds >= {TARGET_BATCHED:,} agent-steps/s: {r1024:,.0f} ({r1024 / TARGET_BATCHED:.2f}x): {verdict(r1024 >= TARGET_BATCHED)}"
    )
    print(
        f"  rapier within {TARGET_RATIO}x of discs at 1,024 worlds (median of the repeats' ratios): {ratio_1024:.2f}x: {verdict(ratio_1024 <= TARGET_RATIO)}"
    )
    print(
        f"  discs at 1,024 worlds at least as fast as at 32 (same): {ratio_worlds:.2f}x: {verdict(ratio_worlds >= 1.0)}"
    )
    print(
        f"  10,000 robots on rapier <= {TARGET_SWARM_MS} ms a step: {s_r:.2f} ms: {verdict(s_r <= TARGET_SWARM_MS)}"
    )
    print(
        f"  10,000 robots on rapier within {TARGET_RATIO}x of discs (same): {ratio_swarm:.2f}x: {verdict(ratio_swarm <= TARGET_RATIO)}"
    )


if __name__ == "__main__":
    main()
