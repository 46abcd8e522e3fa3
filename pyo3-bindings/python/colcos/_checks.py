"""Arguments checked one way everywhere: the value, or a `colcos` error naming the argument and what
was given. Python numbers and numpy scalars are accepted alike; booleans are flags, not numbers."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from colcos._core import LIMITS, ArgumentTypeError, TaskError

SEED_MAX = 2**64 - 1


def _range(lo: int, hi: int) -> str:
    return f"an integer in {lo}..={'2**64-1' if hi == SEED_MAX else hi}"


def _show(value: Any) -> str:
    r = repr(value)
    return r if len(r) <= 80 else r[:77] + "..."


def is_bool(value: Any) -> bool:
    return isinstance(value, (bool, np.bool_))


def integer(value: Any, name: str, lo: int, hi: int) -> int:
    """An int (or numpy integer) in `lo..=hi`; bools, floats and strings are refused."""
    if is_bool(value) or not isinstance(value, (int, np.integer)):
        raise ArgumentTypeError(f"{name} must be {_range(lo, hi)}, got {_show(value)} ({type(value).__name__})")
    v = int(value)
    if not lo <= v <= hi:
        raise TaskError(f"{name} must be {_range(lo, hi)}, got {_show(value)}")
    return v


def seed(value: Any, name: str = "seed") -> int:
    """A seed: an integer in 0..=2**64-1 (as the native module checks it)."""
    return integer(value, name, 0, SEED_MAX)


def flag(value: Any, name: str) -> bool:
    """True or False (or a numpy bool); never a truthy string or number."""
    if not is_bool(value):
        raise ArgumentTypeError(f"{name} must be True or False, got {_show(value)} ({type(value).__name__})")
    return bool(value)


def real(value: Any, name: str, positive: bool = False) -> float:
    """A finite number (int, float or numpy scalar; not a bool or a string)."""
    if is_bool(value) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ArgumentTypeError(f"{name} must be a number, got {_show(value)} ({type(value).__name__})")
    v = float(value)
    if not math.isfinite(v) or (positive and v <= 0):
        raise TaskError(f"{name} must be a {'positive ' if positive else ''}finite number, got {_show(value)}")
    return v


def choice(value: Any, name: str, options: Sequence[str | None]) -> Any:
    """One of `options` (strings or None)."""
    if value is not None and not isinstance(value, str):
        raise ArgumentTypeError(f"{name} must be one of {list(options)}, got {_show(value)} ({type(value).__name__})")
    if value not in options:
        raise TaskError(f"{name} {value!r} is not one of {list(options)}")
    return value


def limit(name: str) -> int:
    """The native module's bound on `name` (num_envs, num_threads, max_cycles, render_width, patch)."""
    return int(LIMITS[name])


def plain(value: Any, key: str) -> Any:
    """A task parameter as plain JSON data (numpy scalars and arrays become numbers and lists); NaN,
    infinities and objects JSON cannot hold are refused naming `key`."""
    if value is None or isinstance(value, str) or is_bool(value):
        return bool(value) if is_bool(value) else value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            raise TaskError(f"task parameter `{key}` must be finite, got {_show(value)}")
        return v
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [plain(v, f"{key}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise ArgumentTypeError(f"task parameter `{key}` has a key that is not a str: {_show(k)}")
            out[k] = plain(v, f"{key}.{k}")
        return out
    raise ArgumentTypeError(
        f"task parameter `{key}` must be a number, string, bool or a list of them, got {_show(value)} ({type(value).__name__})"
    )


def options(options: Any, known: tuple[str, ...]) -> None:
    """A `reset` options dict: None or a dict whose keys are all in `known` (a misspelt key would
    otherwise be ignored without a word)."""
    if options is None:
        return
    if not isinstance(options, dict):
        raise ArgumentTypeError(f"options must be a dict or None, got {type(options).__name__}")
    unknown = sorted(str(k) for k in options if k not in known)
    if unknown:
        expected = ", ".join(repr(k) for k in known) if known else "none"
        raise TaskError(f"unknown reset option(s) {unknown}; known: {expected}")
