#!/usr/bin/env python3
"""The ColCOSPhi GUI's own NumPy/OpenCV pheromone model next to colcos' grid field, same work.

Peer (after the authors' VColCOSP_GUI, see shared/reference/peers.md): a H x W x 3 float field,
dt = 0.1 s; per channel: evaporation -(1/tau) Phi (tau = 8 / 200 / 300 s), diffusion by a normalised
Gaussian blur (kernel 71 / 51 / 51 px, sigma = size / 2, cv2.GaussianBlur) mixed in with the diffusion
factor (0.1 / 0.1 / 0.5), injection of filled discs (radii 100 / 20 / 4 px, factors 200 / 100.2 / 0.9)
at a robot position, and the display image clipped to 0..255 uint8.

Ours: `cargo run --release -p colcos-sim --example field_throughput -- --nx W --ny H --steps N --inject`
(three GridFields, dt = 0.1 s, the same variance of diffusion per step, a disc deposit per field per step).

Needs numpy and opencv-python-headless (pip install numpy opencv-python-headless); installs nothing.

    python3 benches/field_peer.py --nx 640 --ny 480 --steps 50
    python3 benches/field_peer.py --nx 3840 --ny 2160 --steps 5
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

try:
    import cv2
    import numpy as np
except ImportError as e:  # pragma: no cover
    sys.exit(f"field_peer.py needs numpy and opencv-python-headless ({e}); pip install numpy opencv-python-headless")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

TAU = (8.0, 200.0, 300.0)
KSIZE = (71, 51, 51)
DIFF = (0.1, 0.1, 0.5)
RADIUS = (100, 20, 4)
INJECT = (200.0, 100.2, 0.9)


def peer(nx, ny, steps, dt=0.1):
    field = np.zeros((ny, nx, 3), np.float32)
    field[ny // 2 - 50 : ny // 2 + 50, nx // 2 - 50 : nx // 2 + 50, :] = 100.0
    times = []
    for s in range(steps + 2):
        t0 = time.perf_counter()
        inj = np.zeros((ny, nx, 3), np.float32)
        pos = (int(0.2 * nx) + s, int(0.3 * ny))
        for c in range(3):
            layer = np.zeros((ny, nx), np.float32)
            cv2.circle(layer, pos, RADIUS[c], INJECT[c], -1)
            inj[:, :, c] = layer
        for c in range(3):
            phi = field[:, :, c]
            k = KSIZE[c]
            blurred = cv2.GaussianBlur(phi, (k, k), k / 2.0)
            phi = phi + DIFF[c] * (blurred - phi)  # diffusion
            phi = phi - dt / TAU[c] * phi  # evaporation
            phi = phi + inj[:, :, c] * dt  # injection
            field[:, :, c] = phi
        image = np.clip(field, 0, 255).astype(np.uint8)  # the screen image
        image.sum()
        if s >= 2:
            times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times)


def ours(nx, ny, steps, scheme):
    cmd = [
        "cargo", "run", "--quiet", "--release", "-p", "colcos-sim", "--example", "field_throughput", "--",
        "--nx", str(nx), "--ny", str(ny), "--steps", str(steps), "--dt", "0.1", "--inject", "--scheme", scheme,
    ]
    out = subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nx", type=int, default=640)
    ap.add_argument("--ny", type=int, default=480)
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--scheme", default="auto", help="auto | implicit | explicit (colcos side)")
    args = ap.parse_args()
    p = peer(args.nx, args.ny, args.steps)
    o = ours(args.nx, args.ny, args.steps, args.scheme)
    print(f"peer (NumPy {np.__version__} + OpenCV {cv2.__version__}), {args.nx}x{args.ny}x3, dt 0.1 s: "
          f"median {p:.2f} ms per step")
    print(f"colcos GridField x3 ({o['scheme']}, d dt/h^2 = {o['r']}), {args.nx}x{args.ny}: "
          f"median {o['median_ms']:.2f} ms per step ({o['threads']} threads)")
    print(f"ratio peer / colcos: {p / o['median_ms']:.2f}x")
    print(json.dumps({"nx": args.nx, "ny": args.ny, "steps": args.steps, "peer_ms": round(p, 3),
                      "colcos_ms": o["median_ms"], "ratio": round(p / o["median_ms"], 3)}))


if __name__ == "__main__":
    main()
