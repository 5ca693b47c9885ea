#!/usr/bin/env python3
"""`gyro-cli diagnose` on the rasteiro recordings, held out by speed and by sensor.

Per sensor axis (the board's x, y and z files):

- by speed: trained on both sensors' recordings at two speeds (4 runs), held out on both
  sensors' recordings at the third (2 runs);
- by sensor: trained on one sensor's three speeds, held out on the other sensor's three.

For each diagnosis it prints what the turns show rest to rest (`turns` in the JSON: the
gyro-reference lag searched wide, the turns' scale with its 95% interval, whether it is
named and written, the held-out turns' own scale and RMS error without and with it, and
the movements the reference does not follow) and the whiteness check of the training
rests (`model.rest_noise`: the white noise from first differences and from 0.05 s blocks). Then the held-out turns' median |error|
(90th percentile) rest to rest against the robot's pose, per group: the plain per-rest
estimator, the same with a least-squares scale of its own turn errors on the same training
recordings (the plainest alternative with the same information), `gyro-cli run` with the
default configuration and `gyro-cli run --model` with the model `diagnose -o` wrote; the
ratio is `run --model` over the plain estimator with its scale. Turns and truth are those
of `rasteiro_turns.py`.

Usage: python3 scripts/rasteiro_diagnose.py [DATA_DIR] [--gyro target/release/gyro-cli]
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rasteiro_calibrated import SENSORS, SPEEDS, line, path_of, plain_scale  # noqa: E402
from rasteiro_turns import positional_args, turns  # noqa: E402


def diagnose(gyro, train, holdout, model):
    """The diagnosis JSON; the model file is written at `model` when anything is."""
    out = subprocess.run(
        [gyro, "diagnose", "--sample-rate-hz", "100", "--format", "json", "-o", model,
         "--train", *train, "--holdout", *holdout],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout)


def pct(x):
    return f"{100 * x:+.2f}%"


def describe(label, d, written):
    t = d.get("turns") or {}
    lag = t.get("lag") or {}
    s = t.get("scale")
    parts = [f"{label}:"]
    if lag:
        lo, hi = lag["train_range_s"]
        parts.append(f"lag {1e3 * lag['median_s']:.0f} ms [{1e3 * lo:.0f}, {1e3 * hi:.0f}]"
                     f"{' written' if lag['written'] else ''}")
    if s:
        verdict = "written" if s["written"] else ("named" if s["named"] else "not named")
        kb, ka = s["holdout_k"]
        rb, ra = s["holdout_turn_rms_deg"]
        parts.append(
            f"scale {pct(s['k'])} [{pct(s['ci95'][0])}, {pct(s['ci95'][1])}] {verdict};"
            f" held out {pct(kb)} -> {pct(ka)}, RMS {rb:.2f} -> {ra:.2f} deg"
        )
    u = t.get("untracked") or []
    if u:
        g = [abs(x["gyro_deg"]) for x in u]
        parts.append(f"{len(u)} untracked ({min(g):.1f}-{max(g):.1f} deg)")
    rest = (d.get("model") or {}).get("rest_noise")
    if rest:
        parts.append(
            f"rest noise {rest['first_difference_arw_deg_per_rt_h']:.2f} -> "
            f"{rest['block_arw_deg_per_rt_h']:.2f} deg/sqrt(h) at {rest['tau_s']:.2f} s"
            f" (z {rest['z']:.0f}{', coloured' if rest['coloured'] else ''})"
        )
    named = [e["id"] for e in d["effects"] if e["significant"]]
    parts.append(f"vocabulary: {', '.join(named) or 'none'}; {len(d.get('unexplained') or [])} unexplained")
    parts.append(f"model file {'written' if written else 'not written'}")
    print("  " + "; ".join(parts))


def held_out(gyro, train, test, cache, label):
    """Rows (truth, plain, plain scaled, run, run --model) over the held-out turns."""
    with tempfile.TemporaryDirectory() as tmp:
        model = os.path.join(tmp, "model.json")
        d = diagnose(gyro, train, test, model)
        written = os.path.exists(model)
        describe(label, d, written)
        k_plain = plain_scale([f for p in train for f in cache[p]])
        rows = []
        for path in test:
            with_model = turns(path, gyro, ("--model", model)) if written else cache[path]
            for (truth, pe, re), (truth2, _, me) in zip(cache[path], with_model):
                assert truth == truth2
                p = truth + pe
                rows.append((truth, pe, p / (1.0 + k_plain) - truth, re, me))
    return rows


def header(title):
    print(title)
    print(f"{'held out':<22} {'turns':>5}  {'plain':>13}  {'plain+scale':>13}  {'run':>13}  {'run --model':>13}  ratio")


def main():
    args = positional_args()
    data = args[0] if args else os.path.join(os.path.dirname(__file__), "../../shared/data/real/rasteiro")
    gyro = sys.argv[sys.argv.index("--gyro") + 1] if "--gyro" in sys.argv else "target/release/gyro-cli"
    paths = [path_of(data, s, v, a) for s in SENSORS for v in SPEEDS for a in "xyz"]
    cache = {p: turns(p, gyro) for p in paths}
    by_speed, by_sensor = {}, {}
    print("held out by speed (trained on both sensors at the other two speeds):")
    for axis in "xyz":
        for speed in SPEEDS:
            train = [path_of(data, s, v, axis) for s in SENSORS for v in SPEEDS if v != speed]
            test = [path_of(data, s, speed, axis) for s in SENSORS]
            rows = held_out(gyro, train, test, cache, f"{axis} held out {speed}")
            by_speed.setdefault(axis, []).extend(rows)
    print("held out by sensor (trained on the other sensor's three speeds):")
    for axis in "xyz":
        for sensor in SENSORS:
            other = [s for s in SENSORS if s != sensor][0]
            train = [path_of(data, other, v, axis) for v in SPEEDS]
            test = [path_of(data, sensor, v, axis) for v in SPEEDS]
            rows = held_out(gyro, train, test, cache, f"{axis} {sensor} from {other}")
            by_sensor.setdefault(axis, []).extend(rows)
    print()
    header("median |error| (90th percentile), deg; ratio: run --model / plain+scale")
    for axis in "xyz":
        line(f"by speed, {axis}", by_speed[axis])
    line("by speed, all", [r for v in by_speed.values() for r in v])
    for axis in "xyz":
        line(f"by sensor, {axis}", by_sensor[axis])
    line("by sensor, all", [r for v in by_sensor.values() for r in v])


if __name__ == "__main__":
    main()
