"""docs/tutorial.md runs as written: every ```sh and ```python block, in order, in one empty directory,
with target/release/colcos on PATH and this interpreter (where colcos is installed) for Python. The
scenario the tutorial writes is the one committed as scenarios/tutorial_y_trail.toml."""

import os
import re
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TUTORIAL = REPO / "docs" / "tutorial.md"
BINARY = REPO / "target" / "release" / "colcos"
BLOCK = re.compile(r"^```(sh|python)\n(.*?)^```$", re.S | re.M)


def blocks():
    return BLOCK.findall(TUTORIAL.read_text())


def test_the_tutorial_has_shell_and_python_blocks():
    kinds = [k for k, _ in blocks()]
    assert kinds.count("sh") >= 4 and kinds.count("python") >= 3, kinds


def test_every_command_of_the_tutorial_runs(tmp_path):
    assert BINARY.is_file(), f"{BINARY} is missing: build it with `cargo build --release`"
    env = dict(os.environ, PATH=f"{BINARY.parent}{os.pathsep}{os.environ.get('PATH', '')}")
    for n, (kind, code) in enumerate(blocks()):
        if kind == "sh":
            cmd = ["bash", "-euo", "pipefail", "-c", code]
        else:
            cmd = [sys.executable, "-c", code]
        done = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, (
            f"block {n} ({kind}) failed:\n{code}\n--- stdout\n{done.stdout}\n--- stderr\n{done.stderr}"
        )
    written = (tmp_path / "y_trail.toml").read_text()
    assert written == (REPO / "scenarios" / "tutorial_y_trail.toml").read_text()
    for f in ["runs/y/run.gif", "runs/y_fast/trajectory.csv", "runs/y_sweep/results.csv", "y_policy.npy"]:
        assert (tmp_path / f).is_file(), f
