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
"""

from __future__ import annotations

import json
import os
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
    import pandas as pd

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
    _die_once: str | None = None,
) -> Any:
    """Runs a sweep and returns its table (pandas DataFrame). See the module docstring.

    threads: worker threads of the local backend, or per Ray task (default: all cores, one per task
    with Ray). `_die_once` (tests only): a path; the first task to find it missing creates it and
    kills its worker process, to exercise Ray's retry.
    """
    sweep = load(spec, base_dir)
    out = Path(out) if out is not None else Path("runs") / "sweeps" / sweep.name
    if threads is not None and (not isinstance(threads, int) or threads < 1):
        raise _core.ScenarioError(f"threads = {threads!r}: a positive integer")
    if backend == "local":
        _total, _ran, _skipped, table = sweep.run_local(str(out), threads, resume)
        return read_table(table)
    if backend == "ray":
        return read_table(_run_ray(sweep, out, threads, resume, group_size, retries, _die_once))
    raise _core.ScenarioError(f"backend = {backend!r}: \"local\" or \"ray\"")


def _run_group(text: str, scenario_dir: str, ids: list[int], threads: int | None, die_once: str | None):
    """One Ray task: the rows of runs `ids`."""
    if die_once is not None and not os.path.exists(die_once):
        Path(die_once).write_text("died\n")
        os._exit(1)
    sweep = _core.Sweep(text=text, base_dir=scenario_dir)
    return sweep.run_ids(ids, threads)


def _run_ray(sweep, out: Path, threads, resume, group_size, retries, die_once) -> str:
    import ray

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
            task.remote(text_ref, scenario_dir, pending[i : i + group_size], per_task, die_once)
            for i in range(0, len(pending), group_size)
        ]
        while waiting:
            done, waiting = ray.wait(waiting, num_returns=1)
            for ref in done:
                table.append(ray.get(ref))
    finally:
        path = table.finish()
    return path
