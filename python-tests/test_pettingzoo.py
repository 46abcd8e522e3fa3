"""PettingZoo's own conformance suite, for every task (and the discrete and patch variants)."""

from __future__ import annotations

from pettingzoo.test import (
    api_test,
    max_cycles_test,
    parallel_api_test,
    parallel_seed_test,
    render_test,
    seed_test,
    state_test,
)

import colcos
from conftest import task_module


def test_parallel_api(task):
    parallel_api_test(colcos.parallel_env(task=task, max_cycles=200), num_cycles=300)


def test_aec_api(task):
    api_test(colcos.env(task=task, max_cycles=200), num_cycles=300)


def test_max_cycles(task):
    max_cycles_test(task_module(task))


def test_render(task):
    render_test(lambda render_mode=None: colcos.env(task=task, render_mode=render_mode, max_cycles=50))


def test_state(task):
    state_test(colcos.env(task=task, max_cycles=100), colcos.parallel_env(task=task, max_cycles=100), num_cycles=50)


def test_seed(task):
    seed_test(lambda: colcos.env(task=task, max_cycles=100), num_cycles=100)


def test_parallel_seed(task):
    parallel_seed_test(lambda: colcos.parallel_env(task=task, max_cycles=100), num_cycles=100)


def test_discrete_variant(task):
    parallel_api_test(colcos.parallel_env(task=task, max_cycles=100, continuous=False), num_cycles=150)
    api_test(colcos.env(task=task, max_cycles=100, continuous=False), num_cycles=150)


def test_patch_variant():
    env = colcos.parallel_env(task="aggregation", max_cycles=50, patch=12)
    parallel_api_test(env, num_cycles=60)
    obs, _ = env.reset(seed=1)
    first = next(iter(obs.values()))
    assert first["patch"].shape == (12, 12, 3) and first["patch"].dtype.name == "uint8"
    # The aggregation pheromone covers the arena: every patch shows some green.
    assert all(o["patch"][..., 1].max() > 0 for o in obs.values())
