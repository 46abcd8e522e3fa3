"""Tasks written in Python: subclass `colcos.Task` and pass an instance where a task name goes
(`colcos.vector.VecEnv(MyTask(), num_envs=1024)`, `colcos.parallel_env(task=MyTask())`).

Each hook runs **once per batched step over every world**, on numpy arrays (`E` worlds, `N` agents,
`R` robots): no Python loop over worlds. After the worlds have moved, the task sees a `View`:

- `reset(ctx)`: worlds `ctx.worlds` start an episode (per-episode state, per-world parameters drawn
  from `ctx.rng`, e.g. food positions; `ctx.place(poses)` starts their robots elsewhere);
- `observe(view) -> (E, N, k)`: extra observation entries appended to the 17 sensor values, within
  the bounds the task declares (`obs_low`, `obs_high`, `k` each);
- `reward(view) -> (E, N)`; `terminated(view) -> (E, N)` bool (an agent that terminated stays
  terminated for the rest of its episode); `info(view) -> dict` (optional, returned in `infos["task"]`).

A hook that raises is re-raised as `colcos.TaskHookError` naming the task and the hook; a result of
the wrong shape, dtype or with non-finite values is refused naming the hook and the shape expected.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from colcos import _core
from colcos._core import ActionError, ColcosError, TaskError
from colcos._options import readonly_views

OBS_DIM = 17


class TaskHookError(TaskError):
    """A hook of a `colcos.Task` raised or returned something unusable (the task and hook named)."""


class View:
    """Every world's state after a step, over the whole batch.

    Arrays: `poses`, `tracked` (E, R, 3) x m, y m, heading rad (true; as the tracker last delivered),
    `seen` (E, R), `wheels` (E, R, 2) the drives' wheel speeds m/s, `commands` (E, R, 2) the last
    wheel commands m/s, `obs` (E, N, 17) the agents' sensor values (`intensities` (E, N, 4, 3) in
    [0, 1], sensors right, front, left, back; `bumpers` (E, N, 3)), `deposit_actions` (E, N, D) the
    rate fractions the agents chose, `steps` (E,) steps of the episode so far, `episode` (E,),
    `time` (E,) s; `headings` (E, R, 2) each robot's (cos, sin) of its true heading. Fixed:
    `agent_robots` (N,), `roles` [R], `arena` (w, h) m, `pheromones` [F] names, `colours` (F, 3)
    their screen levels per unit (r, g, b), `max_wheel_speed`, `wheel_base`, `dt`.
    `fields(points)` samples every pheromone; `gradients(points)` also gives their gradients.
    """

    def __init__(self, core: _core.VecEnv | _core.Plant, info: dict[str, Any], agent_robots: np.ndarray) -> None:
        d = _core.task_view(core)
        self._core = core
        self.poses: np.ndarray = d["poses"]
        self.tracked: np.ndarray = d["tracked"]
        self.seen: np.ndarray = d["seen"]
        self.wheels: np.ndarray = d["wheels"]
        self.commands: np.ndarray = d["commands"]
        self.deposit_actions: np.ndarray = d["deposit_actions"]
        self.steps: np.ndarray = d["steps"]
        self.stepped: np.ndarray = d["stepped"]
        self.episode: np.ndarray = d["episode"]
        self.time: np.ndarray = d["time"]
        self.obs: np.ndarray = d["obs"]
        self.agent_robots = agent_robots
        a = agent_robots
        consecutive = a.size > 0 and a[-1] - a[0] == a.size - 1 and bool((np.diff(a) == 1).all())
        self._rows: slice | np.ndarray = slice(int(a[0]), int(a[-1]) + 1) if consecutive else a
        self._headings: np.ndarray | None = None
        self.roles: list[str] = info["roles"]
        self.arena: tuple[float, float] = (float(info["arena"][0]), float(info["arena"][1]))
        self.pheromones: list[str] = info["pheromones"]
        self.colours: np.ndarray = np.asarray(info["colours"], np.float32).reshape(-1, 3)
        self.max_wheel_speed = np.float32(info["max_wheel_speed"])
        self.wheel_base = np.float32(info["wheel_base"])
        self.dt = np.float32(info["dt"])

    @property
    def intensities(self) -> np.ndarray:
        return self.obs[..., :12].reshape(*self.obs.shape[:2], 4, 3)

    @property
    def bumpers(self) -> np.ndarray:
        return self.obs[..., 12:15]

    @property
    def headings(self) -> np.ndarray:
        """Each robot's heading as a unit vector (cos, sin), (E, R, 2) float32, with the simulator's
        own sine and cosine (numpy's float32 ones differ from it in the last bit)."""
        if self._headings is None:
            self._headings = _core.unit_vectors(np.ascontiguousarray(self.poses[..., 2]))
        return self._headings

    def agents(self, per_robot: np.ndarray) -> np.ndarray:
        """The agents' rows of a per-robot array `(E, R, ...)`: `(E, N, ...)` (a view, no copy, where
        the agents are consecutive robots, as in every built-in scenario)."""
        return per_robot[:, self._rows]

    def fields(self, points: np.ndarray) -> np.ndarray:
        """Every pheromone's value at `points` (E, P, 2) m of each world: (E, P, F) float32."""
        return _core.sample_fields(self._core, np.ascontiguousarray(points, dtype=np.float32))

    def gradients(self, points: np.ndarray, step: float = 0.005) -> tuple[np.ndarray, np.ndarray]:
        """Every pheromone's value at `points` (E, P, 2) m of each world as the sensors read it this
        step, and its gradient per m: (E, P, F) and (E, P, F, 2) float32. Gaussian sources give their
        gradient analytically, grids by central differences `step` m apart (as the built-in tasks)."""
        return _core.sample_gradients(self._core, np.ascontiguousarray(points, dtype=np.float32), float(step))


class ResetContext:
    """Worlds starting an episode: `worlds` (indices), `view` (their state with the rest), `rng`;
    `place(poses)` starts their robots elsewhere."""

    def __init__(self, worlds: np.ndarray, view: View, rng: np.random.Generator, runner: TaskRunner) -> None:
        self.worlds = worlds
        self.view = view
        self.rng = rng
        self._runner = runner
        self.placed = False

    def place(self, poses: np.ndarray, robots: Sequence[int] | np.ndarray | None = None) -> None:
        """Starts robots `robots` (indices, default every robot) of the worlds `worlds` at `poses`
        `(len(worlds), K, 3)`: x m, y m, heading rad. Each pose must be finite and hold the robot
        inside the arena, clear of obstacles and of the other robots; else nothing of that world
        moves and `TaskHookError` names the hook, world and robot. The observations after the
        reset, and `view.poses` from then on, are taken where the robots now stand. Only in a
        simulated batch: a plant's robots are where they are."""
        self._runner.place(self.worlds, poses, robots)
        self.placed = True


class Task:
    """Base class of a task written in Python. Override `reward` (required) and any of `reset`,
    `observe`, `terminated`, `info`; set `name`, `agent_role` (the role of the robot groups whose
    robots are agents), `scenario` (a path or TOML text; None: the `trail` task's), and `obs_low` /
    `obs_high` (one bound each per extra observation entry)."""

    name: str = "python_task"
    agent_role: str = "agent"
    scenario: str | os.PathLike[str] | None = None
    obs_low: Sequence[float] = ()
    obs_high: Sequence[float] = ()
    #: Start static pheromone maps at their steady state, as the built-in tasks do.
    prefill_static_maps: bool = True
    #: Seed of `ResetContext.rng`.
    seed: int = 0

    def reset(self, ctx: ResetContext) -> None:
        """Worlds `ctx.worlds` start an episode."""

    def observe(self, view: View) -> np.ndarray | None:
        """Extra observation entries (E, N, k), or None when `k` is 0."""
        return None

    def reward(self, view: View) -> np.ndarray:
        """Each agent's reward for the step just taken, (E, N)."""
        raise NotImplementedError(f"{type(self).__name__} must define reward(view)")

    def terminated(self, view: View) -> np.ndarray | None:
        """Which agents reached a terminal state, (E, N) bool; None: none."""
        return None

    def info(self, view: View) -> dict[str, Any] | None:
        """Anything to report (returned in `infos["task"]`)."""
        return None


class TaskRunner:
    """Runs a `Task`'s hooks around a native `VecEnv` of the `python` task: the step in two halves
    with the hooks between, the observations with the task's extra entries."""

    def __init__(self, task: Task, core: _core.VecEnv | _core.Plant, spec: dict[str, Any], same_step: bool) -> None:
        self.task = task
        self.core = core
        self.same_step = same_step
        low = np.asarray(task.obs_low, dtype=np.float32).reshape(-1)
        high = np.asarray(task.obs_high, dtype=np.float32).reshape(-1)
        if low.shape != high.shape or not (np.isfinite(low).all() and np.isfinite(high).all()) or (low > high).any():
            raise TaskError(
                f"task {task.name!r}: obs_low and obs_high must be finite bounds of equal length with low <= high, "
                f"got {list(task.obs_low)} and {list(task.obs_high)}"
            )
        self.k = int(low.size)
        self.obs_low, self.obs_high = low, high
        self.info = _core.task_info(core)
        self.agent_robots = np.asarray(spec["agent_robots"], dtype=np.int64)
        e, n = int(spec["num_envs"]), int(spec["num_agents"])
        self.shape = (e, n)
        self.native = readonly_views(core.views())
        self.obs = np.zeros((e, n, OBS_DIM + self.k), np.float32)
        # Same-step autoreset's final observations (the batched env only).
        self.final_obs = np.zeros_like(self.obs)
        self.rng = np.random.default_rng(task.seed)
        self.last_info: dict[str, Any] | None = None

    def view(self) -> View:
        return View(self.core, self.info, self.agent_robots)

    def _call(self, hook: str, *args: Any) -> Any:
        try:
            return getattr(self.task, hook)(*args)
        except TaskHookError:
            raise
        except Exception as e:  # re-raised with the task and hook named
            raise TaskHookError(f"task {self.task.name!r}: hook {hook}() raised {type(e).__name__}: {e}") from e

    def _array(self, hook: str, value: Any, shape: tuple[int, ...], kind: str) -> np.ndarray:
        want = f"an array of shape {shape} ({'bool' if kind == 'b' else 'float'})"
        try:
            a = np.asarray(value)
        except (TypeError, ValueError) as e:
            raise TaskHookError(f"task {self.task.name!r}: {hook}() must return {want}: {e}") from None
        if a.shape != shape:
            raise TaskHookError(f"task {self.task.name!r}: {hook}() returned shape {a.shape}, expected {want}")
        if kind == "b":
            if a.dtype != np.bool_:
                raise TaskHookError(f"task {self.task.name!r}: {hook}() returned dtype {a.dtype}, expected {want}")
            return a
        if a.dtype.kind not in "iuf":
            raise TaskHookError(f"task {self.task.name!r}: {hook}() returned dtype {a.dtype}, expected {want}")
        a = a.astype(np.float32, copy=False)
        if not np.isfinite(a).all():
            raise TaskHookError(f"task {self.task.name!r}: {hook}() returned non-finite values")
        return a

    def _extra(self, view: View) -> np.ndarray | None:
        if self.k == 0:
            return None
        a = self._array("observe", self._call("observe", view), (*self.shape, self.k), "f")
        return np.clip(a, self.obs_low, self.obs_high)

    def _write_obs(self, out: np.ndarray, native: np.ndarray, extra: np.ndarray | None) -> None:
        out[..., :OBS_DIM] = native
        if extra is not None:
            out[..., OBS_DIM:] = extra

    def place(self, worlds: np.ndarray, poses: Any, robots: Any) -> None:
        """`ResetContext.place`: checked here for shape, in Rust for where the robots land."""
        r = len(self.info["roles"])
        where = f"task {self.task.name!r}: hook reset(): ctx.place"
        ids = np.arange(r, dtype=np.int64) if robots is None else np.asarray(robots).reshape(-1)
        if ids.dtype.kind not in "iu" or ((ids < 0) | (ids >= r)).any():
            raise TaskHookError(f"{where}: robots must be robot indices below {r}, got {list(ids)}")
        want = (len(worlds), len(ids), 3)
        try:
            a = np.asarray(poses, dtype=np.float32)
        except (TypeError, ValueError) as e:
            raise TaskHookError(f"{where}: poses must be an array of shape {want} (x m, y m, heading rad): {e}") from None
        if a.shape != want:
            raise TaskHookError(f"{where}: poses has shape {a.shape}, expected {want} (worlds, robots, x y heading)")
        try:
            _core.place_robots(
                self.core, np.ascontiguousarray(worlds, np.int64), ids.astype(np.int64), np.ascontiguousarray(a)
            )
        except ColcosError as e:
            raise TaskHookError(f"{where}: {e}") from None

    def _reset(self, worlds: np.ndarray, view: View) -> View:
        """The task's reset of `worlds`; the view afresh where it placed robots."""
        ctx = ResetContext(worlds, view, self.rng, self)
        self._call("reset", ctx)
        return self.view() if ctx.placed else view

    def after_reset(self, worlds: np.ndarray) -> None:
        """Worlds `worlds` were reset (by `reset`): the task's reset, then the observations."""
        view = self.view()
        if worlds.size:
            view = self._reset(worlds, view)
        self._write_obs(self.obs, self.native["obs"], self._extra(view))

    def step(self, actions: np.ndarray) -> None:
        _core.step_deferred(self.core, actions)
        view = self.view()
        # Worlds that only reset in this step (their episode ended at the last): a new episode.
        started = np.flatnonzero(~view.stepped)
        if started.size:
            view = self._reset(started, view)
        rewards = self._array("reward", self._call("reward", view), self.shape, "f")
        term = self._call("terminated", view)
        terminated = np.zeros(self.shape, np.bool_) if term is None else self._array("terminated", term, self.shape, "b")
        extra = self._extra(view)
        self.last_info = self._call("info", view)
        try:
            _core.conclude(self.core, np.ascontiguousarray(rewards), np.ascontiguousarray(terminated))
        except ActionError as e:
            raise TaskHookError(f"task {self.task.name!r}: {e}") from None
        final = self.native["final_mask"] if self.same_step else None
        if final is not None and final.any():
            # Finished worlds were reset within the step: their last observation is the final one.
            self._write_obs(self.final_obs, self.native["final_obs"], extra)
            again = self._reset(np.flatnonzero(final), self.view())
            extra = self._extra(again)
        self._write_obs(self.obs, self.native["obs"], extra)


def core_task(task: Task, scenario: Any, params: dict[str, Any]) -> tuple[str, Any, dict[str, Any]]:
    """The native task name, scenario and parameters for a Python task."""
    if not isinstance(task, Task):
        raise TaskError(f"task must be a task name or a colcos.Task, got {type(task).__name__}")
    if params:
        raise TaskError(f"task parameters {sorted(params)} are for built-in tasks; set them on your {type(task).__name__}")
    if not isinstance(task.agent_role, str):
        raise TaskError(f"task {task.name!r}: agent_role must be a str, got {task.agent_role!r}")
    native = {"agent_role": task.agent_role, "prefill": bool(task.prefill_static_maps)}
    return "python", scenario if scenario is not None else task.scenario, native
