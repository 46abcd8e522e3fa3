"""colcos's BenchMARL task family (colcos.benchmarl) through BenchMARL's own Experiment: one tiny
iteration of each algorithm family (on-policy MAPPO/IPPO, off-policy MASAC, value-based QMIX on the
discrete variant), every built-in task in the family, bad names and configs refused."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

benchmarl = pytest.importorskip("benchmarl")

import colcos  # noqa: E402
from colcos._core import TaskError  # noqa: E402
from colcos.baselines import Baseline  # noqa: E402
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
    [("mappo", []), ("ippo", ["--scenario"]), ("masac", []), ("qmix", ["--discrete"])],
)
def test_one_tiny_iteration_of_each_algorithm(tmp_path, algorithm, extra):
    out = tmp_path / algorithm
    # IPPO trains on a scenario file in place of the task's own: a smaller arena.
    small = tmp_path / "small_arena.toml"
    small.write_text(colcos.default_scenario("aggregation").replace("size = [1.439, 0.809]", "size = [0.72, 0.405]"))
    extra = [a for e in extra for a in ((e, str(small)) if e == "--scenario" else (e,))]
    cmd = [sys.executable, str(EXAMPLE), "--algorithm", algorithm, "--task", "aggregation", "--tiny", "--out", str(out), *extra]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["runs"][0]["final_return"] is not None
    assert set(summary["references"]) == {"aggregation_follower", "random"}
    # The trained policy and the follower on the same held-out episodes, through colcos's own env.
    held = summary["runs"][0]["held_out"]
    assert np.isfinite(held["mean"]) and held["se"] > 0
    assert (summary["held_out"]["worlds"], summary["held_out"]["seed"]) == (4, 777)
    assert set(summary["held_out"]["references"]) == {"aggregation_follower"}
    # BenchMARL's own marl-eval JSON, which its plotting reads.
    assert list(out.rglob("*.json"))
    if algorithm in ("mappo", "qmix"):
        # The checkpoint reloads as the same policy: the same held-out return, on the task's scenario
        # given as a file too.
        checkpoint = summary["runs"][0]["checkpoint"]
        scenario = tmp_path / "aggregation.toml"
        scenario.write_text(colcos.default_scenario("aggregation"))
        again = subprocess.run([sys.executable, str(EXAMPLE), "--evaluate", checkpoint, "--scenario", str(scenario),
                                "--holdout-worlds", "4"], capture_output=True, text=True, timeout=600)  # fmt: skip
        assert again.returncode == 0, again.stderr[-3000:]
        assert f"held-out episodes of {scenario} (seed 777): {held['mean']:.1f} ± {held['se']:.1f}" in again.stdout, again.stdout
        assert "aggregation_follower:" in again.stdout
    if algorithm == "ippo":
        # The run trained and was scored on the file: its checkpoint remembers it, and its follower
        # reference is the follower's return there, not on the task's own scenario.
        assert summary["scenario"] == str(small)
        again = subprocess.run([sys.executable, str(EXAMPLE), "--evaluate", summary["runs"][0]["checkpoint"], "--holdout-worlds", "4"],
                               capture_output=True, text=True, timeout=600)  # fmt: skip
        assert again.returncode == 0, again.stderr[-3000:]
        assert f"held-out episodes of {small} (seed 777): {held['mean']:.1f} ± {held['se']:.1f}" in again.stdout, again.stdout
        example = _example()
        follower = summary["held_out"]["references"]["aggregation_follower"]["mean"]
        on = [example.episode_returns("aggregation", lambda v: Baseline(v, "aggregation_follower").act, 20, 4, 777, scenario=s)
              for s in (str(small), None)]  # fmt: skip
        assert follower == round(float(on[0].mean()), 2) and abs(on[0].mean() - on[1].mean()) > 0.5, on
        # The transfer study takes the checkpoint as one more policy, on the simulator and the twin.
        study = tmp_path / "transfer"
        done = subprocess.run([sys.executable, str(EXAMPLE.parent / "transfer.py"), "--variants", "--benchmarl",
                               f"ippo={summary['runs'][0]['checkpoint']}", "--episode", "20", "--eval-worlds", "2",
                               "--twin-episodes", "1", "--out", str(study)], capture_output=True, text=True, timeout=600)  # fmt: skip
        assert done.returncode == 0, done.stderr[-3000:]
        returns = json.loads((study / "result.json").read_text())["returns"]
        assert set(returns) == {"ippo", "hand-written", "standing still"}
        assert [len(returns["ippo"][c]) for c in ("sim_nominal", "sim_truth", "twin")] == [2, 2, 1]
        assert not list(study.glob("*-s0"))  # no PPO policy trained


def test_the_example_refuses_unknown_algorithms_tasks_and_bad_files(tmp_path):
    for args in (["--algorithm", "mapo"], ["--task", "nope"]):
        done = subprocess.run([sys.executable, str(EXAMPLE), *args, "--tiny"], capture_output=True, text=True, timeout=120)
        assert done.returncode == 2 and args[1] in done.stderr, done.stderr
    bad = tmp_path / "bad.toml"
    bad.write_text('[arena]\nwidth = "x"\n')
    for args, text in ((["--scenario", "x.toml"], "--scenario 'x.toml': no such file"),
                       (["--scenario", str(bad)], f"--scenario {str(bad)!r}: "),
                       (["--evaluate", "no/such.pt"], "--evaluate 'no/such.pt': no such checkpoint file")):  # fmt: skip
        done = subprocess.run([sys.executable, str(EXAMPLE), *args], capture_output=True, text=True, timeout=120)
        assert done.returncode == 2 and text in done.stderr, done.stderr


def _example():
    import importlib.util

    spec = importlib.util.spec_from_file_location("benchmarl_run", EXAMPLE)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_ppo_settings_replace_benchmarls_defaults_for_on_policy_runs(tmp_path):
    import argparse

    example = _example()
    args = argparse.Namespace(algorithm="mappo", frames=100_000, discrete=False, lr=None, eval_episodes=8, worlds=32,
                              max_steps=500, tiny=False, horizon=64, ppo_settings=False, eval_every=5)
    own = example.experiment_config(args, tmp_path)
    assert (own.on_policy_collected_frames_per_batch, own.on_policy_n_minibatch_iters, own.lr) == (32 * 500, 45, 5e-5)
    args.ppo_settings, args.eval_every = True, 60
    cfg = example.experiment_config(args, tmp_path)
    assert (cfg.on_policy_collected_frames_per_batch, cfg.on_policy_n_minibatch_iters, cfg.on_policy_minibatch_size) == (2048, 4, 512)
    assert (cfg.lr, cfg.gamma, cfg.clip_grad_val) == (1e-3, 0.98, 0.5)
    assert cfg.evaluation_interval == 60 * 2048
    args.lr = 3e-4
    assert example.experiment_config(args, tmp_path).lr == 3e-4
    args.lr, args.algorithm = None, "masac"  # off-policy: BenchMARL's own settings
    assert not example.ppo_settings(args) and example.experiment_config(args, tmp_path).lr == 5e-5


def test_algorithm_settings_are_typed_and_unknown_ones_refused():
    example = _example()
    assert example.algorithm_setting("mappo", "use_tanh_normal=false") == ("use_tanh_normal", False)
    assert example.algorithm_setting("mappo", "entropy_coef=0.01") == ("entropy_coef", 0.01)
    assert example.algorithm_setting("masac", "min_alpha=0.05") == ("min_alpha", 0.05)
    assert example.algorithm_setting("masac", "max_alpha=null") == ("max_alpha", None)
    with pytest.raises(ValueError, match="number or null"):
        example.algorithm_setting("masac", "min_alpha=low")
    for bad, named in (("use_tanh=false", "use_tanh"), ("use_tanh_normal=maybe", "true or false"),
                       ("clip_epsilon=wide", "float"), ("entropy_coef", "KEY=VALUE")):
        with pytest.raises(ValueError, match=named):
            example.algorithm_setting("mappo", bad)
    done = subprocess.run([sys.executable, str(EXAMPLE), "--set", "nope=1", "--tiny"], capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 2 and "nope" in done.stderr and "clip_epsilon" in done.stderr, done.stderr
