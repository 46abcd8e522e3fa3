"""`colcos.vector.VecEnv` as a TorchRL `EnvBase`: batch size `[E]`, agents grouped under `"robot"`
(as TorchRL's `PettingZooWrapper` groups `robot_0..`). Observations reach torch through
one copy of the Rust buffers each (they are read-only views, overwritten by the next step).

Keys: `("robot", "observation")` `[E, N, 17]`, `("robot", "action")` `[E, N, 2]`,
`("robot", "reward")` `[E, N, 1]`, `("robot", "terminated"|"truncated"|"done")` `[E, N, 1]`, and
`"done"`/`"terminated"`/`"truncated"` `[E, 1]` (a world is done when all its agents are); `"state"`
`[E, S]` when the env has a global state.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from gymnasium import spaces
from tensordict import TensorDict, TensorDictBase
from torchrl.data import Bounded, Categorical, Composite, Unbounded
from torchrl.envs import EnvBase

from colcos import _checks
from colcos._core import TaskError
from colcos.vector import VecEnv


class ColcosTorchEnv(EnvBase):
    """TorchRL environment over a colcos batch. Keyword arguments go to `colcos.vector.VecEnv`
    (autoreset is handled by TorchRL: the core runs with autoreset disabled)."""

    def __init__(self, task: str = "aggregation", num_envs: int = 1, device: str | torch.device = "cpu", **kwargs: Any) -> None:
        kwargs["autoreset_mode"] = "disabled"
        if kwargs.get("patch") is not None:
            raise TaskError(
                "patch= is not carried by the TorchRL adapter; use colcos.vector.VecEnv (infos['patch']) or "
                "colcos.gymnasium_vector (infos['patch'])"
            )
        self.venv = VecEnv(task, num_envs=num_envs, **kwargs)
        v = self.venv
        super().__init__(device=device, batch_size=torch.Size([v.num_envs]))
        e, n = v.num_envs, v.num_agents
        # The bounds the values take, per entry (as the Gymnasium spaces declare them).
        o = v.single_observation_space
        lo, hi = (torch.as_tensor(np.broadcast_to(b, (e, n, *o.shape)).copy()) for b in (o.low, o.high))
        obs = Bounded(low=lo, high=hi, shape=(e, n, *o.shape), dtype=torch.float32, device=self.device)
        group = Composite(observation=obs, shape=(e, n), device=self.device)
        spec = Composite(robot=group, shape=(e,), device=self.device)
        if v.state is not None and v.state_space is not None:
            s = v.state_space
            lo, hi = (torch.as_tensor(np.broadcast_to(b, (e, *s.shape)).copy()) for b in (s.low, s.high))
            spec["state"] = Bounded(low=lo, high=hi, shape=(e, *s.shape), dtype=torch.float32, device=self.device)
        self.observation_spec = spec
        if v.continuous:
            a = v.single_action_space
            assert isinstance(a, spaces.Box)
            lo, hi = (torch.as_tensor(np.broadcast_to(b, (e, n, *a.shape)).copy()) for b in (a.low, a.high))
            act = Bounded(low=lo, high=hi, shape=(e, n, *a.shape), dtype=torch.float32, device=self.device)
        else:
            assert isinstance(v.single_action_space, spaces.Discrete)
            act = Categorical(n=int(v.single_action_space.n), shape=(e, n), dtype=torch.int64, device=self.device)
        self.action_spec = Composite(robot=Composite(action=act, shape=(e, n), device=self.device), shape=(e,), device=self.device)
        self.reward_spec = Composite(
            robot=Composite(reward=Unbounded(shape=(e, n, 1), dtype=torch.float32, device=self.device), shape=(e, n), device=self.device),
            shape=(e,),
            device=self.device,
        )
        flag = lambda *s: Categorical(n=2, shape=s, dtype=torch.bool, device=self.device)  # noqa: E731
        self.done_spec = Composite(
            done=flag(e, 1),
            terminated=flag(e, 1),
            truncated=flag(e, 1),
            robot=Composite(done=flag(e, n, 1), terminated=flag(e, n, 1), truncated=flag(e, n, 1), shape=(e, n), device=self.device),
            shape=(e,),
            device=self.device,
        )
        self._started = False

    def _obs_td(self) -> dict[str, Any]:
        v = self.venv
        group = TensorDict(
            {"observation": torch.tensor(v.obs, device=self.device)},
            batch_size=(v.num_envs, v.num_agents),
            device=self.device,
        )
        out: dict[str, Any] = {"robot": group}
        if v.state is not None:
            out["state"] = torch.tensor(v.state, device=self.device)
        return out

    def _flags(self, out: dict[str, Any]) -> None:
        v = self.venv
        term = torch.from_numpy(v.terminated.copy()).to(self.device).unsqueeze(-1)
        trunc = torch.from_numpy(v.truncated.copy()).to(self.device).unsqueeze(-1)
        done = term | trunc
        out["robot"].update({"terminated": term, "truncated": trunc, "done": done})
        out["terminated"] = term.all(dim=1)
        out["truncated"] = trunc.any(dim=1) & done.all(dim=1)
        out["done"] = done.all(dim=1)

    def _reset(self, tensordict: TensorDictBase | None = None, **kwargs: Any) -> TensorDictBase:
        mask = None
        if tensordict is not None and "_reset" in tensordict.keys() and self._started:
            mask = tensordict.get("_reset").reshape(self.venv.num_envs, -1).any(dim=-1).cpu().numpy()
        self.venv.reset(options={"reset_mask": mask} if mask is not None else None)
        self._started = True
        out = self._obs_td()
        self._flags(out)
        return TensorDict(out, batch_size=self.batch_size, device=self.device)

    def _step(self, tensordict: TensorDictBase) -> TensorDictBase:
        a = tensordict.get(("robot", "action")).detach().cpu().numpy()
        self.venv.step(np.ascontiguousarray(a))
        out = self._obs_td()
        out["robot"]["reward"] = torch.from_numpy(self.venv.rewards.copy()).to(self.device).unsqueeze(-1)
        self._flags(out)
        return TensorDict(out, batch_size=self.batch_size, device=self.device)

    def _set_seed(self, seed: int | None) -> None:
        if seed is not None:
            self.venv.reset(seed=_checks.seed(seed))
            self._started = True
