"""`colcos.rig.identify` on a rig log with known truths (bridge/tests/data/identify: three robots with
their own wheel scales, latency and sensor gain, recorded by a Rust test over printed stripes), its
refusals, and `truth=` giving a twin's robots hidden values."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import colcos
import colcos.rig

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

FIXTURE = Path(__file__).resolve().parents[1] / "bridge" / "tests" / "data" / "identify"


def test_the_fixture_identifies_to_its_truth_and_the_overlay_is_written(tmp_path):
    out = tmp_path / "fit.toml"
    fit = colcos.rig.identify(FIXTURE / "rig.mcap", scenario=FIXTURE / "scenario.toml", out=out)
    truth = {r["index"]: r for r in tomllib.loads((FIXTURE / "truth.toml").read_text())["robot"]}
    assert len(fit.robots) == 3 and fit.duration > 9.0 and fit.pose_delay == 0.0
    for robot in fit.robots:
        t = truth[robot.index]
        assert robot.wheel_scale is not None, robot.why
        for (value, sd), want in zip(robot.wheel_scale, t["wheel_scale"], strict=True):
            assert abs(value - want) / want < 0.05 and 0.0 < sd < 0.05
        assert robot.sensor_gain is not None and robot.sensor_offset is not None, robot.why
        gain, sd = robot.sensor_gain
        assert abs(gain - t["sensor_gain"]) / t["sensor_gain"] < 0.1 and sd >= 0.0
        assert abs(robot.sensor_offset[0] - t["sensor_offset"]) < 100.0
        assert robot.readings_used >= 20 and robot.readings >= robot.readings_used
    written = tomllib.loads(out.read_text())
    assert written == tomllib.loads(fit.overlay)
    entries = {r["index"]: r for r in written["robot"]}
    assert abs(entries[0]["sensor_gain"] - 0.8) < 0.08 and "sensor_gain_sd" in entries[0]
    assert written["identified"]["scenario"] == "identify"


def test_bad_logs_and_arguments_are_refused_with_the_reason(tmp_path):
    other = tmp_path / "other.toml"
    other.write_text((FIXTURE / "scenario.toml").read_text().replace('name = "identify"', 'name = "other"'))
    with pytest.raises(colcos.ColcosError, match=r'scenario "identify" with 3 robots, not "other"'):
        colcos.rig.identify(FIXTURE / "rig.mcap", scenario=other)
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not a log")
    with pytest.raises(colcos.ColcosError, match="no tick records"):
        colcos.rig.identify(junk, scenario=FIXTURE / "scenario.toml")
    with pytest.raises(OSError, match="missing.mcap"):
        colcos.rig.identify(tmp_path / "missing.mcap", scenario=FIXTURE / "scenario.toml")
    with pytest.raises(colcos.ScenarioError):
        colcos.rig.identify(FIXTURE / "rig.mcap", scenario=tmp_path / "missing.toml")
    with pytest.raises(colcos.ArgumentTypeError, match="log must be a path"):
        colcos.rig.identify(3, scenario=FIXTURE / "scenario.toml")  # type: ignore[arg-type]
    with pytest.raises(colcos.ColcosError, match="pose_delay = -1"):
        colcos.rig.identify(FIXTURE / "rig.mcap", scenario=FIXTURE / "scenario.toml", pose_delay=-1.0)
    assert not (tmp_path / "fit.toml").exists()


def test_a_twin_with_a_truth_drives_its_robots_on_their_hidden_wheels(tmp_path):
    # Every robot's wheels at half speed on the twin: the same commands move them half as far.
    text = colcos.parallel_env(task="aggregation")._core.scenario_toml()
    robots = len(colcos.parallel_env(task="aggregation")._core.poses(0))
    truth = tmp_path / "truth.toml"
    truth.write_text("".join(f"[[robot]]\nindex = {i}\nwheel_scale = [0.5, 0.5]\n" for i in range(robots)))

    def moved(**kw) -> float:
        with colcos.parallel_env(task="aggregation", scenario=text, plant="twin", goto=False, max_cycles=30, **kw) as env:
            env.reset(seed=0)
            start = env._core.poses(0)[:, :2].copy()
            while env.agents:
                env.step({a: np.full(2, 0.3, np.float32) for a in env.agents})
            return float(np.median(np.linalg.norm(env._core.poses(0)[:, :2] - start, axis=1)))

    full, half = moved(), moved(truth=truth)
    assert full > 0.01, full
    assert 0.3 < half / full < 0.7, (half, full)
    with pytest.raises(colcos.TaskError, match="truth"):
        colcos.parallel_env(task="aggregation", truth=truth)
    with pytest.raises(colcos.ArgumentTypeError, match="truth must be a path"):
        colcos.parallel_env(task="aggregation", plant="twin", truth=3)
