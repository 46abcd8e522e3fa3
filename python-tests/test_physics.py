"""`physics=`: the robots' contact solver chosen from Python, over the scenario's."""

from __future__ import annotations

import numpy as np
import pytest

import colcos
from colcos.vector import VecEnv


def _rollout(**kw) -> np.ndarray:
    env = VecEnv(task="aggregation", num_envs=4, seed=3, num_threads=1, max_cycles=200, **kw)
    obs, _ = env.reset(seed=3)
    rng = np.random.default_rng(0)
    seen = []
    for _ in range(150):
        actions = rng.uniform(-1, 1, size=(env.num_envs, env.num_agents, 2)).astype(np.float32)
        obs, *_ = env.step(actions)
        seen.append(np.array(obs))
    env.close()
    return np.stack(seen)


def test_the_solver_is_chosen_from_python():
    default, rapier, discs = _rollout(), _rollout(physics="rapier"), _rollout(physics="Discs")
    # The tasks' scenarios say rapier; the disc solver moves robots in contact otherwise.
    np.testing.assert_array_equal(default, rapier)
    assert not np.array_equal(rapier, discs)
    env = colcos.parallel_env(task="trail", physics="discs", max_cycles=5)
    env.reset(seed=1)
    env.step({a: env.action_space(a).sample() for a in env.agents})
    env.close()


def test_an_unknown_solver_is_refused_by_name():
    with pytest.raises(colcos.TaskError, match=r"physics must be one of \('rapier', 'discs'\).*'box2d'"):
        VecEnv(task="aggregation", physics="box2d")
    with pytest.raises(colcos.TaskError, match="physics"):
        colcos.parallel_env(task="aggregation", physics=3)
