"""The Python API under misuse: one exception tree, seeds, sizes, flags and actions checked the same
way everywhere, limits named, no panic and no deadlock."""

from __future__ import annotations

import inspect
import pydoc
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import colcos
from colcos.baselines import Baseline
from colcos.vector import VecEnv

BAD_SEEDS = [-1, 2**64, 1.5, True, "3", None]
GOOD_SEEDS = [0, 2**64 - 1, np.int32(3), np.uint64(2**64 - 1), np.int64(7)]


def test_exception_tree_subclasses_the_matching_builtins():
    tree = {
        colcos.ScenarioError: ValueError,
        colcos.TaskError: ValueError,
        colcos.ActionError: ValueError,
        colcos.StateError: RuntimeError,
        colcos.BackendError: ValueError,
        colcos.DisplayError: ValueError,
        colcos.ArgumentTypeError: TypeError,
        colcos.ActionTypeError: TypeError,
        colcos.UnknownAgentError: KeyError,
        colcos.InternalError: RuntimeError,
    }
    for cls, builtin in tree.items():
        assert issubclass(cls, colcos.ColcosError), cls
        assert issubclass(cls, builtin), cls
        assert cls.__module__ == "colcos"
    assert issubclass(colcos.ArgumentTypeError, colcos.TaskError)
    assert issubclass(colcos.UnknownAgentError, colcos.ActionError)
    # KeyError quotes its message; the colcos one prints it as given.
    assert str(colcos.UnknownAgentError("unknown agent 'x'")) == "unknown agent 'x'"


def test_a_panic_becomes_an_internal_error():
    with pytest.raises(colcos.InternalError, match="internal error.*boom"):
        colcos._core._test_panic("boom")


@pytest.mark.parametrize("seed", BAD_SEEDS[:-1], ids=repr)
def test_bad_seeds_are_refused_the_same_way_everywhere(seed):
    messages = set()
    env = colcos.parallel_env(max_cycles=5)
    venv = VecEnv("aggregation", num_envs=2, max_cycles=5)
    calls = [
        lambda: colcos.parallel_env(seed=seed),
        lambda: env.reset(seed=seed),
        lambda: VecEnv("aggregation", seed=seed),
        lambda: venv.reset(seed=seed),
        lambda: venv._core.reset(seed),
        lambda: colcos._core.VecEnv("aggregation", seed=seed),
        lambda: Baseline(venv, "avoid", seed=seed),
    ]
    for call in calls:
        with pytest.raises(colcos.ColcosError, match="seed must be an integer in 0..=2\\*\\*64-1") as e:
            call()
        expected = TypeError if isinstance(seed, (bool, float, str)) else ValueError
        assert isinstance(e.value, expected), (call, e.value)
        messages.add(str(e.value))
    assert len(messages) == 1, messages


@pytest.mark.parametrize("seed", GOOD_SEEDS, ids=repr)
def test_integer_seeds_and_numpy_scalars_are_accepted(seed):
    env = colcos.parallel_env(max_cycles=5, seed=seed)
    obs, _ = env.reset(seed=seed)
    venv = VecEnv("aggregation", num_envs=1, max_cycles=5, seed=seed)
    venv.reset(seed=seed)
    assert venv._core.seed == int(seed)
    np.testing.assert_array_equal(venv.obs[0, 0], obs["robot_0"])


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"num_envs": -1}, "num_envs"),
        ({"num_envs": 0}, "num_envs"),
        ({"num_envs": 10**6}, "num_envs"),
        ({"num_envs": 2.0}, "num_envs"),
        ({"num_threads": 0}, "num_threads"),
        ({"num_threads": 10**5}, "num_threads"),
        ({"max_cycles": 0}, "max_cycles"),
        ({"max_cycles": 2**40}, "max_cycles"),
        ({"max_cycles": -3}, "max_cycles"),
        ({"patch": 10**20}, "patch"),
        ({"patch": 0}, "patch"),
        ({"patch": 8, "patch_side": float("nan")}, "patch_side"),
        ({"continuous": "False"}, "continuous"),
        ({"continuous": 0}, "continuous"),
        ({"global_state": "yes"}, "global_state"),
        ({"capture_distance": float("nan")}, "capture_distance"),
        ({"capture_distance": "0.1"}, "aggregation.capture_distance"),
        ({"progress_weight": 1e30}, "progress_weight"),
        ({"alarm_weight": np.float64(3e38)}, "alarm_weight"),
        ({"render_mode": 3}, "render_mode"),
        ({"autoreset_mode": "sometimes"}, "autoreset_mode"),
        ({"task": 3}, "task"),
    ],
    ids=str,
)
def test_bad_arguments_name_the_argument(kwargs, name):
    with pytest.raises(colcos.ColcosError, match=name) as e:
        VecEnv(**{"task": "aggregation", **kwargs})
    assert not isinstance(e.value, OverflowError)


def test_flags_accept_numpy_bools_and_numbers_accept_numpy_scalars():
    env = colcos.parallel_env(
        continuous=np.bool_(False),
        global_state=np.bool_(True),
        max_cycles=np.int64(5),
        patch=np.int32(4),
        patch_side=np.float32(0.05),
        capture_distance=np.float32(0.1),
        seed=np.uint64(1),
    )
    obs, _ = env.reset()
    assert obs["robot_0"]["patch"].shape == (4, 4, 3)
    assert env.action_space("robot_0").n == 6
    venv = VecEnv("trail", num_envs=np.int64(2), num_threads=np.int8(1), seed=np.uint8(4), bump_penalty=np.float16(0.5))
    assert venv.num_envs == 2 and venv._core.seed == 4


def test_render_and_world_limits():
    venv = VecEnv("aggregation", num_envs=2, max_cycles=5)
    venv.reset(seed=0)
    assert venv.render(1, np.int64(32)).shape[1] == 32
    for world, width, name in [(0, 10**9, "width"), (0, -1, "width"), (0, 2**70, "width"), (2, 64, "world"), (-1, 64, "world"), (0, 64.0, "width")]:
        with pytest.raises(colcos.ColcosError, match=name):
            venv.render(world, width)
    for call in (venv.episode_steps, venv.episode, venv.poses):
        with pytest.raises(colcos.TaskError, match="world"):
            call(5)


def test_reset_masks_are_checked():
    venv = VecEnv("aggregation", num_envs=3, max_cycles=5)
    venv.reset(seed=0)
    with pytest.raises(colcos.ActionTypeError, match="reset_mask"):
        venv.reset(options={"reset_mask": np.ones(3, np.int64)})
    with pytest.raises(colcos.ActionError, match="reset_mask"):
        venv.reset(options={"reset_mask": np.ones((3, 1), bool)})
    with pytest.raises(colcos.ArgumentTypeError, match="options"):
        venv.reset(options=[1])
    g = colcos.gymnasium_vector.ColcosVectorEnv("aggregation", num_envs=2, max_cycles=5)
    g.reset(seed=0)
    with pytest.raises(colcos.ActionError, match=r"reset_mask must have shape \(6,\)"):
        g.reset(options={"reset_mask": np.ones(5, bool)})
    with pytest.raises(colcos.ActionError, match=r"expected \(6, 2\)"):
        g.step(np.zeros((5, 2), np.float32))


def _acts(env, value=0.0):
    return {a: np.full(2, value, np.float32) for a in env.agents}


@pytest.mark.parametrize(
    ("action", "error", "pattern"),
    [
        (None, colcos.ActionTypeError, "robot_1"),
        (0.5, colcos.ActionError, r"robot_1.*shape \(2,\)"),
        (np.float32(0.5), colcos.ActionError, r"robot_1.*shape \(2,\)"),
        ([0.5], colcos.ActionError, r"robot_1.*shape \(2,\)"),
        (np.zeros((1, 2)), colcos.ActionError, r"robot_1.*shape \(2,\)"),
        ("go", colcos.ActionTypeError, "robot_1"),
        ([True, False], colcos.ActionTypeError, "robot_1"),
        ([np.inf, 0.0], colcos.ActionError, "robot_1.*finite"),
    ],
    ids=repr,
)
def test_bad_continuous_actions_are_refused(action, error, pattern):
    env = colcos.parallel_env(max_cycles=5)
    env.reset(seed=0)
    acts = _acts(env)
    acts["robot_1"] = action
    with pytest.raises(error, match=pattern):
        env.step(acts)


def test_missing_and_unknown_agents_are_refused():
    env = colcos.parallel_env(max_cycles=5)
    env.reset(seed=0)
    acts = _acts(env)
    del acts["robot_2"]
    with pytest.raises(colcos.ActionError, match="robot_2"):
        env.step(acts)
    with pytest.raises(KeyError):
        env.step({**_acts(env), "robot_9": np.zeros(2, np.float32)})
    with pytest.raises(colcos.ActionTypeError, match="dict"):
        env.step([np.zeros(2, np.float32)] * 3)
    for space in (env.observation_space, env.action_space):
        with pytest.raises(colcos.UnknownAgentError, match="robot_7"):
            space("robot_7")
    with pytest.raises(colcos.TaskError, match="render mode"):
        env.render("ascii")


def test_out_of_range_continuous_actions_are_clipped():
    runs = []
    for value in (1.0, 7.5, 1e30):
        env = colcos.parallel_env(max_cycles=5)
        env.reset(seed=3)
        for _ in range(3):
            obs, *_ = env.step(_acts(env, value))
        runs.append((obs["robot_0"], env.poses()))
    for obs, poses in runs[1:]:
        np.testing.assert_array_equal(obs, runs[0][0])
        np.testing.assert_array_equal(poses, runs[0][1])


@pytest.mark.parametrize("action", [None, 1.0, True, "1", np.float64(2.0), [1]], ids=repr)
def test_bad_discrete_actions_are_refused(action):
    env = colcos.parallel_env(max_cycles=5, continuous=False)
    env.reset(seed=0)
    acts = {a: 1 for a in env.agents}
    acts["robot_0"] = action
    with pytest.raises(colcos.ActionError, match="robot_0"):
        env.step(acts)


def test_discrete_actions_take_numpy_integers():
    env = colcos.parallel_env(max_cycles=5, continuous=False)
    env.reset(seed=0)
    env.step({a: np.int64(1) if i else np.array(2) for i, a in enumerate(env.agents)})


def test_the_aec_env_raises_at_the_step_that_receives_a_bad_action():
    aec = colcos.env(task="aggregation", max_cycles=5)
    aec.reset(seed=0)
    first = aec.agent_selection
    with pytest.raises(colcos.ActionError, match=first):
        aec.step(np.array([0.1, 0.2, 0.3], np.float32))
    assert aec.agent_selection == first
    aec.step(np.zeros(2, np.float32))
    with pytest.raises(colcos.ActionTypeError, match=aec.agent_selection):
        aec.step(None)
    # A done agent's action must be None (PettingZoo's convention), said as an ActionError.
    while aec.agents:
        agent = aec.agent_selection
        done = aec.terminations[agent] or aec.truncations[agent]
        if done:
            with pytest.raises(colcos.ActionError, match=f"{agent}.*done"):
                aec.step(np.zeros(2, np.float32))
        aec.step(None if done else np.zeros(2, np.float32))


def test_help_shows_the_real_signature_and_docs():
    for make in (colcos.parallel_env, colcos.env, colcos.raw_env):
        params = inspect.signature(make).parameters
        for name in ("task", "scenario", "max_cycles", "continuous", "seed", "backend", "params"):
            assert name in params, (make, name)
        text = pydoc.render_doc(make)
        assert "max_cycles" in text and "steps per episode" in text


def test_import_colcos_makes_the_vector_modules_available():
    code = "import colcos; print(colcos.vector.VecEnv.__name__, colcos.gymnasium_vector.ColcosVectorEnv.__name__)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["VecEnv", "ColcosVectorEnv"]


@pytest.mark.parametrize("task", sorted(colcos.tasks()))
def test_observation_spaces_bound_the_values(task):
    env = colcos.parallel_env(task=task, max_cycles=150, patch=4)
    space = env.observation_space("robot_0")
    vec = space["vector"]
    # 17 sensor values, then the task's extra entries (a carrying or predator-near flag in [0, 1]).
    assert (vec.low[:15] == 0).all() and (vec.low[15:17] == -1).all() and (vec.high == 1).all()
    assert (vec.low[17:] == 0).all()
    width = env.action_space("robot_0").shape[0]
    state = env.state_space
    assert state.low[-1] == 0 and (state.low[:-1] == -1).all()
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=1)
    seen = []
    for _ in range(150):
        for a, o in obs.items():
            assert env.observation_space(a).contains(o), (a, o)
            seen.append(o["vector"])
        assert state.contains(env.state())
        if not env.agents:
            break
        obs, *_ = env.step({a: rng.uniform(-1.5, 1.5, width).astype(np.float32) for a in env.agents})
    venv = VecEnv(task, num_envs=2, max_cycles=20)
    assert venv.single_observation_space.contains(venv.obs[0, 0])
    assert np.array_equal(venv.single_observation_space.low, vec.low)


THREADS = textwrap.dedent(
    """
    import threading, time
    import numpy as np
    import colcos
    from colcos.vector import VecEnv

    env = colcos.parallel_env(task="trail", max_cycles=10**6)
    env.reset(seed=0)
    venv = VecEnv("trail", num_envs=4, num_threads=2, max_cycles=50)
    venv.reset(seed=0)
    acts = np.zeros((4, venv.num_agents, 2), np.float32)
    stop = time.monotonic() + 2.0
    counts = {}

    def loop(name, body):
        n = 0
        while time.monotonic() < stop:
            body()
            n += 1
        counts[name] = n

    bodies = {
        "step": lambda: env.step({a: np.full(2, 0.3, np.float32) for a in env.agents}),
        "vstep": lambda: venv.step(acts),
        "vstep2": lambda: venv.step(acts),
        "read": lambda: (env.poses(), env.backend_name, env.backend_info, env.state(),
                         venv.poses(1), venv.episode_steps(0), venv.episode(3), venv._core.seed,
                         venv._core.spec(), venv._core.roles(), venv.render(0, 32)),
        "reset": lambda: venv.reset(options={"reset_mask": np.array([False, True, False, False])}),
    }
    threads = [threading.Thread(target=loop, args=kv) for kv in bodies.items()]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    print(sorted(counts.items()))
    assert all(n > 0 for n in counts.values()), counts
    """
)


def test_threads_sharing_an_env_never_deadlock():
    # A child process, so that a deadlock fails this test instead of hanging the suite.
    try:
        out = subprocess.run([sys.executable, "-c", THREADS], capture_output=True, text=True, timeout=90)
    except subprocess.TimeoutExpired:
        pytest.fail("threads sharing one env deadlocked (the child did not finish in 90 s)")
    assert out.returncode == 0, out.stderr[-2000:]
