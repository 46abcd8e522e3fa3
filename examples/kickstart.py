"""Kickstarting: a PPO actor first imitates a teacher policy (behaviour cloning), then trains on the
task's reward as usual. For tasks whose reward a Gaussian-noise learner never meets (`colony`: no
untrained agent ever carries food home), the teacher's demonstrations put the learner where the
reward is; what the learner then keeps, changes or loses of the teacher's behaviour is up to PPO.

`demonstrations(teacher, env_kwargs, worlds, steps, seed, to_env)` records the teacher acting in
its own env (the env gets the teacher's actions through `to_env`, so an ablation that forces some
outputs to 0 sees its own world); `imitate(model, obs, actions, low, high)` fits the actor's mean to
those actions (mean squared error on the actions clipped to the action box) and sets the actor's
noise. Used by `stigmergy.py --kickstart`. Needs torch.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import ppo
import torch
from colcos.vector import VecEnv


def demonstrations(teacher: Callable[[VecEnv], Callable[[np.ndarray], np.ndarray]], env_kwargs: dict, worlds: int,
                   steps: int, seed: int, to_env: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(observations, teacher actions) of about `steps` agent-steps: the teacher acting in `worlds` fresh
    worlds seeded `seed`, its actions sent to the env through `to_env`, recorded as it chose them."""
    env = VecEnv(num_envs=worlds, seed=seed, **env_kwargs)
    act = teacher(env)
    obs, _ = env.reset(seed=seed)
    xs, ys = [], []
    for _ in range(max(1, math.ceil(steps / (worlds * env.num_agents)))):
        a = np.asarray(act(obs), dtype=np.float32)
        xs.append(obs.reshape(-1, obs.shape[-1]).copy())
        ys.append(a.reshape(-1, a.shape[-1]).copy())
        obs, _, _, _, _ = env.step(to_env(a))
    return np.concatenate(xs), np.concatenate(ys)


def imitate(model: ppo.ActorCritic, obs: np.ndarray, actions: np.ndarray, low: np.ndarray, high: np.ndarray,
            epochs: int = 20, minibatch: int = 1024, lr: float = 1e-3, std: float = 0.2, seed: int = 0) -> list[float]:  # fmt: skip
    """Fits `model`'s actor mean to the teacher's `actions` (clipped to [low, high]) on `obs`; the
    observation normaliser learns the demonstrations' statistics first, and the actor's noise is set
    to `std`. Returns the mean squared error after each epoch."""
    g = torch.Generator().manual_seed(seed)
    x = torch.from_numpy(np.asarray(obs, dtype=np.float32))
    y = torch.from_numpy(np.clip(actions, low, high).astype(np.float32))
    model.obs_norm.update(x)
    opt = torch.optim.Adam(model.pi.parameters(), lr=lr)
    losses = []
    for _ in range(epochs):
        perm, total = torch.randperm(len(x), generator=g), 0.0
        for k in range(0, len(x), minibatch):
            idx = perm[k : k + minibatch]
            loss = (model.mean(x[idx]) - y[idx]).pow(2).mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float(loss.detach()) * len(idx)
        losses.append(total / len(x))
    with torch.no_grad():
        model.log_std.fill_(math.log(std))
    return losses
