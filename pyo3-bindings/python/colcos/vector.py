"""The batched environment: `E` worlds x `N` agents stepped in Rust, arrays shaped `(E, N, ...)`.

The arrays returned by `reset` and `step` are numpy *views of Rust memory* (no copies). They are
overwritten in place by the next `step`/`reset`: copy what you need to keep (`obs.copy()`). The GIL is
released while the worlds step, on `num_threads` threads (default: one per core). Results do not depend
on `num_threads`: each world draws from its own random streams derived from (seed, world, episode).

Autoreset modes, as in Gymnasium 1.x (`autoreset_mode=`):
- `"next_step"` (default): a world that finished is reset by the next `step`, which ignores its actions
  and returns its first observation with reward 0.
- `"same_step"`: reset within the same `step`; the final observation is in `infos["final_obs"]`,
  `infos["_final_obs"]` marks the worlds.
- `"disabled"`: reset finished worlds yourself with `reset(options={"reset_mask": mask})`.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np
from gymnasium import spaces

from colcos import _core
from colcos._core import ActionError
from colcos._options import BackendInfo, HumanWindow, core_kwargs, log_backend, make_space

__all__ = ["VecEnv"]

AUTORESET_MODES = ("next_step", "same_step", "disabled")


class VecEnv(BackendInfo):
    """`num_envs` worlds of one task, batched.

    Args:
        task: task name (`colcos.tasks()`).
        num_envs: number of worlds `E`.
        seed: base seed; `reset(seed=...)` replaces it.
        num_threads: worker threads (None: one per core).
        scenario, max_cycles, continuous, global_state, patch, patch_side, **params: as for
            `colcos.parallel_env`.
        autoreset_mode: `"next_step"`, `"same_step"` or `"disabled"`.
        backend: field backend of the grid pheromones, `"cpu"`, `"gpu"` or `"auto"` (None: the
            scenario's `[field] backend`), as for `colcos.parallel_env`; see `backend_name`.
        render_mode: None, `"rgb_array"` or `"human"` (a window showing world 0 with its robots,
            updated by every `reset` and `step`, at the field's rate; `close()` closes it).
    """

    def __init__(
        self,
        task: str = "aggregation",
        num_envs: int = 1,
        seed: int = 0,
        num_threads: int | None = None,
        scenario: str | os.PathLike[str] | None = None,
        max_cycles: int | None = 500,
        continuous: bool = True,
        autoreset_mode: str = "next_step",
        global_state: bool = True,
        patch: int | None = None,
        patch_side: float = 0.08,
        backend: str | None = None,
        render_mode: str | None = None,
        **params: Any,
    ) -> None:
        if render_mode not in (None, "rgb_array", "human"):
            raise _core.TaskError(f"render_mode {render_mode!r} is not one of ['human', 'rgb_array'] or None")
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise _core.TaskError(f"num_envs must be a positive integer, got {num_envs!r}")
        if num_threads is not None and (not isinstance(num_threads, (int, np.integer)) or num_threads < 1):
            raise _core.TaskError(f"num_threads must be a positive integer or None, got {num_threads!r}")
        if autoreset_mode not in AUTORESET_MODES:
            raise _core.TaskError(f"autoreset_mode {autoreset_mode!r} is not one of {AUTORESET_MODES}")
        self._init_kwargs = dict(
            task=task, num_envs=num_envs, seed=seed, num_threads=num_threads, scenario=scenario, max_cycles=max_cycles,
            continuous=continuous, autoreset_mode=autoreset_mode, global_state=global_state, patch=patch,
            patch_side=patch_side, backend=backend, render_mode=render_mode, **params,
        )
        kw = core_kwargs(task, scenario, max_cycles, continuous, global_state, patch, patch_side, params, backend)
        self._core = _core.VecEnv(
            num_envs=int(num_envs), seed=int(seed), num_threads=num_threads, autoreset_mode=autoreset_mode, **kw
        )
        log_backend(self._core, backend)
        self.spec: dict[str, Any] = self._core.spec()
        self.render_mode = render_mode
        self._window = HumanWindow(f"colcos: {self.spec['env_name']}", 1.0 / self.spec["dt"]) if render_mode == "human" else None
        self.task = task
        self.num_envs: int = self.spec["num_envs"]
        self.num_agents: int = self.spec["num_agents"]
        self.agents: list[str] = list(self.spec["agent_names"])
        self.autoreset_mode = autoreset_mode
        self.continuous = self.spec["action"]["kind"] == "box"
        self.single_observation_space: spaces.Box = make_space(self.spec["observation"])
        self.single_action_space: spaces.Space = make_space(self.spec["action"])
        self.state_space: spaces.Box | None = make_space(self.spec["state"]) if self.spec["state"] else None
        self.patch_space: spaces.Box | None = make_space(self.spec["patch"]) if self.spec["patch"] else None
        v = self._core.views()
        self.obs: np.ndarray = v["obs"]
        self.rewards: np.ndarray = v["rewards"]
        self.terminated: np.ndarray = v["terminated"]
        self.truncated: np.ndarray = v["truncated"]
        self.state: np.ndarray | None = v.get("state")
        self.patch: np.ndarray | None = v.get("patch")
        self.final_obs: np.ndarray = v["final_obs"]
        self.final_mask: np.ndarray = v["final_mask"]
        self._act_shape = (self.num_envs, self.num_agents, 2) if self.continuous else (self.num_envs, self.num_agents)
        self._act_dtype = np.float32 if self.continuous else np.int64

    def __getstate__(self) -> dict[str, Any]:
        # Pickling rebuilds the env from its arguments (a fresh copy that needs a reset).
        return {"init_kwargs": self._init_kwargs}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(**state["init_kwargs"])

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        """Resets all worlds, or those in `options["reset_mask"]` (bool array of length E)."""
        mask = None
        if options and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"])
            if mask.dtype != np.bool_ or mask.shape != (self.num_envs,):
                raise ActionError(f"reset_mask must be a bool array of shape ({self.num_envs},), got {mask.dtype} {mask.shape}")
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0):
            raise _core.TaskError(f"seed must be a non-negative integer, got {seed!r}")
        self._core.reset(None if seed is None else int(seed), mask)
        if self._window is not None:
            self._window.show(self._core.render(0, 640))
        return self.obs, self._infos()

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        """Steps every world with `actions` of shape (E, N, 2) float (continuous) or (E, N) int."""
        a = actions
        if not (isinstance(a, np.ndarray) and a.dtype == self._act_dtype):
            try:
                a = np.asarray(a)
            except (TypeError, ValueError) as e:
                raise ActionError(f"actions cannot be made an array: {e}") from None
            if not self.continuous and a.dtype.kind == "f":
                if not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
                    raise ActionError("discrete actions must be integers")
            if a.dtype.kind not in "biuf":
                raise ActionError(f"actions must be numbers, got dtype {a.dtype}")
            a = a.astype(self._act_dtype)
        if a.shape != self._act_shape:
            raise ActionError(f"actions have shape {a.shape}, expected {self._act_shape}")
        self._core.step(a)
        if self._window is not None:
            self._window.show(self._core.render(0, 640))
        return self.obs, self.rewards, self.terminated, self.truncated, self._infos()

    def _infos(self) -> dict:
        infos: dict[str, Any] = {}
        if self.state is not None:
            infos["state"] = self.state
        if self.patch is not None:
            infos["patch"] = self.patch
        if self.autoreset_mode == "same_step" and self.final_mask.any():
            infos["final_obs"] = self.final_obs
            infos["_final_obs"] = self.final_mask
        return infos

    def render(self, world: int = 0, width: int = 640) -> np.ndarray:
        """The screen of `world` with the robots drawn on it, (H, W, 3) uint8."""
        return self._core.render(world, width)

    def episode_steps(self, world: int) -> int:
        return self._core.episode_steps(world)

    def poses(self, world: int) -> np.ndarray:
        """True poses (R, 3) of every robot of `world` (analysis only)."""
        return self._core.poses(world)

    def close(self) -> None:
        """Closes the `render_mode="human"` window, if one is open."""
        if self._window is not None:
            self._window.close()
