"""The pre-flight check on the digital twin: a policy that drives into the walls is refused with the
limit it broke named; one that keeps clear passes."""

from __future__ import annotations

import numpy as np
import pytest

import colcos
from colcos.preflight import PreflightError, PreflightLimits, preflight

# A loaded CI machine may overrun ticks; the check under test here is the policy's, not the machine's.
LIMITS = PreflightLimits(overruns=0.5)


def test_a_policy_that_drives_into_the_walls_is_refused():
    with pytest.raises(PreflightError, match="walled") as e:
        preflight(lambda obs: np.ones(2, np.float32), episodes=1, max_cycles=150, limits=LIMITS)
    report = e.value.report
    agents = len(colcos.parallel_env(task="aggregation").possible_agents)
    assert report.walled > 0 and report.episodes == 1 and report.agent_steps == 150 * agents
    assert isinstance(e.value, colcos.ColcosError)


def test_a_policy_that_keeps_clear_passes():
    report = preflight(lambda obs: np.array([-0.2, 0.2], np.float32), episodes=1, max_cycles=100, limits=LIMITS)
    assert report.broken == [] and report.walled == 0 and report.boundary == 0
    assert report.steps == 100 and len(report.returns) == 1


def test_a_boundary_refusal_names_the_robot_the_step_and_the_distance():
    strict = PreflightLimits(overruns=0.5, walled=1.0, capped=1.0, edge_tolerance=-0.05)
    with pytest.raises(PreflightError, match=r"boundary = \d+ over the limit 0 \(worst: robot \d+, episode 0, step \d+: [\d.]+ mm (past|inside) the edge\)") as e:
        preflight(lambda obs: np.ones(2, np.float32), episodes=1, max_cycles=150, limits=strict)
    assert e.value.report.worst_boundary is not None


def test_bad_arguments_are_named():
    with pytest.raises(colcos.TaskError, match="episodes"):
        preflight(lambda obs: obs[:2], episodes=0)
