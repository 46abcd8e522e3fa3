"""The paper's hand-written behaviours as baseline policies over a `colcos.vector.VecEnv` or a
`colcos.parallel_env(...)` on any plant (the simulator, a twin, the rig).

A behaviour decides from the same raw sensor readings an agent's observation vector is built from
(and keeps its own state, e.g. a turn in progress), so it is evaluated in Rust next to the worlds, or
next to the host's arena on a twin or the rig.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
from gymnasium import spaces

from colcos import _checks, _core
from colcos.pettingzoo_env import ColcosParallelEnv
from colcos.vector import VecEnv

__all__ = ["Baseline", "RandomPolicy"]


class Baseline:
    """Behaviour `name` (see `colcos.behaviours()`) driving every agent of `env`, or a task's own
    policy (`colcos.task_policies()`, e.g. `"colony_ant"`: it also chooses the deposit rates).

    >>> venv = VecEnv("aggregation", num_envs=8)
    >>> policy = Baseline(venv, "avoid", speed=0.1)
    >>> obs, _ = venv.reset(seed=0)
    >>> obs, rew, term, trunc, _ = venv.step(policy.act())

    On a `parallel_env` (one arena; `plant="twin"` or `"rig"` too) `actions()` gives the PettingZoo
    action dict of the agents still running:

    >>> env = colcos.parallel_env(task="aggregation", plant="twin")
    >>> follower = Baseline(env, "aggregation_follower")
    >>> obs, _ = env.reset(seed=1)
    >>> obs, rew, term, trunc, _ = env.step(follower.actions())
    """

    def __init__(self, env: VecEnv | ColcosParallelEnv, name: str, seed: int = 0, **params: Any) -> None:
        if not isinstance(env, (VecEnv, ColcosParallelEnv)):
            raise _core.ArgumentTypeError(
                f"env must be a colcos.vector.VecEnv or a colcos.parallel_env, got {type(env).__name__}"
            )
        continuous = env.continuous if isinstance(env, VecEnv) else env._continuous
        if not continuous:
            raise _core.TaskError("baseline policies produce continuous wheel speeds; make the env with continuous=True")
        self.env = env
        self.name = name
        plain = {k: _checks.plain(v, k) for k, v in params.items()}
        self._policy = _core.Baseline(env._core, name, json.dumps(plain) if plain else None, _checks.seed(seed))

    def act(self, obs: np.ndarray | None = None) -> np.ndarray:
        """Actions (E, N, 2 + D) float32 for the env's current sensor readings (`obs` is ignored): the
        wheels, then the deposit rates (0 from a behaviour; a task policy chooses them)."""
        return self._policy.act(self.env._core)

    def actions(self) -> dict[str, np.ndarray]:
        """For a `parallel_env`: `{agent: action}` of the agents still running (PettingZoo's form)."""
        env = self.env
        if not isinstance(env, ColcosParallelEnv):
            raise _core.TaskError("actions() is for a colcos.parallel_env; use act() on a VecEnv")
        acts = self.act()[0]
        return {a: acts[env._index[a]] for a in env.agents}


class RandomPolicy:
    """Uniform random actions, seeded."""

    def __init__(self, env: VecEnv, seed: int = 0) -> None:
        self.env = env
        self.rng = np.random.default_rng(_checks.seed(seed))

    def act(self, obs: np.ndarray | None = None) -> np.ndarray:
        e, n = self.env.num_envs, self.env.num_agents
        if self.env.continuous:
            # Wheels in [-1, 1], then deposit rates (if any) in [0, 1]: the action space's bounds.
            space = self.env.single_action_space
            assert isinstance(space, spaces.Box)
            return self.rng.uniform(space.low, space.high, size=(e, n, *space.shape)).astype(np.float32)
        n_actions = int(getattr(self.env.single_action_space, "n", 0))
        return self.rng.integers(0, n_actions, size=(e, n))
