#!/usr/bin/env bash
# Builds the colcos wheel once (with `pip wheel ./pyo3-bindings`, the same path as the README's
# `pip install ./pyo3-bindings`), installs it into two venvs and runs every Python suite (what CI runs):
#   main venv  (requirements.txt):       PettingZoo suite, errors, vector env, determinism,
#                                        SuperSuit -> SB3 PPO, our SB3 adapter, TorchRL
#   rllib venv (requirements-rllib.txt): RLlib ParallelPettingZooEnv (ray pins gymnasium 1.2.2); sweeps on a local Ray cluster, the Ray Tune example
#   benchmarl venv (requirements-benchmarl.txt): colcos's BenchMARL task family, one tiny run per algorithm
# The requirement files are complete locks installed with --no-deps (no resolver); the main venv gets
# PyPI's torch without its CUDA libraries, made loadable by torch_cpu_stubs.py (see requirements.txt).
# The first run builds the wheel from a cold cargo target and fills both venvs (tens of minutes on
# two cores, ~760 MB downloaded, ~2.4 GB on disk); a rerun reuses the venvs and the cargo target.
# The wheel is the one users install: abi3 (CPython >= 3.10), its manylinux tag checked by maturin's
# compliance check; it is installed and tested with every cargo and rustc dropped from PATH, as on a
# machine without Rust. The sdist is built too and checked to hold what a build from it needs.
# Usage: python-tests/run.sh [pytest args]       (from anywhere; uses python3 from PATH)
# Env: COLCOS_PY_WORK (default: <repo>/target/python) holds the venvs, wheel and cargo target dir.
#      COLCOS_PY_PEERS=0 runs only the core suites in a small venv (requirements-core.txt, ~1 min).
#      COLCOS_WHEEL_COMPAT (default manylinux_2_35): the wheel's platform tag (maturin --compatibility).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/.." && pwd)"
work="${COLCOS_PY_WORK:-$repo/target/python}"
py="${PYTHON:-python3}"
mkdir -p "$work"
stamp() { date +%s; }
t0=$(stamp)
t=$t0
lap() { local now; now=$(stamp); echo "   $1 in $((now - t)) s"; t=$now; }

compat="${COLCOS_WHEEL_COMPAT:-manylinux_2_35}"
echo "== building the colcos wheel (pip wheel ./pyo3-bindings, maturin --compatibility $compat)"
[ -x "$work/build-venv/bin/python" ] || "$py" -m venv "$work/build-venv"
"$work/build-venv/bin/pip" install -q --upgrade pip "maturin==1.16.0"
rm -rf "$work/wheels" "$work/sdist"
# The bindings build shares the workspace target dir: the sim crates it depends on are then built once
# for both (crates built with other features sit beside each other; nothing is rebuilt back and forth).
# --compatibility makes maturin check the library against that manylinux policy (glibc symbol
# versions, linked libraries) and tag the wheel with it; the lowest policy a build passes depends on
# the building machine's glibc (docs/python.md, "Install").
(cd "$repo" && CARGO_TARGET_DIR="${COLCOS_PY_CARGO_TARGET:-$repo/target}" MATURIN_PEP517_ARGS="--compatibility $compat" \
    "$work/build-venv/bin/pip" wheel ./pyo3-bindings --no-deps -w "$work/wheels")
wheel="$(ls "$work/wheels"/colcos-*.whl)"
case "$(basename "$wheel")" in
    colcos-*-cp310-abi3-"$compat"_*.whl) ;;
    *) echo "error: $wheel is not the cp310-abi3-$compat wheel (pyo3's abi3-py310 feature, maturin --compatibility)"; exit 1 ;;
esac
lap "wheel built ($wheel, $(du -h "$wheel" | cut -f1))"
"$work/build-venv/bin/maturin" sdist -m "$repo/pyo3-bindings/Cargo.toml" -o "$work/sdist"
"$work/build-venv/bin/python" "$here/check_sdist.py" "$work/sdist"/colcos-*.tar.gz
lap "sdist built and checked"

# Every PATH entry holding cargo or rustc is dropped where the wheel is installed and tested, and
# rustup's and cargo's variables are unset: the package must not need Rust once built.
# A system folder (a distribution's packaged Rust in /usr/bin) cannot be dropped without the shell's
# own tools: then the check that Rust is gone is left out, and said.
norust_path=""
rust_in_system=0
IFS=: read -r -a path_dirs <<<"$PATH"
for d in "${path_dirs[@]}"; do
    if [ -e "$d/cargo" ] || [ -e "$d/rustc" ]; then
        case "$d" in
            /bin | /usr/bin | /sbin | /usr/sbin) rust_in_system=1 ;;
            *) continue ;;
        esac
    fi
    norust_path="${norust_path:+$norust_path:}$d"
done
[ "$rust_in_system" = 0 ] || echo "note: Rust is installed in a system folder on PATH: the tests run with it there"
no_rust() { env -u CARGO_HOME -u RUSTUP_HOME -u RUSTUP_TOOLCHAIN -u CARGO_TARGET_DIR PATH="$norust_path" "$@"; }

make_venv() { # name requirements [pip install options]
    local v="$work/$1" req="$2"
    shift 2
    [ -x "$v/bin/python" ] || "$py" -m venv "$v"
    "$v/bin/pip" install -q --upgrade pip
    # --no-compile: byte-compiling every module of torch and ray up front costs minutes on 2 cores;
    # Python compiles (and caches) the modules the tests import when they first run.
    "$v/bin/pip" install -q --no-compile "$@" -r "$req"
    no_rust "$v/bin/pip" install -q --no-compile --force-reinstall --no-deps "$wheel"
    [ "$rust_in_system" = 1 ] || no_rust "$v/bin/python" -c 'import shutil, sys; found = {t: shutil.which(t) for t in ("cargo", "rustc") if shutil.which(t)}; sys.exit(f"error: Rust is still on PATH: {found}" if found else 0)'
}

# A --no-deps lock that misses a dependency fails here rather than in a test. torch's CUDA requirements
# are deliberately left out of the main venv (the stubs stand in for them).
check_venv() { # name
    local out
    out="$("$work/$1/bin/pip" check 2>&1 | grep -v -E '^torch [^ ]+ requires (nvidia-|cuda-|triton)|^benchmarl [^ ]+ requires (torchvision|av)' || true)"
    if [ -n "$out" ] && [ "$out" != "No broken requirements found." ]; then
        echo "$out"
        echo "error: the $1 lock is incomplete (python-tests/requirements*.txt)"
        exit 1
    fi
}

cd "$here"
status=0
if [ "${COLCOS_PY_PEERS:-1}" = 0 ]; then
    echo "== core venv (PettingZoo, errors, vector env, determinism, ids, package; without COLCOS_PY_PEERS=0 also the peer libraries)"
    make_venv venv-core "$here/requirements-core.txt" --no-deps --only-binary=:all:
    check_venv venv-core
    lap "installed"
    no_rust "$work/venv-core/bin/python" -m pytest -q -p no:cacheprovider \
        test_pettingzoo.py test_errors.py test_misuse.py test_misuse_adapters.py test_hypothesis.py \
        test_vector.py test_determinism.py test_backend.py test_render_human.py test_behaviours.py \
        test_sweep.py test_plants.py test_preflight.py test_tutorial.py test_obstacles.py test_physics.py \
        test_env_ids.py test_package.py "$@" || status=1
    lap "core suites"
    echo "== python part done in $(($(stamp) - t0)) s (status $status)"
    exit $status
fi

echo "== main venv (requirements.txt, torch without its CUDA libraries)"
make_venv venv-main "$here/requirements.txt" --no-deps --only-binary=:all:
"$work/venv-main/bin/python" "$here/torch_cpu_stubs.py"
check_venv venv-main
# The peer suites importorskip their libraries: make a broken install fail here instead of skipping.
"$work/venv-main/bin/python" -c "import torch, tensordict, torchrl, stable_baselines3, supersuit"
lap "installed ($(du -sh "$work/venv-main" | cut -f1))"
echo "== rllib venv (requirements-rllib.txt)"
make_venv venv-rllib "$here/requirements-rllib.txt" --no-deps --only-binary=:all:
check_venv venv-rllib
"$work/venv-rllib/bin/python" -c "import ray.rllib"
lap "installed ($(du -sh "$work/venv-rllib" | cut -f1))"
echo "== benchmarl venv (requirements-benchmarl.txt)"
make_venv venv-benchmarl "$here/requirements-benchmarl.txt" --no-deps --only-binary=:all: --no-binary=benchmarl,antlr4-python3-runtime
"$work/venv-benchmarl/bin/python" "$here/torch_cpu_stubs.py"
check_venv venv-benchmarl
"$work/venv-benchmarl/bin/python" -c "import benchmarl.experiment, colcos.benchmarl"
lap "installed ($(du -sh "$work/venv-benchmarl" | cut -f1))"

echo "== pytest (main venv)"
no_rust "$work/venv-main/bin/python" -m pytest -q -p no:cacheprovider --durations=5 --ignore=test_rllib.py --ignore=test_sweep_ray.py --ignore=test_tune_example.py --ignore=test_benchmarl.py "$@" || status=1
lap "main suites"
echo "== pytest (rllib venv)"
no_rust "$work/venv-rllib/bin/python" -m pytest -q -p no:cacheprovider test_rllib.py test_sweep_ray.py test_tune_example.py "$@" || status=1
lap "rllib suite"
echo "== pytest (benchmarl venv)"
no_rust "$work/venv-benchmarl/bin/python" -m pytest -q -p no:cacheprovider test_benchmarl.py "$@" || status=1
lap "benchmarl suite"
echo "== python part done in $(($(stamp) - t0)) s (status $status)"
exit $status
