"""`examples/transfer.py` end to end on a tiny budget: the three trainings with actors that see their
agent's id, the simulator's columns and one short episode on the in-process twin for every policy."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import pytest

REPO = pathlib.Path(__file__).resolve().parents[1]


def test_tiny_transfer_study_with_agent_ids(tmp_path):
    pytest.importorskip("torch")
    args = ["--updates", "1", "--seeds", "0", "--agent-id", "--episode", "20", "--eval-worlds", "2",
            "--twin-episodes", "1", "--threads", "1", "--out", str(tmp_path)]
    out = subprocess.run([sys.executable, str(REPO / "examples" / "transfer.py"), *args],
                         capture_output=True, text=True, timeout=900, check=True).stdout
    assert "| identified-s0 |" in out and "| standing still |" in out
    result = json.loads((tmp_path / "result.json").read_text())
    returns = result["returns"]
    assert set(returns) == {"nominal-s0", "generic-s0", "identified-s0", "hand-written", "standing still"}
    for policy, cols in returns.items():
        assert len(cols["sim_nominal"]) == len(cols["sim_truth"]) == 2, policy
        assert len(cols["twin"]) == 1, policy
    for variant in ("nominal", "generic", "identified"):
        trained = result["trained"][f"{variant}-s0"]
        assert trained["runs"][0]["updates"] == 1
        assert "--agent-id" in trained["command"]
        assert "--no-own-critic" in trained["command"]  # the documented tables' learner
        assert "--recipe short" in trained["command"]


def test_tiny_transfer_study_of_one_variant_on_a_compensated_twin_too(tmp_path):
    pytest.importorskip("torch")
    args = ["--updates", "1", "--seeds", "0", "--variants", "nominal", "--compensate", "--learner", "short",
            "--episode", "20", "--eval-worlds", "2", "--twin-episodes", "1", "--threads", "1", "--out", str(tmp_path)]
    out = subprocess.run([sys.executable, str(REPO / "examples" / "transfer.py"), *args],
                         capture_output=True, text=True, timeout=900, check=True).stdout
    assert "twin, truth, compensated" in out and "| nominal-s0: compensated − not |" in out
    assert 'compensate = "' in (tmp_path / "host_compensated.toml").read_text()
    result = json.loads((tmp_path / "result.json").read_text())
    assert set(result["returns"]) == {"nominal-s0", "hand-written", "standing still"}
    assert not (tmp_path / "generic-s0").exists()  # only the variant asked for is trained
    command = result["trained"]["nominal-s0"]["command"]
    assert "--no-own-critic" not in command and "--clip-together" not in command  # the short recipe as it is
    assert "--recipe short" in command
    for policy, cols in result["returns"].items():
        assert len(cols["twin"]) == len(cols["twin_compensated"]) == 1, policy
    assert set(result["ratios"]) == {"twin", "twin_compensated"}
    assert set(result["ratios"]["twin_compensated"]) == {"nominal-s0", "hand-written"}
    assert "twin_compensated_stats" in result and "twin_stats" in result


def test_the_compensated_twin_alone_is_one_column_without_pairs():
    pytest.importorskip("torch")
    import argparse
    import importlib.util

    spec = importlib.util.spec_from_file_location("transfer_example", REPO / "examples" / "transfer.py")
    assert spec is not None and spec.loader is not None
    transfer = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(transfer)
    args = argparse.Namespace(compensate=False, compensated_only=True, variants=["nominal"], seeds=[0],
                              eval_worlds=2, twin_episodes=3)
    assert transfer.twin_columns(args) == {"twin_compensated": "host_compensated"}
    both = argparse.Namespace(**{**vars(args), "compensate": True, "compensated_only": False})
    assert transfer.twin_columns(both) == {"twin": "host", "twin_compensated": "host_compensated"}
    sim_only = argparse.Namespace(**{**vars(args), "compensated_only": False, "twin_episodes": 0})
    assert transfer.twin_columns(sim_only) == {}
    sims = {k: {"sim_nominal": [v, v + 2.0], "sim_truth": [v, v]} for k, v in
            (("nominal-s0", -100.0), ("hand-written", -150.0), ("standing still", -300.0))}
    sim_table = transfer.report({"returns": sims}, sim_only)
    assert sim_table.splitlines()[0] == "| policy | simulator, nominal (2 worlds) | simulator, truth (2 worlds) |"
    assert "| nominal-s0 | -99.0 ± 1.4 | -100.0 ± 0.0 |" in sim_table and "twin" not in sim_table
    cols = lambda sim, twin: {"sim_nominal": [sim, sim + 2.0], "sim_truth": [sim, sim], "twin_compensated": [twin] * 3}
    result = {"returns": {"nominal-s0": cols(-100.0, -200.0), "hand-written": cols(-150.0, -150.0),
                          "standing still": cols(-300.0, -300.0)}}
    table = transfer.report(result, args)
    assert "twin, truth, compensated (3 episodes)" in table and "paired by episode" not in table
    assert set(result["ratios"]) == {"twin_compensated"} and result["differences"] == {}
    # The twin keeps half the simulator's gain over standing still (100 of 200), the hand-written follower all.
    assert result["ratios"]["twin_compensated"]["nominal-s0"][0] == pytest.approx(0.5)
    assert result["ratios"]["twin_compensated"]["hand-written"][0] == pytest.approx(1.0)


def test_bad_benchmarl_policies_are_refused_naming_them(tmp_path):
    checkpoint = tmp_path / "run.pt"
    checkpoint.write_bytes(b"")
    for spec, text in ((str(checkpoint), "expected NAME=CHECKPOINT"), ("ippo=no/such.pt", "no such checkpoint file 'no/such.pt'"),
                       ("hand-written=" + str(checkpoint), "['hand-written'] are used twice or by another policy")):  # fmt: skip
        done = subprocess.run([sys.executable, str(REPO / "examples" / "transfer.py"), "--variants", "--benchmarl", spec,
                               "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=120)  # fmt: skip
        assert done.returncode == 2 and text in done.stderr, done.stderr


def test_bad_evaluation_sizes_are_refused_naming_them(tmp_path):
    for args, text in ((["--twin-episodes", "-1"], "--twin-episodes (-1) must be at least 0"),
                       (["--twin-episodes", "0", "--compensate"], "need twin episodes"),
                       (["--eval-worlds", "1"], "--eval-worlds (1) must be at least 2")):  # fmt: skip
        done = subprocess.run([sys.executable, str(REPO / "examples" / "transfer.py"), *args, "--out", str(tmp_path)],
                              capture_output=True, text=True, timeout=120)  # fmt: skip
        assert done.returncode == 2 and text in done.stderr, done.stderr
        assert not any(tmp_path.iterdir())  # refused before anything is written or trained


def test_the_ippo_learner_trains_with_the_quick_starts_default_recipe(tmp_path):
    pytest.importorskip("torch")
    args = ["--updates", "1", "--seeds", "0", "--variants", "nominal", "--learner", "ippo", "--episode", "20",
            "--eval-worlds", "2", "--twin-episodes", "0", "--threads", "1", "--out", str(tmp_path)]
    subprocess.run([sys.executable, str(REPO / "examples" / "transfer.py"), *args],
                   capture_output=True, text=True, timeout=900, check=True)
    trained = json.loads((tmp_path / "result.json").read_text())["trained"]["nominal-s0"]
    assert "--recipe ippo" in trained["command"] and "--no-own-critic" not in trained["command"]
    assert trained["recipe"] == "ippo" and trained["runs"][0]["updates"] == 1
