"""The built-in `colony` task (central-place foraging) written as a `colcos.Task`: agents pick units
of food up at finite patches and carry them to the nest; each delivery pays the whole team. Its
per-episode state (food left in each patch of each world, who carries, units delivered) lives on the
task as numpy arrays, set afresh by `reset` for the worlds starting an episode. It gives exactly the
Rust task's rewards and observations (a test checks it over 1,000 steps).

    python examples/tasks/colony.py      # 256 worlds of it, and the units delivered
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

import colcos
from _common import Rewrite, random_steps

F32 = np.float32


class Colony(Rewrite, builtin="colony", prefill=False):
    obs_low, obs_high = (0.0,), (1.0,)  # one extra entry: carrying (0 or 1)

    def __init__(
        self,
        nest: Sequence[float] = (0.25, 0.405),
        nest_radius: float = 0.08,
        food: Sequence[Sequence[float]] = ((1.15, 0.65), (1.15, 0.16)),
        food_radius: float = 0.07,
        food_amount: int = 10,
        delivery_reward: float = 1.0,
        pickup_reward: float = 0.0,
        step_penalty: float = 0.0,
    ) -> None:
        self.nest = np.asarray(nest, F32)
        self.food = np.asarray(food, F32).reshape(-1, 2)
        self.nest2 = F32(nest_radius) * F32(nest_radius)
        self.food2 = F32(food_radius) * F32(food_radius)
        self.food_amount = int(food_amount)
        self.delivery_reward = F32(delivery_reward)
        self.pickup_reward = F32(pickup_reward)
        self.step_penalty = F32(step_penalty)
        self.left = np.zeros((0, len(self.food)), np.int64)  # (E, patches) units left
        self.carrying = np.zeros((0, 0), np.bool_)  # (E, N)
        self.delivered = np.zeros(0, np.int64)  # (E,) units delivered this episode

    def reset(self, ctx: colcos.ResetContext) -> None:
        e, n = ctx.view.obs.shape[:2]
        if self.carrying.shape != (e, n):
            self.left = np.zeros((e, len(self.food)), np.int64)
            self.carrying = np.zeros((e, n), np.bool_)
            self.delivered = np.zeros(e, np.int64)
        self.left[ctx.worlds] = self.food_amount
        self.carrying[ctx.worlds] = False
        self.delivered[ctx.worlds] = 0

    def reward(self, view: colcos.View) -> np.ndarray:
        p = view.agents(view.poses)[..., :2]  # (E, N, 2)
        dn = p - self.nest
        at_nest = (dn[..., 0] * dn[..., 0] + dn[..., 1] * dn[..., 1]) <= self.nest2
        df = p[:, :, None, :] - self.food  # (E, N, patches, 2)
        at_food = (df[..., 0] * df[..., 0] + df[..., 1] * df[..., 1]) <= self.food2
        # Only worlds that moved are evaluated (one that just started an episode keeps its state).
        moved = view.stepped
        rewards = np.full(at_nest.shape, -self.step_penalty, F32)
        delivered = np.zeros(len(moved), np.int64)
        # Agent by agent, over all worlds at once: the last unit of a patch goes to the lowest agent
        # index that reaches it in a step, as in the Rust task.
        for k in range(at_nest.shape[1]):
            carrying = self.carrying[:, k] & moved
            deliver = carrying & at_nest[:, k]
            can = (self.left > 0) & at_food[:, k] & (moved & ~self.carrying[:, k])[:, None]
            worlds = np.flatnonzero(can.any(axis=1))
            patch = can.argmax(axis=1)[worlds]  # the first patch with food in reach
            self.left[worlds, patch] -= 1
            self.carrying[worlds, k] = True
            rewards[worlds, k] += self.pickup_reward
            self.carrying[deliver, k] = False
            delivered += deliver
        self.delivered += delivered
        team = self.delivery_reward * delivered.astype(F32)
        return np.where((delivered > 0)[:, None], rewards + team[:, None], rewards)

    def observe(self, view: colcos.View) -> np.ndarray:
        return self.carrying[..., None].astype(F32)

    def info(self, view: colcos.View) -> dict[str, Any]:
        return {"delivered": self.delivered.copy(), "food_left": self.left.copy()}


if __name__ == "__main__":
    *_, infos = list(random_steps(Colony(), 256, 3000, 1000))[-1]
    print(f"units delivered in 1,000 steps of 256 worlds: {int(infos['task']['delivered'].sum())}")
