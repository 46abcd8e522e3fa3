"""What do the learned agents of a study say, and when? For each learned-with policy of a
`examples/stigmergy.py` study, on its evaluation episodes (sampled as the study evaluated them, or the
mean action), the share of agent-steps on which each deposit action is on (a rate above 0.5, an
emitter switched on), split by the task's flag (entry 17: `carrying` for `colony`, `predator_near`
for `alarm`, `on_spot` for `rally`), and the mean forward speed (`|left + right| / 2`, a fraction of
full speed) split the same way. A message is informative when it is sent more with the flag
than without.

    python examples/stigmergy_probe.py --out runs/stigmergy/rally_team --task rally
"""

from __future__ import annotations

import argparse
import json
import pathlib

import numpy as np
import torch
from colcos.vector import VecEnv

import ppo
import stigmergy


def probe(folder: pathlib.Path, seed: int, task: str, worlds: int) -> dict:
    saved = json.loads((folder / f"with_seed{seed}.json").read_text())
    cfg = stigmergy.parse_args([])  # every default, for the settings an older run's file lacks
    vars(cfg).update(saved["config"], threads=1)
    steps = stigmergy.episode_steps(task, cfg)
    env = VecEnv(num_envs=worlds, max_cycles=steps, num_threads=1, **stigmergy.task_kwargs(task, cfg, training=False))
    d, w = env.single_observation_space.shape[0], env.single_action_space.shape[0]
    if d < 18:
        raise SystemExit(f"{task} has no flag entry to split by (observation width {d})")
    model = ppo.ActorCritic(d, ppo.critic_dim(env, bool(cfg.team_critic)), act_dim=w)
    model.load_state_dict(torch.load(folder / f"with_seed{seed}.pt"))
    act = stigmergy.acting(model, True, cfg)(env)
    obs, _ = env.reset(seed=cfg.eval_seed)
    lay = np.zeros((2, w - 2))
    speed, count = np.zeros(2), np.zeros(2)
    for _ in range(steps):
        a = act(obs)
        flag = (obs[..., 17] > 0.5).astype(int)
        for f in (0, 1):
            sel = flag == f
            count[f] += sel.sum()
            lay[f] += (a[..., 2:][sel] > 0.5).sum(axis=0)
            speed[f] += np.abs(a[..., :2][sel].sum(axis=-1) / 2).sum()
        obs, *_ = env.step(a)
    count = np.maximum(count, 1)
    return {"seed": seed, "agent_steps": count.astype(int).tolist(), "lay_without_flag": (lay[0] / count[0]).tolist(),
            "lay_with_flag": (lay[1] / count[1]).tolist(), "speed_without_flag": speed[0] / count[0],
            "speed_with_flag": speed[1] / count[1]}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, help="the study's folder (stigmergy.py --out)")
    p.add_argument("--task", required=True, choices=[t for t in stigmergy.TASKS if t != "coverage"])
    p.add_argument("--worlds", type=int, default=16, help="evaluation episodes per policy")
    args = p.parse_args()
    torch.set_num_threads(1)
    folder = pathlib.Path(args.out) / args.task
    seeds = sorted(int(f.stem.removeprefix("with_seed")) for f in folder.glob("with_seed*.pt"))
    if not seeds:
        raise SystemExit(f"no learned-with policy under {folder}")
    print("| seed | flag: share of agent-steps | lay, flag off | lay, flag on | speed, flag off | speed, flag on |")
    print("| --- | --- | --- | --- | --- | --- |")
    rows = []
    for seed in seeds:
        r = probe(folder, seed, args.task, args.worlds)
        rows.append(r)
        share = r["agent_steps"][1] / sum(r["agent_steps"])
        fmt = lambda xs: ", ".join(f"{x:.2f}" for x in xs)
        print(f"| {seed} | {share:.3f} | {fmt(r['lay_without_flag'])} | {fmt(r['lay_with_flag'])} "
              f"| {r['speed_without_flag']:.2f} | {r['speed_with_flag']:.2f} |", flush=True)
    (folder / "probe.json").write_text(json.dumps(rows, indent=1))
    print(f"saved {folder / 'probe.json'}")


if __name__ == "__main__":
    main()
