"""The quick start's PPO minibatch step, eager against `--compile`, side by side in one run.

    python benches/ppo_step.py [--threads 2] [--reps 5]

One step = `ppo.Trainer`'s loss on 1,200 rows (a minibatch of the default recipe: 48,000 agent-steps
in 40 minibatches), backward, the gradient clip and Adam, as `Trainer._learn` makes it. Rows: torch's
defaults (Adam and the clip one tensor at a time), the eager step as `ppo.py` makes it (`foreach`: the
same bits), and the compiled one (`Config(compile=True)`: the loss through torch.compile, fused Adam).
Each figure is the median over `--reps` blocks of 100 steps, the rows taken in turn; the first
compiled steps (tracing, kernels) are done before timing. Needs torch.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples"))
import ppo  # noqa: E402
import torch  # noqa: E402
from colcos.vector import VecEnv  # noqa: E402

ROWS = 1200


def trainer(compiled: bool, torch_defaults: bool = False) -> ppo.Trainer:
    env = VecEnv(task="aggregation", num_envs=4, max_cycles=50, num_threads=1)
    t = ppo.Trainer(env, ppo.Config(own_critic=True, compile=compiled), seed=0)
    if torch_defaults:
        t.opt = torch.optim.Adam(t.model.parameters(), lr=t.cfg.lr, eps=1e-5)
    return t


def step(t: ppo.Trainer, batch: tuple[torch.Tensor, ...], foreach: bool) -> float:
    loss, ratio, log_ratio = t.loss(*batch, False)
    t.opt.zero_grad()
    loss.backward()
    if foreach:
        ppo.clip_gradients(t.model, t.cfg.clip_apart, t.cfg.grad_norm)
    else:  # torch's default on the CPU: one tensor at a time
        torch.nn.utils.clip_grad_norm_([*t.model.pi.parameters(), t.model.log_std], t.cfg.grad_norm, foreach=False)
        torch.nn.utils.clip_grad_norm_(t.model.v.parameters(), t.cfg.grad_norm, foreach=False)
    t.opt.step()
    with torch.no_grad():
        return float(((ratio - 1) - log_ratio).mean())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--threads", type=int, default=os.cpu_count() or 1, help="torch threads (the update's)")
    p.add_argument("--reps", type=int, default=5)
    args = p.parse_args()
    torch.set_num_threads(args.threads)
    rows = {"torch defaults": (trainer(False, torch_defaults=True), False),
            "eager (ppo.py)": (trainer(False), True),
            "compiled (--compile)": (trainer(True), True)}
    d, c = rows["eager (ppo.py)"][0].d, rows["eager (ppo.py)"][0].c
    g = torch.Generator().manual_seed(1)
    batch = (torch.randn(ROWS, d, generator=g), torch.randn(ROWS, 2, generator=g) * 0.3,
             -torch.rand(ROWS, generator=g) * 3, torch.randn(ROWS, generator=g), torch.randn(ROWS, c, generator=g),
             torch.randn(ROWS, generator=g))
    for t, foreach in rows.values():
        for _ in range(10):
            step(t, batch, foreach)
    ms: dict[str, list[float]] = {k: [] for k in rows}
    for _ in range(args.reps):
        for name, (t, foreach) in rows.items():
            t0 = time.perf_counter()
            for _ in range(100):
                step(t, batch, foreach)
            ms[name].append((time.perf_counter() - t0) * 10)
    base = statistics.median(ms["torch defaults"])
    print(f"PPO minibatch step, {ROWS} rows, torch on {args.threads} threads, medians of {args.reps} x 100 steps")
    for name, v in ms.items():
        print(f"  {name:22s} {statistics.median(v):6.2f} ms  ({base / statistics.median(v):4.2f}x torch defaults)")


if __name__ == "__main__":
    main()
