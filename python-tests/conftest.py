"""Shared fixtures: every task, built small and short so the suites stay fast."""

from __future__ import annotations

import functools
import os
import types

import pytest

# examples/ppo.py's setting, before any test runs a matrix product: its update is the same on any
# number of threads (test_quickstart.py).
os.environ.setdefault("MKL_CBWR", "AUTO,STRICT")

import colcos

TASKS = sorted(colcos.tasks())


def task_module(task: str, **kwargs) -> types.SimpleNamespace:
    """A module-like namespace with `parallel_env` and `env` for one task (what max_cycles_test wants)."""
    return types.SimpleNamespace(
        parallel_env=functools.partial(colcos.parallel_env, task=task, **kwargs),
        env=functools.partial(colcos.env, task=task, **kwargs),
        raw_env=functools.partial(colcos.raw_env, task=task, **kwargs),
    )


@pytest.fixture(params=TASKS)
def task(request) -> str:
    return request.param
