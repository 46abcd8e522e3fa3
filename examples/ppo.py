"""PPO with parameter sharing over colcos's batched `VecEnv`: the trainer the examples share.

All agents of all worlds share one policy; each (world, agent) pair is one sample stream. The actor sees
only the agent's own observation (running z-score); the critic, used only in training, also sees the
global state (`infos["state"]`) and a one-hot agent id (with `Config.own_critic`, the observation
alone, as IPPO's; with `Config.bootstrap_truncated`, an episode cut by its time limit bootstraps from
its final observation's value instead of ending at 0). One `Trainer.iterate()` collects a rollout of
`horizon` steps of every stream and runs `epochs` x `minibatches` clipped-PPO steps on it; a budget is
a whole number of those updates, so a loaded machine changes the time a run takes, not its result.

Used by `train_aggregation.py` (the quick start), `stigmergy.py` and, through the former, `transfer.py`
and `onboard_export.py`; the network itself is in `ppo_model.py`. Needs torch.
"""

from __future__ import annotations

import copy
import dataclasses
import os
import time
from collections.abc import Callable, Sequence

import numpy as np

# Intel's MKL (torch's matrix products on x86) splits a product's sums over threads unless told not to:
# strict reproducibility keeps the update's result the same on any number of threads (read at MKL's
# first call, so before any product runs; a 1,200-row weight gradient 1.3x slower on one thread, the same on two).
os.environ.setdefault("MKL_CBWR", "AUTO,STRICT")
import torch  # noqa: E402
from colcos.vector import VecEnv
from torch import nn

# The policy lives in ppo_model.py; its names stay importable from here.
from ppo_model import LOG_2PI, SOFTPLUS_BIAS, ActorCritic, Memory, RunningNorm, load_model, mlp  # noqa: F401


def critic_input(obs: np.ndarray, state: np.ndarray, team: bool = False, own: bool = False) -> np.ndarray:
    """(E, N, obs) and (E, S) -> (E * N, obs + S + N): own observation, global state, one-hot agent id;
    with `team`, then every agent's observation too (+ N * obs: what the whole team senses, such as
    who stands where a task pays, which the poses alone do not say). With `own`, the own observation
    only (E * N, obs): an independent learner's critic, as IPPO's."""
    e, n, d = obs.shape
    if own:
        return np.ascontiguousarray(obs, dtype=np.float32).reshape(e * n, d)
    s = np.broadcast_to(state[:, None, :], (e, n, state.shape[-1]))
    ids = np.broadcast_to(np.eye(n, dtype=np.float32)[None], (e, n, n))
    parts = [obs, s, ids]
    if team:
        parts.append(np.broadcast_to(obs.reshape(e, 1, n * d), (e, n, n * d)))
    return np.concatenate(parts, axis=-1, dtype=np.float32).reshape(e * n, -1)


def critic_dim(env: VecEnv, team: bool = False, own: bool = False) -> int:
    """The width of `critic_input` for `env`'s observations and state."""
    n, d = env.num_agents, env.single_observation_space.shape[0]
    if own:
        return d
    return d + env.state_space.shape[0] + n + (n * d if team else 0)


@dataclasses.dataclass
class Config:
    """PPO's settings; the defaults are `train_aggregation.py --recipe short`'s (see docs/python.md,
    "Training") but for `own_critic` and `bootstrap_truncated`, which `train_aggregation.py` turns on
    (the other examples' documented studies were measured with both off)."""

    horizon: int = 64  # steps of every stream per rollout
    epochs: int = 4
    minibatches: int = 4
    lr: float = 1e-3
    gamma: float = 0.98
    lam: float = 0.95
    clip: float = 0.2
    ent_coef: float = 0.0
    hidden: int = 64
    anneal: int = 0  # with N > 0, the learning rate falls linearly to 0 over N updates (the budget)
    # With K > 0, the learning rate adapts to keep each minibatch step's KL divergence near K (rl_games'
    # "adaptive" schedule): divided by 1.5 above 2 K, multiplied by 1.5 below K / 2, within [1e-5, 1e-2].
    target_kl: float = 0.0
    agent_id: bool = False  # the actor also sees which agent it drives (a one-hot: ActorCritic's `agents`)
    history: int = 1  # the actor reads the last `history` observations (ActorCritic's `history`)
    anchor: float = 0.0  # weight of a term keeping the actor's mean near the one `Trainer.set_anchor` froze
    actor_warmup: int = 0  # the first N updates train only the critic (an actor that starts good, e.g. kickstarted, keeps still)
    team_critic: bool = False  # the critic sees every agent's observation (critic_input's `team`)
    own_critic: bool = False  # the critic sees only the agent's own observation (critic_input's `own`)
    # IPPO's objective (BenchMARL's ClipPPOLoss: normalize_advantage=False, no reward scaling): with
    # `raw_advantages` the advantages are not standardised over the batch, with `raw_rewards` the
    # rewards are not divided by the running std of the discounted return.
    raw_advantages: bool = False
    raw_rewards: bool = False
    # The actor's and the critic's inputs as the env gives them (BenchMARL's default): their running
    # z-scores are never updated, so they stay the identity (within their clamp at +-10).
    raw_observations: bool = False
    # Truncated episodes (the time limit) bootstrap from their final observation's value, as TorchRL's
    # and SB3's PPO do; off, a truncation is treated as a termination (the value after it is 0).
    bootstrap_truncated: bool = False
    tanh: bool = False  # BenchMARL's actor: tanh of a Gaussian of learned, observation-dependent widths (ActorCritic's `tanh`)
    # Clip the actor's and the critic's gradients to `grad_norm` each, instead of one norm over both (where a
    # large critic error shrinks the actor's step with it).
    clip_apart: bool = False
    grad_norm: float = 0.5  # the gradient norm clipping keeps (each, with `clip_apart`)
    start_forward: float = 0.0  # the untrained actor's mean for both wheels: > 0 drives forward, an exploration prior
    start_lay: float = 0.0  # the untrained actor's mean for the outputs after the wheels (deposit rates): < 0 lays rarely
    # Biases for learned communication (Eccles et al. 2019, "Biases for emergent communication in multi-agent
    # RL"), both 0 (off) by default. `listen_bias`: reward wheels that respond to the message, the L1 distance
    # between the wheel means and those with `message_inputs` (observation entries) at their mean. `signal_bias`:
    # reward a message that depends on the observation, the mutual information between observation and
    # sending (output `message_output` above `message_threshold`) over the minibatch.
    listen_bias: float = 0.0
    signal_bias: float = 0.0
    message_inputs: tuple[int, ...] = ()
    message_output: int = 2
    message_threshold: float = 0.5
    # torch threads for the update (the rollout keeps the caller's): its minibatches of ~1,000 rows
    # are big enough to share (1.4x faster on two cores), and the result is the same for any number.
    learn_threads: int = 1
    # The loss through torch.compile and Adam as one fused kernel: a faster update, not the same bits.
    compile: bool = False


def clip_gradients(model: ActorCritic, apart: bool, norm: float = 0.5) -> None:
    """Clips the gradients to `norm`: one norm over actor and critic, or (`apart`) each its own."""
    # foreach: the norms and the scaling in one call per group (the same bits as one tensor at a time).
    if apart:
        nn.utils.clip_grad_norm_([*model.pi.parameters(), model.log_std], norm, foreach=True)
        nn.utils.clip_grad_norm_(model.v.parameters(), norm, foreach=True)
    else:
        nn.utils.clip_grad_norm_(model.parameters(), norm, foreach=True)


def clip_wheels(a: np.ndarray) -> np.ndarray:
    """A policy's raw Gaussian sample as the env's wheel commands, clipped to [-1, 1]."""
    return np.clip(a, -1.0, 1.0).astype(np.float32)


class Trainer:
    """PPO on one `VecEnv`: `iterate()` is one rollout and one update; `model` is the policy.

    `to_env` maps the policy's raw (E, N, act_dim) sample to the env's action (clipping, or forcing
    some outputs to 0 for an ablation); the loss uses the raw sample."""

    def __init__(self, env: VecEnv, cfg: Config, seed: int,
                 to_env: Callable[[np.ndarray], np.ndarray] = clip_wheels) -> None:  # fmt: skip
        torch.manual_seed(seed)
        self.env, self.cfg, self.to_env = env, cfg, to_env
        e, n, d = env.num_envs, env.num_agents, env.single_observation_space.shape[0]
        self.e, self.n, self.d, self.b = e, n, d, e * n
        self.w = env.single_action_space.shape[0]
        self.c = critic_dim(env, cfg.team_critic, cfg.own_critic)
        if cfg.tanh and (cfg.anchor or cfg.listen_bias or cfg.signal_bias or cfg.start_forward or cfg.start_lay):
            raise ValueError("a tanh actor (Config.tanh) takes no anchor, listen_bias, signal_bias, start_forward or start_lay")
        self.model = ActorCritic(d, self.c, act_dim=self.w, hidden=cfg.hidden, agents=n if cfg.agent_id else 0,
                                 history=cfg.history, tanh=cfg.tanh)
        # The actor's input: the observations it remembers (and the agent's one-hot).
        self.d_in = d * cfg.history + self.model.agents
        self.memory = Memory(cfg.history)
        with torch.no_grad():
            self.model.pi[-1].bias[:2] = cfg.start_forward
            self.model.pi[-1].bias[2 : self.w] = cfg.start_lay
        # Adam over all parameters at once (foreach: the same bits as torch's CPU default, one tensor at
        # a time); with Config.compile one fused kernel (other bits), and the loss's forward and
        # backward fused into generated kernels.
        self.opt = torch.optim.Adam(self.model.parameters(), lr=cfg.lr, eps=1e-5,
                                    **({"fused": True} if cfg.compile else {"foreach": True}))
        self.loss = torch.compile(self._minibatch_loss, dynamic=False) if cfg.compile else self._minibatch_loss
        self.kl = 0.0  # the mean KL divergence of the last update's minibatch steps
        # Rewards are divided by a running std of the discounted return, so that the critic's targets
        # stay O(1) whatever the reward's scale.
        self.ret_norm = RunningNorm(1)
        self.disc_ret = np.zeros(self.b)
        obs, infos = env.reset(seed=seed)
        self.obs, self.state = obs, infos["state"]
        self.view = self.memory.push(obs)  # what the actor reads
        self.anchor: tuple[nn.Module, RunningNorm] | None = None  # set_anchor's frozen actor
        self.prev_done = np.zeros(self.b, dtype=bool)
        self.ep_return = np.zeros(self.b)
        self.finished: list[float] = []  # returns of the training episodes, in the order they ended
        self.updates = 0
        self.agent_steps = 0
        self.seconds = {"env": 0.0, "act": 0.0, "learn": 0.0}  # wall time of each phase

    def set_anchor(self) -> None:
        """Freezes a copy of the actor as it is now (e.g. after imitation): with `cfg.anchor` > 0 the
        loss adds `anchor` x the squared distance of the actor's mean from the frozen one's, as
        kickstarting does (Schmitt et al. 2018), so that PPO refines that actor rather than loses it."""
        self.anchor = (copy.deepcopy(self.model.pi).requires_grad_(False), copy.deepcopy(self.model.obs_norm))

    def iterate(self) -> float:
        """One rollout and one PPO update; returns the rollout's mean reward per agent-step."""
        cfg, e, n, b, T = self.cfg, self.e, self.n, self.b, self.cfg.horizon
        obs_buf = np.zeros((T, b, self.d_in), np.float32)
        cri_buf = np.zeros((T + 1, b, self.c), np.float32)
        act_buf = torch.zeros(T, b, self.w)
        logp_buf = torch.zeros(T, b)
        rew_buf = np.zeros((T, b), np.float32)
        done_buf = np.zeros((T, b), np.float32)
        term_buf = np.zeros((T, b), np.float32)
        valid_buf = np.zeros((T, b), bool)
        model = self.model
        for t in range(T):
            t0 = time.perf_counter()
            obs_buf[t] = model.actor_input(self.view).reshape(b, self.d_in)
            cri_buf[t] = critic_input(self.obs, self.state, self.cfg.team_critic, self.cfg.own_critic)
            with torch.no_grad():
                noise = torch.randn(b, self.w)
                head = model.head(torch.from_numpy(obs_buf[t]))
                log_std = model.log_stds(head)
                act_buf[t] = head[:, : self.w] + noise * log_std.exp()
                logp_buf[t] = -0.5 * (noise * noise).sum(-1) - log_std.sum(-1) - 0.5 * LOG_2PI * self.w
            raw = act_buf[t].numpy().reshape(e, n, self.w)
            action = self.to_env(np.tanh(raw) if cfg.tanh else raw)
            t1 = time.perf_counter()
            self.obs, rew, term, trunc, infos = self.env.step(action)
            self.seconds["env"] += time.perf_counter() - t1
            self.seconds["act"] += t1 - t0
            # A step after a done one reset its world: that row's history starts again.
            self.view = self.memory.push(self.obs, fresh=self.prev_done.reshape(e, n))
            self.state = infos["state"]
            r = rew.reshape(b).astype(np.float64)
            done = (term | trunc).reshape(b)
            # Next-step autoreset: the step after a done one only resets the world (actions ignored,
            # reward 0); it is no transition of the policy's, so it is masked out of the loss.
            valid_buf[t] = ~self.prev_done
            self.disc_ret = self.disc_ret * cfg.gamma * (~self.prev_done) + r
            self.ret_norm.update(torch.from_numpy(self.disc_ret[~self.prev_done].astype(np.float32))[:, None])
            rew_buf[t], done_buf[t], term_buf[t] = r, done, term.reshape(b)
            self.ep_return += r
            if done.any():
                self.finished.extend(self.ep_return[done].tolist())
                self.ep_return[done] = 0.0
            self.prev_done = done
            self.agent_steps += b
        t0 = time.perf_counter()
        cri_buf[T] = critic_input(self.obs, self.state, self.cfg.team_critic, self.cfg.own_critic)
        rollout_threads = torch.get_num_threads()
        torch.set_num_threads(cfg.learn_threads)
        try:
            self._learn(obs_buf, cri_buf, act_buf, logp_buf, rew_buf, done_buf, term_buf, valid_buf)
        finally:
            torch.set_num_threads(rollout_threads)
        self.seconds["learn"] += time.perf_counter() - t0
        self.updates += 1
        return float(rew_buf[valid_buf].mean()) if valid_buf.any() else 0.0

    def _learn(self, obs_buf, cri_buf, act_buf, logp_buf, rew_buf, done_buf, term_buf, valid_buf) -> None:
        cfg, model, T, b = self.cfg, self.model, self.cfg.horizon, self.b
        cri = torch.from_numpy(cri_buf)
        with torch.no_grad():  # every value of the rollout in one batched forward pass
            values = model.value(cri.reshape((T + 1) * b, -1)).reshape(T + 1, b).numpy()
        adv = gae(rew_buf / self.reward_scale(), values, done_buf, term_buf, cfg.gamma, cfg.lam, cfg.bootstrap_truncated)
        ret = adv + values[:T]
        keep = torch.from_numpy(valid_buf.reshape(-1))
        fo = torch.from_numpy(obs_buf.reshape(T * b, -1))[keep]
        fc = cri[:T].reshape(T * b, -1)[keep]
        fa, fl = act_buf.reshape(T * b, -1)[keep], logp_buf.reshape(-1)[keep]
        fadv = torch.from_numpy(adv.reshape(-1))[keep]
        fret = torch.from_numpy(ret.reshape(-1))[keep]
        if not cfg.raw_observations:
            model.obs_norm.update(fo)
            model.critic_norm.update(fc)
        fadv = self.policy_advantages(fadv)
        m = fo.shape[0]
        size = max(1, -(-m // cfg.minibatches))
        if cfg.anneal:
            self._set_lr(cfg.lr * max(0.0, 1.0 - self.updates / cfg.anneal))
        kls: list[float] = []
        warm = self.updates < cfg.actor_warmup
        for _ in range(cfg.epochs):
            # One gather a pass (index_select: 4.6x faster than x[perm]), then contiguous slices: the same
            # minibatches as gathering each one, whose gathers took an eighth of a 1,200-row step.
            perm = torch.randperm(m)
            po, pc, pa, pl, padv, pret = (x.index_select(0, perm) for x in (fo, fc, fa, fl, fadv, fret))
            for k in range(0, m, size):
                loss, ratio, log_ratio = self.loss(po[k : k + size], pa[k : k + size], pl[k : k + size],
                                                   padv[k : k + size], pc[k : k + size], pret[k : k + size], warm)
                self.opt.zero_grad()
                loss.backward()
                clip_gradients(model, cfg.clip_apart, cfg.grad_norm)
                self.opt.step()
                with torch.no_grad():  # the k3 estimate of KL(old || new), as rl_games and CleanRL compute it
                    kl = float(((ratio - 1) - log_ratio).mean())
                kls.append(kl)
                if cfg.target_kl:
                    self._set_lr(adapt_lr(self.lr, kl, cfg.target_kl))
        self.kl = float(np.mean(kls))

    def _minibatch_loss(self, o: torch.Tensor, a: torch.Tensor, old_logp: torch.Tensor, adv: torch.Tensor,
                        cri: torch.Tensor, ret: torch.Tensor, warm: bool) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """PPO's loss on one minibatch, with its probability ratio and log ratio (for the KL estimate);
        `warm`: the critic's loss alone (`Config.actor_warmup`)."""
        cfg, model = self.cfg, self.model
        head = model.head(o)
        mu = head[:, : self.w]
        log_ratio = model.log_prob(o, a, head) - old_logp
        ratio = log_ratio.exp()
        pg = -torch.min(ratio * adv, ratio.clamp(1 - cfg.clip, 1 + cfg.clip) * adv).mean()
        vloss = 0.5 * (model.value(cri) - ret).pow(2).mean()
        # The Gaussian's entropy is sum(log_std) + const (before a tanh).
        loss = pg + 0.5 * vloss - cfg.ent_coef * model.log_stds(head).sum(-1).mean()
        if cfg.anchor and self.anchor is not None:
            with torch.no_grad():
                frozen = self.anchor[0](self.anchor[1](o))
            loss = loss + cfg.anchor * (mu - frozen).pow(2).sum(-1).mean()
        if cfg.listen_bias:
            loss = loss - cfg.listen_bias * listening(model, o, mu, cfg.message_inputs)
        if cfg.signal_bias:
            loss = loss - cfg.signal_bias * signalling(model, mu, cfg.message_output, cfg.message_threshold)
        if warm:
            loss = 0.5 * vloss
        return loss, ratio, log_ratio

    def reward_scale(self) -> float:
        """What the rewards are divided by before the advantages: the running sd of the discounted
        return, or 1 with `raw_rewards`."""
        return 1.0 if self.cfg.raw_rewards else float(torch.sqrt(self.ret_norm.var[0] + 1e-8))

    def policy_advantages(self, adv: torch.Tensor) -> torch.Tensor:
        """The advantages the policy loss weighs: standardised over the batch, or as they are with
        `raw_advantages`."""
        return adv if self.cfg.raw_advantages else (adv - adv.mean()) / (adv.std() + 1e-8)

    @property
    def lr(self) -> float:
        """The optimiser's learning rate now (the schedule's: constant, annealed or adaptive)."""
        return float(self.opt.param_groups[0]["lr"])

    def _set_lr(self, lr: float) -> None:
        for group in self.opt.param_groups:
            group["lr"] = lr


def gae(rew: np.ndarray, values: np.ndarray, done: np.ndarray, term: np.ndarray, gamma: float, lam: float,
        bootstrap_truncated: bool = False) -> np.ndarray:  # fmt: skip
    """Generalised advantage estimates (T, B) of a rollout: rewards, dones and terminations (T, B),
    values (T + 1, B). After a done step the estimate starts again; an episode cut by its time limit
    goes on from its final observation (the one the done step returned, `values[t + 1]`) with
    `bootstrap_truncated`, else it is worth nothing after it, as after a termination."""
    adv = np.zeros(rew.shape, np.float32)
    last = np.zeros(rew.shape[1:], np.float32)
    for t in reversed(range(rew.shape[0])):
        nonterminal = 1.0 - done[t]
        boot = 1.0 - term[t] if bootstrap_truncated else nonterminal
        delta = rew[t] + gamma * values[t + 1] * boot - values[t]
        last = delta + gamma * lam * nonterminal * last
        adv[t] = last
    return adv


def adapt_lr(lr: float, kl: float, target: float, low: float = 1e-5, high: float = 1e-2) -> float:
    """rl_games' adaptive schedule: a step that moved the policy by more than twice the target KL slows the
    next one, one that moved it by less than half speeds it up."""
    if kl > 2.0 * target:
        return max(lr / 1.5, low)
    if kl < 0.5 * target:
        return min(lr * 1.5, high)
    return lr


def listening(model: ActorCritic, obs: torch.Tensor, mu: torch.Tensor, inputs: tuple[int, ...]) -> torch.Tensor:
    """How much the wheel commands (clipped means) respond to the message: the mean L1 distance to those
    of the same observations with the message's entries `inputs` at their running mean (the actor's
    normalised input 0). The mean, not a raw 0: a sensor never reads exactly nothing, and an input far
    outside what the actor has seen would reward reacting to that, not to the message. `inputs` index
    the actor's input, which is the observation itself only for an actor without `history` or
    `agents` (as `stigmergy.py` trains)."""
    z = model.obs_norm(obs)
    z[:, list(inputs)] = 0.0
    return (mu[:, :2].clamp(-1, 1) - model.pi(z)[:, :2].clamp(-1, 1)).abs().sum(-1).mean()


def signalling(model: ActorCritic, mu: torch.Tensor, output: int, threshold: float) -> torch.Tensor:
    """Mutual information (nats) between observation and sending over a minibatch: H(mean p) - mean H(p),
    with p = P(output's Gaussian sample > threshold) per observation. High when the sender sends in some
    situations and not in others, zero when it sends with the same probability everywhere."""
    p = 0.5 * (1.0 + torch.erf((mu[:, output] - threshold) * torch.exp(-model.log_std[output]) / np.sqrt(2.0)))
    p = p.clamp(1e-6, 1.0 - 1e-6)

    def h(q: torch.Tensor) -> torch.Tensor:
        return -(q * torch.log(q) + (1.0 - q) * torch.log1p(-q))

    return h(p.mean()) - h(p).mean()


def episode_returns(policy: Callable[[VecEnv], Callable[[np.ndarray], np.ndarray]], env_kwargs: dict,
                    worlds: int, steps: int, seed: int) -> list[float]:  # fmt: skip
    """Each world's undiscounted return per agent over `worlds` seeded episodes of `steps` steps;
    `policy(env)` gives the function from observations to actions (a `Baseline` needs its env)."""
    v = VecEnv(num_envs=worlds, max_cycles=steps, **env_kwargs)
    act = policy(v)
    obs, _ = v.reset(seed=seed)
    total = np.zeros((worlds, v.num_agents))
    for _ in range(steps):
        obs, rew, _, _, _ = v.step(act(obs))
        total += rew
    return total.mean(axis=1).tolist()


def mean_and_se(returns: Sequence[float] | np.ndarray) -> dict[str, float]:
    """Episode returns as their mean and the standard error of that mean, to 0.01 (at least two)."""
    r = np.asarray(returns, dtype=np.float64)
    return {"mean": round(float(r.mean()), 2), "se": round(float(r.std(ddof=1) / np.sqrt(len(r))), 2)}


def evaluate(policy: Callable[[VecEnv], Callable[[np.ndarray], np.ndarray]], env_kwargs: dict, worlds: int,
             steps: int, seed: int) -> float:  # fmt: skip
    """The mean of `episode_returns`: the mean return per agent over the seeded episodes."""
    return float(np.mean(episode_returns(policy, env_kwargs, worlds, steps, seed)))
