"""colcos as a BenchMARL task family, in BenchMARL's own form (as its VMAS family): a `TaskClass`
that builds the TorchRL environment over the batched core (`colcos.torchrl_env.ColcosTorchEnv`), an
enum `ColcosTask` with one member per built-in task, and one YAML config per task under `conf/`.

    from benchmarl.algorithms import MappoConfig
    from benchmarl.experiment import Experiment, ExperimentConfig
    from benchmarl.models.mlp import MlpConfig
    from colcos.benchmarl import ColcosTask

    Experiment(task=ColcosTask.AGGREGATION.get_from_yaml(), algorithm_config=MappoConfig.get_from_yaml(),
               model_config=MlpConfig.get_from_yaml(), critic_model_config=MlpConfig.get_from_yaml(),
               seed=0, config=ExperimentConfig.get_from_yaml()).run()

`examples/benchmarl_run.py` does this from the command line. BenchMARL's `num_envs` (its
`on_policy_n_envs_per_worker` / `off_policy_n_envs_per_worker`) is the number of colcos worlds
stepped as one batch in Rust; the agents of a world form one group, `"robot"`. Needs `benchmarl`
(1.5, with its TorchRL 0.11).
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Callable
from pathlib import Path
from typing import Any

from benchmarl.environments.common import Task, TaskClass
from torchrl.data import Composite
from torchrl.envs import EnvBase

from colcos import _core
from colcos._core import TaskError

_CONF = Path(__file__).resolve().parent / "conf"


@dataclasses.dataclass
class TaskConfig:
    """The keys a task's YAML may set (every other key is refused, naming it)."""

    max_steps: int = 500
    """Steps of an episode (the env's `max_cycles`) and of BenchMARL's evaluation rollouts."""
    scenario: str | None = None
    """A scenario file (TOML) in place of the task's own."""
    physics: str | None = None
    """`"discs"` or `"rapier"` (default: the scenario's)."""
    backend: str | None = None
    """The field backend: `"cpu"`, `"gpu"` or `"auto"` (default: the scenario's)."""
    num_threads: int | None = None
    """Threads stepping the worlds (default: all cores)."""
    params: dict[str, Any] = dataclasses.field(default_factory=dict)
    """The task's own parameters (docs/tasks.md), e.g. `{capture_radius: 0.1}` for `alarm`."""


def _checked(task: str, config: dict[str, Any]) -> dict[str, Any]:
    known = {f.name for f in dataclasses.fields(TaskConfig)}
    unknown = sorted(set(config) - known)
    if unknown:
        raise TaskError(f"colcos/{task}: unknown config key(s) {unknown}; known: {sorted(known)}")
    return dataclasses.asdict(TaskConfig(**config))


class ColcosClass(TaskClass):
    """A colcos task for BenchMARL: `name` is the task's enum name, `config` its YAML."""

    def get_env_fun(self, num_envs: int, continuous_actions: bool, seed: int | None, device: Any) -> Callable[[], EnvBase]:
        from colcos.torchrl_env import ColcosTorchEnv

        task = self.name.lower()
        config = _checked(task, copy.deepcopy(self.config))
        params = config.pop("params") or {}
        kwargs = {k: v for k, v in config.items() if v is not None and k != "max_steps"}

        def make() -> EnvBase:
            env = ColcosTorchEnv(
                task, num_envs=num_envs, device=device, continuous=continuous_actions, max_cycles=config["max_steps"], **kwargs, **params
            )
            if seed is not None:
                env.set_seed(seed)
            return env

        return make

    def supports_continuous_actions(self) -> bool:
        return True

    def supports_discrete_actions(self) -> bool:
        return True

    def has_render(self, env: EnvBase) -> bool:
        return False

    def max_steps(self, env: EnvBase) -> int:
        return int(_checked(self.name.lower(), dict(self.config))["max_steps"])

    def group_map(self, env: EnvBase) -> dict[str, list[str]]:
        return {"robot": [f"robot_{i}" for i in range(env.venv.num_agents)]}

    def observation_spec(self, env: EnvBase) -> Composite:
        spec = env.full_observation_spec_unbatched.clone()
        if "state" in spec.keys():
            del spec["state"]
        return spec

    def info_spec(self, env: EnvBase) -> Composite | None:
        return None

    def state_spec(self, env: EnvBase) -> Composite | None:
        spec = env.full_observation_spec_unbatched
        if "state" not in spec.keys():
            return None
        return Composite(state=spec["state"].clone())

    def action_spec(self, env: EnvBase) -> Composite:
        return env.full_action_spec_unbatched

    def action_mask_spec(self, env: EnvBase) -> Composite | None:
        return None

    @staticmethod
    def env_name() -> str:
        return "colcos"


class _ColcosTaskBase(Task):
    @staticmethod
    def associated_class() -> type[TaskClass]:
        return ColcosClass

    def get_from_yaml(self, path: str | None = None) -> TaskClass:
        """The task with its config from `path` (default: colcos's own `conf/<task>.yaml`), keys checked."""
        import yaml

        file = Path(path) if path is not None else _CONF / f"{self.name.lower()}.yaml"
        config = yaml.safe_load(file.read_text()) or {}
        config.pop("defaults", None)
        _checked(self.name.lower(), config)
        return self.get_task(config=config)


# One member per built-in task, as the native core lists them (new tasks join without an edit here).
ColcosTask = _ColcosTaskBase("ColcosTask", [name.upper() for name, _ in _core.tasks()])


def task(name: str) -> TaskClass:
    """The BenchMARL task `name` (`"aggregation"` or `"colcos/aggregation"`) with its default config;
    an unknown name is refused, listing the known ones."""
    short = name.removeprefix("colcos/")
    members = {m.name.lower(): m for m in ColcosTask}
    if short not in members:
        raise TaskError(f"unknown BenchMARL task {name!r}; known: {['colcos/' + k for k in sorted(members)]}")
    return members[short].get_from_yaml()


__all__ = ["ColcosClass", "ColcosTask", "TaskConfig", "task"]
