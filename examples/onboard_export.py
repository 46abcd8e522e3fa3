"""Export the PPO example's trained actor to C for the Colias robot (`colcos.onboard.export_c`).

    python examples/train_aggregation.py --out runs/aggregation           # trains, writes policy.pt
    python examples/onboard_export.py --policy runs/aggregation/policy.pt --out firmware/policy

writes `firmware/policy.h` and `firmware/policy.c`: the observation encoding (raw colour and bumper
counts to the 17 inputs), the actor with its input normaliser, and the action decoding to wheel
speeds; the header's comment shows the firmware side. Without `--policy` it exports an untrained actor
of the same shape (random weights, numpy only: what `scripts/onboard_footprint.sh` measures, whose
sizes do not depend on the values). `--scenario` takes the sensor calibration and the largest wheel
speed from a scenario file instead of the simulator's defaults.
"""

from __future__ import annotations

import argparse

import numpy as np

from colcos.onboard import export_c

HIDDEN = 64  # the example's mlp(17, 2, hidden=64)


def actor_from_state_dict(path: str):
    """The actor's (weight, bias) pairs and its normaliser's mean and var from the example's policy.pt."""
    import torch

    state = torch.load(path, map_location="cpu", weights_only=True)
    keys = sorted({k.split(".")[1] for k in state if k.startswith("pi.") and k.endswith(".weight")}, key=int)
    if not keys:
        raise SystemExit(f"{path}: no actor (`pi.*.weight`) in it: is it the state_dict train_aggregation.py saves?")
    pairs = [(state[f"pi.{k}.weight"].numpy(), state[f"pi.{k}.bias"].numpy()) for k in keys]
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


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--policy", help="policy.pt of examples/train_aggregation.py (default: an untrained actor)")
    p.add_argument("--out", default="firmware/policy", help="file stem: writes OUT.h and OUT.c")
    p.add_argument("--scenario", help="scenario file whose [sensor] and robot.max_wheel_speed the encoding uses")
    p.add_argument("--prefix", default="colcos_policy", help="prefix of the C names")
    p.add_argument("--seed", type=int, default=0, help="seed of the untrained actor")
    args = p.parse_args()
    pairs, mean, var = actor_from_state_dict(args.policy) if args.policy else untrained_actor(args.seed)
    info = export_c(pairs, args.out, activation="tanh", obs_mean=mean, obs_var=var, scenario=args.scenario, prefix=args.prefix)
    print(f"wrote {info.header} and {info.source}")
    print(
        f"network {'-'.join(map(str, info.layer_sizes))} ({', '.join(info.activations)}): {info.n_params:,} parameters, "
        f"{info.weight_bytes:,} bytes of weights in flash, {info.stack_bytes:,} bytes of layer buffers on the stack, "
        f"{info.macs:,} multiply-adds per step"
    )


if __name__ == "__main__":
    main()
