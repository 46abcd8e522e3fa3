"""The installed package: one version everywhere, complete metadata, the stable-ABI native module, the
typing marker. run.sh installs the wheel and runs this with cargo and rustc off PATH."""

from __future__ import annotations

import importlib.metadata as md
import re
from pathlib import Path

import colcos
from colcos import _core

REPO = Path(__file__).resolve().parents[1]


def test_one_version():
    # Written once, as the crate's version: the native module, the package and its metadata agree.
    # Read with patterns rather than tomllib, which Python 3.10 (the oldest the wheel serves) lacks.
    cargo = (REPO / "pyo3-bindings" / "Cargo.toml").read_text()
    crate = re.search(r'^\[package\][^\[]*?^version = "([^"]+)"', cargo, re.M | re.S)
    assert crate is not None
    assert colcos.__version__ == _core.__version__ == md.version("colcos") == crate.group(1)
    project = (REPO / "pyo3-bindings" / "pyproject.toml").read_text().split("[project]", 1)[1].split("\n[", 1)[0]
    assert 'dynamic = ["version"]' in project and not re.search(r"^version\s*=", project, re.M)


def test_metadata_complete():
    meta = md.metadata("colcos")
    assert meta["Name"] == "colcos" and meta["Summary"]
    assert meta["Requires-Python"] == ">=3.10"
    assert meta["License-Expression"] == "MIT OR Apache-2.0"
    classifiers = meta.get_all("Classifier") or []
    for c in ("Typing :: Typed", "Programming Language :: Rust", "Programming Language :: Python :: 3.10"):
        assert c in classifiers
    assert meta["Description-Content-Type"].startswith("text/markdown") and "pip install" in meta.get_payload()
    requires = meta.get_all("Requires-Dist") or []
    assert {re.split(r"[<>=; ]", r, maxsplit=1)[0] for r in requires} >= {"numpy", "gymnasium", "pettingzoo"}
    # The licence texts travel with the package (PEP 639 `License-File`, under dist-info/licenses).
    assert set(meta.get_all("License-File") or []) >= {"LICENSE-MIT", "LICENSE-APACHE"}
    files = {f.name for f in md.files("colcos") or []}
    assert {"LICENSE-MIT", "LICENSE-APACHE"} <= files


def test_abi3_native_module_and_typing_marker():
    dist = md.distribution("colcos")
    files = {str(f) for f in dist.files or []}
    # One native module for every CPython >= 3.10 (pyo3's abi3-py310), and the wheel says so.
    assert any(re.fullmatch(r"colcos/_core\.abi3\.so", f) for f in files), sorted(files)
    wheel = dist.read_text("WHEEL") or ""
    assert re.search(r"^Tag: cp310-abi3-", wheel, re.M), wheel
    assert "colcos/py.typed" in files and "colcos/tasks/__init__.py" in files
    assert Path(_core.__file__).name == "_core.abi3.so"
