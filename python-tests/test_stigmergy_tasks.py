"""The tasks whose agents lay pheromone (`colony`, `coverage`, `alarm`) from Python: listed, their
spaces (the task's extra observation entry, the deposit rates), and their hand-written policies as
`colcos.baselines.Baseline`, which set the deposit rates too."""

from __future__ import annotations

import numpy as np
import pytest

import colcos
from colcos.baselines import Baseline, RandomPolicy
from colcos.vector import VecEnv

NEW = {"colony": (18, 4, "colony_ant"), "coverage": (17, 3, "coverage_walk"), "alarm": (18, 3, "alarm_flee")}


def test_listed_with_their_policies():
    assert set(NEW) <= set(colcos.tasks())
    policies = colcos.task_policies()
    for task, (_, _, name) in NEW.items():
        assert policies[name][0] == task


@pytest.mark.parametrize("task", sorted(NEW))
def test_spaces_and_baseline(task):
    obs_dim, width, name = NEW[task]
    env = colcos.parallel_env(task=task, max_cycles=20)
    obs, _ = env.reset(seed=0)
    agent = env.possible_agents[0]
    assert obs[agent].shape == (obs_dim,)
    assert env.action_space(agent).shape == (width,)
    venv = VecEnv(task, num_envs=3, max_cycles=50)
    venv.reset(seed=1)
    policy = Baseline(venv, name, seed=2)
    total = np.zeros((3, venv.num_agents))
    for _ in range(50):
        a = policy.act()
        assert a.shape == (3, venv.num_agents, width) and a.dtype == np.float32
        assert np.all(a[..., 2:] >= 0) and np.all(a[..., 2:] <= 1)
        _, rew, *_ = venv.step(a)
        total += rew
    # Team rewards: every agent of a world gets the same (no penalties by default).
    assert np.allclose(total, total[:, :1])
    # A sim behaviour works on these tasks too and lays nothing.
    assert np.all(Baseline(venv, "avoid").act()[..., 2:] == 0)
    with pytest.raises(colcos.ColcosError, match="takes no parameters"):
        Baseline(venv, name, speed=0.1)
    RandomPolicy(venv).act()


def test_colony_on_the_twin_has_the_carrying_entry():
    """The plants write the task's extra entry too: a twin's observations fill the simulator's space."""
    sim = colcos.parallel_env(task="colony", max_cycles=40)
    with colcos.parallel_env(task="colony", plant="twin", goto=False, max_cycles=40) as env:
        assert env.observation_space("robot_0") == sim.observation_space("robot_0")
        obs, _ = env.reset(seed=3)
        while env.agents:
            for o in obs.values():
                assert o.shape == (18,) and o[17] in (0.0, 1.0)
                assert env.observation_space("robot_0").contains(o)
            obs, *_ = env.step({a: np.array([0.5, 0.5, 1.0, 0.0], np.float32) for a in env.agents})
