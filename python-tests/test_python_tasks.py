"""Tasks written in Python (`colcos.Task`): the built-in tasks re-written under examples/tasks/ give
exactly the Rust tasks' rewards, terminations and observations over 1,000 steps of a batch; hooks see
the whole batch at once; a hook that raises or returns the wrong shape is named."""

from __future__ import annotations

import numpy as np
import pytest
from example_modules import load_task as _load

import colcos

# Parameters given alike to the Rust task and its Python re-write: the colony's food lies near the
# nest so that pickups and deliveries happen within the run; captures cost something.
PARAMS = {
    "colony": dict(food=[[0.45, 0.45], [0.3, 0.62]], food_amount=3, pickup_reward=0.25, step_penalty=0.01),
    "coverage": dict(cell=0.1, bump_penalty=0.05),
    "alarm": dict(capture_penalty=0.5),
}


def _events(name: str, obs: np.ndarray, rewards: np.ndarray) -> int:
    """How often what the task is about happened in one step of the Rust task (0 if never)."""
    if name == "colony":
        return int(obs[..., -1].sum()) + int((rewards > 0.5).sum())  # carrying; a delivery paid
    if name == "alarm":
        return int(obs[..., -1].sum()) + int((rewards < 0).sum())  # predator sensed; captured
    if name == "coverage":
        return int((rewards >= 1.0).sum())  # a new cell
    if name == "aggregation":
        return int((rewards < -1.0).sum())  # captured, or far from the leader in the alarm
    return 1


@pytest.mark.parametrize(
    ("name", "cls"),
    [("trail", "Trail"), ("foraging", "Foraging"), ("aggregation", "Aggregation"), ("colony", "Colony"),
     ("coverage", "Coverage"), ("alarm", "Alarm")],
)
def test_python_rewrites_of_the_builtin_tasks_match_them_exactly(name, cls):
    params = PARAMS.get(name, {})
    task = getattr(_load(name), cls)(**params)
    kw = dict(num_envs=6, seed=4, max_cycles=300, num_threads=2)
    rust = colcos.vector.VecEnv(name, **kw, **params)
    py = colcos.vector.VecEnv(task, **kw)
    assert py.single_observation_space == rust.single_observation_space
    assert py.single_action_space == rust.single_action_space
    o1, _ = rust.reset(seed=4)
    o2, _ = py.reset(seed=4)
    np.testing.assert_array_equal(o1, o2)
    rng = np.random.default_rng(0)
    width = rust.single_action_space.shape[0]
    ended = events = 0
    for t in range(1000):
        a = np.empty((6, rust.num_agents, width), np.float32)
        a[..., :2] = rng.uniform(-0.3, 1.0, (6, rust.num_agents, 2))
        a[..., 2:] = rng.uniform(0.0, 1.0, (6, rust.num_agents, width - 2))  # pheromone actions
        r1 = rust.step(a)
        r2 = py.step(a)
        for what, x, y in zip(("obs", "rewards", "terminated", "truncated"), r1[:4], r2[:4], strict=True):
            assert np.array_equal(x, y), f"{name}: {what} differ at step {t}"
        ended += int(r1[2].sum() + r1[3].sum())
        events += _events(name, r1[0], r1[1])
    assert ended > 0, "no episode ended: the test would not see terminations or truncations"
    assert events > 0, f"{name}: what the task rewards never happened: the test would not see it"


class Probe(colcos.Task):
    """Counts what it is asked, adds two observation entries, ends world 0's episodes at step 5."""

    name = "probe"
    obs_low = (0.0, -1.0)
    obs_high = (1.0, 1.0)

    def __init__(self) -> None:
        self.resets: list[list[int]] = []
        self.calls = 0

    def reset(self, ctx: colcos.ResetContext) -> None:
        self.resets.append(sorted(int(w) for w in ctx.worlds))

    def observe(self, view: colcos.View) -> np.ndarray:
        e, n = view.obs.shape[:2]
        x = view.agents(view.poses)[..., 0] / np.float32(view.arena[0])
        return np.stack([x, np.full((e, n), 2.0, np.float32)], axis=-1)  # 2.0 is clipped to 1

    def reward(self, view: colcos.View) -> np.ndarray:
        self.calls += 1
        # The fields sampled in Rust at every agent's position: (E, N, F), finite.
        levels = view.fields(view.agents(view.poses)[..., :2])
        assert levels.shape == (*view.obs.shape[:2], len(view.pheromones)) and np.isfinite(levels).all()
        return np.ones(view.obs.shape[:2], np.float32) * view.steps[:, None]

    def terminated(self, view: colcos.View) -> np.ndarray:
        t = np.zeros(view.obs.shape[:2], bool)
        t[0] = view.steps[0] >= 5
        return t


def test_hooks_run_once_per_step_over_the_whole_batch():
    task = Probe()
    env = colcos.vector.VecEnv(task, num_envs=3, seed=1, max_cycles=100)
    assert env.single_observation_space.shape == (19,)
    obs, _ = env.reset(seed=1)
    assert task.resets == [[0, 1, 2]]
    assert obs.shape == (3, env.num_agents, 19) and (obs[..., 18] == 1.0).all()
    for _ in range(5):
        obs, rew, term, trunc, _ = env.step(np.zeros((3, env.num_agents, 2), np.float32))
    assert task.calls == 5
    assert term[0].all() and not term[1:].any()
    assert rew[1, 0] == 5.0
    env.step(np.zeros((3, env.num_agents, 2), np.float32))  # world 0 starts over (next-step autoreset)
    assert task.resets[-1] == [0]
    assert env.episode(0) == 1 and env.episode(1) == 0


class Broken(colcos.Task):
    name = "broken"

    def __init__(self, mode: str) -> None:
        self.mode = mode

    def reward(self, view: colcos.View) -> np.ndarray:
        if self.mode == "raise":
            raise KeyError("food")
        if self.mode == "shape":
            return np.zeros(3, np.float32)
        return np.full(view.obs.shape[:2], np.nan, np.float32)


@pytest.mark.parametrize(
    ("mode", "needle"),
    [("raise", r"'broken': hook reward\(\) raised KeyError"), ("shape", r"reward\(\) returned shape \(3,\), expected"),
     ("nan", "non-finite")],
)
def test_a_broken_hook_is_named(mode, needle):
    env = colcos.vector.VecEnv(Broken(mode), num_envs=2)
    env.reset()
    with pytest.raises(colcos.TaskHookError, match=needle):
        env.step(np.zeros((2, env.num_agents, 2), np.float32))


def test_a_python_task_refuses_builtin_parameters():
    with pytest.raises(colcos.TaskError, match="channel"):
        colcos.vector.VecEnv(Probe(), channel="b")


def test_a_python_task_runs_on_the_twin_and_replays_as_the_rust_task(tmp_path):
    log = tmp_path / "rig.mcap"
    ahead = np.array([0.5, 0.5], np.float32)
    env = colcos.parallel_env(task=_load("trail").Trail(), plant="twin", goto=False, max_cycles=40, log=str(log))
    obs, _ = env.reset(seed=1)
    assert obs["robot_0"].shape == (17,)
    total = 0.0
    while env.agents:
        obs, rewards, _, _, _ = env.step({a: ahead for a in env.agents})
        total += sum(rewards.values())
    env.close()
    assert np.isfinite(total) and total != 0.0

    # The recorded run replayed with the Rust task and with its Python re-write: the same rewards.
    def replay(task) -> list[list[float]]:
        e = colcos.parallel_env(task=task, plant="replay", log=str(log), max_cycles=40)
        e.reset(seed=1)
        out = []
        while e.agents:
            _, r, _, _, _ = e.step({a: ahead for a in e.agents})
            out.append([r[a] for a in sorted(r)])
        return out

    rust = replay("trail")
    assert len(rust) == 40
    assert replay(_load("trail").Trail()) == rust
