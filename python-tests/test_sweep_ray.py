"""colcos.sweep on a real local Ray cluster (started here): the same table as the local backend, a
task whose worker dies is retried without a row written twice, and a DataFrame equal to the table."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import ray

import colcos.sweep

REPO = Path(__file__).resolve().parent.parent
TINY = REPO / "scenarios" / "sweeps" / "tiny.toml"


@pytest.fixture(scope="module")
def cluster():
    # A cluster of our own, whatever an earlier suite of the session left running.
    if ray.is_initialized():
        ray.shutdown()
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def without_wall(df: pd.DataFrame) -> pd.DataFrame:
    return df.drop(columns=["wall_s"])


def test_local_and_ray_give_the_same_table(cluster, tmp_path):
    local = colcos.sweep.run(TINY, backend="local", out=tmp_path / "local", threads=2)
    on_ray = colcos.sweep.run(TINY, backend="ray", out=tmp_path / "ray", group_size=3)
    assert list(local["run_id"]) == list(range(8))
    pd.testing.assert_frame_equal(without_wall(local), without_wall(on_ray))
    # The DataFrame is the table on disk.
    pd.testing.assert_frame_equal(on_ray, pd.read_csv(tmp_path / "ray" / "results.csv"))
    assert (tmp_path / "ray" / "results.csv").read_text() != ""


def test_a_dead_task_is_retried_without_duplicate_rows(cluster, tmp_path):
    marker = tmp_path / "died"
    df = colcos.sweep.run(
        TINY, backend="ray", out=tmp_path / "retry", group_size=2, _die_once=str(marker)
    )
    assert marker.exists(), "no task died: the retry was not exercised"
    assert list(df["run_id"]) == list(range(8))
    lines = (tmp_path / "retry" / "results.csv").read_text().splitlines()
    assert len(lines) == 9
    local = colcos.sweep.run(TINY, out=tmp_path / "local", threads=1)
    pd.testing.assert_frame_equal(without_wall(local), without_wall(df))


def test_ray_resumes_a_partial_table(cluster, tmp_path):
    out = tmp_path / "partial"
    full = colcos.sweep.run(TINY, backend="local", out=tmp_path / "full", threads=2)
    text = (tmp_path / "full" / "results.csv").read_text().splitlines(keepends=True)
    out.mkdir()
    (out / "plan.toml").write_text((tmp_path / "full" / "plan.toml").read_text())
    # Three complete rows and a torn fourth, as a killed sweep leaves them.
    (out / "results.csv").write_text("".join(text[:4]) + text[4][:7])
    df = colcos.sweep.run(TINY, backend="ray", out=out, resume=True)
    pd.testing.assert_frame_equal(without_wall(full), without_wall(df))
    # The three rows found were kept as they were.
    pd.testing.assert_frame_equal(df.iloc[:3], full.iloc[:3])


def leader_travel(run: dict) -> float:
    """How far the leader ended from where it started, m."""
    k = run["roles"].index("leader")
    return float(np.linalg.norm(run["positions"][-1, k] - run["positions"][0, k]))


def test_python_metrics_locally_and_on_ray(cluster, tmp_path):
    metrics = {"leader_travel": leader_travel, "seed_twice": lambda run: 2 * run["seed"]}
    local = colcos.sweep.run(TINY, out=tmp_path / "local", threads=2, metrics=metrics)
    on_ray = colcos.sweep.run(TINY, backend="ray", out=tmp_path / "ray", metrics=metrics, group_size=3)
    pd.testing.assert_frame_equal(without_wall(local), without_wall(on_ray))
    assert list(local.columns[-3:]) == ["leader_travel", "seed_twice", "wall_s"]
    assert (local["seed_twice"] == 2 * local["seed"]).all()
    assert (local["leader_travel"] > 0).all()
    # The built-in columns are those of a sweep without Python metrics.
    plain = colcos.sweep.run(TINY, out=tmp_path / "plain", threads=2)
    pd.testing.assert_frame_equal(without_wall(plain), without_wall(local).drop(columns=["leader_travel", "seed_twice"]))
