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

from colcos import _checks, _core
from colcos._core import ActionError, ActionTypeError
from colcos._options import (
    BackendInfo,
    HumanWindow,
    core_kwargs,
    log_backend,
    make_box,
    make_space,
    readonly_views,
)
from colcos.task import Task, TaskRunner, core_task

__all__ = ["VecEnv"]

AUTORESET_MODES = ("next_step", "same_step", "disabled")


class VecEnv(BackendInfo):
    """`num_envs` worlds of one task, batched.

    Args:
        task: task name (`colcos.tasks()`), or a `colcos.Task` written in Python (its hooks run once
            per step over the whole batch; see `colcos.task`).
        num_envs: number of worlds `E` (1..=65536; a batch whose worlds would not fit in memory is
            refused, naming num_envs).
        seed: base seed, an integer in 0..=2**64-1; `reset(seed=...)` replaces it.
        num_threads: worker threads, 1..=1024 (None: one per core).
        scenario, max_cycles, continuous, global_state, patch, patch_side, **params: as for
            `colcos.parallel_env`.
        autoreset_mode: `"next_step"`, `"same_step"` or `"disabled"`.
        backend: field backend of the grid pheromones, `"cpu"`, `"gpu"` or `"auto"` (None: the
            scenario's `[field] backend`), as for `colcos.parallel_env`; see `backend_name`.
        physics: the contact solver, `"rapier"` or `"discs"` (None: the scenario's), as for
            `colcos.parallel_env`.
        render_mode: None, `"rgb_array"` or `"human"` (a window showing world 0 with its robots,
            updated by every `reset` and `step`, at the field's rate; `close()` closes it).
    """

    def __init__(
        self,
        task: str | Task = "aggregation",
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
        physics: str | None = None,
        render_mode: str | None = None,
        **params: Any,
    ) -> None:
        _checks.choice(render_mode, "render_mode", [None, "rgb_array", "human"])
        num_envs = _checks.integer(num_envs, "num_envs", 1, _checks.limit("num_envs"))
        if num_threads is not None:
            num_threads = _checks.integer(num_threads, "num_threads", 1, _checks.limit("num_threads"))
        _checks.choice(autoreset_mode, "autoreset_mode", AUTORESET_MODES)
        seed = _checks.seed(seed)
        self._init_kwargs = dict(
            task=task, num_envs=num_envs, seed=seed, num_threads=num_threads, scenario=scenario, max_cycles=max_cycles,
            continuous=continuous, autoreset_mode=autoreset_mode, global_state=global_state, patch=patch,
            patch_side=patch_side, backend=backend, physics=physics, render_mode=render_mode, **params,
        )
        native, scenario, params = (task, scenario, params) if isinstance(task, str) else core_task(task, scenario, params)
        kw = core_kwargs(native, scenario, max_cycles, continuous, global_state, patch, patch_side, params, backend, physics)
        self._core = _core.VecEnv(num_envs=num_envs, seed=seed, num_threads=num_threads, autoreset_mode=autoreset_mode, **kw)
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
        self.single_observation_space: spaces.Box = make_box(self.spec["observation"])
        self.single_action_space: spaces.Space = make_space(self.spec["action"])
        self.state_space: spaces.Box | None = make_box(self.spec["state"]) if self.spec["state"] else None
        self.patch_space: spaces.Box | None = make_box(self.spec["patch"]) if self.spec["patch"] else None
        v = readonly_views(self._core.views())
        self.obs: np.ndarray = v["obs"]
        self.rewards: np.ndarray = v["rewards"]
        self.terminated: np.ndarray = v["terminated"]
        self.truncated: np.ndarray = v["truncated"]
        self.state: np.ndarray | None = v.get("state")
        self.patch: np.ndarray | None = v.get("patch")
        self.final_obs: np.ndarray = v["final_obs"]
        self.final_mask: np.ndarray = v["final_mask"]
        # Continuous: two wheels, then one rate per deposit action (`robots[].deposit_actions`).
        self.action_width = int(np.prod(self.spec["action"]["shape"])) if self.continuous else 0
        self._act_shape = (
            (self.num_envs, self.num_agents, self.action_width) if self.continuous else (self.num_envs, self.num_agents)
        )
        self._act_dtype = np.float32 if self.continuous else np.int64
        # A task written in Python: its hooks run around every step; observations gain its entries.
        self._runner: TaskRunner | None = None
        if isinstance(task, Task):
            self._runner = TaskRunner(task, self._core, self.spec, autoreset_mode == "same_step")
            self.obs, self.final_obs = self._runner.obs, self._runner.final_obs
            box = self.single_observation_space
            self.single_observation_space = spaces.Box(
                low=np.concatenate([box.low, self._runner.obs_low]),
                high=np.concatenate([box.high, self._runner.obs_high]),
                dtype=np.float32,
            )

    def __getstate__(self) -> dict[str, Any]:
        # Pickling rebuilds the env from its arguments (a fresh copy that needs a reset).
        return {"init_kwargs": self._init_kwargs}

    def __setstate__(self, state: dict[str, Any]) -> None:
        VecEnv.__init__(self, **state["init_kwargs"])

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        """Resets all worlds, or those in `options["reset_mask"]` (bool array of length E)."""
        mask = None
        _checks.options(options, ("reset_mask",))
        if options and options.get("reset_mask") is not None:
            mask = np.asarray(options["reset_mask"])
            if mask.dtype != np.bool_:
                raise ActionTypeError(f"reset_mask must be a bool array of shape ({self.num_envs},), got dtype {mask.dtype}")
            if mask.shape != (self.num_envs,):
                raise ActionError(f"reset_mask must have shape ({self.num_envs},) = (num_envs,), got {mask.shape}")
        if seed is not None:
            seed = _checks.seed(seed)
        self._core.reset(seed, mask)
        if self._runner is not None:
            self._runner.after_reset(np.arange(self.num_envs) if mask is None else np.flatnonzero(mask))
        if self._window is not None:
            self._window.show(self._core.render(0, 640))
        return self.obs, self._infos()

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        """Steps every world with `actions` of shape (E, N, 2) float (continuous) or (E, N) int."""
        a = actions
        if not (isinstance(a, np.ndarray) and a.dtype == self._act_dtype):
            if a is None:
                raise ActionTypeError(f"actions must be an array of shape {self._act_shape}, got None")
            try:
                a = np.asarray(a)
            except (TypeError, ValueError) as e:
                raise ActionTypeError(f"actions cannot be made an array: {e}") from None
            if a.dtype.kind not in "iuf":
                raise ActionTypeError(f"actions must be real numbers, got dtype {a.dtype}")
            if not self.continuous and a.dtype.kind == "f":
                if not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
                    raise ActionError("discrete actions must be integers")
            if a.shape == self._act_shape:
                a = a.astype(self._act_dtype)
        if a.shape != self._act_shape:
            raise ActionError(f"actions have shape {a.shape}, expected {self._act_shape}")
        if self._runner is not None:
            self._runner.step(a)
        else:
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
        if self._runner is not None and self._runner.last_info is not None:
            infos["task"] = self._runner.last_info
        if self.autoreset_mode == "same_step" and self.final_mask.any():
            infos["final_obs"] = self.final_obs
            infos["_final_obs"] = self.final_mask
        return infos

    def render(self, world: int = 0, width: int = 640) -> np.ndarray:
        """The screen of `world` with the robots drawn on it, (H, W, 3) uint8, `width` pixels wide
        (16..=7680; the height follows the screen's aspect)."""
        return self._core.render(world, width)

    def episode_steps(self, world: int) -> int:
        """Steps taken in the current episode of `world`."""
        return self._core.episode_steps(world)

    def episode(self, world: int) -> int:
        """Episode number of `world` since the seed was last set."""
        return self._core.episode(world)

    def poses(self, world: int) -> np.ndarray:
        """True poses (R, 3) of every robot of `world` (analysis only)."""
        return self._core.poses(world)

    def close(self) -> None:
        """Closes the `render_mode="human"` window, if one is open."""
        if self._window is not None:
            self._window.close()
