#!/usr/bin/env bash
# Checks that a change of structure changed no output: builds gyro-cli at REV (default:
# HEAD~1) in a temporary worktree and at the work tree, runs both on the same inputs and
# compares every output byte for byte.
#
# Inputs: every fixture log, every real recording under ../shared/data/real (ssong and
# rasteiro), six simulated bench runs (simulate is itself compared), noise on the
# simulated runs' rests and on rasteiro, calibrate on the simulated runs, diagnose with its
# HTML report on the simulated runs, and one diagnose self-test case.
#
# Usage: scripts/same_behaviour.sh [REV]      exit 0 when every output is equal
#        OLD_BIN=path/to/old/gyro-cli scripts/same_behaviour.sh   (skip building REV)
#        NEW_BIN=path/to/new/gyro-cli scripts/same_behaviour.sh   (skip building the work tree)
#        KEEP=dir scripts/same_behaviour.sh                       (keep the outputs in dir)
set -euo pipefail
cd "$(dirname "$0")/.."
top=$(pwd)
rev="${1:-HEAD~1}"
work=$(mktemp -d)
trap 'git -C "$top" worktree remove --force "$work/old" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT

if [ -n "${OLD_BIN:-}" ]; then
    old="$OLD_BIN" # a gyro-cli already built at REV
else
    git worktree add --detach "$work/old" "$rev" >/dev/null
    (cd "$work/old" && CARGO_TARGET_DIR="$top/target/same-behaviour-old" cargo build --release -q -p gyro-cli)
    old="$top/target/same-behaviour-old/release/gyro-cli"
fi
if [ -n "${NEW_BIN:-}" ]; then
    new="$NEW_BIN" # a gyro-cli already built from the work tree
else
    cargo build --release -q -p gyro-cli
    new="$top/target/release/gyro-cli"
fi
real="$top/../shared/data/real"

# snapshot BIN OUTDIR: every output of BIN on the inputs, one file each.
snapshot() {
    local bin="$1" out="$2"
    mkdir -p "$out/sim"
    for seed in 101 102 103 104 105 106; do
        "$bin" simulate -o "$out/sim/run$seed.csv" --seed "$seed" --duration-s 60 \
            --effect turn_on_bias:sigma_dps=0.3 >"$out/simulate-$seed.txt" 2>&1
    done
    local logs=("$top"/fixtures/logs/*.csv "$top"/fixtures/mcap/*.mcap "$real"/*.csv
        "$real"/rasteiro/*.csv "$out"/sim/run101.csv)
    for log in "${logs[@]}"; do
        name=$(basename "$log")
        "$bin" run "$log" --format json >"$out/run-$name.json" 2>"$out/run-$name.err" || true
    done
    "$bin" run "$top/fixtures/logs/bench_run.csv" --format csv --out "$out/series.csv" \
        >"$out/run-bench.csv" 2>&1
    "$bin" run "$top/fixtures/logs/bench_run.csv" >"$out/run-bench.txt" 2>&1
    "$bin" noise --static-only --format json "$out"/sim/run10[1-3].csv >"$out/noise-sim.json" 2>&1
    "$bin" noise --static-only --format json "$real"/rasteiro/*V_300_x.csv \
        >"$out/noise-rasteiro.json" 2>&1 || true
    "$bin" calibrate "$out"/sim/run10[1-4].csv --holdout "$out"/sim/run10[56].csv \
        -o "$out/model.json" --format json >"$out/calibrate.json" 2>"$out/calibrate.err"
    "$bin" run "$out/sim/run105.csv" --model "$out/model.json" --format json >"$out/run-model.json" 2>&1
    "$bin" convert "$top/fixtures/logs/bench_run.csv" "$out/bench.mcap" >/dev/null 2>&1
    "$bin" diagnose --train "$out"/sim/run10[1-3].csv --holdout "$out"/sim/run10[4-6].csv \
        --members 12 --candidate-members 6 --format json --report "$out/report" \
        >"$out/diagnose-sim.json" 2>/dev/null
    "$bin" diagnose --self-test --seed 8 --only scale_factor --format json >"$out/diagnose.json" \
        2>/dev/null
    # Paths differ between the two runs: compare names relative to the snapshot.
    find "$out" -type f -exec sed -i "s#$out#OUT#g" {} +
}

snapshot "$old" "$work/old-out"
snapshot "$new" "$work/new-out"
[ -n "${KEEP:-}" ] && rm -rf "$KEEP" && cp -r "$work/new-out" "$KEEP" # KEEP=dir: keep the outputs
if diff -r "$work/old-out" "$work/new-out"; then
    echo "same behaviour: $(find "$work/new-out" -type f | wc -l) outputs equal ($rev vs work tree)"
else
    echo "outputs differ ($rev vs work tree)" >&2
    exit 1
fi
