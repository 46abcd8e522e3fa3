"""`examples/stigmergy.py` end to end on a tiny budget: both trainings (with and without pheromone
actions), the four evaluations and the summary, for one task."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

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
