"""PPO with parameter sharing over the batched colcos env: learn the follower of case II (aggregation).

All followers of all worlds share one policy; each (world, follower) pair is one sample stream. The
script prints the learning curve, compares the learned policy with a random one and with the paper's
hand-written follower on the same seeds, saves the curve as a PNG and the policy as a .pt file.

    python examples/train_aggregation.py --minutes 9 --out runs/aggregation

Needs torch (and matplotlib for the PNG).
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np
import torch
import torch.nn as nn

import colcos
from colcos.baselines import Baseline, RandomPolicy
from colcos.vector import VecEnv


class ActorCritic(nn.Module):
    def __init__(self, obs_dim: int, act_dim: int = 2, hidden: int = 64) -> None:
        super().__init__()
        self.pi = nn.Sequential(nn.Linear(obs_dim, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(), nn.Linear(hidden, act_dim))
        self.v = nn.Sequential(nn.Linear(obs_dim, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(), nn.Linear(hidden, 1))
        self.log_std = nn.Parameter(torch.full((act_dim,), -0.5))
        self.register_buffer("obs_mean", torch.zeros(obs_dim))
        self.register_buffer("obs_var", torch.ones(obs_dim))
        self.register_buffer("obs_count", torch.tensor(1e-4))

    def normalise(self, obs: torch.Tensor) -> torch.Tensor:
        return ((obs - self.obs_mean) / torch.sqrt(self.obs_var + 1e-8)).clamp(-10, 10)

    def update_stats(self, obs: torch.Tensor) -> None:
        m, v, n = obs.mean(0), obs.var(0, unbiased=False), obs.shape[0]
        delta, tot = m - self.obs_mean, self.obs_count + n
        self.obs_mean += delta * n / tot
        self.obs_var = (self.obs_var * self.obs_count + v * n + delta**2 * self.obs_count * n / tot) / tot
        self.obs_count = tot

    def dist(self, obs: torch.Tensor) -> torch.distributions.Normal:
        return torch.distributions.Normal(self.pi(self.normalise(obs)), self.log_std.exp())

    def value(self, obs: torch.Tensor) -> torch.Tensor:
        return self.v(self.normalise(obs)).squeeze(-1)

    @torch.no_grad()
    def act(self, obs: np.ndarray, deterministic: bool = True) -> np.ndarray:
        o = torch.from_numpy(obs.reshape(-1, obs.shape[-1]))
        a = self.pi(self.normalise(o)) if deterministic else self.dist(o).sample()
        return a.clamp(-1, 1).numpy().reshape(*obs.shape[:-1], -1).astype(np.float32)


def evaluate(policy_fn, task_kwargs: dict, worlds: int, steps: int, seed: int = 12345) -> float:
    """Mean undiscounted return per follower and episode over `worlds` episodes of `steps` steps."""
    v = VecEnv(num_envs=worlds, max_cycles=steps, **task_kwargs)
    act = policy_fn(v)
    obs, _ = v.reset(seed=seed)
    total = np.zeros((worlds, v.num_agents))
    for _ in range(steps):
        obs, rew, _, _, _ = v.step(act(obs))
        total += rew
    return float(total.mean())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--minutes", type=float, default=9.0, help="wall-clock training budget")
    p.add_argument("--num-envs", type=int, default=64)
    p.add_argument("--horizon", type=int, default=128, help="steps per rollout")
    p.add_argument("--episode", type=int, default=500, help="steps per episode (10 s)")
    p.add_argument("--threads", type=int, default=None)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="runs/aggregation")
    args = p.parse_args()
    torch.manual_seed(args.seed)
    torch.set_num_threads(1)
    os.makedirs(args.out, exist_ok=True)
    task_kwargs = {"task": "aggregation", "num_threads": args.threads}

    env = VecEnv(num_envs=args.num_envs, seed=args.seed, max_cycles=args.episode, **task_kwargs)
    e, n, d = env.num_envs, env.num_agents, env.single_observation_space.shape[0]
    b = e * n
    model = ActorCritic(d)
    opt = torch.optim.Adam(model.parameters(), lr=3e-4)
    gamma, lam, clip, epochs, minibatch = 0.99, 0.95, 0.2, 4, 4096
    T = args.horizon
    obs_buf = torch.zeros(T, b, d)
    act_buf = torch.zeros(T, b, 2)
    logp_buf = torch.zeros(T, b)
    rew_buf = torch.zeros(T, b)
    done_buf = torch.zeros(T, b)
    val_buf = torch.zeros(T + 1, b)

    obs, _ = env.reset(seed=args.seed)
    ep_return = np.zeros(b)
    finished: list[float] = []
    curve: list[tuple[float, int, float]] = []
    start = time.time()
    steps = 0
    update = 0
    print(f"training: {e} worlds x {n} followers, horizon {T}, budget {args.minutes:.1f} min")
    while time.time() - start < args.minutes * 60:
        for t in range(T):
            o = torch.from_numpy(obs.reshape(b, d).copy())
            with torch.no_grad():
                dist = model.dist(o)
                a = dist.sample()
                obs_buf[t], act_buf[t], logp_buf[t], val_buf[t] = o, a, dist.log_prob(a).sum(-1), model.value(o)
            obs, rew, term, trunc, _ = env.step(a.clamp(-1, 1).numpy().reshape(e, n, 2))
            r = rew.reshape(b)
            done = (term | trunc).reshape(b)
            rew_buf[t] = torch.from_numpy(r.copy())
            done_buf[t] = torch.from_numpy(done.astype(np.float32))
            ep_return += r
            if done.any():
                finished.extend(ep_return[done].tolist())
                ep_return[done] = 0.0
            steps += b
        # Next-step autoreset: the step after a done one only resets (its reward is 0, its transition is
        # masked by done_buf), so bootstrapping stops at episode ends.
        with torch.no_grad():
            val_buf[T] = model.value(torch.from_numpy(obs.reshape(b, d).copy()))
        adv = torch.zeros(T, b)
        last = torch.zeros(b)
        for t in reversed(range(T)):
            nonterminal = 1.0 - done_buf[t]
            delta = rew_buf[t] + gamma * val_buf[t + 1] * nonterminal - val_buf[t]
            last = delta + gamma * lam * nonterminal * last
            adv[t] = last
        ret = adv + val_buf[:T]
        flat = lambda x: x.reshape(T * b, *x.shape[2:])  # noqa: E731
        fo, fa, fl, fadv, fret = flat(obs_buf), flat(act_buf), flat(logp_buf), flat(adv), flat(ret)
        model.update_stats(fo)
        fadv = (fadv - fadv.mean()) / (fadv.std() + 1e-8)
        for _ in range(epochs):
            perm = torch.randperm(T * b)
            for k in range(0, T * b, minibatch):
                idx = perm[k : k + minibatch]
                dist = model.dist(fo[idx])
                logp = dist.log_prob(fa[idx]).sum(-1)
                ratio = (logp - fl[idx]).exp()
                pg = -torch.min(ratio * fadv[idx], ratio.clamp(1 - clip, 1 + clip) * fadv[idx]).mean()
                vloss = 0.5 * (model.value(fo[idx]) - fret[idx]).pow(2).mean()
                loss = pg + 0.5 * vloss - 0.001 * dist.entropy().sum(-1).mean()
                opt.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(model.parameters(), 0.5)
                opt.step()
        update += 1
        if finished:
            mean_ret = float(np.mean(finished[-b:]))
            curve.append((time.time() - start, steps, mean_ret))
            if update % 5 == 0:
                print(f"  {time.time() - start:6.0f} s  {steps:>10,d} agent-steps  mean episode return {mean_ret:8.2f}", flush=True)
    train_time = time.time() - start
    torch.save(model.state_dict(), os.path.join(args.out, "policy.pt"))

    worlds, horizon = 32, args.episode
    learned = evaluate(lambda v: lambda o: model.act(o), task_kwargs, worlds, horizon)
    rand = evaluate(lambda v: RandomPolicy(v, seed=1).act, task_kwargs, worlds, horizon)
    names = colcos.behaviours()
    follower = "aggregation_follower" if "aggregation_follower" in names else "avoid"
    hand = evaluate(lambda v: Baseline(v, follower).act, task_kwargs, worlds, horizon)
    result = {
        "train_seconds": round(train_time, 1),
        "agent_steps": steps,
        "agent_steps_per_second": round(steps / train_time),
        "eval_worlds": worlds,
        "eval_steps": horizon,
        "return_learned": round(learned, 2),
        "return_random": round(rand, 2),
        f"return_handwritten_{follower}": round(hand, 2),
    }
    print(json.dumps(result, indent=2))
    with open(os.path.join(args.out, "result.json"), "w") as f:
        json.dump({"result": result, "curve": curve}, f, indent=1)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.plot([c[1] / 1e6 for c in curve], [c[2] for c in curve], label="PPO (training episodes)")
        ax.axhline(rand, color="grey", ls="--", label="random")
        ax.axhline(hand, color="green", ls=":", label=f"hand-written ({follower})")
        ax.set_xlabel("agent-steps (millions)")
        ax.set_ylabel("mean return per follower")
        ax.set_title("colcos aggregation: PPO, parameter sharing")
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, "learning_curve.png"), dpi=120)
        print(f"saved {args.out}/learning_curve.png and {args.out}/policy.pt")
    except ImportError:
        print("matplotlib not installed: no PNG")


if __name__ == "__main__":
    main()
