"""`colcos.vector.VecEnv` as a Gymnasium 1.x `VectorEnv`, each (world, agent) pair one sub-environment.

Parameter sharing: `num_envs = E * N`; observations `(E*N, 17)`, actions `(E*N, 2)` or `(E*N,)`.
A world's agents finish together in every built-in task but `foraging`, where an agent that has
arrived waits (stopped, reward 0, flagged terminated) until its world ends. Arrays are views of Rust
memory, overwritten by the next step.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from colcos.vector import VecEnv

_MODES = {"next_step": AutoresetMode.NEXT_STEP, "same_step": AutoresetMode.SAME_STEP, "disabled": AutoresetMode.DISABLED}


class ColcosVectorEnv(VectorEnv):
    """Gymnasium `VectorEnv` over a colcos batch (see module docs). Keyword arguments go to `VecEnv`."""

    def __init__(self, task: str = "aggregation", num_envs: int = 1, **kwargs: Any) -> None:
        self.venv = VecEnv(task, num_envs=num_envs, **kwargs)
        v = self.venv
        self.num_envs = v.num_envs * v.num_agents
        self.single_observation_space = v.single_observation_space
        self.single_action_space = v.single_action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.metadata = {"autoreset_mode": _MODES[v.autoreset_mode], "render_modes": ["rgb_array"]}
        self.render_mode = "rgb_array"
        n = self.num_envs
        self._obs = v.obs.reshape(n, -1)
        self._rew = v.rewards.reshape(n)
        self._term = v.terminated.reshape(n)
        self._trunc = v.truncated.reshape(n)
        self._act_shape = v._act_shape

    def reset(self, *, seed: int | list[int] | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        if isinstance(seed, (list, tuple)):
            seed = seed[0] if seed else None
        if options and "reset_mask" in options:
            m = np.asarray(options["reset_mask"]).reshape(self.venv.num_envs, self.venv.num_agents)
            options = dict(options, reset_mask=m.any(axis=1))
        self.venv.reset(seed=seed, options=options)
        return self._obs, self._infos()

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        self.venv.step(np.asarray(actions).reshape(self._act_shape))
        return self._obs, self._rew, self._term, self._trunc, self._infos()

    def _infos(self) -> dict:
        v = self.venv
        if v.autoreset_mode == "same_step" and v.final_mask.any():
            n = self.num_envs
            return {"final_obs": v.final_obs.reshape(n, -1), "_final_obs": np.repeat(v.final_mask, v.num_agents)}
        return {}

    def render(self) -> np.ndarray:
        return self.venv.render(0)

    def close_extras(self, **kwargs: Any) -> None:
        self.venv.close()
