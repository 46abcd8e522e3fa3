"""`render_mode="human"`: a window (the `colcos-display` crate, on a display thread) showing the screen
with the robots, one frame per step at the field's rate; `close()` closes it.

The window test runs in a subprocess: under the current X display if there is one, else under
`xvfb-run` if installed (gpu/ci.sh installs xvfb), else it is skipped. With COLCOS_REQUIRE_DISPLAY=1 a
skip is a failure. It also compares a screenshot of the window (ImageMagick's `import`, if installed)
with the `rgb_array` image of the same step.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest

REQUIRE = os.environ.get("COLCOS_REQUIRE_DISPLAY") == "1"

WINDOW_SCRIPT = r"""
import os, subprocess, sys, tempfile, time
import numpy as np
import colcos
from colcos.vector import VecEnv

env = colcos.parallel_env(task="trail", render_mode="human", max_cycles=40, seed=1)
env.reset(seed=1)
w = env.unwrapped._window
if w.window is None:
    print("NOWINDOW")
    sys.exit(0)
t0 = time.monotonic()
steps = 25
for _ in range(steps):
    assert env.step({a: np.array([0.6, 0.4], np.float32) for a in env.agents})[0]
    assert env.render() is None  # shows nothing new: step already showed this frame
elapsed = time.monotonic() - t0
print("ELAPSED", elapsed)
assert elapsed >= 0.9 * steps * 0.02, f"{steps} steps in {elapsed:.3f} s: not paced to dt = 20 ms"
deadline = time.monotonic() + 30
while w.presented < 2 and time.monotonic() < deadline:
    time.sleep(0.05)
time.sleep(0.5)  # let the last frame reach the screen
print("PRESENTED", w.presented)
assert w.presented >= 2, "the window presented no frames"
assert w.is_open
frame = env.unwrapped._core.render(0, 640)
shot_ok = "NOSHOT"
if subprocess.run(["sh", "-c", "command -v import"], capture_output=True).returncode == 0:
    path = os.path.join(tempfile.mkdtemp(), "shot.png")
    subprocess.run(["import", "-window", "root", path], check=True, capture_output=True)
    out = subprocess.run(["convert", path, "-depth", "8", "rgb:-"], check=True, capture_output=True).stdout
    ident = subprocess.run(["identify", "-format", "%w %h", path], check=True, capture_output=True, text=True).stdout
    sw, sh = map(int, ident.split())
    shot = np.frombuffer(out, np.uint8).reshape(sh, sw, 3)
    h, wd, _ = frame.shape
    differ = int(np.any(shot[:h, :wd] != frame, axis=2).sum())
    shot_ok = f"SHOT {differ} of {h * wd} pixels differ"
    assert differ == 0, shot_ok
print(shot_ok)
env.close()
assert not w.is_open
env.close()  # twice is harmless

# The vector env's window shows world 0; a second window in the same process works too.
v = VecEnv("trail", num_envs=2, render_mode="human", max_cycles=10)
v.reset()
for _ in range(5):
    v.step(np.zeros((2, v.num_agents, 2), np.float32))
deadline = time.monotonic() + 30
while v._window.presented < 1 and time.monotonic() < deadline:
    time.sleep(0.05)
print("VECTOR", v._window.presented)
assert v._window.presented >= 1
v.close()
print("OK")
"""


def _run(cmd: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)


def _skip(why: str) -> None:
    if REQUIRE:
        pytest.fail(f"COLCOS_REQUIRE_DISPLAY=1 but {why}")
    pytest.skip(why)


def test_human_window_under_x():
    env = dict(os.environ, XDG_RUNTIME_DIR=os.environ.get("XDG_RUNTIME_DIR", "/tmp"))
    if os.environ.get("DISPLAY"):
        cmd = [sys.executable, "-c", WINDOW_SCRIPT]
    elif shutil.which("xvfb-run"):
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", sys.executable, "-c", WINDOW_SCRIPT]
    else:
        return _skip("no X display and no xvfb-run (apt-get install xvfb xauth)")
    out = _run(cmd, env)
    print(out.stdout)
    print(out.stderr[-3000:], file=sys.stderr)
    if "NOWINDOW" in out.stdout:
        return _skip(f"no window could be opened: {out.stderr[-500:]}")
    assert out.returncode == 0, out.stderr[-3000:]
    assert "OK" in out.stdout


def test_human_without_display_warns_and_runs():
    """Headless, human mode warns once and keeps running (PettingZoo's render_test constructs it)."""
    code = (
        "import warnings, numpy as np, colcos\n"
        "with warnings.catch_warnings(record=True) as ws:\n"
        "    warnings.simplefilter('always')\n"
        "    env = colcos.parallel_env(task='trail', render_mode='human', max_cycles=5)\n"
        "    env.reset(seed=0)\n"
        "    for _ in range(3):\n"
        "        env.step({a: np.zeros(2, np.float32) for a in env.agents})\n"
        "        assert env.render() is None\n"
        "    env.close()\n"
        "msgs = [str(w.message) for w in ws if issubclass(w.category, RuntimeWarning)]\n"
        "assert len(msgs) == 1, msgs\n"
        "assert 'no window' in msgs[0] and 'DISPLAY' in msgs[0], msgs\n"
        "print('OK')\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    out = _run([sys.executable, "-c", code], env)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "OK" in out.stdout
