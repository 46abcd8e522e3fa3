"""Bad input from Python raises a clear exception naming what is wrong; nothing panics."""

from __future__ import annotations

import numpy as np
import pytest

import colcos
from colcos.vector import VecEnv


def test_unknown_task():
    with pytest.raises(colcos.TaskError, match="unknown task \"nope\".*aggregation"):
        colcos.parallel_env(task="nope")


def test_unknown_task_parameter_names_the_key():
    with pytest.raises(colcos.TaskError, match="aggregation.*capture_distanse"):
        colcos.parallel_env(task="aggregation", capture_distanse=0.1)


def test_invalid_task_parameter_value():
    with pytest.raises(colcos.TaskError, match="aggregation.capture_distance"):
        colcos.parallel_env(task="aggregation", capture_distance=-1.0)


def test_unknown_scenario_key_names_the_key():
    text = colcos.default_scenario("aggregation").replace("duration = 20.0", "duration = 20.0\ndurashun = 3")
    with pytest.raises(colcos.ScenarioError, match="durashun"):
        colcos.parallel_env(task="aggregation", scenario=text)


def test_missing_scenario_file():
    with pytest.raises(colcos.ScenarioError, match="no_such_file.toml"):
        colcos.parallel_env(task="aggregation", scenario="no_such_file.toml")


def test_scenario_without_the_task_roles():
    text = colcos.default_scenario("trail")
    with pytest.raises(colcos.TaskError, match="follower"):
        colcos.parallel_env(task="aggregation", scenario=text)


def _nan_for_robot_1(agents: list[str]) -> dict[str, np.ndarray]:
    acts = {a: np.zeros(2, np.float32) for a in agents}
    acts["robot_1"] = np.array([np.nan, 0.0], np.float32)
    return acts


@pytest.mark.parametrize(
    ("continuous", "actions", "match"),
    [
        # An agent that does not exist.
        (True, lambda agents: {"robot_99": np.zeros(2, np.float32)}, "unknown agent 'robot_99'"),
        # A non-finite action names its agent.
        (True, _nan_for_robot_1, "robot_1.*finite"),
        # The wrong shape.
        (True, lambda agents: {"robot_0": np.zeros(3, np.float32)}, "robot_0"),
        # A discrete action out of range.
        (False, lambda agents: {"robot_0": 17}, "robot_0 is 17"),
    ],
)
def test_bad_actions_name_the_agent(continuous, actions, match):
    env = colcos.parallel_env(continuous=continuous)
    env.reset(seed=0)
    with pytest.raises(colcos.ActionError, match=match):
        env.step(actions(env.agents))


def test_step_before_reset():
    env = colcos.parallel_env()
    with pytest.raises(colcos.StateError, match="reset"):
        env.step({})


def test_vec_wrong_shape_and_nan():
    v = VecEnv("aggregation", num_envs=4)
    v.reset(seed=0)
    with pytest.raises(colcos.ActionError, match=r"expected \(4, 3, 2\)"):
        v.step(np.zeros((4, 2, 2), np.float32))
    a = np.zeros((4, 3, 2), np.float32)
    a[2, 1, 0] = np.inf
    with pytest.raises(colcos.ActionError, match="world 2, agent robot_1"):
        v.step(a)
    with pytest.raises(colcos.ActionError, match="reset_mask"):
        v.reset(options={"reset_mask": np.ones(3, bool)})


def test_bad_constructor_arguments():
    with pytest.raises(colcos.TaskError, match="num_envs"):
        VecEnv("aggregation", num_envs=0)
    with pytest.raises(colcos.TaskError, match="autoreset_mode"):
        VecEnv("aggregation", autoreset_mode="sometimes")
    with pytest.raises(colcos.TaskError, match="max_cycles"):
        colcos.parallel_env(max_cycles=0)
    with pytest.raises(colcos.TaskError, match="render_mode"):
        colcos.parallel_env(render_mode="ascii")


def test_errors_are_value_errors():
    assert issubclass(colcos.ActionError, ValueError)
    assert issubclass(colcos.ScenarioError, colcos.ColcosError)
