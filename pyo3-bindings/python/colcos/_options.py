"""Turning Python keyword arguments into the native environment's options (one place for both faces)."""

from __future__ import annotations

import json
import os
from typing import Any

import numpy as np
from gymnasium import spaces

from colcos._core import TaskError


def core_kwargs(
    task: str,
    scenario: str | os.PathLike[str] | None,
    max_cycles: int | None,
    continuous: bool,
    global_state: bool,
    patch: int | None,
    patch_side: float,
    params: dict[str, Any],
) -> dict[str, Any]:
    """Keyword arguments of `colcos._core.VecEnv` (all but num_envs, seed, threads, autoreset)."""
    if not isinstance(task, str):
        raise TaskError(f"task must be a task name (str), got {type(task).__name__}")
    kw: dict[str, Any] = {"task": task}
    if scenario is not None:
        text = os.fspath(scenario) if isinstance(scenario, os.PathLike) else scenario
        if not isinstance(text, str):
            raise TaskError(f"scenario must be a path or TOML text, got {type(scenario).__name__}")
        if "\n" in text:
            kw["scenario_text"] = text
        else:
            kw["scenario"] = text
    if max_cycles is not None:
        if isinstance(max_cycles, bool) or not isinstance(max_cycles, (int, np.integer)) or max_cycles < 1:
            raise TaskError(f"max_cycles must be a positive integer, got {max_cycles!r}")
        kw["max_cycles"] = int(max_cycles)
    kw["action"] = "continuous" if continuous else "discrete"
    kw["global_state"] = bool(global_state)
    if patch is not None:
        kw["patch_pixels"] = int(patch)
        kw["patch_side"] = float(patch_side)
    if params:
        try:
            kw["params_json"] = json.dumps(params)
        except TypeError as e:
            raise TaskError(f"task parameters must be plain numbers, strings, booleans and lists: {e}") from e
    return kw


def make_space(d: dict[str, Any]) -> spaces.Space:
    """A Gymnasium space from the native spec dict."""
    if d["kind"] == "discrete":
        return spaces.Discrete(int(d["n"]))
    dtype = np.float32 if d["dtype"] == "float32" else np.uint8
    return spaces.Box(low=d["low"], high=d["high"], shape=tuple(d["shape"]), dtype=dtype)
