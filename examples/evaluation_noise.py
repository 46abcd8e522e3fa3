"""How far apart two evaluations of one policy fall: a saved quick-start actor (`policy.pt` of
`examples/train_aggregation.py`) on its 32 evaluation episodes as saved and with its actor's weights
perturbed `--times` times by Gaussian noise of sd `--perturb` (a policy neither better nor worse whose
robots take other paths), and on `--holdout-worlds` held-out episodes with the standard error of their
mean, beside the paper's follower on both sets.

    python examples/evaluation_noise.py runs/quickstart/seed0/policy.pt
    python examples/evaluation_noise.py runs/quickstart/seed*/policy.pt --perturb 1e-4 --times 20

The spread of the perturbed evaluations is what a learning curve on those episodes moves by without
learning anything; the held-out mean is the policy's return within about two standard errors.
Prints one line per policy and writes nothing. Needs torch.
"""

from __future__ import annotations

import argparse
import copy
import os
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ppo
from colcos.baselines import Baseline


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("policies", nargs="+", help="policy.pt files of train_aggregation.py (actors of the 17 sensor values alone)")
    p.add_argument("--perturb", type=float, default=1e-3, help="sd of the noise added to every actor weight")
    p.add_argument("--times", type=int, default=10, help="perturbed copies evaluated")
    p.add_argument("--eval-worlds", type=int, default=32)
    p.add_argument("--eval-seed", type=int, default=12345)
    p.add_argument("--holdout-worlds", type=int, default=1024)
    p.add_argument("--holdout-seed", type=int, default=777)
    p.add_argument("--episode", type=int, default=500, help="steps per episode")
    args = p.parse_args()
    if args.perturb < 0 or args.times < 2 or args.eval_worlds < 1 or args.holdout_worlds < 2:
        p.error(f"--perturb ({args.perturb}) must be >= 0, --times ({args.times}) and --holdout-worlds "
                f"({args.holdout_worlds}) at least 2, --eval-worlds ({args.eval_worlds}) at least 1")  # fmt: skip
    missing = [f for f in args.policies if not os.path.isfile(f)]
    if missing:
        p.error(f"no such policy file: {', '.join(missing)}")
    torch.set_num_threads(1)
    torch.set_grad_enabled(False)
    kw = {"task": "aggregation"}

    def returns(policy, worlds: int, seed: int) -> np.ndarray:
        return np.array(ppo.episode_returns(policy, kw, worlds, args.episode, seed))

    def line(name: str, evaluation: float, held: np.ndarray, extra: str = "") -> None:
        h = ppo.mean_and_se(held)
        print(f"{name}: {args.eval_worlds} evaluation episodes {evaluation:.1f}{extra};"
              f" {len(held)} held-out episodes {h['mean']:.1f} ± {h['se']:.1f} (se)", flush=True)  # fmt: skip

    follower = lambda v: Baseline(v, "aggregation_follower").act
    line("paper's follower", returns(follower, args.eval_worlds, args.eval_seed).mean(),
         returns(follower, args.holdout_worlds, args.holdout_seed))  # fmt: skip
    for path in args.policies:
        model = ppo.load_model(path, 17)
        if model.agents:
            p.error(f"{path}: an actor with {model.pi[0].in_features} inputs (agent ids or a history); this script"
                    " evaluates actors that read the 17 sensor values alone")  # fmt: skip
        evaluation = returns(lambda v: model.policy(), args.eval_worlds, args.eval_seed).mean()
        perturbed = []
        for k in range(args.times):
            noisy = copy.deepcopy(model)
            g = torch.Generator().manual_seed(k)
            for w in noisy.pi.parameters():
                w.add_(torch.randn(w.shape, generator=g) * args.perturb)
            perturbed.append(returns(lambda v: noisy.policy(), args.eval_worlds, args.eval_seed).mean())
        q = np.array(perturbed)
        extra = (f" (perturbed by {args.perturb:g}, {args.times} times: sd {q.std(ddof=1):.1f},"
                 f" {q.min():.1f} to {q.max():.1f})")  # fmt: skip
        line(path, evaluation, returns(lambda v: model.policy(), args.holdout_worlds, args.holdout_seed), extra)


if __name__ == "__main__":
    main()
