#!/usr/bin/env bash
# Accuracy by compensation mode on hold-out runs (docs/figures.md, "Accuracy by compensation mode").
#
# 20 simulated CRM100 bench runs of 90 s (the nominal sensor model of `gyro-cli simulate`
# plus a turn-on bias of sigma 0.3 deg/s: each power cycle starts with another bias),
# seeds 101-120; calibrate on 101-110, score on 111-120 (max abs angle error per run,
# with no compensation, the paper's error model and the Kalman form with rest updates).
#
# Usage: scripts/accuracy_by_mode.sh [OUTDIR]   (default: a temporary folder)
#        EFFECTS="" scripts/accuracy_by_mode.sh   (the paper's assumption: the same bias
#        every run; EFFECTS holds --effect options for every run)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-$(mktemp -d)}"
mkdir -p "$out"
effects="${EFFECTS-"--effect turn_on_bias:sigma_dps=0.3"}"
cargo build --release -q -p gyro-cli
gyro=target/release/gyro-cli
for seed in $(seq 101 120); do
    # shellcheck disable=SC2086
    "$gyro" simulate --force -o "$out/run$seed.csv" --seed "$seed" --duration-s 90 $effects 2>/dev/null
done
train=$(for s in $(seq 101 110); do echo "$out/run$s.csv"; done)
holdout=$(for s in $(seq 111 120); do echo "$out/run$s.csv"; done)
# shellcheck disable=SC2086
time "$gyro" calibrate $train --holdout $holdout --force -o "$out/model.json"
