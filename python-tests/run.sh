#!/usr/bin/env bash
# Builds the colcos wheel once (with `pip wheel ./pyo3-bindings`, the same path as the README's
# `pip install ./pyo3-bindings`), installs it into two venvs and runs every Python suite:
#   main venv  (requirements.txt):       PettingZoo suite, errors, vector env, determinism,
#                                        SuperSuit -> SB3, TorchRL
#   rllib venv (requirements-rllib.txt): RLlib ParallelPettingZooEnv (ray pins gymnasium 1.2.2)
# Usage: python-tests/run.sh [pytest args]       (from anywhere; uses python3 from PATH)
# Env: COLCOS_PY_WORK (default: <repo>/target/python) holds the venvs, wheel and cargo target dir.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/.." && pwd)"
work="${COLCOS_PY_WORK:-$repo/target/python}"
py="${PYTHON:-python3}"
mkdir -p "$work"
stamp() { date +%s; }
t0=$(stamp)

echo "== building the colcos wheel (pip wheel ./pyo3-bindings)"
[ -x "$work/build-venv/bin/python" ] || "$py" -m venv "$work/build-venv"
"$work/build-venv/bin/pip" install -q --upgrade pip "maturin==1.16.0"
rm -rf "$work/wheels"
# The bindings crate gets its own target dir: alternating with the workspace's builds would rebuild pyo3.
(cd "$repo" && CARGO_TARGET_DIR="$work/cargo-target" "$work/build-venv/bin/pip" wheel ./pyo3-bindings --no-deps -w "$work/wheels")
wheel="$(ls "$work/wheels"/colcos-*.whl)"
t1=$(stamp); echo "   wheel built in $((t1 - t0)) s: $wheel"

make_venv() { # name requirements
    local v="$work/$1"
    [ -x "$v/bin/python" ] || "$py" -m venv "$v"
    "$v/bin/pip" install -q --upgrade pip
    "$v/bin/pip" install -q -r "$2"
    "$v/bin/pip" install -q --force-reinstall --no-deps "$wheel"
}

peers="${COLCOS_PY_PEERS:-0}"
cd "$here"
status=0
if [ "$peers" != 1 ]; then
    echo "== core venv (PettingZoo, errors, vector env, determinism; COLCOS_PY_PEERS=1 adds the peer libraries)"
    make_venv venv-core "$here/requirements-core.txt"
    t2=$(stamp); echo "   installed in $((t2 - t1)) s"
    "$work/venv-core/bin/python" -m pytest -q -p no:cacheprovider \
        test_pettingzoo.py test_errors.py test_vector.py test_determinism.py \
        test_backend.py test_render_human.py "$@" || status=1
    echo "== python part done in $(( $(stamp) - t0 )) s (status $status)"
    exit $status
fi

echo "== main venv"
make_venv venv-main "$here/requirements.txt"
t2=$(stamp); echo "   installed in $((t2 - t1)) s"
echo "== rllib venv"
make_venv venv-rllib "$here/requirements-rllib.txt"
t3=$(stamp); echo "   installed in $((t3 - t2)) s"

echo "== pytest (main venv)"
"$work/venv-main/bin/python" -m pytest -q -p no:cacheprovider --ignore=test_rllib.py "$@" || status=1
t4=$(stamp); echo "   main suites in $((t4 - t3)) s"
echo "== pytest (rllib venv)"
"$work/venv-rllib/bin/python" -m pytest -q -p no:cacheprovider test_rllib.py "$@" || status=1
t5=$(stamp); echo "   rllib suite in $((t5 - t4)) s"
echo "== python part done in $((t5 - t0)) s (status $status)"
exit $status
