"""Train a BenchMARL algorithm on a colcos task, then compare it with the task's hand-written policy
and random actions on the same measure (mean over agents and episodes of an agent's episode return).

    python examples/benchmarl_run.py --algorithm mappo --task aggregation --frames 600000 --seeds 0 1 2
    python examples/benchmarl_run.py --algorithm qmix --task aggregation --discrete --frames 300000
    python examples/benchmarl_run.py --algorithm masac --task colony --tiny          # one small iteration
    python examples/benchmarl_run.py --algorithm ippo --scenario robots.toml --lr 3e-4 # another scenario of the task
    python examples/benchmarl_run.py --evaluate CHECKPOINT --scenario truth.toml     # a trained policy again

Algorithms: BenchMARL's (`mappo`, `ippo`, `masac`, `isac`, `maddpg`, `iddpg`, `qmix`, `vdn`, `iql`,
...); tasks: `colcos.tasks()`. Each run writes BenchMARL's own outputs (CSV logs, marl-eval JSON,
the trained experiment's checkpoint without its replay buffer) under `--out`, and `summary.json` there
with every run's final evaluation return, its held-out return, its checkpoint, its wall time and the
references. Needs `benchmarl` (python-tests/requirements-benchmarl.txt).

`--evaluate CHECKPOINT` trains nothing: it reloads a run's checkpoint (`runs[i].checkpoint` in its
`summary.json`) and plays its policy and the task's hand-written reference on the held-out episodes,
of the scenario it trained on or of `--scenario FILE` (robots that differ, for instance), and prints
both. Without `--evaluate`, `--scenario FILE` trains and evaluates on that file in place of the task's
own scenario (the task's rewards and observations on other robots, fields or arenas).

`--ppo-settings` trains the on-policy algorithms (`mappo`, `ippo`) with the settings of colcos's own
PPO's short recipe (`examples/train_aggregation.py --recipe short`) instead of BenchMARL's defaults: batches of `--horizon` 64 steps of every
world, 4 passes of 4 minibatches over each, learning rate 1e-3, gamma 0.98, GAE lambda 0.95,
gradients clipped at 0.5 (docs/training.md: on `aggregation` MAPPO learned no better with them).
`--set KEY=VALUE` sets any field of the algorithm's BenchMARL config (`--set use_tanh_normal=false
--set entropy_coef=0.01`), typed as its default; an unknown field is refused, listing the known ones.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import sys
import time
from typing import Any

import colcos
import numpy as np
import torch
from benchmarl.algorithms import (
    IddpgConfig,
    IppoConfig,
    IqlConfig,
    IsacConfig,
    MaddpgConfig,
    MappoConfig,
    MasacConfig,
    QmixConfig,
    VdnConfig,
)
from benchmarl.experiment import Experiment, ExperimentConfig
from benchmarl.models.mlp import MlpConfig
from colcos.baselines import Baseline, RandomPolicy
from colcos.benchmarl import task as benchmarl_task
from colcos.vector import VecEnv

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ppo  # noqa: E402  (examples/ppo.py, beside this file)

ON_POLICY = ("mappo", "ippo")
ALGORITHMS: dict[str, Any] = {
    "mappo": MappoConfig,
    "ippo": IppoConfig,
    "masac": MasacConfig,
    "isac": IsacConfig,
    "maddpg": MaddpgConfig,
    "iddpg": IddpgConfig,
    "qmix": QmixConfig,
    "vdn": VdnConfig,
    "iql": IqlConfig,
}
# The hand-written reference of each task (colcos.behaviours() / colcos.task_policies()).
REFERENCE = {"aggregation": "aggregation_follower"}


def reference_policy(task: str) -> str | None:
    if task in REFERENCE:
        return REFERENCE[task]
    for name, (owner, _) in colcos.task_policies().items():
        if owner == task:
            return name
    return None


def episode_returns(task: str, make_policy: Any, max_steps: int, episodes: int, seed: int, continuous: bool = True,
                    scenario: str | None = None) -> np.ndarray:  # fmt: skip
    """Each episode's return averaged over its agents: an agent's summed reward over `max_steps` steps
    (on the task's own scenario, or `scenario`, a file)."""
    extra = {"scenario": scenario} if scenario else {}
    venv = VecEnv(task, num_envs=episodes, max_cycles=max_steps, autoreset_mode="disabled", continuous=continuous, **extra)
    venv.reset(seed=seed)
    policy = make_policy(venv)
    total = np.zeros((episodes, venv.num_agents))
    for _ in range(max_steps):
        _, rewards, _, _, _ = venv.step(policy())
        total += rewards
    return total.mean(axis=1)


def episode_return(task: str, make_policy: Any, max_steps: int, episodes: int, seed: int, scenario: str | None = None) -> float:
    """Mean over agents and episodes of an agent's summed reward over an episode of `max_steps` steps."""
    return float(episode_returns(task, make_policy, max_steps, episodes, seed, scenario=scenario).mean())


def held_out(task: str, make_policy: Any, args: argparse.Namespace, continuous: bool = True) -> dict[str, float]:
    """Mean and standard error over the `--holdout-worlds` held-out episodes (seed `--holdout-seed`;
    the same worlds whether the actions are continuous or not)."""
    return ppo.mean_and_se(episode_returns(task, make_policy, args.max_steps, args.holdout_worlds, args.holdout_seed, continuous,
                                           args.scenario))  # fmt: skip


def observation_policy(experiment: Experiment) -> Any:
    """The trained policy as BenchMARL evaluates it (deterministic: its distribution's mode, or the
    greedy action), as a function from observations `(worlds, agents, obs)` to actions."""
    from tensordict import TensorDict
    from torchrl.envs.utils import ExplorationType, set_exploration_type

    policy = experiment.policy

    def act(observations: np.ndarray) -> np.ndarray:
        obs = torch.as_tensor(np.array(observations, dtype=np.float32), device=experiment.config.sampling_device)
        group = TensorDict({"observation": obs}, batch_size=obs.shape[:2])
        with torch.no_grad(), set_exploration_type(ExplorationType.DETERMINISTIC):
            out = policy(TensorDict({"robot": group}, batch_size=obs.shape[:1]))
        return np.ascontiguousarray(out.get(("robot", "action")).cpu().numpy())

    return act


def trained_policy(experiment: Experiment) -> Any:
    """The trained policy acting in a colcos `VecEnv`: `make(venv)()` gives the actions for `venv.obs`."""
    act = observation_policy(experiment)
    return lambda venv: (lambda: act(venv.obs))  # `act` copies the observations once


def experiment_config(args: argparse.Namespace, out: pathlib.Path) -> ExperimentConfig:
    cfg = ExperimentConfig.get_from_yaml()
    cfg.max_n_frames = args.frames
    cfg.loggers = ["csv"]
    cfg.create_json = True  # marl-eval's JSON, which BenchMARL's plotting reads
    cfg.save_folder = str(out)
    # The trained policy (and critic and optimiser) at each evaluation and at the end, for `--evaluate`
    # and for a run that diverges: the latest only, no replay buffer.
    cfg.checkpoint_at_end = True
    cfg.exclude_buffer_from_checkpoint = True
    cfg.keep_checkpoints_num = 1
    cfg.prefer_continuous_actions = not args.discrete
    cfg.evaluation_episodes = args.eval_episodes
    # colcos steps all worlds of a batch in Rust: large batches of worlds, one collector.
    cfg.on_policy_n_envs_per_worker = cfg.off_policy_n_envs_per_worker = args.worlds
    cfg.on_policy_collected_frames_per_batch = cfg.off_policy_collected_frames_per_batch = args.worlds * args.max_steps
    if ppo_settings(args):
        # examples/ppo.py's: short rollouts of every world, a few passes of a few minibatches each.
        cfg.on_policy_collected_frames_per_batch = args.worlds * args.horizon
        cfg.on_policy_n_minibatch_iters = 4
        cfg.on_policy_minibatch_size = max(1, cfg.on_policy_collected_frames_per_batch // 4)
        cfg.lr, cfg.gamma, cfg.clip_grad_norm, cfg.clip_grad_val = 1e-3, 0.98, True, 0.5
    if args.lr is not None:
        cfg.lr = args.lr
    batch = cfg.on_policy_collected_frames_per_batch if args.algorithm in ON_POLICY else cfg.off_policy_collected_frames_per_batch
    cfg.evaluation_interval = batch * args.eval_every
    if args.tiny:
        cfg.max_n_iters = 1
        cfg.max_n_frames = cfg.on_policy_collected_frames_per_batch
        cfg.evaluation_interval = cfg.on_policy_collected_frames_per_batch
        cfg.on_policy_n_minibatch_iters = 1
        cfg.on_policy_minibatch_size = 64
        cfg.off_policy_n_optimizer_steps = 2
        cfg.off_policy_train_batch_size = 32
        cfg.off_policy_init_random_frames = 0
    cfg.checkpoint_interval = cfg.evaluation_interval
    return cfg


def algorithm_setting(algorithm: str, text: str) -> tuple[str, Any]:
    """`KEY=VALUE` for a field of the algorithm's BenchMARL config, the value parsed as the field's
    default is typed; an unknown field or a value of the wrong kind is refused, naming it."""
    key, sep, value = text.partition("=")
    defaults = vars(ALGORITHMS[algorithm].get_from_yaml())
    if not sep or key not in defaults:
        raise ValueError(f"--set {text!r}: expected KEY=VALUE with KEY one of {algorithm}'s settings {sorted(defaults)}")
    default = defaults[key]
    if default is None:  # an optional number (MASAC's min_alpha, max_alpha)
        if value.lower() in ("null", "none"):
            return key, None
        try:
            return key, float(value)
        except ValueError:
            raise ValueError(f"--set {text!r}: {key} takes a number or null") from None
    if isinstance(default, bool):
        if value.lower() not in ("true", "false"):
            raise ValueError(f"--set {text!r}: {key} takes true or false")
        return key, value.lower() == "true"
    try:
        return key, type(default)(value)
    except (TypeError, ValueError):
        raise ValueError(f"--set {text!r}: {key} takes a {type(default).__name__} like {default!r}") from None


def ppo_settings(args: argparse.Namespace) -> bool:
    """Whether this run takes examples/ppo.py's settings instead of BenchMARL's defaults."""
    return args.algorithm in ON_POLICY and args.ppo_settings and not args.tiny


def run(args: argparse.Namespace, seed: int, out: pathlib.Path) -> dict[str, Any]:
    task = benchmarl_task(args.task)
    task.config["max_steps"] = args.max_steps
    if args.scenario:
        task.config["scenario"] = os.path.abspath(args.scenario)
    algorithm = ALGORITHMS[args.algorithm].get_from_yaml()
    if ppo_settings(args):
        algorithm.lmbda = 0.95
    for key, value in args.set:
        setattr(algorithm, key, value)
    t0 = time.time()
    experiment = Experiment(
        task=task,
        algorithm_config=algorithm,
        model_config=MlpConfig.get_from_yaml(),
        critic_model_config=MlpConfig.get_from_yaml(),
        seed=seed,
        config=experiment_config(args, out),
    )
    diverged = None
    try:
        experiment.run()
    except colcos.ActionError as e:
        if "NaN" not in str(e):
            raise
        # BenchMARL's PPO can diverge to NaN actions (facebookresearch/BenchMARL#144): the run is
        # scored on its last checkpoint instead of losing it.
        diverged = f"the policy's actions became NaN after {experiment.total_frames} frames"
    wall = time.time() - t0
    checkpoints = sorted((pathlib.Path(experiment.folder_name) / "checkpoints").glob("*.pt"),
                         key=lambda p: int(p.stem.rpartition("_")[2]))  # fmt: skip
    scored = experiment
    if diverged:
        print(f"seed {seed}: {diverged}; scored on its last checkpoint"
              f" ({checkpoints[-1].name if checkpoints else 'none: not scored'})", file=sys.stderr)  # fmt: skip
        scored = Experiment.reload_from_file(str(checkpoints[-1])) if checkpoints else None
    held = held_out(args.task, trained_policy(scored), args, continuous=not args.discrete) if scored else None
    files = sorted(pathlib.Path(experiment.folder_name).rglob("*.json"))
    final = None
    if files:
        data = json.loads(files[-1].read_text())
        steps = data["colcos"][args.task][args.algorithm][f"seed_{seed}"]
        last = max((k for k in steps if k.startswith("step_")), key=lambda k: int(k.split("_")[1]))
        # "return": per evaluation episode, an agent's summed reward averaged over the agents.
        final = float(np.mean(steps[last]["return"]))
    return {"seed": seed, "final_return": final, "held_out": held, "wall_s": wall, "frames": experiment.total_frames,
            "folder": str(experiment.folder_name), "checkpoint": str(checkpoints[-1]) if checkpoints else None,
            "diverged": diverged}  # fmt: skip


def evaluate(args: argparse.Namespace) -> None:
    """`--evaluate`: a trained run's policy and the task's reference on the held-out episodes."""
    experiment = Experiment.reload_from_file(args.evaluate)
    task = experiment.task_name
    args.max_steps = int(experiment.task.config.get("max_steps", args.max_steps))
    continuous = experiment.continuous_actions
    args.scenario = args.scenario or experiment.task.config.get("scenario")  # default: the one it trained on
    where = args.scenario or f"the {task} scenario"
    policy = held_out(task, trained_policy(experiment), args, continuous=continuous)
    print(f"{experiment.algorithm_name} ({args.evaluate}) on {args.holdout_worlds} held-out episodes of {where}"
          f" (seed {args.holdout_seed}): {policy['mean']:.1f} ± {policy['se']:.1f}")  # fmt: skip
    name = reference_policy(task)
    if name is not None:
        ref = held_out(task, lambda v: Baseline(v, name).act, args)
        print(f"  {name}: {ref['mean']:.1f} ± {ref['se']:.1f} on the same episodes")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--algorithm", default="mappo", help=f"one of {sorted(ALGORITHMS)}")
    p.add_argument("--task", default="aggregation", help="a colcos task (colcos.tasks())")
    p.add_argument("--seeds", type=int, nargs="+", default=[0])
    p.add_argument("--frames", type=int, default=None,
                   help="world steps of training (BenchMARL's frames; default 1,474,560 = 720 batches of 32 x 64 with the "
                        "PPO settings, as the short recipe's 720 updates, else 600,000)")
    p.add_argument("--worlds", type=int, default=32, help="worlds stepped as one batch")
    p.add_argument("--max-steps", type=int, default=500, help="steps per episode")
    p.add_argument("--horizon", type=int, default=64, help="steps of every world per collected batch (PPO settings)")
    p.add_argument("--ppo-settings", action="store_true",
                   help="on-policy algorithms train with examples/ppo.py's batch, passes and learning rate, not BenchMARL's")
    p.add_argument("--eval-every", type=int, default=None,
                   help="evaluate every this many collected batches (default 60 with the PPO settings, else 5)")
    p.add_argument("--eval-episodes", type=int, default=8)
    p.add_argument("--holdout-worlds", type=int, default=1024,
                   help="after training, the policy and the references on this many held-out episodes (standard errors)")
    p.add_argument("--holdout-seed", type=int, default=777)
    p.add_argument("--discrete", action="store_true", help="the discrete action variant (continuous=False)")
    p.add_argument("--tiny", action="store_true", help="one small iteration (a check that it runs)")
    p.add_argument("--threads", type=int, default=1, help="torch threads")
    p.add_argument("--lr", type=float, default=None, help="learning rate (BenchMARL's default: 5e-5)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a setting of the algorithm's BenchMARL config, e.g. use_tanh_normal=false or entropy_coef=0.01 (repeatable)")
    p.add_argument("--out", default="runs/benchmarl")
    p.add_argument("--evaluate", default=None, metavar="CHECKPOINT",
                   help="train nothing: play a run's checkpoint (summary.json's runs[i].checkpoint) on the held-out episodes")
    p.add_argument("--scenario", default=None,
                   help="a scenario file in place of the task's own: to train and evaluate on, or with --evaluate to evaluate on")
    args = p.parse_args()
    if args.tiny and not args.evaluate:
        args.worlds, args.max_steps, args.eval_episodes, args.holdout_worlds = 2, 20, 1, 4
    if args.scenario and not os.path.isfile(args.scenario):
        p.error(f"--scenario {args.scenario!r}: no such file")
    if args.holdout_worlds < 2:
        p.error(f"--holdout-worlds {args.holdout_worlds}: at least 2 (a standard error needs two)")
    if args.evaluate:
        if not os.path.isfile(args.evaluate):
            p.error(f"--evaluate {args.evaluate!r}: no such checkpoint file")
        torch.set_num_threads(args.threads)
        evaluate(args)
        return
    if args.algorithm not in ALGORITHMS:
        p.error(f"--algorithm {args.algorithm!r}: one of {sorted(ALGORITHMS)}")
    if args.task not in colcos.tasks():
        p.error(f"--task {args.task!r}: one of {sorted(colcos.tasks())}")
    if args.scenario:
        try:
            VecEnv(args.task, num_envs=1, scenario=args.scenario)
        except (colcos.ScenarioError, colcos.TaskError) as e:
            p.error(f"--scenario {args.scenario!r}: {e}")
    try:
        args.set = [algorithm_setting(args.algorithm, kv) for kv in args.set]
    except ValueError as e:
        p.error(str(e))
    if args.horizon < 1:
        p.error(f"--horizon {args.horizon}: at least 1")
    if args.frames is None:
        args.frames = 720 * args.worlds * args.horizon if ppo_settings(args) else 600_000
    if args.eval_every is None:
        args.eval_every = 60 if ppo_settings(args) else 5
    torch.set_num_threads(args.threads)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = [run(args, seed, out) for seed in args.seeds]
    episodes = 32
    refs: dict[str, float] = {}
    name = reference_policy(args.task)
    if name is not None:
        refs[name] = episode_return(args.task, lambda v: Baseline(v, name).act, args.max_steps, episodes, 12345, args.scenario)
    refs["random"] = episode_return(args.task, lambda v: RandomPolicy(v, seed=1).act, args.max_steps, episodes, 12345, args.scenario)
    held_refs: dict[str, dict[str, float]] = {}
    if name is not None:
        held_refs[name] = held_out(args.task, lambda v: Baseline(v, name).act, args)
    finals = [r["final_return"] for r in runs if r["final_return"] is not None]
    summary = {"algorithm": args.algorithm, "task": args.task, "scenario": args.scenario, "continuous": not args.discrete,
               "settings": "examples/ppo.py" if ppo_settings(args) else "BenchMARL defaults",
               "algorithm_settings": dict(args.set), "frames": args.frames, "runs": runs, "references": refs,
               "held_out": {"worlds": args.holdout_worlds, "seed": args.holdout_seed, "references": held_refs}}
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    print(f"{args.algorithm} on {args.task} ({'discrete' if args.discrete else 'continuous'}), {args.frames} frames:")
    for r in runs:
        h = r["held_out"]
        scored = f"{h['mean']:.1f} ± {h['se']:.1f}" if h else "not scored"
        print(f"  seed {r['seed']}: final evaluation return {r['final_return']}, {r['wall_s']:.0f} s;"
              f" {args.holdout_worlds} held-out episodes {scored}" + (f" ({r['diverged']})" if r["diverged"] else ""))  # fmt: skip
    if finals:
        print(f"  median {np.median(finals):.1f}, spread {np.min(finals):.1f} .. {np.max(finals):.1f}")
    for k, v in refs.items():
        print(f"  {k}: {v:.1f} (same measure, {episodes} episodes)")
    for k, h in held_refs.items():
        print(f"  {k}: {h['mean']:.1f} ± {h['se']:.1f} on the held-out episodes")


if __name__ == "__main__":
    main()
