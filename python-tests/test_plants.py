"""One suite over every plant a policy can run on: the simulator, the digital twin (started in this
process, over the rig's real wire formats on loopback) and a recorded rig run replayed. The same
spaces, dtypes and info keys everywhere; PettingZoo's own API check; a policy that drives at the walls
never leaves the arena, because the same safety shield runs in every plant."""

from __future__ import annotations

import numpy as np
import pytest
from pettingzoo.test import parallel_api_test

import colcos

STEPS = 100


@pytest.fixture(scope="module")
def rig_log(tmp_path_factory) -> str:
    """A twin run's rig log, for the replay plant."""
    path = tmp_path_factory.mktemp("rig") / "rig.mcap"
    env = colcos.parallel_env(task="aggregation", plant="twin", log=str(path), max_cycles=STEPS)
    env.reset(seed=1)
    while env.agents:
        env.step({a: np.ones(2, np.float32) for a in env.agents})
    env.close()
    return str(path)


@pytest.fixture(params=["sim", "twin", "replay"])
def make_env(request, rig_log):
    def make(**kw):
        if request.param == "replay":
            kw["log"] = rig_log
        return colcos.parallel_env(task="aggregation", plant=request.param, max_cycles=STEPS, **kw)

    make.plant = request.param
    return make


def test_spaces_dtypes_and_info_keys_are_those_of_the_simulator(make_env):
    sim = colcos.parallel_env(task="aggregation", max_cycles=STEPS)
    env = make_env()
    assert env.possible_agents == sim.possible_agents
    for a in env.possible_agents:
        assert env.observation_space(a) == sim.observation_space(a)
        assert env.action_space(a) == sim.action_space(a)
    assert env.state_space == sim.state_space
    obs, infos = env.reset(seed=2)
    step = env.step({a: env.action_space(a).sample() for a in env.agents})
    for o in list(obs.values()) + list(step[0].values()):
        assert o.dtype == np.float32 and env.observation_space("robot_0").contains(o)
    assert set(step[4]["robot_0"]) == {"shield_capped", "shield_walled"}
    assert env.state().dtype == np.float32 and env.state().shape == sim.state().shape
    env.close()


def test_pettingzoo_parallel_api(make_env):
    if make_env.plant == "twin":
        pytest.skip("paced to 20 ms a step; the API test's 1000 steps are covered on the simulator and the replay")
    parallel_api_test(make_env(), num_cycles=STEPS)


def test_a_policy_driving_at_the_walls_stays_inside(make_env):
    env = make_env()
    env.reset(seed=3)
    walled = 0
    width, height = _arena(env)
    while env.agents:
        _, _, _, _, infos = env.step({a: np.ones(2, np.float32) for a in env.agents})
        walled += sum(i["shield_walled"] for i in infos.values())
        poses = env.poses()
        if make_env.plant != "replay":  # replayed poses are the recording's
            assert (poses[:, 0] > 0).all() and (poses[:, 0] < width).all(), poses
            assert (poses[:, 1] > 0).all() and (poses[:, 1] < height).all(), poses
    if make_env.plant != "replay":  # the recorded robots need not come near a wall
        assert walled > 0, "the shield never turned an agent from a wall"
    info = env.plant_info()
    assert info["plant"] == make_env.plant
    if make_env.plant == "twin":
        assert info["shield_walled"] >= walled and info["stops"] == [] and info["goto_arrived"] == 5
    env.close()


def test_a_policy_that_raises_stops_the_robots_at_once():
    with pytest.raises(ZeroDivisionError):
        with colcos.parallel_env(task="aggregation", plant="twin", max_cycles=STEPS) as env:
            env.reset(seed=0)
            for _ in range(10):
                env.step({a: np.ones(2, np.float32) for a in env.agents})
            1 / 0  # noqa: B018
    assert env.plant_info()["commands_sent"] > 0


def test_plant_arguments_are_checked():
    with pytest.raises(colcos.TaskError, match="plant"):
        colcos.parallel_env(task="aggregation", plant="simulator")
    with pytest.raises(colcos.TaskError, match="tracker"):
        colcos.parallel_env(task="aggregation", plant="rig")
    with pytest.raises(colcos.TaskError, match="log"):
        colcos.parallel_env(task="aggregation", log="rig.mcap")
    with pytest.raises(colcos.ColcosError, match="nope.mcap"):
        colcos.parallel_env(task="aggregation", plant="replay", log="nope.mcap")


def _arena(env) -> tuple[float, float]:
    import tomllib

    text = colcos.parallel_env(task="aggregation")._core.scenario_toml()
    size = tomllib.loads(text)["screen"]["size"]
    return float(size[0]), float(size[1])


def test_a_twin_playing_its_own_scenario_runs_and_one_of_another_arena_is_refused(tmp_path):
    # The twin's tracker 150 ms late and its colour sensors at 70 % gain: the host still runs.
    with colcos.parallel_env(
        task="aggregation", plant="twin", goto=False, max_cycles=10,
        twin_scenario={"tracker.latency": 0.15, "sensor.gain": 0.7},
    ) as env:
        env.reset(seed=0)
        while env.agents:
            env.step({a: np.zeros(2, np.float32) for a in env.agents})
    with pytest.raises(colcos.TaskError, match=r"`twin_scenario\.dt`"):
        colcos.parallel_env(task="aggregation", plant="twin", twin_scenario={"dt": 0.04})
    with pytest.raises(colcos.TaskError, match=r"`twin_scenario\.tracker\.latncy`"):
        colcos.parallel_env(task="aggregation", plant="twin", twin_scenario={"tracker.latncy": 0.1})
    text = colcos.parallel_env(task="aggregation")._core.scenario_toml()
    other = tmp_path / "other.toml"
    other.write_text(text.replace('count = 1\nrole = "leader"', 'count = 2\nrole = "leader"', 1))
    with pytest.raises(colcos.TaskError, match=r"`twin_scenario\.robots`: 6 robots on the twin but 5"):
        colcos.parallel_env(task="aggregation", plant="twin", twin_scenario=str(other))
    with pytest.raises(colcos.TaskError, match="twin_scenario"):
        colcos.parallel_env(task="aggregation", twin_scenario={"tracker.latency": 0.1})
    with pytest.raises(colcos.ArgumentTypeError, match="twin_scenario"):
        colcos.parallel_env(task="aggregation", plant="twin", twin_scenario=3)


def test_the_twins_own_sensor_gain_reaches_a_host_reading_the_robots_sensors():
    # `[rig] sensors = "robot"`: the host takes the robots' telemetry, which the twin computes from the
    # frames the host shows with its own sensor model; a fifth of the gain reads markedly darker.
    host = colcos.parallel_env(task="aggregation")._core.scenario_toml() + '\n[rig]\nsensors = "robot"\n'

    def late_obs(gain: float) -> np.ndarray:
        seen = []
        with colcos.parallel_env(task="aggregation", scenario=host, plant="twin", goto=False, max_cycles=60,
                                 twin_scenario={"sensor.gain": gain}) as env:
            obs, _ = env.reset(seed=4)
            while env.agents:
                obs, *_ = env.step({a: np.zeros(2, np.float32) for a in env.agents})
                if obs:
                    seen.append(np.stack(list(obs.values())))
        return np.array(seen[-10:])

    bright, dark = late_obs(1500.0), late_obs(300.0)
    assert bright.max() > 0.05, bright.max(axis=(0, 1))
    assert dark.sum() < 0.75 * bright.sum(), (dark.mean(axis=(0, 1)), bright.mean(axis=(0, 1)))
