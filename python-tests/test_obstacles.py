"""Obstacles from Python: the trail task's maze (walls the bumpers see), its refusal without obstacles,
and the walls drawn in the rendered frame."""

from __future__ import annotations

import numpy as np
import pytest

import colcos
from colcos.vector import VecEnv

BUMPERS = slice(12, 15)  # observation entries 12-14: the three bumpers


def test_maze_walls_reach_the_bumpers():
    v = VecEnv("trail", num_envs=2, maze=True, render_mode="rgb_array")
    obs, _ = v.reset(seed=1)
    n = obs.shape[1]
    seen = 0.0
    for _ in range(200):
        obs, *_ = v.step(np.tile(np.array([1.0, 0.8], np.float32), (2, n, 1)))
        seen = max(seen, float(obs[:, :, BUMPERS].max()))
    assert seen > 0.5, seen
    frame = v.render()
    # The walls' amber outline (255, 176, 0) is in the rendered image.
    amber = np.all(frame == np.array([255, 176, 0], np.uint8), axis=-1)
    assert amber.sum() > 100


def test_maze_needs_obstacles():
    plain = colcos.default_scenario("trail")
    with pytest.raises(colcos.TaskError, match="maze"):
        VecEnv("trail", scenario=plain, maze=True)
