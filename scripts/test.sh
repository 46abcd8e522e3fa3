#!/usr/bin/env bash
# The whole test suite, on a fresh machine (Rust toolchain, Python 3.11 with pip, root for apt-get):
#   1. formatting and lints of the Rust workspace and the Python package (ruff, mypy),
#   2. the Rust tests (simulator, case studies, CLI, RL core),
#   3. the GPU field backend on Debian's software Vulkan driver and the display window under Xvfb,
#   4. the Python package through PettingZoo's, SuperSuit/SB3's, RLlib's and TorchRL's own checks.
# Set COLCOS_SKIP_GPU=1 or COLCOS_SKIP_PYTHON=1 to leave a part out locally.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never
t0=$(date +%s)
say() { echo; echo "== $* ($(( $(date +%s) - t0 )) s)"; }

say "cargo fmt --check"
cargo fmt --all -- --check
cargo fmt --manifest-path pyo3-bindings/Cargo.toml -- --check

say "cargo clippy"
cargo clippy --workspace --all-targets --features colcos-env/gpu -- -D warnings
# The Python bindings are a workspace of their own (maturin builds them); sharing the target dir reuses
# the checked dependencies of the line above. --locked: their committed Cargo.lock must be current
# (`pip install ./pyo3-bindings` would otherwise rewrite it).
CARGO_TARGET_DIR=target cargo clippy --locked --manifest-path pyo3-bindings/Cargo.toml --all-targets -- -D warnings

say "ruff and mypy on the Python package (pinned in python-tests/requirements-lint.txt)"
[ -x target/python-lint/bin/python ] || python3 -m venv target/python-lint
target/python-lint/bin/pip install -q --no-deps --only-binary=:all: -r python-tests/requirements-lint.txt
(cd pyo3-bindings && ../target/python-lint/bin/ruff check python/colcos && ../target/python-lint/bin/mypy)

say "cargo test (release profile, shared with the GPU and Python builds)"
# gpu/ci.sh runs its tests with this same selection and features: nothing is built twice.
cargo test --workspace --release --features colcos-env/gpu

if [ "${COLCOS_SKIP_GPU:-0}" != 1 ]; then
    say "GPU backend on lavapipe, display window under Xvfb"
    bash gpu/ci.sh
fi

if [ "${COLCOS_SKIP_PYTHON:-0}" != 1 ]; then
    say "Python package"
    bash python-tests/run.sh
fi

say "all tests passed"
