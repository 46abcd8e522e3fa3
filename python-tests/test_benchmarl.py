"""colcos's BenchMARL task family (colcos.benchmarl) through BenchMARL's own Experiment: one tiny
iteration of each algorithm family (on-policy MAPPO/IPPO, off-policy MASAC, value-based QMIX on the
discrete variant), every built-in task in the family, bad names and configs refused."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import pytest

benchmarl = pytest.importorskip("benchmarl")

import colcos  # noqa: E402
from colcos._core import TaskError  # noqa: E402
from colcos.benchmarl import ColcosTask, task  # noqa: E402

EXAMPLE = pathlib.Path(__file__).resolve().parent.parent / "examples" / "benchmarl_run.py"


def test_every_task_is_in_the_family_with_its_yaml():
    assert {m.name.lower() for m in ColcosTask} == set(colcos.tasks())
    for member in ColcosTask:
        t = member.get_from_yaml()
        assert t.config["max_steps"] == 500
        assert t.supports_continuous_actions() and t.supports_discrete_actions()


def test_unknown_names_and_keys_are_refused():
    with pytest.raises(TaskError, match="unknown BenchMARL task 'colcos/aggregatoin'.*colcos/aggregation"):
        task("colcos/aggregatoin")
    t = task("aggregation")
    t.config["max_step"] = 10
    with pytest.raises(TaskError, match=r"unknown config key\(s\) \['max_step'\]"):
        t.get_env_fun(2, True, 0, "cpu")()


def test_specs_match_the_env(tmp_path):
    t = task("colcos/aggregation")
    env = t.get_env_fun(3, True, 0, "cpu")()
    assert t.group_map(env) == {"robot": ["robot_0", "robot_1", "robot_2"]}
    obs = t.observation_spec(env)[("robot", "observation")]
    assert tuple(obs.shape) == (3, 17)
    assert t.state_spec(env) is not None
    assert tuple(t.action_spec(env)[("robot", "action")].shape) == (3, 2)


@pytest.mark.parametrize(
    "algorithm,extra",
    [("mappo", []), ("ippo", []), ("masac", []), ("qmix", ["--discrete"])],
)
def test_one_tiny_iteration_of_each_algorithm(tmp_path, algorithm, extra):
    out = tmp_path / algorithm
    cmd = [sys.executable, str(EXAMPLE), "--algorithm", algorithm, "--task", "aggregation", "--tiny", "--out", str(out), *extra]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["runs"][0]["final_return"] is not None
    assert set(summary["references"]) == {"aggregation_follower", "random"}
    # BenchMARL's own marl-eval JSON, which its plotting reads.
    assert list(out.rglob("*.json"))


def test_the_example_refuses_unknown_algorithms_and_tasks():
    for args in (["--algorithm", "mapo"], ["--task", "nope"]):
        done = subprocess.run([sys.executable, str(EXAMPLE), *args, "--tiny"], capture_output=True, text=True, timeout=120)
        assert done.returncode == 2 and args[1] in done.stderr, done.stderr
