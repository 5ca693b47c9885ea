#!/usr/bin/env bash
# Writes a 24-hour simulated log at 1 kHz (86 400 001 rows, about 3.2 GB) for the log
# throughput figures (docs/figures.md, "Log throughput"): `simulate` holds a run in memory and
# refuses one over 2^26 samples, so the day is 24 one-hour runs (seeds SEED..SEED+23),
# each shifted to follow the previous one in time (1 ms later) and in reference angle.
#
# Usage: scripts/day_log.sh GYRO_CLI OUT.csv [SEED]   (default seed 9; temporary hour
#        files go beside OUT)
set -euo pipefail
cli="$1" out="$2" seed="${3:-9}"
hour="$out.hour.csv"
trap 'rm -f "$hour"' EXIT
t0=0 r0=0
: >"$out"
for k in $(seq 0 23); do
    "$cli" simulate --duration-s 3600 --seed $((seed + k)) -o "$hour" --force >/dev/null
    # The first hour keeps its comment and header lines; every hour is shifted.
    read -r t0 r0 < <(awk -F, -v k="$k" -v t0="$t0" -v r0="$r0" -v out="$out" '
        /^#/ || /^time_s/ { if (k == 0) print >> out; next }
        { t = $1 + t0; r = $4 + r0; printf "%.3f,%s,%s,%.6f\n", t, $2, $3, r >> out }
        END { printf "%.3f %.6f\n", t + 0.001, r }' "$hour")
done
