"""A task written in Python places robots in `reset(ctx)` (`ctx.place`): the robots start where it
put them (poses, tracked poses and sensor values after the reset, and again after an autoreset), and
a pose that is not finite, leaves the arena or overlaps an obstacle or another robot is refused,
naming the hook, the world and the robot."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

import colcos

MAZE = pathlib.Path(__file__).resolve().parents[1] / "env" / "scenarios" / "trail_maze.toml"
# Agent 0 on the blue trail's lowest stretch, heading along it; the others inside the loop, off it.
SPOTS = np.array([[0.72, 0.12, 0.0], [0.5, 0.4, 1.0], [0.72, 0.4, 2.0], [0.95, 0.4, -1.0]], np.float32)


class Placer(colcos.Task):
    """Starts the agents of world w at `SPOTS`, shifted right by 1 cm per world; one extra
    observation entry: the agent's x (from `view.poses`)."""

    name = "placer"
    obs_low, obs_high = (0.0,), (2.0,)

    def __init__(self, poses: np.ndarray | None = None) -> None:
        self.poses = poses

    def spots(self, worlds: np.ndarray) -> np.ndarray:
        if self.poses is not None:
            return np.broadcast_to(self.poses, (len(worlds), *self.poses.shape))
        p = np.repeat(SPOTS[None], len(worlds), axis=0)
        p[..., 0] += np.float32(0.01) * worlds[:, None]
        return p

    def reset(self, ctx: colcos.ResetContext) -> None:
        ctx.place(self.spots(ctx.worlds), robots=ctx.view.agent_robots)

    def observe(self, view: colcos.View) -> np.ndarray:
        return view.agents(view.poses)[..., :1]

    def reward(self, view: colcos.View) -> np.ndarray:
        return np.zeros(view.obs.shape[:2], np.float32)


class Recorder(colcos.Task):
    """Keeps the agents' poses and tracked poses of every reset."""

    name = "recorder"

    def __init__(self, scenario: str | None = None) -> None:
        self.scenario = scenario
        self.seen: list[tuple[np.ndarray, np.ndarray]] = []

    def reset(self, ctx: colcos.ResetContext) -> None:
        v = ctx.view
        self.seen.append((v.agents(v.poses)[ctx.worlds].copy(), v.agents(v.tracked)[ctx.worlds].copy()))

    def reward(self, view: colcos.View) -> np.ndarray:
        return np.zeros(view.obs.shape[:2], np.float32)


class PlaceThenRecord(Placer):
    """Places as `Placer`, then keeps the poses the next view shows (its `observe` runs on it)."""

    def __init__(self) -> None:
        super().__init__()
        self.views: list[colcos.View] = []

    def observe(self, view: colcos.View) -> np.ndarray:
        self.views.append(view)
        return super().observe(view)


def test_placed_robots_are_observed_where_they_were_put():
    task = PlaceThenRecord()
    env = colcos.vector.VecEnv(task, num_envs=3, max_cycles=4)
    obs, _ = env.reset(seed=2)
    want = task.spots(np.arange(3))
    np.testing.assert_array_equal(obs[..., 17], want[..., 0])
    view = task.views[-1]
    np.testing.assert_array_equal(view.agents(view.poses), want)
    np.testing.assert_array_equal(view.agents(view.tracked), want)
    # The sensors read the screen where the robots stand: agent 0 sees the blue trail, the others,
    # inside the loop, hardly any.
    blue = obs[..., 2:12:3]  # (E, N, 4) every sensor's blue
    assert (blue[:, 0].max(axis=-1) > 0.2).all(), blue[:, 0]
    assert (blue[:, 1:].max(axis=-1) < 0.05).all(), blue[:, 1:]
    # Robots move away, and start over at their places after the autoreset (next-step mode).
    ahead = np.full((3, env.num_agents, 2), 0.8, np.float32)
    for _ in range(4):
        obs, *_ = env.step(ahead)
    assert not np.array_equal(obs[..., 17], want[..., 0])
    obs, *_ = env.step(ahead)
    np.testing.assert_array_equal(obs[..., 17], want[..., 0])
    np.testing.assert_array_equal(task.views[-1].agents(task.views[-1].poses), want)


def test_placing_gives_the_start_of_a_scenario_that_starts_there():
    # The maze's explicit start poses, read off a run of it, given by ctx.place to the same maze
    # with random placement: the sensors read what they read at the maze's own start.
    explicit = MAZE.read_text()
    random = explicit.replace('placement = "explicit"', 'placement = "random"')
    random = "\n".join(line for line in random.splitlines() if not line.startswith("poses = "))
    assert random != explicit and "poses = " not in random
    recorder = Recorder(explicit)
    rust = colcos.vector.VecEnv(recorder, num_envs=2)
    start, _ = rust.reset(seed=0)
    poses = recorder.seen[0][0]
    placer = Placer(poses[0])
    placer.scenario = random
    placed = colcos.vector.VecEnv(placer, num_envs=2)
    obs, _ = placed.reset(seed=0)
    np.testing.assert_array_equal(obs[..., 17], poses[..., 0])
    # The blue trail map, read with each world's own sensor noise, and the bumpers and commands
    # exactly; red is left out: the maze's first red deposits lie where its robots started.
    np.testing.assert_allclose(obs[..., 2:12:3], start[..., 2:12:3], atol=0.005)
    assert (start[..., 2:12:3] > 0.3).any(), "no sensor saw the trail: the comparison says nothing"
    np.testing.assert_array_equal(obs[..., 12:17], start[..., 12:17])


def _placing(poses: np.ndarray, scenario: str | None = None) -> None:
    env = colcos.vector.VecEnv(Placer(poses), num_envs=2, scenario=scenario)
    env.reset(seed=0)


@pytest.mark.parametrize(
    ("poses", "scenario", "needle"),
    [
        ([[np.nan, 0.4, 0], [0.5, 0.4, 0], [0.7, 0.4, 0], [0.9, 0.4, 0]], None, r"world 0: robot 0 at \[NaN.*finite"),
        ([[0.3, 0.4, 0], [5.0, 0.4, 0], [0.7, 0.4, 0], [0.9, 0.4, 0]], None, r"world 0: robot 1 at \[5.*outside the arena"),
        ([[0.3, 0.4, 0], [0.5, 0.4, 0], [0.5, 0.41, 0], [0.9, 0.4, 0]], None, r"world 0: robot 1 .* overlaps robot 2"),
        ([[0.72, 0.12, 0], [0.72, 0.4, 0], [0.3, 0.7, 0], [1.2, 0.1, 0]], str(MAZE), r"world 0: robot 1 .* overlaps obstacle 0"),
        ([[0.3, 0.4, 0], [0.5, 0.4, 0]], None, r"poses has shape \(2, 2, 3\), expected \(2, 4, 3\)"),
    ],
)
def test_a_bad_placement_is_refused_naming_the_hook_world_and_robot(poses, scenario, needle):
    with pytest.raises(colcos.TaskHookError, match=r"task 'placer': hook reset\(\): ctx.place: .*" + needle):
        _placing(np.asarray(poses, np.float32), scenario)


def test_a_plant_refuses_to_place_robots():
    env = colcos.parallel_env(task=Placer(), plant="twin", goto=False, max_cycles=5)
    try:
        with pytest.raises(colcos.TaskHookError, match=r"hook reset\(\): ctx.place: .*plant"):
            env.reset(seed=0)
    finally:
        env.close()
