"""System identification from a rig log: each robot's wheel scales, motor lag, command latency and
colour sensor gain and offset, fitted from what the bridge recorded while `colcos rig excite` drove
the robots (the commands sent, the poses tracked, the telemetry's colour counts), each with its
uncertainty; what the log cannot pin down comes with the reason instead of a number.

    import colcos.rig
    fit = colcos.rig.identify("runs/excite/rig.mcap", scenario="lab.toml", out="fit.toml")
    fit.robots[0].sensor_gain        # (value, sd), or None: fit.robots[0].why["sensor_gain"]

`out` is a file of `[[robot]]` entries that a scenario's `[individual] file` reads (and
`colcos twin --truth`, `colcos.parallel_env(..., plant="twin", truth=...)`), as `colcos rig identify`
writes it (docs/identify.md).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any

from colcos import _core
from colcos._core import ArgumentTypeError

Value = tuple[float, float]
"""A fitted value and its standard deviation."""


@dataclass(frozen=True)
class RobotFit:
    """One robot's fitted values, each `(value, sd)`, or None with the reason in `why`."""

    index: int
    wheel_scale: tuple[Value, Value] | None
    """(left, right), each (scale, sd)."""
    motor_lag: Value | None
    """s."""
    latency: Value | None
    """s, from a command leaving the bridge to the wheels taking it (plus half a simulator step)."""
    sensor_gain: Value | None
    sensor_offset: Value | None
    """Counts added after the gain."""
    why: dict[str, str] = field(default_factory=dict)
    """Why a parameter is None ("unidentifiable: the robot saw too little contrast ...")."""
    windows: int = 0
    """Windows of motion fitted."""
    readings: int = 0
    """Colour readings the robot reported, and those used for its gain."""
    readings_used: int = 0


@dataclass(frozen=True)
class Fit:
    """What `identify` found in one log."""

    robots: list[RobotFit]
    duration: float
    """Seconds of log."""
    pose_delay: float
    """s added to every logged pose age (the tracker's delivery the ages leave out)."""
    tracker_latency: float | None
    """The poses' mean logged age, s."""
    telemetry_round_trip: float | None
    """Median time from a data request to its answer, s."""
    overlay: str
    """The file of per-robot values (TOML), as written to `out`."""


def _value(d: dict[str, Any]) -> Value | None:
    return None if "why" in d else (float(d["value"]), float(d["sd"]))


def _robot(d: dict[str, Any]) -> RobotFit:
    why = {k: d[k]["why"] for k in ("wheel_scale", "motor_lag", "latency", "sensor_gain", "sensor_offset") if "why" in d[k]}
    ws = d["wheel_scale"]
    wheel = None if "why" in ws else ((ws["value"][0], ws["sd"][0]), (ws["value"][1], ws["sd"][1]))
    return RobotFit(
        index=int(d["index"]),
        wheel_scale=wheel,
        motor_lag=_value(d["motor_lag"]),
        latency=_value(d["latency"]),
        sensor_gain=_value(d["sensor_gain"]),
        sensor_offset=_value(d["sensor_offset"]),
        why=why,
        windows=int(d["windows"]),
        readings=int(d["readings"]),
        readings_used=int(d["readings_used"]),
    )


def _path(value: Any, name: str) -> str:
    if not isinstance(value, (str, os.PathLike)):
        raise ArgumentTypeError(f"{name} must be a path (str or os.PathLike), got {type(value).__name__}")
    return os.fspath(value)


def identify(
    log: str | os.PathLike[str],
    scenario: str | os.PathLike[str],
    out: str | os.PathLike[str] | None = None,
    pose_delay: float | None = None,
) -> Fit:
    """Fits every robot of `scenario` (the scenario file the log was recorded with) from the rig log
    `log` (`rig.mcap`); writes the per-robot values to `out` when given. `pose_delay`: s to add to
    every logged pose age (default: the `[tracker] latency` the log was recorded with).

    Raises `colcos.ColcosError` for a log that cannot be fitted, with the reason (no wheel commands,
    no poses, a log of another scenario), `colcos.ScenarioError` for a bad scenario and `OSError`
    for a file that cannot be read or written."""
    args = {"log": _path(log, "log"), "scenario": _path(scenario, "scenario")}
    if out is not None:
        args["out"] = _path(out, "out")
    if pose_delay is not None and (isinstance(pose_delay, bool) or not isinstance(pose_delay, (int, float))):
        raise ArgumentTypeError(f"pose_delay must be a number of seconds, got {type(pose_delay).__name__}")
    raw = json.loads(_core.rig_identify(**args, pose_delay=None if pose_delay is None else float(pose_delay)))
    return Fit(
        robots=[_robot(r) for r in raw["robots"]],
        duration=float(raw["duration"]),
        pose_delay=float(raw["pose_delay"]),
        tracker_latency=raw["tracker_latency"],
        telemetry_round_trip=raw["telemetry_round_trip"],
        overlay=str(raw["overlay"]),
    )
