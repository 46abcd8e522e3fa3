"""The built-in `coverage` task written as a `colcos.Task`: the arena is cut into square cells and
the team is paid for each cell it enters for the first time in an episode. The cells covered so far
in each world are the task's per-episode state, a numpy array cleared by `reset` for the worlds
starting an episode. It gives exactly the Rust task's rewards (a test checks it over 1,000 steps).

    python examples/tasks/coverage.py      # 256 worlds of it, and the cells they covered
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import colcos
from _common import Rewrite, random_steps

F32 = np.float32


class Coverage(Rewrite, builtin="coverage", prefill=False):

    def __init__(self, cell: float = 0.05, cell_reward: float = 1.0, bump_penalty: float = 0.0) -> None:
        self.cell = F32(cell)
        self.cell_reward = F32(cell_reward)
        self.bump_penalty = F32(bump_penalty)
        self.cols = self.rows = 0
        self.covered = np.zeros((0, 0), np.bool_)  # (E, rows * cols): entered this episode
        self.count = np.zeros(0, np.int64)  # (E,) cells covered this episode

    def reset(self, ctx: colcos.ResetContext) -> None:
        # The grid: ceil(arena / cell) cells a side, computed in float32 as the Rust task does.
        w, h = F32(ctx.view.arena[0]), F32(ctx.view.arena[1])
        self.cols = max(math.ceil(w / self.cell), 1)
        self.rows = max(math.ceil(h / self.cell), 1)
        e = ctx.view.obs.shape[0]
        if self.covered.shape != (e, self.rows * self.cols):
            self.covered = np.zeros((e, self.rows * self.cols), np.bool_)
            self.count = np.zeros(e, np.int64)
        self.covered[ctx.worlds] = False
        self.count[ctx.worlds] = 0

    def reward(self, view: colcos.View) -> np.ndarray:
        p = view.agents(view.poses)  # (E, N, 3)
        inv = F32(1.0) / self.cell
        # A robot pushed onto the edge counts in the edge cell; float32 -> integer truncates.
        c = np.minimum(np.maximum(p[..., 0] * inv, F32(0.0)).astype(np.int64), self.cols - 1)
        r = np.minimum(np.maximum(p[..., 1] * inv, F32(0.0)).astype(np.int64), self.rows - 1)
        cell = r * self.cols + c  # (E, N)
        # Only worlds that moved are evaluated (one that just started an episode keeps its state).
        moved = view.stepped
        worlds = np.arange(len(moved))
        new = np.zeros(len(moved), np.int64)
        # Agent by agent, over all worlds at once: two agents entering one new cell count it once.
        for k in range(cell.shape[1]):
            fresh = moved & ~self.covered[worlds, cell[:, k]]
            self.covered[worlds[fresh], cell[fresh, k]] = True
            new += fresh
        self.count += new
        team = self.cell_reward * new.astype(F32)
        bump = np.maximum(view.bumpers.max(axis=-1), F32(0.0))
        return team[:, None] - self.bump_penalty * bump

    def info(self, view: colcos.View) -> dict[str, Any]:
        return {"covered": self.count.copy()}


if __name__ == "__main__":
    *_, infos = list(random_steps(Coverage(), 256, 3000, 1000))[-1]
    print(f"mean cells covered in 1,000 steps, over 256 worlds: {infos['task']['covered'].mean():.1f}")
