"""A plant's safety edges from Python: a closed twin (by `close()`, by leaving `with env:`, or after a
policy raised inside it) never drives again, and a twin whose tracker cannot be reached raises within
seconds naming the URL and the reason, instead of observations of robots at (0, 0)."""

from __future__ import annotations

import re
import socket
import time

import numpy as np
import pytest

import colcos


def _dead_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _ahead(env) -> dict:
    return {a: np.ones(2, np.float32) for a in env.agents}


def test_a_closed_twin_refuses_to_step_or_reset():
    env = colcos.parallel_env(task="aggregation", plant="twin", max_cycles=50, goto=False)
    obs, _ = env.reset(seed=1)
    # The first observation is of tracked robots: no bumper reads 1.0 as at the (0, 0) corner.
    assert all(o[12:15].max() < 1.0 for o in obs.values())
    env.step(_ahead(env))
    env.close()
    with pytest.raises(colcos.StateError, match="closed"):
        env.step(_ahead(env))
    with pytest.raises(colcos.StateError, match="closed"):
        env.reset()
    assert "shutdown" in env.plant_info()["stops"]
    env.close()  # twice is harmless


def test_leaving_with_closes_even_when_the_policy_raised():
    with pytest.raises(ZeroDivisionError):
        with colcos.parallel_env(task="aggregation", plant="twin", max_cycles=50, goto=False) as env:
            env.reset(seed=0)
            env.step(_ahead(env))
            1 / 0  # noqa: B018
    with pytest.raises(colcos.StateError, match="closed"):
        env.reset()


def test_a_twin_whose_tracker_is_not_there_raises_naming_it():
    tracker = f"swarmcon://127.0.0.1:{_dead_port()}"
    robots = f"udp://127.0.0.1:{_dead_port()}"
    env = colcos.parallel_env(task="aggregation", plant="twin", tracker=tracker, robots=robots, goto=False)
    t0 = time.monotonic()
    with pytest.raises(colcos.PlantUnreachableError, match=re.escape(tracker)) as e:
        env.reset(seed=0)
    assert time.monotonic() - t0 < 8.0
    assert "refused" in str(e.value).lower()
    assert isinstance(e.value, ConnectionError) and isinstance(e.value, colcos.StateError)
    env.close()


def test_preflight_is_reachable_after_import():
    assert callable(colcos.preflight.preflight)
