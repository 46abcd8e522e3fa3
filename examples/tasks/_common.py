"""What the built-in tasks' Python re-writes share: the class they derive from (named after the
built-in, on its scenario) and the run under random actions each does when started as a script."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

import colcos


class Rewrite(colcos.Task):
    """A built-in task re-written in Python: `class Alarm(Rewrite, builtin="alarm", prefill=False)`
    is the task `alarm_py` on the built-in `alarm` scenario, leaving the fields as they start at a
    reset as the Rust task does (`prefill=True`: bringing static maps to their steady state)."""

    def __init_subclass__(cls, builtin: str, prefill: bool, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls.name = f"{builtin}_py"
        cls.scenario = colcos.default_scenario(builtin)
        cls.prefill_static_maps = prefill


def random_steps(
    task: colcos.Task, num_envs: int, max_cycles: int, steps: int, low: float = 0.0
) -> Iterator[tuple[Any, ...]]:
    """What `step` returns for each of `steps` steps of `num_envs` worlds of `task` (seed 0) under
    actions drawn uniformly from `[low, 1]`."""
    env = colcos.vector.VecEnv(task, num_envs=num_envs, max_cycles=max_cycles)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    width = env.single_action_space.shape[0]
    for _ in range(steps):
        yield env.step(rng.uniform(low, 1, (num_envs, env.num_agents, width)).astype(np.float32))
