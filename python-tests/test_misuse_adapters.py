"""The adapters under misuse and at their edges: agents that finish early (foraging) through
Gymnasium's `RecordEpisodeStatistics`, and bad input to the Gymnasium vector env."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.wrappers.vector import RecordEpisodeStatistics

import colcos
from colcos.gymnasium_vector import ColcosVectorEnv
from colcos.vector import VecEnv

STEPS = 30


def _food_under_agent_0(seed: int) -> list[list[float]]:
    probe = VecEnv("foraging", num_envs=1, max_cycles=STEPS, seed=seed)
    probe.reset(seed=seed)
    x, y, _ = probe.poses(0)[probe.spec["agent_robots"][0]]
    return [[float(x), float(y)]]


def test_record_episode_statistics_sees_one_episode_per_agent_and_world():
    # Food right under agent 0 of world 0: it arrives at the first step and waits for the world,
    # which is truncated after STEPS steps; the other agents stand still.
    food = _food_under_agent_0(seed=5)
    env = ColcosVectorEnv(
        "foraging", num_envs=2, max_cycles=STEPS, seed=5, food=food, reach_distance=0.01, step_penalty=0.01
    )
    n_agents = env.venv.num_agents
    g = RecordEpisodeStatistics(env)
    g.reset(seed=5)
    zeros = np.zeros((g.num_envs, 2), np.float32)
    waiting_steps = 0
    for t in range(1, STEPS + 1):
        _, rew, term, trunc, infos = g.step(zeros)
        waiting_steps += int(infos.get("waiting", np.zeros(g.num_envs, bool))[0])
        if t < STEPS:
            assert "episode" not in infos, (t, infos)
            assert not (term | trunc).any(), t
            if t > 1:
                assert rew[0] == 0.0  # a waiting agent earns nothing
    assert waiting_steps == STEPS - 1  # from its arrival until the step before its world ends
    assert term[0] and not trunc[0]  # agent 0 of world 0 reached the food
    assert trunc[1:].all() and not term[1:].any()  # everyone else ran out of time
    ep = infos["episode"]
    assert infos["_episode"].all()
    assert ep["l"].tolist() == [STEPS] * g.num_envs
    assert ep["r"][0] == pytest.approx(1.0 - 0.01, abs=1e-6)
    others = np.delete(ep["r"], 0)
    assert others == pytest.approx(np.full(2 * n_agents - 1, -0.01 * STEPS), abs=1e-5)
    # The step after the worlds ended resets them (next-step autoreset) and counts toward no episode.
    _, rew, term, trunc, infos = g.step(zeros)
    assert not (term | trunc).any() and "episode" not in infos and (rew == 0).all()
    assert len(g.return_queue) == g.num_envs


def test_gymnasium_vector_refuses_bad_input_with_colcos_errors():
    g = ColcosVectorEnv("aggregation", num_envs=2, max_cycles=5)
    with pytest.raises(colcos.TaskError, match="seed"):
        g.reset(seed=[-1])
    g.reset(seed=[3, 4])
    assert g.venv._core.seed == 3
    for bad in (None, "go", np.zeros(6), np.zeros((6, 3)), [[0.0, 0.0]] * 5):
        with pytest.raises(colcos.ActionError):
            g.step(bad)
    with pytest.raises(colcos.ActionTypeError, match="reset_mask"):
        g.reset(options={"reset_mask": np.ones(6)})
