"""colcos.sweep without pandas or Ray: plans, errors naming the key, the local runner and its table."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

import colcos
import colcos.sweep

REPO = Path(__file__).resolve().parent.parent
TINY = REPO / "scenarios" / "sweeps" / "tiny.toml"


def rows(path) -> list[list[str]]:
    """The table without its wall-time column."""
    with open(path, newline="") as f:
        table = list(csv.reader(f))
    wall = table[0].index("wall_s")
    return [r[:wall] + r[wall + 1 :] for r in table]


def test_a_sweep_file_and_the_same_sweep_as_a_dict_plan_the_same_runs():
    a = colcos.sweep.load(TINY)
    spec = {
        "scenario": "../case2_alarm.toml",
        "duration": 2.0,
        "seeds": 2,
        "metrics": list(a.metrics[:-2]) + ["field_mass"],
        "axes": [
            {"key": "robots[1].params.speed", "name": "follower_speed", "values": [0.05, 0.1]},
            {"key": "robots[1].count", "values": [1, 3]},
        ],
    }
    b = colcos.sweep.load(spec, base_dir=TINY.parent)
    assert a.total == b.total == 8
    assert a.columns == b.columns
    assert a.columns[:5] == ["run_id", "combo", "follower_speed", "robots[1].count", "seed"]


def test_local_runs_resume_and_give_the_same_table(tmp_path):
    sweep = colcos.sweep.load(TINY)
    total, ran, skipped, table = sweep.run_local(str(tmp_path / "a"), 2, False)
    assert (total, ran, skipped) == (8, 8, 0)
    # A rerun into the same directory runs nothing; one thread gives the same table.
    assert sweep.run_local(str(tmp_path / "a"), 2, False)[1:3] == (0, 8)
    one = sweep.run_local(str(tmp_path / "b"), 1, False)[3]
    assert rows(table) == rows(one)
    assert [r[0] for r in rows(table)[1:]] == [str(i) for i in range(8)]


def test_rows_computed_elsewhere_go_into_the_table_once(tmp_path):
    sweep = colcos.sweep.load(TINY)
    text, base = sweep.portable()
    worker = colcos._core.Sweep(text=text, base_dir=base)
    table = sweep.open_table(str(tmp_path))
    assert table.pending() == list(range(8))
    first = worker.run_ids([5, 1, 2], 1)
    assert table.append(first) == 3
    assert table.append(first) == 0  # a retried task's rows are not written twice
    assert table.pending() == [0, 3, 4, 6, 7]
    assert table.append(worker.run_ids([0, 3, 4, 6, 7])) == 5
    assert table.complete()
    path = table.finish()
    reference = sweep.run_local(str(tmp_path / "local"), 2, False)[3]
    assert rows(path) == rows(reference)


@pytest.mark.parametrize(
    ("spec", "words"),
    [
        ({"scenario": "../case2_alarm.toml", "metrics": ["s_man"]}, ["metrics[0]", "s_man"]),
        ({"scenario": "../case2_alarm.toml", "metrics": ["s_mean"], "seeds": 0}, ["`seeds` = 0"]),
        ({"scenario": "../case2_alarm.toml", "metrics": ["s_mean"], "colour": 1}, ["unknown field `colour`"]),
        (
            {
                "scenario": "../case2_alarm.toml",
                "metrics": ["s_mean"],
                "axes": [{"key": "robots[1].count", "values": [1, -3]}],
            },
            ["combination 1", "robots[1].count = -3"],
        ),
    ],
)
def test_bad_sweeps_raise_scenario_errors_naming_the_key(spec, words):
    with pytest.raises(colcos.ScenarioError) as e:
        colcos.sweep.load(spec, base_dir=TINY.parent).check()
    for w in words:
        assert w in str(e.value)
    assert isinstance(e.value, ValueError)


def test_bad_arguments(tmp_path):
    with pytest.raises(colcos.ScenarioError, match="backend = 'spark'"):
        colcos.sweep.run(TINY, backend="spark", out=tmp_path)
    with pytest.raises(TypeError, match="spec"):
        colcos.sweep.load(42)
    with pytest.raises(colcos.ScenarioError, match="nothing to resume"):
        colcos.sweep.load(TINY).run_local(str(tmp_path / "none"), 1, True)


def test_traced_runs_give_the_poses_at_the_sample_times():
    sweep = colcos.sweep.load(TINY).with_metrics(["mine"])
    assert sweep.columns[-2:] == ["mine", "wall_s"]
    [(run_id, cells, run)] = sweep.run_traced([3], 1)
    assert run_id == 3 and cells[sweep.columns.index("mine")] == ""
    # 2 s sampled every 0.1 s from t = 0; a leader, 3 followers and a predator.
    assert run["times"].shape == (21,)
    assert run["positions"].shape == (21, 5, 2)
    assert run["headings"].shape == (21, 5)
    assert run["roles"] == ["leader", "follower", "follower", "follower", "predator"]
    # The same run without tracing gives the same built-in metrics.
    [(_, plain)] = sweep.run_ids([3], 1)
    assert plain[:-1] == cells[:-1]
    with pytest.raises(colcos.ScenarioError, match="s_mean"):
        colcos.sweep.load(TINY).with_metrics(["s_mean"])
