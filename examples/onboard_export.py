"""Export the PPO example's trained actor to C for the Colias robot (`colcos.onboard.export_c`).

    python examples/train_aggregation.py --out runs/aggregation           # trains, writes policy.pt
    python examples/onboard_export.py --policy runs/aggregation/policy.pt --out firmware/policy

writes `firmware/policy.h` and `firmware/policy.c`: the observation encoding (raw colour and bumper
counts to the 17 inputs), the actor with its input normaliser, and the action decoding to wheel
speeds; the header's comment shows the firmware side. Without `--policy` it exports an untrained actor
of the same shape (random weights, numpy only: what `scripts/onboard_footprint.sh` measures, whose
sizes do not depend on the values). `--scenario` takes the sensor calibration and the largest wheel
speed from a scenario file instead of the simulator's defaults. `--check N` compiles the C with the
host's `cc` and drives N episodes of the `aggregation` task with it and with the same network in numpy
(same seeds): the returns and the largest action difference, a check before flashing. `--twin S` runs
the exported C on the robots of the digital twin for S seconds: a scenario naming the export's manifest
in `[rig] onboard`, `colcos twin` and `colcos bridge` over loopback (the bridge uploads each robot's
parameters, starts the policy and sends only stops; the twin compiles the C and runs it on each
robot's own readings of the screen the bridge shows), then what the robots did.

    python examples/onboard_export.py --policy runs/aggregation/policy.pt --out firmware/policy --twin 20
"""

from __future__ import annotations

import argparse
import csv
import ctypes
import json
import re
import shutil
import socket
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import colcos

from colcos.onboard import export_c

HIDDEN = 64  # the example's mlp(17, 2, hidden=64)


def actor_from_state_dict(path: str):
    """The actor's (weight, bias) pairs and its normaliser's mean and var from the example's policy.pt."""
    import torch

    if not Path(path).is_file():
        raise SystemExit(f"--policy {path}: no such file (train_aggregation.py writes OUT/policy.pt)")
    state = torch.load(path, map_location="cpu", weights_only=True)
    keys = sorted(
        {
            k.split(".")[1]
            for k in state
            if k.startswith("pi.") and k.endswith(".weight")
        },
        key=int,
    )
    if not keys:
        raise SystemExit(
            f"{path}: no actor (`pi.*.weight`) in it: is it the state_dict train_aggregation.py saves?"
        )
    pairs = [
        (state[f"pi.{k}.weight"].numpy(), state[f"pi.{k}.bias"].numpy()) for k in keys
    ]
    if pairs[-1][0].shape[0] != state["log_std"].shape[0]:
        raise SystemExit(
            f"{path}: a tanh actor (train_aggregation.py --tanh) is not exported: the C clips the mean"
        )
    return pairs, state["obs_norm.mean"].numpy(), state["obs_norm.var"].numpy()


def untrained_actor(seed: int):
    """An actor of the example's shape with random weights, and a unit normaliser."""
    rng = np.random.default_rng(seed)
    sizes = [17, HIDDEN, HIDDEN, 2]
    pairs = [
        (rng.uniform(-1, 1, (o, i)) / np.sqrt(i), rng.uniform(-1, 1, o) / np.sqrt(i))
        for i, o in zip(sizes, sizes[1:], strict=False)
    ]
    return pairs, np.zeros(17), np.ones(17)


def numpy_act(pairs, mean, var, obs: np.ndarray) -> np.ndarray:
    """The network in numpy (f64), as the example's ActorCritic.act computes it."""
    h = np.clip(
        (obs - mean) / np.sqrt(np.asarray(var, np.float32) + np.float32(1e-8)), -10, 10
    )
    for k, (w, b) in enumerate(pairs):
        h = h @ np.asarray(w, np.float64).T + b
        h = np.tanh(h) if k < len(pairs) - 1 else h
    return np.clip(h, -1, 1).astype(np.float32)


def c_act_fn(info):
    """`<prefix>_act` of the exported C, compiled with the host's cc, over a batch of observations."""
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        raise SystemExit("--check needs a C compiler (cc, gcc or clang) on PATH")
    so = Path(tempfile.mkdtemp(prefix="colcos-onboard-")) / "policy.so"
    subprocess.run(
        [
            cc,
            "-std=c99",
            "-O2",
            "-shared",
            "-fPIC",
            str(info.source),
            "-o",
            str(so),
            "-lm",
        ],
        check=True,
    )
    fn = getattr(ctypes.CDLL(str(so)), f"{info.prefix}_act")
    f32p = ctypes.POINTER(ctypes.c_float)
    fn.argtypes = [f32p, f32p]

    def act(obs: np.ndarray) -> np.ndarray:
        obs = np.ascontiguousarray(obs, dtype=np.float32)
        out = np.zeros((len(obs), 2), dtype=np.float32)
        for i in range(len(obs)):
            fn(obs[i].ctypes.data_as(f32p), out[i].ctypes.data_as(f32p))
        return out

    return act


def episode_returns(
    act, episodes: int, scenario: str | None
) -> tuple[float, list[np.ndarray]]:
    """Mean return per agent over `episodes` seeded aggregation episodes driven by `act`, and the
    observations seen."""
    env = colcos.parallel_env(
        task="aggregation",
        max_cycles=500,
        **({"scenario": scenario} if scenario else {}),
    )
    total, seen = 0.0, []
    for ep in range(episodes):
        obs, _ = env.reset(seed=1000 + ep)
        while env.agents:
            batch = np.stack([obs[a] for a in env.agents])
            seen.append(batch)
            a = act(batch)
            obs, rew, *_ = env.step({name: a[k] for k, name in enumerate(env.agents)})
            total += sum(rew.values()) / len(rew)
    env.close()
    return total / episodes, seen


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_on_twin(info, seconds: float, scenario: str | None, colcos_bin: str) -> None:
    """The exported C on the twin's robots, driven by `colcos bridge` with `[rig] onboard`."""
    binary = shutil.which(colcos_bin) or (colcos_bin if Path(colcos_bin).is_file() else None)
    if binary is None:
        raise SystemExit(f"--colcos {colcos_bin}: no such program (cargo build --release builds target/release/colcos)")
    text = Path(scenario).read_text() if scenario else colcos.default_scenario("aggregation")
    line = f'onboard = "{info.manifest.name}"'
    if re.search(r"^\[rig\]\s*$", text, re.M):
        text = re.sub(r"^\[rig\]\s*$", f"[rig]\n{line}", text, count=1, flags=re.M)
    else:
        text += f"\n[rig]\n{line}\n"
    work = info.manifest.parent
    sc = work / "twin_scenario.toml"
    sc.write_text(text)
    out = work / "twin_run"
    tracker, robots, frames = free_port(), free_port(), free_port()
    twin = subprocess.Popen(
        [binary, "twin", str(sc), "--tracker", f"127.0.0.1:{tracker}", "--robots", f"udp://127.0.0.1:{robots}",
         "--frames", f"127.0.0.1:{frames}", "--duration", str(seconds + 5)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )
    try:
        deadline = time.monotonic() + 30  # the twin compiles the C first
        while True:
            try:
                socket.create_connection(("127.0.0.1", tracker), timeout=0.2).close()
                break
            except OSError:
                if twin.poll() is not None or time.monotonic() > deadline:
                    raise SystemExit(f"the twin did not start:\n{twin.communicate()[0]}") from None
                time.sleep(0.1)
        bridge = subprocess.run(
            [binary, "bridge", str(sc), "--tracker", f"swarmcon://127.0.0.1:{tracker}", "--robots",
             f"udp://127.0.0.1:{robots}", "--frames", f"127.0.0.1:{frames}", "--duration", str(seconds),
             "--out", str(out)],
            capture_output=True, text=True,
        )
        if bridge.returncode != 0:
            raise SystemExit(f"colcos bridge failed:\n{bridge.stderr}")
    finally:
        twin.terminate()
        twin.wait()
    rows = list(csv.DictReader((out / "trajectory.csv").open()))
    robots_n = 1 + max(int(r["robot"]) for r in rows)
    ticks = sorted({int(r["tick"]) for r in rows})
    at = {(int(r["tick"]), int(r["robot"])): (float(r["x"]), float(r["y"])) for r in rows}
    seen = [t for t in ticks if all(at.get((t, i), (0.0, 0.0)) != (0.0, 0.0) for i in range(robots_n))]
    first, last = np.array([at[(seen[0], i)] for i in range(robots_n)]), np.array([at[(seen[-1], i)] for i in range(robots_n)])

    def spread(p: np.ndarray) -> float:
        d = np.linalg.norm(p[:, None] - p[None], axis=-1)
        return float(d.sum() / (robots_n * (robots_n - 1)))

    summary = json.loads((out / "summary.json").read_text())
    print(
        f"on the twin, {robots_n} robots ran the C on board for {seconds:g} s: moved {np.linalg.norm(last - first, axis=1).mean():.3f} m "
        f"each on average (start to end), mean distance between robots {spread(first):.3f} -> {spread(last):.3f} m; "
        f"the bridge sent {summary.get('commands_sent', '?')} frames (parameters, starts, telemetry requests, stops), "
        f"safety stops: {summary.get('stops') or 'none'}; run in {out}"
    )


def main() -> None:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument(
        "--policy",
        help="policy.pt of examples/train_aggregation.py (default: an untrained actor)",
    )
    p.add_argument(
        "--out", default="firmware/policy", help="file stem: writes OUT.h and OUT.c"
    )
    p.add_argument(
        "--scenario",
        help="scenario file whose [sensor] and robot.max_wheel_speed the encoding uses",
    )
    p.add_argument("--prefix", default="colcos_policy", help="prefix of the C names")
    p.add_argument("--seed", type=int, default=0, help="seed of the untrained actor")
    p.add_argument(
        "--check",
        type=int,
        default=0,
        metavar="N",
        help="run N aggregation episodes with the C and with numpy",
    )
    p.add_argument("--twin", type=float, default=0.0, metavar="S", help="run the C on the digital twin's robots for S s")
    p.add_argument("--colcos", default="target/release/colcos", help="the colcos program (for --twin)")
    args = p.parse_args()
    pairs, mean, var = (
        actor_from_state_dict(args.policy)
        if args.policy
        else untrained_actor(args.seed)
    )
    info = export_c(
        pairs,
        args.out,
        activation="tanh",
        obs_mean=mean,
        obs_var=var,
        scenario=args.scenario,
        prefix=args.prefix,
    )
    print(f"wrote {info.header}, {info.source} and {info.manifest}")
    print(
        f"network {'-'.join(map(str, info.layer_sizes))} ({', '.join(info.activations)}): {info.n_params:,} parameters, "
        f"{info.weight_bytes:,} bytes of weights in flash, {info.stack_bytes:,} bytes of layer buffers on the stack, "
        f"{info.macs:,} multiply-adds per step"
    )
    if args.check > 0:
        c_act = c_act_fn(info)
        ret_c, seen = episode_returns(c_act, args.check, args.scenario)
        ret_np, _ = episode_returns(
            lambda o: numpy_act(pairs, mean, var, o), args.check, args.scenario
        )
        obs = np.concatenate(seen)
        diff = float(np.abs(c_act(obs) - numpy_act(pairs, mean, var, obs)).max())
        print(
            f"check over {args.check} episodes of 500 steps: mean return per agent, C {ret_c:.2f}, numpy {ret_np:.2f}; "
            f"largest action difference on the C run's {len(obs):,} observations {diff:.3g}"
        )
    if args.twin > 0:
        run_on_twin(info, args.twin, args.scenario, args.colcos)


if __name__ == "__main__":
    main()
