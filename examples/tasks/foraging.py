"""The built-in `foraging` task (case I) written as a `colcos.Task`: each step costs a little, an
agent that reaches the food end is rewarded and done, one that reaches an empty end is penalised and
done. It gives exactly the Rust task's rewards and terminations (a test checks it over 1,000 steps).

    python examples/tasks/foraging.py
"""

from __future__ import annotations

import numpy as np

import colcos
from _common import Rewrite


class Foraging(Rewrite, builtin="foraging", prefill=True):
    agent_role = "forager"

    def __init__(self) -> None:
        self.food = np.array([[1.3, 0.55]], np.float32)
        self.empty = np.array([[1.3, 0.7], [1.3, 0.1], [1.3, 0.25]], np.float32)
        self.reach = np.float32(0.05)
        self.food_reward = np.float32(1.0)
        self.wrong_end_penalty = np.float32(1.0)
        self.step_penalty = np.float32(0.001)

    def _near(self, view: colcos.View, ends: np.ndarray) -> np.ndarray:
        p = view.agents(view.poses)[..., None, :2]  # (E, N, 1, 2)
        d = ends[None, None] - p
        return ((d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1]) <= self.reach * self.reach).any(axis=-1)

    def reward(self, view: colcos.View) -> np.ndarray:
        food, empty = self._near(view, self.food), self._near(view, self.empty)
        r = np.full(food.shape, -self.step_penalty, np.float32)
        r = np.where(food, r + self.food_reward, np.where(empty, r - self.wrong_end_penalty, r))
        return r.astype(np.float32)

    def terminated(self, view: colcos.View) -> np.ndarray:
        return self._near(view, self.food) | self._near(view, self.empty)


if __name__ == "__main__":
    env = colcos.vector.VecEnv(Foraging(), num_envs=256, max_cycles=1000)
    env.reset(seed=0)
    done = 0
    for _ in range(1000):
        _, _, terminated, _, _ = env.step(np.tile(np.float32([0.6, 0.6]), (256, env.num_agents, 1)))
        done += int(terminated.sum())
    print(f"{done} agent episodes ended at an end in 1,000 steps of 256 worlds")
