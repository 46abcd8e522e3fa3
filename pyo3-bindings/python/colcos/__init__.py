"""colcos: ColCOSPhi multi-pheromone swarm robotics as PettingZoo and Gymnasium environments.

Environments over a batched Rust core. Every task's agents observe only their own robot's sensors
(four colour sensors x three channels, three bumpers, their last wheel command) and set its two
wheel speeds.

>>> import colcos
>>> env = colcos.parallel_env(task="aggregation", max_cycles=500)
>>> obs, infos = env.reset(seed=0)

| task          | agents                | observation     | action                          |
|---------------|-----------------------|-----------------|---------------------------------|
| `aggregation` | followers (3)         | Box((17,)) f32  | Box(-1, 1, (2,)) or Discrete(6) |
| `foraging`    | foragers (2)          | Box((17,)) f32  | same                            |
| `trail`       | trail robots (4)      | Box((17,)) f32  | same                            |
| `colony`      | ants (6)              | Box((18,)) f32  | Box((4,)) or Discrete(24)       |
| `coverage`    | explorers (4)         | Box((17,)) f32  | Box((3,)) or Discrete(12)       |
| `alarm`       | prey (6)              | Box((18,)) f32  | Box((3,)) or Discrete(12)       |

Versioned by task, as PettingZoo's and Gymnasium's environments are: `from colcos.tasks import
aggregation_v0; aggregation_v0.parallel_env()`, `gymnasium.make_vec("colcos/aggregation-v0", num_envs=64)`
(see `colcos.tasks`).

Observation bounds per entry: colour intensities and bumpers in [0, 1], the last wheel command in
[-1, 1]; `colony` appends a carrying flag and `alarm` a predator-near flag, each in [0, 1]. The
last three tasks' agents also choose how much pheromone to lay (docs/tasks.md). Every error raised
is a `colcos.ColcosError` (see docs/python.md, "Errors").
"""

from __future__ import annotations

# `colcos.vector` and `colcos.gymnasium_vector` come with `import colcos` (they need only numpy and
# gymnasium); the SB3 and TorchRL adapters import their libraries and stay opt-in. `colcos.tasks()`
# lists the tasks, `colcos.tasks.aggregation_v0` etc. make them, and importing `colcos.tasks`
# registers the Gymnasium ids `colcos/<task>-v<version>`.
from colcos import _core, gymnasium_vector, rig, sweep, tasks, vector
from colcos import preflight as preflight  # noqa: E402  (after pettingzoo_env, which it imports)
from colcos._core import (
    ActionError,
    ActionTypeError,
    ArgumentTypeError,
    BackendError,
    ColcosError,
    DisplayError,
    InternalError,
    PlantUnreachableError,
    ScenarioError,
    StateError,
    TaskError,
    UnknownAgentError,
    default_scenario,
    discrete_actions,
    observation_names,
)
from colcos.pettingzoo_env import ColcosParallelEnv, env, parallel_env, raw_env
from colcos.task import ResetContext, Task, TaskHookError, View

__version__ = _core.__version__

__all__ = [
    "ActionError",
    "ActionTypeError",
    "ArgumentTypeError",
    "BackendError",
    "ColcosError",
    "DisplayError",
    "ColcosParallelEnv",
    "InternalError",
    "PlantUnreachableError",
    "ResetContext",
    "ScenarioError",
    "StateError",
    "Task",
    "TaskError",
    "TaskHookError",
    "UnknownAgentError",
    "View",
    "behaviour_params",
    "behaviours",
    "default_scenario",
    "discrete_actions",
    "env",
    "gymnasium_vector",
    "observation_names",
    "parallel_env",
    "preflight",
    "raw_env",
    "rig",
    "sweep",
    "task_policies",
    "tasks",
    "vector",
]


def behaviours() -> dict[str, str]:
    """Every hand-written behaviour (usable with `colcos.baselines.Baseline`): name -> description.

    `behaviour_params(name)` lists the parameters of each.
    """
    return dict(_core.behaviours())


def task_policies() -> dict[str, tuple[str, str]]:
    """The hand-written policies of the tasks whose agents lay pheromone (usable with
    `colcos.baselines.Baseline`, which then sets the deposit rates too): name -> (task, description).
    """
    return {name: (task, about) for name, task, about in _core.task_policies()}


def behaviour_params(name: str) -> list[dict[str, str]]:
    """The keys of behaviour `name`'s `params`, as `colcos behaviours` prints them: one dict per key
    with `name`, `type` (TOML type, unit and allowed range), `default` (as TOML) and `meaning`.

    Raises `TaskError` for an unknown behaviour.
    """
    return [
        {"name": key, "type": ty, "default": default, "meaning": meaning}
        for key, ty, default, meaning in _core.behaviour_params(name)
    ]
