"""The communication biases of `examples/ppo.py` (positive listening and signalling) and how
`examples/stigmergy.py` finds the observation entries a call is heard in."""

from __future__ import annotations

import json
import math
import pathlib
import subprocess
import sys

import pytest

torch = pytest.importorskip("torch")
from example_modules import load_ppo  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[1]


def _model(ppo, obs_dim: int = 18):
    torch.manual_seed(0)
    model = ppo.ActorCritic(obs_dim, 4, act_dim=3)
    with torch.no_grad():  # wheels that visibly depend on every input
        model.pi[-1].weight.normal_(0.0, 1.0)
    return model


def test_listening_is_zero_for_wheels_deaf_to_the_message_and_positive_otherwise():
    ppo = load_ppo()
    model = _model(ppo)
    obs = torch.rand(64, 18)
    inputs = (1, 4, 7, 10)
    heard = ppo.listening(model, obs, model.mean(obs), inputs)
    assert heard.item() > 1e-3
    heard.backward()  # differentiable: it is a loss term
    with torch.no_grad():
        model.pi[0].weight[:, list(inputs)] = 0.0  # the actor no longer reads the message's entries
    assert ppo.listening(model, obs, model.mean(obs), inputs).item() == pytest.approx(0.0, abs=1e-7)
    # The message's entries at their running mean already: setting them there changes nothing.
    model = _model(ppo)
    model.obs_norm.update(torch.rand(256, 18) * 3.0)
    usual = obs.clone()
    usual[:, list(inputs)] = model.obs_norm.mean[list(inputs)]
    assert ppo.listening(model, usual, model.mean(usual), inputs).item() == pytest.approx(0.0, abs=1e-6)
    # Elsewhere it counts: the same entries at their raw 0, far below their mean of about 1.5.
    quiet = obs.clone()
    quiet[:, list(inputs)] = 0.0
    assert ppo.listening(model, quiet, model.mean(quiet), inputs).item() > 1e-3


def test_signalling_is_the_mutual_information_of_sending_and_observation():
    ppo = load_ppo()
    model = _model(ppo)
    with torch.no_grad():
        model.log_std[2] = math.log(0.01)
    same = torch.zeros(100, 3)
    same[:, 2] = 0.3  # everyone sends with the same (small) probability: no information
    assert ppo.signalling(model, same, 2, 0.5).item() == pytest.approx(0.0, abs=1e-6)
    split = torch.zeros(100, 3)
    split[:50, 2] = 1.5  # half the observations always send, half never: one bit, ln 2 nats
    split[50:, 2] = -0.5
    assert ppo.signalling(model, split, 2, 0.5).item() == pytest.approx(math.log(2.0), abs=1e-3)
    rare = split.clone()
    rare[10:, 2] = -0.5  # a tenth send: H(0.1)
    assert ppo.signalling(model, rare, 2, 0.5).item() == pytest.approx(-(0.1 * math.log(0.1) + 0.9 * math.log(0.9)), abs=1e-3)


def test_the_biases_off_change_nothing_and_on_change_the_update():
    ppo = load_ppo()
    from colcos.vector import VecEnv

    sys.path.insert(0, str(REPO / "examples" / "tasks"))
    from rally import Rally

    def trained(**bias):
        env = VecEnv(Rally(), num_envs=2, max_cycles=40, num_threads=1)
        cfg = ppo.Config(horizon=16, message_inputs=(1, 4, 7, 10), **bias)
        trainer = ppo.Trainer(env, cfg, seed=0, to_env=lambda a: ppo.clip_wheels(a))
        trainer.iterate()
        return torch.cat([p.detach().flatten() for p in trainer.model.pi.parameters()])

    plain = trained()
    assert torch.equal(plain, trained(listen_bias=0.0, signal_bias=0.0))
    assert not torch.equal(plain, trained(listen_bias=0.5))
    assert not torch.equal(plain, trained(signal_bias=0.5))


def test_the_study_hears_rally_s_call_on_the_green_entries_and_saves_the_biases(tmp_path):
    sys.path.insert(0, str(REPO / "examples"))
    import stigmergy

    args = stigmergy.parse_args(["--tasks", "rally"])
    assert stigmergy.message_inputs("rally", args) == (1, 4, 7, 10)
    assert stigmergy.message_inputs("coverage", args) != ()
    run = subprocess.run([sys.executable, str(REPO / "examples" / "stigmergy.py"), "--tasks", "rally", "--steps", "1500",
                          "--seeds", "0", "--episode", "30", "--num-envs", "2", "--horizon", "16", "--eval-worlds", "2",
                          "--listen-bias", "0.05", "--signal-bias", "0.01", "--out", str(tmp_path)],
                         capture_output=True, text=True, timeout=600, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    saved = json.loads((tmp_path / "rally" / "with_seed0.json").read_text())["config"]
    assert saved["listen_bias"] == 0.05 and saved["signal_bias"] == 0.01
    # The arm without pheromone actions has no message: it trains without the biases, as with none given.
    plain = tmp_path / "plain"
    run = subprocess.run([sys.executable, str(REPO / "examples" / "stigmergy.py"), "--tasks", "rally", "--modes", "without",
                          "--steps", "1500", "--seeds", "0", "--episode", "30", "--num-envs", "2", "--horizon", "16",
                          "--eval-worlds", "2", "--out", str(plain)], capture_output=True, text=True, timeout=600, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    biased = json.loads((tmp_path / "rally" / "without_seed0.json").read_text())
    unbiased = json.loads((plain / "rally" / "without_seed0.json").read_text())
    assert biased["eval"] == unbiased["eval"]
    assert biased["config"] == unbiased["config"]  # so either run serves a study with or without biases
