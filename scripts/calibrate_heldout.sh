#!/usr/bin/env bash
# The model `calibrate` writes against the default configuration, on runs it was not
# fitted on (docs/figures.md, "Calibration").
#
# 20 simulated 90 s CRM100 bench runs (the nominal sensor model of `gyro-cli simulate`
# plus EFFECTS; default: a rate random walk of the bias, 0.02 deg/s/sqrt(s)), seeds
# 201-220; calibrate on 201-210, then `gyro-cli run` every run 211-220 with the written
# model and without one (the default: Kalman form, built-in settings). Prints the mode
# written and the median over the 10 held-out runs of the max abs angle error of each.
#
# Usage: scripts/calibrate_heldout.sh [OUTDIR]   (default: a temporary folder)
#        EFFECTS="--effect turn_on_bias:sigma_dps=0.3" scripts/calibrate_heldout.sh
#        GYRO=path/to/gyro-cli scripts/calibrate_heldout.sh   (another build)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-$(mktemp -d)}"
mkdir -p "$out"
effects="${EFFECTS-"--effect rate_random_walk:k_dps_per_rt_s=0.02"}"
if [ -z "${GYRO:-}" ]; then
    cargo build --release -q -p gyro-cli
    GYRO="${CARGO_TARGET_DIR:-target}/release/gyro-cli"
fi
first="${FIRST:-201}"
for seed in $(seq "$first" $((first + 19))); do
    # shellcheck disable=SC2086
    "$GYRO" simulate --force -o "$out/run$seed.csv" --seed "$seed" --duration-s 90 $effects 2>/dev/null
done
train=$(for s in $(seq "$first" $((first + 9))); do echo "$out/run$s.csv"; done)
# shellcheck disable=SC2086
"$GYRO" calibrate $train --force -o "$out/model.json" >"$out/calibrate.txt" 2>"$out/calibrate.err"
median_max_abs() {
    for s in $(seq $((first + 10)) $((first + 19))); do
        "$GYRO" run "$out/run$s.csv" --format json "$@" 2>/dev/null |
            python3 -c 'import json,sys; print(json.load(sys.stdin)["summary"]["max_abs_error_deg"])'
    done | sort -g | awk '{v[NR]=$1} END {printf "%.3f", (v[NR/2]+v[NR/2+1])/2}'
}
mode=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1])).get("config",{}).get("compensation","kalman"))' "$out/model.json")
echo "written compensation: $mode"
grep '^wrote' "$out/calibrate.err" || true
echo "held-out median max abs error: written model $(median_max_abs --model "$out/model.json") deg, default $(median_max_abs) deg"
