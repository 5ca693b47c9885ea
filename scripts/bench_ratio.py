#!/usr/bin/env python3
"""ns per input sample of each bench in a criterion group, and its ratio to the floor.

Reads target/criterion/GROUP/*/new/{benchmark,estimates}.json, as left by the last
`cargo bench -p gyro-benches --bench pipeline` (so every figure comes from the same run),
and prints, per bench, the median time per iteration over the elements it processes
(criterion's throughput), and that over the floor bench's. The median rather than the
mean: on a shared machine a few slow iterations move the mean.

Usage: scripts/bench_ratio.py [GROUP [FLOOR]]
       (defaults: pipeline_90s_1khz plain_loop; CARGO_TARGET_DIR is honoured)
"""
import json
import os
import sys


def main():
    group = sys.argv[1] if len(sys.argv) > 1 else "pipeline_90s_1khz"
    floor = sys.argv[2] if len(sys.argv) > 2 else "plain_loop"
    target = os.environ.get("CARGO_TARGET_DIR") or os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "target"
    )
    root = os.path.join(target, "criterion", group)
    if not os.path.isdir(root):
        sys.exit(f"{root}: no criterion results (run `cargo bench -p gyro-benches --bench pipeline`)")
    per_sample = {}
    for name in sorted(os.listdir(root)):
        new = os.path.join(root, name, "new")
        try:
            with open(os.path.join(new, "benchmark.json")) as f:
                bench = json.load(f)
            with open(os.path.join(new, "estimates.json")) as f:
                estimates = json.load(f)
        except FileNotFoundError:
            continue
        elements = (bench.get("throughput") or {}).get("Elements") or 1
        name = bench.get("value_str") or bench["function_id"]
        per_sample[name] = estimates["median"]["point_estimate"] / elements
    if floor not in per_sample:
        sys.exit(f"{root}: no '{floor}' bench among {sorted(per_sample)}")
    base = per_sample[floor]
    print(f"{'bench':<20} {'ns/sample':>10} {'× ' + floor:>16}")
    for name, ns in sorted(per_sample.items(), key=lambda item: item[1]):
        print(f"{name:<20} {ns:>10.2f} {ns / base:>16.1f}")


if __name__ == "__main__":
    main()
