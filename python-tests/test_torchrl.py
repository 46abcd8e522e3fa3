"""TorchRL: its PettingZooWrapper over our parallel_env, and our own EnvBase adapter, through
check_env_specs."""

from __future__ import annotations

import pytest

import colcos

torch = pytest.importorskip("torch")
torchrl = pytest.importorskip("torchrl")

from torchrl.envs.libs.pettingzoo import PettingZooWrapper  # noqa: E402
from torchrl.envs.utils import check_env_specs  # noqa: E402


@pytest.mark.parametrize("task", ["aggregation", "foraging", "trail"])
def test_pettingzoo_wrapper(task):
    env = PettingZooWrapper(colcos.parallel_env(task=task, max_cycles=50), use_mask=(task == "foraging"))
    assert "robot" in env.group_map
    check_env_specs(env, seed=0)
    td = env.rollout(20)
    assert td.batch_size[0] == 20


@pytest.mark.parametrize("continuous", [True, False])
def test_our_adapter(continuous):
    from colcos.torchrl_env import ColcosTorchEnv

    env = ColcosTorchEnv("aggregation", num_envs=4, max_cycles=30, continuous=continuous)
    check_env_specs(env, seed=0)
    td = env.rollout(80, break_when_any_done=False)  # crosses episode ends: TorchRL resets done worlds
    assert td.batch_size == torch.Size([4, 80])
    assert td["next", "robot", "observation"].shape == (4, 80, 3, 17)
    assert td["next", "done"].any()


def test_our_adapter_zero_copy_source():
    import numpy as np

    from colcos.vector import VecEnv

    v = VecEnv("aggregation", num_envs=2)
    v.reset(seed=0)
    t = torch.from_numpy(v.obs)
    assert t.data_ptr() == v.obs.__array_interface__["data"][0]
    v.step(np.zeros((2, 3, 2), np.float32))
    assert torch.equal(t, torch.from_numpy(v.obs))
