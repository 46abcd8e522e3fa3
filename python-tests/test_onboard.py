"""Policies on board: the exported C, compiled with the host's compiler, against the Python policy (on
10,000 observations of a real `parallel_env` rollout) and against the simulator's observation encoding."""

from __future__ import annotations

import ctypes
import importlib.util
import shutil
import subprocess
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import colcos
from colcos.onboard import Encoding, ExportError, encode_counts, export_c
from example_modules import load_ppo

CC = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
pytestmark = pytest.mark.skipif(CC is None, reason="no C compiler (cc, gcc or clang) on PATH")
REPO = Path(__file__).resolve().parents[1]
N_OBS = 10_000
# Telemetry colour sensor w (front, back, left, right) -> simulator slot (right, front, left, back).
TELEMETRY_TO_SIM = (1, 3, 2, 0)
F32P = ctypes.POINTER(ctypes.c_float)
U16P = ctypes.POINTER(ctypes.c_uint16)


class CPolicy:
    """The exported C as a shared library, called row by row through ctypes."""

    def __init__(self, info, build: Path) -> None:
        so = build / f"lib{info.prefix}_{info.source.stem}.so"
        flags = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", "-shared", "-fPIC"]
        r = subprocess.run([CC, *flags, str(info.source), "-o", str(so), "-lm"], capture_output=True, text=True)
        assert r.returncode == 0, f"the exported C does not compile:\n{r.stderr}"
        lib = ctypes.CDLL(str(so))
        p = info.prefix
        self.encode_fn = getattr(lib, f"{p}_encode")
        self.encode_fn.argtypes = [U16P, U16P, U16P, ctypes.c_float, ctypes.c_float, F32P]
        self.forward_fn, self.act_fn = getattr(lib, f"{p}_forward"), getattr(lib, f"{p}_act")
        for f in (self.forward_fn, self.act_fn):
            f.argtypes = [F32P, F32P]
        self.step_fn = getattr(lib, f"{p}_step")
        self.step_fn.argtypes = [U16P, U16P, U16P, F32P, F32P]

    def _rows(self, fn, obs: np.ndarray) -> np.ndarray:
        obs = np.ascontiguousarray(obs, dtype=np.float32)
        out = np.zeros((len(obs), 2), dtype=np.float32)
        for i in range(len(obs)):
            fn(obs[i].ctypes.data_as(F32P), out[i].ctypes.data_as(F32P))
        return out

    def forward(self, obs: np.ndarray) -> np.ndarray:
        return self._rows(self.forward_fn, obs)

    def act(self, obs: np.ndarray) -> np.ndarray:
        return self._rows(self.act_fn, obs)

    def encode(self, colour: np.ndarray, on: np.ndarray, off: np.ndarray, last: np.ndarray) -> np.ndarray:
        colour, on, off = (np.ascontiguousarray(a, dtype=np.uint16) for a in (colour.reshape(len(colour), 12), on, off))
        out = np.zeros((len(colour), 17), dtype=np.float32)
        for i in range(len(colour)):
            self.encode_fn(
                colour[i].ctypes.data_as(U16P), on[i].ctypes.data_as(U16P), off[i].ctypes.data_as(U16P),
                float(last[i, 0]), float(last[i, 1]), out[i].ctypes.data_as(F32P),
            )  # fmt: skip
        return out

    def step(self, colour: np.ndarray, on: np.ndarray, off: np.ndarray, last: np.ndarray) -> np.ndarray:
        colour, on, off = (np.ascontiguousarray(a, dtype=np.uint16) for a in (colour.reshape(len(colour), 12), on, off))
        wheels = np.ascontiguousarray(last, dtype=np.float32).copy()
        for i in range(len(colour)):
            w = wheels[i]
            self.step_fn(
                colour[i].ctypes.data_as(U16P), on[i].ctypes.data_as(U16P), off[i].ctypes.data_as(U16P),
                w[0:1].ctypes.data_as(F32P), w[1:2].ctypes.data_as(F32P),
            )  # fmt: skip
        return wheels


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """The example's actor with wide output weights, and 10,000 observations of a parallel_env rollout it
    drove (with exploration noise); its input normaliser fitted to them, as training leaves it."""
    torch = pytest.importorskip("torch")
    example = load_ppo()
    torch.manual_seed(0)
    model = example.ActorCritic(17, 18)
    with torch.no_grad():  # the example starts near "stand still"; a trained actor drives
        model.pi[-1].weight.normal_(0.0, 0.6)
        model.pi[-1].bias.uniform_(-0.3, 0.3)
    env = colcos.parallel_env(task="aggregation", max_cycles=500)
    rng = np.random.default_rng(7)
    rows: list[np.ndarray] = []
    episode = 0
    obs, _ = env.reset(seed=100)
    while len(rows) < N_OBS:
        if not env.agents:
            episode += 1
            obs, _ = env.reset(seed=100 + episode)
        batch = np.stack([obs[a] for a in env.agents])
        rows.extend(batch)
        act = np.clip(model.act(batch) + rng.normal(0.0, 0.3, size=(len(batch), 2)), -1, 1).astype(np.float32)
        obs, *_ = env.step({a: act[k] for k, a in enumerate(env.agents)})
    env.close()
    observations = np.stack(rows[:N_OBS]).astype(np.float32)
    model.obs_norm.update(torch.from_numpy(observations))
    build = tmp_path_factory.mktemp("onboard")
    info = export_c(model.pi, build / "policy", obs_norm=model.obs_norm)
    return SimpleNamespace(torch=torch, model=model, obs=observations, info=info, c=CPolicy(info, build), build=build)


def test_c_actions_match_the_python_policy_on_10000_observations(recorded):
    torch, model, obs = recorded.torch, recorded.model, recorded.obs
    with torch.no_grad():
        raw = model.pi(model.obs_norm(torch.from_numpy(obs))).numpy()
    act = model.act(obs)
    c_raw, c_act = recorded.c.forward(obs), recorded.c.act(obs)
    d_raw, d_act = float(np.abs(c_raw - raw).max()), float(np.abs(c_act - act).max())
    print(
        f"\nC vs torch over {len(obs):,} observations: max |action difference| {d_act:.3g}, raw outputs {d_raw:.3g} (|raw| up to {np.abs(raw).max():.2f})"
    )
    # The comparison means something only if the actions are spread out and mostly not clamped.
    assert (np.abs(act) < 0.99).mean() > 0.5 and act.std(0).min() > 0.2, "the test policy's actions are degenerate"
    assert d_act <= 1e-5
    assert d_raw <= 1e-5 * max(1.0, float(np.abs(raw).max()))


def reconstruct_counts(obs: np.ndarray, enc: Encoding):
    """Raw readings that the simulator's sensor model turns into `obs`: the forward model (transfer
    curve, crosstalk, gain, dark counts) applied to the intensities. Exact (the very counts the
    simulator drew) for a sensor whose three channels lie strictly inside (0, 1); returned with that mask
    (per simulator slot), in the telemetry's order, with the bumpers' and the last command's raw values."""
    inten = obs[:, :12].reshape(-1, 4, 3).astype(np.float64)
    raw = enc.dark_counts + enc.gain * enc.integration_ms * (inten**enc.gamma) @ np.asarray(enc.crosstalk).T
    counts = np.clip(np.rint(raw), 0, 65535)
    exact = (np.abs(raw - counts) < 0.05).all(-1) & (inten > 0).all(-1) & (inten < 1).all(-1)
    wire = np.zeros((len(obs), 4, 3), dtype=np.uint16)
    for w, s in enumerate(TELEMETRY_TO_SIM):
        wire[:, w] = counts[:, s]
    off = np.full((len(obs), 3), 100, dtype=np.uint16)
    on = (100 + np.rint(obs[:, 12:15].astype(np.float64) * enc.bumper_span)).astype(np.uint16)
    last = (obs[:, 15:17] * np.float32(enc.max_wheel_speed)).astype(np.float32)
    return wire, on, off, last, exact


def test_c_encoding_gives_the_simulators_observations(recorded):
    obs, enc = recorded.obs, Encoding()
    wire, on, off, last, exact = reconstruct_counts(obs, enc)
    got = recorded.c.encode(wire, on, off, last)
    sensors = np.repeat(exact, 3, axis=1)  # (N, 12): the channels of exactly reconstructed sensors
    d_colour = float(np.abs(got[:, :12] - obs[:, :12])[sensors].max())
    d_bump, d_last = float(np.abs(got[:, 12:15] - obs[:, 12:15]).max()), float(np.abs(got[:, 15:] - obs[:, 15:]).max())
    print(
        f"\nC encoding vs the simulator: {exact.sum():,} of {exact.size:,} sensor readings reconstructed exactly, max |intensity difference| {d_colour:.3g}; bumpers {d_bump:.3g}, last command {d_last:.3g}"
    )
    assert exact.sum() > 5_000, "too few sensor readings to compare"
    assert (obs[:, 12:15] > 0).any(), "no bumper contact in the rollout"
    assert d_colour <= 1e-6
    assert d_bump <= 0.5 / enc.bumper_span + 1e-6  # the bumper counts are whole numbers
    assert d_last <= 1e-6


def test_c_step_turns_raw_readings_into_the_policys_wheel_speeds(recorded):
    """`step` (encode, act, decode) from raw readings: the torch policy's wheel speeds on what the C
    encodes, for every observation; and on the simulator's own observation where all four sensors and
    the bumpers were reconstructed exactly."""
    obs, enc, model = recorded.obs, Encoding(), recorded.model
    wire, on, off, last, exact = reconstruct_counts(obs, enc)
    wheels = recorded.c.step(wire, on, off, last)
    speed = np.float32(enc.max_wheel_speed)
    assert float(np.abs(wheels - model.act(recorded.c.encode(wire, on, off, last)) * speed).max()) <= 1e-5
    bumps = obs[:, 12:15].astype(np.float64) * enc.bumper_span
    whole = exact.all(1) & (np.abs(bumps - np.rint(bumps)) < 1e-3).all(1)
    assert whole.sum() > 50
    assert float(np.abs(wheels[whole] - model.act(obs[whole]) * speed).max()) <= 1e-5


def test_c_encoding_matches_the_numpy_reference_at_the_edges(recorded):
    rng = np.random.default_rng(3)
    n = 4000
    colour = rng.integers(0, 65536, size=(n, 4, 3)).astype(np.uint16)
    colour[: n // 4] = rng.integers(0, 200, size=(n // 4, 4, 3))  # dark: the clamp at 0 light
    colour[n // 4 : n // 2] = rng.integers(40000, 65536, size=(n // 4, 4, 3))  # bright: the clamp at 1
    colour[::7, 0, 1] = 65535  # saturated channels read 1
    on, off = rng.integers(0, 4000, size=(n, 3)), rng.integers(0, 400, size=(n, 3))
    last = rng.uniform(-0.5, 0.5, size=(n, 2)).astype(np.float32)
    last[::11, 0] = np.nan  # a corrupt command reads as 0
    got = recorded.c.encode(colour, on, off, last)
    want = encode_counts(colour, on, off, last)
    assert np.all(np.isfinite(got)) and got[:, :15].min() >= 0 and got[:, :15].max() <= 1
    assert float(np.abs(got - want).max()) <= 2e-6
    assert np.all(got[::7, 4] == 1.0)  # telemetry front -> simulator slot 1: its green is input 3 * 1 + 1
    assert np.all(got[::11, 15] == 0.0)


def test_torch_module_and_weight_lists_give_the_same_c(recorded, tmp_path):
    pi = recorded.model.pi
    pairs = [(m.weight, m.bias) for m in pi if hasattr(m, "weight")]
    a = export_c(pi, tmp_path / "a", obs_norm=recorded.model.obs_norm, prefix="p")
    b = export_c(pairs, tmp_path / "b.c", obs_mean=recorded.model.obs_norm.mean, obs_var=recorded.model.obs_norm.var, prefix="p")
    assert b.source == tmp_path / "b.c" and b.header == tmp_path / "b.h"
    assert a.source.read_text().split("\n", 1)[1] == b.source.read_text().split("\n", 1)[1].replace('"b.h"', '"a.h"')
    assert (a.n_params, a.weight_bytes, a.stack_bytes, a.macs) == (5442, 21904, 512, 5312)


@pytest.mark.parametrize("activation", ["relu", "sigmoid", "identity"])
def test_other_activations_without_normaliser(activation, tmp_path):
    rng = np.random.default_rng(5)
    sizes = [17, 24, 12, 2]
    layers = [(rng.normal(0, 0.6, (o, i)), rng.normal(0, 0.2, o)) for i, o in zip(sizes, sizes[1:], strict=False)]
    info = export_c(layers, tmp_path / "net", activation=activation, prefix=f"net_{activation}")
    x = rng.uniform(-1, 1, size=(500, 17)).astype(np.float32)
    h = x.astype(np.float64)
    f = {"relu": lambda v: np.maximum(v, 0), "sigmoid": lambda v: 1 / (1 + np.exp(-v)), "identity": lambda v: v}[activation]
    for k, (w, b) in enumerate(layers):
        h = h @ np.float32(w).T.astype(np.float64) + np.float32(b)
        h = f(h) if k < len(layers) - 1 else h
    got = CPolicy(info, tmp_path).forward(x)
    assert float(np.abs(got - h).max()) <= 1e-5 * max(1.0, float(np.abs(h).max()))
    assert ("tanhf" in info.source.read_text()) is False


def test_encoding_from_scenario():
    assert Encoding.from_scenario('name = "x"\ndt = 0.02\n') == Encoding()  # the simulator's defaults
    assert Encoding.from_scenario(colcos.default_scenario("aggregation")).checked()
    enc = Encoding.from_scenario("dt = 0.05\n[sensor]\ngain = 1000.0\ndark_counts = 12\n[robot]\nmax_wheel_speed = 0.2\n")
    assert (enc.gain, enc.dark_counts, enc.max_wheel_speed, enc.dt, enc.integration_ms) == (1000.0, 12, 0.2, 0.05, 24.0)
    with pytest.raises(ExportError, match="singular"):
        Encoding.from_scenario("[sensor]\ncrosstalk = [[1, 1, 0], [1, 1, 0], [0, 0, 1]]\n")
    with pytest.raises(ExportError, match="`crosstalk` = 3: must be a 3x3 matrix"):
        Encoding.from_scenario("[sensor]\ncrosstalk = 3\n")
    with pytest.raises(ExportError, match="unknown encoding key `gian`"):
        Encoding.from_scenario("dt = 0.02", gian=3)
    with pytest.raises(ExportError, match="not valid TOML"):
        Encoding.from_scenario("[sensor\n")
    with pytest.raises(ExportError, match=r"`gain` = -1"):
        Encoding(gain=-1).checked()
    with pytest.raises(ExportError, match="cannot read"):
        Encoding.from_scenario("no/such/scenario.toml")


def _bad_policies(torch):
    nn = torch.nn
    z = np.zeros
    return [
        ("policy.pt", "builtins.str"),
        ({"pi.0.weight": z((64, 17))}, "builtins.dict"),
        (load_ppo().ActorCritic(17, 18), r"ActorCritic, not an nn.Sequential \(pass its actor, e.g. model.pi"),
        (nn.Sequential(nn.Linear(17, 8), nn.Dropout(), nn.Linear(8, 2)), r"policy\[1\] is Dropout"),
        (nn.Sequential(nn.Tanh(), nn.Linear(17, 2)), r"policy\[0\] is Tanh before any Linear"),
        (nn.Sequential(nn.Linear(17, 8), nn.Tanh(), nn.ReLU(), nn.Linear(8, 2)), "right after another activation"),
        (nn.Sequential(nn.Linear(20, 2)), "takes 20 inputs: the on-board observation has 17"),
        (nn.Sequential(nn.Linear(17, 6)), "gives 6 outputs"),
        ([(z((8, 17)), z(4)), (z((2, 8)), z(2))], r"policy\[0\] bias has shape \(4,\)"),
        ([(z((8, 17)), z(8)), (z((2, 9)), z(2))], "layer 1 takes 9 inputs but layer 0 gives 8"),
        ([(np.full((2, 17), np.nan), z(2))], r"policy\[0\] weight holds nan"),
        ([(z((2, 17)), z(2)), "W"], r"policy\[1\] is a str"),
        ([(z((1024, 17)), z(1024)), (z((2, 1024)), z(2))], "max_weight_bytes"),
        ([], "no Linear layer"),
    ]


def test_refuses_what_it_cannot_export(tmp_path):
    torch = pytest.importorskip("torch")
    for policy, message in _bad_policies(torch):
        with pytest.raises(ExportError, match=message):
            export_c(policy, tmp_path / "x")
    ok = [(np.zeros((2, 17)), np.zeros(2))]
    for kwargs, message in [
        ({"activation": "gelu"}, "`activation` = 'gelu'"),
        ({"obs_mean": np.zeros(16), "obs_var": np.ones(16)}, r"`obs_mean` has shape \(16,\)"),
        ({"obs_mean": np.zeros(17)}, "go together"),
        ({"obs_mean": np.zeros(17), "obs_var": -np.ones(17)}, "variances must be >= 0"),
        ({"obs_norm": object()}, "without `mean` and `var`"),
        ({"prefix": "1st"}, "`prefix` = '1st'"),
        ({"encoding": {"gain": 1}}, "expected colcos.onboard.Encoding"),
        ({"encoding": Encoding(), "scenario": "dt = 0.02"}, "not both"),
    ]:
        with pytest.raises(ExportError, match=message):
            export_c(ok, tmp_path / "x", **kwargs)
    with pytest.raises(ExportError, match="is a directory"):
        export_c(ok, tmp_path)
    assert issubclass(ExportError, colcos.ColcosError)


def test_runtime_parameters_rewrite_the_encoding(tmp_path):
    """The C's runtime block (what the bridge writes with `PWP`): the defaults are the export's
    encoding; a block from another calibration encodes as that calibration does; bad writes change
    nothing."""
    rng = np.random.default_rng(11)
    info = export_c([(rng.normal(0, 0.3, (2, 17)), np.zeros(2))], tmp_path / "p", prefix="rt")
    so = tmp_path / "librt.so"
    r = subprocess.run([CC, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", "-shared", "-fPIC",
                        str(info.source), "-o", str(so), "-lm"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    lib = ctypes.CDLL(str(so))
    n = len(info.encoding.runtime_params())
    params = np.zeros(n, dtype=np.float32)
    lib.rt_default_params(params.ctypes.data_as(F32P))
    assert np.array_equal(params, Encoding().runtime_params())
    other = Encoding(gain=900.0, dark_counts=55.0, gamma=1.9, max_wheel_speed=0.2,
                     crosstalk=((1.0, 0.2, 0.0), (0.1, 0.9, 0.1), (0.0, 0.15, 1.1)))
    block = other.runtime_params()
    write = lib.rt_write_params
    write.argtypes = [F32P, ctypes.c_uint16, ctypes.c_uint8, F32P]
    for k in range(0, n, 5):
        chunk = np.zeros(5, dtype=np.float32)
        chunk[: min(5, n - k)] = block[k : k + 5]
        assert write(params.ctypes.data_as(F32P), k, min(5, n - k), chunk.ctypes.data_as(F32P)) == 1
    assert np.array_equal(params, block)
    for offset, values in [(n - 2, [1.0] * 3), (2, [0.0]), (3 + 14 + 3, [-1.0]), (0, [np.inf]), (7, [np.nan])]:
        v = np.array(values + [0.0] * (5 - len(values)), dtype=np.float32)
        assert write(params.ctypes.data_as(F32P), offset, len(values), v.ctypes.data_as(F32P)) == 0, (offset, values)
    assert np.array_equal(params, block)
    colour = rng.integers(0, 65536, size=(300, 4, 3)).astype(np.uint16)
    on, off = rng.integers(0, 4000, size=(300, 3)).astype(np.uint16), np.full((300, 3), 100, np.uint16)
    last = rng.uniform(-0.4, 0.4, size=(300, 2)).astype(np.float32)
    enc = lib.rt_encode_with
    enc.argtypes = [F32P, U16P, U16P, U16P, ctypes.c_float, ctypes.c_float, F32P]
    got = np.zeros((300, 17), dtype=np.float32)
    for i in range(300):
        c = np.ascontiguousarray(colour[i].reshape(12))
        enc(params.ctypes.data_as(F32P), c.ctypes.data_as(U16P), on[i].ctypes.data_as(U16P), off[i].ctypes.data_as(U16P),
            float(last[i, 0]), float(last[i, 1]), got[i].ctypes.data_as(F32P))
    want = encode_counts(colour, on, off, last, encoding=other)
    assert float(np.abs(got - want).max()) <= 2e-6


def test_hash_and_manifest(tmp_path):
    """The manifest names the policy (hash of its network) and its runtime defaults; the hash moves
    with any weight and not with the encoding."""
    import json

    rng = np.random.default_rng(3)
    layers = [(rng.normal(0, 0.3, (4, 17)), rng.normal(0, 0.1, 4)), (rng.normal(0, 0.3, (2, 4)), np.zeros(2))]
    a = export_c(layers, tmp_path / "a")
    m = json.loads(a.manifest.read_text())
    assert m["format"] == "colcos-onboard-policy/1" and m["hash"] == a.policy_hash and m["source"] == "a.c"
    assert np.array_equal(np.array(m["runtime_defaults"], dtype=np.float32), Encoding().runtime_params())
    assert f"#define COLCOS_POLICY_HASH 0x{a.policy_hash:08x}u" in a.header.read_text()
    assert export_c(layers, tmp_path / "b", encoding=Encoding(gain=700.0)).policy_hash == a.policy_hash
    nudged = [(layers[0][0], layers[0][1]), (layers[1][0] + np.float32(1e-3), layers[1][1])]
    assert export_c(nudged, tmp_path / "c").policy_hash != a.policy_hash


def test_the_bridges_fixture_is_what_export_c_writes(tmp_path):
    """bridge/tests/data/onboard is the twin's on-board policy in the Rust tests: written by
    scripts/onboard_fixture.py, and byte for byte what `export_c` writes now."""
    spec = importlib.util.spec_from_file_location("onboard_fixture", REPO / "scripts" / "onboard_fixture.py")
    assert spec is not None and spec.loader is not None
    fixture = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fixture)
    fixture.write(tmp_path)
    for name in ("policy.c", "policy.h", "policy.json"):
        committed = (REPO / "bridge" / "tests" / "data" / "onboard" / name).read_text()
        assert (tmp_path / name).read_text() == committed, f"{name}: run python scripts/onboard_fixture.py"


def test_the_example_runs_the_c_on_the_twins_robots(tmp_path):
    """`examples/onboard_export.py --twin`: the exported C on board the twin's robots, driven by
    `colcos bridge` with `[rig] onboard` (target/release/colcos, which `cargo test --release` builds)."""
    binary = REPO / "target" / "release" / "colcos"
    if not binary.is_file():
        pytest.skip(f"{binary} is missing: build it with `cargo build --release`")
    import sys

    done = subprocess.run(
        [sys.executable, str(REPO / "examples" / "onboard_export.py"), "--out", str(tmp_path / "policy"),
         "--twin", "2", "--colcos", str(binary)],
        capture_output=True, text=True, timeout=120,
    )
    assert done.returncode == 0, done.stderr
    line = done.stdout.strip().splitlines()[-1]
    assert "robots ran the C on board for 2 s" in line and "safety stops: none" in line, line
    moved = float(line.split("moved ")[1].split(" m")[0])
    assert moved > 0.005, line
    assert (tmp_path / "twin_run" / "rig.mcap").is_file()
