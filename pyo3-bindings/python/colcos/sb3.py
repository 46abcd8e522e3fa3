"""`colcos.vector.VecEnv` as a Stable-Baselines3 `VecEnv` (parameter sharing: one sub-env per agent).

SB3 expects next-step semantics of its own: when an env is done, `step` returns the first observation
of the next episode and `infos[i]["terminal_observation"]`. This adapter runs the core in same-step
autoreset mode, which gives exactly that.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import VecEnv as SB3VecEnv

from colcos import _checks
from colcos._core import ActionError
from colcos.vector import VecEnv


class ColcosSB3VecEnv(SB3VecEnv):
    def __init__(self, task: str = "aggregation", num_envs: int = 1, **kwargs: Any) -> None:
        kwargs["autoreset_mode"] = "same_step"
        self.venv = VecEnv(task, num_envs=num_envs, **kwargs)
        v = self.venv
        super().__init__(v.num_envs * v.num_agents, v.single_observation_space, v.single_action_space)
        self._actions: np.ndarray | None = None
        self._seed: int | None = None
        self.render_mode = "rgb_array"

    def reset(self) -> np.ndarray:
        obs, _ = self.venv.reset(seed=self._seed)
        self._seed = None
        return obs.reshape(self.num_envs, -1).copy()

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict]]:
        v = self.venv
        a = np.asarray(self._actions)
        want = (self.num_envs, v.action_width) if v.continuous else (self.num_envs,)
        if a.shape != want:
            raise ActionError(f"actions have shape {a.shape}, expected {want} = (num_envs, ...)")
        obs, rew, term, trunc, _ = v.step(a.reshape(v._act_shape))
        n = self.num_envs
        dones = np.repeat(v.final_mask, v.num_agents)
        final = v.final_obs.reshape(n, -1)
        t = term.reshape(n)
        u = trunc.reshape(n)
        infos: list[dict] = [{} for _ in range(n)]
        if v.patch is not None:
            # Each sub-environment's (agent's) screen patch, (P, P, 3) uint8.
            patches = v.patch.reshape(n, *v.patch.shape[2:])
            for info, patch in zip(infos, patches, strict=True):
                info["patch"] = patch.copy()
        for i in np.flatnonzero(dones):
            infos[i]["terminal_observation"] = final[i].copy()
            infos[i]["TimeLimit.truncated"] = bool(u[i] and not t[i])
        return obs.reshape(n, -1).copy(), rew.reshape(n).copy(), dones, infos

    def close(self) -> None:
        self.venv.close()

    def seed(self, seed: int | None = None) -> list[int | None]:
        self._seed = None if seed is None else _checks.seed(seed)
        return [seed] * self.num_envs

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(self.venv, attr_name)] * len(self._get_indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        setattr(self.venv, attr_name, value)

    def env_method(self, method_name: str, *args: Any, indices: Any = None, **kwargs: Any) -> list[Any]:
        return [getattr(self.venv, method_name)(*args, **kwargs)] * len(self._get_indices(indices))

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False] * len(self._get_indices(indices))

    def get_images(self) -> list[np.ndarray]:
        return [self.venv.render(0)]
