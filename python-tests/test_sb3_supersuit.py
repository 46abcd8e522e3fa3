"""Stable-Baselines3 PPO through SuperSuit's PettingZoo -> vector env conversion, and through our
own SB3 VecEnv adapter."""

from __future__ import annotations

import numpy as np
import pytest

import colcos

ss = pytest.importorskip("supersuit")
sb3 = pytest.importorskip("stable_baselines3")


def test_supersuit_to_sb3_ppo():
    env = colcos.parallel_env(task="aggregation", max_cycles=100)
    venv = ss.pettingzoo_env_to_vec_env_v1(env)
    venv = ss.concat_vec_envs_v1(venv, 2, num_cpus=0, base_class="stable_baselines3")
    model = sb3.PPO("MlpPolicy", venv, n_steps=256, batch_size=256, n_epochs=2, device="cpu", verbose=0)
    model.learn(total_timesteps=3000)
    obs = venv.reset()
    action, _ = model.predict(obs, deterministic=True)
    assert action.shape == (6, 2)
    venv.close()


def test_supersuit_black_death_on_foraging():
    """Foraging agents terminate on arrival: SuperSuit needs black_death to keep the agent set fixed."""
    env = ss.black_death_v3(colcos.parallel_env(task="foraging", max_cycles=100))
    venv = ss.concat_vec_envs_v1(ss.pettingzoo_env_to_vec_env_v1(env), 1, num_cpus=0, base_class="stable_baselines3")
    model = sb3.PPO("MlpPolicy", venv, n_steps=128, batch_size=128, n_epochs=1, device="cpu", verbose=0)
    model.learn(total_timesteps=1000)
    venv.close()


def test_our_sb3_adapter_ppo():
    from stable_baselines3.common.env_checker import check_env  # noqa: F401  (single-env checker, not for VecEnv)

    from colcos.sb3 import ColcosSB3VecEnv

    venv = ColcosSB3VecEnv("aggregation", num_envs=8, max_cycles=64)
    obs = venv.reset()
    assert obs.shape == (24, 17)
    model = sb3.PPO("MlpPolicy", venv, n_steps=64, batch_size=512, n_epochs=2, device="cpu", verbose=0)
    model.learn(total_timesteps=24 * 64 * 2)
    obs, rew, done, infos = venv.step(np.zeros((24, 2), np.float32))
    assert rew.shape == (24,) and done.dtype == np.bool_
