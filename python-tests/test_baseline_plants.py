"""The hand-written behaviours as policies on a `parallel_env`: the same actions and returns as on a
one-world `VecEnv` of the same seed (simulator), and driving the robots of a digital twin."""

from __future__ import annotations

import numpy as np
import pytest

import colcos
from colcos.baselines import Baseline
from colcos.vector import VecEnv

STEPS = 60


def test_a_baseline_on_the_parallel_env_acts_as_on_a_one_world_vector_env():
    venv = VecEnv("aggregation", num_envs=1, max_cycles=STEPS, autoreset_mode="disabled")
    env = colcos.parallel_env(task="aggregation", max_cycles=STEPS)
    on_venv, on_env = Baseline(venv, "aggregation_follower", seed=3), Baseline(env, "aggregation_follower", seed=3)
    venv.reset(seed=11)
    env.reset(seed=11)
    total_v = total_e = 0.0
    for _ in range(STEPS):
        a_v, acts = on_venv.act(), on_env.actions()
        assert set(acts) == set(env.agents)
        np.testing.assert_array_equal(np.stack([acts[a] for a in env.agents]), a_v[0])
        _, rew_v, *_ = venv.step(a_v)
        _, rew, *_ = env.step(acts)
        total_v += float(rew_v.sum())
        total_e += sum(rew.values())
    assert total_e == pytest.approx(total_v, rel=1e-6)
    with pytest.raises(colcos.TaskError, match="parallel_env"):
        on_venv.actions()


def test_a_baseline_drives_the_twins_robots():
    with colcos.parallel_env(task="aggregation", plant="twin", goto=False, max_cycles=STEPS) as env:
        follower = Baseline(env, "aggregation_follower")
        env.reset(seed=5)
        start = env.poses().copy()
        while env.agents:
            acts = follower.actions()
            assert all(np.isfinite(a).all() for a in acts.values())
            env.step(acts)
        followers = list(env._spec["agent_robots"])
        moved = np.linalg.norm(env.poses()[followers, :2] - start[followers, :2], axis=1)
        assert moved.min() > 0.01, f"a follower moved only {moved.min()} m"
