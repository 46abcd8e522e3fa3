"""`backend=`: the field backend of the grid pheromones, chosen from Python.

`gpu` runs on any adapter (lavapipe, Mesa's software Vulkan driver, in CI) and gives the CPU's
observations; `auto` takes a hardware GPU only, so on a machine with lavapipe alone it takes the CPU
and says why; `gpu` where wgpu finds no adapter at all raises `colcos.BackendError`.
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys

import numpy as np
import pytest

import colcos
from colcos.vector import VecEnv

REQUIRE_GPU = os.environ.get("COLCOS_REQUIRE_GPU") == "1"


def _gpu_env(**kw):
    """A trail env (grid pheromones) on the GPU, or a skip where there is no adapter."""
    try:
        return colcos.parallel_env(task="trail", backend="gpu", **kw)
    except colcos.BackendError as e:
        if REQUIRE_GPU:
            raise
        pytest.skip(f"no GPU adapter: {e}")


def test_default_and_cpu():
    env = colcos.parallel_env(task="trail", max_cycles=5)
    assert env.backend_name == "cpu"
    assert env.backend_info.startswith("cpu")
    env = colcos.parallel_env(task="trail", max_cycles=5, backend="cpu")
    assert env.backend_name == "cpu"
    assert "asked for" in env.backend_info


def test_auto_says_what_it_took(caplog):
    with caplog.at_level(logging.INFO, logger="colcos"):
        env = colcos.parallel_env(task="trail", max_cycles=5, backend="auto")
    assert env.backend_name in ("cpu", "gpu")
    assert env.unwrapped.backend_name == env.backend_name
    assert any("field backend" in r.getMessage() and env.backend_info in r.getMessage() for r in caplog.records)
    if env.backend_name == "cpu":
        assert "auto" in env.backend_info  # why: no adapter, or only a software one
    # The AEC face and the vector env say the same.
    assert colcos.env(task="trail", max_cycles=5, backend="auto").unwrapped.backend_name == env.backend_name
    assert VecEnv("trail", num_envs=2, backend="auto").backend_name == env.backend_name


def test_bad_backend_name():
    with pytest.raises(colcos.TaskError, match="backend"):
        colcos.parallel_env(task="trail", backend="cuda")
    with pytest.raises(colcos.TaskError, match="backend"):
        VecEnv("trail", backend=3)


def test_gpu_matches_cpu():
    steps = 40
    gpu = _gpu_env(max_cycles=steps, seed=3)
    assert gpu.backend_name == "gpu", gpu.backend_info
    cpu = colcos.parallel_env(task="trail", max_cycles=steps, seed=3)
    rng = np.random.default_rng(0)
    og, _ = gpu.reset(seed=3)
    oc, _ = cpu.reset(seed=3)
    worst = 0.0
    for _ in range(steps):
        acts = {a: rng.uniform(-1, 1, 2).astype(np.float32) for a in cpu.agents}
        og, rg, *_ = gpu.step(acts)
        oc, rc, *_ = cpu.step(acts)
        for a in oc:
            worst = max(worst, float(np.abs(og[a] - oc[a]).max()))
            assert rg[a] == pytest.approx(rc[a], rel=1e-5, abs=1e-6)
    assert worst < 1e-5, f"largest observation difference {worst}"


def test_gpu_vector_env():
    try:
        v = VecEnv("trail", num_envs=3, seed=1, backend="gpu", max_cycles=10)
    except colcos.BackendError as e:
        if REQUIRE_GPU:
            raise
        pytest.skip(f"no GPU adapter: {e}")
    c = VecEnv("trail", num_envs=3, seed=1, max_cycles=10)
    assert v.backend_name == "gpu"
    v.reset()
    c.reset()
    a = np.random.default_rng(1).uniform(-1, 1, (3, v.num_agents, 2)).astype(np.float32)
    for _ in range(12):  # past an autoreset: the rebuilt worlds are on the GPU too
        v.step(a)
        c.step(a)
        np.testing.assert_allclose(v.obs, c.obs, atol=1e-5)


def test_gaussian_only_task_reports_cpu():
    """aggregation has Gaussian pheromones only (analytic): nothing for the GPU to step."""
    try:
        env = colcos.parallel_env(task="aggregation", backend="gpu", max_cycles=5)
    except colcos.BackendError as e:
        if REQUIRE_GPU:
            raise
        pytest.skip(f"no GPU adapter: {e}")
    assert env.backend_name == "cpu"
    assert "no grid pheromones" in env.backend_info


def test_gpu_without_adapter_is_a_clear_error():
    """No adapter at all (wgpu limited to a backend this OS lacks): `gpu` raises, `auto` takes the CPU."""
    code = (
        "import colcos\n"
        "env = colcos.parallel_env(task='trail', backend='auto')\n"
        "assert env.backend_name == 'cpu', env.backend_info\n"
        "print('AUTO', env.backend_info)\n"
        "try:\n"
        "    colcos.parallel_env(task='trail', backend='gpu')\n"
        "except colcos.BackendError as e:\n"
        "    print('ERROR', e)\n"
        "except BaseException as e:\n"
        "    print('WRONG', type(e).__name__, e)\n"
        "else:\n"
        "    print('NO ERROR')\n"
    )
    env = dict(os.environ, WGPU_BACKEND="metal")  # no Metal on Linux: wgpu sees no adapter
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "AUTO cpu (auto: no GPU adapter)" in out.stdout, out.stdout
    line = next(l for l in out.stdout.splitlines() if l.startswith(("ERROR", "WRONG", "NO ERROR")))
    assert line.startswith("ERROR"), line
    assert "no GPU adapter found" in line and "backend" in line, line
