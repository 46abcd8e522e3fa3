"""examples/tune_aggregation.py, the Ray Tune training sweep in docs/sweeps.md, runs end to end: one
trial per grid point, each scored, the best named (tiny settings: seconds of training)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("ray.tune")

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "tune_aggregation.py"


def test_a_tune_sweep_trains_every_grid_point_and_names_the_best(tmp_path: Path) -> None:
    args = ["--lr", "0.05", "--weights", "0.5,2", "--iterations", "2", "--pairs", "2", "--steps", "20"]
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    out = subprocess.run(
        [sys.executable, str(EXAMPLE), *args, "--storage", str(tmp_path)],
        capture_output=True, text=True, timeout=600, env=env,
    )
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    rows = [line.split() for line in out.stdout.splitlines() if line.strip().startswith("0.05")]
    assert sorted(float(r[1]) for r in rows) == [0.5, 2.0], out.stdout
    assert all(r[4] == "2" for r in rows), out.stdout  # every trial reported both iterations
    best = max(rows, key=lambda r: float(r[2]))
    assert f"best: lr=0.05 progress_weight={float(best[1])}" in out.stdout, out.stdout


def test_bad_arguments_are_named() -> None:
    out = subprocess.run(
        [sys.executable, str(EXAMPLE), "--weights", "1,x"], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 2 and "--weights '1,x'" in out.stderr, out.stderr
