"""Actions checked against the action space, agent by agent, before anything is stepped.

Continuous: two wheel speeds, then one rate in [0, 1] per deposit action (`robots[].deposit_actions`),
any real array-like of shape (2 + D,); values beyond their bounds are clipped (as the native core
does), NaN and infinities refused. Discrete: one integer (Python or numpy)
in 0..n. `None`, scalars for continuous actions, floats for discrete ones, strings and wrong shapes
are refused with the agent named.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pettingzoo.utils.conversions import parallel_to_aec_wrapper

from colcos._core import ActionError, ActionTypeError


def _show(a: Any) -> str:
    r = repr(a)
    return r if len(r) <= 80 else r[:77] + "..."


def _entries(width: int) -> str:
    return "two wheel speeds" if width == 2 else f"two wheel speeds and {width - 2} deposit rates"


def continuous(agent: str, a: Any, width: int = 2) -> np.ndarray:
    """Agent `agent`'s action (two wheel speeds, then `width - 2` deposit rates) as float32 (not yet
    clipped), or an error naming it."""
    if type(a) is np.ndarray and a.dtype == np.float32 and a.shape == (width,):
        arr = a
    else:
        if a is None or isinstance(a, (str, bytes, dict)):
            raise ActionTypeError(
                f"action of agent {agent!r} must be {_entries(width)} (shape ({width},)), got {_show(a)}"
            )
        try:
            arr = np.asarray(a)
        except (TypeError, ValueError) as e:
            raise ActionTypeError(f"action of agent {agent!r} cannot be made an array: {e}") from None
        if arr.dtype.kind not in "iuf":
            raise ActionTypeError(
                f"action of agent {agent!r} must be real numbers, got {_show(a)} (dtype {arr.dtype})"
            )
        if arr.shape != (width,):
            raise ActionError(
                f"action of agent {agent!r} must have shape ({width},) ({_entries(width)}), "
                f"got shape {arr.shape}: {_show(a)}"
            )
    if not np.isfinite(arr).all():
        raise ActionError(f"action of agent {agent!r} is {_show(a)} (must be finite)")
    return arr


def discrete(agent: str, a: Any, n: int) -> int:
    """Agent `agent`'s discrete action as an int in 0..n, or an error naming it."""
    if isinstance(a, np.ndarray) and a.shape == () and a.dtype.kind in "iu":
        a = a[()]
    if isinstance(a, (bool, np.bool_)) or not isinstance(a, (int, np.integer)):
        raise ActionTypeError(f"action of agent {agent!r} must be an integer in 0..{n}, got {_show(a)}")
    v = int(a)
    if not 0 <= v < n:
        raise ActionError(f"action of agent {agent} is {v}, not in 0..{n}")
    return v


class CheckedAecWrapper(parallel_to_aec_wrapper):
    """PettingZoo's AEC view of a parallel env, raising for a bad action at the `step` that
    receives it (the parallel env only steps once the last agent has acted)."""

    def step(self, action: Any) -> None:
        agent = self.agent_selection
        live = not (self.terminations.get(agent, False) or self.truncations.get(agent, False))
        if live:
            self.env.check_action(agent, action)
        elif action is not None:
            raise ActionError(f"agent {agent!r} is done: its action must be None, got {_show(action)}")
        super().step(action)
