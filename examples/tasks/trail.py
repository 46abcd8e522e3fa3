"""The built-in `trail` task written as a `colcos.Task`: agents are rewarded for driving forward on
the blue trail and penalised for bumping. It gives exactly the Rust task's rewards (a test checks it
over 1,000 steps), float32 operation for float32 operation.

    python examples/tasks/trail.py      # 1,024 worlds of it, and their mean reward
"""

from __future__ import annotations

import numpy as np

import colcos
from _common import Rewrite, random_steps


class Trail(Rewrite, builtin="trail", prefill=True):

    def __init__(self, channel: int = 2, bump_penalty: float = 0.1) -> None:
        self.channel = channel
        self.bump_penalty = np.float32(bump_penalty)

    def reward(self, view: colcos.View) -> np.ndarray:
        wheels = view.agents(view.wheels)  # (E, N, 2) m/s, as the drive turns them
        forward = np.float32(0.5) * (wheels[..., 0] + wheels[..., 1])
        inv = np.float32(1.0) / view.max_wheel_speed
        s = view.intensities[..., self.channel]  # (E, N, 4)
        strength = (((s[..., 0] + s[..., 1]) + s[..., 2]) + s[..., 3]) / np.float32(4.0)
        bump = view.bumpers.max(axis=-1)
        return forward * inv * strength - self.bump_penalty * bump


if __name__ == "__main__":
    total = sum(float(rewards.mean()) for _, rewards, *_ in random_steps(Trail(), 1024, 500, 100, low=-1.0))
    print(f"mean reward per agent-step over 100 steps of 1,024 worlds: {total / 100:.4f}")
