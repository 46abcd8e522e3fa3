"""RLlib's ParallelPettingZooEnv over our parallel_env (run in its own venv: ray pins gymnasium)."""

from __future__ import annotations

import pytest

import colcos

pytest.importorskip("ray.rllib")

from ray.rllib.env.wrappers.pettingzoo_env import ParallelPettingZooEnv  # noqa: E402


@pytest.mark.parametrize("task", ["aggregation", "foraging", "trail"])
def test_parallel_pettingzoo_env(task):
    env = ParallelPettingZooEnv(colcos.parallel_env(task=task, max_cycles=40, render_mode="rgb_array"))
    obs, infos = env.reset(seed=0)
    assert set(obs) == set(env.get_agent_ids())
    steps = 0
    while True:
        actions = {a: env.action_space[a].sample() for a in obs}
        obs, rew, term, trunc, infos = env.step(actions)
        steps += 1
        assert all(env.observation_space[a].contains(o) for a, o in obs.items())
        if term["__all__"] or trunc["__all__"]:
            break
    assert steps <= 40
    frame = env.render()  # RLlib calls render(mode) with an argument
    assert frame.ndim == 3 and frame.shape[2] == 3


def test_rllib_env_checker():
    from ray.rllib.utils.pre_checks.env import check_multiagent_environments

    check_multiagent_environments(ParallelPettingZooEnv(colcos.parallel_env(task="aggregation", max_cycles=40)))
