#!/usr/bin/env bash
# Flash and RAM of the PPO example's actor (17-64-64-2, tanh) exported with colcos.onboard for the
# Colias's STM32F334 (72 MHz Cortex-M4F, 12 KB SRAM, 64 KB flash). Not run in CI.
#
#   apt-get install -y gcc-arm-none-eabi            # Debian's toolchain (with newlib)
#   bash scripts/onboard_footprint.sh [policy.pt]   # default: an untrained actor of the same shape
#
# Prints arm-none-eabi-size of the policy's object (-mcpu=cortex-m4 -mfpu=fpv4-sp-d16
# -mfloat-abi=hard -Os), its stack per function (-fstack-usage) and the deepest call chain, and the
# flash the policy adds to a minimal firmware (examples/onboard_firmware.c linked with and without it,
# newlib's tanhf included). Sizes do not depend on the weights' values.
# Env: PYTHON, a python with colcos installed (default: target/python/venv-main/bin/python, else
# python3); OUT, the build directory (default: target/onboard).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${OUT:-$repo/target/onboard}"
py="${PYTHON:-}"
if [ -z "$py" ]; then
    if [ -x "$repo/target/python/venv-main/bin/python" ]; then py="$repo/target/python/venv-main/bin/python"; else py=python3; fi
fi
for tool in arm-none-eabi-gcc arm-none-eabi-size arm-none-eabi-objdump; do
    command -v "$tool" >/dev/null || { echo "error: $tool not found: apt-get install -y gcc-arm-none-eabi" >&2; exit 1; }
done
"$py" -c "import colcos.onboard" 2>/dev/null || { echo "error: $py cannot import colcos.onboard: set PYTHON to a python with colcos installed (python-tests/run.sh makes one)" >&2; exit 1; }
mkdir -p "$out"

echo "== export ($("$py" --version), $(date -u +%Y-%m-%dT%H:%MZ), $(uname -m), $(nproc) cores)"
"$py" "$repo/examples/onboard_export.py" --out "$out/policy" ${1:+--policy "$1"}

cflags=(-std=c99 -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -Os -Wall -Wextra -Werror)
echo "== object: arm-none-eabi-gcc ${cflags[*]} -fstack-usage -c policy.c ($(arm-none-eabi-gcc -dumpversion))"
(cd "$out" && arm-none-eabi-gcc "${cflags[@]}" -fstack-usage -c policy.c -o policy.o)
arm-none-eabi-size "$out/policy.o"
echo "   sections:"
arm-none-eabi-size -A "$out/policy.o" | awk '$2 > 0 && $1 ~ /^\./ {printf "     %-12s %7d bytes\n", $1, $2}'

echo "== stack per function (bytes, -fstack-usage)"
sed -E 's/^[^:]*:[0-9]+:[0-9]+:/   /' "$out/policy.su"
frame() { awk -v f="$1" -F'\t' '{n=split($1,a,":"); if (a[n]==f) print $2}' "$out/policy.su"; }
# Newlib's tanhf and what it calls are not in the .su file: their frames from the prologues (push, vpush,
# sub sp in the first instructions) of the linked firmware below.
libm_frame() { # function -> bytes its prologue reserves
    arm-none-eabi-objdump -d "$out/firmware.elf" | awk -v f="<$1>:" '
        $2 == f {on = 1; k = 0; next}
        on && (/^$/ || ++k > 6) {on = 0}
        on && /push|vpush|stmdb\tsp!/ { n = gsub(/r[0-9]+|lr|fp|ip/, "&"); d = gsub(/d[0-9]+/, "&"); s = gsub(/s[0-9]+/, "&"); b += 4 * n + 8 * d + 4 * s }
        on && /sub\tsp, #/ { match($0, /#[0-9]+/); b += substr($0, RSTART + 1, RLENGTH - 1) }
        END {print b + 0}'
}

echo "== firmware: examples/onboard_firmware.c with and without the policy (-specs=nano.specs -specs=nosys.specs -Wl,--gc-sections)"
lflags=(-ffunction-sections -fdata-sections -specs=nano.specs -specs=nosys.specs -Wl,--gc-sections)
arm-none-eabi-gcc "${cflags[@]}" "${lflags[@]}" -I"$out" -DWITH_POLICY=0 "$repo/examples/onboard_firmware.c" -o "$out/firmware_none.elf" -lm
arm-none-eabi-gcc "${cflags[@]}" "${lflags[@]}" -I"$out" -DWITH_POLICY=1 "$repo/examples/onboard_firmware.c" "$out/policy.c" -o "$out/firmware.elf" -lm
arm-none-eabi-size "$out/firmware_none.elf" "$out/firmware.elf"
read -r t0 d0 b0 _ < <(arm-none-eabi-size "$out/firmware_none.elf" | tail -1)
read -r t1 d1 b1 _ < <(arm-none-eabi-size "$out/firmware.elf" | tail -1)
syms() { arm-none-eabi-nm -S -t d "$1" | awk '$3 ~ /[Tt]/ && $4 !~ /^(colcos_policy|main$)/ {print $4 " " $2 + 0}' | sort; }
echo "   the policy adds $((t1 + d1 - t0 - d0)) bytes of flash (text + data); library functions it pulls in (bytes):"
comm -13 <(syms "$out/firmware_none.elf") <(syms "$out/firmware.elf") | sed 's/^/     /'
read -r pt pd pb _ < <(arm-none-eabi-size "$out/policy.o" | tail -1)

step="$(frame colcos_policy_step_with)"; encode="$(frame colcos_policy_encode_with)"; pow="$(frame colcos_policy_pow_unit)"
act="$(frame colcos_policy_act)"; forward="$(frame colcos_policy_forward)"; dense="$(frame colcos_policy_dense)"
tanh="$(libm_frame tanhf)"; expm1="$(libm_frame expm1f)"
enc_chain=$((encode + ${pow:-0}))
net_chain=$((act + forward + (${dense:-0} > tanh + expm1 ? ${dense:-0} : tanh + expm1)))
deepest=$((step + (enc_chain > net_chain ? enc_chain : net_chain)))
echo "== deepest stack below control_tick: step_with $step + max(encode $encode + pow_unit ${pow:-inlined}, act $act + forward $forward + max(dense ${dense:-inlined}, tanhf $tanh + expm1f $expm1)) = $deepest bytes"
echo "== summary: flash $((t1 + d1 - t0 - d0)) bytes of 65536 (policy.o $((pt + pd)) + libm and the rest), static RAM $((pd + pb)) bytes in policy.o, $((d1 + b1 - d0 - b0)) added to the firmware (its parameter block and state), stack $deepest bytes of 12288 SRAM"
