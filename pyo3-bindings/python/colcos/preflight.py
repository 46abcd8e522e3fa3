"""Pre-flight check: a policy runs a few episodes on the digital twin (with the scenario's calibration
and latency) before it may drive the real robots; it is refused, with the limit named, when the
safety shield had to step in too often, robots reached the arena's edge or ran into each other, or the
loop overran its ticks.

    from colcos.preflight import preflight
    report = preflight(policy, task="aggregation", episodes=3)   # raises PreflightError if refused
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

# tomllib is Python >= 3.11's; on 3.10 the package depends on tomli, the same parser.
if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

from colcos import _core
from colcos.pettingzoo_env import ColcosParallelEnv


class PreflightError(_core.StateError):
    """The policy broke a pre-flight limit; `.report` holds the measurements."""

    def __init__(self, message: str, report: PreflightReport) -> None:
        super().__init__(message)
        self.report = report


@dataclass
class PreflightLimits:
    """What a policy may do on the twin and still be let onto the rig (fractions of agent-steps or
    ticks, and counts)."""

    walled: float = 0.05
    """Agent-steps the shield turned from a virtual wall."""
    capped: float = 0.05
    """Agent-steps whose wheel speeds the shield capped."""
    boundary: int = 0
    """Steps with a robot's body past the arena's edge by more than `edge_tolerance` m (by its
    tracked pose)."""
    collisions: float = 0.02
    """Steps with two robots overlapping by more than `overlap` m (by their tracked poses)."""
    overruns: float = 0.02
    """Loop ticks that ended after their 20 ms slot."""
    overlap: float = 0.005
    edge_tolerance: float | None = None
    """How far past the edge a tracked body may seem to be without counting, m; `None`: the tracker's
    noise, 3 mm or five standard deviations of `[tracker] position_noise`, whichever is larger (a
    robot pushed against the wall shows a few millimetres past it in that noise)."""


@dataclass
class PreflightReport:
    episodes: int = 0
    agent_steps: int = 0
    steps: int = 0
    ticks: int = 0
    walled: int = 0
    capped: int = 0
    boundary: int = 0
    collisions: int = 0
    overruns: int = 0
    returns: list[float] = field(default_factory=list)
    worst_boundary: dict[str, Any] | None = None
    """The nearest a body came to the edge, or the farthest past it: episode, step, robot, metres past
    (negative: inside)."""
    broken: list[str] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def preflight(
    policy: Callable[[np.ndarray], Any],
    task: str = "aggregation",
    episodes: int = 3,
    max_cycles: int = 500,
    limits: PreflightLimits | None = None,
    **env_kwargs: Any,
) -> PreflightReport:
    """Runs `policy` (observation -> action, per agent) for `episodes` episodes of `max_cycles` steps
    on the digital twin (`plant="twin"`; pass `tracker=`/`robots=` for a twin started by
    `colcos twin`), and returns the measurements, or raises `PreflightError` naming every limit
    broken."""
    limits = limits or PreflightLimits()
    if not isinstance(episodes, int) or isinstance(episodes, bool) or episodes < 1:
        raise _core.TaskError(f"episodes must be a positive integer, got {episodes!r}")
    env_kwargs.setdefault("plant", "twin")
    report = PreflightReport()
    for episode in range(episodes):
        env = ColcosParallelEnv(task=task, max_cycles=max_cycles, **env_kwargs)
        with env:
            radius, arena, noise = _geometry(env)
            tolerance = limits.edge_tolerance if limits.edge_tolerance is not None else max(0.003, 5.0 * noise)
            obs, _ = env.reset(seed=episode)
            total = 0.0
            while env.agents:
                actions = {a: policy(obs[a]) for a in env.agents}
                obs, rewards, _, _, infos = env.step(actions)
                total += sum(rewards.values())
                report.steps += 1
                report.agent_steps += len(infos)
                report.walled += sum(bool(i["shield_walled"]) for i in infos.values())
                report.capped += sum(bool(i["shield_capped"]) for i in infos.values())
                poses = env.poses()
                past = _past_edge(poses, radius, arena)
                worst = int(np.argmax(past))
                if past[worst] > tolerance:
                    report.boundary += 1
                if report.worst_boundary is None or past[worst] > report.worst_boundary["past"]:
                    report.worst_boundary = dict(
                        episode=episode, step=env._core.episode_steps(0), robot=worst, past=float(past[worst])
                    )
                report.collisions += int(_overlapping(poses, radius, limits.overlap))
            info = env.plant_info()
            report.ticks += int(info.get("ticks", report.steps))
            report.overruns += int(info.get("overruns", 0))
            report.returns.append(total)
        report.episodes += 1
    checks = [
        ("walled", report.walled / max(report.agent_steps, 1), limits.walled),
        ("capped", report.capped / max(report.agent_steps, 1), limits.capped),
        ("boundary", report.boundary, limits.boundary),
        ("collisions", report.collisions / max(report.steps, 1), limits.collisions),
        ("overruns", report.overruns / max(report.ticks, 1), limits.overruns),
    ]
    for name, value, limit in checks:
        if value > limit:
            detail = ""
            if name == "boundary" and report.worst_boundary is not None:
                w = report.worst_boundary
                where = "past" if w["past"] > 0 else "inside"
                detail = (
                    f" (worst: robot {w['robot']}, episode {w['episode']}, step {w['step']}: "
                    f"{1000 * abs(w['past']):.1f} mm {where} the edge)"
                )
            report.broken.append(f"{name} = {value:.4g} over the limit {limit:g}{detail}")
    if report.broken:
        raise PreflightError(
            f"pre-flight refused over {report.episodes} twin episodes: " + "; ".join(report.broken), report
        )
    return report


def _geometry(env: ColcosParallelEnv) -> tuple[float, tuple[float, float], float]:
    """Robot radius, arena size and the tracker's position noise (m) of the env's scenario."""
    scenario = tomllib.loads(env._core.scenario_toml())
    radius = float(scenario.get("robot", {}).get("radius", 0.02))
    size = scenario["screen"]["size"]
    noise = float(scenario.get("tracker", {}).get("position_noise", 0.001))
    return radius, (float(size[0]), float(size[1])), noise


def _past_edge(poses: np.ndarray, radius: float, arena: tuple[float, float]) -> np.ndarray:
    """How far each robot's body reaches past the arena's edge, m (negative: inside)."""
    x, y = poses[:, 0], poses[:, 1]
    return np.max(np.stack([radius - x, radius - y, x + radius - arena[0], y + radius - arena[1]]), axis=0)


def _overlapping(poses: np.ndarray, radius: float, overlap: float) -> bool:
    p = poses[:, :2]
    d = np.sqrt(((p[:, None, :] - p[None, :, :]) ** 2).sum(-1))
    np.fill_diagonal(d, math.inf)
    return bool((d < 2 * radius - overlap).any())
