"""The policy of `ppo.py`'s PPO: the actor-critic network, its input normalisation, an actor's memory of
its last observations, and loading a saved policy (what evaluation, the transfer study and
`onboard_export.py` need without the trainer). Needs torch.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import torch
from torch import nn


LOG_2PI = float(np.log(2 * np.pi))
# softplus(0 + SOFTPLUS_BIAS) + 1e-4 = 1: a tanh actor's widths start at 1, as BenchMARL's.
SOFTPLUS_BIAS = float(np.log(np.expm1(1.0 - 1e-4)))


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
    """Gaussian actor on the agent's own observation; critic on observation + global state + agent id.

    With `history` = k > 1 the actor reads the agent's last k observations, oldest first (a `Memory`
    stacks them: `policy()` gives an acting function that keeps one). With `agents` = N > 0 it also
    sees which of the N agents it drives (a one-hot appended, `actor_input`): one network, but free to
    drive robots that differ (wheels, lags, sensor gains) each in its own way. `pi`, `obs_norm` and
    `log_std` are what a robot runs (`onboard_export.py` reads them by name; it takes only actors of
    the 17 observation entries).

    With `tanh`, the actor is BenchMARL's and IPPO's: `pi` also gives each action entry's width (a
    biased softplus of its second half: 1 at an output of 0), and the action is the tanh of the
    Gaussian sample (its mean's tanh when acting deterministically); `log_std` goes unused."""

    def __init__(self, obs_dim: int, critic_dim: int, act_dim: int = 2, hidden: int = 64, agents: int = 0,
                 history: int = 1, tanh: bool = False) -> None:  # fmt: skip
        super().__init__()
        self.agents, self.history, self.tanh, self.act_dim = agents, history, tanh, act_dim
        self.pi = mlp(obs_dim * history + agents, 2 * act_dim if tanh else act_dim, hidden)
        self.v = mlp(critic_dim, 1, hidden)
        self.log_std = nn.Parameter(torch.full((act_dim,), -0.5))
        self.obs_norm = RunningNorm(obs_dim * history + agents)
        self.critic_norm = RunningNorm(critic_dim)
        with torch.no_grad():  # small initial actions: the policy starts near "stand still", not saturated
            self.pi[-1].weight.mul_(0.01)
            self.pi[-1].bias.zero_()

    def actor_input(self, obs: np.ndarray, ids: np.ndarray | None = None) -> np.ndarray:
        """What the actor reads for observations `obs` (..., N, obs_dim): the observations, and with
        `agents` the one-hot of each row's agent appended. Rows along axis -2 are agents 0..N-1 unless
        `ids` (their agent indices, shape (N,)) says otherwise (a PettingZoo dict of the live agents)."""
        obs = np.asarray(obs, dtype=np.float32)
        if not self.agents:
            return obs
        if ids is None:
            if obs.ndim < 2 or obs.shape[-2] != self.agents:
                raise ValueError(f"an actor of {self.agents} agents needs observations (..., {self.agents}, obs) "
                                 f"or the agents' ids, got shape {obs.shape}")
            ids = np.arange(self.agents)
        ids = np.asarray(ids)
        if ids.shape != obs.shape[-2:-1] or ids.min(initial=0) < 0 or ids.max(initial=0) >= self.agents:
            raise ValueError(f"agent ids {ids.tolist()} for observations of shape {obs.shape}: one id in "
                             f"0..{self.agents - 1} per row")
        hot = np.broadcast_to(np.eye(self.agents, dtype=np.float32)[ids], (*obs.shape[:-1], self.agents))
        return np.concatenate([obs, hot], axis=-1)

    def head(self, obs: torch.Tensor) -> torch.Tensor:
        """What `pi` gives for raw actor inputs (`actor_input`; normalised here): the Gaussian's mean,
        and with `tanh` its widths' pre-activations after it."""
        return self.pi(self.obs_norm(obs))

    def mean(self, obs: torch.Tensor) -> torch.Tensor:
        """The Gaussian's mean for raw actor inputs (before the tanh, with `tanh`)."""
        return self.head(obs)[..., : self.act_dim]

    def log_stds(self, head: torch.Tensor) -> torch.Tensor:
        """Each action entry's log width for a `head` output: `log_std`, or with `tanh` the biased
        softplus of the head's second half (BenchMARL's `biased_softplus_1.0`, at least 1e-4)."""
        if not self.tanh:
            return self.log_std.expand(*head.shape[:-1], self.act_dim)
        return torch.log(nn.functional.softplus(head[..., self.act_dim :] + SOFTPLUS_BIAS) + 1e-4)

    def log_prob(self, obs: torch.Tensor, act: torch.Tensor, head: torch.Tensor | None = None) -> torch.Tensor:
        """log pi(act | obs) of the Gaussian sample `act` (before the tanh, with `tanh`: the tanh's
        Jacobian is the same for the old and the new policy, so it leaves PPO's ratio alone), summed
        over the action's entries: torch's `Normal(...).log_prob(act).sum(-1)` in fewer tensor
        operations (the update's hot path on small batches); `head`: `head(obs)` if known."""
        head = self.head(obs) if head is None else head
        log_std = self.log_stds(head)
        z = (act - head[..., : self.act_dim]) * torch.exp(-log_std)
        return -0.5 * (z * z).sum(-1) - log_std.sum(-1) - 0.5 * LOG_2PI * act.shape[-1]

    def value(self, critic_in: torch.Tensor) -> torch.Tensor:
        return self.v(self.critic_norm(critic_in)).squeeze(-1)

    def policy(self) -> Callable[..., np.ndarray]:
        """`act` for a stream of observations (one episode, or one per world of a batch): with a
        `history`, each call's observations join the last ones in a fresh `Memory`."""
        if self.history == 1:
            return self.act
        memory = Memory(self.history)
        return lambda obs, ids=None: self.act(memory.push(obs), ids)

    @torch.no_grad()
    def act(self, obs: np.ndarray, ids: np.ndarray | None = None) -> np.ndarray:
        """Deterministic action (the mean, clipped to [-1, 1]; its tanh with `tanh`) for observations of shape (..., obs_dim)
        ((..., N, obs_dim) with `agents`, or `ids` given: see `actor_input`; with a `history`, stacked
        observations: see `policy`)."""
        x = self.actor_input(obs, ids)
        o = torch.from_numpy(np.array(x, dtype=np.float32).reshape(-1, x.shape[-1]))
        mu = self.mean(o)
        a = torch.tanh(mu) if self.tanh else mu.clamp(-1, 1)
        return a.numpy().reshape(*x.shape[:-1], -1).astype(np.float32)

    @torch.no_grad()
    def sample(self, obs: np.ndarray, generator: torch.Generator, ids: np.ndarray | None = None) -> np.ndarray:
        """Stochastic action, as in training: the mean plus Gaussian noise of sd `exp(log_stds)` drawn
        from `generator`, unclipped (the env's action map clips it); its tanh with `tanh`."""
        x = self.actor_input(obs, ids)
        o = torch.from_numpy(np.array(x, dtype=np.float32).reshape(-1, x.shape[-1]))
        head = self.head(o)
        mu = head[..., : self.act_dim]
        a = mu + torch.exp(self.log_stds(head)) * torch.randn(mu.shape, generator=generator)
        a = torch.tanh(a) if self.tanh else a
        return a.numpy().reshape(*x.shape[:-1], -1).astype(np.float32)


class Memory:
    """The last `history` observations of every row, oldest first, flattened: what an actor with a
    history reads. A row's first observation (or one marked `fresh`: the first of a new episode)
    fills its whole history."""

    def __init__(self, history: int) -> None:
        self.history = history
        self.stack: np.ndarray | None = None

    def push(self, obs: np.ndarray, fresh: np.ndarray | None = None) -> np.ndarray:
        """Adds `obs` (..., obs_dim); returns (..., history * obs_dim). `fresh`: a mask over the rows
        (obs.shape[:-1]) that start again."""
        obs = np.asarray(obs, dtype=np.float32)
        if self.history == 1:
            return obs
        if self.stack is None or self.stack.shape[:-2] != obs.shape[:-1]:
            self.stack = np.repeat(obs[..., None, :], self.history, axis=-2)
        else:
            self.stack = np.concatenate([self.stack[..., 1:, :], obs[..., None, :]], axis=-2)
            if fresh is not None and fresh.any():
                self.stack[fresh] = obs[fresh][..., None, :]
        return self.stack.reshape(*obs.shape[:-1], -1)


def load_model(path: str, obs_dim: int, history: int = 1) -> ActorCritic:
    """A saved `ActorCritic` (its `state_dict`) of actors with `history`; its sizes (critic input,
    actions, hidden units, agent ids) read from the saved tensors; in evaluation mode."""
    state = torch.load(path)
    hidden, inputs = state["pi.0.weight"].shape
    act_dim = state["log_std"].shape[0]
    model = ActorCritic(obs_dim, state["v.0.weight"].shape[1], act_dim=act_dim, hidden=hidden,
                        agents=inputs - obs_dim * history, history=history, tanh=state["pi.4.weight"].shape[0] == 2 * act_dim)
    model.load_state_dict(state)
    model.eval()
    return model
