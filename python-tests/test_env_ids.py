"""Registered ids: `gymnasium.make_vec("colcos/<task>-v<N>")` and `colcos.tasks.<task>_v<N>` modules for
every task of `colcos.tasks()`, the same environments as `colcos.parallel_env(task=...)`, and unknown
ids refused by name."""

from __future__ import annotations

import importlib
import pickle
import subprocess
import sys
import types

import gymnasium
import numpy as np
import pytest
from pettingzoo.test import parallel_api_test

import colcos
import colcos.tasks
from colcos.gymnasium_vector import ColcosVectorEnv

TASKS = sorted(colcos.tasks())


def test_tasks_is_callable_and_a_package():
    # `colcos.tasks()` lists the tasks as it always has; `colcos.tasks` is also the package of modules.
    assert isinstance(colcos.tasks, types.ModuleType)
    listed = colcos.tasks()
    assert isinstance(listed, dict) and {"aggregation", "foraging", "trail"} <= set(listed)
    assert all(isinstance(d, str) and d for d in listed.values())
    assert colcos.tasks.versions() == {t: colcos.tasks.VERSION_BUMPS.get(t, 0) for t in listed}


def test_every_task_has_an_id_and_a_module():
    # Derived from the core's tasks: a task added there has both with nothing else to write.
    versions = colcos.tasks.versions()
    assert set(versions) == set(TASKS)
    assert colcos.tasks.ids() == [f"colcos/{t}-v{v}" for t, v in versions.items()]
    for task, v in versions.items():
        gid = f"colcos/{task}-v{v}"
        assert gid in gymnasium.registry
        mod = importlib.import_module(f"colcos.tasks.{task}_v{v}")
        assert mod is getattr(colcos.tasks, f"{task}_v{v}")
        assert (mod.TASK, mod.VERSION, mod.ENV_ID) == (task, v, gid)
        assert f"{task}_v{v}" in colcos.tasks.__all__


@pytest.mark.parametrize("task", TASKS)
def test_module_is_the_task(task):
    # The versioned module's env follows the same trajectory as `colcos.parallel_env(task=...)`.
    mod = getattr(colcos.tasks, colcos.tasks.module_name(task, colcos.tasks.versions()[task]))
    a = mod.parallel_env(max_cycles=20)
    b = colcos.parallel_env(task=task, max_cycles=20)
    assert a.metadata["name"] == f"colcos_{mod.__name__.rsplit('.', 1)[1]}"
    oa, _ = a.reset(seed=3)
    ob, _ = b.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(20):
        if not a.agents:
            break
        space = a.action_space(a.agents[0])  # wheels, then the task's deposit rates
        acts = {ag: rng.uniform(space.low, space.high).astype(np.float32) for ag in a.agents}
        oa, ra, ta, ua, _ = a.step(acts)
        ob, rb, tb, ub, _ = b.step(acts)
        assert ra == rb and ta == tb and ua == ub
        for ag in oa:
            np.testing.assert_array_equal(oa[ag], ob[ag])
    aec = mod.env(max_cycles=5)
    aec.reset(seed=0)
    assert aec.metadata["name"] == a.metadata["name"]
    raw = mod.raw_env(max_cycles=5)
    raw.reset(seed=0)
    for env in (a, b, aec, raw):
        env.close()


def test_module_passes_pettingzoo_api_test():
    from colcos.tasks import aggregation_v0

    parallel_api_test(aggregation_v0.parallel_env(max_cycles=30), num_cycles=30)


def test_import_forms_and_pickle():
    import colcos.tasks.trail_v0 as trail_v0
    from colcos.tasks import foraging_v0

    assert trail_v0.TASK == "trail" and foraging_v0.TASK == "foraging"
    # The functions and the environments pickle (SuperSuit and multiprocessing send them).
    make = pickle.loads(pickle.dumps(foraging_v0.parallel_env))
    assert make is foraging_v0.parallel_env
    env = pickle.loads(pickle.dumps(foraging_v0.parallel_env(max_cycles=5)))
    assert env.metadata["name"] == "colcos_foraging_v0"
    env.reset(seed=0)
    env.close()


def test_signature_and_help_name_the_real_arguments():
    import inspect

    from colcos.tasks import aggregation_v0

    params = inspect.signature(aggregation_v0.parallel_env).parameters
    assert "max_cycles" in params and "continuous" in params and "task" not in params
    assert "aggregation" in (aggregation_v0.parallel_env.__doc__ or "")
    assert "aggregation" in (aggregation_v0.__doc__ or "")


@pytest.mark.parametrize("task", TASKS)
def test_make_vec(task):
    gid = colcos.tasks.env_id(task, colcos.tasks.versions()[task])
    venv = gymnasium.make_vec(gid, num_envs=2, max_cycles=10, continuous=False)
    assert isinstance(venv, ColcosVectorEnv)
    agents = venv.venv.num_agents
    # `num_envs` counts worlds: one sub-environment per agent of each world.
    assert venv.num_envs == 2 * agents
    assert venv.spec is not None and venv.spec.id == gid
    obs, _ = venv.reset(seed=0)
    # 17 sensor values, then the task's own entries (colony's carrying flag, alarm's predator flag).
    assert obs.shape == (2 * agents, venv.single_observation_space.shape[0])
    assert obs.shape[1] >= 17
    obs, rew, term, trunc, _ = venv.step(venv.action_space.sample())
    assert rew.shape == (2 * agents,) and term.dtype == np.bool_ and trunc.dtype == np.bool_
    venv.close()


def test_make_vec_with_module_prefix_imports_colcos():
    # `module:id` makes Gymnasium import colcos (which registers the ids) in a fresh interpreter.
    code = (
        "import sys, gymnasium; assert 'colcos' not in sys.modules;"
        "v = gymnasium.make_vec('colcos:colcos/aggregation-v0', num_envs=3); print(v.num_envs)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "9"


def test_make_single_env_refused():
    # A multi-agent task is no single-agent Env: the message points at make_vec and the module.
    with pytest.raises(colcos.TaskError, match=r"make_vec\('colcos/aggregation-v0'.*aggregation_v0\.parallel_env"):
        gymnasium.make("colcos/aggregation-v0")


def test_unknown_ids_refused_by_name():
    with pytest.raises(gymnasium.error.NameNotFound, match="nosuch"):
        gymnasium.make_vec("colcos/nosuch-v0", num_envs=1)
    with pytest.raises(gymnasium.error.VersionNotFound, match=r"v7.*colcos/aggregation"):
        gymnasium.make_vec("colcos/aggregation-v7", num_envs=1)
    # The task modules: an unknown one is a TaskError and an ImportError naming it and the known ones.
    with pytest.raises(colcos.tasks.UnknownTaskIdError, match=r"'nosuch_v0'.*aggregation_v0, .*foraging_v0, trail_v0"):
        from colcos.tasks import nosuch_v0  # noqa: F401
    with pytest.raises(colcos.TaskError, match=r"'aggregation_v7'.*is at aggregation_v0"):
        colcos.tasks.aggregation_v7  # noqa: B018
    with pytest.raises(ImportError, match="trail_v9"):
        from colcos.tasks import trail_v9  # noqa: F401
    # Anything that is not a task module's name stays a plain AttributeError (hasattr works).
    assert not hasattr(colcos.tasks, "no_such_thing")


def test_fixed_task_not_overridden():
    from colcos.tasks import aggregation_v0

    with pytest.raises(colcos.TaskError, match=r"aggregation_v0.parallel_env makes task 'aggregation'.*task='trail'"):
        aggregation_v0.parallel_env(task="trail")
    with pytest.raises(colcos.TaskError, match="aggregation_v0.vector_env makes task 'aggregation'"):
        gymnasium.make_vec("colcos/aggregation-v0", num_envs=1, task="trail")
    # Bad arguments are refused as by colcos.parallel_env.
    with pytest.raises(colcos.TaskError, match="no_such_param"):
        aggregation_v0.parallel_env(no_such_param=1)


def test_reimport_keeps_one_registration(recwarn):
    # Reloading the package leaves the registry as it was, without Gymnasium's override warning.
    before = {gid: gymnasium.registry[gid] for gid in colcos.tasks.ids()}
    importlib.reload(colcos.tasks)
    assert {gid: gymnasium.registry[gid] for gid in colcos.tasks.ids()} == before
    assert not [w for w in recwarn if "Overriding environment" in str(w.message)]
    assert callable(colcos.tasks) and "aggregation" in colcos.tasks()
