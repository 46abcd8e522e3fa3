"""Runs a function in a forked, memory-limited child, so that an abort, a runaway allocation or a hang
is reported as a failure instead of taking the test process down.

The children are forked from a zygote: a helper process that imports colcos and the module of the
functions once, builds no environment and starts no worker thread, and then forks one child per call
(cheap: nothing is imported again). Forking the test process itself would copy a process whose
worker threads (rayon's pools) the child does not get.
"""

from __future__ import annotations

import importlib
import os
import pickle
import resource
import select
import signal
import struct
import subprocess
import sys
import time
from dataclasses import dataclass
from typing import Any, Callable

# Address space a child may take beyond what it starts with (the worlds it builds, its arrays).
EXTRA_MEMORY = 2 << 30


@dataclass
class Outcome:
    ok: bool
    error_type: str = ""
    message: str = ""
    is_colcos: bool = False


def _send(fd: int, obj: Any) -> None:
    data = pickle.dumps(obj)
    os.write(fd, struct.pack("<Q", len(data)))
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def _recv(fd: int) -> Any:
    def exactly(n: int) -> bytes:
        buf = b""
        while len(buf) < n:
            chunk = os.read(fd, n - len(buf))
            if not chunk:
                raise EOFError
            buf += chunk
        return buf

    (n,) = struct.unpack("<Q", exactly(8))
    return pickle.loads(exactly(n))


def _vm_size() -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


def _child(out: int, module: str, name: str, args: tuple) -> None:
    limit = _vm_size() + EXTRA_MEMORY
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    import colcos

    try:
        getattr(importlib.import_module(module), name)(*args)
        result: dict = {"ok": True}
    except BaseException as e:  # noqa: BLE001 - every kind is reported to the parent
        result = {
            "ok": False,
            "error_type": f"{type(e).__module__}.{type(e).__qualname__}",
            "message": str(e)[:1000],
            "is_colcos": isinstance(e, colcos.ColcosError),
        }
    _send(out, result)


def _serve(requests: int, replies: int) -> None:
    """The zygote: one forked child per request, its answer (or why there is none) sent back."""
    while True:
        try:
            module, name, args, timeout = _recv(requests)
        except EOFError:
            return
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(r)
            try:
                _child(w, module, name, args)
            finally:
                os._exit(0)
        os.close(w)
        deadline = time.monotonic() + timeout
        data = b""
        hung = False
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                hung = True
                break
            ready, _, _ = select.select([r], [], [], left)
            if ready:
                chunk = os.read(r, 1 << 16)
                if not chunk:
                    break
                data += chunk
        os.close(r)
        if hung:
            os.kill(pid, signal.SIGKILL)
        _, status = os.waitpid(pid, 0)
        if hung:
            reply: Any = {"failure": f"hung (no answer in {timeout} s)"}
        elif len(data) > 8:
            reply = pickle.loads(data[8:])
            if status != 0:
                reply = {"failure": f"answered, then exited with status {status}"}
        elif os.WIFSIGNALED(status):
            reply = {"failure": f"killed by signal {os.WTERMSIG(status)} (an abort or a crash)"}
        else:
            reply = {"failure": f"exited with status {os.WEXITSTATUS(status)} without an answer"}
        _send(replies, reply)


class _Zygote:
    def __init__(self, module: str) -> None:
        req_r, self.req_w = os.pipe()
        self.rep_r, rep_w = os.pipe()
        path = os.path.dirname(os.path.abspath(__file__))
        code = f"import sys; sys.path.insert(0, {path!r}); import isolate, {module}; isolate._serve({req_r}, {rep_w})"
        self.proc = subprocess.Popen([sys.executable, "-c", code], pass_fds=(req_r, rep_w))
        os.close(req_r)
        os.close(rep_w)

    def call(self, module: str, name: str, args: tuple, timeout: float) -> dict:
        _send(self.req_w, (module, name, args, timeout))
        return _recv(self.rep_r)


_ZYGOTES: dict[str, _Zygote] = {}


def run(fn: Callable[..., Any], *args: Any, timeout: float = 30.0) -> Outcome:
    """`fn(*args)` (a module-level function) in a forked child; raises AssertionError if the child
    hangs, aborts or dies."""
    module = fn.__module__
    if module not in _ZYGOTES:
        _ZYGOTES[module] = _Zygote(module)
    reply = _ZYGOTES[module].call(module, fn.__name__, args, timeout)
    if "failure" in reply:
        raise AssertionError(f"{fn.__name__}{args!r}: the child {reply['failure']}")
    return Outcome(**reply)
