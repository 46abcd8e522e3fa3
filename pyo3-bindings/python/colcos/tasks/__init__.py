"""The built-in tasks by versioned name: `colcos.tasks()` lists them, a module per task makes them.

>>> import colcos
>>> colcos.tasks()                                   # name -> one-line description
>>> from colcos.tasks import aggregation_v0           # PettingZoo-style, as MPE's `simple_spread_v3`
>>> env = aggregation_v0.parallel_env(max_cycles=500)
>>> import gymnasium
>>> venv = gymnasium.make_vec("colcos/aggregation-v0", num_envs=64)

`colcos.tasks` is a package that can also be called: `colcos.tasks()` returns every task's name and
description. For every task it holds a module `<task>_v<version>` with `parallel_env(**kwargs)`,
`env(**kwargs)` and `raw_env(**kwargs)` (those of `colcos.parallel_env` etc. with the task fixed) and
`vector_env(num_envs, **kwargs)` (a `colcos.gymnasium_vector.ColcosVectorEnv`), and `import colcos`
registers the Gymnasium id `colcos/<task>-v<version>` with that `vector_env` as its vector entry
point. The modules and ids are made from the tasks the native core has, so every task has them.

A task's version rises when a change alters what the task returns for the same seed, arguments and
actions (observations, rewards, terminations, truncations, infos, spaces): results reported against
`colcos/aggregation-v0` stay comparable. Only the current version of each task exists; an older
version is refused, naming the current one (Gymnasium raises its `DeprecatedEnv`).
"""

from __future__ import annotations

import re
import sys
import types
from importlib.machinery import ModuleSpec
from typing import Any

import gymnasium
from pettingzoo.utils import wrappers

from colcos import _actions, _core
from colcos._core import TaskError
from colcos._options import share_signature
from colcos.gymnasium_vector import ColcosVectorEnv
from colcos.pettingzoo_env import ColcosParallelEnv

# The tasks whose version is above 0: a change that alters what a task returns raises its entry here
# (see the module docs). A task not listed, a new one included, is at version 0.
VERSION_BUMPS: dict[str, int] = {}

NAMESPACE = "colcos"

# What a task module's name looks like: an attribute of this form that is not one is refused with
# the known modules listed (any other missing attribute is a plain AttributeError).
_MODULE_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*_v[0-9]+")


class UnknownTaskIdError(TaskError, ImportError):
    """An environment id or task module that colcos does not have (a `TaskError` and an
    `ImportError`, which `from colcos.tasks import ...` raises)."""


class _TasksModule(types.ModuleType):
    """`colcos.tasks` itself: a package, and callable so that `colcos.tasks()` lists the tasks."""

    def __call__(self) -> dict[str, str]:
        """Every task: name -> one-line description."""
        return dict(_core.tasks())


def versions() -> dict[str, int]:
    """Every task's current version: task name -> version."""
    return {task: VERSION_BUMPS.get(task, 0) for task, _ in _core.tasks()}


def module_name(task: str, version: int) -> str:
    """The name of `task`'s module in `colcos.tasks` (`aggregation_v0`)."""
    return f"{task.replace('-', '_')}_v{version}"


def env_id(task: str, version: int) -> str:
    """`task`'s Gymnasium id (`colcos/aggregation-v0`)."""
    return f"{NAMESPACE}/{task}-v{version}"


def ids() -> list[str]:
    """Every registered Gymnasium id, one per task at its current version."""
    return [env_id(task, v) for task, v in versions().items()]


def _fixed(task: str, name: str, kwargs: dict[str, Any]) -> dict[str, Any]:
    """`kwargs` with `task` set; a `task=` of the caller's is refused rather than silently replaced."""
    if "task" in kwargs:
        raise TaskError(
            f"{name} makes task {task!r}; other tasks have their own modules (colcos.tasks), and "
            f"colcos.parallel_env(task=...) takes any task, a colcos.Task included; got task={kwargs['task']!r}"
        )
    return dict(kwargs, task=task)


def _task_module(task: str, version: int) -> types.ModuleType:
    """The module `colcos.tasks.<task>_v<version>` (see the package docs)."""
    short = module_name(task, version)
    full = f"{__name__}.{short}"
    gym_id = env_id(task, version)
    mod = types.ModuleType(
        full,
        f"Task `{task}`, version {version}: `parallel_env()`, `env()` and `raw_env()` as PettingZoo's, "
        f"`vector_env(num_envs)` (Gymnasium id `{gym_id}`). Arguments: those of `colcos.parallel_env`, "
        "without `task`.",
    )
    # A spec lets tools that look modules up by name (pickle, multiprocessing, inspect) find it.
    mod.__spec__ = ModuleSpec(full, None)
    mod.__package__ = __name__
    # PettingZoo's convention: an environment's metadata names its versioned module.
    metadata_name = f"{NAMESPACE}_{short}"

    def parallel_env(**kwargs: Any) -> ColcosParallelEnv:
        env = ColcosParallelEnv(**_fixed(task, f"{short}.parallel_env", kwargs))
        env.metadata = dict(env.metadata, name=metadata_name)
        return env

    def raw_env(**kwargs: Any) -> Any:
        return _actions.CheckedAecWrapper(parallel_env(**kwargs))

    def env(**kwargs: Any) -> Any:
        return wrappers.OrderEnforcingWrapper(raw_env(**kwargs))

    def vector_env(num_envs: int = 1, **kwargs: Any) -> ColcosVectorEnv:
        """A Gymnasium `VectorEnv` over `num_envs` worlds: one sub-environment per agent of each world,
        `num_envs * agents` in all (parameter sharing). Other arguments go to `colcos.vector.VecEnv`.
        The vector entry point of `gymnasium.make_vec`."""
        return ColcosVectorEnv(num_envs=num_envs, **_fixed(task, f"{short}.vector_env", kwargs))

    def _single_env(**kwargs: Any) -> Any:
        # `gymnasium.make` wants a single-agent `Env`, which a multi-agent task is not.
        raise TaskError(
            f"{gym_id} is multi-agent and has no single-agent gymnasium.make: use "
            f"gymnasium.make_vec({gym_id!r}, num_envs=...) (one sub-environment per agent) or "
            f"colcos.tasks.{short}.parallel_env() (PettingZoo)"
        )

    docs = {
        parallel_env: f"Task `{task}` as a PettingZoo `ParallelEnv` (`colcos.parallel_env` with the task fixed).",
        raw_env: f"The AEC form of `parallel_env`, without the order-enforcing wrapper (task `{task}`).",
        env: f"The AEC form of `parallel_env`, wrapped as PettingZoo's `env()` functions are (task `{task}`).",
    }
    for f in (parallel_env, raw_env, env, vector_env, _single_env):
        # Named as module-level functions of `full`, so pickle finds them there.
        f.__module__ = full
        f.__qualname__ = f.__name__
        setattr(mod, f.__name__, f)
    for f, doc in docs.items():
        f.__doc__ = doc
        share_signature(f, ColcosParallelEnv)
        sig = f.__signature__  # type: ignore[attr-defined]
        f.__signature__ = sig.replace(parameters=[p for p in sig.parameters.values() if p.name != "task"])  # type: ignore[attr-defined]
    mod.TASK = task  # type: ignore[attr-defined]
    mod.VERSION = version  # type: ignore[attr-defined]
    mod.ENV_ID = gym_id  # type: ignore[attr-defined]
    mod.__all__ = ["parallel_env", "env", "raw_env", "vector_env", "TASK", "VERSION", "ENV_ID"]  # type: ignore[attr-defined]
    return mod


def _register(mod: types.ModuleType) -> None:
    """Registers `mod`'s Gymnasium id, once per interpreter (a re-import leaves it as it is)."""
    gym_id = mod.ENV_ID
    if gym_id in gymnasium.registry:
        return
    gymnasium.register(
        id=gym_id,
        entry_point=f"{mod.__name__}:_single_env",
        vector_entry_point=f"{mod.__name__}:vector_env",
        # The checker steps a single-agent `Env`; `make` refuses these ids before it would run.
        disable_env_checker=True,
    )


def _known() -> str:
    return ", ".join(sorted(_MODULES))


def __getattr__(name: str) -> Any:
    if _MODULE_NAME.fullmatch(name):
        task = name.rsplit("_v", 1)[0]
        same = [m for m in _MODULES if m.rsplit("_v", 1)[0] == task]
        hint = f" (task {task!r} is at {same[0]}: a task's version rises when what it returns changes)" if same else ""
        raise UnknownTaskIdError(f"colcos.tasks has no module {name!r}{hint}; the task modules are {_known()}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# One module per task, made now: `import colcos.tasks.aggregation_v0` and
# `from colcos.tasks import aggregation_v0` then find it in `sys.modules` and in this package.
_MODULES: dict[str, types.ModuleType] = {}
for _task, _version in versions().items():
    _mod = _task_module(_task, _version)
    _MODULES[module_name(_task, _version)] = _mod
    sys.modules[_mod.__name__] = _mod
    globals()[module_name(_task, _version)] = _mod
    _register(_mod)

__all__ = ["NAMESPACE", "VERSION_BUMPS", "UnknownTaskIdError", "env_id", "ids", "module_name", "versions", *_MODULES]

sys.modules[__name__].__class__ = _TasksModule
