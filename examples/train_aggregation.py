"""PPO with parameter sharing over the batched colcos env: learn the follower of case II (aggregation).

All followers of all worlds share one policy; each (world, follower) pair is one sample stream. The
actor sees only the follower's own 17 sensor values; the critic (used only in training) also sees the
global state (every robot's pose, the episode's elapsed fraction) and which follower it is. The script
prints the learning curve, compares the learned policy with a random one and with the paper's
hand-written follower on the same seeds and episodes, saves the curve as a PNG, the policy as a .pt
file and a JSON summary.

    python examples/train_aggregation.py --minutes 8 --out runs/aggregation

Needs torch (and matplotlib for the PNG). The reward is the env's (`aggregation` task, see
docs/python.md "Training"); nothing is added here.
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


class RunningNorm(nn.Module):
    """Running mean / variance of the inputs (Chan et al. parallel update), applied as a z-score."""

    def __init__(self, dim: int) -> None:
        super().__init__()
        self.register_buffer("mean", torch.zeros(dim))
        self.register_buffer("var", torch.ones(dim))
        self.register_buffer("count", torch.tensor(1e-4))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return ((x - self.mean) / torch.sqrt(self.var + 1e-8)).clamp(-10, 10)

    @torch.no_grad()
    def update(self, x: torch.Tensor) -> None:
        if x.shape[0] == 0:
            return
        m, v, n = x.mean(0), x.var(0, unbiased=False), x.shape[0]
        delta, tot = m - self.mean, self.count + n
        self.mean += delta * n / tot
        self.var = (self.var * self.count + v * n + delta**2 * self.count * n / tot) / tot
        self.count = tot


def mlp(i: int, o: int, hidden: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(i, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(), nn.Linear(hidden, o))


class ActorCritic(nn.Module):
    """Gaussian actor on the agent's own observation; critic on observation + global state + agent id."""

    def __init__(self, obs_dim: int, critic_dim: int, act_dim: int = 2, hidden: int = 64) -> None:
        super().__init__()
        self.pi = mlp(obs_dim, act_dim, hidden)
        self.v = mlp(critic_dim, 1, hidden)
        self.log_std = nn.Parameter(torch.full((act_dim,), -0.5))
        self.obs_norm = RunningNorm(obs_dim)
        self.critic_norm = RunningNorm(critic_dim)
        with torch.no_grad():  # small initial actions: the policy starts near "stand still", not saturated
            self.pi[-1].weight.mul_(0.01)
            self.pi[-1].bias.zero_()

    def dist(self, obs: torch.Tensor) -> torch.distributions.Normal:
        return torch.distributions.Normal(self.pi(self.obs_norm(obs)), self.log_std.exp())

    def value(self, critic_in: torch.Tensor) -> torch.Tensor:
        return self.v(self.critic_norm(critic_in)).squeeze(-1)

    @torch.no_grad()
    def act(self, obs: np.ndarray) -> np.ndarray:
        """Deterministic action (the mean, clipped to [-1, 1]) for observations of shape (..., obs_dim)."""
        o = torch.from_numpy(np.ascontiguousarray(obs, dtype=np.float32).reshape(-1, obs.shape[-1]))
        a = self.pi(self.obs_norm(o)).clamp(-1, 1)
        return a.numpy().reshape(*obs.shape[:-1], -1).astype(np.float32)


def critic_input(obs: np.ndarray, state: np.ndarray) -> torch.Tensor:
    """(E, N, obs) and (E, S) -> (E * N, obs + S + N): own observation, global state, one-hot agent id."""
    e, n, _ = obs.shape
    s = np.broadcast_to(state[:, None, :], (e, n, state.shape[-1]))
    ids = np.broadcast_to(np.eye(n, dtype=np.float32)[None], (e, n, n))
    return torch.from_numpy(np.concatenate([obs, s, ids], axis=-1).reshape(e * n, -1))


def evaluate(policy_fn, task_kwargs: dict, worlds: int, steps: int, seed: int) -> float:
    """Mean undiscounted return per follower over `worlds` episodes of `steps` steps (seeded)."""
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
    p.add_argument("--minutes", type=float, default=8.0, help="wall-clock training budget (evaluation adds ~0.5 min)")
    p.add_argument("--num-envs", type=int, default=32)
    p.add_argument("--horizon", type=int, default=64, help="steps per rollout")
    p.add_argument("--episode", type=int, default=500, help="steps per episode (10 s)")
    p.add_argument("--threads", type=int, default=None, help="env worker threads (default: one per core)")
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument("--eval-worlds", type=int, default=32)
    p.add_argument("--eval-seed", type=int, default=12345)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="runs/aggregation")
    p.add_argument("--scenario", default=None, help="scenario file for training and evaluation (e.g. with a [randomize] section)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="numeric task parameter for training and evaluation, e.g. progress_weight=0 (repeatable)")
    args = p.parse_args()
    torch.manual_seed(args.seed)
    torch.set_num_threads(1)
    os.makedirs(args.out, exist_ok=True)
    task_kwargs = {"task": "aggregation", "num_threads": args.threads}
    if args.scenario:
        task_kwargs["scenario"] = args.scenario
    for kv in args.param:
        key, value = kv.split("=", 1)
        task_kwargs[key] = float(value)

    env = VecEnv(num_envs=args.num_envs, seed=args.seed, max_cycles=args.episode, **task_kwargs)
    e, n, d = env.num_envs, env.num_agents, env.single_observation_space.shape[0]
    c = d + env.state_space.shape[0] + n
    b = e * n
    model = ActorCritic(d, c)
    opt = torch.optim.Adam(model.parameters(), lr=args.lr, eps=1e-5)
    gamma, lam, clip, epochs, minibatches, ent_coef = 0.98, 0.95, 0.2, 4, 4, 0.0
    T = args.horizon
    obs_buf = torch.zeros(T, b, d)
    cri_buf = torch.zeros(T, b, c)
    act_buf = torch.zeros(T, b, 2)
    logp_buf = torch.zeros(T, b)
    rew_buf = torch.zeros(T, b)
    done_buf = torch.zeros(T, b)
    valid_buf = torch.zeros(T, b)
    val_buf = torch.zeros(T + 1, b)
    # Rewards are divided by a running std of the discounted return, so that the critic's targets stay
    # O(1) whatever the reward's scale (a per-step -0.4 alone gives discounted returns near -20).
    ret_norm = RunningNorm(1)
    disc_ret = np.zeros(b)

    obs, infos = env.reset(seed=args.seed)
    state = infos["state"]
    prev_done = np.zeros(b, dtype=bool)
    ep_return = np.zeros(b)
    finished: list[float] = []
    curve: list[tuple[float, int, float]] = []
    start, cpu_start = time.time(), time.process_time()
    t_env = t_policy = 0.0
    steps = 0
    update = 0
    print(f"training: {e} worlds x {n} followers, horizon {T}, budget {args.minutes:.1f} min")
    while time.time() - start < args.minutes * 60:
        for t in range(T):
            t0 = time.perf_counter()
            o = torch.from_numpy(obs.reshape(b, d).copy())
            ci = critic_input(obs, state)
            with torch.no_grad():
                dist = model.dist(o)
                a = dist.sample()
                obs_buf[t], cri_buf[t], act_buf[t] = o, ci, a
                logp_buf[t], val_buf[t] = dist.log_prob(a).sum(-1), model.value(ci)
            t1 = time.perf_counter()
            obs, rew, term, trunc, infos = env.step(a.clamp(-1, 1).numpy().reshape(e, n, 2))
            t2 = time.perf_counter()
            t_env += t2 - t1
            t_policy += t1 - t0
            state = infos["state"]
            r = rew.reshape(b).astype(np.float64)
            done = (term | trunc).reshape(b)
            # Next-step autoreset: the step after a done one only resets the world (actions ignored,
            # reward 0); it is no transition of the policy's, so it is masked out of the loss.
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
            val_buf[T] = model.value(critic_input(obs, state))
        scale = float(torch.sqrt(ret_norm.var[0] + 1e-8))
        adv = torch.zeros(T, b)
        last = torch.zeros(b)
        for t in reversed(range(T)):
            nonterminal = 1.0 - done_buf[t]
            delta = rew_buf[t] / scale + gamma * val_buf[t + 1] * nonterminal - val_buf[t]
            last = delta + gamma * lam * nonterminal * last
            adv[t] = last
        ret = adv + val_buf[:T]
        flat = lambda x: x.reshape(T * b, *x.shape[2:])  # noqa: E731
        keep = flat(valid_buf) > 0
        fo, fc, fa, fl, fadv, fret = (flat(x)[keep] for x in (obs_buf, cri_buf, act_buf, logp_buf, adv, ret))
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
                logp = dist.log_prob(fa[idx]).sum(-1)
                ratio = (logp - fl[idx]).exp()
                pg = -torch.min(ratio * fadv[idx], ratio.clamp(1 - clip, 1 + clip) * fadv[idx]).mean()
                vloss = 0.5 * (model.value(fc[idx]) - fret[idx]).pow(2).mean()
                loss = pg + 0.5 * vloss - ent_coef * dist.entropy().sum(-1).mean()
                opt.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(model.parameters(), 0.5)
                opt.step()
        update += 1
        if finished:
            mean_ret = float(np.mean(finished[-3 * b :]))  # the last three batches of episodes
            curve.append((time.time() - start, steps, mean_ret))
            if update % 20 == 0:
                print(
                    f"  {time.time() - start:6.0f} s  {steps:>10,d} agent-steps  mean episode return {mean_ret:8.2f}"
                    f"  std {model.log_std.exp().mean().item():.2f}",
                    flush=True,
                )
    train_time, train_cpu = time.time() - start, time.process_time() - cpu_start
    torch.save(model.state_dict(), os.path.join(args.out, "policy.pt"))

    worlds, horizon, seed = args.eval_worlds, args.episode, args.eval_seed
    t0 = time.time()
    learned = evaluate(lambda v: model.act, task_kwargs, worlds, horizon, seed)
    rand = evaluate(lambda v: RandomPolicy(v, seed=1).act, task_kwargs, worlds, horizon, seed)
    names = colcos.behaviours()
    follower = "aggregation_follower" if "aggregation_follower" in names else "avoid"
    hand = evaluate(lambda v: Baseline(v, follower).act, task_kwargs, worlds, horizon, seed)
    still = evaluate(lambda v: (lambda o: np.zeros((v.num_envs, v.num_agents, 2), np.float32)), task_kwargs, worlds, horizon, seed)
    result = {
        "train_seconds": round(train_time, 1),
        "eval_seconds": round(time.time() - t0, 1),
        "agent_steps": steps,
        "agent_steps_per_second": round(steps / train_time),
        "train_cpu_seconds": round(train_cpu, 1),
        "env_step_seconds": round(t_env, 1),
        "env_agent_steps_per_second": round(steps / t_env),
        "policy_seconds": round(t_policy, 1),
        "update_seconds": round(train_time - t_env - t_policy, 1),
        "load_average_1min": round(os.getloadavg()[0], 1),
        "updates": update,
        "eval_worlds": worlds,
        "eval_steps": horizon,
        "eval_seed": seed,
        "scenario": args.scenario,
        "task_params": {k: v for k, v in task_kwargs.items() if k not in ("task", "num_threads", "scenario")},
        "return_learned": round(learned, 2),
        "return_random": round(rand, 2),
        f"return_handwritten_{follower}": round(hand, 2),
        "return_standing_still": round(still, 2),
    }
    print(json.dumps(result, indent=2))
    with open(os.path.join(args.out, "result.json"), "w") as f:
        json.dump({"result": result, "curve": curve}, f, indent=1)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.plot([c[1] / 1e6 for c in curve], [c[2] for c in curve], label="PPO (training episodes, stochastic)", lw=1)
        ax.axhline(learned, color="C0", ls="-.", label="PPO (evaluation, deterministic)")
        ax.axhline(rand, color="grey", ls="--", label="random")
        ax.axhline(hand, color="green", ls=":", label=f"hand-written ({follower})")
        ax.set_xlabel("agent-steps (millions)")
        ax.set_ylabel("mean return per follower")
        ax.set_title("colcos aggregation: PPO, parameter sharing")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, "learning_curve.png"), dpi=120)
        print(f"saved {args.out}/learning_curve.png, {args.out}/policy.pt and {args.out}/result.json")
    except ImportError:
        print("matplotlib not installed: no PNG")


if __name__ == "__main__":
    main()
