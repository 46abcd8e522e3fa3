"""The built-in `aggregation` task (case II) written as a `colcos.Task`: followers are paid for
driving toward the leader while calm and down the alarm gradient while the alarm is up, and pay for
their distance to the leader, the alarm level and a predator's capture. It gives exactly the Rust
task's rewards (a test checks it over 1,000 steps), float32 operation for float32 operation: the
alarm's level and gradient come from `view.gradients` and the headings' sine and cosine from
`view.headings`, as the Rust task reads them.

    python examples/tasks/aggregation.py      # 1,024 worlds of it, and their mean reward
"""

from __future__ import annotations

import numpy as np

import colcos
from _common import Rewrite, random_steps

F32 = np.float32
#: Step of the central differences that give a grid pheromone's gradient, m (as the Rust task).
GRADIENT_STEP = 0.005


def normalize_or_zero(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`(x, y)` scaled to length 1, or zero where it has no direction (glam's `normalize_or_zero`)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        rcp = F32(1.0) / np.sqrt(x * x + y * y)
        ok = np.isfinite(rcp) & (rcp > 0)
        return np.where(ok, x * rcp, F32(0.0)), np.where(ok, y * rcp, F32(0.0))


class Aggregation(Rewrite, builtin="aggregation", prefill=False):
    agent_role = "follower"

    def __init__(
        self,
        leader_role: str = "leader",
        predator_role: str = "predator",
        capture_distance: float = 0.1,
        capture_penalty: float = 1.0,
        distance_weight: float = 1.0,
        progress_weight: float = 1.0,
        alarm_weight: float = 1.0,
        alarm_threshold: float = 0.05,
        alarm_channel: str = "r",
    ) -> None:
        self.leader_role, self.predator_role = leader_role, predator_role
        self.c2 = F32(capture_distance) * F32(capture_distance)
        self.capture_penalty = F32(capture_penalty)
        self.distance_weight = F32(distance_weight)
        self.progress_weight = F32(progress_weight)
        self.alarm_weight = F32(alarm_weight)
        self.alarm_threshold = F32(alarm_threshold)
        self.channel = "rgb".index(alarm_channel)

    def reset(self, ctx: colcos.ResetContext) -> None:
        # Who leads and hunts, and the arena's size (looked up at every reset: a few microseconds).
        view = ctx.view
        self.leader = view.roles.index(self.leader_role)
        self.predators = np.array([i for i, r in enumerate(view.roles) if r == self.predator_role], np.int64)
        w, h = F32(view.arena[0]), F32(view.arena[1])
        self.inv_diagonal = F32(1.0) / max(np.sqrt(w * w + h * h), F32(1e-6))
        # The pheromones drawn in the alarm channel, each with its share of the screen level.
        k = view.colours[:, self.channel]
        self.alarm_sources = [(j, k[j] / F32(255.0)) for j in range(len(k)) if k[j] != 0]
        s = view.max_wheel_speed
        self.inv_max_speed = F32(1.0) / s if s > 0 else F32(0.0)

    def reward(self, view: colcos.View) -> np.ndarray:
        poses = view.poses
        p = view.agents(poses)[..., :2]  # (E, N, 2)
        px, py = p[..., 0], p[..., 1]
        tx = poses[:, self.leader, None, 0] - px
        ty = poses[:, self.leader, None, 1] - py
        d = np.sqrt(tx * tx + ty * ty)

        # The alarm channel's screen level at each follower and its gradient.
        values, grads = view.gradients(p, GRADIENT_STEP)
        alarm = np.zeros(px.shape, F32)
        gx, gy = np.zeros_like(alarm), np.zeros_like(alarm)
        for j, k in self.alarm_sources:
            alarm = alarm + k * values[..., j]
            gx = gx + k * grads[..., j, 0]
            gy = gy + k * grads[..., j, 1]

        # Goal: down the alarm gradient while the alarm is up, else toward the leader.
        fx, fy = normalize_or_zero(gx, gy)
        lx, ly = normalize_or_zero(tx, ty)
        fleeing = alarm > self.alarm_threshold
        goal_x, goal_y = np.where(fleeing, -fx, lx), np.where(fleeing, -fy, ly)

        wheels = view.agents(view.wheels)
        forward = F32(0.5) * (wheels[..., 0] + wheels[..., 1])
        heading = view.agents(view.headings)
        vx, vy = heading[..., 0] * forward, heading[..., 1] * forward
        bump = np.maximum(view.bumpers.max(axis=-1), F32(0.0))
        free = np.clip(F32(1.0) - bump, F32(0.0), F32(1.0))
        progress = np.clip((vx * goal_x + vy * goal_y) * self.inv_max_speed, F32(-1.0), F32(1.0)) * free
        reward = (
            self.progress_weight * progress
            - self.distance_weight * d * self.inv_diagonal
            - self.alarm_weight * np.minimum(alarm, F32(1.0))
        )
        if self.predators.size:
            q = poses[:, self.predators, None, :2] - p[:, None]  # (E, P, N, 2)
            captured = ((q[..., 0] * q[..., 0] + q[..., 1] * q[..., 1]) < self.c2).any(axis=1)
            reward = np.where(captured, reward - self.capture_penalty, reward)
        return reward


if __name__ == "__main__":
    total = sum(float(rewards.mean()) for _, rewards, *_ in random_steps(Aggregation(), 1024, 500, 100, low=-1.0))
    print(f"mean reward per agent-step over 100 steps of 1,024 worlds: {total / 100:.4f}")
