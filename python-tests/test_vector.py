"""The batched VecEnv: zero-copy views, autoreset modes, partial resets, Gymnasium adapter, baselines."""

from __future__ import annotations

import numpy as np
import pytest

import colcos
from colcos.baselines import Baseline, RandomPolicy
from colcos.gymnasium_vector import ColcosVectorEnv
from colcos.vector import VecEnv


def test_views_are_zero_copy():
    v = VecEnv("aggregation", num_envs=3)
    obs, _ = v.reset(seed=0)
    assert obs.shape == (3, 3, 17) and obs.dtype == np.float32
    assert not obs.flags.owndata  # a view of Rust memory
    before = obs.copy()
    obs2, rew, term, trunc, _ = v.step(np.ones((3, 3, 2), np.float32))
    assert obs2 is obs or np.shares_memory(obs2, obs)
    assert not np.array_equal(before, obs)  # the same memory was overwritten in place
    assert rew.shape == (3, 3) and term.dtype == np.bool_ and trunc.dtype == np.bool_
    assert v.state is not None and v.state.shape == (3, 4 * 5 + 1)


def _still(num_envs: int, max_cycles: int, autoreset_mode: str = "next_step") -> tuple[VecEnv, np.ndarray]:
    """A batch of `aggregation` reset with seed 0, and still wheels for its 3 agents."""
    v = VecEnv("aggregation", num_envs=num_envs, max_cycles=max_cycles, autoreset_mode=autoreset_mode)
    v.reset(seed=0)
    return v, np.zeros((num_envs, 3, 2), np.float32)


def test_next_step_autoreset():
    v, a = _still(2, 5)
    for _ in range(4):
        _, _, _, trunc, _ = v.step(a)
        assert not trunc.any()
    _, _, _, trunc, _ = v.step(a)
    assert trunc.all()
    obs, rew, term, trunc, _ = v.step(a)  # the reset step
    assert not trunc.any() and not term.any() and (rew == 0).all()
    assert v.episode_steps(0) == 0


def test_same_step_autoreset():
    v, a = _still(2, 3, "same_step")
    v.step(a)
    v.step(a)
    obs, _, _, trunc, infos = v.step(a)
    assert trunc.all() and infos["_final_obs"].all()
    assert v.episode_steps(0) == 0
    assert not np.array_equal(infos["final_obs"], obs)


def test_disabled_autoreset_and_partial_reset():
    v, a = _still(3, 2, "disabled")
    v.step(a)
    v.step(a)
    with pytest.raises(colcos.StateError, match="world 0"):
        v.step(a)
    keep = v.obs[1].copy()
    v.reset(options={"reset_mask": np.array([True, False, True])})
    np.testing.assert_array_equal(v.obs[1], keep)  # world 1 untouched
    with pytest.raises(colcos.StateError, match="world 1"):
        v.step(a)
    v.reset(options={"reset_mask": np.array([False, True, False])})
    v.step(a)


def test_reset_with_seed_reproduces():
    v = VecEnv("trail", num_envs=2)
    first = v.reset(seed=5)[0].copy()
    v.step(np.full((2, 4, 2), 0.5, np.float32))
    again = v.reset(seed=5)[0]
    np.testing.assert_array_equal(first, again)


def test_gymnasium_vector_env():
    from gymnasium.vector import AutoresetMode

    env = ColcosVectorEnv("aggregation", num_envs=4, max_cycles=10)
    assert env.num_envs == 12 and env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    obs, _ = env.reset(seed=0)
    assert obs.shape == (12, 17) and env.single_observation_space.contains(obs[0])
    for _ in range(12):
        obs, rew, term, trunc, _ = env.step(env.action_space.sample())
        assert obs.shape == (12, 17) and rew.shape == (12,)
    env.close()


def test_baseline_beats_random_on_trail():
    v = VecEnv("trail", num_envs=8, max_cycles=400)
    def run(policy):
        v.reset(seed=1)
        total = 0.0
        for _ in range(400):
            _, rew, _, _, _ = v.step(policy.act())
            total += float(rew.sum())
        return total / (8 * 4)
    follow = run(Baseline(v, "follow", channel="b", speed=0.1, sensitivity=0.5, threshold=0.08))
    rand = run(RandomPolicy(v, seed=0))
    assert follow > rand + 1.0, (follow, rand)


def test_baseline_errors():
    v = VecEnv("aggregation", num_envs=2)
    with pytest.raises(colcos.ScenarioError, match="unknown behaviour"):
        Baseline(v, "teleport")
    with pytest.raises(colcos.ScenarioError, match="speed"):
        Baseline(v, "wander", speed=-1.0)


def test_render():
    v = VecEnv("foraging", num_envs=2)
    img = v.render(1, width=320)
    assert img.dtype == np.uint8 and img.shape[1] == 320 and img.shape[2] == 3
    assert img.max() > 0
