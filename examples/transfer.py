"""The transfer study: does a follower trained on identified robot values hold on robots that differ?

Trains three PPO aggregation followers with examples/train_aggregation.py, the same budget each
(`--updates` PPO updates, or wall-clock `--minutes`): (a) on the nominal values, (b) with generic
per-robot `[randomize]` ranges (wheel scales, motor lags, command latencies, sensor gains), (c) on the
identified values (`[individual] file = FIT`) with narrow randomisation around them. Evaluates each,
the hand-written follower and standing still on (i) the simulator with the nominal values
(`--eval-worlds` seeded worlds) and (ii) the digital twin started here whose robots drive and sense
with the hidden values of `--truth` while the host assumes the nominal ones and reads the robots' own
sensors (`--twin-episodes` real-time episodes each).
Transfer ratio = (twin return - twin floor) / (sim return - sim floor), standing still the floor.
Writes `OUT/table.md` and `OUT/result.json` (every episode's return).

    python examples/transfer.py --updates 2400 --twin-episodes 20 --out runs/transfer

`--benchmarl NAME=CHECKPOINT` adds a BenchMARL policy (`examples/benchmarl_run.py --scenario OUT/identified.toml`
trains one on a variant's scenario) to every column; `--variants` with no name leaves the PPO ones out.

The fit comes from `colcos rig excite` on a twin with the truth and `colcos rig identify`
(docs/transfer.md gives the commands; `examples/data/transfer/` holds the truth and the fit). Needs
torch; matplotlib for `OUT/transfer.png`. The twin episodes run in real time (20 ms a step).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np
import torch

import colcos
from colcos.baselines import Baseline
from colcos.vector import VecEnv

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sim_to_real_policies import sim_returns, stacked, twin_episode  # noqa: E402
from ppo import load_model  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data", "transfer")
# Generic ranges: wide enough to hold every robot of the truth, chosen without looking at the fit.
GENERIC = """
[randomize]
wheel_scale = [0.75, 1.15]
motor_lag_factor = [0.5, 2.5]
command_latency = [0.0, 0.1]
robot_sensor_gain = [0.6, 1.3]
"""
# Around the identified values: the fit's spread is a few per mill on scales, ~1 ms on lag and latency
# and nothing on sensor gain, but a real rig drifts, and the fit's latencies carry the pipeline's
# common offset (docs/identify.md), so the ranges are a few times wider than its uncertainties.
AROUND_FIT = """
[randomize]
wheel_scale = [0.97, 1.03]
motor_lag_factor = [0.85, 1.15]
command_latency = [-0.02, 0.02]
robot_sensor_gain = [0.95, 1.05]
"""
VARIANTS = ("nominal", "generic", "identified")


def write_scenarios(out: str, fit: str, truth: str) -> dict[str, str]:
    """The training scenarios (a, b, c), the host's scenario for the twin and the twin's truth."""
    base = colcos.parallel_env(task="aggregation")._core.scenario_toml()
    fit_line = f'\n[individual]\nfile = "{os.path.abspath(fit)}"\n'
    texts = {
        "nominal": base,
        "generic": base + GENERIC,
        "identified": base + fit_line + AROUND_FIT,
        "host": base + '\n[rig]\nsensors = "robot"\n',
        # The same rig with the fit undone in the bridge: commands over the wheel scales, counts back
        # through the sensor gains (`[rig] compensate`).
        "host_compensated": base + f'\n[rig]\nsensors = "robot"\ncompensate = "{os.path.abspath(fit)}"\n',
        "truth": base + f'\n[individual]\nfile = "{os.path.abspath(truth)}"\n',
    }
    paths = {}
    for name, text in texts.items():
        paths[name] = os.path.join(out, f"{name}.toml")
        with open(paths[name], "w") as f:
            f.write(text)
    return paths


def train(paths: dict[str, str], args: argparse.Namespace) -> None:
    """Trains each variant and seed with train_aggregation.py unless its policy.pt exists: `--updates`
    PPO updates each (the same samples for every variant, whatever the machine's load), or `--minutes`."""
    budget = ["--updates", str(args.updates)] if args.updates else ["--minutes", str(args.minutes)]
    threads = ["--threads", str(args.threads)] if args.threads else []
    flags = ["--anneal"] if args.anneal and args.updates else []
    flags += ["--agent-id"] if args.agent_id else []
    flags += ["--history", str(args.history)]
    # study and short are train_aggregation.py's 64-step recipe, ippo its default (whole episodes).
    flags += ["--recipe", "ippo" if args.learner == "ippo" else "short"]
    if args.learner == "study":
        # docs/transfer.md's tables were measured with one gradient norm, the critic on state and
        # agent id, and time limits worth 0 after the cut: these flags keep them reproducible.
        flags += ["--clip-together", "--no-own-critic", "--no-bootstrap-truncated"]
    flags += ["--holdout-worlds", "0"]  # this study evaluates every policy itself, on its own episodes
    for seed in args.seeds:
        for name in args.variants:
            d = os.path.join(args.out, f"{name}-s{seed}")
            if os.path.exists(os.path.join(d, "policy.pt")):
                continue
            subprocess.run([sys.executable, os.path.join(HERE, "train_aggregation.py"), *budget, *flags, *threads,
                            "--episode", str(args.episode), "--scenario", paths[name], "--seed", str(seed), "--out", d],
                           check=True)


def hand_written(env):
    """The hand-written follower on a twin episode (a fresh behaviour state each episode)."""
    follower = Baseline(env, "aggregation_follower")
    return lambda _env, _obs: follower.actions()


def policies(out: str, seeds: list[int], episode: int, history: int = 1, variants: tuple[str, ...] = VARIANTS) -> dict:
    """Every policy as (simulator act factory, twin act): PPO per variant and seed, references."""
    v = VecEnv("aggregation", num_envs=1, max_cycles=episode)
    d = v.single_observation_space.shape[0]
    table: dict = {}
    for seed in seeds:
        for name in variants:
            model = load_model(os.path.join(out, f"{name}-s{seed}", "policy.pt"), d, history)
            table[f"{name}-s{seed}"] = (lambda _v, m=model: m.policy(), stacked(model.policy))
    table["hand-written"] = (lambda v: Baseline(v, "aggregation_follower").act,
                             hand_written)
    table["standing still"] = (lambda v: (lambda o: np.zeros((v.num_envs, v.num_agents, 2), np.float32)),
                               lambda _env: (lambda env, _o: {a: np.zeros(2, np.float32) for a in env.agents}))
    return table


def benchmarl_policies(specs: list[tuple[str, str]], episode: int) -> dict:
    """BenchMARL runs' checkpoints (`examples/benchmarl_run.py`, `NAME=CHECKPOINT`) as (simulator act
    factory, twin act), each acting as BenchMARL evaluates it (its distribution's mode)."""
    if not specs:
        return {}
    from benchmarl.experiment import Experiment

    import benchmarl_run

    n = VecEnv("aggregation", num_envs=1, max_cycles=episode).num_agents
    table: dict = {}
    for name, path in specs:
        act = benchmarl_run.observation_policy(Experiment.reload_from_file(path))

        def twin_act(a=act):
            def run(obs: np.ndarray, ids: np.ndarray) -> np.ndarray:
                full = np.zeros((1, n, obs.shape[1]), np.float32)  # the group's layout; absent agents read zeros
                full[0, ids] = obs
                return a(full)[0, ids]

            return run

        table[name] = (lambda _v, a=act: a, stacked(twin_act))
    return table


def boot(rng, stat, *xs: np.ndarray) -> tuple[float, float, float]:
    """`stat` of the arrays and its bootstrap 5-95 % interval (each array resampled on its own)."""
    draws = [stat(*(x[rng.integers(0, len(x), len(x))] for x in xs)) for _ in range(4000)]
    lo, hi = np.percentile(draws, [5, 95])
    return float(stat(*xs)), float(lo), float(hi)


def ratio(tw: np.ndarray, sim: np.ndarray) -> float:
    """Transfer ratio from paired gains over standing still: twin episodes, simulator worlds."""
    return float(tw.mean() / sim.mean())


def twin_columns(args) -> dict[str, str]:
    """The twin's columns and the host scenario of each: as the bridge assumes the nominal robots,
    and (`--compensate`) with the fit undone in the bridge; `--compensated-only` runs the latter alone;
    none with `--twin-episodes 0` (the simulator's columns only)."""
    if args.twin_episodes == 0:
        return {}
    if args.compensated_only:
        return {"twin_compensated": "host_compensated"}
    return {"twin": "host", **({"twin_compensated": "host_compensated"} if args.compensate else {})}


def evaluate(paths: dict[str, str], args) -> dict:
    """Every policy's returns: simulator (nominal, truth) per world, twin per episode (interleaved),
    one twin pass per column of `twin_columns` over the same episodes."""
    table = policies(args.out, args.seeds, args.episode, args.history, tuple(args.variants))
    table.update(benchmarl_policies(args.benchmarl, args.episode))
    res: dict = {k: {} for k in table}
    for k, (sim_act, _) in table.items():
        for col in ("nominal", "truth"):
            res[k][f"sim_{col}"] = sim_returns(sim_act, paths[col], args.eval_worlds, args.episode, args.eval_seed)
    out: dict = {"returns": res}
    t0 = time.time()
    for col, host in twin_columns(args).items():
        for k in table:
            res[k][col] = []
        with colcos.parallel_env(task="aggregation", scenario=paths[host], plant="twin", twin_scenario=paths["truth"],
                                 max_cycles=args.episode) as env:
            for ep in range(args.twin_episodes):
                for k, (_, twin_act) in table.items():  # interleaved: a drift in the machine's load hits all alike
                    res[k][col].append(twin_episode(env, twin_act, 100 + ep))
                print(f"  {col} episode {ep + 1}/{args.twin_episodes} ({time.time() - t0:.0f} s): "
                      + ", ".join(f"{k} {v[col][-1]:.1f}" for k, v in res.items()), flush=True)
            out[f"{col}_stats"] = env.plant_info()
    return out


def report(result: dict, args) -> str:
    """The table: mean ± sd per cell; gains over standing still paired by episode (every policy
    starts each twin episode, and each simulator world, from the same seed); transfer ratios and
    differences with bootstrap 5-95 % intervals."""
    res, rng = result["returns"], np.random.default_rng(0)
    twins = list(twin_columns(args))
    floor = {c: np.array(res["standing still"][c]) for c in ("sim_nominal", *twins)}
    gain = {k: {c: np.array(r[c]) - floor[c] for c in floor} for k, r in res.items()}
    named = {"twin": "twin, truth", "twin_compensated": "twin, truth, compensated"}
    header = [f"simulator, nominal ({args.eval_worlds} worlds)", f"simulator, truth ({args.eval_worlds} worlds)"]
    header += [f"{named[c]} ({args.twin_episodes} episodes)" for c in twins]
    for c in twins:
        header += [f"{named[c]}: gain over standing still", f"{named[c]}: transfer ratio (5-95 %)"]
    lines = ["| policy | " + " | ".join(header) + " |", "| --- " * (len(header) + 1) + "|"]
    result["ratios"], result["differences"] = {c: {} for c in twins}, {}
    for k, r in res.items():
        cells = [f"{np.mean(r[c]):.1f} ± {np.std(r[c], ddof=1):.1f}" for c in ("sim_nominal", "sim_truth", *twins)]
        for c in twins:
            g = gain[k][c]
            cells.append(f"{g.mean():.1f} ± {np.std(g, ddof=1):.1f}")
            if k == "standing still":
                cells.append("(floor)")
            else:
                pt, lo, hi = boot(rng, ratio, g, gain[k]["sim_nominal"])
                result["ratios"][c][k] = [pt, lo, hi]
                cells.append(f"{pt:.2f} ({lo:.2f} to {hi:.2f})")
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    pairs = []  # (name, (policy, column), (policy, column)): a - b, paired by episode
    if set(VARIANTS) <= set(args.variants) and "twin" in twins:
        pairs += [(f"identified-s{seed} − {other}-s{seed}", (f"identified-s{seed}", "twin"), (f"{other}-s{seed}", "twin"))
                  for seed in args.seeds for other in ("nominal", "generic")]
    if "twin" in twins:
        bench = [name for name, _ in args.benchmarl]
        pairs += [(f"{k} − {bench[0]}", (k, "twin"), (bench[0], "twin")) for k in bench[1:]]
    if {"twin", "twin_compensated"} <= set(twins):
        pairs += [(f"{k}: compensated − not", (k, "twin_compensated"), (k, "twin")) for k in res if k != "standing still"]
    if pairs:
        lines += ["", "| on the twin, paired by episode | mean difference (5-95 %) |", "| --- | --- |"]
    for name, (a, ca), (b, cb) in pairs:
        pt, lo, hi = boot(rng, np.mean, np.array(res[a][ca]) - np.array(res[b][cb]))
        result["differences"][name.replace("−", "-")] = [pt, lo, hi]
        lines.append(f"| {name} | {pt:.1f} ({lo:.1f} to {hi:.1f}) |")
    return "\n".join(lines)


def figure(result: dict, path: str) -> None:
    """Bar chart: mean return per policy on the simulator and the twin, sd as error bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    res = result["returns"]
    names = list(res)
    x = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(8, 3.8))
    cols = [("sim_nominal", "simulator, nominal"), ("sim_truth", "simulator, truth"), ("twin", "twin, truth (real time)"),
            ("twin_compensated", "twin, truth, compensated")]
    cols = [c for c in cols if c[0] in res[names[0]]]
    width = 0.8 / len(cols)
    for i, (col, label) in enumerate(cols):
        ax.bar(x + (i - (len(cols) - 1) / 2) * width, [np.mean(res[n][col]) for n in names], width,
               yerr=[np.std(res[n][col], ddof=1) for n in names], label=label, capsize=2)
    ax.set_xticks(x, names, rotation=20, fontsize=8)
    ax.set_ylabel("mean return per follower")
    ax.set_title("colcos aggregation follower: sim-to-twin transfer")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--minutes", type=float, default=3.0, help="training budget of each policy, wall-clock")
    p.add_argument("--updates", type=int, default=None, help="training budget of each policy in PPO updates (instead of --minutes)")
    p.add_argument("--anneal", action="store_true", help="with --updates: the learning rate falls linearly to 0 over the budget")
    p.add_argument("--threads", type=int, default=None, help="env worker threads of each training run")
    p.add_argument("--episode", type=int, default=500, help="steps per episode (10 s)")
    p.add_argument("--seeds", type=int, nargs="+", default=[0])
    p.add_argument("--eval-worlds", type=int, default=32, help="simulator worlds (episodes) of each column")
    p.add_argument("--eval-seed", type=int, default=12345, help="seed of the simulator's evaluation worlds")
    p.add_argument("--twin-episodes", type=int, default=8, help="real-time twin episodes; 0: the simulator's columns only")
    p.add_argument("--fit", default=os.path.join(DATA, "fit.toml"))
    p.add_argument("--truth", default=os.path.join(DATA, "truth.toml"))
    p.add_argument("--agent-id", action="store_true",
                   help="each policy's actor also sees which follower it drives (train_aggregation.py --agent-id)")
    p.add_argument("--history", type=int, default=1,
                   help="each policy's actor reads its last K observations (train_aggregation.py --history)")
    p.add_argument("--variants", nargs="*", choices=VARIANTS, default=list(VARIANTS),
                   help="the PPO policies to train and evaluate (default: all three; none: the --benchmarl ones only)")
    p.add_argument("--benchmarl", action="append", default=[], metavar="NAME=CHECKPOINT",
                   help="also evaluate a BenchMARL run's checkpoint (examples/benchmarl_run.py) under NAME (repeatable; "
                        "the table compares each later one with the first on the twin)")
    p.add_argument("--compensate", action="store_true",
                   help="also evaluate every policy on the twin with the fit undone in the bridge ([rig] compensate)")
    p.add_argument("--compensated-only", action="store_true",
                   help="evaluate on the compensated twin only (the pass --compensate adds, without the other)")
    p.add_argument("--learner", choices=("study", "short", "ippo"), default="study",
                   help="study: the PPO settings docs/transfer.md's tables were trained with; short: "
                        "train_aggregation.py --recipe short as it is (IPPO's critic, the time-limit bootstrap); "
                        "ippo: its default recipe (BenchMARL's IPPO schedule: --updates 38 is its budget)")
    p.add_argument("--train-only", action="store_true")
    p.add_argument("--out", default="runs/transfer")
    args = p.parse_args()
    if args.updates is not None and args.updates < 1:
        p.error(f"--updates ({args.updates}) must be at least 1")
    if args.twin_episodes < 0:
        p.error(f"--twin-episodes ({args.twin_episodes}) must be at least 0")
    if args.twin_episodes == 0 and (args.compensate or args.compensated_only):
        p.error("--compensate and --compensated-only need twin episodes (--twin-episodes 0 was given)")
    if args.eval_worlds < 2:
        p.error(f"--eval-worlds ({args.eval_worlds}) must be at least 2 (a column's sd needs two)")
    if args.history < 1:
        p.error(f"--history ({args.history}) must be at least 1")
    specs = [spec.partition("=") for spec in args.benchmarl]
    for spec, (name, eq, path) in zip(args.benchmarl, specs):
        if not eq or not name:
            p.error(f"--benchmarl {spec!r}: expected NAME=CHECKPOINT")
        if not os.path.isfile(path):
            p.error(f"--benchmarl {spec!r}: no such checkpoint file {path!r}")
    args.benchmarl = [(name, path) for name, _, path in specs]
    names = [name for name, _ in args.benchmarl]
    taken = {f"{v}-s{seed}" for v in args.variants for seed in args.seeds} | {"hand-written", "standing still"}
    clash = sorted({n for n in names if names.count(n) > 1 or n in taken})
    if clash:
        p.error(f"--benchmarl: the name(s) {clash} are used twice or by another policy of the table")
    os.makedirs(args.out, exist_ok=True)
    paths = write_scenarios(args.out, args.fit, args.truth)
    train(paths, args)
    if args.train_only:
        return
    t0 = time.time()
    torch.set_num_threads(1)
    result = evaluate(paths, args)
    table = report(result, args)
    print(table)
    budget = f"{args.updates} updates{' (annealed)' if args.anneal else ''}" if args.updates else f"{args.minutes} min"
    stats = {k: v for k, v in result.items() if k.endswith("_stats")}
    trained_here = f"; PPO training {budget} each" if args.variants else ""
    print(f"evaluation {time.time() - t0:.0f} s{trained_here}; twin {stats}")
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table + "\n")
    trained = {}
    for k in os.listdir(args.out):
        rj = os.path.join(args.out, k, "result.json")
        if os.path.exists(rj):
            with open(rj) as f:
                trained[k] = json.load(f)
    with open(os.path.join(args.out, "result.json"), "w") as f:
        json.dump({**result, "trained": trained, "args": vars(args)}, f, indent=1, default=str)
    try:
        figure(result, os.path.join(args.out, "transfer.png"))
    except ImportError:
        print("matplotlib not installed: no PNG")


if __name__ == "__main__":
    main()
