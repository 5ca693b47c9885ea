#!/usr/bin/env python3
"""The table (docs/diagnose.md, "Results") of `gyro-cli diagnose` on the bundled ssong recordings: per axis,
trained on one speed and held out on the other (each recording cut into 100 s windows),
both directions:

    gyro-cli diagnose --split-s 100 --train ssong_{ax}_{a}.csv --holdout ssong_{ax}_{b}.csv \
        --format json -o MODEL

and from its JSON: the effects named with their 95% intervals, the held-out gap G before
and after (fraction closed), whether the fitted bias was written, and the held-out
windows' max |angle error| with the default configuration and with the written model
(`compensation.runs`).

Usage: python3 scripts/ssong_diagnose.py [DATA_DIR] [--gyro target/release/gyro-cli]
(DATA_DIR: default ../shared/data/real).
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np


def param(effect):
    """The effect's leading parameter and its interval, in an engineer's units."""
    p, ci = effect["params"], effect.get("ci95") or {}
    key = "rate_per_s" if "rate_per_s" in p else next(iter(p))
    scale, unit = {
        "delay_s": (1e3, " ms"),
        "k": (100.0, "%"),
        "rate_per_s": (1.0, "/s"),
        "amplitude_dps": (1.0, " deg/s"),
        "ppm": (1.0, " ppm"),
    }.get(key, (1.0, ""))
    lo, hi = (ci.get(key) or [None, None])
    text = f"{effect['id']} {p[key] * scale:.3g}{unit}"
    if lo is not None and hi is not None:
        text += f" [{lo * scale:.3g}, {hi * scale:.3g}]"
    if "mean_samples" in p:
        text += f" of {p['mean_samples']:.2f} samples"
    if "frequency_hz" in p:
        text += f" at {p['frequency_hz']:.1f} Hz"
    return text


def main():
    args = [a for a in sys.argv[1:]]
    gyro = "target/release/gyro-cli"
    if "--gyro" in args:
        i = args.index("--gyro")
        gyro = args[i + 1]
        del args[i:i + 2]
    root = args[0] if args else "../shared/data/real"
    tmp = tempfile.mkdtemp(prefix="ssong_diagnose_")
    written_by_row = []
    print("| axis | train → held out | named (95% interval) | held-out G (closed) | bias written | "
          "held-out max \\|angle error\\| per window, median (worst): default → written model | windows better |")
    print("|---|---|---|---|---|---|---|")
    for axis, name in (("x", "roll"), ("y", "pitch"), ("z", "yaw")):
        for a, b in (("slow", "medium"), ("medium", "slow")):
            model = os.path.join(tmp, f"{axis}-{a}.model.json")
            out = subprocess.run(
                [gyro, "diagnose", "--split-s", "100", "--train", f"{root}/ssong_{axis}_{a}.csv",
                 "--holdout", f"{root}/ssong_{axis}_{b}.csv", "--format", "json", "-o", model],
                check=True, capture_output=True, text=True,
            ).stdout
            d = json.loads(out)
            named = set(d["verdict"]["unmodelled"])
            effects = "; ".join(param(e) for e in d["effects"] if e["id"] in named) or "nothing"
            g = d["gap"]
            closed = d["verdict"]["fraction_closed_holdout"]
            comp = d.get("compensation") or {}
            bias = next((c for c in comp.get("not_corrected", []) if c["id"] == "bias"), None)
            written = json.load(open(model))
            kal = written.get("config", {}).get("kalman", {})
            bias_text = (f"no ({bias['median_max_abs_error_with_deg']:.1f}° held out with it)"
                         if bias else f"{kal.get('bias_mean_dps', 0.0):+.3f} deg/s")
            runs = comp.get("runs", [])
            before = np.array([r["max_abs_error_before_deg"] for r in runs])
            after = np.array([r["max_abs_error_after_deg"] for r in runs])
            if len(runs):
                errors = (f"{np.median(before):.1f} ({before.max():.1f}) → "
                          f"{np.median(after):.1f} ({after.max():.1f})")
                better = f"{int(np.sum(after < before))}/{len(runs)}"
            else:
                errors, better = "no correction", "-"
            written_by_row.append(f"{name} ({axis}) {a} → {b}: {', '.join(comp.get('corrected', [])) or 'nothing'}")
            print(f"| {name} ({axis}) | {a} → {b} | {effects} | {g['holdout_before']:.0f} → "
                  f"{g['holdout_after']:.0f} ({100 * closed:.0f}%) | {bias_text} | {errors} | {better} |")
    print("\ncorrections written:")
    for row in written_by_row:
        print(f"  {row}")


if __name__ == "__main__":
    main()
