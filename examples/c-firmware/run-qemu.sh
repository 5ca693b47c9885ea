#!/usr/bin/env bash
# Build the C firmware example with arm-none-eabi-gcc against libgyro_ffi.a
# (thumbv7em-none-eabihf), boot it on an emulated Cortex-M4F (QEMU mps2-an386), and check
# that it computes exactly what the host computes: the same rate words go through `gyro-cli
# run` (paper and kalman compensation, the same tightening window), and every movement
# (start, end, angle, raw angle, σ, the saturated flag, the verdict) and the final angles
# must be the same numbers, bit for bit.
#
# Needs: cargo with the thumbv7em-none-eabihf target, arm-none-eabi-gcc, qemu-system-arm,
# jq, od, awk.
#   apt-get install -y --no-install-recommends gcc-arm-none-eabi qemu-system-arm jq
# Environment: QEMU (default qemu-system-arm), ARM_CC (default arm-none-eabi-gcc),
# QEMU_TIMEOUT_S (default 120), GYRO_CLI (the host's gyro-cli; default: `cargo run -p
# gyro-cli`).
# Exit status: 0 if the firmware ran clean and matches the host, 1 otherwise, 2 if a tool is
# missing.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
fixture=$root/fixtures/firmware/bench_run_20s.i16be
qemu=${QEMU:-qemu-system-arm}
arm_cc=${ARM_CC:-arm-none-eabi-gcc}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The tightening window of main.c (TARGET_DEG, TOLERANCE_DEG), given to gyro-cli as well.
target_deg=90
tolerance_deg=0.25

for tool in cargo "$arm_cc" "$qemu" jq od awk timeout; do
    if ! command -v "$tool" >/dev/null; then
        echo "run-qemu.sh: '$tool' not found" \
            "(apt-get install -y gcc-arm-none-eabi qemu-system-arm jq)" >&2
        exit 2
    fi
done

echo "== build libgyro_ffi.a for thumbv7em-none-eabihf"
(cd "$root" && cargo build --release -p gyro-ffi --target thumbv7em-none-eabihf)
target_dir=$(cd "$root" && cargo metadata --format-version 1 --no-deps | jq -r .target_directory)
lib=$target_dir/thumbv7em-none-eabihf/release/libgyro_ffi.a

echo "== build the C firmware with $arm_cc"
# Cortex-M4F, hard-float ABI: what thumbv7em-none-eabihf is. No C library: startup.c has
# the vector table, the reset handler and semihosting.
cflags=(-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -std=c11 -O2 -g
    -Wall -Wextra -Werror -ffreestanding -ffunction-sections -fdata-sections)
"$arm_cc" "${cflags[@]}" -I "$root/crates/gyro-ffi/include" -c "$here/main.c" -o "$work/main.o"
"$arm_cc" "${cflags[@]}" -c "$here/startup.c" -o "$work/startup.o"
"$arm_cc" "${cflags[@]}" "-Wa,-I$(dirname "$fixture")" -c "$here/fixture.S" -o "$work/fixture.o"
elf=$work/gyro-c-firmware.elf
"$arm_cc" "${cflags[@]}" -nostdlib -T "$here/link.ld" -Wl,--gc-sections -Wl,-z,noexecstack \
    "$work/main.o" "$work/startup.o" "$work/fixture.o" "$lib" -lgcc -o "$elf"
arm-none-eabi-size "$elf" 2>/dev/null || true

echo "== run it on qemu mps2-an386 (Cortex-M4F)"
status=0
timeout "${QEMU_TIMEOUT_S:-120}" "$qemu" -machine mps2-an386 -cpu cortex-m4 -nographic \
    -monitor none -serial none -semihosting-config enable=on,target=native \
    -kernel "$elf" >"$work/firmware.txt" || status=$?
cat "$work/firmware.txt"
if [ "$status" -ne 0 ]; then
    [ "$status" -eq 124 ] && echo "run-qemu.sh: qemu timed out" >&2
    echo "run-qemu.sh: C firmware run failed (exit status $status)" >&2
    exit 1
fi

echo "== the host: gyro-cli run on the same rate words"
# The CSV the host replays, as examples/firmware/run-qemu.sh makes it: counts/24 printed
# with 17 significant digits is the double nearest to it, which gyro-cli rounds to the same
# f32 the firmware computes ((float)counts / 24); times k/1000 parse to the firmware's.
csv=$work/bench_run_20s.csv
{
    echo "# sensor: CRM100 (fixtures/firmware/bench_run_20s.i16be, +/-300 deg/s, 24 LSB per deg/s)"
    echo "# sample_rate_hz: 1000"
    echo "time_s,rate_dps"
    od -An -v -t d2 --endian=big "$fixture" |
        awk '{ for (i = 1; i <= NF; i++) { printf "%.6f,%.17g\n", k / 1000, $i / 24; k++ } }'
} >"$csv"
# The host's gyro-cli: $GYRO_CLI when given (CI passes the one its test step built), else
# built here.
if [ -n "${GYRO_CLI:-}" ]; then
    host_cli=("$GYRO_CLI")
else
    host_cli=(cargo run -q -p gyro-cli --)
fi
for compensation in paper kalman; do
    (cd "$root" && "${host_cli[@]}" run "$csv" --compensation "$compensation" \
        --range-dps 300 --target-deg "$target_deg" --tolerance-deg "$tolerance_deg" \
        --format json) >"$work/host-$compensation.json"
    # One "compensation what key value" line per figure (flags as 0 or 1, null as none).
    jq -r --arg c "$compensation" '
        def text: if type == "boolean" then (if . then 1 else 0 end)
                  elif . == null then "none" else . end;
        (.movements[] | select(.complete) | . as $m
            | ("start_time_s", "end_time_s", "angle_deg", "raw_angle_deg", "angle_std_deg",
               "saturated", "verdict")
            | "\($c) movement_\($m.index) \(.) \($m[.] | text)"),
        (.summary | . as $s
            | ("outputs", "rejected_samples", "movements", "final_angle_deg", "final_raw_angle_deg")
            | "\($c) summary \(.) \($s[.] | text)")' "$work/host-$compensation.json"
done >"$work/host.txt"

# The same lines from the firmware's key=value output.
awk '
    $1 == "movement" || $1 == "summary" {
        delete f
        for (i = 2; i <= NF; i++) { split($i, kv, "="); f[kv[1]] = kv[2] }
        if ($1 == "movement") {
            n = split("start_time_s end_time_s angle_deg raw_angle_deg angle_std_deg saturated verdict", keys, " ")
            what = "movement_" f["index"]
        } else {
            n = split("outputs rejected_samples movements final_angle_deg final_raw_angle_deg", keys, " ")
            what = "summary"
        }
        for (i = 1; i <= n; i++) print f["compensation"], what, keys[i], f[keys[i]]
    }' "$work/firmware.txt" >"$work/firmware-figures.txt"

echo "== C firmware (qemu) against host (gyro-cli run)"
# The firmware prints IEEE 754 bits (0x + 8 hex digits: f32, 16: f64), decoded here to
# their exact values. The host prints decimals: a time is parsed as the double it is; an
# angle is the shortest decimal of an f32, rounded here to the nearest f32. Equal values are
# then the same bits. (awk works in doubles, which hold every f32 and f64 value exactly.)
awk '
    function hexval(s,    i, v) {
        v = 0
        for (i = 1; i <= length(s); i++) v = v * 16 + index("0123456789abcdef", substr(s, i, 1)) - 1
        return v
    }
    # 0x + 8 hex digits: an f32; 0x + 16: an f64 (normal numbers and zero).
    function from_bits(s,    h, top, e, m, sign) {
        h = substr(s, 3)
        if (length(h) == 8) {
            m = hexval(h)
            sign = m >= 2^31 ? -1 : 1; m = m % 2^31
            e = int(m / 2^23); m = m % 2^23
            return e == 0 ? sign * m * 2^-149 : sign * (m + 2^23) * 2^(e - 150)
        }
        top = hexval(substr(h, 1, 3)); m = hexval(substr(h, 4))
        sign = top >= 2048 ? -1 : 1; e = top % 2048
        return e == 0 ? sign * m * 2^-1074 : sign * (m + 2^52) * 2^(e - 1075)
    }
    # The f32 nearest to x (ties to even), for normal f32 magnitudes.
    function to_f32(x,    sign, e, r, frac) {
        if (x == 0) return 0
        sign = 1; if (x < 0) { sign = -1; x = -x }
        e = 0
        while (x >= 2^24) { x /= 2; e++ }
        while (x < 2^23) { x *= 2; e-- }
        r = int(x); frac = x - r
        if (frac > 0.5 || (frac == 0.5 && r % 2 == 1)) r++
        return sign * r * 2^e
    }
    BEGIN {
        printf "%-7s %-11s %-20s %-26s %-26s\n", "comp", "what", "figure", "firmware", "host"
        split("angle_deg raw_angle_deg angle_std_deg final_angle_deg final_raw_angle_deg", a, " ")
        for (i in a) is_f32[a[i]] = 1
        split("start_time_s end_time_s", a, " ")
        for (i in a) is_f64[a[i]] = 1
    }
    FNR == NR { host[$1 " " $2 " " $3] = $4; next }
    {
        id = $1 " " $2 " " $3
        if (!(id in host)) {
            printf "%-7s %-11s %-20s %-26s %-26s MISSING ON HOST\n", $1, $2, $3, $4, "-"; bad++
            next
        }
        mine = $4; theirs = host[id]
        if ((is_f32[$3] || is_f64[$3]) && mine ~ /^0x[0-9a-f]+$/ && theirs != "none") {
            value = from_bits(mine)
            expected = is_f32[$3] ? to_f32(theirs + 0) : theirs + 0
            same = (value == expected)
            shown = sprintf(is_f32[$3] ? "%.9g" : "%.17g", value)
        } else {
            same = (mine == theirs)
            shown = mine
        }
        printf "%-7s %-11s %-20s %-26s %-26s %s\n", $1, $2, $3, shown, theirs, same ? "equal" : "DIFFERENT"
        if (!same) bad++
        seen[id] = 1; checked++
    }
    END {
        for (id in host) if (!(id in seen)) { print "missing in the firmware output: " id; bad++ }
        printf "%d figures compared, %d differ or are missing\n", checked, bad
        if (checked == 0 || bad > 0) {
            print "run-qemu.sh: the C firmware and gyro-cli run disagree" > "/dev/stderr"
            exit 1
        }
    }' "$work/host.txt" "$work/firmware-figures.txt"
