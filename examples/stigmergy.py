"""Does laying pheromone help agents that learn? PPO on `colony`, `coverage` and `alarm`, with and without
pheromone actions.

For each task and seed the same PPO (parameter sharing; the actor, critic and trainer of
`examples/ppo.py`, 4 epochs x 4 minibatches) trains twice with the same budget of agent-steps (a whole
number of updates, so the machine's load changes only the wall time): once with its deposit outputs
sent to the env ("with"), once with them forced to 0 before every step ("without": the ablation; the policy is the
same network, its deposit outputs simply never lay anything). Then learned-with, learned-without, the
task's hand-written policy (`colcos.task_policies()`) and uniform random actions run on the same seeded
evaluation episodes (every world's first episode after `reset(seed=--eval-seed)`); the learned-with
policy is also evaluated with its rates forced to 0 (what its own trails are worth to it). Prints a
markdown table (mean return per agent, ± the spread across training seeds), writes `result.json` (per
seed and per episode) and, with matplotlib, one learning-curve PNG per task (mean over seeds, band:
lowest to highest seed).

Every run (task, with/without, seed) is saved as it finishes under `OUT/<task>/` (`with_seed0.json`
and `.pt`, ...), as are the reference policies' evaluations; a run whose file exists is loaded, not
trained again, so an interrupted study resumes, and several processes may share the work (split by
`--tasks`, `--modes`, `--seeds`) before one last call with everything gathers the table.

    python examples/stigmergy.py --steps 2000000 --seeds 0 1 2 --out runs/stigmergy
    python examples/stigmergy.py --tasks coverage --steps 20000 --seeds 0 --episode 50   # a smoke run
    python examples/stigmergy.py --tasks colony --seeds 0 --twin-episodes 2 --out runs/stigmergy   # + the twin

`--twin-episodes K` then runs the learned-with policy of the first seed of the first task on the digital
twin (`parallel_env(plant="twin")`, real time at 50 Hz) for K episodes and on the simulator's
`parallel_env` with the same seeds, and reports both returns.

`--param KEY=VALUE` sets a task parameter for training and evaluation (`'food=[[0.75, 0.65], [0.75, 0.16]]'`),
`--shaping KEY=VALUE` one for training only (`pickup_reward=1`: both arms get the same extra reward, every
policy is evaluated on the task's own), `--scenario FILE` another scenario.

    python examples/stigmergy.py --tasks colony --shaping pickup_reward=1 --out runs/stigmergy/shaped

Needs torch. Without `--shaping` the rewards are the tasks' own (docs/tasks.md).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import pathlib
import sys
import time
import tomllib

import colcos
import numpy as np
import torch
from colcos.baselines import Baseline, RandomPolicy
from colcos.vector import VecEnv
from torch import nn

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kickstart
import ppo

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "tasks"))
from rally import Rally, RallyCall

TASKS = ("colony", "coverage", "alarm", "rally")
PYTHON_TASKS = {"rally": (Rally, RallyCall)}  # written in Python: the task's class and its hand-written policy
MODES = ("with", "without")


def to_env(a: np.ndarray, lay: bool) -> np.ndarray:
    """A policy's raw output (..., 2 + D) as the env's action: wheels clipped to [-1, 1], deposit rates
    clipped to [0, 1], or forced to 0 without pheromone actions."""
    out = np.clip(a, -1.0, 1.0).astype(np.float32)
    out[..., 2:] = np.clip(out[..., 2:], 0.0, 1.0) if lay else 0.0
    return out


def scenario_of(task: str, args: argparse.Namespace) -> dict:
    """The scenario the task runs on (`--scenario`, or the task's own), parsed."""
    if args.scenario:
        text = pathlib.Path(args.scenario).read_text()
    else:
        text = PYTHON_TASKS[task][0].scenario if task in PYTHON_TASKS else colcos.default_scenario(task)
    return tomllib.loads(text)


def episode_steps(task: str, args: argparse.Namespace) -> int:
    """Steps per episode: `--episode`, or with 0 the task's scenario's own duration."""
    if args.episode:
        return args.episode
    scenario = scenario_of(task, args)
    return round(scenario["duration"] / scenario["dt"])


def message_inputs(task: str, args: argparse.Namespace) -> tuple[int, ...]:
    """The observation entries an agent hears the others' pheromone in (for `--listen-bias`): the colour
    channels of every pheromone the agents lay by action, at each of the four sensors (entries
    `3 * sensor + channel`)."""
    scenario = scenario_of(task, args)
    laid = set()
    for group in scenario.get("robots", []):
        laid.update(d["pheromone"] for d in group.get("deposit_actions", []))
        laid.update(e["pheromone"] for e in group.get("emits", []) if e.get("when") == "action")
    channels = sorted({c for ph in scenario.get("pheromones", []) if ph["name"] in laid
                       for c in range(3) if ph["colour"][c] > 0})
    return tuple(3 * s + c for s in range(4) for c in channels)


def updates_for(args: argparse.Namespace, num_agents: int) -> int:
    """The budget as a whole number of PPO updates (rollouts of `horizon` steps of every agent)."""
    return max(1, math.ceil(args.steps / (args.horizon * args.num_envs * num_agents)))


def task_kwargs(task: str, args: argparse.Namespace, training: bool) -> dict:
    """The env's task, scenario and task parameters: `--scenario` and `--param` everywhere, `--shaping`
    (extra reward terms such as `pickup_reward=1`) only while training, so that every policy is
    evaluated on the task's own reward. A task written in Python takes its parameters itself, and a
    fresh instance per env (it keeps per-world state)."""
    params: dict = dict(args.param)
    if training:
        params.update(args.shaping)
    kw: dict = {"task": PYTHON_TASKS[task][0](**params)} if task in PYTHON_TASKS else {"task": task, **params}
    if args.scenario:
        kw["scenario"] = args.scenario
    return kw


def train(task: str, lay: bool, seed: int, args: argparse.Namespace) -> tuple[nn.Module, dict]:
    """PPO on `task` for the budget's updates; the model and its log: the learning curve (per update:
    agent-steps, mean reward per agent-step of the rollout; per finished batch of training episodes:
    agent-steps, their mean return), the updates, agent-steps and wall time."""
    env = VecEnv(num_envs=args.num_envs, seed=seed, max_cycles=episode_steps(task, args), num_threads=args.threads,
                 **task_kwargs(task, args, training=True))
    updates = updates_for(args, env.num_agents)
    cfg = ppo.Config(horizon=args.horizon, epochs=4, minibatches=4, lr=args.lr, gamma=args.gamma,
                     anneal=updates if args.anneal else 0, team_critic=args.team_critic,
                     start_forward=args.start_forward, start_lay=args.start_lay,
                     # The communication biases act on a message: the arm that lays none has none to hear.
                     listen_bias=args.listen_bias if lay else 0.0, signal_bias=args.signal_bias if lay else 0.0,
                     message_inputs=message_inputs(task, args), actor_warmup=args.actor_warmup,
                     anchor=args.anchor)
    trainer = ppo.Trainer(env, cfg, seed, to_env=lambda a: to_env(a, lay))
    kicked: dict = {}
    if args.kickstart:
        kicked = kickstart_actor(trainer, task, lay, seed, args)
        trainer.set_anchor()
    rate_curve: list[tuple[int, float]] = []
    episode_curve: list[tuple[int, float]] = []
    start = time.time()
    for update in range(updates):
        ended = len(trainer.finished)
        rate_curve.append((trainer.agent_steps + cfg.horizon * trainer.b, trainer.iterate()))
        if len(trainer.finished) > ended:
            episode_curve.append((trainer.agent_steps, float(np.mean(trainer.finished[ended:]))))
        if args.verbose and (update + 1) % args.verbose == 0:
            print(f"  {task} {'with' if lay else 'without'} seed {seed}: update {update + 1}/{updates}, "
                  f"{trainer.agent_steps:,} agent-steps, reward/agent-step {rate_curve[-1][1]:.5f}, "
                  f"last episodes {episode_curve[-1][1] if episode_curve else float('nan'):.2f}, "
                  f"{time.time() - start:.0f} s", flush=True)
    log = {"updates": updates, "agent_steps": trainer.agent_steps, "train_seconds": round(time.time() - start, 1),
           "rate_curve": rate_curve, "episode_curve": episode_curve, **kicked}
    return trainer.model, log


def hand_written(task: str):
    """The task's hand-written policy as `make(env)` -> (observations -> actions): the baseline of
    every study and the teacher of `--kickstart`."""
    if task in PYTHON_TASKS:
        return lambda v: PYTHON_TASKS[task][1](seed=1).act
    name = {t: p for p, (t, _) in colcos.task_policies().items()}[task]
    return lambda v: Baseline(v, name).act


def kickstart_actor(trainer: ppo.Trainer, task: str, lay: bool, seed: int, args: argparse.Namespace) -> dict:
    """`--kickstart`: the trainer's actor imitates the task's hand-written policy, acting in worlds of
    this arm (without pheromone actions its trails are never laid), before PPO; the imitation's error
    and the kickstarted policy's evaluation, for the run's record."""
    t0 = time.time()
    env_kwargs = {"max_cycles": episode_steps(task, args), "num_threads": args.threads, **task_kwargs(task, args, training=True)}
    obs, acts = kickstart.demonstrations(hand_written(task), env_kwargs, args.num_envs, args.kickstart, seed + 1000,
                                         lambda a: to_env(a, lay))
    space = trainer.env.single_action_space
    losses = kickstart.imitate(trainer.model, obs, acts, space.low, space.high, std=args.kickstart_std, seed=seed)
    return {"kickstart_mse": [round(v, 5) for v in losses], "kickstart_seconds": round(time.time() - t0, 1),
            "eval_kickstart": evaluate(task, acting(trainer.model, lay, args), args)}


def evaluate(task: str, act, args: argparse.Namespace) -> list[float]:
    """Return per agent of each of `args.eval_worlds` seeded episodes (every
    world's first episode after `reset(seed=args.eval_seed)`); `act(venv)` gives the policy
    (observations -> actions)."""
    env_kwargs = {"num_threads": args.threads, **task_kwargs(task, args, training=False)}
    return ppo.episode_returns(act, env_kwargs, args.eval_worlds, episode_steps(task, args), args.eval_seed)


def acting(model: nn.Module, lay: bool, args: argparse.Namespace):
    """The evaluation's policy of a trained model: its mean action (`--eval-policy mean`), or actions
    sampled as in training (`sample`), the noise seeded by `--eval-seed`, the same for every model."""
    if args.eval_policy == "mean":
        return lambda v: lambda o: to_env(model.act(o), lay)

    def make(v):
        g = torch.Generator().manual_seed(args.eval_seed)
        return lambda o: to_env(model.sample(o, g), lay)

    return make


def _dump(path: pathlib.Path, obj: dict) -> None:
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(obj, indent=1))
    tmp.replace(path)


def run(task: str, mode: str, seed: int, args: argparse.Namespace) -> dict:
    """One training run and its evaluations, loaded from `OUT/<task>/<mode>_seed<seed>.json` if that
    exists (made with the same budget), else trained and saved there."""
    folder = pathlib.Path(args.out) / task
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{mode}_seed{seed}.json"
    if path.exists():
        saved = json.loads(path.read_text())
        if same_config(saved["config"], config(args, mode), args):
            return saved
        print(f"{path}: made with another configuration, trained again", flush=True)
    lay = mode == "with"
    model, log = train(task, lay, seed, args)
    torch.save(model.state_dict(), folder / f"{mode}_seed{seed}.pt")
    t0 = time.time()
    rec = {"task": task, "mode": mode, "seed": seed, "config": config(args, mode), **log,
           "eval": evaluate(task, acting(model, lay, args), args)}
    if lay:
        rec["eval_rates_off"] = evaluate(task, acting(model, False, args), args)
    rec["eval_seconds"] = round(time.time() - t0, 1)
    _dump(path, rec)
    return rec


def reference(task: str, name: str, args: argparse.Namespace) -> list[float]:
    """The hand-written policy's or random actions' evaluation returns, cached in `OUT/<task>/`."""
    folder = pathlib.Path(args.out) / task
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.json"
    cfg = {k: v for k, v in config(args).items() if k in ("episode", "eval_worlds", "eval_seed", "param", "scenario")}
    if path.exists():
        saved = json.loads(path.read_text())
        if same_config(saved["config"], cfg, args):
            return saved["eval"]
    make = hand_written(task) if name == "baseline" else (lambda v: RandomPolicy(v, seed=1).act)
    returns = evaluate(task, make, args)
    _dump(path, {"config": cfg, "eval": returns})
    return returns


def config(args: argparse.Namespace, mode: str = "with") -> dict:
    """What a saved run of `mode` must share with this call to be reused. The arm without pheromone
    actions trains without the communication biases (`train`), so it records them as 0: one such run
    serves studies with any biases."""
    keys = ("steps", "num_envs", "horizon", "episode", "lr", "gamma", "anneal", "team_critic", "start_forward", "start_lay",
            "listen_bias", "signal_bias", "param", "shaping", "scenario", "eval_worlds", "eval_seed", "eval_policy",
            "kickstart", "kickstart_std", "actor_warmup", "anchor")
    out = {k: getattr(args, k) for k in keys}
    if mode == "without":
        out["listen_bias"] = out["signal_bias"] = 0.0
    return out


def same_config(saved: dict, current: dict, args: argparse.Namespace) -> bool:
    """Whether a saved run's configuration is `current`; a setting the saved file lacks (one added to
    the script since) counts as its default."""
    return all(saved.get(k, args.defaults.get(k)) == v for k, v in current.items())


def twin(task: str, seed: int, args: argparse.Namespace) -> dict:
    """The learned-with policy of `seed` on the digital twin and on the simulator's `parallel_env`, the
    same episode seeds; mean return per agent of each episode."""
    folder = pathlib.Path(args.out) / task
    probe = VecEnv(num_envs=1, max_cycles=episode_steps(task, args), num_threads=args.threads,
                   **task_kwargs(task, args, training=False))
    d, w = probe.single_observation_space.shape[0], probe.single_action_space.shape[0]
    n = probe.num_agents
    model = ppo.ActorCritic(d, ppo.critic_dim(probe, args.team_critic), act_dim=w)
    model.load_state_dict(torch.load(folder / f"with_seed{seed}.pt"))
    out: dict = {"seed": seed, "episodes": args.twin_episodes, "episode_steps": args.twin_steps or episode_steps(task, args)}
    for plant in ("sim", "twin"):
        returns, t0 = [], time.time()
        with colcos.parallel_env(plant=plant, max_cycles=out["episode_steps"], **task_kwargs(task, args, False)) as env:
            act = acting(model, True, args)(env)  # sampled noise: the same seed on both plants
            for k in range(args.twin_episodes):
                obs, _ = env.reset(seed=args.eval_seed + k)
                total = 0.0
                while env.agents:
                    acts = {a: act(obs[a]) for a in env.agents}
                    obs, rew, _, _, _ = env.step(acts)
                    total += sum(rew.values())
                returns.append(total / n)
                print(f"  {plant} episode {k}: {returns[-1]:.2f} ({time.time() - t0:.0f} s)", flush=True)
            if plant == "twin":
                out["plant_info"] = {k: v for k, v in env.plant_info().items() if isinstance(v, (int, float, str))}
        out[plant] = returns
        out[f"{plant}_seconds"] = round(time.time() - t0, 1)
    _dump(folder / f"twin_seed{seed}.json", out)
    return out


def sd(xs) -> float:
    """The sample standard deviation (ddof 1; 0 for a single value)."""
    return float(np.std(xs, ddof=1)) if len(xs) > 1 else 0.0


def spread(xs) -> str:
    return f"{np.mean(xs):.2f} ± {sd(xs):.2f}"


def plot(task: str, row: dict, args: argparse.Namespace) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no PNG")
        return
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), gridspec_kw={"width_ratios": [3, 2]})
    ax = axes[0]
    for mode, colour in (("with", "C0"), ("without", "C1")):
        curves = [np.array(row["runs"][mode][s]["episode_curve"]) for s in sorted(row["runs"][mode])]
        curves = [c for c in curves if len(c)]
        if not curves:
            continue
        xs = curves[0][:, 0]
        ys = np.stack([np.interp(xs, c[:, 0], c[:, 1]) for c in curves])
        ax.plot(xs / 1e6, ys.mean(0), color=colour, lw=1.2, marker="o", ms=3,
                label=f"learned, {mode} pheromone (mean of {len(curves)} seeds; band: min-max)")
        ax.fill_between(xs / 1e6, ys.min(0), ys.max(0), color=colour, alpha=0.2, lw=0)
    ax.axhline(np.mean(row["baseline"]), color="green", ls=":", label="hand-written (evaluation)")
    ax.axhline(np.mean(row["random"]), color="grey", ls="--", label="random (evaluation)")
    ax.set_xlabel("agent-steps (millions)")
    ax.set_title("training: mean return of each batch of episodes (stochastic policy)", fontsize=9)
    ax.legend(fontsize=7, loc="best")
    # Evaluation: one dot per training seed (its mean over the evaluation episodes), the references'
    # episodes as a mean and sd.
    ax = axes[1]
    cols = [("with", "learned\nwith", "C0"), ("without", "learned\nwithout", "C1"), ("with_rates_off", "with,\nrates 0", "C2")]
    for i, (key, _, colour) in enumerate(cols):
        ax.scatter(np.full(len(row[key]), i), row[key], color=colour, s=18, zorder=3)
        ax.hlines(np.mean(row[key]), i - 0.25, i + 0.25, color=colour)
    for i, key in ((3, "baseline_episodes"), (4, "random_episodes")):
        ax.errorbar(i, np.mean(row[key]), yerr=np.std(row[key], ddof=1), fmt="s", color="k", ms=4, capsize=3)
    ax.set_xticks(range(5), [c[1] for c in cols] + ["hand-\nwritten", "random"], fontsize=7)
    ax.set_title(f"evaluation, {len(row['baseline_episodes'])} seeded episodes\ndots: training seeds (bar: mean);"
                 " squares: mean ± sd over episodes", fontsize=8)
    axes[0].set_ylabel("mean return per agent")
    fig.suptitle(f"colcos {task}: PPO with and without pheromone actions, {episode_steps(task, args)}-step episodes", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, f"stigmergy_{task}.png"), dpi=110)
    plt.close(fig)


def parse_param(p: argparse.ArgumentParser, flag: str, kv: str) -> tuple[str, object]:
    """`KEY=VALUE` with VALUE in JSON (`5`, `[[0.7, 0.6]]`, `"agent"`); a bare word is taken as a string."""
    key, sep, value = kv.partition("=")
    if not sep or not key:
        p.error(f"{flag} {kv!r}: expected KEY=VALUE")
    try:
        return key, json.loads(value)
    except json.JSONDecodeError:
        return key, value


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The study's settings from `argv` (the command line if None; `[]`: every default), `--param`
    and `--shaping` as dicts, `defaults` holding what a saved run that lacks a setting counts it as."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tasks", nargs="+", default=list(TASKS), choices=TASKS)
    p.add_argument("--modes", nargs="+", default=list(MODES), choices=MODES, help="train only these (a share of the work)")
    p.add_argument("--steps", type=int, default=2_000_000, help="training budget per run, agent-steps (rounded up to whole updates)")
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    p.add_argument("--num-envs", type=int, default=32)
    p.add_argument("--horizon", type=int, default=64, help="steps per rollout")
    p.add_argument("--episode", type=int, default=0, help="steps per episode, training and evaluation (0: the scenario's duration)")
    p.add_argument("--threads", type=int, default=1, help="env worker threads (1: reproducible, and fair on a shared machine)")
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument("--team-critic", action="store_true", help="the critic sees every agent's observation")
    p.add_argument("--anneal", action="store_true", help="the learning rate falls linearly to 0 over the budget")
    p.add_argument("--gamma", type=float, default=0.98, help="discount per step (0.98: about a second ahead)")
    p.add_argument("--eval-worlds", type=int, default=32)
    p.add_argument("--eval-seed", type=int, default=12345)
    p.add_argument("--eval-policy", choices=("mean", "sample"), default="mean",
                   help="evaluate the learned policies' mean action, or sample them as in training (an on/off call "
                        "whose mean stays below 0.5 never sounds in the mean action)")
    p.add_argument("--out", default="runs/stigmergy")
    p.add_argument("--verbose", type=int, default=0, metavar="K", help="print progress every K updates")
    p.add_argument("--twin-episodes", type=int, default=0, help="then run the first task's learned-with policy on the twin")
    p.add_argument("--twin-steps", type=int, default=0, help="steps per twin episode (0: as --episode)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="task parameter for training and evaluation, the value in JSON: food_amount=5, "
                        "'food=[[0.75, 0.65], [0.75, 0.16]]' (repeatable)")
    p.add_argument("--shaping", action="append", default=[], metavar="KEY=VALUE",
                   help="task parameter for training only (evaluation keeps the task's own reward): pickup_reward=1")
    p.add_argument("--start-forward", type=float, default=0.0, metavar="F",
                   help="the untrained policy drives forward at F (both wheels' mean output), not standing still")
    p.add_argument("--start-lay", type=float, default=0.0, metavar="F",
                   help="the untrained policy's mean deposit output (before clipping to [0, 1]): below 0 it lays rarely")
    p.add_argument("--listen-bias", type=float, default=0.0, metavar="W",
                   help="weight of a loss term rewarding wheels that respond to the pheromone the agents lay (the arm "
                        "with pheromone actions; ppo.Config.listen_bias)")
    p.add_argument("--signal-bias", type=float, default=0.0, metavar="W",
                   help="weight of a loss term rewarding a call that depends on what the caller senses (the arm with "
                        "pheromone actions; ppo.Config.signal_bias)")
    p.add_argument("--kickstart", type=int, default=0, metavar="STEPS",
                   help="before PPO the actor imitates the task's hand-written policy over STEPS agent-steps of it acting "
                        "(in the arm's own worlds: without pheromone actions nothing it lays is laid); 0: off")
    p.add_argument("--kickstart-std", type=float, default=0.2, help="the kickstarted actor's noise (sd of its Gaussian)")
    p.add_argument("--anchor", type=float, default=0.0, metavar="W",
                   help="with --kickstart: weight of a loss term keeping the actor near the imitated one during PPO "
                        "(ppo.Config.anchor)")
    p.add_argument("--actor-warmup", type=int, default=0, metavar="N",
                   help="the first N PPO updates train only the critic (for a kickstarted actor)")
    p.add_argument("--scenario", default=None, help="scenario file instead of the task's own (training and evaluation)")
    args = p.parse_args(argv)
    if args.kickstart < 0 or args.actor_warmup < 0 or not args.kickstart_std > 0 or not args.anchor >= 0:
        p.error(f"--kickstart ({args.kickstart}), --actor-warmup ({args.actor_warmup}) and --anchor ({args.anchor}) "
                f"must be at least 0, --kickstart-std ({args.kickstart_std}) above 0")
    args.defaults = {k: p.get_default(k) for k in vars(args)} | {"param": {}, "shaping": {}}
    for name in ("param", "shaping"):
        setattr(args, name, dict(parse_param(p, f"--{name}", kv) for kv in getattr(args, name)))
    return args


def main() -> None:
    args = parse_args()
    torch.set_num_threads(1)
    os.makedirs(args.out, exist_ok=True)
    results: dict = {"args": {k: v for k, v in vars(args).items() if k != "defaults"}, "tasks": {}}
    start = time.time()
    for task in args.tasks:
        row: dict = {"runs": {m: {} for m in args.modes}}
        for mode in args.modes:
            for seed in args.seeds:
                rec = run(task, mode, seed, args)
                row["runs"][mode][seed] = rec
                print(f"{task} {mode} seed {seed}: {np.mean(rec['eval']):.2f} (trained {rec['agent_steps']:,} agent-steps"
                      f" in {rec['updates']} updates, {rec['train_seconds']:.0f} s; {time.time() - start:.0f} s so far)", flush=True)
        for mode in args.modes:  # per training seed: the mean over the evaluation episodes
            row[mode] = [float(np.mean(row["runs"][mode][s]["eval"])) for s in args.seeds]
        if "with" in args.modes:
            row["with_rates_off"] = [float(np.mean(row["runs"]["with"][s]["eval_rates_off"])) for s in args.seeds]
        row["baseline_episodes"] = reference(task, "baseline", args)
        row["random_episodes"] = reference(task, "random", args)
        row["baseline"] = float(np.mean(row["baseline_episodes"]))
        row["random"] = float(np.mean(row["random_episodes"]))
        twin_file = pathlib.Path(args.out) / task / f"twin_seed{args.seeds[0]}.json"
        if twin_file.exists():  # from an earlier call with --twin-episodes
            row["twin"] = json.loads(twin_file.read_text())
        row["train_seconds"] = sum(r["train_seconds"] + r.get("eval_seconds", 0) for m in row["runs"].values() for r in m.values())
        results["tasks"][task] = row
    if set(args.modes) == set(MODES):
        print("\n| task | learned, with pheromone | learned, without | learned-with, rates forced to 0 | hand-written | random |")
        print("| --- | --- | --- | --- | --- | --- |")
        for task, row in results["tasks"].items():
            print(f"| `{task}` | {spread(row['with'])} | {spread(row['without'])} | {spread(row['with_rates_off'])} "
                  f"| {spread(row['baseline_episodes'])} | {spread(row['random_episodes'])} |")
        print(f"(mean return per agent over {args.eval_worlds} episodes, seed {args.eval_seed}, of "
              f"{', '.join(f'{episode_steps(t, args)} steps ({t})' for t in results['tasks'])};"
              f" learned: ± the sample sd across training seeds {args.seeds} of each seed's mean; hand-written and random: ± the sd"
              f" across the episodes; {args.steps:,} agent-steps per run)")
        for task, row in results["tasks"].items():
            gap, top = np.mean(row["with"]) - np.mean(row["without"]), max(sd(row["with"]), sd(row["without"]))
            se = np.sqrt(sd(row["with"]) ** 2 / len(row["with"]) + sd(row["without"]) ** 2 / len(row["without"]))
            row["with_minus_without"], row["largest_seed_sd"] = float(gap), top
            row["welch_t"] = float(gap / se) if se > 0 else None
            print(f"{task}: with - without = {gap:+.2f}; largest sd across seeds {top:.2f}; "
                  f"{'beats it by more than the spread' if gap > top else 'not more than the spread'}"
                  f"{f'; Welch t = {gap / se:.2f}' if se > 0 else ''}")
            ep_sd = [float(np.std(row["runs"][m][s]["eval"])) for m in MODES for s in args.seeds]
            print(f"  per seed with {np.round(row['with'], 2).tolist()}, without {np.round(row['without'], 2).tolist()};"
                  f" sd across the episodes of one learned policy {min(ep_sd):.2f} to {max(ep_sd):.2f}")
    results["wall_seconds"] = round(time.time() - start, 1)
    if args.twin_episodes:
        task, seed = args.tasks[0], args.seeds[0]
        res = twin(task, seed, args)
        results["twin"] = res
        print(f"{task} learned-with seed {seed}, {args.twin_episodes} episodes of {res['episode_steps']} steps from seed "
              f"{args.eval_seed}: simulator {spread(res['sim'])}, twin {spread(res['twin'])}")
    for task, row in results["tasks"].items():
        for mode in args.modes:  # keep result.json small: curves stay in the per-run files
            row["runs"][mode] = {s: {k: v for k, v in r.items() if k not in ("rate_curve", "episode_curve")}
                                 | {"curves": f"{task}/{mode}_seed{s}.json"} for s, r in row["runs"][mode].items()}
    with open(os.path.join(args.out, "result.json"), "w") as f:
        json.dump(results, f, indent=1)
    if set(args.modes) == set(MODES):
        for task in args.tasks:
            row = results["tasks"][task]
            row_full = dict(row, runs={m: {s: json.loads((pathlib.Path(args.out) / task / f"{m}_seed{s}.json").read_text())
                                           for s in args.seeds} for m in MODES})
            plot(task, row_full, args)
    print(f"saved {args.out}/result.json and the learning curves ({time.time() - start:.0f} s)")


if __name__ == "__main__":
    main()
