"""Quick start: PPO learns the follower of case II (aggregation) in about a minute and a half on two cores.

All followers of all worlds share one policy (`examples/ppo.py`); each (world, follower) pair is one
sample stream. The actor sees only the follower's own 17 sensor values, and so does the critic (used
only in training; IPPO's, `--no-own-critic` adds the global state and which follower it is); an
episode cut by its time limit is valued on from its final observation (`--no-bootstrap-truncated`:
worth 0 after the cut); the actor's and the critic's gradients are clipped each to its own norm
(`ppo.Config.clip_apart`). `--recipe` chooses the schedule and objective: `ippo` (the default)
collects whole 500-step episodes of the 32 worlds and makes 15 passes of 40 minibatches over each,
with BenchMARL's IPPO objective (observations, rewards and advantages as they are, gamma 0.99, GAE
lambda 0.9, gradient norm 5), 38 updates; `short` collects 64 steps and makes 4 passes of 4
minibatches with standardised inputs, rewards and advantages (gamma 0.98, lambda 0.95, norm 0.5),
720 updates. A flag named on the command line overrides its recipe's value. The budget is a number
of PPO updates, so a loaded machine changes how long a run takes, not what it learns. Every
`--eval-every` updates the deterministic policy is evaluated on the same 32 seeded episodes as the
paper's hand-written follower (evaluation time is not counted as training time), and at half the
budget and at the end on 1,024 held-out episodes. With several `--seeds` it trains one policy per
seed and reports, per seed and as a median, the return at half the budget and at the end, against the
wall-clock seconds of training.

    python examples/train_aggregation.py                                  # one seed, the default budget
    python examples/train_aggregation.py --seeds 0 1 2 3 4 --out runs/quickstart   # the 5-seed check
    python examples/train_aggregation.py --recipe short --minutes 8 --out runs/aggregation   # a wall-clock budget

Writes `OUT/policy.pt` (the first seed's; `OUT/seed<k>/policy.pt` for each with several seeds),
`OUT/result.json` and, with matplotlib, `OUT/learning_curve.png` (evaluation return against training
seconds, one line per seed, the paper's follower and random actions as lines). Needs torch. The reward
is the env's (`aggregation` task, see docs/python.md "Training"); nothing is added here.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import tomllib
from collections.abc import Callable

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import colcos
import kickstart
import ppo
from colcos.baselines import Baseline, RandomPolicy
from colcos.vector import VecEnv

# Each recipe's schedule, objective and budget (ippo about 1.5 minutes of training on an idle 2-core
# x86 machine, short about 1.5, docs/python.md); a flag given on the command line overrides its entry.
# `ippo` is BenchMARL's IPPO (whole episodes, raw objective) with 15 passes a batch at 1e-3 where
# BenchMARL makes 45 at 3e-4: as much learning in a third of the gradient steps (docs/ppo_studies.md).
RECIPES: dict[str, dict] = {
    "ippo": {"updates": 38, "eval_every": 4, "horizon": 500, "epochs": 15, "minibatches": 40, "lr": 1e-3,
             "gamma": 0.99, "lam": 0.9, "grad_norm": 5.0,
             "raw_advantages": True, "raw_rewards": True, "raw_observations": True},
    "short": {"updates": 720, "eval_every": 60, "horizon": 64, "epochs": 4, "minibatches": 4, "lr": 1e-3,
              "gamma": ppo.Config.gamma, "lam": ppo.Config.lam, "grad_norm": ppo.Config.grad_norm,
              "raw_advantages": False, "raw_rewards": False, "raw_observations": False},
}  # fmt: skip


def references(env_kwargs: dict, args: argparse.Namespace) -> dict[str, float]:
    """The paper's follower, uniform random actions and standing still on the evaluation episodes."""
    ev = lambda policy: round(ppo.evaluate(policy, env_kwargs, args.eval_worlds, args.episode, args.eval_seed), 2)
    return {
        "paper_follower": ev(lambda v: Baseline(v, "aggregation_follower").act),
        "random": ev(lambda v: RandomPolicy(v, seed=1).act),
        "standing_still": ev(lambda v: (lambda o: np.zeros((v.num_envs, v.num_agents, 2), np.float32))),
    }


def sees_the_leader(v: VecEnv) -> Callable[[np.ndarray], np.ndarray]:
    """A controller that reads the true positions (the global state: four values a robot, in the
    default scenario's order of robots) and drives each follower straight at the leader: what a
    policy with full information scores, as a reference for one that only senses."""
    spec = tomllib.loads(colcos.default_scenario("aggregation"))
    size = np.array(spec.get("arena", {}).get("size", spec["screen"]["size"]), np.float32)  # as Scenario::arena_size
    roles = [g["role"] for g in spec["robots"] for _ in range(g["count"])]
    leader, followers = roles.index("leader"), [i for i, r in enumerate(roles) if r == "follower"]

    def act(_obs: np.ndarray) -> np.ndarray:
        s = np.asarray(v.state)[:, : 4 * len(roles)].reshape(v.num_envs, len(roles), 4)
        xy = (s[..., :2] + 1) / 2 * size
        me = s[:, followers]
        d = xy[:, leader : leader + 1] - xy[:, followers]
        turn = np.arctan2(d[..., 1], d[..., 0]) - np.arctan2(me[..., 3], me[..., 2])
        turn = (turn + np.pi) % (2 * np.pi) - np.pi
        forward = np.clip(np.cos(turn), 0, 1) * np.clip(np.linalg.norm(d, axis=-1) / 0.1, 0, 1)
        steer = np.clip(2 * turn, -1, 1)
        return np.stack([forward - steer, forward + steer], -1).clip(-1, 1).astype(np.float32)

    return act


def holdout(policy: Callable[[VecEnv], Callable[[np.ndarray], np.ndarray]], env_kwargs: dict, args: argparse.Namespace) -> dict:
    """Mean return per follower and its standard error over the held-out episodes (`--holdout-worlds`
    seeded `--holdout-seed`): the test set no choice was made on."""
    return ppo.mean_and_se(ppo.episode_returns(policy, env_kwargs, args.holdout_worlds, args.episode, args.holdout_seed))


def holdout_references(env_kwargs: dict, args: argparse.Namespace) -> dict[str, dict]:
    """The paper's follower, standing still and (default scenario only) `sees_the_leader` on the
    held-out episodes."""
    refs = {
        "paper_follower": holdout(lambda v: Baseline(v, "aggregation_follower").act, env_kwargs, args),
        "standing_still": holdout(lambda v: (lambda o: np.zeros((v.num_envs, v.num_agents, 2), np.float32)), env_kwargs, args),
    }
    if not args.scenario:
        refs["sees_the_leader"] = holdout(sees_the_leader, env_kwargs, args)
    return refs


def train(seed: int, env_kwargs: dict, args: argparse.Namespace, out: str) -> dict:
    """One training run: its evaluation curve (training seconds, updates, agent-steps, return)."""
    env = VecEnv(num_envs=args.num_envs, seed=seed, max_cycles=args.episode, **env_kwargs)
    cfg = ppo.Config(horizon=args.horizon, epochs=args.epochs, minibatches=args.minibatches, lr=args.lr, gamma=args.gamma,
                     lam=args.lam, hidden=args.hidden, own_critic=args.own_critic, grad_norm=args.grad_norm, tanh=args.tanh,
                     raw_advantages=args.raw_advantages, raw_rewards=args.raw_rewards, raw_observations=args.raw_observations,
                     bootstrap_truncated=args.bootstrap_truncated,
                     anneal=args.updates if args.anneal and not args.minutes else 0, team_critic=args.team_critic,
                     agent_id=args.agent_id, history=args.history, clip_apart=not args.clip_together,
                     target_kl=args.target_kl, anchor=args.anchor, actor_warmup=args.actor_warmup,
                     learn_threads=args.learn_threads, compile=args.compile)
    trainer = ppo.Trainer(env, cfg, seed)
    train_seconds, cpu_start = 0.0, time.process_time()
    if args.kickstart:
        # Imitation is training: its seconds count in the budget's clock.
        t0 = time.perf_counter()
        follower = lambda v: Baseline(v, "aggregation_follower").act
        obs, acts = kickstart.demonstrations(follower, env_kwargs, args.num_envs, args.kickstart, seed + 1000, ppo.clip_wheels)
        space = env.single_action_space
        kickstart.imitate(trainer.model, obs, acts, space.low, space.high, std=args.kickstart_std, seed=seed)
        trainer.set_anchor()
        train_seconds += time.perf_counter() - t0
    kickstart_seconds = train_seconds
    evaluate = lambda: round(ppo.evaluate(lambda v: trainer.model.policy(), env_kwargs, args.eval_worlds, args.episode, args.eval_seed), 2)
    curve: list[tuple[float, int, int, float]] = [(round(train_seconds, 1), 0, 0, evaluate())]
    budget = args.minutes * 60 if args.minutes else None
    what = f"{args.minutes:.1f} min" if budget else f"{args.updates} updates"
    print(f"seed {seed}: {env.num_envs} worlds x {env.num_agents} followers, rollouts of {cfg.horizon} steps, {what};"
          f" evaluation return at the start {curve[0][3]:.2f} ({curve[0][0]:.1f} s)", flush=True)
    held: dict[str, dict] = {}

    def hold(when: str) -> None:
        if args.holdout_worlds:
            held[when] = {"seconds": round(train_seconds, 1), "updates": trainer.updates,
                          **holdout(lambda v: trainer.model.policy(), env_kwargs, args)}  # fmt: skip
            h = held[when]
            print(f"  held-out return at {when} ({h['updates']} updates): {h['mean']:.2f} ± {h['se']:.2f}", flush=True)

    while (train_seconds < budget) if budget else (trainer.updates < args.updates):
        t0 = time.perf_counter()
        trainer.iterate()
        train_seconds += time.perf_counter() - t0
        if trainer.updates % args.eval_every == 0:
            curve.append((round(train_seconds, 1), trainer.updates, trainer.agent_steps, evaluate()))
            print(f"  {train_seconds:6.1f} s  update {trainer.updates:5d}  {trainer.agent_steps:>10,d} agent-steps"
                  f"  evaluation return {curve[-1][3]:8.2f}  (KL {trainer.kl:.4f}, lr {trainer.lr:.2e})", flush=True)
        past_half = (train_seconds >= budget / 2) if budget else (2 * trainer.updates >= args.updates)
        if past_half and "half" not in held:
            hold("half")
    if curve[-1][1] != trainer.updates:
        curve.append((round(train_seconds, 1), trainer.updates, trainer.agent_steps, evaluate()))
    hold("end")
    os.makedirs(out, exist_ok=True)
    torch.save(trainer.model.state_dict(), os.path.join(out, "policy.pt"))
    s = trainer.seconds
    return {
        "seed": seed,
        "train_seconds": round(train_seconds, 1),
        "kickstart_seconds": round(kickstart_seconds, 3),
        "train_cpu_seconds": round(time.process_time() - cpu_start, 1),
        "updates": trainer.updates,
        "agent_steps": trainer.agent_steps,
        "agent_steps_per_second": round(trainer.agent_steps / train_seconds),
        "seconds_env_act_learn": [round(s["env"], 1), round(s["act"], 1), round(s["learn"], 1)],
        "return_learned": curve[-1][3],
        "holdout": held,
        "curve": curve,
    }


def at_half(run: dict) -> tuple[float, float]:
    """(training seconds, return) at the evaluation nearest to half the run's updates."""
    half = run["updates"] / 2
    t, _, _, r = min(run["curve"], key=lambda c: abs(c[1] - half))
    return t, r


def holdout_summary(runs: list[dict], held_refs: dict[str, dict], args: argparse.Namespace) -> dict:
    """The held-out evaluation: its episodes, the references and the medians over seeds at half the
    budget and at the end, and whether every seed's interval (mean ± 2 se) is above the follower's."""
    if not held_refs:
        return {}
    follower = held_refs["paper_follower"]["mean"]
    out: dict = {"worlds": args.holdout_worlds, "seed": args.holdout_seed, "references": held_refs}
    for when in ("half", "end"):
        got = [r["holdout"][when] for r in runs if when in r["holdout"]]
        if got:
            out[f"median_{when}"] = float(np.median([g["mean"] for g in got]))
            out[f"every_seed_above_follower_{when}"] = all(g["mean"] - 2 * g["se"] > follower for g in got)
    return out


def print_holdout(runs: list[dict], h: dict) -> None:
    refs = h["references"]
    print(f"\n| seed | held-out return at half the budget | at the end |  ({h['worlds']} episodes seeded {h['seed']}; mean ± se)")
    print("| ---: | ---: | ---: |")
    for r in runs:
        cells = [f"{r['holdout'][w]['mean']:.1f} ± {r['holdout'][w]['se']:.1f}" if w in r["holdout"] else "" for w in ("half", "end")]
        print(f"| {r['seed']} | {cells[0]} | {cells[1]} |")
    print(f"| median | {h.get('median_half', float('nan')):.1f} | {h.get('median_end', float('nan')):.1f} |")
    print("held out: " + ", ".join(f"{k.replace('_', ' ')} {v['mean']:.1f} ± {v['se']:.1f}" for k, v in refs.items())
          + f"; every seed above the follower (mean - 2 se) at half the budget: {h.get('every_seed_above_follower_half')},"
          f" at the end: {h.get('every_seed_above_follower_end')}")


def plot(runs: list[dict], refs: dict[str, float], held_refs: dict[str, dict], out: str) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no PNG")
        return
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for k, run in enumerate(runs):
        c = np.array(run["curve"])
        ax.plot(c[:, 0], c[:, 3], color=f"C{k % 10}", lw=1.2, marker="o", ms=2.5, label=f"PPO, seed {run['seed']}")
        held = list(run["holdout"].values())
        if held:
            ax.errorbar([h["seconds"] for h in held], [h["mean"] for h in held], yerr=[2 * h["se"] for h in held],
                        color=f"C{k % 10}", ls="none", marker="s", ms=5, mfc="none", capsize=2)
    ax.axhline(refs["paper_follower"], color="green", ls=":", label="paper's follower")
    if held_refs:
        ax.axhline(held_refs["paper_follower"]["mean"], color="green", ls="-.", lw=0.8, label="paper's follower, held out")
    ax.axhline(refs["random"], color="grey", ls="--", label="random")
    ax.set_xlabel("training wall-clock seconds (evaluation not counted)")
    rate = runs[0]["updates"] / max(runs[0]["train_seconds"], 1e-9)  # updates per second, for the top axis
    top = ax.secondary_xaxis("top", functions=(lambda t: t * rate, lambda u: u / rate))
    top.set_xlabel(f"PPO updates (seed {runs[0]['seed']}'s pace)", fontsize=8)
    ax.set_ylabel("mean return per follower")
    if held_refs:
        ax.set_title("colcos aggregation: PPO quick start\n(lines: the 32 evaluation episodes; squares: held out, ± 2 se)", fontsize=9)
    else:
        ax.set_title("colcos aggregation: PPO quick start", fontsize=10)
    ax.legend(fontsize=7, loc="upper left", ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "learning_curve.png"), dpi=120)
    plt.close(fig)


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The command line, with the recipe's values where no flag was given; bad values refused by name."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--recipe", choices=sorted(RECIPES), default="ippo",
                   help="schedule, objective and budget (see above); flags given override its values")
    p.add_argument("--updates", type=int, default=None, help="training budget in PPO updates (ippo 38, short 720)")
    p.add_argument("--minutes", type=float, default=None, help="a wall-clock budget instead of --updates")
    p.add_argument("--seeds", type=int, nargs="+", default=None, help="train one policy per seed (default: --seed)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--eval-every", type=int, default=None, help="evaluate the policy every K updates (ippo 4, short 60)")
    p.add_argument("--num-envs", type=int, default=32, help="worlds stepped as one batch")
    p.add_argument("--horizon", type=int, default=None, help="steps per rollout (ippo 500, short 64)")
    p.add_argument("--epochs", type=int, default=None, help="passes over each rollout (ippo 15, short 4)")
    p.add_argument("--minibatches", type=int, default=None, help="minibatches a pass (ippo 40, short 4)")
    p.add_argument("--lr", type=float, default=None, help="learning rate (1e-3)")
    p.add_argument("--gamma", type=float, default=None, help="discount per step of 20 ms (ippo 0.99, short 0.98)")
    p.add_argument("--lam", type=float, default=None, help="GAE's lambda (ippo 0.9, short 0.95)")
    p.add_argument("--hidden", type=int, default=ppo.Config.hidden, help="units in each of the two hidden layers (actor and critic)")
    p.add_argument("--anneal", action="store_true", help="the learning rate falls linearly to 0 over --updates")
    p.add_argument("--target-kl", type=float, default=0.0,
                   help="adapt the learning rate to keep each step's KL divergence near this (ppo.Config.target_kl; 0: off)")
    p.add_argument("--kickstart", type=int, default=0, metavar="STEPS",
                   help="first imitate the paper's follower over STEPS agent-steps of it acting (kickstart.py), then PPO")
    p.add_argument("--kickstart-std", type=float, default=0.3, help="the kickstarted actor's noise (sd)")
    p.add_argument("--anchor", type=float, default=0.0, help="with --kickstart: weight keeping the actor near the imitated one")
    p.add_argument("--actor-warmup", type=int, default=0, help="the first N updates train only the critic")
    p.add_argument("--clip-together", action="store_true",
                   help="clip actor and critic gradients as one norm (by default each its own: ppo.Config.clip_apart)")
    p.add_argument("--team-critic", action="store_true", help="the critic also sees every follower's observation")
    p.add_argument("--grad-norm", type=float, default=None, help="gradients are clipped to this norm (ippo 5, short 0.5)")
    p.add_argument("--own-critic", action=argparse.BooleanOptionalAction, default=None,
                   help="the critic sees only the agent's own observation, as IPPO's (the default unless --team-critic); "
                        "--no-own-critic: also the global state and which follower it is")
    p.add_argument("--raw-advantages", action=argparse.BooleanOptionalAction, default=None,
                   help="advantages not standardised over each batch, as BenchMARL's PPO losses (ippo: on; short: off)")
    p.add_argument("--raw-rewards", action=argparse.BooleanOptionalAction, default=None,
                   help="rewards not scaled by the running sd of the discounted return, as BenchMARL's (ippo: on; short: off)")
    p.add_argument("--raw-observations", action=argparse.BooleanOptionalAction, default=None,
                   help="observations not standardised, as BenchMARL's default: the running z-scores stay the identity (ippo: on; short: off)")
    p.add_argument("--bootstrap-truncated", action=argparse.BooleanOptionalAction, default=True,
                   help="an episode cut by its time limit bootstraps from its final observation's value (the default; "
                        "--no-bootstrap-truncated: it is worth 0 after the cut, as after a termination)")
    p.add_argument("--tanh", action="store_true",
                   help="BenchMARL's actor: the tanh of a Gaussian whose widths the network gives per observation")
    p.add_argument("--agent-id", action="store_true",
                   help="the actor also sees which follower it drives (a one-hot): one policy, each robot its own way")
    p.add_argument("--history", type=int, default=1,
                   help="the actor reads its last K observations (oldest first): a memory of its recent readings and commands")
    p.add_argument("--episode", type=int, default=500, help="steps per episode (10 s)")
    p.add_argument("--threads", type=int, default=None, help="env worker threads (default: one per core)")
    p.add_argument("--learn-threads", type=int, default=os.cpu_count() or 1,
                   help="torch threads for the policy update (default: one per core; the result is the same for any number)")
    p.add_argument("--compile", action="store_true",
                   help="the update's loss through torch.compile and Adam fused (faster; not the same bits as without it)")
    p.add_argument("--eval-worlds", type=int, default=32)
    p.add_argument("--eval-seed", type=int, default=12345)
    p.add_argument("--holdout-worlds", type=int, default=1024,
                   help="held-out episodes evaluated at half the budget and at the end (0: none)")
    p.add_argument("--holdout-seed", type=int, default=777)
    p.add_argument("--out", default="runs/aggregation")
    p.add_argument("--scenario", default=None, help="scenario file for training and evaluation (e.g. with a [randomize] section)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="numeric task parameter for training and evaluation, e.g. progress_weight=0 (repeatable)")
    args = p.parse_args(argv)
    for key, value in RECIPES[args.recipe].items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    if args.anneal and args.target_kl:
        p.error("--anneal and --target-kl both set the learning rate: choose one")
    for flag in ("horizon", "epochs", "minibatches"):
        if getattr(args, flag) < 1:
            p.error(f"--{flag} ({getattr(args, flag)}) must be at least 1")
    if args.updates < 1 or args.eval_every < 1 or args.history < 1:
        p.error(f"--updates ({args.updates}), --eval-every ({args.eval_every}) and --history ({args.history}) must be at least 1")
    if not 0.0 < args.gamma <= 1.0:
        p.error(f"--gamma ({args.gamma}) must be in (0, 1]")
    if not 0.0 <= args.lam <= 1.0:
        p.error(f"--lam ({args.lam}) must be in [0, 1]")
    if not args.grad_norm > 0.0:
        p.error(f"--grad-norm ({args.grad_norm}) must be above 0")
    if args.learn_threads < 1:
        p.error(f"--learn-threads ({args.learn_threads}) must be at least 1")
    if args.hidden < 1:
        p.error(f"--hidden ({args.hidden}) must be at least 1")
    if args.tanh and (args.kickstart or args.anchor):
        p.error("--tanh: a tanh actor is not kickstarted (--kickstart, --anchor)")
    if args.own_critic and args.team_critic:
        p.error("--own-critic and --team-critic choose the critic's input: choose one")
    if args.own_critic is None:
        args.own_critic = not args.team_critic
    if args.holdout_worlds < 0 or args.holdout_worlds == 1:
        p.error(f"--holdout-worlds ({args.holdout_worlds}) must be 0 (none) or at least 2 (a standard error needs two)")
    if args.holdout_seed == args.eval_seed:
        p.error(f"--holdout-seed ({args.holdout_seed}) must differ from --eval-seed: the held-out episodes are other episodes")
    for kv in args.param:
        key, sep, value = kv.partition("=")
        if not sep:
            p.error(f"--param {kv!r}: expected KEY=VALUE")
        try:
            float(value)
        except ValueError:
            p.error(f"--param {kv!r}: {value!r} is not a number")
    return args


def main() -> None:
    args = parse_args()
    # The rollout's tensors are small: one torch thread is fastest there (two fight the env's workers);
    # the update's minibatches take --learn-threads (ppo.Config.learn_threads).
    torch.set_num_threads(1)
    os.makedirs(args.out, exist_ok=True)
    env_kwargs: dict = {"task": "aggregation", "num_threads": args.threads}
    if args.scenario:
        env_kwargs["scenario"] = args.scenario
    for kv in args.param:
        key, _, value = kv.partition("=")
        env_kwargs[key] = float(value)
    seeds = args.seeds or [args.seed]
    refs = references(env_kwargs, args)
    print("references on the evaluation episodes:", json.dumps(refs), flush=True)
    held_refs = holdout_references(env_kwargs, args) if args.holdout_worlds else {}
    if held_refs:
        print(f"references on the {args.holdout_worlds} held-out episodes:", json.dumps(held_refs), flush=True)
    runs = []
    for seed in seeds:
        out = args.out if len(seeds) == 1 else os.path.join(args.out, f"seed{seed}")
        runs.append(train(seed, env_kwargs, args, out))
    if len(seeds) > 1:
        torch.save(torch.load(os.path.join(args.out, f"seed{seeds[0]}", "policy.pt")), os.path.join(args.out, "policy.pt"))
    half = [at_half(r) for r in runs]
    result = {
        "command": " ".join(sys.argv),
        "date": time.strftime("%Y-%m-%d"),
        "cores": os.cpu_count(),
        "load_average_1min": round(os.getloadavg()[0], 1),
        "eval_worlds": args.eval_worlds, "eval_steps": args.episode, "eval_seed": args.eval_seed,
        "scenario": args.scenario,
        "recipe": args.recipe,
        "critic": "own" if args.own_critic else "team" if args.team_critic else "state",
        "bootstrap_truncated": args.bootstrap_truncated,
        "task_params": {k: v for k, v in env_kwargs.items() if k not in ("task", "num_threads", "scenario")},
        "references": refs,
        "median_half": {"seconds": float(np.median([h[0] for h in half])), "return": float(np.median([h[1] for h in half]))},
        "median_end": {"seconds": float(np.median([r["train_seconds"] for r in runs])),
                       "return": float(np.median([r["return_learned"] for r in runs]))},
        "every_seed_beats_follower_at_half": all(h[1] > refs["paper_follower"] for h in half),
        "holdout": holdout_summary(runs, held_refs, args),
        "runs": runs,
    }  # fmt: skip
    with open(os.path.join(args.out, "result.json"), "w") as f:
        json.dump(result, f, indent=1)
    print("\n| seed | half budget: s | return | end: s | updates | return |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: |")
    for r, (t, v) in zip(runs, half):
        print(f"| {r['seed']} | {t:.0f} | {v:.1f} | {r['train_seconds']:.0f} | {r['updates']} | {r['return_learned']:.1f} |")
    mh, me = result["median_half"], result["median_end"]
    print(f"| median | {mh['seconds']:.0f} | {mh['return']:.1f} | {me['seconds']:.0f} | | {me['return']:.1f} |")
    print(f"paper's follower {refs['paper_follower']:.1f}, random {refs['random']:.1f}, standing still {refs['standing_still']:.1f};"
          f" every seed above the follower at half the budget: {result['every_seed_beats_follower_at_half']}")
    if held_refs:
        print_holdout(runs, result["holdout"])
    plot(runs, refs, held_refs, args.out)
    print(f"saved {args.out}/result.json, policy.pt and learning_curve.png")


if __name__ == "__main__":
    main()
