"""Writes the on-board policy the bridge's tests run on the digital twin (bridge/tests/data/onboard/):
one linear layer, 17 -> 2, driving both wheels at half the largest wheel speed, the left one slower
by the front-left bumper's reading (so the robot's own readings reach the policy). python-tests
checks that the committed files are what `export_c` writes.

    python scripts/onboard_fixture.py [OUT_DIR]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from colcos.onboard import export_c

DEFAULT_DIR = Path(__file__).resolve().parent.parent / "bridge" / "tests" / "data" / "onboard"


def fixture_layers() -> list[tuple[np.ndarray, np.ndarray]]:
    w = np.zeros((2, 17), dtype=np.float32)
    w[0, 12] = -0.5  # front-left bumper slows the left wheel
    b = np.array([0.5, 0.5], dtype=np.float32)
    return [(w, b)]


def write(out_dir: Path) -> None:
    export_c(fixture_layers(), out_dir / "policy", prefix="twin_policy")


if __name__ == "__main__":
    write(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_DIR)
