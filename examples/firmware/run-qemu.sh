#!/usr/bin/env bash
# Boot the firmware example on an emulated Cortex-M4F (QEMU mps2-an386) and check that it
# computes exactly what the host computes: the same rate words go through `gyro-cli run`
# (paper and kalman compensation), and every movement (start, end, angle, raw angle, the
# saturated flag) and the final angles must be the same numbers, bit for bit.
#
# Needs: cargo with the thumbv7em-none-eabihf target, qemu-system-arm, jq, od, awk.
#   apt-get install -y --no-install-recommends qemu-system-arm jq
# Environment: QEMU (default qemu-system-arm), QEMU_TIMEOUT_S (default 120), GYRO_CLI (the
# host's gyro-cli; default: `cargo run -p gyro-cli`).
# Exit status: 0 if the firmware ran clean and matches the host, 1 otherwise, 2 if a tool is
# missing.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
fixture=$root/fixtures/firmware/bench_run_20s.i16be
qemu=${QEMU:-qemu-system-arm}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

for tool in cargo "$qemu" jq od awk timeout; do
    if ! command -v "$tool" >/dev/null; then
        echo "run-qemu.sh: '$tool' not found (apt-get install -y qemu-system-arm jq)" >&2
        exit 2
    fi
done

echo "== build the firmware for thumbv7em-none-eabihf"
# From the crate's folder, so that its .cargo/config.toml (target, linker script) applies.
(cd "$here" && cargo build --release)
target_dir=${CARGO_TARGET_DIR:-$here/target}
elf=$target_dir/thumbv7em-none-eabihf/release/gyro-firmware-example

echo "== run it on qemu mps2-an386 (Cortex-M4F)"
status=0
timeout "${QEMU_TIMEOUT_S:-120}" "$qemu" -machine mps2-an386 -cpu cortex-m4 -nographic \
    -monitor none -serial none -semihosting-config enable=on,target=native \
    -kernel "$elf" >"$work/firmware.txt" || status=$?
cat "$work/firmware.txt"
if [ "$status" -ne 0 ]; then
    [ "$status" -eq 124 ] && echo "run-qemu.sh: qemu timed out" >&2
    echo "run-qemu.sh: firmware run failed (exit status $status)" >&2
    exit 1
fi

echo "== the host: gyro-cli run on the same rate words"
# The CSV the host replays: the fixture's words as deg/s. counts/24 printed with 17
# significant digits is the double nearest to it, which gyro-cli rounds to the same f32 the
# driver computes (f32(counts) / 24). Times k/1000 parse to what the firmware computes.
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
        --range-dps 300 --format json) >"$work/host-$compensation.json"
    # One "compensation what key value" line per figure (the saturated flag as 0 or 1).
    jq -r --arg c "$compensation" '
        (.movements[] | select(.complete) | . as $m
            | ("start_time_s", "end_time_s", "angle_deg", "raw_angle_deg", "saturated")
            | "\($c) movement_\($m.index) \(.) \($m[.] | if type == "boolean" then (if . then 1 else 0 end) else . end)"),
        (.summary | . as $s
            | ("outputs", "rejected_samples", "movements", "final_angle_deg", "final_raw_angle_deg")
            | "\($c) summary \(.) \($s[.])")' "$work/host-$compensation.json"
done >"$work/host.txt"

# The same lines from the firmware's key=value output.
awk '
    $1 == "movement" || $1 == "summary" {
        delete f
        for (i = 2; i <= NF; i++) { split($i, kv, "="); f[kv[1]] = kv[2] }
        if ($1 == "movement") {
            n = split("start_time_s end_time_s angle_deg raw_angle_deg saturated", keys, " ")
            what = "movement_" f["index"]
        } else {
            n = split("outputs rejected_samples movements final_angle_deg final_raw_angle_deg", keys, " ")
            what = "summary"
        }
        for (i = 1; i <= n; i++) print f["compensation"], what, keys[i], f[keys[i]]
    }' "$work/firmware.txt" >"$work/firmware-figures.txt"

echo "== firmware (qemu) against host (gyro-cli run)"
# Both sides print the shortest decimal that round-trips (Rust's `{}`, serde_json's ryu),
# and jq may lengthen it to 17 digits; comparing the parsed doubles is therefore exact:
# equal here means the same f32 (angles) or f64 (times) bits.
awk '
    BEGIN { printf "%-7s %-11s %-20s %-22s %-22s\n", "comp", "what", "figure", "firmware", "host" }
    FNR == NR { host[$1 " " $2 " " $3] = $4; next }
    {
        id = $1 " " $2 " " $3
        if (id in host) {
            same = ($4 + 0 == host[id] + 0)
            printf "%-7s %-11s %-20s %-22s %-22s %s\n", $1, $2, $3, $4, host[id], same ? "equal" : "DIFFERENT"
            if (!same) bad++
            seen[id] = 1; checked++
        } else {
            printf "%-7s %-11s %-20s %-22s %-22s MISSING ON HOST\n", $1, $2, $3, $4, "-"; bad++
        }
    }
    END {
        for (id in host) if (!(id in seen)) { print "missing in the firmware output: " id; bad++ }
        printf "%d figures compared, %d differ or are missing\n", checked, bad
        exit bad > 0
    }' "$work/host.txt" "$work/firmware-figures.txt"
