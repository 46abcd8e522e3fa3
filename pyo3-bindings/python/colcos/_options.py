"""Turning Python keyword arguments into the native environment's options (one place for both faces)."""

from __future__ import annotations

import inspect
import json
import logging
import os
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
from gymnasium import spaces

from colcos import _checks, _core
from colcos._core import ArgumentTypeError, TaskError

log = logging.getLogger("colcos")

BACKENDS = ("cpu", "gpu", "auto")
PHYSICS = ("rapier", "discs")


def core_kwargs(
    task: str,
    scenario: str | os.PathLike[str] | None,
    max_cycles: int | None,
    continuous: bool,
    global_state: bool,
    patch: int | None,
    patch_side: float,
    params: dict[str, Any],
    backend: str | None = None,
    physics: str | None = None,
) -> dict[str, Any]:
    """Keyword arguments of `colcos._core.VecEnv` (all but num_envs, seed, threads, autoreset)."""
    if not isinstance(task, str):
        raise ArgumentTypeError(f"task must be a task name (str), got {task!r} ({type(task).__name__})")
    kw: dict[str, Any] = {"task": task}
    if scenario is not None:
        text = os.fspath(scenario) if isinstance(scenario, os.PathLike) else scenario
        if not isinstance(text, str):
            raise ArgumentTypeError(f"scenario must be a path or TOML text, got {type(scenario).__name__}")
        if "\n" in text:
            kw["scenario_text"] = text
        else:
            kw["scenario"] = text
    if max_cycles is not None:
        kw["max_cycles"] = _checks.integer(max_cycles, "max_cycles", 1, _checks.limit("max_cycles"))
    kw["action"] = "continuous" if _checks.flag(continuous, "continuous") else "discrete"
    kw["global_state"] = _checks.flag(global_state, "global_state")
    if patch is not None:
        kw["patch_pixels"] = _checks.integer(patch, "patch", 1, _checks.limit("patch"))
        kw["patch_side"] = _checks.real(patch_side, "patch_side", positive=True)
    if backend is not None:
        if not isinstance(backend, str) or backend.lower() not in BACKENDS:
            raise TaskError(f"backend must be one of {BACKENDS} (or None: the scenario's [field] backend), got {backend!r}")
        kw["backend"] = backend.lower()
    if physics is not None:
        if not isinstance(physics, str) or physics.lower() not in PHYSICS:
            raise TaskError(f"physics must be one of {PHYSICS} (or None: the scenario's), got {physics!r}")
        kw["physics"] = physics.lower()
    if params:
        kw["params_json"] = json.dumps({k: _checks.plain(v, k) for k, v in params.items()})
    return kw


def twin_kwargs(twin_scenario: Any, truth: Any = None) -> dict[str, Any]:
    """`colcos._core.Plant`'s keywords for a twin's own scenario (a file, TOML text or overrides) and
    its robots' hidden per-robot values (`truth`: a file of `[[robot]]` entries)."""
    out: dict[str, Any] = {}
    if truth is not None:
        if not isinstance(truth, (str, os.PathLike)):
            raise ArgumentTypeError(f"truth must be a path (str or os.PathLike), got {type(truth).__name__}")
        out["truth"] = os.fspath(truth)
    if twin_scenario is None:
        return out
    if isinstance(twin_scenario, dict):
        for k in twin_scenario:
            if not isinstance(k, str):
                raise ArgumentTypeError(f"twin_scenario keys must be key paths (str), got {k!r}")
        sets = {k: _checks.plain(v, f"twin_scenario.{k}") for k, v in twin_scenario.items()}
        return {**out, "twin_overrides_json": json.dumps(sets)}
    text = os.fspath(twin_scenario) if isinstance(twin_scenario, os.PathLike) else twin_scenario
    if not isinstance(text, str):
        raise ArgumentTypeError(
            f"twin_scenario must be a path, TOML text or a dict of key paths, got {type(twin_scenario).__name__}"
        )
    return {**out, "twin_scenario_text": text} if "\n" in text else {**out, "twin_scenario": text}


def make_space(d: dict[str, Any]) -> spaces.Space:
    """A Gymnasium space from the native spec dict."""
    if d["kind"] == "discrete":
        return spaces.Discrete(int(d["n"]))
    dtype = np.float32 if d["dtype"] == "float32" else np.uint8
    shape = tuple(d["shape"])
    # Per-entry bounds (a list) where the values take tighter ones than the envelope.
    low = np.asarray(d["low"], dtype=dtype).reshape(shape) if isinstance(d["low"], list) else d["low"]
    high = np.asarray(d["high"], dtype=dtype).reshape(shape) if isinstance(d["high"], list) else d["high"]
    return spaces.Box(low=low, high=high, shape=shape, dtype=dtype)


def make_box(d: dict[str, Any]) -> spaces.Box:
    """A Gymnasium Box from a native spec dict of kind `box`."""
    space = make_space(d)
    assert isinstance(space, spaces.Box), d
    return space


def share_signature(make: Callable[..., Any], cls: type) -> None:
    """Gives `make` (a function returning a `cls`) the signature and documentation of `cls`'s
    constructor, so that `help(make)` shows the real arguments rather than `**kwargs`."""
    sig = inspect.signature(cls.__init__)  # type: ignore[misc]
    params = [p for name, p in sig.parameters.items() if name != "self"]
    returns = inspect.signature(make).return_annotation
    make.__signature__ = sig.replace(parameters=params, return_annotation=returns)  # type: ignore[attr-defined]
    own = inspect.getdoc(make) or ""
    make.__doc__ = f"{own}\n\n{inspect.getdoc(cls) or ''}"


def log_backend(core: Any, asked: str | None) -> None:
    """One log line on the field backend the environment took (`colcos` logger, INFO)."""
    log.info("field backend%s: %s", f" ({asked} asked for)" if asked else "", core.backend_info)


class HumanWindow:
    """The window of `render_mode="human"`: opened at the first frame, paced to the field's rate.

    Where no window can be opened (no display, built without it) it warns once and shows nothing, so
    that code written for a desktop still runs headless.
    """

    def __init__(self, title: str, fps: float) -> None:
        self.title = title
        self.fps = fps
        self.window: Any = None
        self.failed = False
        self.shown_key: Any = None

    def show(self, frame: np.ndarray, key: Any = None) -> None:
        """Shows `frame` (H, W, 3) uint8, unless `key` is that of the frame shown last."""
        if self.failed or (key is not None and key == self.shown_key):
            return
        self.shown_key = key
        if self.window is None:
            try:
                self.window = _core.Window(frame.shape[1], frame.shape[0], title=self.title, fps=self.fps)
            except _core.DisplayError as e:
                self.failed = True
                warnings.warn(
                    f"render_mode='human': no window can be opened ({e}); frames are not shown "
                    "(render_mode='rgb_array' gives them as arrays)",
                    RuntimeWarning,
                    stacklevel=4,
                )
                return
        self.window.show(frame)

    @property
    def presented(self) -> int:
        """Frames the window has presented (0 before it opens)."""
        return 0 if self.window is None else int(self.window.presented)

    @property
    def is_open(self) -> bool:
        return self.window is not None and bool(self.window.is_open)

    def close(self) -> None:
        if self.window is not None:
            self.window.close()
            self.window = None
        self.shown_key = None


class BackendInfo:
    """`backend_name` / `backend_info` of an environment whose native core is `self._core`."""

    _core: Any

    @property
    def backend_name(self) -> str:
        """What steps the grid pheromones: `"cpu"` or `"gpu"`."""
        return self._core.backend_name

    @property
    def backend_info(self) -> str:
        """One line on the field backend: `gpu: <adapter>` or `cpu (<why>)`."""
        return self._core.backend_info


def readonly_views(views: dict[str, Any]) -> dict[str, Any]:
    """The native output buffers as read-only arrays: the core rewrites them at every step, and a
    write from Python would be lost (or read back as the env's own output) without a word."""
    for a in views.values():
        a.flags.writeable = False
    return views
