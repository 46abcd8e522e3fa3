"""`rally`, a task written only in Python: six agents look for a hidden spot and may call the others to it.

Each episode every world draws a spot (a disc of radius `spot_radius`) at random in its arena; nothing
marks it on the screen. An agent knows only whether it stands on the spot itself (one extra observation
entry, `on_spot`). Every agent carries a "call" emitter (a wide Gaussian source, green) that it
switches on and off with its third action entry: a call is the only way one agent can tell the others
where the spot is. Reward of every agent each step: the share of the team on the spot (so an episode's
return is the team's mean time on the spot, in steps; at most `max_cycles`).

`RallyCall` is the hand-written policy: on the spot, stop and call; else climb the call's gradient
where one is sensed; else a correlated random walk that turns away from bumps.

    python examples/tasks/rally.py      # 64 worlds of it: random actions, the hand-written policy, it without its call
"""

from __future__ import annotations

import pathlib
import tomllib

import numpy as np

import colcos

F32 = np.float32

SCENARIO = (pathlib.Path(__file__).parent / "rally.toml").read_text()  # six agents, each with a call


class Rally(colcos.Task):
    """Find a hidden spot, drawn anew each episode, as a team; the call is the only message."""

    name = "rally"
    scenario = SCENARIO
    prefill_static_maps = False
    obs_low, obs_high = (0.0,), (1.0,)  # one extra entry: on_spot (0 or 1)

    def __init__(self, spot_radius: float = 0.1, margin: float = 0.15, seed: int = 0) -> None:
        if not (0.0 < spot_radius and 0.0 <= margin):
            raise ValueError(f"rally: spot_radius ({spot_radius}) must be > 0 and margin ({margin}) >= 0")
        self.spot_radius2 = F32(spot_radius) * F32(spot_radius)
        self.margin = float(margin)
        self.seed = seed
        self.spots = np.zeros((0, 2), F32)  # (E, 2) the spot of each world's episode

    def reset(self, ctx: colcos.ResetContext) -> None:
        e = ctx.view.obs.shape[0]
        if len(self.spots) != e:
            self.spots = np.zeros((e, 2), F32)
        w, h = ctx.view.arena[:2]
        lo, hi = np.array([self.margin, self.margin]), np.array([w - self.margin, h - self.margin])
        if np.any(hi <= lo):
            raise ValueError(f"rally: margin {self.margin} m leaves no room in a {w} x {h} m arena")
        self.spots[ctx.worlds] = ctx.rng.uniform(lo, hi, (len(ctx.worlds), 2)).astype(F32)

    def _on_spot(self, view: colcos.View) -> np.ndarray:
        d = view.agents(view.poses)[..., :2] - self.spots[:, None, :]  # (E, N, 2)
        return (d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1]) <= self.spot_radius2

    def reward(self, view: colcos.View) -> np.ndarray:
        on = self._on_spot(view)
        share = on.mean(axis=1, dtype=F32)
        return np.broadcast_to(share[:, None], on.shape).astype(F32)

    def observe(self, view: colcos.View) -> np.ndarray:
        return self._on_spot(view)[..., None].astype(F32)

    def info(self, view: colcos.View) -> dict:
        return {"on_spot": self._on_spot(view).sum(axis=1), "spots": self.spots.copy()}


class RallyCall:
    """The hand-written rally policy over a batch of observations `(E, N, 18)`, as actions `(E, N, 3)`.

    Reads the sensors as the built-in policies do (right 0, front 1, left 2, back 3; three channels
    each, then three bumpers; entry 17 is `on_spot`). Keeps each agent's walk and pivot state."""

    CALL, HEARD, BUMP, PIVOT_STEPS, PIVOT_SPEED = 1, 0.02, 0.2, 10, 0.2

    def __init__(self, seed: int = 0) -> None:
        self.rng = np.random.default_rng(seed)
        self.turn = np.zeros(0, F32)
        self.pivot = np.zeros(0, np.int64)
        self.sign = np.zeros(0, F32)

    def act(self, obs: np.ndarray) -> np.ndarray:
        shape = obs.shape[:-1]
        o = obs.reshape(-1, obs.shape[-1])
        m = len(o)
        if len(self.turn) != m:
            self.turn, self.pivot, self.sign = np.zeros(m, F32), np.zeros(m, np.int64), np.zeros(m, F32)
        level = o[:, 0:12].reshape(m, 4, 3)[:, :, self.CALL]  # (M, 4 sensors)
        on = o[:, 17] > 0.5
        heard = level.mean(axis=1) > self.HEARD
        up = np.arctan2(level[:, 2] - level[:, 0], level[:, 1] - level[:, 3])  # rad from ahead, CCW
        climb = np.clip(0.5 * up, -0.3, 0.3)
        # The random walk's turn drifts slowly; bumps start a pivot away from the contact.
        self.turn = np.clip(0.9 * self.turn + 0.01 * self.rng.standard_normal(m), -0.05, 0.05).astype(F32)
        bumped = (self.pivot == 0) & (o[:, 12:15].max(axis=1) > self.BUMP)
        self.sign[bumped] = np.where(o[bumped, 12] > o[bumped, 14], -1.0, 1.0)
        self.pivot[bumped] = self.PIVOT_STEPS
        turn = np.where(heard, climb, self.turn)
        left, right = 1.0 - turn, 1.0 + turn
        pivoting = self.pivot > 0
        left = np.where(pivoting, -self.PIVOT_SPEED * self.sign, left)
        right = np.where(pivoting, self.PIVOT_SPEED * self.sign, right)
        self.pivot[pivoting] -= 1
        left, right = np.where(on, 0.0, left), np.where(on, 0.0, right)
        out = np.stack([np.clip(left, -1, 1), np.clip(right, -1, 1), on.astype(F32)], axis=-1)
        return out.astype(F32).reshape(*shape, 3)


if __name__ == "__main__":
    spec = tomllib.loads(SCENARIO)
    steps = round(spec["duration"] / spec["dt"])
    for label in ("random", "rally_call", "rally_call, call forced off"):
        env = colcos.vector.VecEnv(Rally(), num_envs=64, max_cycles=steps)
        obs, _ = env.reset(seed=0)
        rng, policy = np.random.default_rng(0), RallyCall(seed=0)
        total = np.zeros(64)
        for _ in range(steps):
            if label == "random":
                act = rng.uniform([-1, -1, 0], [1, 1, 1], (64, env.num_agents, 3)).astype(F32)
            else:
                act = policy.act(obs)
                if label.endswith("forced off"):
                    act[..., 2] = 0.0
            obs, rew, *_ = env.step(act)
            total += rew.mean(axis=1)
        print(f"{label}: mean return {total.mean():.1f} ± {total.std():.1f} of at most {steps}"
              " (the team's mean steps on the spot; ± the sd over the 64 episodes)")
