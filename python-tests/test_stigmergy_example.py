"""`examples/stigmergy.py` end to end on a tiny budget: both trainings (with and without pheromone
actions), the four evaluations and the summary, for one task."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[1]


def test_tiny_study_runs(tmp_path):
    pytest.importorskip("torch")
    args = ["--tasks", "alarm", "--steps", "1500", "--seeds", "0", "--episode", "30", "--num-envs", "2",
            "--horizon", "16", "--eval-worlds", "2", "--threads", "1", "--out", str(tmp_path)]
    out = subprocess.run([sys.executable, str(REPO / "examples" / "stigmergy.py"), *args],
                         capture_output=True, text=True, timeout=600, check=True).stdout
    assert "| `alarm` |" in out
    row = json.loads((tmp_path / "result.json").read_text())["tasks"]["alarm"]
    assert len(row["with"]) == len(row["without"]) == 1
    # 6 agents, 30 steps, a safe fraction in [0, 1] each step.
    for value in (*row["with"], *row["without"], row["baseline"], row["random"]):
        assert 0.0 <= value <= 30.0


def _study(tmp_path, *extra: str) -> subprocess.CompletedProcess:
    args = ["--steps", "1500", "--seeds", "0", "--episode", "30", "--num-envs", "2", "--horizon", "16",
            "--eval-worlds", "2", "--threads", "1", "--out", str(tmp_path), *extra]
    return subprocess.run([sys.executable, str(REPO / "examples" / "stigmergy.py"), *args],
                          capture_output=True, text=True, timeout=600, check=False)


def test_a_python_task_with_sampled_evaluation_and_training_only_shaping(tmp_path):
    pytest.importorskip("torch")
    run = _study(tmp_path, "--tasks", "rally", "--eval-policy", "sample", "--start-forward", "0.5", "--gamma", "0.99",
                 "--team-critic", "--anneal", "--param", "spot_radius=0.3", "--shaping", "margin=0.2")
    assert run.returncode == 0, run.stderr
    saved = json.loads((tmp_path / "rally" / "with_seed0.json").read_text())
    assert saved["config"]["param"] == {"spot_radius": 0.3} and saved["config"]["shaping"] == {"margin": 0.2}
    assert saved["config"]["eval_policy"] == "sample" and saved["config"]["gamma"] == 0.99
    assert saved["config"]["team_critic"] and saved["config"]["anneal"]
    # At most 30 steps on the spot per episode; the sampled evaluation is seeded: the same again.
    assert all(0.0 <= r <= 30.0 for r in saved["eval"])
    _study(tmp_path / "again", "--tasks", "rally", "--eval-policy", "sample", "--start-forward", "0.5",
                   "--gamma", "0.99", "--team-critic", "--anneal", "--param", "spot_radius=0.3", "--shaping", "margin=0.2")
    assert json.loads((tmp_path / "again" / "rally" / "with_seed0.json").read_text())["eval"] == saved["eval"]
    # What the learned agents lay, and when: shares in [0, 1], split by the task's flag.
    probe = subprocess.run([sys.executable, str(REPO / "examples" / "stigmergy_probe.py"), "--out", str(tmp_path),
                            "--task", "rally", "--worlds", "2"], capture_output=True, text=True, timeout=600, check=False)
    assert probe.returncode == 0, probe.stderr
    (row,) = json.loads((tmp_path / "rally" / "probe.json").read_text())
    assert row["seed"] == 0 and sum(row["agent_steps"]) == 2 * 6 * 30
    assert all(0.0 <= x <= 1.0 for x in (*row["lay_with_flag"], *row["lay_without_flag"], row["speed_without_flag"]))


def test_a_bad_task_parameter_is_refused_by_name(tmp_path):
    pytest.importorskip("torch")
    run = _study(tmp_path, "--tasks", "colony", "--param", "bogus=1")
    assert run.returncode != 0 and "colony.bogus" in run.stderr, run.stderr[-2000:]
    run = _study(tmp_path, "--tasks", "colony", "--param", "no_equals_sign")
    assert run.returncode != 0 and "--param 'no_equals_sign': expected KEY=VALUE" in run.stderr, run.stderr[-2000:]


def test_a_kickstarted_study_imitates_the_hand_written_policy_first(tmp_path):
    pytest.importorskip("torch")
    run = _study(tmp_path, "--tasks", "colony", "--kickstart", "6000", "--actor-warmup", "1")
    assert run.returncode == 0, run.stderr[-2000:]
    for mode in ("with", "without"):
        saved = json.loads((tmp_path / "colony" / f"{mode}_seed0.json").read_text())
        assert saved["config"]["kickstart"] == 6000 and saved["config"]["actor_warmup"] == 1
        mse = saved["kickstart_mse"]
        assert len(mse) == 20 and mse[-1] < 0.5 * mse[0], mse  # the actor learns the teacher's actions
        assert len(saved["eval_kickstart"]) == 2
    bad = _study(tmp_path / "bad", "--tasks", "colony", "--kickstart", "-1")
    assert bad.returncode == 2 and "--kickstart (-1)" in bad.stderr, bad.stderr[-2000:]


def test_imitation_fits_a_teacher_and_sets_the_noise():
    torch = pytest.importorskip("torch")
    sys.path.insert(0, str(REPO / "examples"))
    from example_modules import load_ppo

    load_ppo()
    import kickstart

    rng = np.random.default_rng(0)
    obs = rng.normal(2.0, 3.0, size=(4000, 5)).astype(np.float32)
    teacher = np.tanh(obs @ rng.normal(size=(5, 2)) / 3.0).astype(np.float32)  # a smooth policy in the box
    model = sys.modules["ppo"].ActorCritic(5, 4, act_dim=2)
    losses = kickstart.imitate(model, obs, teacher, np.array([-1.0, -1.0]), np.array([1.0, 1.0]), epochs=30, minibatch=256, std=0.3)
    assert losses[-1] < 0.05 * losses[0], losses
    assert torch.allclose(model.log_std.exp(), torch.tensor(0.3))
    assert np.abs(model.act(obs) - teacher).mean() < 0.1


def test_an_anchored_trainer_stays_nearer_its_frozen_actor():
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv
    from example_modules import load_ppo

    ppo = load_ppo()
    env = VecEnv(task="alarm", num_envs=2, max_cycles=40, num_threads=1)

    def drift(anchor: float) -> float:
        trainer = ppo.Trainer(env, ppo.Config(horizon=16, epochs=2, minibatches=2, lr=3e-3, anchor=anchor), seed=0)
        trainer.set_anchor()
        probe = torch.randn(256, env.single_observation_space.shape[0], generator=torch.Generator().manual_seed(1))
        with torch.no_grad():
            before = trainer.anchor[0](trainer.anchor[1](probe))
        for _ in range(4):
            trainer.iterate()
        with torch.no_grad():
            return float((trainer.model.pi(trainer.anchor[1](probe)) - before).pow(2).sum(-1).mean())

    free, held = drift(0.0), drift(100.0)
    assert held < 0.5 * free, (held, free)
