"""Does laying pheromone help agents that learn? PPO on `colony`, `coverage` and `alarm`, with and without
pheromone actions.

For each task and seed the same PPO (parameter sharing, the actor and critic of
`examples/train_aggregation.py`) trains twice with the same budget of agent-steps: once with its
deposit outputs sent to the env ("with"), once with them forced to 0 before every step ("without":
the ablation; the policy is the same network, its deposit outputs simply never lay anything). Then
learned-with, learned-without, the task's hand-written policy (`colcos.task_policies()`) and uniform
random actions run on the same seeded evaluation episodes. Prints a markdown table (mean return per
agent, with the spread across training seeds), writes `result.json` and, with matplotlib, one
learning-curve PNG per task.

    python examples/stigmergy.py --steps 2000000 --seeds 0 1 2 --out runs/stigmergy
    python examples/stigmergy.py --tasks coverage --steps 20000 --seeds 0 --episode 50   # a smoke run

Needs torch. The rewards are the tasks' own (docs/tasks.md); nothing is added here.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import pathlib
import time

import numpy as np
import torch
import torch.nn as nn

import colcos
from colcos.baselines import Baseline, RandomPolicy
from colcos.vector import VecEnv

TASKS = ("colony", "coverage", "alarm")


def _ppo_parts():
    """`examples/train_aggregation.py` as a module: its ActorCritic, RunningNorm and critic_input."""
    path = pathlib.Path(__file__).resolve().parent / "train_aggregation.py"
    spec = importlib.util.spec_from_file_location("train_aggregation", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


PPO = _ppo_parts()


def to_env(a: np.ndarray, lay: bool) -> np.ndarray:
    """A policy's raw output (..., 2 + D) as the env's action: wheels clipped to [-1, 1], deposit rates
    clipped to [0, 1], or forced to 0 without pheromone actions."""
    out = np.clip(a, -1.0, 1.0).astype(np.float32)
    out[..., 2:] = np.clip(out[..., 2:], 0.0, 1.0) if lay else 0.0
    return out


def train(task: str, lay: bool, seed: int, args: argparse.Namespace) -> tuple[nn.Module, list[tuple[int, float]]]:
    """PPO on `task` for `args.steps` agent-steps; the model and its learning curve (agent-steps, mean
    return of the last finished training episodes)."""
    torch.manual_seed(seed)
    env = VecEnv(task, num_envs=args.num_envs, seed=seed, max_cycles=args.episode, num_threads=args.threads)
    e, n, d = env.num_envs, env.num_agents, env.single_observation_space.shape[0]
    w = env.single_action_space.shape[0]
    c = d + env.state_space.shape[0] + n
    b = e * n
    model = PPO.ActorCritic(d, c, act_dim=w)
    opt = torch.optim.Adam(model.parameters(), lr=args.lr, eps=1e-5)
    gamma, lam, clip, epochs, minibatches = 0.98, 0.95, 0.2, 4, 4
    T = args.horizon
    bufs = {k: torch.zeros(T, b, *s) for k, s in (("obs", (d,)), ("cri", (c,)), ("act", (w,)))}
    logp_buf, rew_buf, done_buf, valid_buf = (torch.zeros(T, b) for _ in range(4))
    val_buf = torch.zeros(T + 1, b)
    ret_norm, disc_ret = PPO.RunningNorm(1), np.zeros(b)
    obs, infos = env.reset(seed=seed)
    state = infos["state"]
    prev_done = np.zeros(b, dtype=bool)
    ep_return, finished, curve, steps = np.zeros(b), [], [], 0
    while steps < args.steps:
        for t in range(T):
            o = torch.from_numpy(obs.reshape(b, d).copy())
            ci = PPO.critic_input(obs, state)
            with torch.no_grad():
                dist = model.dist(o)
                a = dist.sample()
                bufs["obs"][t], bufs["cri"][t], bufs["act"][t] = o, ci, a
                logp_buf[t], val_buf[t] = dist.log_prob(a).sum(-1), model.value(ci)
            obs, rew, term, trunc, infos = env.step(to_env(a.numpy().reshape(e, n, w), lay))
            state = infos["state"]
            r = rew.reshape(b).astype(np.float64)
            done = (term | trunc).reshape(b)
            # The step after a done one only resets the world: no transition of the policy's.
            valid_buf[t] = torch.from_numpy((~prev_done).astype(np.float32))
            disc_ret = disc_ret * gamma * (~prev_done) + r
            ret_norm.update(torch.from_numpy(disc_ret[~prev_done].astype(np.float32))[:, None])
            rew_buf[t] = torch.from_numpy(r.astype(np.float32))
            done_buf[t] = torch.from_numpy(done.astype(np.float32))
            ep_return += r
            if done.any():
                finished.extend(ep_return[done].tolist())
                ep_return[done] = 0.0
            prev_done = done.copy()
            steps += b
        with torch.no_grad():
            val_buf[T] = model.value(PPO.critic_input(obs, state))
        scale = float(torch.sqrt(ret_norm.var[0] + 1e-8))
        adv, last = torch.zeros(T, b), torch.zeros(b)
        for t in reversed(range(T)):
            nonterminal = 1.0 - done_buf[t]
            delta = rew_buf[t] / scale + gamma * val_buf[t + 1] * nonterminal - val_buf[t]
            last = delta + gamma * lam * nonterminal * last
            adv[t] = last
        ret = adv + val_buf[:T]
        keep = valid_buf.reshape(-1) > 0
        fo, fc, fa = (x.reshape(T * b, -1)[keep] for x in (bufs["obs"], bufs["cri"], bufs["act"]))
        fl, fadv, fret = (x.reshape(-1)[keep] for x in (logp_buf, adv, ret))
        model.obs_norm.update(fo)
        model.critic_norm.update(fc)
        fadv = (fadv - fadv.mean()) / (fadv.std() + 1e-8)
        m = fo.shape[0]
        size = max(1, m // minibatches)
        for _ in range(epochs):
            perm = torch.randperm(m)
            for k in range(0, m, size):
                idx = perm[k : k + size]
                dist = model.dist(fo[idx])
                ratio = (dist.log_prob(fa[idx]).sum(-1) - fl[idx]).exp()
                pg = -torch.min(ratio * fadv[idx], ratio.clamp(1 - clip, 1 + clip) * fadv[idx]).mean()
                vloss = 0.5 * (model.value(fc[idx]) - fret[idx]).pow(2).mean()
                opt.zero_grad()
                (pg + 0.5 * vloss).backward()
                nn.utils.clip_grad_norm_(model.parameters(), 0.5)
                opt.step()
        if finished:
            curve.append((steps, float(np.mean(finished[-b:]))))
    return model, curve


def evaluate(task: str, act, args: argparse.Namespace) -> float:
    """Mean return per agent over `args.eval_worlds` seeded episodes of `args.episode` steps; `act(venv)`
    gives the policy (observations -> actions)."""
    v = VecEnv(task, num_envs=args.eval_worlds, max_cycles=args.episode, num_threads=args.threads)
    policy = act(v)
    obs, _ = v.reset(seed=args.eval_seed)
    total = np.zeros((v.num_envs, v.num_agents))
    for _ in range(args.episode):
        obs, rew, _, _, _ = v.step(policy(obs))
        total += rew
    return float(total.mean())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tasks", nargs="+", default=list(TASKS), choices=TASKS)
    p.add_argument("--steps", type=int, default=2_000_000, help="training budget per run, agent-steps")
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    p.add_argument("--num-envs", type=int, default=32)
    p.add_argument("--horizon", type=int, default=64, help="steps per rollout")
    p.add_argument("--episode", type=int, default=1000, help="steps per episode, training and evaluation")
    p.add_argument("--threads", type=int, default=None)
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument("--eval-worlds", type=int, default=32)
    p.add_argument("--eval-seed", type=int, default=12345)
    p.add_argument("--out", default="runs/stigmergy")
    args = p.parse_args()
    torch.set_num_threads(1)
    os.makedirs(args.out, exist_ok=True)
    policies = {task: name for name, (task, _) in colcos.task_policies().items()}
    results: dict = {"args": vars(args), "tasks": {}}
    start = time.time()
    for task in args.tasks:
        row: dict = {"with": [], "without": [], "curves": {}}
        for lay in (True, False):
            key = "with" if lay else "without"
            for seed in args.seeds:
                model, curve = train(task, lay, seed, args)
                row["curves"][f"{key}/{seed}"] = curve
                row[key].append(evaluate(task, lambda v, m=model, lay=lay: lambda o: to_env(m.act(o), lay), args))
                print(f"{task} {key} seed {seed}: {row[key][-1]:.2f} ({time.time() - start:.0f} s)", flush=True)
        row["baseline"] = evaluate(task, lambda v: Baseline(v, policies[task]).act, args)
        row["random"] = evaluate(task, lambda v: RandomPolicy(v, seed=1).act, args)
        results["tasks"][task] = row
    print("\n| task | learned, with pheromone | learned, without | hand-written | random |")
    print("| --- | --- | --- | --- | --- |")
    for task, row in results["tasks"].items():
        cell = lambda xs: f"{np.mean(xs):.2f} ± {np.std(xs):.2f}"  # noqa: E731
        print(f"| `{task}` | {cell(row['with'])} | {cell(row['without'])} | {row['baseline']:.2f} | {row['random']:.2f} |")
    print(f"(mean return per agent over {args.eval_worlds} episodes of {args.episode} steps, seed {args.eval_seed};"
          f" ± the spread across training seeds {args.seeds}; {args.steps:,} agent-steps per run)")
    with open(os.path.join(args.out, "result.json"), "w") as f:
        json.dump(results, f, indent=1)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no PNG")
        return
    for task, row in results["tasks"].items():
        fig, ax = plt.subplots(figsize=(6, 3.5))
        for name, curve in row["curves"].items():
            if curve:
                xs, ys = zip(*curve)
                ax.plot(np.array(xs) / 1e6, ys, lw=1, color="C0" if name.startswith("with/") else "C1", label=name)
        ax.axhline(row["baseline"], color="green", ls=":", label="hand-written")
        ax.axhline(row["random"], color="grey", ls="--", label="random")
        ax.set_xlabel("agent-steps (millions)")
        ax.set_ylabel("mean return per agent")
        ax.set_title(f"colcos {task}: PPO with and without pheromone actions")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, f"{task}_curve.png"), dpi=120)
    print(f"saved {args.out}/result.json and the learning curves")


if __name__ == "__main__":
    main()
