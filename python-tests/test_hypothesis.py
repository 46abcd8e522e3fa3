"""Property tests over the Python API: constructors, reset, step, render and every adapter fed
arbitrary arguments. Each example runs in a forked, memory-limited child (`isolate.run`): whatever
the input, the call returns or raises a `colcos.ColcosError` with a message; an abort, a hang, a
`PanicException` or any other exception fails the test. Derandomized, so CI runs the same examples.
"""

from __future__ import annotations

import importlib.util
import os
import time
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import colcos
from isolate import run

HAS_SB3 = importlib.util.find_spec("stable_baselines3") is not None
HAS_TORCHRL = importlib.util.find_spec("torchrl") is not None
# Imported here, so that the zygote the children are forked from has them (torch takes seconds).
if HAS_SB3:
    import colcos.sb3  # noqa: F401
if HAS_TORCHRL:
    import colcos.torchrl_env  # noqa: F401

SETTINGS = settings(
    max_examples=50,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)

TASKS = sorted(colcos.tasks())

numpy_scalars = st.one_of(
    st.integers(-(2**63), 2**63 - 1).map(np.int64),
    st.integers(0, 2**64 - 1).map(np.uint64),
    st.floats(width=32).map(np.float32),
    st.booleans().map(np.bool_),
)
anything = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.integers(-3, 70),
    st.floats(),
    st.text(max_size=4),
    st.lists(st.floats(-2, 2), max_size=3),
    numpy_scalars,
)
sizes = st.one_of(st.integers(-3, 6), st.sampled_from([2**16, 2**16 + 1, 2**64, 10**30]), anything)


def checked(outcome: Any) -> None:
    """A call returned, or raised a ColcosError with a message."""
    if not outcome.ok:
        assert outcome.is_colcos, f"{outcome.error_type}: {outcome.message}"
        assert outcome.message.strip(), outcome.error_type


def valid_seed(v: Any) -> bool:
    return not isinstance(v, (bool, np.bool_)) and isinstance(v, (int, np.integer)) and 0 <= int(v) < 2**64


# --- what the children run (module level, so that they can be sent to the child) ---


def make_parallel(kwargs: dict, steps: int) -> None:
    env = colcos.parallel_env(**kwargs)
    env.reset(seed=1)
    for _ in range(steps):
        if not env.agents:
            break
        env.step({a: env.action_space(a).sample() for a in env.agents})
    env.render() if env.render_mode == "rgb_array" else None


def make_vec(kwargs: dict) -> None:
    v = colcos.vector.VecEnv(**kwargs)
    v.reset()
    v.step(np.zeros(v._act_shape, v._act_dtype))


def reset_both(seed: Any, options: Any) -> str:
    env = colcos.parallel_env(max_cycles=5)
    env.reset(seed=seed, options=options)
    v = colcos.vector.VecEnv(num_envs=2, max_cycles=5)
    v.reset(seed=seed, options=options)
    return "ok"


def step_parallel(continuous: bool, actions: dict) -> None:
    env = colcos.parallel_env(max_cycles=5, continuous=continuous)
    env.reset(seed=0)
    env.step(actions)


def step_aec(actions: list) -> None:
    env = colcos.env(max_cycles=3)
    env.reset(seed=0)
    for a in actions:
        if not env.agents:
            break
        env.step(None if env.terminations[env.agent_selection] or env.truncations[env.agent_selection] else a)


def step_vec(actions: Any) -> None:
    v = colcos.vector.VecEnv(num_envs=2, max_cycles=5)
    v.reset(seed=0)
    v.step(actions)


def render(world: Any, width: Any) -> None:
    v = colcos.vector.VecEnv(num_envs=2, max_cycles=5)
    v.reset(seed=0)
    img = v.render(world, width)
    assert img.ndim == 3 and img.shape[2] == 3


def gym_vector(kwargs: dict, seed: Any, actions: Any) -> None:
    from colcos.gymnasium_vector import ColcosVectorEnv

    g = ColcosVectorEnv(**kwargs)
    g.reset(seed=seed)
    g.step(actions)


def sb3(kwargs: dict, seed: Any, actions: Any) -> None:
    from colcos.sb3 import ColcosSB3VecEnv

    e = ColcosSB3VecEnv(**kwargs)
    e.seed(seed)
    e.reset()
    e.step(actions)


def torchrl(kwargs: dict, seed: Any) -> None:
    from colcos.torchrl_env import ColcosTorchEnv

    e = ColcosTorchEnv(**kwargs)
    e.set_seed(seed)
    e.rollout(2)


def baseline(name: Any, seed: Any, params: dict) -> None:
    from colcos.baselines import Baseline

    v = colcos.vector.VecEnv(num_envs=1, max_cycles=5)
    v.reset(seed=0)
    v.step(Baseline(v, name, seed=seed, **params).act())


def abort() -> None:
    os.abort()


def hang() -> None:
    time.sleep(600)


def hog() -> None:
    bytearray(3 << 30)


def test_the_harness_reports_aborts_hangs_and_runaway_memory():
    with pytest.raises(AssertionError, match="signal 6"):
        run(abort)
    with pytest.raises(AssertionError, match="hung"):
        run(hang, timeout=1)
    out = run(hog)
    assert not out.ok and out.error_type == "builtins.MemoryError"
    checked(run(make_vec, {"num_envs": 2}))


# --- the properties ---

env_kwargs = st.fixed_dictionaries(
    {},
    optional={
        "task": st.one_of(st.sampled_from(TASKS), anything),
        "max_cycles": st.one_of(st.integers(1, 20), sizes),
        "continuous": st.one_of(st.booleans(), anything),
        "global_state": st.one_of(st.booleans(), anything),
        "patch": st.one_of(st.none(), st.integers(1, 8), sizes),
        "patch_side": st.one_of(st.floats(0.01, 0.2), anything),
        "seed": st.one_of(st.integers(0, 2**64 - 1), anything),
        "backend": st.sampled_from([None, "cpu", "CPU", "nope", 3]),
        "render_mode": st.sampled_from([None, "rgb_array", "ascii", 1]),
        "capture_distance": st.one_of(st.floats(0, 1), anything),
        "progress_weight": anything,
        "food": st.one_of(st.lists(st.lists(st.floats(-1, 2), max_size=3), max_size=2), anything),
        "no_such_param": anything,
    },
)


@SETTINGS
@given(kwargs=env_kwargs, steps=st.integers(0, 3))
def test_parallel_env_constructor(kwargs, steps):
    out = run(make_parallel, kwargs, steps)
    checked(out)
    if "seed" in kwargs and not valid_seed(kwargs["seed"]):
        assert not out.ok


vec_kwargs = st.fixed_dictionaries(
    {},
    optional={
        "task": st.sampled_from(TASKS),
        "num_envs": sizes,
        "num_threads": st.one_of(st.none(), st.integers(1, 4), sizes),
        "autoreset_mode": st.one_of(st.sampled_from(["next_step", "same_step", "disabled"]), anything),
        "max_cycles": st.one_of(st.integers(1, 20), sizes),
        "seed": st.one_of(st.integers(0, 2**64 - 1), anything),
        "patch": st.one_of(st.none(), st.integers(1, 8), sizes),
    },
)


@SETTINGS
@given(kwargs=vec_kwargs)
def test_vec_env_constructor(kwargs):
    checked(run(make_vec, kwargs))


@SETTINGS
@given(
    seed=st.one_of(st.none(), st.integers(0, 2**64 - 1), anything),
    options=st.one_of(st.none(), st.just({}), st.fixed_dictionaries({"reset_mask": anything}), anything),
)
def test_reset(seed, options):
    out = run(reset_both, seed, options)
    checked(out)
    if seed is not None and not valid_seed(seed):
        assert not out.ok
    if (seed is None or valid_seed(seed)) and options in (None, {}):
        assert out.ok, out.message


actions = st.one_of(
    anything,
    st.lists(st.floats(), min_size=2, max_size=2),
    st.integers(-2, 8),
    st.lists(st.integers(-2, 8), max_size=3).map(np.array),
    st.tuples(st.floats(-5, 5), st.floats(-5, 5)).map(lambda t: np.array(t, np.float32)),
)
agent_names = st.sampled_from(["robot_0", "robot_1", "robot_2", "robot_3", "robot_9", "", 0])


@SETTINGS
@given(continuous=st.booleans(), acts=st.dictionaries(agent_names, actions, max_size=4))
def test_parallel_step(continuous, acts):
    checked(run(step_parallel, continuous, acts))


@SETTINGS
@given(acts=st.lists(actions, max_size=8))
def test_aec_step(acts):
    checked(run(step_aec, acts))


@SETTINGS
@given(
    acts=st.one_of(
        anything,
        st.tuples(st.integers(0, 3), st.integers(0, 4), st.integers(0, 3)).map(lambda s: np.full(s, 0.5, np.float32)),
        st.just(np.full((2, 3, 2), np.nan, np.float32)),
        st.just(np.zeros((2, 3, 2), np.float64)),
    )
)
def test_vec_step(acts):
    checked(run(step_vec, acts))


@SETTINGS
@given(world=st.one_of(st.integers(-2, 3), anything), width=st.one_of(st.integers(-5, 700), sizes))
def test_render(world, width):
    checked(run(render, world, width))


@SETTINGS
@given(
    kwargs=st.fixed_dictionaries(
        {"task": st.sampled_from(TASKS), "max_cycles": st.integers(1, 5)},
        optional={"num_envs": sizes, "autoreset_mode": st.sampled_from(["next_step", "same_step", "sometimes"])},
    ),
    seed=st.one_of(st.none(), st.integers(0, 5), st.lists(st.integers(-1, 5), max_size=3), anything),
    acts=st.one_of(anything, st.integers(0, 12).map(lambda n: np.zeros((n, 2), np.float32))),
)
def test_gymnasium_vector(kwargs, seed, acts):
    checked(run(gym_vector, kwargs, seed, acts))


@SETTINGS
@given(
    name=st.one_of(st.sampled_from(sorted(colcos.behaviours())), anything),
    seed=st.one_of(st.integers(0, 9), anything),
    params=st.dictionaries(st.sampled_from(["speed", "nope", "turn_time"]), anything, max_size=2),
)
def test_baseline(name, seed, params):
    checked(run(baseline, name, seed, params))


@pytest.mark.skipif(not HAS_SB3, reason="needs stable-baselines3")
@settings(SETTINGS, max_examples=10)
@given(
    kwargs=st.fixed_dictionaries({"max_cycles": st.integers(1, 5)}, optional={"num_envs": sizes}),
    seed=st.one_of(st.none(), st.integers(0, 5), anything),
    acts=st.one_of(anything, st.integers(0, 12).map(lambda n: np.zeros((n, 2), np.float32))),
)
def test_sb3_adapter(kwargs, seed, acts):
    checked(run(sb3, kwargs, seed, acts, timeout=60))


@pytest.mark.skipif(not HAS_TORCHRL, reason="needs torchrl")
@settings(SETTINGS, max_examples=10)
@given(
    kwargs=st.fixed_dictionaries({"max_cycles": st.integers(1, 5)}, optional={"num_envs": sizes}),
    # TorchRL derives further seeds from a valid one itself; the invalid ones must stop at colcos.
    seed=st.one_of(st.none(), st.integers(0, 5), st.sampled_from([-1, 2**64, 1.5, True, "3"])),
)
def test_torchrl_adapter(kwargs, seed):
    checked(run(torchrl, kwargs, seed, timeout=60))
