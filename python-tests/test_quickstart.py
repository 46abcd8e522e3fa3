"""`examples/train_aggregation.py` (the quick start) end to end on a tiny budget, and the shared PPO of
`examples/ppo.py`: its log-probability against torch's Normal, and its update budget."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from example_modules import load_ppo, load_quickstart

REPO = pathlib.Path(__file__).resolve().parents[1]


def test_log_prob_is_the_gaussian_log_density():
    torch = pytest.importorskip("torch")
    ppo = load_ppo()
    torch.manual_seed(3)
    model = ppo.ActorCritic(17, 20, act_dim=3)
    with torch.no_grad():
        model.log_std.copy_(torch.tensor([-0.3, 0.2, -1.0]))
        model.pi[-1].weight.normal_()
    obs, act = torch.randn(50, 17), torch.randn(50, 3)
    want = torch.distributions.Normal(model.pi(model.obs_norm(obs)), model.log_std.exp()).log_prob(act).sum(-1)
    assert torch.allclose(model.log_prob(obs, act), want, atol=1e-5)


def test_a_tanh_actor_is_a_squashed_gaussian_of_learned_widths(tmp_path):
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    torch.manual_seed(4)
    model = ppo.ActorCritic(17, 20, act_dim=2, tanh=True)
    assert model.pi[-1].out_features == 4
    obs = torch.randn(50, 17)
    # Untrained: the widths are 1, as BenchMARL's biased softplus starts them.
    assert torch.allclose(model.log_stds(model.head(obs)).exp(), torch.ones(50, 2), atol=1e-2)
    with torch.no_grad():
        model.pi[-1].weight.normal_()
    head = model.head(obs)
    sd = torch.nn.functional.softplus(head[:, 2:] + ppo.SOFTPLUS_BIAS) + 1e-4
    act = torch.randn(50, 2) * 3
    want = torch.distributions.Normal(head[:, :2], sd).log_prob(act).sum(-1)
    assert torch.allclose(model.log_prob(obs, act), want, atol=1e-4)
    # Acting: the mean's tanh; sampling: inside (-1, 1) and spread by the widths.
    x = obs.numpy()
    np.testing.assert_allclose(model.act(x), torch.tanh(head[:, :2]).detach().numpy(), atol=1e-6)
    drawn = model.sample(x, torch.Generator().manual_seed(0))
    assert np.all(np.abs(drawn) < 1) and not np.allclose(drawn, model.act(x))
    # Trained a little and saved, it loads back as the same tanh actor.
    env = VecEnv(task="aggregation", num_envs=2, max_cycles=20, num_threads=1)
    trainer = ppo.Trainer(env, ppo.Config(horizon=8, epochs=1, minibatches=2, tanh=True, hidden=16), seed=0)
    before = trainer.model.pi[-1].weight.detach().clone()
    trainer.iterate()
    assert not torch.equal(before, trainer.model.pi[-1].weight)
    torch.save(trainer.model.state_dict(), tmp_path / "policy.pt")
    loaded = ppo.load_model(str(tmp_path / "policy.pt"), 17)
    assert loaded.tanh
    np.testing.assert_array_equal(loaded.act(x), trainer.model.act(x))
    with pytest.raises(ValueError, match="a tanh actor"):
        ppo.Trainer(env, ppo.Config(tanh=True, anchor=0.1), seed=0)


def test_raw_rewards_and_advantages_are_left_as_they_are():
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    env = VecEnv(task="aggregation", num_envs=2, max_cycles=20, num_threads=1)
    adv = torch.tensor([3.0, -1.0, 5.0, 0.5])
    scaled = ppo.Trainer(env, ppo.Config(horizon=8, epochs=1, minibatches=1, hidden=16), seed=0)
    raw = ppo.Trainer(env, ppo.Config(horizon=8, epochs=1, minibatches=1, hidden=16, raw_rewards=True, raw_advantages=True), seed=0)
    for trainer in (scaled, raw):
        trainer.iterate()
    assert scaled.reward_scale() != pytest.approx(1.0, abs=1e-3) and raw.reward_scale() == 1.0
    standard = scaled.policy_advantages(adv)
    assert float(standard.mean()) == pytest.approx(0.0, abs=1e-6) and float(standard.std()) == pytest.approx(1.0, abs=1e-5)
    assert torch.equal(raw.policy_advantages(adv), adv)


def test_raw_observations_reach_the_networks_as_the_env_gives_them():
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    env = VecEnv(task="aggregation", num_envs=2, max_cycles=20, num_threads=1)
    cfg = {"horizon": 8, "epochs": 1, "minibatches": 1, "hidden": 16, "own_critic": True}
    scored = ppo.Trainer(env, ppo.Config(**cfg), seed=0)
    raw = ppo.Trainer(env, ppo.Config(**cfg, raw_observations=True), seed=0)
    for trainer in (scored, raw):
        trainer.iterate()
    assert float(scored.model.obs_norm.mean.abs().max()) > 1e-3
    x = torch.from_numpy(np.array(env.obs, np.float32).reshape(-1, env.single_observation_space.shape[0]))
    for norm in (raw.model.obs_norm, raw.model.critic_norm):
        assert torch.equal(norm(x), x.clamp(-10, 10))


def test_a_truncated_episode_bootstraps_from_its_final_observation_only_when_asked():
    pytest.importorskip("torch")
    ppo = load_ppo()
    g, lam = 0.9, 0.5
    rew = np.array([[1.0], [1.0], [1.0]], np.float32)
    values = np.array([[0.5], [0.5], [2.0], [0.5]], np.float32)  # values[2]: the final observation of step 1
    done, term = np.array([[0.0], [1.0], [0.0]], np.float32), np.zeros((3, 1), np.float32)
    after = 1.0 + g * 0.5 - 2.0  # step 2 (a reset step, masked in training) bootstraps from values[3]
    for boot, cut in ((False, 1.0 - 0.5), (True, 1.0 + g * 2.0 - 0.5)):
        adv = ppo.gae(rew, values, done, term, g, lam, bootstrap_truncated=boot)
        # The episode ends at step 1: its estimate does not run on into step 2's.
        np.testing.assert_allclose(adv[:, 0], [1.0 + g * 0.5 - 0.5 + g * lam * cut, cut, after], rtol=1e-6)
    # A termination is worth nothing after it either way.
    ended = ppo.gae(rew, values, done, done, g, lam, bootstrap_truncated=True)
    np.testing.assert_allclose(ended, ppo.gae(rew, values, done, done, g, lam), rtol=1e-6)
    assert ended[1, 0] == pytest.approx(0.5)


def test_trainer_counts_updates_and_samples():
    pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    env = VecEnv(task="aggregation", num_envs=2, max_cycles=20, num_threads=1)
    trainer = ppo.Trainer(env, ppo.Config(horizon=8, epochs=1, minibatches=2), seed=0)
    before = [p.detach().clone() for p in trainer.model.pi.parameters()]
    for _ in range(3):
        trainer.iterate()
    assert trainer.updates == 3
    assert trainer.agent_steps == 3 * 8 * 2 * env.num_agents
    assert trainer.finished, "episodes of 20 steps end within 24 steps"
    assert any(not np.array_equal(a.numpy(), p.detach().numpy()) for a, p in zip(before, trainer.model.pi.parameters()))


def test_the_update_learns_the_same_on_any_number_of_threads():
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    learned, before = [], torch.get_num_threads()
    for threads in (1, 2):
        env = VecEnv(task="aggregation", num_envs=16, max_cycles=50, num_threads=1)
        # Minibatches of 1,200 rows: big enough that torch splits its matrix products and tanh over threads.
        cfg = ppo.Config(horizon=50, epochs=2, minibatches=2, own_critic=True, learn_threads=threads)
        trainer = ppo.Trainer(env, cfg, seed=3)
        torch.set_num_threads(1)
        trainer.iterate()
        assert torch.get_num_threads() == 1, "the rollout's thread count is restored after the update"
        learned.append(torch.cat([p.detach().flatten() for p in trainer.model.parameters()]))
    torch.set_num_threads(before)
    assert torch.equal(learned[0], learned[1])


def test_the_compiled_update_learns_what_the_eager_one_does():
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    learned = []
    for compiled in (False, True):
        env = VecEnv(task="aggregation", num_envs=4, max_cycles=50, num_threads=1)
        cfg = ppo.Config(horizon=50, epochs=2, minibatches=3, own_critic=True, compile=compiled)
        trainer = ppo.Trainer(env, cfg, seed=5)
        start = torch.cat([p.detach().flatten() for p in trainer.model.parameters()])
        trainer.iterate()
        learned.append(torch.cat([p.detach().flatten() for p in trainer.model.parameters()]) - start)
    # The same steps to within the rounding of fused kernels: far closer than any step is long.
    step = learned[0].abs().max()
    assert step > 1e-4
    assert (learned[1] - learned[0]).abs().max() < 1e-3 * step


def test_the_team_critic_sees_every_agents_observation():
    pytest.importorskip("torch")
    ppo = load_ppo()
    rng = np.random.default_rng(0)
    obs, state = rng.normal(size=(2, 3, 5)).astype(np.float32), rng.normal(size=(2, 4)).astype(np.float32)
    plain, team = ppo.critic_input(obs, state), ppo.critic_input(obs, state, team=True)
    assert plain.shape == (6, 5 + 4 + 3) and team.shape == (6, 5 + 4 + 3 + 3 * 5)
    np.testing.assert_array_equal(team[:, :12], plain)
    for world in range(2):
        for agent in range(3):  # each agent's row holds its world's whole team, in agent order
            np.testing.assert_array_equal(team[3 * world + agent, 12:], obs[world].reshape(-1))
    from colcos.vector import VecEnv

    env = VecEnv(task="aggregation", num_envs=2, max_cycles=20, num_threads=1)
    trainer = ppo.Trainer(env, ppo.Config(horizon=4, epochs=1, minibatches=1, team_critic=True), seed=0)
    trainer.iterate()
    assert trainer.c == ppo.critic_dim(env, team=True) == ppo.critic_dim(env) + env.num_agents * 17


def test_the_own_critic_sees_only_the_agents_observation():
    pytest.importorskip("torch")
    ppo = load_ppo()
    rng = np.random.default_rng(1)
    obs, state = rng.normal(size=(2, 3, 5)).astype(np.float32), rng.normal(size=(2, 4)).astype(np.float32)
    own = ppo.critic_input(obs, state, own=True)
    assert own.shape == (6, 5) and own.dtype == np.float32
    np.testing.assert_array_equal(own, obs.reshape(6, 5))
    from colcos.vector import VecEnv

    env = VecEnv(task="aggregation", num_envs=2, max_cycles=20, num_threads=1)
    trainer = ppo.Trainer(env, ppo.Config(horizon=4, epochs=1, minibatches=1, own_critic=True, hidden=16), seed=0)
    trainer.iterate()
    assert trainer.c == ppo.critic_dim(env, own=True) == 17
    assert trainer.model.v[0].weight.shape == (16, 17) and trainer.model.pi[0].weight.shape == (16, 17)


def test_clipping_apart_keeps_a_large_critic_gradient_from_shrinking_the_actors():
    torch = pytest.importorskip("torch")
    ppo = load_ppo()
    actor_norm = {}
    for apart in (False, True):
        model = ppo.ActorCritic(17, 20)
        for q in model.parameters():
            q.grad = torch.zeros_like(q)
        model.log_std.grad = torch.tensor([0.3, 0.0])  # the actor's gradient: norm 0.3
        first = next(model.v.parameters())
        first.grad = torch.zeros_like(first)
        first.grad.view(-1)[0] = 100.0  # the critic's: norm 100
        ppo.clip_gradients(model, apart)
        actor_norm[apart] = float(torch.cat([q.grad.flatten() for q in [*model.pi.parameters(), model.log_std]]).norm())
        assert float(first.grad.norm()) == pytest.approx(0.5, rel=1e-3)
    assert actor_norm[True] == pytest.approx(0.3, rel=1e-5)
    assert actor_norm[False] == pytest.approx(0.3 * 0.5 / (100**2 + 0.3**2) ** 0.5, rel=1e-3)


def test_start_forward_and_start_lay_set_the_untrained_means_of_their_outputs():
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    env = VecEnv(task="alarm", num_envs=2, max_cycles=20, num_threads=1)  # wheels and one deposit rate

    def untrained_mean(**kw: float) -> "torch.Tensor":
        trainer = ppo.Trainer(env, ppo.Config(horizon=4, **kw), seed=0)
        with torch.no_grad():
            return trainer.model.pi(torch.zeros(1, env.single_observation_space.shape[0]))[0]

    mean = untrained_mean(start_forward=0.5)
    assert torch.allclose(mean[:2], torch.tensor(0.5), atol=0.05) and abs(float(mean[2])) < 0.05
    mean = untrained_mean(start_lay=-0.5)
    assert torch.allclose(mean[:2], torch.tensor(0.0), atol=0.05) and abs(float(mean[2]) + 0.5) < 0.05


def test_quickstart_runs_and_reports(tmp_path):
    torch = pytest.importorskip("torch")
    args = ["--updates", "4", "--eval-every", "2", "--seeds", "0", "1", "--num-envs", "2", "--horizon", "8",
            "--episode", "20", "--eval-worlds", "2", "--holdout-worlds", "6", "--threads", "1", "--out", str(tmp_path)]
    out = subprocess.run([sys.executable, str(REPO / "examples" / "train_aggregation.py"), *args],
                         capture_output=True, text=True, timeout=600, check=True).stdout
    assert "| median |" in out and "held out: paper follower" in out
    result = json.loads((tmp_path / "result.json").read_text())
    assert [r["seed"] for r in result["runs"]] == [0, 1]
    for run in result["runs"]:
        assert run["updates"] == 4
        assert [c[1] for c in run["curve"]] == [0, 2, 4]  # evaluated before training and every 2 updates
        assert (tmp_path / f"seed{run['seed']}" / "policy.pt").exists()
        # The held-out episodes at half the budget and at the end, each with its standard error.
        assert [(h["updates"], h["se"] > 0) for h in run["holdout"].values()] == [(2, True), (4, True)]
    assert (tmp_path / "policy.pt").exists()
    # By default the critic reads the agent's own 17 observation entries and time limits bootstrap.
    assert (result["critic"], result["bootstrap_truncated"]) == ("own", True)
    assert torch.load(tmp_path / "policy.pt")["v.0.weight"].shape[1] == 17
    assert set(result["references"]) == {"paper_follower", "random", "standing_still"}
    held = result["holdout"]
    assert (held["worlds"], held["seed"]) == (6, 777)
    assert set(held["references"]) == {"paper_follower", "standing_still", "sees_the_leader"}
    assert held["median_end"] == float(np.median([r["holdout"]["end"]["mean"] for r in result["runs"]]))
    # A controller that reads the true positions outscores one that only senses, on the same episodes.
    assert held["references"]["sees_the_leader"]["mean"] > held["references"]["standing_still"]["mean"]
    # The saved policy through the evaluation-noise check: its perturbed copies' spread and held-out mean.
    noise = subprocess.run([sys.executable, str(REPO / "examples" / "evaluation_noise.py"), str(tmp_path / "policy.pt"),
                            "--times", "3", "--eval-worlds", "2", "--holdout-worlds", "4", "--episode", "10"],
                           capture_output=True, text=True, timeout=600, check=True).stdout.splitlines()
    assert noise[0].startswith("paper's follower: 2 evaluation episodes") and len(noise) == 2
    assert "perturbed by 0.001, 3 times: sd" in noise[1] and "4 held-out episodes" in noise[1]


def test_a_recipe_fills_what_the_command_line_leaves_out():
    pytest.importorskip("torch")
    qs = load_quickstart()
    ippo = qs.parse_args([])
    assert (ippo.recipe, ippo.updates, ippo.horizon, ippo.epochs, ippo.minibatches) == ("ippo", 38, 500, 15, 40)
    assert (ippo.gamma, ippo.lam, ippo.grad_norm, ippo.lr) == (0.99, 0.9, 5.0, 1e-3)
    assert ippo.raw_advantages and ippo.raw_rewards and ippo.raw_observations
    short = qs.parse_args(["--recipe", "short"])
    assert (short.updates, short.eval_every, short.horizon, short.epochs, short.minibatches) == (720, 60, 64, 4, 4)
    assert (short.gamma, short.lam, short.grad_norm) == (0.98, 0.95, 0.5)
    assert not (short.raw_advantages or short.raw_rewards or short.raw_observations)
    # A flag given wins over its recipe's value, the rest of the recipe stays.
    mixed = qs.parse_args(["--recipe", "short", "--horizon", "100", "--raw-rewards"])
    assert (mixed.horizon, mixed.epochs, mixed.raw_rewards, mixed.raw_advantages) == (100, 4, True, False)
    mixed = qs.parse_args(["--no-raw-observations", "--updates", "3"])
    assert (mixed.raw_observations, mixed.raw_rewards, mixed.updates, mixed.horizon) == (False, True, 3, 500)


def test_quickstart_refuses_a_bad_param(tmp_path):
    pytest.importorskip("torch")
    res = subprocess.run([sys.executable, str(REPO / "examples" / "train_aggregation.py"), "--param", "progress_weight",
                          "--out", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2
    assert "--param 'progress_weight': expected KEY=VALUE" in res.stderr
    res = subprocess.run([sys.executable, str(REPO / "examples" / "train_aggregation.py"), "--anneal", "--target-kl",
                          "0.01", "--out", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2 and "--anneal and --target-kl both set the learning rate" in res.stderr
    res = subprocess.run([sys.executable, str(REPO / "examples" / "train_aggregation.py"), "--holdout-seed", "12345",
                          "--out", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2 and "--holdout-seed (12345) must differ from --eval-seed" in res.stderr
    res = subprocess.run([sys.executable, str(REPO / "examples" / "train_aggregation.py"), "--gamma", "0",
                          "--out", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2 and "--gamma (0.0) must be in (0, 1]" in res.stderr
    for flags, text in ((["--lam", "1.5"], "--lam (1.5) must be in [0, 1]"), (["--hidden", "0"], "--hidden (0) must be at least 1"),
                        (["--grad-norm", "0"], "--grad-norm (0.0) must be above 0"),
                        (["--epochs", "0"], "--epochs (0) must be at least 1"),
                        (["--recipe", "long"], "argument --recipe: invalid choice: 'long'"),
                        (["--param", "progress_weight=fast"], "--param 'progress_weight=fast': 'fast' is not a number"),
                        (["--own-critic", "--team-critic"], "--own-critic and --team-critic choose the critic's input"),
                        (["--tanh", "--kickstart", "100"], "--tanh: a tanh actor is not kickstarted")):  # fmt: skip
        res = subprocess.run([sys.executable, str(REPO / "examples" / "train_aggregation.py"), *flags, "--out", str(tmp_path)],
                             capture_output=True, text=True, timeout=120)  # fmt: skip
        assert res.returncode == 2 and text in res.stderr, flags


def test_an_agent_id_actor_tells_its_agents_apart_and_loads_back(tmp_path):
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    env = VecEnv(task="aggregation", num_envs=2, max_cycles=20, num_threads=1)
    trainer = ppo.Trainer(env, ppo.Config(horizon=4, epochs=1, minibatches=1, agent_id=True), seed=0)
    trainer.iterate()
    model, n = trainer.model, env.num_agents
    assert model.agents == n and model.pi[0].in_features == 17 + n
    with torch.no_grad():  # a first layer that reads only the one-hot: the agents' actions differ
        model.pi[0].weight[:, :17] = 0.0
        model.pi[-1].weight.normal_()
    obs = np.repeat(np.random.default_rng(1).normal(size=(2, 1, 17)).astype(np.float32), n, axis=1)
    act = model.act(obs)
    assert act.shape == (2, n, 2)
    assert not np.allclose(act[:, 0], act[:, 1]) and not np.allclose(act[:, 1], act[:, 2])
    # A PettingZoo dict of some agents, in another order: the ids name each row's agent.
    np.testing.assert_allclose(model.act(obs[0, [2, 0]], ids=np.array([2, 0])), act[0, [2, 0]], rtol=1e-6)
    with pytest.raises(ValueError, match=r"an actor of 3 agents needs observations \(\.\.\., 3, obs\)"):
        model.act(obs[:, :2])
    with pytest.raises(ValueError, match=r"agent ids \[0, 3\]"):
        model.act(obs[0, :2], ids=np.array([0, 3]))
    torch.save(model.state_dict(), tmp_path / "policy.pt")
    loaded = ppo.load_model(str(tmp_path / "policy.pt"), 17)
    assert (loaded.agents, loaded.pi[-1].out_features) == (n, 2)
    np.testing.assert_array_equal(loaded.act(obs), act)
    plain = ppo.Trainer(env, ppo.Config(horizon=4), seed=0).model
    torch.save(plain.state_dict(), tmp_path / "plain.pt")
    assert ppo.load_model(str(tmp_path / "plain.pt"), 17).agents == 0


def test_a_memory_stacks_each_rows_last_observations_and_starts_rows_again():
    ppo = load_ppo()
    memory = ppo.Memory(3)
    first = np.arange(4, dtype=np.float32).reshape(2, 1, 2)  # 2 worlds x 1 agent x 2 entries
    np.testing.assert_array_equal(memory.push(first), np.tile(first, 3))  # the first fills the history
    second = first + 10
    np.testing.assert_array_equal(memory.push(second)[0, 0], [0, 1, 0, 1, 10, 11])
    third = first + 20
    got = memory.push(third, fresh=np.array([[False], [True]]))
    np.testing.assert_array_equal(got[0, 0], [0, 1, 10, 11, 20, 21])  # oldest first
    np.testing.assert_array_equal(got[1, 0], [22, 23, 22, 23, 22, 23])  # world 1 started a new episode
    assert ppo.Memory(1).push(first) is not None and ppo.Memory(1).push(first).shape == first.shape


def test_an_actor_with_a_history_trains_acts_on_a_stream_and_loads_back(tmp_path):
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    env = VecEnv(task="aggregation", num_envs=2, max_cycles=6, num_threads=1)
    trainer = ppo.Trainer(env, ppo.Config(horizon=8, epochs=1, minibatches=1, history=3), seed=0)
    trainer.iterate()  # episodes of 6 steps end inside the rollout: the memory starts again
    model = trainer.model
    assert model.pi[0].in_features == 3 * 17 and trainer.view.shape == (2, env.num_agents, 3 * 17)
    obs = env.reset(seed=1)[0].copy()  # the env's arrays are views its next step overwrites
    act = model.policy()
    a0 = act(obs)
    np.testing.assert_array_equal(a0, model.act(np.tile(obs, 3)))  # the first observation fills the history
    obs2, *_ = env.step(a0)
    np.testing.assert_array_equal(act(obs2), model.act(np.concatenate([obs, obs, obs2], axis=-1)))
    torch.save(model.state_dict(), tmp_path / "policy.pt")
    loaded = ppo.load_model(str(tmp_path / "policy.pt"), 17, history=3)
    assert (loaded.history, loaded.agents) == (3, 0)
    np.testing.assert_array_equal(loaded.act(np.tile(obs, 3)), model.act(np.tile(obs, 3)))


def test_the_adaptive_rate_follows_the_kl_divergence():
    ppo = load_ppo()
    assert ppo.adapt_lr(1e-3, kl=0.05, target=0.01) == pytest.approx(1e-3 / 1.5)  # above twice the target
    assert ppo.adapt_lr(1e-3, kl=0.001, target=0.01) == pytest.approx(1.5e-3)  # below half of it
    assert ppo.adapt_lr(1e-3, kl=0.01, target=0.01) == 1e-3
    assert ppo.adapt_lr(1.2e-5, kl=1.0, target=0.01) == 1e-5 and ppo.adapt_lr(9e-3, kl=0.0, target=0.01) == 1e-2


def test_a_trainer_with_a_target_kl_moves_its_rate_each_step():
    torch = pytest.importorskip("torch")
    from colcos.vector import VecEnv

    ppo = load_ppo()
    env = VecEnv(task="aggregation", num_envs=2, max_cycles=20, num_threads=1)
    # Steps this small move the policy by far less than half of a KL of 1: each of the 2 x 2 steps speeds up.
    trainer = ppo.Trainer(env, ppo.Config(horizon=8, epochs=2, minibatches=2, target_kl=1.0), seed=0)
    trainer.iterate()
    assert trainer.lr == pytest.approx(1e-3 * 1.5**4)
    assert 0.0 <= trainer.kl < 0.5
    fixed = ppo.Trainer(env, ppo.Config(horizon=8, epochs=2, minibatches=2), seed=0)
    fixed.iterate()
    assert fixed.lr == 1e-3 and torch.isfinite(torch.tensor(fixed.kl))


def test_a_kickstarted_quickstart_counts_its_imitation_as_training(tmp_path):
    pytest.importorskip("torch")
    args = ["--updates", "2", "--eval-every", "2", "--num-envs", "2", "--horizon", "8", "--episode", "20",
            "--eval-worlds", "2", "--threads", "1", "--kickstart", "300", "--anchor", "1", "--actor-warmup", "1",
            "--out", str(tmp_path)]
    out = subprocess.run([sys.executable, str(REPO / "examples" / "train_aggregation.py"), *args],
                         capture_output=True, text=True, timeout=600, check=True).stdout
    assert "evaluation return at the start" in out
    run = json.loads((tmp_path / "result.json").read_text())["runs"][0]
    assert run["kickstart_seconds"] > 0.0  # imitated before the first update, on the training clock
    assert run["curve"][0][1] == 0 and run["curve"][0][0] == round(run["kickstart_seconds"], 1)
    assert run["curve"][-1][0] >= run["curve"][0][0]
