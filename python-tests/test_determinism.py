"""Determinism over 1,000 steps (PettingZoo's seed tests only look at the first step): identical
trajectories across 1, 2 and 4 threads, and between the batched core and `parallel_env`."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

import colcos
from colcos.vector import VecEnv

STEPS = 1000


def batched_trajectory(task: str, threads: int, num_envs: int = 8, seed: int = 3) -> tuple[str, np.ndarray, np.ndarray]:
    """Digest of every observation, reward and flag over STEPS random steps; world 0's obs and rewards."""
    v = VecEnv(task, num_envs=num_envs, seed=seed, num_threads=threads, max_cycles=300)
    rng = np.random.default_rng(11)
    h = hashlib.sha256()
    obs, _ = v.reset(seed=seed)
    h.update(obs.tobytes())
    w0_obs, w0_rew = [obs[0].copy()], []
    for _ in range(STEPS):
        a = rng.uniform(-1, 1, size=(num_envs, v.num_agents, 2)).astype(np.float32)
        obs, rew, term, trunc, _ = v.step(a)
        for arr in (obs, rew, term, trunc, v.state):
            h.update(arr.tobytes())
        w0_obs.append(obs[0].copy())
        w0_rew.append(rew[0].copy())
    return h.hexdigest(), np.stack(w0_obs), np.stack(w0_rew)


@pytest.mark.parametrize("task", ["aggregation", "foraging", "trail"])
def test_thread_count_does_not_matter(task):
    digests = {t: batched_trajectory(task, t)[0] for t in (1, 2, 4)}
    assert len(set(digests.values())) == 1, digests


@pytest.mark.parametrize("task", ["aggregation", "foraging"])
def test_batched_equals_parallel_env(task):
    """World 0 of the batch and a parallel_env with the same seed and actions agree over 1,000 steps,
    across episode ends (next-step autoreset in the batch, reset() in the parallel env)."""
    num_envs, seed = 4, 3
    _, b_obs, b_rew = batched_trajectory(task, 2, num_envs=num_envs, seed=seed)
    env = colcos.parallel_env(task=task, max_cycles=300)
    names = env.possible_agents
    rng = np.random.default_rng(11)
    obs, _ = env.reset(seed=seed)
    np.testing.assert_array_equal(np.stack([obs[a] for a in names]), b_obs[0])
    done = False
    for k in range(STEPS):
        a = rng.uniform(-1, 1, size=(num_envs, len(names), 2)).astype(np.float32)
        if done:
            obs, _ = env.reset()
            done = False
            rew = dict.fromkeys(names, 0.0)
            live = names
        else:
            live = list(env.agents)
            obs, rew, term, trunc, _ = env.step({n: a[0, i] for i, n in enumerate(names) if n in live})
            done = not env.agents
        got = np.stack([obs[n] if n in obs else b_obs[k + 1][i] for i, n in enumerate(names)])
        np.testing.assert_array_equal(got, b_obs[k + 1], err_msg=f"step {k}")
        for i, n in enumerate(names):
            if n in rew:
                assert rew[n] == pytest.approx(float(b_rew[k][i]), abs=0), f"step {k} {n}"


def test_different_seeds_differ():
    a = batched_trajectory("aggregation", 2, num_envs=2, seed=1)[0]
    b = batched_trajectory("aggregation", 2, num_envs=2, seed=2)[0]
    assert a != b
