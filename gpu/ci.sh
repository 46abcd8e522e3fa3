#!/usr/bin/env bash
# CI for the GPU field backend and the display window, on Debian's software Vulkan driver (lavapipe).
# Called from .ci/run; needs root for apt-get (or the packages preinstalled).
#   apt packages: mesa-vulkan-drivers libvulkan1 (lavapipe), xvfb (X server), imagemagick (`import`
#   for the screenshot), xauth (xvfb-run).
# With COLCOS_REQUIRE_GPU=1 / COLCOS_REQUIRE_DISPLAY=1 the tests fail instead of skipping when the
# adapter or the display is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${COLCOS_CI_SKIP_APT:-0}" != 1 ]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        mesa-vulkan-drivers libvulkan1 xvfb xauth imagemagick >/dev/null
fi
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
export COLCOS_REQUIRE_GPU=1 COLCOS_REQUIRE_DISPLAY=1
# The same selection and features as scripts/test.sh's `cargo test`, so that nothing is built again:
# with `-p`, cargo unifies the dependencies' features over that package alone, and a cold machine
# then built the simulator's crates (and wgpu's) once per package named here. The test targets are
# picked by name (unique in the workspace); the GPU crates' unit tests need no adapter and run there.
workspace=(--release --workspace --features colcos-env/gpu)
# Built already where scripts/test.sh ran first; here on its own, this builds what it would.
cargo test "${workspace[@]}" --no-run
# GPU against CPU (colcos-gpu): every scheme and option, screens and sensors of both case studies,
# worlds; wgpu errors and a lost device as Err values. A vector env's worlds on the GPU (colcos-env,
# the scenario's [field] backend): every world's fields, deposits and sensing in one resident batch,
# the CPU's observations, rewards and resets.
cargo test "${workspace[@]}" --test errors --test grid_vs_cpu --test screen_and_worlds --test world_fields \
    --test backend --test gpu_batch -- --test-threads=1
# The window under Xvfb (colcos-display): screenshot against the headless PNG.
xvfb-run -a -s "-screen 0 640x480x24" cargo test "${workspace[@]}" --test headless --test xvfb -- --test-threads=1
# The CLI (the binary that build made for the CLI tests): `gpu` on lavapipe works, `auto` prefers the
# CPU over a software adapter.
colcos=target/release/colcos
$colcos run scenarios/three_trails.toml --duration 0.2 --backend gpu --quiet --out target/ci-gpu-run
# (the report goes to a file first: `grep -q` stops reading at its first match)
$colcos run scenarios/three_trails.toml --duration 0.2 --backend auto --quiet --out target/ci-auto-run \
    > target/ci-auto-run.log
grep -q "field backend: cpu" target/ci-auto-run.log
$colcos display scenarios/three_trails.toml --png target/ci-display.png --size 480x270 --seconds 0.1
# The window with the GPU backend presents with the backend's device and the GPU-composed screen.
xvfb-run -a -s "-screen 0 640x480x24" $colcos display scenarios/three_trails.toml \
    --backend gpu --size 480x270 --close-after 2 2>&1 | tee target/ci-display-gpu.log
grep -q "screen composed on the GPU" target/ci-display-gpu.log
grep -q "the device of the field backend" target/ci-display-gpu.log
# The bridge shows the arena's screen in a full-screen window while it drives the twin.
$colcos twin scenarios/case2_alarm.toml --tracker 127.0.0.1:16866 --robots udp://127.0.0.1:16867 --duration 5 \
    > target/ci-twin.log 2>&1 &
sleep 0.5
xvfb-run -a -s "-screen 0 640x480x24" $colcos bridge scenarios/case2_alarm.toml \
    --tracker swarmcon://127.0.0.1:16866 --robots udp://127.0.0.1:16867 --display 0 --duration 2 --quiet \
    --out target/ci-bridge > target/ci-bridge.log 2>&1
wait
grep -q "safety stops: none" target/ci-bridge.log
grep -q "commands received" target/ci-twin.log
