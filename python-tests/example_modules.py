"""The examples' shared modules, loaded by path for the tests (examples/ is no package)."""

from __future__ import annotations

import importlib.util
import pathlib
import sys
import types

REPO = pathlib.Path(__file__).resolve().parents[1]


def load_ppo() -> types.ModuleType:
    """examples/ppo.py: the PPO trainer and its ActorCritic, the network the robots run (importing its
    ppo_model as the scripts do)."""
    folder = REPO / "examples"
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    spec = importlib.util.spec_from_file_location("ppo", REPO / "examples" / "ppo.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["ppo"] = module  # its dataclass looks its module up while the class is made
    spec.loader.exec_module(module)
    return module


def load_task(name: str) -> types.ModuleType:
    """examples/tasks/<name>.py (a task written in Python), importing its `_common` as the script does."""
    folder = REPO / "examples" / "tasks"
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    spec = importlib.util.spec_from_file_location(f"colcos_example_{name}", folder / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_quickstart() -> types.ModuleType:
    """examples/train_aggregation.py (it puts examples/ on sys.path for its ppo and kickstart)."""
    spec = importlib.util.spec_from_file_location("train_aggregation", REPO / "examples" / "train_aggregation.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
