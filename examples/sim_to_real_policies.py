"""A policy trained with and without domain randomisation, run on a twin whose latency and sensors differ
from training: the mean return per follower in each case.

Trains two PPO policies for the aggregation task with examples/train_aggregation.py (the task's own
scenario, and the same with a `[randomize]` section over tracker latency, sensor gain and crosstalk),
then evaluates each, and the hand-written follower and standing still, on (i) the simulator with the
training values (`--eval-worlds` seeded worlds) and (ii) the digital twin started here, whose tracker
is `TWIN_LATENCY` s late and whose colour sensors have 70 % of the gain and more crosstalk, with the
host reading the robots' own sensors (`[rig] sensors = "robot"`, telemetry) and compensating nothing
(`--twin-episodes` real-time episodes each). Writes `OUT/table.md` and `OUT/result.json`.

    python examples/sim_to_real_policies.py --minutes 2 --out runs/sim_to_real

Needs torch. The twin episodes run in real time (20 ms a step).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
import tomllib

import numpy as np

import colcos
from colcos.baselines import Baseline
from colcos.vector import VecEnv

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ppo import episode_returns, load_model  # noqa: E402

TWIN_LATENCY = 0.15
RANDOMIZE = """
[randomize]
tracker_latency = [0.02, 0.2]
sensor_gain = [0.6, 1.4]
crosstalk = [0.0, 0.15]
"""


def twin_values(base: dict) -> dict:
    """The twin's true values: a late tracker, weaker sensors with more crosstalk."""
    sensor = base["sensor"]
    cross = [[v if i == j else v + 0.1 for j, v in enumerate(row)] for i, row in enumerate(sensor["crosstalk"])]
    return {"tracker.latency": TWIN_LATENCY, "sensor.gain": 0.7 * sensor["gain"], "sensor.crosstalk": cross}


def sim_returns(act, scenario: str, worlds: int, steps: int, seed: int) -> list[float]:
    """Each world's mean return per follower over `worlds` seeded episodes on the simulator."""
    return episode_returns(act, {"task": "aggregation", "scenario": scenario}, worlds, steps, seed)


def on_sim(act, scenario: str, worlds: int, steps: int, seed: int) -> float:
    """Mean return per follower over `worlds` seeded episodes on the simulator."""
    return float(np.mean(sim_returns(act, scenario, worlds, steps, seed)))


def twin_episode(env, make, seed: int) -> float:
    """One episode on a twin `parallel_env`: the mean return per follower. `make(env)`, called once
    per episode (a behaviour keeps state), gives `act(env, obs)`: the PettingZoo action dict."""
    obs, _ = env.reset(seed=seed)
    act = make(env)
    total = 0.0
    while env.agents:
        obs, rew, _, _, _ = env.step(act(env, obs))
        total += float(np.mean(list(rew.values()))) if rew else 0.0
    return total


def stacked(make_act):
    """A policy on stacked observations (agents, obs) as a `make(env)` for twin_episode: `make_act()`
    gives, fresh each episode, `act(obs, ids)` of the live agents' observations and indices."""

    def make(_env):
        act = make_act()

        def run(env, obs):
            ids = np.array([env.possible_agents.index(a) for a in env.agents])
            acts = act(np.stack([obs[a] for a in env.agents]), ids)
            return {a: acts[i] for i, a in enumerate(env.agents)}

        return run

    return make


def on_twin(make_act, scenario: str, twin, episodes: int, steps: int, seed: int) -> float:
    """Mean return per follower over `episodes` real-time episodes on the twin started here
    (`make_act`: see `stacked`)."""
    with colcos.parallel_env(task="aggregation", scenario=scenario, plant="twin", twin_scenario=twin, max_cycles=steps) as env:
        return float(np.mean([twin_episode(env, stacked(make_act), seed + k) for k in range(episodes)]))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--minutes", type=float, default=2.0, help="training budget of each policy")
    p.add_argument("--episode", type=int, default=500, help="steps per episode (10 s)")
    p.add_argument("--eval-worlds", type=int, default=16)
    p.add_argument("--twin-episodes", type=int, default=2)
    p.add_argument("--out", default="runs/sim_to_real")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    base_text = colcos.parallel_env(task="aggregation")._core.scenario_toml()
    base = tomllib.loads(base_text)
    plain_path = os.path.join(args.out, "train.toml")
    rand_path = os.path.join(args.out, "train_randomized.toml")
    host_path = os.path.join(args.out, "host_robot_sensors.toml")
    for path, text in ((plain_path, base_text), (rand_path, base_text + RANDOMIZE),
                       (host_path, base_text + '\n[rig]\nsensors = "robot"\n')):
        with open(path, "w") as f:
            f.write(text)
    here = os.path.dirname(os.path.abspath(__file__))
    for name, scen in (("plain", plain_path), ("randomized", rand_path)):
        out = os.path.join(args.out, name)
        if not os.path.exists(os.path.join(out, "policy.pt")):
            subprocess.run([sys.executable, os.path.join(here, "train_aggregation.py"), "--minutes", str(args.minutes),
                            "--recipe", "short", "--no-own-critic", "--no-bootstrap-truncated", "--episode", str(args.episode), "--scenario", scen, "--out", out], check=True)
    v = VecEnv("aggregation", num_envs=1, max_cycles=args.episode)
    d = v.single_observation_space.shape[0]
    models = {name: load_model(os.path.join(args.out, name, "policy.pt"), d) for name in ("plain", "randomized")}
    twin = twin_values(base)
    rows = []
    t0 = time.time()
    for name, model in models.items():
        sim = on_sim(lambda _v, m=model: m.policy(), plain_path, args.eval_worlds, args.episode, 12345)
        tw = on_twin(model.policy, host_path, twin, args.twin_episodes, args.episode, 100)
        rows.append((f"PPO, {name}", sim, tw))
    hand = on_sim(lambda v: Baseline(v, "aggregation_follower").act, plain_path, args.eval_worlds, args.episode, 12345)
    still = on_sim(lambda v: (lambda o: np.zeros((v.num_envs, v.num_agents, 2), np.float32)), plain_path,
                   args.eval_worlds, args.episode, 12345)
    still_twin = on_twin(lambda: (lambda o, _ids: np.zeros((o.shape[0], 2), np.float32)), host_path, twin, args.twin_episodes, args.episode, 100)
    rows += [("hand-written follower", hand, None), ("standing still", still, still_twin)]
    lines = [
        f"| policy | simulator, training values ({args.eval_worlds} worlds) | twin: tracker {TWIN_LATENCY} s, "
        f"sensor gain x0.7, crosstalk +0.1, robot sensors ({args.twin_episodes} episodes) |",
        "| --- | --- | --- |",
    ]
    lines += [f"| {r[0]} | {r[1]:.2f} | {'-' if r[2] is None else f'{r[2]:.2f}'} |" for r in rows]
    table = "\n".join(lines)
    print(table)
    print(f"evaluation {time.time() - t0:.0f} s; training {args.minutes} min each")
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table + "\n")
    with open(os.path.join(args.out, "result.json"), "w") as f:
        json.dump({"rows": rows, "twin": twin, "minutes": args.minutes, "episode": args.episode}, f, indent=1)


if __name__ == "__main__":
    main()
