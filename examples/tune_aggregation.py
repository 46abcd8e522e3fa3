"""A training sweep with Ray Tune over the batched colcos env: learning rate x reward weight.

Each trial trains a linear tanh policy for the followers of the `aggregation` task (shared by every
follower, 17 sensor values in, two wheel commands out) with evolution strategies: every world of one
`colcos.vector.VecEnv` plays its own antithetic perturbation of the parameters, so one batched rollout
scores the whole population. Trials differ by the ES learning rate and by the task's
`progress_weight` (the reward's term for driving up the leader's trail); every trial is scored with the
task's *default* reward on fixed evaluation seeds, so trials trained on different rewards are compared
on the same footing. numpy only: it runs in the environment that has Ray.

    python examples/tune_aggregation.py                          # 2 x 3 trials, ~2 min on 2 cores
    python examples/tune_aggregation.py --lr 0.05 --weights 0.5,2 --iterations 3 --steps 40   # seconds

With `ray.init(address="auto")` (`--address auto`) the trials run on a Ray cluster (docs/sweeps.md).
"""

from __future__ import annotations

import argparse
import os
import tempfile
from typing import Any

import numpy as np
import ray
from ray import tune

from colcos.vector import VecEnv


def act(params: np.ndarray, obs: np.ndarray) -> np.ndarray:
    """Wheel commands (E, N, 2) from observations (E, N, D) and per-world parameters (E, 2, D + 1)."""
    w, b = params[:, :, :-1], params[:, :, -1]
    return np.tanh(np.einsum("ekd,end->enk", w, obs) + b[:, None, :]).astype(np.float32)


def returns(env: VecEnv, params: np.ndarray, steps: int, seed: int) -> np.ndarray:
    """Each world's return per follower over `steps` steps from a reset with `seed`."""
    obs, _ = env.reset(seed=seed)
    total = np.zeros(env.num_envs)
    for _ in range(steps):
        obs, rewards, _, _, _ = env.step(act(params, obs))
        total += rewards.sum(axis=1)
    return total / env.num_agents


def train(config: dict[str, Any]) -> None:
    """One trial: `iterations` ES updates, each reported to Tune with the default-reward score."""
    pairs, steps = int(config["pairs"]), int(config["steps"])
    common = dict(task="aggregation", max_cycles=steps, num_threads=1)
    env = VecEnv(num_envs=2 * pairs, seed=config["seed"], progress_weight=config["progress_weight"], **common)
    judge = VecEnv(num_envs=4, seed=10_000, **common)
    rng = np.random.default_rng(config["seed"])
    dim = env.single_observation_space.shape[0]
    theta = np.zeros((2, dim + 1))
    sigma = 0.1
    for it in range(int(config["iterations"])):
        eps = rng.standard_normal((pairs, 2, dim + 1))
        population = theta[None] + sigma * np.concatenate([eps, -eps])
        r = returns(env, population, steps, seed=config["seed"] * 1000 + it)
        advantage = r[:pairs] - r[pairs:]
        scale = advantage.std() + 1e-8
        theta += config["lr"] / (2 * pairs * sigma) * np.einsum("p,pkd->kd", advantage / scale, eps)
        score = returns(judge, np.broadcast_to(theta, (judge.num_envs, *theta.shape)).copy(), steps, seed=10_000)
        tune.report({"score": float(score.mean()), "train_return": float(r.mean()), "iteration": it + 1})
    env.close()
    judge.close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lr", default="0.02,0.05", help="ES learning rates, comma-separated")
    ap.add_argument("--weights", default="0.5,1,2", help="the task's progress_weight values, comma-separated")
    ap.add_argument("--iterations", type=int, default=8, help="ES updates per trial")
    ap.add_argument("--pairs", type=int, default=8, help="antithetic pairs per update (2x worlds)")
    ap.add_argument("--steps", type=int, default=100, help="steps per rollout (20 ms each)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--address", default=None, help="a Ray cluster's address (default: start one here)")
    ap.add_argument("--storage", default=None, help="Tune's results directory (default: a temporary one)")
    args = ap.parse_args()

    def floats(text: str, name: str) -> list[float]:
        try:
            values = [float(v) for v in text.split(",")]
        except ValueError:
            ap.error(f"--{name} {text!r}: expected comma-separated numbers")
        if not values or not all(np.isfinite(values)):
            ap.error(f"--{name} {text!r}: expected finite numbers")
        return values

    for name, value in (("iterations", args.iterations), ("pairs", args.pairs), ("steps", args.steps)):
        if value < 1:
            ap.error(f"--{name} {value}: must be at least 1")
    space = {
        "lr": tune.grid_search(floats(args.lr, "lr")),
        "progress_weight": tune.grid_search(floats(args.weights, "weights")),
        "iterations": args.iterations,
        "pairs": args.pairs,
        "steps": args.steps,
        "seed": args.seed,
    }
    ray.init(address=args.address, include_dashboard=False, log_to_driver=False)
    storage = args.storage or tempfile.mkdtemp(prefix="colcos-tune-")
    tuner = tune.Tuner(
        tune.with_resources(train, {"cpu": 1}),
        param_space=space,
        tune_config=tune.TuneConfig(metric="score", mode="max"),
        run_config=tune.RunConfig(name="tune_aggregation", storage_path=os.path.abspath(storage), verbose=0),
    )
    results = tuner.fit()
    frame = results.get_dataframe()
    columns = ["config/lr", "config/progress_weight", "score", "train_return", "iteration"]
    print(frame[columns].sort_values("score", ascending=False).to_string(index=False))
    if results.errors:
        raise SystemExit(f"{len(results.errors)} trial(s) failed: {results.errors[0]}")
    best = results.get_best_result()
    print(f"best: lr={best.config['lr']} progress_weight={best.config['progress_weight']} "
          f"score {best.metrics['score']:.2f} (default reward per follower, evaluation seeds)")
    ray.shutdown()


if __name__ == "__main__":
    main()
