"""`colcos.vector.VecEnv` as a Gymnasium 1.x `VectorEnv`, each (world, agent) pair one sub-environment.

Parameter sharing: `num_envs = E * N`; observations `(E*N, 17)`, actions `(E*N, 2)` or `(E*N,)`.
Arrays are views of Rust memory, overwritten by the next step.

Agents that finish early (`foraging`: an agent that reaches a branch end) wait, stopped, until every
agent of their world has finished or the world is truncated. A waiting agent's sub-environment
reports reward 0 and `terminated=False` while it waits, and `terminated=True` at the step its world
ends, so each sub-environment ends each episode exactly once (what Gymnasium's wrappers, e.g.
`RecordEpisodeStatistics`, count) and its return is the agent's own. `infos["waiting"]` (with
`infos["_waiting"]`) marks the waiting sub-environments: their actions are ignored, and a learner
may drop those steps. In the other built-in tasks a world's agents finish together.

`render()` gives one frame per sub-environment, as Gymnasium's vector wrappers expect (an agent's
frame is its world's screen with the robots; each world is drawn once per call, when first asked
for), so `gymnasium.wrappers.vector.RecordVideo(env, folder, record_first_only=True)` records world 0.

`reset(options={"reset_mask": m})` takes a bool array of shape `(E*N,)` and resets every world with
a marked agent (a world resets as a whole). `reset(seed=[...])` uses the first seed (one base seed
for the whole batch; None entries are allowed, the others must be valid seeds).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from colcos import _checks
from colcos._core import ActionError, ActionTypeError, ArgumentTypeError
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
        self.metadata = {
            "autoreset_mode": _MODES[v.autoreset_mode],
            "render_modes": ["rgb_array"],
            "render_fps": round(1.0 / float(v.spec["dt"])),
        }
        self.render_mode = "rgb_array"
        n = self.num_envs
        self._obs = v.obs.reshape(n, -1)
        self._rew = v.rewards.reshape(n)
        self._act_shape = v._act_shape
        self._flat_act_shape = (n, v.action_width) if v.continuous else (n,)

    def reset(self, *, seed: int | list[int] | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        if isinstance(seed, (list, tuple)):
            seeds = [None if s is None else _checks.seed(s, f"seed[{i}]") for i, s in enumerate(seed)]
            seed = seeds[0] if seeds else None
        if options is not None and not isinstance(options, dict):
            raise ArgumentTypeError(f"options must be a dict or None, got {type(options).__name__}")
        if options and "reset_mask" in options:
            m = np.asarray(options["reset_mask"])
            if m.dtype != np.bool_:
                raise ActionTypeError(f"reset_mask must be a bool array of shape ({self.num_envs},), got dtype {m.dtype}")
            if m.shape != (self.num_envs,):
                raise ActionError(f"reset_mask must have shape ({self.num_envs},) = (num_envs,), got {m.shape}")
            m = m.reshape(self.venv.num_envs, self.venv.num_agents)
            options = dict(options, reset_mask=m.any(axis=1))
        self.venv.reset(seed=seed, options=options)
        return self._obs, self._infos(None)

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        try:
            a = np.asarray(actions)
        except (TypeError, ValueError) as e:
            raise ActionTypeError(f"actions cannot be made an array: {e}") from None
        if a.shape != self._flat_act_shape:
            raise ActionError(f"actions have shape {a.shape}, expected {self._flat_act_shape} = (num_envs, ...)")
        v = self.venv
        v.step(a.reshape(self._act_shape))
        term, trunc = v.terminated, v.truncated
        ended = (term | trunc).all(axis=1, keepdims=True)  # the worlds that end at this step
        waiting = term & ~ended
        n = self.num_envs
        out_term = (term & ended).reshape(n)
        out_trunc = (trunc & ~term & ended).reshape(n)
        return self._obs, self._rew, out_term, out_trunc, self._infos(waiting.reshape(n))

    def _infos(self, waiting: np.ndarray | None) -> dict:
        v = self.venv
        infos: dict[str, Any] = {}
        if v.autoreset_mode == "same_step" and v.final_mask.any():
            n = self.num_envs
            infos["final_obs"] = v.final_obs.reshape(n, -1)
            infos["_final_obs"] = np.repeat(v.final_mask, v.num_agents)
        if waiting is not None and waiting.any():
            infos["waiting"] = waiting
            infos["_waiting"] = waiting
        if v.patch is not None:
            # Each sub-environment's (agent's) screen patch, (E*N, P, P, 3) uint8.
            infos["patch"] = v.patch.reshape(self.num_envs, *v.patch.shape[2:]).copy()
        return infos

    # A lazy sequence, not the tuple Gymnasium's signature names: drawing every world at every call
    # would cost a batch of thousands of worlds a render each (the wrappers ask for a Sequence).
    def render(self) -> Sequence[np.ndarray]:  # type: ignore[override]
        """One `(H, W, 3)` uint8 frame per sub-environment: its world's screen with the robots."""
        return _Frames(self.venv)

    def close_extras(self, **kwargs: Any) -> None:
        self.venv.close()


class _Frames(Sequence[np.ndarray]):
    """The frames of every sub-environment, each world drawn once, when first asked for."""

    def __init__(self, venv: VecEnv) -> None:
        self._venv = venv
        self._agents = venv.num_agents
        self._worlds: dict[int, np.ndarray] = {}

    def __len__(self) -> int:
        return self._venv.num_envs * self._agents

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        if not isinstance(i, (int, np.integer)) or isinstance(i, bool):
            raise ArgumentTypeError(f"frame index must be an integer, got {type(i).__name__}")
        n = len(self)
        k = int(i) + n if i < 0 else int(i)
        if not 0 <= k < n:
            raise IndexError(f"frame {i} out of range for {n} sub-environments")
        w = k // self._agents
        if w not in self._worlds:
            self._worlds[w] = self._venv.render(w)
        return self._worlds[w]
