"""Reset options, render sizes, patches and the native buffers as documented: a misspelt option key of
the vector env is refused by name instead of being ignored (PettingZoo envs take any, as PettingZoo's
API test expects), `render(width=)` gives an image of that width, patches reach the Gymnasium vector
env, and the native buffers are read-only."""

from __future__ import annotations

import numpy as np
import pytest

import colcos


def test_a_misspelt_reset_option_is_refused():
    v = colcos.vector.VecEnv("aggregation", num_envs=2)
    with pytest.raises(colcos.TaskError, match="reset_msk"):
        v.reset(options={"reset_msk": np.array([True, False])})
    v.reset(options={"reset_mask": np.array([True, False])})
    with pytest.raises(colcos.TaskError, match="unknown reset option"):
        v.reset(options={"seed": 3})


def test_render_takes_a_width():
    env = colcos.parallel_env(task="aggregation", render_mode="rgb_array")
    env.reset(seed=0)
    assert env.render(width=320).shape[1] == 320
    assert env.render().shape[1] == 640


def test_patches_reach_the_gymnasium_vector_env():
    from colcos.gymnasium_vector import ColcosVectorEnv

    env = ColcosVectorEnv("aggregation", num_envs=2, patch=8)
    _, infos = env.reset(seed=0)
    assert infos["patch"].shape == (2 * 3, 8, 8, 3) and infos["patch"].dtype == np.uint8
    _, _, _, _, infos = env.step(env.action_space.sample())
    assert infos["patch"].shape == (6, 8, 8, 3)


def test_the_native_buffers_are_read_only():
    v = colcos.vector.VecEnv("aggregation", num_envs=2)
    v.reset(seed=0)
    for a in (v.obs, v.rewards, v.terminated, v.truncated):
        with pytest.raises(ValueError, match="read-only"):
            a[...] = 0
