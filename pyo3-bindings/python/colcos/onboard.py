"""Policies on board: a small trained MLP policy as dependency-free C99 for the Colias robot.

The Colias's STM32F334 (72 MHz Cortex-M4F, 12 KB SRAM, 64 KB flash) can run the PPO example's actor
(17-64-64-2, tanh; `examples/train_aggregation.py`) itself: `export_c` writes a header and a source
with the weights as `static const float` arrays, f32 arithmetic, no allocation and no libm beyond the
activation's `tanhf` / `expf`, together with the observation encoding the policy was trained on
(raw colour-sensor counts and IR bumper counts to the 17 inputs, as `env/src/encoding.rs` and the
sensor's calibrated inverse in `sim/src/sensors/colour.rs` do) and the action decoding to wheel speeds.

    from colcos.onboard import export_c
    info = export_c(model.pi, "firmware/policy", obs_norm=model.obs_norm)   # policy.h, policy.c
    info.weight_bytes, info.stack_bytes                                     # (21904, 512) for 17-64-64-2

Beside the C it writes `<path>.json`, the policy's manifest (its hash and its runtime parameter block:
the largest wheel speed, the bumper span and each colour sensor's calibration, which the host may
rewrite over the radio): name it in a scenario's `[rig] onboard` and the bridge uploads each robot's
parameters and starts the policy, and the digital twin runs this C on its robots (docs/bridge.md).

The policy can be a torch `nn.Sequential` of `Linear` layers and activations (`Tanh`, `ReLU`,
`Sigmoid`, `Identity`), or plain arrays: a list of `(weight, bias)` pairs, `weight` shaped
`(out, in)` as in `torch.nn.Linear`, with `activation=` for the hidden layers (the last is linear).
"""

from __future__ import annotations

import json
import math
import os
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from colcos import _onboard_c
from colcos._core import ColcosError

__all__ = ["Encoding", "Export", "ExportError", "encode_counts", "export_c"]

OBS_DIM = 17
MANIFEST_FORMAT = "colcos-onboard-policy/1"
ACT_DIM = 2
ACTIVATIONS = ("tanh", "relu", "sigmoid", "identity")
_TORCH_ACTIVATIONS = {"Tanh": "tanh", "ReLU": "relu", "Sigmoid": "sigmoid"}


class ExportError(ColcosError):
    """A policy, an argument or a calibration that cannot be exported to C (names what and why)."""


@dataclass(frozen=True)
class Encoding:
    """What the on-board encoding needs to know about the robot: the colour sensors' calibration
    (the scenario's `[sensor]`), the largest wheel speed (`robot.max_wheel_speed`) and the IR bumpers'
    count span (emitter on minus off at contact; 3000 on the digital twin, calibrate it on the rig).
    Defaults: the simulator's."""

    gamma: float = 2.2
    crosstalk: tuple[tuple[float, float, float], ...] = ((1.0, 0.08, 0.03), (0.06, 1.0, 0.10), (0.02, 0.12, 1.0))
    gain: float = 1500.0
    integration_ms: float = 24.0
    dark_counts: float = 30.0
    max_wheel_speed: float = 0.35
    bumper_span: float = 3000.0
    dt: float = 0.02

    @classmethod
    def from_scenario(cls, scenario: str | os.PathLike, **overrides: Any) -> Encoding:
        """The encoding of a scenario (TOML text, or the path of a `.toml` file): its `[sensor]`,
        `robot.max_wheel_speed` and `dt`, the simulator's defaults for what it leaves out."""
        text = _scenario_text(scenario)
        try:
            import tomllib
        except ImportError:  # Python 3.10
            try:
                import tomli as tomllib  # type: ignore[no-redef]
            except ImportError:
                raise ExportError(
                    "reading a scenario needs Python >= 3.11 (tomllib) or the tomli package; pass encoding=Encoding(...) instead"
                ) from None
        try:
            doc = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise ExportError(f"`scenario` is not valid TOML: {e}") from None
        sensor, robot = doc.get("sensor", {}), doc.get("robot", {})
        kw: dict[str, Any] = {
            k: sensor[k] for k in ("gamma", "crosstalk", "gain", "integration_ms", "dark_counts") if k in sensor
        }
        if "max_wheel_speed" in robot:
            kw["max_wheel_speed"] = robot["max_wheel_speed"]
        if "dt" in doc:
            kw["dt"] = doc["dt"]
        kw.update(overrides)
        unknown = sorted(set(kw) - set(cls.__dataclass_fields__))
        if unknown:
            raise ExportError(f"unknown encoding key `{unknown[0]}`: expected one of {', '.join(cls.__dataclass_fields__)}")
        if isinstance(kw.get("crosstalk"), list) and all(isinstance(r, list) for r in kw["crosstalk"]):
            kw["crosstalk"] = tuple(tuple(r) for r in kw["crosstalk"])
        return cls(**kw).checked()

    def checked(self) -> Encoding:
        """Itself, or an `ExportError` naming the first value that cannot be encoded."""
        for key, lo in (
            ("gamma", 0.0),
            ("gain", 0.0),
            ("integration_ms", 0.0),
            ("max_wheel_speed", 0.0),
            ("bumper_span", 0.0),
            ("dt", 0.0),
        ):
            v = getattr(self, key)
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v <= lo:
                raise ExportError(f"`{key}` = {v!r}: must be a finite number > 0")
        if not isinstance(self.dark_counts, (int, float)) or not math.isfinite(self.dark_counts) or self.dark_counts < 0:
            raise ExportError(f"`dark_counts` = {self.dark_counts!r}: must be a finite number >= 0")
        m = np.asarray(self.crosstalk, dtype=np.float64) if _is_numeric_nested(self.crosstalk) else None
        if m is None or m.shape != (3, 3) or not np.all(np.isfinite(m)):
            raise ExportError(f"`crosstalk` = {self.crosstalk!r}: must be a 3x3 matrix of finite numbers")
        if _invert3(m.astype(np.float32)) is None:
            raise ExportError(f"`crosstalk` = {self.crosstalk!r}: matrix is singular: the sensor could not be calibrated")
        return self

    def runtime_params(self) -> np.ndarray:
        """The exported C's runtime parameter block (`<PREFIX>_N_RUNTIME` f32, the layout in its header)
        for this encoding: what `<prefix>_default_params` fills and the host may rewrite with `PWP`."""
        f32 = np.float32
        out = [f32(self.max_wheel_speed), f32(1.0) / f32(self.max_wheel_speed), f32(self.bumper_span)]
        inverse = self.inverse()
        for _ in range(4):
            out += [f32(self.dark_counts)] * 3
            out += [f32(self.gain) * f32(self.integration_ms), f32(1.0) / f32(self.gamma)]
            out += list(inverse.ravel())
        return np.array(out, dtype=np.float32)

    def inverse(self) -> np.ndarray:
        """The crosstalk's inverse as the simulator computes it (f64 adjugate / det, rounded to f32)."""
        inv = _invert3(np.asarray(self.crosstalk, dtype=np.float32))
        assert inv is not None  # checked()
        return inv


@dataclass(frozen=True)
class Export:
    """What `export_c` wrote: the two files and the policy's size on the robot."""

    header: Path
    source: Path
    prefix: str
    layer_sizes: tuple[int, ...]
    activations: tuple[str, ...]
    n_params: int
    weight_bytes: int
    stack_bytes: int
    macs: int
    encoding: Encoding = field(repr=False)
    policy_hash: int = 0
    """The network's FNV-1a hash (`<PREFIX>_HASH`): what the host's `PRN` names."""
    manifest: Path | None = None
    """`<path>.json`: what the bridge and the digital twin read (`[rig] onboard`)."""


def export_c(
    policy: Any,
    path: str | os.PathLike,
    *,
    activation: str = "tanh",
    obs_norm: Any = None,
    obs_mean: Any = None,
    obs_var: Any = None,
    obs_eps: float = 1e-8,
    obs_clip: float | None = 10.0,
    scenario: str | os.PathLike | None = None,
    encoding: Encoding | None = None,
    prefix: str = "colcos_policy",
    max_weight_bytes: int | None = 48 * 1024,
    max_stack_bytes: int | None = 2048,
) -> Export:
    """Write `<path>.h` and `<path>.c` (`path` may end in `.c` or `.h`) for `policy`.

    policy: a torch `nn.Sequential` of `Linear` and `Tanh` / `ReLU` / `Sigmoid` / `Identity`, or a list
        of `(weight, bias)` array pairs (`weight` shaped `(out, in)`), whose hidden layers use
        `activation` (`"tanh"`, `"relu"`, `"sigmoid"` or `"identity"`) and whose last layer is linear.
        17 inputs (the colcos observation) and 2 outputs (left, right wheel, in [-1, 1] after a clamp).
    obs_norm / obs_mean, obs_var: the input z-score the policy was trained behind,
        `clamp((obs - mean) / sqrt(var + obs_eps), -obs_clip, obs_clip)`: either a module with `mean`
        and `var` (the PPO example's `RunningNorm`) or the two arrays; none for raw observations.
    scenario / encoding: the sensor calibration and largest wheel speed of the encoding (TOML text or
        a path, or an `Encoding`); the simulator's defaults when neither is given.
    prefix: the C names' prefix (`<prefix>_step`, ...). max_weight_bytes / max_stack_bytes: refuse a
        network that would not fit the robot (defaults leave 16 KB of the 64 KB flash to the firmware and
        most of the 12 KB SRAM to it); None to skip.
    """
    if not isinstance(prefix, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", prefix):
        raise ExportError(f"`prefix` = {prefix!r}: must be a C identifier")
    if encoding is not None and scenario is not None:
        raise ExportError("give `scenario` or `encoding`, not both")
    if encoding is not None and not isinstance(encoding, Encoding):
        raise ExportError(f"`encoding` is a {type(encoding).__name__}: expected colcos.onboard.Encoding")
    enc = (encoding or (Encoding.from_scenario(scenario) if scenario is not None else Encoding())).checked()
    layers = _layers(policy, activation)
    norm = _normaliser(obs_norm, obs_mean, obs_var, obs_eps, obs_clip)
    header_path, source_path = _paths(path)

    n_params = sum(w.size + b.size for w, b, _ in layers)
    weight_bytes = 4 * (n_params + (2 * OBS_DIM if norm is not None else 0))
    width = max([OBS_DIM] + [w.shape[0] for w, _, _ in layers])
    stack_bytes = 2 * 4 * width
    if max_weight_bytes is not None and weight_bytes > max_weight_bytes:
        raise ExportError(
            f"the policy's weights take {weight_bytes:,} bytes of flash, over max_weight_bytes = {max_weight_bytes:,} (the STM32F334 has 64 KB)"
        )
    if max_stack_bytes is not None and stack_bytes > max_stack_bytes:
        raise ExportError(
            f"the layer buffers take {stack_bytes:,} bytes of stack (widest layer {width}), over max_stack_bytes = {max_stack_bytes:,} (the STM32F334 has 12 KB of SRAM)"
        )

    acts = [a for _, _, a in layers]
    policy_hash = _policy_hash(layers, norm)
    runtime = enc.runtime_params()
    math_funcs = sorted({{"tanh": "tanhf", "sigmoid": "expf"}[a] for a in acts if a in ("tanh", "sigmoid")})
    f32 = np.float32
    params = {
        "prefix": prefix,
        "header_name": header_path.name,
        "source_name": source_path.name,
        "summary": " -> ".join([str(OBS_DIM)] + [f"{w.shape[0]} ({a})" for w, _, a in layers])
        + (", inputs z-scored" if norm is not None else ""),
        "n_params": n_params,
        "weight_bytes": weight_bytes,
        "stack_bytes": stack_bytes,
        "math_note": f" and <math.h> ({', '.join(math_funcs)})" if math_funcs else "",
        "uses_math": bool(math_funcs),
        "math_funcs": ", ".join(math_funcs),
        "max_wheel_speed": enc.max_wheel_speed,
        "dt_note": f"{enc.dt:g} s",
        "integration_ms": f"{enc.integration_ms:g}",
        "gamma": f"{enc.gamma:g}",
        "gain": f"{enc.gain:g}",
        "dark_counts": f"{enc.dark_counts:g}",
        "crosstalk_text": str([list(r) for r in enc.crosstalk]),
        "dark_f32": f32(enc.dark_counts),
        "scale_f32": f32(enc.gain) * f32(enc.integration_ms),
        "inv_gamma_f32": f32(1.0) / f32(enc.gamma),
        "inv_max_speed_f32": f32(1.0) / f32(enc.max_wheel_speed),
        "bumper_span": enc.bumper_span,
        "inverse": enc.inverse(),
        "layers": layers,
        "norm": norm,
        "hash_hex": f"0x{policy_hash:08x}",
        "n_runtime": len(runtime),
        "runtime_defaults": runtime,
    }
    header_path.write_text(_onboard_c.header(params))
    source_path.write_text(_onboard_c.source(params))
    manifest_path = header_path.with_suffix(".json")
    manifest = {
        "format": MANIFEST_FORMAT,
        "prefix": prefix,
        "hash": policy_hash,
        "source": source_path.name,
        "header": header_path.name,
        "layer_sizes": [OBS_DIM] + [int(w.shape[0]) for w, _, _ in layers],
        "activations": acts,
        "runtime_defaults": [float(v) for v in runtime],
        "encoding": {
            "gamma": enc.gamma,
            "crosstalk": [list(r) for r in enc.crosstalk],
            "gain": enc.gain,
            "integration_ms": enc.integration_ms,
            "dark_counts": enc.dark_counts,
            "max_wheel_speed": enc.max_wheel_speed,
            "bumper_span": enc.bumper_span,
            "dt": enc.dt,
        },
    }
    tmp = manifest_path.with_name(manifest_path.name + ".tmp")
    tmp.write_text(json.dumps(manifest, indent=2) + "\n")
    os.replace(tmp, manifest_path)
    return Export(
        header=header_path,
        source=source_path,
        prefix=prefix,
        layer_sizes=tuple([OBS_DIM] + [w.shape[0] for w, _, _ in layers]),
        activations=tuple(acts),
        n_params=n_params,
        weight_bytes=weight_bytes,
        stack_bytes=stack_bytes,
        macs=sum(w.size for w, _, _ in layers),
        encoding=enc,
        policy_hash=policy_hash,
        manifest=manifest_path,
    )


def encode_counts(colour: Any, ir_on: Any, ir_off: Any, last_command: Any, encoding: Encoding | None = None) -> np.ndarray:
    """The on-board encoding in numpy (what the exported `<prefix>_encode` computes), batched.

    colour: counts (..., 4, 3) in the telemetry's order (front, back, left, right) x (R, G, B);
    ir_on, ir_off: (..., 3) bumper counts; last_command: (..., 2) wheel speeds, m/s. Returns (..., 17)
    float32 (the C uses the simulator's exact `pow_unit` and agrees within a few f32 ulps).
    """
    enc = (encoding or Encoding()).checked()
    colour = np.asarray(colour)
    if colour.shape[-2:] != (4, 3):
        raise ExportError(f"`colour` has shape {colour.shape}: expected (..., 4, 3)")
    f32 = np.float32
    sig = (colour.astype(f32) - f32(enc.dark_counts)) / (f32(enc.gain) * f32(enc.integration_ms))
    inv = enc.inverse()
    light = inv[:, 0] * sig[..., 0:1] + inv[:, 1] * sig[..., 1:2] + inv[:, 2] * sig[..., 2:3]
    light = np.where(light > 0, np.minimum(light, f32(1.0)), f32(0.0)).astype(f32)
    value = np.where(colour == 65535, f32(1.0), np.power(light, f32(1.0) / f32(enc.gamma))).astype(f32)
    batch = colour.shape[:-2]
    out = np.zeros(batch + (OBS_DIM,), dtype=f32)
    for w, s in enumerate(_onboard_c.TELEMETRY_TO_SIM):
        out[..., 3 * s : 3 * s + 3] = value[..., w, :]
    on, off = np.asarray(ir_on, dtype=np.int64), np.asarray(ir_off, dtype=np.int64)
    out[..., 12:15] = np.minimum(np.maximum(on - off, 0).astype(f32) / f32(enc.bumper_span), f32(1.0))
    last = np.nan_to_num(np.asarray(last_command, dtype=f32), nan=0.0, posinf=0.0, neginf=0.0)
    out[..., 15:17] = np.clip(last * (f32(1.0) / f32(enc.max_wheel_speed)), -1, 1)
    return out


# ---- the policy as arrays ----


def _layers(policy: Any, activation: str) -> list[tuple[np.ndarray, np.ndarray, str]]:
    torch = sys.modules.get("torch")
    if torch is not None and isinstance(policy, torch.nn.Module):
        layers = _torch_layers(policy, torch)
    elif isinstance(policy, (list, tuple)):
        layers = _array_layers(policy, activation)
    else:
        raise ExportError(
            f"`policy` is a {type(policy).__module__}.{type(policy).__qualname__}: expected a torch nn.Sequential "
            "of Linear and activation modules, or a list of (weight, bias) array pairs"
        )
    if not layers:
        raise ExportError("`policy` has no Linear layer")
    for i, (w, _, _) in enumerate(layers):
        if i > 0 and w.shape[1] != layers[i - 1][0].shape[0]:
            raise ExportError(f"layer {i} takes {w.shape[1]} inputs but layer {i - 1} gives {layers[i - 1][0].shape[0]}")
    if layers[0][0].shape[1] != OBS_DIM:
        raise ExportError(
            f"the policy takes {layers[0][0].shape[1]} inputs: the on-board observation has {OBS_DIM} (colcos.observation_names())"
        )
    if layers[-1][0].shape[0] != ACT_DIM:
        raise ExportError(
            f"the policy gives {layers[-1][0].shape[0]} outputs: the on-board action is {ACT_DIM} wheel speeds (continuous actions)"
        )
    return layers


def _torch_layers(policy: Any, torch: Any) -> list[tuple[np.ndarray, np.ndarray, str]]:
    nn = torch.nn
    if not isinstance(policy, nn.Sequential):
        hint = " (pass its actor, e.g. model.pi, with obs_norm=model.obs_norm)" if hasattr(policy, "pi") else ""
        raise ExportError(f"`policy` is a torch {type(policy).__qualname__}, not an nn.Sequential{hint}")
    layers: list[list[Any]] = []
    for i, m in enumerate(_flatten(policy, nn)):
        if isinstance(m, nn.Linear):
            w = _array(m.weight, f"policy[{i}].weight")
            b = _array(m.bias, f"policy[{i}].bias") if m.bias is not None else np.zeros(w.shape[0], np.float32)
            layers.append([w, b, "identity"])
        elif isinstance(m, nn.Identity):
            continue
        elif type(m).__name__ in _TORCH_ACTIVATIONS and type(m).__module__.startswith("torch"):
            if not layers or layers[-1][2] != "identity":
                where = "before any Linear" if not layers else "right after another activation"
                raise ExportError(f"policy[{i}] is {type(m).__name__} {where}: expected Linear, activation, Linear, ...")
            layers[-1][2] = _TORCH_ACTIVATIONS[type(m).__name__]
        else:
            raise ExportError(f"policy[{i}] is {type(m).__qualname__}: supported are Linear, Tanh, ReLU, Sigmoid and Identity")
    return [(w, b, a) for w, b, a in layers]


def _flatten(seq: Any, nn: Any) -> list[Any]:
    out: list[Any] = []
    for m in seq:
        out.extend(_flatten(m, nn) if isinstance(m, nn.Sequential) else [m])
    return out


def _array_layers(policy: list | tuple, activation: str) -> list[tuple[np.ndarray, np.ndarray, str]]:
    if activation not in ACTIVATIONS:
        raise ExportError(f"`activation` = {activation!r}: expected one of {', '.join(ACTIVATIONS)}")
    layers = []
    for i, pair in enumerate(policy):
        if not isinstance(pair, (list, tuple)) or len(pair) != 2:
            raise ExportError(f"policy[{i}] is a {type(pair).__name__}: expected a (weight, bias) pair")
        w, b = _array(pair[0], f"policy[{i}] weight"), _array(pair[1], f"policy[{i}] bias")
        if w.ndim != 2:
            raise ExportError(f"policy[{i}] weight has shape {w.shape}: expected (out, in)")
        if b.shape != (w.shape[0],):
            raise ExportError(f"policy[{i}] bias has shape {b.shape}: expected ({w.shape[0]},) for a weight of shape {w.shape}")
        layers.append((w, b, activation if i < len(policy) - 1 else "identity"))
    return layers


def _array(x: Any, what: str) -> np.ndarray:
    """`x` (array-like or torch tensor) as a finite float32 array."""
    if hasattr(x, "detach"):
        x = x.detach().cpu().numpy()
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ExportError(f"{what} is a {type(x).__name__}: expected an array of numbers") from None
    with np.errstate(over="ignore"):
        a32 = a.astype(np.float32)
    if not np.all(np.isfinite(a32)):
        k = int(np.argmin(np.isfinite(a32).ravel()))
        raise ExportError(f"{what} holds {float(a.ravel()[k])!r} at flat index {k}: weights must be finite f32")
    return a32


def _normaliser(
    obs_norm: Any, mean: Any, var: Any, eps: float, clip: float | None
) -> tuple[np.ndarray, np.ndarray, float | None] | None:
    if obs_norm is not None:
        if mean is not None or var is not None:
            raise ExportError("give `obs_norm` or `obs_mean` and `obs_var`, not both")
        if not (hasattr(obs_norm, "mean") and hasattr(obs_norm, "var")):
            raise ExportError(f"`obs_norm` is a {type(obs_norm).__name__} without `mean` and `var`")
        mean, var = obs_norm.mean, obs_norm.var
    if mean is None and var is None:
        return None
    if mean is None or var is None:
        raise ExportError("`obs_mean` and `obs_var` go together")
    m, v = _array(mean, "obs_mean"), _array(var, "obs_var")
    for name, a in (("obs_mean", m), ("obs_var", v)):
        if a.shape != (OBS_DIM,):
            raise ExportError(f"`{name}` has shape {a.shape}: expected ({OBS_DIM},)")
    if np.any(v < 0):
        raise ExportError(f"`obs_var` holds {float(v.min())!r}: variances must be >= 0")
    if not isinstance(eps, (int, float)) or not eps > 0:
        raise ExportError(f"`obs_eps` = {eps!r}: must be > 0")
    if clip is not None and (not isinstance(clip, (int, float)) or not math.isfinite(clip) or clip <= 0):
        raise ExportError(f"`obs_clip` = {clip!r}: must be a finite number > 0, or None")
    # The example's RunningNorm computes sqrt(var + eps) in f32: the same rounding here.
    std = np.sqrt(v + np.float32(eps)).astype(np.float32)
    return m, std, (float(np.float32(clip)) if clip is not None else None)


# ---- helpers ----


def _policy_hash(layers: list[tuple[np.ndarray, np.ndarray, str]], norm: Any) -> int:
    """FNV-1a (32 bit) over the layer sizes, activations, f32 weights and normaliser."""
    h = 0x811C9DC5

    def feed(b: bytes) -> None:
        nonlocal h
        for byte in b:
            h = ((h ^ byte) * 0x01000193) & 0xFFFFFFFF

    for w, b, act in layers:
        feed(np.array(w.shape, dtype="<u4").tobytes())
        feed(act.encode() + b"\0")
        feed(w.astype("<f4").tobytes())
        feed(b.astype("<f4").tobytes())
    if norm is None:
        feed(b"raw")
    else:
        mean, std, clip = norm
        feed(b"norm" + mean.astype("<f4").tobytes() + std.astype("<f4").tobytes())
        feed(np.array([clip if clip is not None else 0.0], dtype="<f4").tobytes())
    return h


def _paths(path: Any) -> tuple[Path, Path]:
    if not isinstance(path, (str, os.PathLike)):
        raise ExportError(f"`path` is a {type(path).__name__}: expected a file path such as 'firmware/policy'")
    p = Path(path)
    if p.is_dir():
        raise ExportError(f"`path` = {str(p)!r} is a directory: give a file stem such as {str(p / 'policy')!r}")
    if p.suffix in (".c", ".h"):
        p = p.with_suffix("")
    p.parent.mkdir(parents=True, exist_ok=True)
    return p.with_name(p.name + ".h"), p.with_name(p.name + ".c")


def _scenario_text(scenario: Any) -> str:
    if isinstance(scenario, os.PathLike) or (isinstance(scenario, str) and "\n" not in scenario and scenario.endswith(".toml")):
        try:
            return Path(scenario).read_text()
        except OSError as e:
            raise ExportError(f"`scenario` = {str(scenario)!r}: cannot read it ({e.strerror})") from None
    if isinstance(scenario, str):
        return scenario
    raise ExportError(f"`scenario` is a {type(scenario).__name__}: expected TOML text or a path")


def _is_numeric_nested(x: Any) -> bool:
    try:
        np.asarray(x, dtype=np.float64)
        return True
    except (TypeError, ValueError):
        return False


def _invert3(m: np.ndarray) -> np.ndarray | None:
    """`colcos_sim::sensors::invert3`: the inverse in f64 (the same operations), rounded to f32."""
    a = [[float(m[r][c]) for c in range(3)] for r in range(3)]

    def cof(r: int, c: int) -> float:
        r1, r2, c1, c2 = (r + 1) % 3, (r + 2) % 3, (c + 1) % 3, (c + 2) % 3
        return a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]

    det = a[0][0] * cof(0, 0) + a[0][1] * cof(0, 1) + a[0][2] * cof(0, 2)
    if not math.isfinite(det) or abs(det) < 1e-9:
        return None
    return np.array([[cof(c, r) / det for c in range(3)] for r in range(3)], dtype=np.float32)
