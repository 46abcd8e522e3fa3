"""Pheromone actions from Python: a group's `deposit_actions` widen every agent's action (wheels, then
one rate in [0, 1] per deposit action; discrete: 6 motions x lay bits), an agent that lays leaves a
trail on the field it names and one that does not leaves none, and bad widths are refused by name."""

from __future__ import annotations

import numpy as np
import pytest

import colcos

LAY = '{ pheromone = "red", kernel = { shape = "disc", radius = 0.01 }, max_rate = 6.0 }'


def _scenario() -> str:
    text = colcos.default_scenario("trail")
    old = next(line for line in text.splitlines() if line.startswith("deposits = "))
    return text.replace(old, f"deposit_actions = [{LAY}]")


def test_the_action_space_gains_one_rate_per_deposit_action():
    env = colcos.parallel_env(task="trail", scenario=_scenario())
    space = env.action_space("robot_0")
    assert space.shape == (3,)
    assert list(space.low) == [-1.0, -1.0, 0.0] and list(space.high) == [1.0, 1.0, 1.0]
    discrete = colcos.parallel_env(task="trail", scenario=_scenario(), continuous=False)
    assert discrete.action_space("robot_0").n == 12


@pytest.mark.parametrize("rate", [0.0, 1.0])
def test_agents_lay_what_they_choose(rate):
    v = colcos.vector.VecEnv(task="trail", scenario=_scenario(), num_envs=2, seed=3)
    v.reset(seed=3)
    a = np.zeros((2, v.num_agents, 3), np.float32)
    a[..., :2] = 0.5
    a[..., 2] = rate
    for _ in range(50):
        v.step(a)
    img = v.render(0, width=320)
    red_only = (img[..., 0].astype(int) - img[..., 2].astype(int)) > 60
    assert red_only.any() == (rate > 0.0)


def test_actions_of_the_wrong_width_are_refused():
    env = colcos.parallel_env(task="trail", scenario=_scenario())
    env.reset(seed=0)
    with pytest.raises(colcos.ActionError, match=r"shape \(3,\)"):
        env.step({a: np.zeros(2, np.float32) for a in env.agents})
    with pytest.raises(colcos.ActionError, match="must be finite"):
        env.step({a: np.array([0, 0, np.nan], np.float32) for a in env.agents})
