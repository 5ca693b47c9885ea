#!/usr/bin/env python3
"""`gyro-cli diagnose` on cases from a generator that is not the project's: numpy only,
written apart from `gyro-sim` and from the self-test, with magnitudes, rates and motion
chosen here and nowhere else. Twelve cases, each four training and four held-out windows
of 60 s at 100 Hz (the held-out windows move 1.7 times faster):

- continuous motion (two sines per window, eased in and out over 3 s so that windows join
  without a step in the rate): a latency with a scale error, a negative latency, an odd
  nonlinearity, a logger-stamped clock error (the sensor samples fast, the rows carry the
  true time, the metadata the nominal 100 Hz), a clock 1.5% fast stamped by the sensor's
  own count (the row stamped t holds the rate of true time t / 1.015 from its window's
  start), and nothing at all;
- a wrench's rest-turn-rest (turns of 45-135 deg either way, a raised-cosine angle over
  0.6-1.4 s, rests of 1.5-3.5 s): a scale error, a latency with a scale error, a bias
  random walk, a temperature bias over a warm-up, a count-stamped clock 2.5% slow, and
  nothing at all.

Every gyro has a bias of 0.15 deg/s and white noise of 0.3 deg/s per sample (1.8
deg/sqrt(h)); the reference is the exact angle, printed to 0.001 deg. Prints one line per case: what was
injected, what `diagnose` named with its 95% interval, whether the selected model fits
the training runs, and G (training and held out, after selection) against its floor.

Usage: python3 scripts/diagnose_unseen.py [--gyro target/release/gyro-cli] [--keep DIR]
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

FS_HZ = 100.0
WINDOW_S = 60.0
WINDOWS = 4
BIAS_DPS = 0.15
SIGMA_DPS = 0.3
EASE_S = 3.0
HOLDOUT_SPEED = 1.7


def ease(tw):
    """Smoothstep envelope over EASE_S at both ends of a window, and its derivative."""
    x = np.clip(np.minimum(tw, WINDOW_S - tw) / EASE_S, 0.0, 1.0)
    env = x * x * (3 - 2 * x)
    slope = 6 * x * (1 - x) / EASE_S * np.where(tw < WINDOW_S / 2, 1.0, -1.0)
    return env, slope


def continuous(rng, speed, t, delay_s):
    """Angle at t and rate at t - delay_s: two sines per window times the envelope."""
    angle = np.zeros_like(t)
    rate = np.zeros_like(t)
    window = np.floor(t / WINDOW_S + 1e-9).astype(int)
    for w in range(WINDOWS):
        s = window == w
        tw = t[s] - w * WINDOW_S
        env, slope = ease(tw)
        env_late, slope_late = ease(tw - delay_s)
        base = np.zeros_like(tw)
        base_late = np.zeros_like(tw)
        rate_late = np.zeros_like(tw)
        for a, f in ((rng.uniform(30, 90), speed * rng.uniform(0.06, 0.14)),
                     (rng.uniform(4, 12), speed * rng.uniform(0.3, 0.8))):
            om, ph = 2 * np.pi * f, rng.uniform(0, 2 * np.pi)
            base += a * np.sin(om * tw + ph)
            base_late += a * np.sin(om * (tw - delay_s) + ph)
            rate_late += a * om * np.cos(om * (tw - delay_s) + ph)
        angle[s] = base * env
        rate[s] = rate_late * env_late + base_late * slope_late
    # Each window starts where the last ended (the envelope is 0 at both ends).
    starts = np.flatnonzero(np.diff(window)) + 1
    for i in starts:
        angle[i:] += angle[i - 1] - angle[i]
    return angle, rate


def wrench(rng, speed, t):
    rate = np.zeros_like(t)
    angle = np.zeros_like(t)
    for w in range(WINDOWS):
        now, end = w * WINDOW_S + rng.uniform(1.5, 3.0), (w + 1) * WINDOW_S
        while True:
            d = rng.uniform(0.6, 1.4) / speed
            if now + d + 1.5 > end:
                break
            a = rng.choice([-1, 1]) * rng.uniform(45, 135)
            s = (t >= now) & (t < now + d)
            rate[s] += a * np.pi / (2 * d) * np.sin(np.pi * (t[s] - now) / d)
            angle += a * (1 - np.cos(np.pi * np.clip((t - now) / d, 0, 1))) / 2
            now += d + rng.uniform(1.5, 3.5)
    return angle, rate


def write(path, stamps, gyro, angle, temperature):
    with open(path, "w") as out:
        out.write("# made by scripts/diagnose_unseen.py (numpy), not by gyro-sim\n")
        out.write(f"# sample_rate_hz: {FS_HZ:g}\n")
        out.write("time_s,rate_dps,reference_deg" + (",temperature_c" if temperature is not None else "") + "\n")
        for i in range(stamps.size):
            line = f"{stamps[i]:.9f},{gyro[i]:.3f},{angle[i]:.3f}"
            if temperature is not None:
                line += f",{temperature[i]:.2f}"
            out.write(line + "\n")


def make(directory, name, seed, kind, delay_s=0.0, k=0.0, k3=0.0, rrw=0.0, tbias=0.0, clock_ppm=0.0,
         count_ppm=0.0):
    rng = np.random.default_rng(seed)
    for part, speed in (("train", 1.0), ("holdout", HOLDOUT_SPEED)):
        clock = 1.0 + clock_ppm * 1e-6
        n = int(round(WINDOW_S * FS_HZ * clock)) * WINDOWS
        t = np.arange(n) / (FS_HZ * clock)  # true sample times; the rows carry them
        # A sensor clock fast by count_ppm whose rows are stamped by its sample count: the
        # row stamped t (and the reference read then) holds the rate of true time
        # t / (1 + e) from the start of its window (each window a run of its own, the
        # sensor started with it).
        count = 1.0 + count_ppm * 1e-6
        window_start = np.floor(t / WINDOW_S + 1e-9) * WINDOW_S
        t_rate = window_start + (t - window_start) / count
        if kind == "continuous":
            state = rng.bit_generator.state
            angle, rate = continuous(rng, speed, t, delay_s)
            if count_ppm:
                rng.bit_generator.state = state
                _, rate = continuous(rng, speed, t_rate, delay_s)
        else:
            angle, rate = wrench(rng, speed, t)
            rate = np.interp(t_rate - delay_s, t, rate)
        gyro = (1 + k) * rate + k3 * rate**3 + BIAS_DPS
        temperature = None
        within = t - np.floor(t / WINDOW_S + 1e-9) * WINDOW_S
        if tbias:
            temperature = 25 + 4 * (1 - np.exp(-within / 20.0))
            gyro += tbias * (temperature - 25)
        if rrw:
            walk = np.cumsum(rng.standard_normal(n)) * rrw / np.sqrt(FS_HZ)
            first = np.searchsorted(t, np.arange(WINDOWS) * WINDOW_S - 1e-9)
            for w in range(WINDOWS):
                end = first[w + 1] if w + 1 < WINDOWS else n
                walk[first[w]:end] -= walk[first[w]]
            gyro += walk
        gyro += SIGMA_DPS * rng.standard_normal(n)
        write(os.path.join(directory, f"{name}_{part}.csv"), t, gyro, angle, temperature)


CASES = [
    ("latency + scale", "continuous", 11, dict(delay_s=0.008, k=-0.012), "latency 8 ms, scale -1.2%"),
    ("negative latency", "continuous", 12, dict(delay_s=-0.006), "latency -6 ms"),
    ("odd nonlinearity", "continuous", 13, dict(k3=3e-7), "k3 3e-7 /(deg/s)^2"),
    ("clock, logger-stamped", "continuous", 19, dict(clock_ppm=4000.0), "clock +4000 ppm"),
    ("clock, count-stamped +1.5%", "continuous", 21, dict(count_ppm=15000.0), "count-stamped clock +15000 ppm"),
    ("clock, count-stamped -2.5% (turns)", "wrench", 22, dict(count_ppm=-25000.0), "count-stamped clock -25000 ppm"),
    ("nothing (continuous)", "continuous", 14, {}, "nothing"),
    ("scale (turns)", "wrench", 16, dict(k=0.015), "scale +1.5%"),
    ("latency + scale (turns)", "wrench", 20, dict(delay_s=0.010, k=0.008), "latency 10 ms, scale +0.8%"),
    ("random walk (turns)", "wrench", 17, dict(rrw=0.03), "rate random walk 0.03 deg/s/sqrt(s)"),
    ("temperature bias (turns)", "wrench", 18, dict(tbias=0.08), "temperature bias 0.08 deg/s/degC"),
    ("nothing (turns)", "wrench", 15, {}, "nothing"),
]


def fmt(params, ci):
    out = []
    for key, value in params.items():
        lo, hi = ci.get(key, [float("nan")] * 2)
        out.append(f"{key} {value:.3g} [{lo:.3g}, {hi:.3g}]")
    return ", ".join(out)


def main():
    args = sys.argv[1:]
    gyro = "target/release/gyro-cli"
    keep = None
    if "--gyro" in args:
        gyro = args[args.index("--gyro") + 1]
    if "--keep" in args:
        keep = args[args.index("--keep") + 1]
    with tempfile.TemporaryDirectory() as scratch:
        directory = keep or scratch
        os.makedirs(directory, exist_ok=True)
        print("| case | injected | named (95% interval) | model fits | G training / held out (floor) |")
        print("|---|---|---|---|---|")
        for i, (label, kind, seed, params, injected) in enumerate(CASES):
            name = f"case{i}"
            make(directory, name, seed, kind, **params)
            cmd = [gyro, "diagnose", "--split-s", "60",
                   "--train", os.path.join(directory, f"{name}_train.csv"),
                   "--holdout", os.path.join(directory, f"{name}_holdout.csv"),
                   "--format", "json"]
            done = subprocess.run(cmd, capture_output=True, text=True, check=True)
            d = json.loads(done.stdout)
            effects = {e["id"]: e for e in d["effects"]}
            named = [f"{n} {fmt(effects[n]['params'], effects[n]['ci95'])}"
                     for n in d["verdict"]["unmodelled"]]
            g = d["gap"]
            fits = "yes" if d["verdict"]["model_fits"] else f"no ({len(d['unexplained'])} unexplained)"
            print(f"| {label} | {injected} | {'; '.join(named) or 'nothing'} | {fits} | "
                  f"{g['train_after']:.1f} / {g['holdout_after']:.1f} ({g['floor']:.2f}) |")


if __name__ == "__main__":
    main()
