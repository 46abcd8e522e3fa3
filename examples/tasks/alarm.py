"""The built-in `alarm` task written as a `colcos.Task`: a scripted predator roams the arena (its
pose is in `view.poses`, its role in `view.roles`); the team is paid for each agent out of its
reach, and an agent near it senses it in one extra observation entry, a warning it may pass on by
laying the alarm pheromone. It gives exactly the Rust task's rewards and observations (a test
checks it over 1,000 steps).

    python examples/tasks/alarm.py      # 256 worlds of it, and the share of agent-steps captured
"""

from __future__ import annotations

import numpy as np

import colcos
from _common import Rewrite, random_steps

F32 = np.float32


class Alarm(Rewrite, builtin="alarm", prefill=False):
    obs_low, obs_high = (0.0,), (1.0,)  # one extra entry: predator_near (0 or 1)

    def __init__(
        self,
        predator_role: str = "predator",
        capture_distance: float = 0.1,
        sense_distance: float = 0.2,
        safe_reward: float = 1.0,
        capture_penalty: float = 0.0,
    ) -> None:
        self.predator_role = predator_role
        self.capture2 = F32(capture_distance) * F32(capture_distance)
        self.sense2 = F32(sense_distance) * F32(sense_distance)
        self.safe_reward = F32(safe_reward)
        self.capture_penalty = F32(capture_penalty)
        self.predators = np.zeros(0, np.int64)

    def reset(self, ctx: colcos.ResetContext) -> None:
        roles = ctx.view.roles
        self.predators = np.array([i for i, r in enumerate(roles) if r == self.predator_role], np.int64)
        if not self.predators.size:
            raise ValueError(f"no robot has role {self.predator_role!r} (roles: {sorted(set(roles))})")

    def _nearest2(self, view: colcos.View) -> np.ndarray:
        """Squared distance from each agent to its nearest predator, (E, N)."""
        p = view.agents(view.poses)[:, None, :, :2]  # (E, 1, N, 2)
        q = view.poses[:, self.predators, None, :2] - p  # (E, P, N, 2)
        return (q[..., 0] * q[..., 0] + q[..., 1] * q[..., 1]).min(axis=1)

    def reward(self, view: colcos.View) -> np.ndarray:
        captured = self._nearest2(view) <= self.capture2
        safe = (~captured).sum(axis=1).astype(F32)
        team = self.safe_reward * safe / F32(captured.shape[1])
        return np.where(captured, -self.capture_penalty, F32(0.0)) + team[:, None]

    def observe(self, view: colcos.View) -> np.ndarray:
        return (self._nearest2(view) <= self.sense2)[..., None].astype(F32)


if __name__ == "__main__":
    near = sum(float(obs[..., -1].mean()) for obs, *_ in random_steps(Alarm(), 256, 3000, 1000))
    print(f"share of agent-steps with the predator near: {near / 1000:.3f}")
