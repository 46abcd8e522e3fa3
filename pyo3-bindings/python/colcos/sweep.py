"""Batch scenario sweeps from Python: the same sweep files, runs and results table as `colcos sweep`.

>>> import colcos.sweep
>>> df = colcos.sweep.run("scenarios/sweeps/tiny.toml", out="runs/tiny")            # all local cores
>>> df = colcos.sweep.run("scenarios/sweeps/tiny.toml", backend="ray", out="runs/tiny_ray")

`spec` is a sweep file's path or its content as a dict (relative scenario paths then resolve against
`base_dir`, default the working directory). The table `out/results.csv` is resumable: a rerun into the
same directory (or `resume=True`) runs only the missing rows, and a complete table is sorted by run id.

With `backend="ray"`, runs are grouped into Ray tasks (`group_size` runs each) that call the Rust
runner with the GIL released; rows come back to this process as tasks finish and are appended to the
table, so a task that dies is retried (`retries`) without a row written twice. It uses the Ray cluster
that `ray.init()` (one machine) or `ray.init(address=...)` (a cluster) connected to, or starts a local
one. Workers rebuild the runs from the sweep with its base scenario inlined; image maps must be at the
same path on every node. Returns a pandas DataFrame of the table (pandas needed).

`metrics={"name": fn}` adds columns computed in Python: `fn(run)` gets a dict with the run's robot poses
at the sample times (`times` (T,), `positions` (T, N, 2), `headings` (T, N), `roles` [N], float32
numpy arrays) and its `run_id`, `seed` and `params` (axis name -> value as written in the table), and
returns a number (None or NaN: an empty cell). With Ray the functions run in the workers.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from colcos import _core

__all__ = ["run", "load", "read_table"]


def load(spec: str | os.PathLike | dict, base_dir: str | os.PathLike | None = None) -> _core.Sweep:
    """The checked plan of a sweep file (path) or a sweep given as a dict."""
    if isinstance(spec, dict):
        base = Path(base_dir) if base_dir is not None else Path.cwd()
        return _core.Sweep(json=json.dumps(spec), base_dir=str(base))
    if isinstance(spec, (str, os.PathLike)):
        return _core.Sweep(path=str(spec))
    raise TypeError(f"spec: a sweep file path or a dict, not {type(spec).__name__}")


def read_table(path: str | os.PathLike):
    """A results table as a pandas DataFrame."""
    import pandas as pd  # type: ignore[import-untyped]  # optional: not where the package is checked

    return pd.read_csv(path)


def run(
    spec: str | os.PathLike | dict,
    backend: str = "local",
    out: str | os.PathLike | None = None,
    threads: int | None = None,
    resume: bool = False,
    base_dir: str | os.PathLike | None = None,
    group_size: int | None = None,
    retries: int = 3,
    metrics: dict[str, Callable[[dict], Any]] | None = None,
    _die_once: str | None = None,
) -> Any:
    """Runs a sweep and returns its table (pandas DataFrame). See the module docstring.

    threads: worker threads of the local backend, or per Ray task (default: all cores, one per task
    with Ray). `_die_once` (tests only): a path; the first task to find it missing creates it and
    kills its worker process, to exercise Ray's retry.
    """
    sweep = load(spec, base_dir)
    metrics = dict(metrics or {})
    for name, fn in metrics.items():
        if not callable(fn):
            raise TypeError(f"metrics[{name!r}]: a callable, not {type(fn).__name__}")
    if metrics:
        sweep = sweep.with_metrics(list(metrics))
    out = Path(out) if out is not None else Path("runs") / "sweeps" / sweep.name
    if threads is not None and (not isinstance(threads, int) or threads < 1):
        raise _core.ScenarioError(f"threads = {threads!r}: a positive integer")
    if backend == "local" and not metrics:
        _total, _ran, _skipped, table = sweep.run_local(str(out), threads, resume)
        return read_table(table)
    if backend == "local":
        return read_table(_run_local_with_metrics(sweep, out, threads, resume, metrics))
    if backend == "ray":
        return read_table(_run_ray(sweep, out, threads, resume, group_size, retries, metrics, _die_once))
    raise _core.ScenarioError(f"backend = {backend!r}: \"local\" or \"ray\"")


def _fill(columns: list[str], traced, metrics: dict) -> tuple[int, list[str]]:
    """A traced run's row with its Python metric cells filled in."""
    run_id, cells, run = traced
    first, seed_col = columns.index("combo") + 1, columns.index("seed")
    run = dict(run)
    run["run_id"] = run_id
    run["seed"] = int(cells[seed_col])
    run["params"] = dict(zip(columns[first:seed_col], cells[first:seed_col], strict=True))
    for name, fn in metrics.items():
        v = fn(run)
        v = float("nan") if v is None else float(v)
        cells[columns.index(name)] = "" if math.isnan(v) or math.isinf(v) else repr(v)
    return run_id, cells


def _rows(sweep, ids: list[int], threads: int | None, metrics: dict) -> list[tuple[int, list[str]]]:
    if not metrics:
        return sweep.run_ids(ids, threads)
    columns = sweep.columns
    return [_fill(columns, t, metrics) for t in sweep.run_traced(ids, threads)]


def _run_local_with_metrics(sweep, out: Path, threads, resume, metrics) -> str:
    sweep.check()
    table = sweep.open_table(str(out), resume)
    try:
        pending = table.pending()
        chunk = 4 * (threads or os.cpu_count() or 1)
        for i in range(0, len(pending), chunk):
            table.append(_rows(sweep, pending[i : i + chunk], threads, metrics))
    finally:
        path = table.finish()
    return path


def _run_group(text: str, scenario_dir: str, ids: list[int], threads, metrics: dict, die_once):
    """One Ray task: the rows of runs `ids`."""
    if die_once is not None and not os.path.exists(die_once):
        Path(die_once).write_text("died\n")
        os._exit(1)
    sweep = _core.Sweep(text=text, base_dir=scenario_dir)
    if metrics:
        sweep = sweep.with_metrics(list(metrics))
    return _rows(sweep, ids, threads, metrics)


def _run_ray(sweep, out: Path, threads, resume, group_size, retries, metrics, die_once) -> str:
    import ray  # type: ignore[import-not-found]  # optional: not where the package is checked

    if group_size is not None and (not isinstance(group_size, int) or group_size < 1):
        raise _core.ScenarioError(f"group_size = {group_size!r}: a positive integer")
    sweep.check()
    table = sweep.open_table(str(out), resume)
    try:
        pending = table.pending()
        if not ray.is_initialized():
            ray.init()
        cpus = max(1, int(ray.cluster_resources().get("CPU", 1)))
        per_task = threads or 1
        if group_size is None:
            # About four tasks per CPU slot: small enough to balance, large enough to amortise Ray.
            group_size = max(1, len(pending) // (4 * max(1, cpus // per_task)))
        task = ray.remote(num_cpus=per_task, max_retries=retries)(_run_group)
        text, scenario_dir = sweep.portable()
        text_ref = ray.put(text)
        waiting = [
            task.remote(text_ref, scenario_dir, pending[i : i + group_size], per_task, metrics, die_once)
            for i in range(0, len(pending), group_size)
        ]
        while waiting:
            done, waiting = ray.wait(waiting, num_returns=1)
            for ref in done:
                table.append(ray.get(ref))
    finally:
        path = table.finish()
    return path
