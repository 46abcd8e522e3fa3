"""`rally` (examples/tasks/rally.py), the task written only in Python: a hidden spot drawn per world
and per episode, a team reward for the share of agents on it, and a call that carries the news."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from example_modules import load_task

import colcos

rally = load_task("rally")


def test_the_spot_is_drawn_per_world_and_episode_inside_the_margins():
    task = rally.Rally()
    env = colcos.vector.VecEnv(task, num_envs=8, max_cycles=20)
    env.reset(seed=3)
    first = task.spots.copy()
    w, h = tomllib.loads(rally.SCENARIO)["screen"]["size"]
    assert np.all(first >= 0.15) and np.all(first[:, 0] <= w - 0.15) and np.all(first[:, 1] <= h - 0.15)
    assert len({tuple(p) for p in first.tolist()}) == 8  # a spot of its own in every world
    zero = np.zeros((8, env.num_agents, 3), np.float32)
    for _ in range(21):  # every world's episode ends at step 20 and the next begins
        env.step(zero)
    assert not np.any(np.all(task.spots == first, axis=1)), "a world kept its spot into the next episode"
    again = rally.Rally()
    colcos.vector.VecEnv(again, num_envs=8, max_cycles=20).reset(seed=3)
    np.testing.assert_array_equal(again.spots, first)  # the same seed, the same spots


def test_reward_and_observation_follow_the_agents_on_the_spot():
    task = rally.Rally(spot_radius=0.3)  # wide, so that some agents stand on it
    env = colcos.vector.VecEnv(task, num_envs=16, max_cycles=200)
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(0)
    seen_on = 0
    for _ in range(100):
        act = rng.uniform([-1, -1, 0], [1, 1, 1], (16, env.num_agents, 3)).astype(np.float32)
        obs, rew, _, _, infos = env.step(act)
        on = obs[..., 17] > 0.5
        np.testing.assert_array_equal(infos["task"]["on_spot"], on.sum(axis=1))
        np.testing.assert_allclose(rew, np.broadcast_to(on.mean(axis=1, keepdims=True), rew.shape), atol=1e-7)
        seen_on += int(on.sum())
    assert seen_on > 0


def _team_return(policy, call: bool, worlds: int = 16, steps: int = 1500) -> float:
    env = colcos.vector.VecEnv(rally.Rally(), num_envs=worlds, max_cycles=steps)
    obs, _ = env.reset(seed=0)
    total = np.zeros(worlds)
    for _ in range(steps):
        act = policy(obs)
        if not call:
            act[..., 2] = 0.0
        obs, rew, *_ = env.step(act)
        total += rew.mean(axis=1)
    return float(total.mean())


def test_the_call_is_what_the_hand_written_policy_lives_on():
    rng = np.random.default_rng(0)
    randomly = _team_return(lambda o: rng.uniform([-1, -1, 0], [1, 1, 1], (*o.shape[:2], 3)).astype(np.float32), True)
    calling = _team_return(rally.RallyCall(seed=0).act, True)
    silent = _team_return(rally.RallyCall(seed=0).act, False)
    print(f"team return: calling {calling:.1f}, silent {silent:.1f}, random {randomly:.1f}")
    assert calling > 1.5 * silent > 2 * randomly, (calling, silent, randomly)


def test_bad_parameters_are_refused_by_name():
    with pytest.raises(ValueError, match="spot_radius"):
        rally.Rally(spot_radius=0.0)
    env = colcos.vector.VecEnv(rally.Rally(margin=0.5), num_envs=2)
    with pytest.raises(colcos.TaskHookError, match="reset.*margin 0.5"):
        env.reset(seed=0)
