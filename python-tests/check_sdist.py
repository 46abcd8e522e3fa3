"""Checks that colcos's sdist holds what a build from it needs, without building it (a cold release
build of the native module takes tens of minutes on two cores).

Usage: python check_sdist.py colcos-<version>.tar.gz      (run.sh runs it on the sdist it builds)

The package's crate depends on path crates of the main workspace (sim, env, ...), which maturin copies
into the sdist beside it. In the unpacked sdist this asserts that `cargo metadata --locked --offline`
resolves the crate with the sdist's own lock file (every manifest there parses, the path crates'
workspace settings included), that every local crate in the dependency graph has its library's
sources and build script, and that the Python package, its typing marker and the task scenarios are
there. It prints what the sdist holds, crate by crate.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tarfile
import tempfile
from collections import Counter
from pathlib import Path

# Files the build or the installed package needs that the dependency graph does not name: the Python
# sources (maturin's python-source), the typing marker, and the data the crates embed at compile time.
REQUIRED = [
    "pyproject.toml",
    "python/colcos/__init__.py",
    "python/colcos/py.typed",
    "python/colcos/_core.pyi",
    "python/colcos/tasks/__init__.py",
    "env/scenarios/aggregation.toml",
    "sim/src/output/DejaVuSans-subset.ttf",
    "gpu/src/field.wgsl",
    "gpu/src/screen/screen.wgsl",
]


def main(sdist: Path) -> None:
    with tempfile.TemporaryDirectory() as tmp, tarfile.open(sdist) as tar:
        tar.extractall(tmp, filter="data")
        (root,) = Path(tmp).iterdir()
        files = sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file())
        missing = [f for f in REQUIRED if f not in files]
        assert not missing, f"{sdist.name} lacks {missing}"

        manifest = root / "pyo3-bindings" / "Cargo.toml"
        out = subprocess.run(
            ["cargo", "metadata", "--locked", "--offline", "--format-version", "1", "--manifest-path", str(manifest)],
            capture_output=True,
            text=True,
        )
        assert out.returncode == 0, f"cargo metadata fails on {sdist.name}:\n{out.stderr}"
        meta = json.loads(out.stdout)
        local = [p for p in meta["packages"] if p["source"] is None]
        for pkg in local:
            for target in pkg["targets"]:
                if {"lib", "cdylib", "custom-build"} & set(target["kind"]):
                    assert Path(target["src_path"]).is_file(), f"{sdist.name} lacks {target['src_path']} ({pkg['name']})"

        per_dir = Counter(f.split("/", 1)[0] if "/" in f else "." for f in files)
        crates = ", ".join(sorted(p["name"] for p in local))
        print(f"{sdist.name}: {sdist.stat().st_size / 1e6:.2f} MB, {len(files)} files; local crates resolved: {crates}")
        print("  files per top-level directory: " + ", ".join(f"{d} {n}" for d, n in sorted(per_dir.items())))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(Path(sys.argv[1]))
