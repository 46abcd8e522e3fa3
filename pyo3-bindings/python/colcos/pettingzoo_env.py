"""The PettingZoo faces: `parallel_env` (native), `raw_env` / `env` (AEC, derived)."""

from __future__ import annotations

import os
import warnings
from typing import Any

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv
from pettingzoo.utils import wrappers
from pettingzoo.utils.conversions import parallel_to_aec_wrapper

from colcos import _actions, _checks, _core
from colcos._core import ActionError, StateError, TaskError, UnknownAgentError
from colcos._options import (
    BackendInfo,
    HumanWindow,
    core_kwargs,
    log_backend,
    make_space,
    readonly_views,
    share_signature,
    twin_kwargs,
)
from colcos.task import Task, TaskRunner, core_task

RENDER_WIDTH = 640
_F32 = np.dtype(np.float32)
PLANTS = ("sim", "twin", "rig", "replay")


class ColcosParallelEnv(BackendInfo, ParallelEnv):
    """A colcos task as a PettingZoo `ParallelEnv`: one world, agents `robot_0..`.

    Built on the batched core with one world, so a run here and world 0 of `colcos.vector.VecEnv`
    with the same seed follow the same trajectory. Observations are copies (safe to keep).

    Args:
        task: `"aggregation"`, `"foraging"` or `"trail"` (see `colcos.tasks()`), or a `colcos.Task`
            written in Python (on every plant; on the twin and the rig its view is of tracked poses;
            see `colcos.task`).
        scenario: a scenario file (path) or scenario TOML text; default: the task's own.
        max_cycles: steps per episode before truncation (default 500; None: the scenario's
            duration / dt).
        render_mode: None, `"human"` (a window showing the screen with the robots, at the field's
            rate, updated by every `reset` and `step`; `close()` closes it) or `"rgb_array"` (that
            image as an array).
        continuous: two wheel speeds in [-1, 1] (True) or `Discrete(6)` (False); a bool.
        global_state: offer `state()` (all robot poses) for centralised critics.
        patch: if set, each observation is a dict with `"vector"` and an egocentric `"patch"` of the
            screen, `patch x patch x 3` uint8, covering `patch_side` m under and ahead of the robot.
        backend: field backend of the grid pheromones: `"cpu"`, `"gpu"` (an error,
            `colcos.BackendError`, where there is no GPU adapter) or `"auto"` (a hardware GPU if there
            is one, else the CPU); None: the scenario's `[field] backend` (default `cpu`). What was
            taken is in `backend_name` (`"cpu"` / `"gpu"`) and `backend_info`, and logged (logger
            `colcos`, INFO).
        physics: the robots' contact solver: `"rapier"` (rigid bodies, the default of the tasks'
            scenarios) or `"discs"` (a position-based disc solver, faster in large batches; see
            docs/python.md); None: the scenario's `physics`.
        seed: the base seed, an integer in 0..=2**64-1 (as for `reset(seed=...)`).
        plant: where the arena is: `"sim"` (the simulator), `"twin"` (the digital twin over the rig's
            wire formats: started in this process on loopback, or at `tracker`/`robots`), `"rig"`
            (the lab's tracker and robots at `tracker` and `robots`) or `"replay"` (the rig log `log`
            fed tick by tick with this policy's commands). Same spaces, dtypes and info keys in each;
            `step` is paced to the screen's 20 ms on the twin and the rig. See docs/bridge.md.
        tracker, robots: the URLs of the tracker (`swarmcon://HOST:PORT`) and the robots' link
            (`serial:///dev/ttyUSB0?baud=115200`, `udp://HOST:PORT`), for `"twin"` and `"rig"`.
        log: `"replay"`: the rig log (`rig.mcap`) to replay; `"twin"`/`"rig"`: where to write one.
        goto: on the twin and the rig, `reset` first drives the robots to the episode's start poses
            (tracker-guided, collision-aware), for at most `goto_timeout` s; False leaves them where
            they are.
        twin_scenario: `"twin"` started here: what the twin plays where it differs from this
            scenario (its true tracker latency, sensor gain and crosstalk, robot body): a scenario
            file, scenario TOML text, or a dict of key paths over this scenario
            (`{"tracker.latency": 0.15, "sensor.gain": 0.8}`). Its robots, arena, screen and tick
            must be this scenario's. The robots' own sensors are read only with `[rig] sensors =
            "robot"` in this scenario. See docs/bridge.md ("Sim-to-real").
        truth: `"twin"` started here: its robots' hidden per-robot values (a file of `[[robot]]`
            entries: wheel scales, motor lag, command latency, sensor gain and offset, as
            `colcos twin --truth` and `colcos.rig.identify`'s `out`) while this scenario assumes its
            own; `colcos.rig.identify` on the `log` recovers them (docs/identify.md).
        **params: task parameters (see the task's docs); unknown ones raise `colcos.TaskError`.

    Actions (`step`): a dict with an action for every agent in `agents`; see docs/python.md
    ("Actions"). Continuous values outside [-1, 1] are clipped to it; anything else wrong raises a
    `colcos.ActionError` naming the agent.
    """

    metadata = {
        "render_modes": ["human", "rgb_array"],
        "name": "colcos_v0",
        "is_parallelizable": True,
        "render_fps": 50,
    }

    def __init__(
        self,
        task: str | Task = "aggregation",
        scenario: str | os.PathLike[str] | None = None,
        max_cycles: int | None = 500,
        render_mode: str | None = None,
        continuous: bool = True,
        global_state: bool = True,
        patch: int | None = None,
        patch_side: float = 0.08,
        seed: int = 0,
        backend: str | None = None,
        physics: str | None = None,
        plant: str = "sim",
        tracker: str | None = None,
        robots: str | None = None,
        log: str | os.PathLike[str] | None = None,
        goto: bool = True,
        goto_timeout: float = 30.0,
        twin_scenario: str | os.PathLike[str] | dict[str, Any] | None = None,
        truth: str | os.PathLike[str] | None = None,
        **params: Any,
    ) -> None:
        self._init_kwargs = dict(
            task=task, scenario=scenario, max_cycles=max_cycles, render_mode=render_mode, continuous=continuous,
            global_state=global_state, patch=patch, patch_side=patch_side, seed=seed, backend=backend,
            physics=physics, plant=plant, tracker=tracker, robots=robots, log=log, goto=goto, goto_timeout=goto_timeout,
            twin_scenario=twin_scenario, truth=truth, **params,
        )
        _checks.choice(render_mode, "render_mode", [None, "human", "rgb_array"])
        _checks.choice(plant, "plant", list(PLANTS))
        native, scenario, params = (task, scenario, params) if isinstance(task, str) else core_task(task, scenario, params)
        kw = core_kwargs(native, scenario, max_cycles, continuous, global_state, patch, patch_side, params, backend, physics)
        self.plant = plant
        self._core: _core.VecEnv | _core.Plant
        if plant == "sim":
            for name, value in (
                ("tracker", tracker), ("robots", robots), ("log", log), ("twin_scenario", twin_scenario), ("truth", truth)
            ):
                if value is not None:
                    raise TaskError(f"{name}={value!r} is for plant='twin', 'rig' or 'replay', not 'sim'")
            self._core = _core.VecEnv(
                num_envs=1, seed=_checks.seed(seed), num_threads=1, autoreset_mode="disabled", **kw
            )
        else:
            self._core = _core.Plant(
                plant=plant, tracker=tracker, robots=robots, log=None if log is None else os.fspath(log),
                goto=_checks.flag(goto, "goto"), goto_timeout=goto_timeout, seed=_checks.seed(seed),
                **twin_kwargs(twin_scenario, truth), **kw,
            )
        log_backend(self._core, backend)
        spec = self._core.spec()
        self._spec = spec
        self.metadata = dict(self.metadata, name=spec["env_name"])
        self.render_mode = render_mode
        self.task = task
        self.possible_agents: list[str] = list(spec["agent_names"])
        self.agents: list[str] = []
        self._index = {a: i for i, a in enumerate(self.possible_agents)}
        self._runner: TaskRunner | None = None
        if isinstance(task, Task):
            self._runner = TaskRunner(task, self._core, spec, same_step=False)
        vector = make_space(spec["observation"])
        if self._runner is not None:
            assert isinstance(vector, spaces.Box)
            vector = spaces.Box(
                low=np.concatenate([vector.low, self._runner.obs_low]),
                high=np.concatenate([vector.high, self._runner.obs_high]),
                dtype=np.float32,
            )
        if spec["patch"] is not None:
            obs_space: spaces.Space = spaces.Dict({"vector": vector, "patch": make_space(spec["patch"])})
        else:
            obs_space = vector
        # One space object per agent, so seeding one agent's space does not touch another's.
        self.observation_spaces = {a: _copy_space(obs_space) for a in self.possible_agents}
        self.action_spaces = {a: make_space(spec["action"]) for a in self.possible_agents}
        self._continuous = spec["action"]["kind"] == "box"
        self._n_actions = 0 if self._continuous else int(spec["action"]["n"])
        # Two wheels, then one rate per deposit action (`robots[].deposit_actions`).
        self._width = int(np.prod(spec["action"]["shape"])) if self._continuous else 0
        if spec["state"] is not None:
            self.state_space = make_space(spec["state"])
        self._views = readonly_views(self._core.views())
        n = len(self.possible_agents)
        self._actions = np.zeros((1, n, self._width), np.float32) if self._continuous else np.zeros((1, n), np.int64)
        self._needs_reset = True
        self._window: HumanWindow | None = None
        if render_mode == "human":
            self._window = HumanWindow(f"colcos: {spec['env_name']}", 1.0 / spec["dt"])

    def _show(self) -> None:
        if self._window is not None:
            key = (self._core.episode(0), self._core.episode_steps(0))
            self._window.show(self._core.render(0, RENDER_WIDTH), key)

    def __getstate__(self) -> dict[str, Any]:
        # Pickling (SuperSuit, multiprocessing) rebuilds the env from its arguments: a fresh copy that
        # needs a reset, as after construction.
        # An instance's own metadata (the versioned modules of `colcos.tasks` name theirs) goes too.
        return {"init_kwargs": self._init_kwargs, "metadata": self.metadata}

    def __setstate__(self, state: dict[str, Any]) -> None:
        ColcosParallelEnv.__init__(self, **state["init_kwargs"])
        self.metadata = state.get("metadata", self.metadata)

    def observation_space(self, agent: str) -> spaces.Space:
        if agent not in self.observation_spaces:
            raise UnknownAgentError(f"unknown agent {agent!r}; the agents are {self.possible_agents}")
        return self.observation_spaces[agent]

    def action_space(self, agent: str) -> spaces.Space:
        if agent not in self.action_spaces:
            raise UnknownAgentError(f"unknown agent {agent!r}; the agents are {self.possible_agents}")
        return self.action_spaces[agent]

    @property
    def num_envs(self) -> int:
        return 1

    def _all_obs(self) -> np.ndarray:
        return self._runner.obs if self._runner is not None else self._views["obs"]

    def _obs(self, i: int) -> Any:
        v = self._all_obs()[0, i].copy()
        if "patch" in self._views:
            return {"vector": v, "patch": self._views["patch"][0, i].copy()}
        return v

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        # No options of its own; PettingZoo's API test passes some, so any are accepted.
        if seed is not None:
            seed = _checks.seed(seed)
        self._core.reset(seed)
        if self._runner is not None:
            self._runner.after_reset(np.zeros(1, np.int64))
        self.agents = self.possible_agents[:]
        self._needs_reset = False
        if self._window is not None:
            self._window.shown_key = None
            self._show()
        return {a: self._obs(i) for i, a in enumerate(self.agents)}, {a: {} for a in self.agents}

    def step(self, actions: dict[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        if self._needs_reset:
            raise StateError("call reset() before step()")
        if not self.agents:
            # Every agent is done. Wrappers such as SuperSuit's black_death step once more with no
            # actions to learn that; answer with empty dicts (the world is not stepped).
            if any(k in self._index for k in actions):
                raise StateError("every agent is done: call reset() before stepping again")
            return {}, {}, {}, {}, {}
        if not isinstance(actions, dict):
            raise _core.ActionTypeError(f"actions must be a dict {{agent name: action}}, got {type(actions).__name__}")
        buf = self._actions
        buf.fill(0)
        index = self._index
        fast = self._continuous
        for name, a in actions.items():
            i = index.get(name)
            if i is None:
                raise UnknownAgentError(f"unknown agent {name!r}; the agents are {self.possible_agents}")
            if fast and type(a) is np.ndarray and a.dtype is _F32 and a.shape == (self._width,):
                buf[0, i] = a  # the common case; the core refuses non-finite values, naming the agent
            elif name in self.agents:
                buf[0, i] = self.check_action(name, a)
            # (actions for agents that are already done are ignored, whatever they are)
        # With every agent live and one action each, none is missing; otherwise look.
        if len(actions) != len(self.agents) or len(self.agents) != len(self.possible_agents):
            missing = [a for a in self.agents if a not in actions]
            if missing:
                raise ActionError(f"no action for agents {missing}: every agent in env.agents needs one")
        if self._runner is not None:
            self._runner.step(buf)
        else:
            self._core.step(buf)
        v = self._views
        # One copy and one conversion per buffer rather than per agent: each agent's observation is a
        # row of this step's own copy (never a view of the native buffer, which the next step rewrites).
        rew, term, trunc = v["rewards"][0].tolist(), v["terminated"][0].tolist(), v["truncated"][0].tolist()
        shield = v["shield"][0].tolist()
        all_obs = self._all_obs()[0].copy()
        patches = v["patch"][0].copy() if "patch" in v else None
        obs: dict[str, Any] = {}
        rewards: dict[str, float] = {}
        terminations: dict[str, bool] = {}
        truncations: dict[str, bool] = {}
        infos: dict[str, dict] = {}
        live = []
        for a in self.agents:
            i = index[a]
            obs[a] = all_obs[i] if patches is None else {"vector": all_obs[i], "patch": patches[i]}
            rewards[a] = rew[i]
            t = terminations[a] = term[i]
            u = truncations[a] = trunc[i]
            infos[a] = {"shield_capped": bool(shield[i] & 1), "shield_walled": bool(shield[i] & 2)}
            if not (t or u):
                live.append(a)
        self.agents = live
        self._show()
        return obs, rewards, terminations, truncations, infos

    def check_action(self, agent: str, action: Any) -> Any:
        """`action` of `agent` checked against its action space (continuous values are clipped to
        [-1, 1] when stepped); raises a `colcos.ActionError` naming the agent."""
        if agent not in self._index:
            raise UnknownAgentError(f"unknown agent {agent!r}; the agents are {self.possible_agents}")
        if self._continuous:
            return _actions.continuous(agent, action, self._width)
        return _actions.discrete(agent, action, self._n_actions)

    def state(self) -> np.ndarray:
        if "state" not in self._views:
            raise StateError("this environment was made with global_state=False")
        return self._views["state"][0].copy()

    def render(self, mode: str | None = None, width: int | None = None) -> np.ndarray | None:
        """The screen with the robots on it: an array `(H, W, 3)` (`rgb_array`, `width` pixels wide,
        16..=7,680, 640 by default) or the window (`human`)."""
        mode = mode or self.render_mode
        _checks.choice(mode, "render mode", [None, "human", "rgb_array"])
        if mode is None:
            warnings.warn("render() called without a render_mode; pass render_mode='rgb_array' or 'human'", stacklevel=2)
            return None
        if mode == "rgb_array":
            return self._core.render(0, RENDER_WIDTH if width is None else width)
        if self._window is None:
            self._window = HumanWindow(f"colcos: {self._spec['env_name']}", 1.0 / self._spec["dt"])
        self._show()  # the frame of this step, if reset/step has not shown it yet
        return None

    def close(self) -> None:
        """Closes the `render_mode="human"` window, if one is open; on the twin and the rig, stops
        every robot and lets go of the tracker and the link: `reset` and `step` raise from then on,
        so a closed plant never drives again."""
        if self._window is not None:
            self._window.close()
        if self.plant != "sim":
            assert isinstance(self._core, _core.Plant)
            self._core.close("the environment was closed")

    def __enter__(self) -> ColcosParallelEnv:
        return self

    def __exit__(self, kind: Any, value: Any, tb: Any) -> None:
        # A policy that raises inside `with env:` stops the robots at once, not after the watchdog's
        # policy-stall limit.
        if self.plant != "sim" and kind is not None:
            assert isinstance(self._core, _core.Plant)
            self._core.stop(f"the policy raised {kind.__name__}")
        self.close()

    def plant_info(self) -> dict[str, Any]:
        """What the plant measured: ticks, overruns, worst and 99th-percentile tick (ms), the shield's
        interventions, safety stops, the last reset's go-to (twin, rig); `{"plant": "sim"}` otherwise."""
        if self.plant == "sim":
            return {"plant": "sim"}
        assert isinstance(self._core, _core.Plant)
        return dict(self._core.plant_info())

    def poses(self) -> np.ndarray:
        """True poses (R, 3): x m, y m, heading rad, of every robot (for analysis, not for policies)."""
        return self._core.poses(0)


def _copy_space(s: spaces.Space) -> spaces.Space:
    if isinstance(s, spaces.Box):
        return spaces.Box(low=s.low, high=s.high, shape=s.shape, dtype=s.dtype)
    if isinstance(s, spaces.Discrete):
        return spaces.Discrete(int(s.n))
    if isinstance(s, spaces.Dict):
        return spaces.Dict({k: _copy_space(v) for k, v in s.spaces.items()})
    return s


def parallel_env(**kwargs: Any) -> ColcosParallelEnv:
    """A colcos task as a PettingZoo `ParallelEnv` (see `ColcosParallelEnv`)."""
    return ColcosParallelEnv(**kwargs)


def raw_env(**kwargs: Any) -> parallel_to_aec_wrapper:
    """The AEC form of `parallel_env`, without the order-enforcing wrapper. A bad action raises at
    the `step` that receives it."""
    return _actions.CheckedAecWrapper(ColcosParallelEnv(**kwargs))


def env(**kwargs: Any) -> wrappers.OrderEnforcingWrapper:
    """The AEC form of `parallel_env`, wrapped as PettingZoo's `env()` functions are."""
    return wrappers.OrderEnforcingWrapper(raw_env(**kwargs))


# help(colcos.parallel_env) shows the environment's own arguments and documentation.
for _make in (parallel_env, raw_env, env):
    share_signature(_make, ColcosParallelEnv)
