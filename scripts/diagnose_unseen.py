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
       python3 scripts/diagnose_unseen.py --matrix [--gyro ...] [--keep DIR] [--out FILE]
                                          [--only EFFECT_ID|none]
                                          [--draw N [--first SEED]]

`--matrix`: each effect alone at three magnitudes of its realistic range (`gyro-cli
simulate --list-effects`), on the wrench's rest-turn-rest only, plus null cases; the
generator of each effect is this script's own (see `matrix_make`). Prints a markdown table
per case and a summary, and the first three lines of `diagnose`'s text output for the
null cases and the failures; `--out FILE` writes the same text to FILE as well.
`--draw N`: instead of the fixed magnitudes, N cases each with one effect at a magnitude
drawn over its range (`DRAW_RANGES`; development seeds from 6000, judging from 5000).
"""
import json
import os
import subprocess
import sys
import tempfile
import time

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
    for now, d, a in turn_plan(rng, speed):
        s = (t >= now) & (t < now + d)
        rate[s] += a * np.pi / (2 * d) * np.sin(np.pi * (t[s] - now) / d)
        angle += a * (1 - np.cos(np.pi * np.clip((t - now) / d, 0, 1))) / 2
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


# ---------------------------------------------------------------------------------------
# --matrix: each effect alone at three magnitudes, on the wrench's rest-turn-rest.
#
# Every generator below is this script's own, written from the effects' physical
# descriptions, not from gyro-sim: the turns are evaluated exactly at any time (so a
# latency or a clock moves the rate, not an interpolation of it), every noise source has
# its own numpy stream (seeded [seed, part, source]), and the sensor is the default
# modes' (bias 0.15 deg/s, white noise 0.3 deg/s per sample = 1.8 deg/sqrt(h)) unless a
# case says "low noise": white noise 0.28 deg/sqrt(h) (CRM100 level, 0.0467 deg/s per
# sample at 100 Hz).
#
# Conventions (the same as docs/effects.md where the project has one):
# - scale_factor k: gyro = (1 + k) rate.
# - scale_asymmetry k: positive rates read (1 + k) rate, negative rates (1 - k) rate.
# - latency d: the row at t holds the rate of true time t - d (d > 0: the gyro late).
# - bandwidth f_c: a causal digital second-order Butterworth low-pass (bilinear transform,
#   cut-off pre-warped, -3 dB at f_c), run over the whole log (started at its steady state
#   for the first sample) on rate + bias + noise alike. Its low-frequency group delay
#   (printed) is about sqrt(2) / (2 pi f_c), not the project's 1 / (pi 1.5538 f_c): a
#   different filter with the same name.
# - clock_error_count_stamped ppm (eps = ppm 1e-6): the row stamped t holds the rate of
#   true time t0 + (t - t0) / (1 + eps), t0 its window's start (each 60 s window a run of
#   its own, the sensor started with it); the reference is read at t.
# - clock_error ppm: sample k is taken at true time k / (fs (1 + eps)) and its row carries
#   that true time (a logger's clock); the metadata says the nominal 100 Hz.
# - turn_on_bias sigma: each 60 s window (a run of its own) adds a constant bias drawn
#   N(0, sigma^2) (the draws are printed).
# - bias_instability sigma: five first-order Gauss-Markov processes with time constants
#   1, 5.6, 31.6, 178 and 1000 s (log-uniform over 1-1000 s), each of sigma / sqrt(5),
#   each started from its stationary distribution and run through the whole log (one
#   sensor on for the 240 s, cut into windows; not restarted per window).
# - temperature_bias c: the default modes' warm-up, 25 -> 29 degC with a 20 s time
#   constant in every window, gyro += c (T - 25); the log has a temperature_c column.
# - quantization q: the output rounded to the nearest multiple of q (last of all).
#
# Judging seeds (none of the default modes' 11-22): the effect's number x 10 + the
# magnitude's number, plus 4800; e.g. 4811-4813 scale_factor, ..., 4901-4903
# scale_asymmetry, 4911-4913 turn_on_bias at low noise, 4921-4923 bias_instability at low
# noise, 4931 and 4932 the two nulls, 4933 a null at low noise (the low-noise cases' own
# control). The ensembles' --seed is diagnose's default (1).
# ---------------------------------------------------------------------------------------

SIGMA_LOW_DPS = 0.28 / 60.0 * np.sqrt(FS_HZ)  # 0.28 deg/sqrt(h) as deg/s per sample
LOOKALIKE = {"latency": "bandwidth", "bandwidth": "latency"}
INSTABILITY_TAUS_S = (1.0, 10 ** 0.75, 10 ** 1.5, 10 ** 2.25, 1000.0)

# (effect id, parameter, [(magnitude, seed, label)], noise: "default" or "low")
MATRIX = [
    ("scale_factor", "k", [(0.002, 4811, "+0.2%"), (-0.01, 4812, "-1%"), (0.03, 4813, "+3%")], "default"),
    ("latency", "delay_s", [(0.002, 4821, "2 ms"), (-0.010, 4822, "-10 ms"), (0.050, 4823, "50 ms")], "default"),
    ("bandwidth", "cutoff_hz", [(40.0, 4831, "40 Hz"), (20.0, 4832, "20 Hz"), (10.0, 4833, "10 Hz")], "default"),
    ("clock_error_count_stamped", "ppm",
     [(5000.0, 4841, "+0.5%"), (-10000.0, 4842, "-1%"), (30000.0, 4843, "+3%")], "default"),
    ("clock_error", "ppm", [(500.0, 4851, "+500 ppm"), (-5000.0, 4852, "-5000 ppm"), (30000.0, 4853, "+3%")],
     "default"),
    ("turn_on_bias", "sigma_dps", [(0.1, 4861, "0.1 deg/s"), (0.3, 4862, "0.3 deg/s"), (1.0, 4863, "1 deg/s")],
     "default"),
    ("bias_instability", "sigma_dps",
     [(0.003, 4871, "11 deg/h"), (0.0125, 4872, "45 deg/h"), (0.05, 4873, "180 deg/h")], "default"),
    ("temperature_bias", "dps_per_c",
     [(0.02, 4881, "0.02 deg/s/degC"), (0.05, 4882, "0.05 deg/s/degC"), (0.15, 4883, "0.15 deg/s/degC")],
     "default"),
    ("quantization", "lsb_dps", [(0.1, 4891, "0.1 deg/s"), (0.2, 4892, "0.2 deg/s"), (0.3, 4893, "0.3 deg/s")],
     "default"),
    ("scale_asymmetry", "k", [(0.002, 4901, "0.2%"), (0.006, 4902, "0.6%"), (0.02, 4903, "2%")], "default"),
    ("turn_on_bias", "sigma_dps", [(0.1, 4911, "0.1 deg/s"), (0.3, 4912, "0.3 deg/s"), (1.0, 4913, "1 deg/s")],
     "low"),
    ("bias_instability", "sigma_dps",
     [(0.003, 4921, "11 deg/h"), (0.0125, 4922, "45 deg/h"), (0.05, 4923, "180 deg/h")], "low"),
    (None, None, [(None, 4931, "null 1"), (None, 4932, "null 2")], "default"),
    (None, None, [(None, 4933, "null, low noise")], "low"),
]


# `--draw N`: N cases, each one effect at a magnitude drawn over its realistic range (the
# issue's and `gyro-cli simulate --list-effects`' ranges; at 100 Hz a Butterworth cutoff
# stops at 40 Hz), log-uniform in size, either sign where the effect has one, at the
# default noise or (one case in three) the CRM100's low noise. Case i draws from the numpy
# stream [seed, 99] with seed = --first + i. Development draws start at 6000 (the default);
# judging draws start at 5000 and are run only to report, never to choose anything.
DRAW_DEVELOPMENT_FIRST = 6000
DRAW_JUDGING_FIRST = 5000
# (effect id, parameter, smallest, largest size, signed, unit's scale, unit)
DRAW_RANGES = [
    ("scale_factor", "k", 0.001, 0.03, True, 100.0, "%"),
    ("scale_asymmetry", "k", 0.001, 0.03, True, 100.0, "%"),
    ("latency", "delay_s", 0.001, 0.05, True, 1e3, " ms"),
    ("bandwidth", "cutoff_hz", 10.0, 40.0, False, 1.0, " Hz"),
    ("clock_error_count_stamped", "ppm", 500.0, 30000.0, True, 1e-4, "%"),
    ("clock_error", "ppm", 500.0, 30000.0, True, 1e-4, "%"),
    ("turn_on_bias", "sigma_dps", 0.05, 1.0, False, 1.0, " deg/s"),
    ("bias_instability", "sigma_dps", 5 / 3600.0, 200 / 3600.0, False, 3600.0, " deg/h"),
    ("temperature_bias", "dps_per_c", 0.01, 0.15, True, 1.0, " deg/s/degC"),
    ("quantization", "lsb_dps", 0.05, 0.3, False, 1.0, " deg/s"),
]


def draw_case(seed):
    """One drawn case: (effect, parameter, value, seed, label, noise)."""
    rng = np.random.default_rng([seed, 99])
    effect, param, lo, hi, signed, scale, unit = DRAW_RANGES[rng.integers(len(DRAW_RANGES))]
    size = float(np.exp(rng.uniform(np.log(lo), np.log(hi))))
    value = size * (rng.choice([-1.0, 1.0]) if signed else 1.0)
    noise = "low" if rng.uniform() < 1 / 3 else "default"
    return effect, param, value, seed, f"{value * scale:+.3g}{unit}", noise


def turn_plan(rng, speed):
    """The wrench's turns as (start, duration, angle), which `wrench` draws its motion from."""
    turns = []
    for w in range(WINDOWS):
        now, end = w * WINDOW_S + rng.uniform(1.5, 3.0), (w + 1) * WINDOW_S
        while True:
            d = rng.uniform(0.6, 1.4) / speed
            if now + d + 1.5 > end:
                break
            a = rng.choice([-1, 1]) * rng.uniform(45, 135)
            turns.append((now, d, a))
            now += d + rng.uniform(1.5, 3.5)
    return turns


def plan_angle(turns, t):
    angle = np.zeros_like(t)
    for now, d, a in turns:
        angle += a * (1 - np.cos(np.pi * np.clip((t - now) / d, 0, 1))) / 2
    return angle


def plan_rate(turns, t):
    rate = np.zeros_like(t)
    for now, d, a in turns:
        s = (t >= now) & (t < now + d)
        rate[s] += a * np.pi / (2 * d) * np.sin(np.pi * (t[s] - now) / d)
    return rate


def butterworth2(cutoff_hz):
    """Digital second-order Butterworth low-pass (bilinear, pre-warped): b, a."""
    K = np.tan(np.pi * cutoff_hz / FS_HZ)
    norm = 1.0 / (1.0 + np.sqrt(2.0) * K + K * K)
    b0 = K * K * norm
    return (b0, 2 * b0, b0), (1.0, 2 * (K * K - 1) * norm, (1 - np.sqrt(2.0) * K + K * K) * norm)


def butterworth2_dc_delay_s(cutoff_hz):
    b, a = butterworth2(cutoff_hz)
    return (sum(i * v for i, v in enumerate(b)) / sum(b) - sum(i * v for i, v in enumerate(a)) / sum(a)) / FS_HZ


def lowpass(x, cutoff_hz):
    """The filter, direct form I, started at its steady state for x[0]."""
    (b0, b1, b2), (_, a1, a2) = butterworth2(cutoff_hz)
    y = np.empty_like(x)
    x1 = x2 = y1 = y2 = x[0]  # DC gain 1: steady state for a constant x[0]
    for i, xi in enumerate(x.tolist()):
        yi = b0 * xi + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2
        y[i] = yi
        x2, x1, y2, y1 = x1, xi, y1, yi
    return y


def gauss_markov_sum(rng, n, sigma_dps):
    """Five first-order Gauss-Markov processes, tau 1-1000 s, each sigma / sqrt(5)."""
    total = np.zeros(n)
    s_i = sigma_dps / np.sqrt(len(INSTABILITY_TAUS_S))
    for tau in INSTABILITY_TAUS_S:
        phi = np.exp(-1.0 / (FS_HZ * tau))
        drive = (s_i * np.sqrt(1 - phi * phi) * rng.standard_normal(n)).tolist()
        b = s_i * rng.standard_normal()
        out = np.empty(n)
        for i in range(n):
            b = phi * b + drive[i]
            out[i] = b
        total += out
    return total


def matrix_make(directory, name, seed, effect, value, noise):
    """Writes name_train.csv and name_holdout.csv; returns notes on what was drawn."""
    notes = []
    sigma = SIGMA_LOW_DPS if noise == "low" else SIGMA_DPS
    for p, (part, speed) in enumerate((("train", 1.0), ("holdout", HOLDOUT_SPEED))):
        motion = np.random.default_rng([seed, p, 0])
        white = np.random.default_rng([seed, p, 1])
        slow = np.random.default_rng([seed, p, 2])
        eps = value * 1e-6 if effect == "clock_error" else 0.0
        n = int(round(WINDOW_S * FS_HZ * (1 + eps))) * WINDOWS
        t = np.arange(n) / (FS_HZ * (1 + eps))  # true sample times, which the rows carry
        window = np.minimum(np.floor(t / WINDOW_S + 1e-9).astype(int), WINDOWS - 1)
        within = t - window * WINDOW_S
        turns = turn_plan(motion, speed)
        angle = plan_angle(turns, t)
        t_rate = t.copy()
        if effect == "clock_error_count_stamped":
            t_rate = window * WINDOW_S + within / (1 + value * 1e-6)
        if effect == "latency":
            t_rate = t_rate - value
        rate = plan_rate(turns, t_rate)
        if effect == "scale_factor":
            rate = (1 + value) * rate
        if effect == "scale_asymmetry":
            rate = rate * (1 + value * np.sign(rate))
        gyro = rate + BIAS_DPS
        temperature = None
        if effect == "temperature_bias":
            temperature = 25 + 4 * (1 - np.exp(-within / 20.0))
            gyro += value * (temperature - 25)
        if effect == "turn_on_bias":
            draws = value * slow.standard_normal(WINDOWS)
            gyro += draws[window]
            notes.append(f"{part} draws " + " ".join(f"{v:+.3f}" for v in draws)
                         + f" (SD {np.std(draws, ddof=1):.3f})")
        if effect == "bias_instability":
            wander = gauss_markov_sum(slow, n, value)
            gyro += wander
            notes.append(f"{part} wander SD {np.std(wander):.4f}, p2p {np.ptp(wander):.4f} deg/s")
        gyro += sigma * white.standard_normal(n)
        if effect == "bandwidth":
            gyro = lowpass(gyro, value)
        if effect == "quantization":
            gyro = np.round(gyro / value) * value
        write(os.path.join(directory, f"{name}_{part}.csv"), t, gyro, angle, temperature)
    if effect == "bandwidth":
        d = butterworth2_dc_delay_s(value)
        notes.append(f"filter's low-frequency delay {d * 1e3:.2f} ms (the project's bandwidth with that delay: "
                     f"{1 / (np.pi * 1.5538 * d):.2f} Hz)")
    return notes


def median(values):
    """The usual median: of 4 runs, the mean of the middle two (diagnose's own text headline
    reads the upper of the two, so its figure can differ from the table's)."""
    values = sorted(v for v in values if v is not None)
    if not values:
        return None
    m = len(values) // 2
    return values[m] if len(values) % 2 else 0.5 * (values[m - 1] + values[m])


def covers(ci, value):
    lo, hi = ci
    return (lo is None or lo <= value) and (hi is None or value <= hi)


def fmt_ci(params, ci):
    out = []
    for key, value in params.items():
        lo, hi = ci.get(key, [None, None])
        out.append(f"{key} {value:.3g} [{'-inf' if lo is None else f'{lo:.3g}'}, "
                   f"{'inf' if hi is None else f'{hi:.3g}'}]")
    return ", ".join(out)


def matrix_case(gyro, directory, name, effect, param, value, seed, label, noise):
    notes = matrix_make(directory, name, seed, effect, value, noise)
    base = [gyro, "diagnose", "--split-s", "60",
            "--train", os.path.join(directory, f"{name}_train.csv"),
            "--holdout", os.path.join(directory, f"{name}_holdout.csv")]
    start = time.time()
    done = subprocess.run(base + ["--format", "json"], capture_output=True, text=True)
    seconds = time.time() - start
    if done.returncode != 0:
        return dict(effect=effect, label=label, seed=seed, noise=noise, error=done.stderr.strip(),
                    base=base, notes=notes, seconds=seconds)
    d = json.loads(done.stdout)
    effects = {e["id"]: e for e in d["effects"]}
    named = list(d["verdict"]["unmodelled"])
    row = dict(effect=effect, param=param, value=value, label=label, seed=seed, noise=noise, base=base,
               notes=notes, seconds=seconds, named=named, model_fits=d["verdict"]["model_fits"],
               unexplained=len(d["unexplained"]), error=None)
    row["named_text"] = [f"{n} {fmt_ci(effects[n]['params'], effects[n]['ci95'])}" for n in named]
    row["first"] = named[0] if named else None
    # The detection limit `diagnose` states for the injected effect when it does not name it.
    row["limit"] = None
    for seen in d.get("not_seen", []):
        if seen["id"] == effect and seen.get("limit") and param in seen["limit"]["params"]:
            row["limit"] = seen["limit"]["params"][param]
    row["below_limit"] = row["limit"] is not None and (
        value > row["limit"] if effect == "bandwidth" else abs(value) < abs(row["limit"]))
    row["extra"] = [n for n in named if n != effect and n != LOOKALIKE.get(effect)]
    row["lookalike"] = [n for n in named if effect and n == LOOKALIKE.get(effect)]
    # The verdict's doubts on what it names (`doubts`: e.g. a latency beside low-passed rests).
    row["doubted"] = bool(d.get("doubts"))
    row["top_strict"] = effect is not None and row["first"] == effect
    row["top_group"] = effect is not None and row["first"] is not None and row["first"] in (effect, LOOKALIKE.get(effect))
    row["injected_named"] = effect in named
    row["fit"] = None
    row["covered"] = None
    if effect is not None and effect in effects:
        e = effects[effect]
        if param in e["params"]:
            ci = e["ci95"].get(param, [None, None])
            row["fit"] = (e["params"][param], ci, e["significant"])
            row["covered"] = covers(ci, value)
    comp = d.get("compensation")
    if comp and comp.get("runs"):
        row["comp"] = (median([r.get("max_abs_error_before_deg") for r in comp["runs"]]),
                       median([r.get("max_abs_error_after_deg") for r in comp["runs"]]))
    else:
        row["comp"] = None
    return row


def matrix_failures(row):
    """Why a case is listed as a failure (empty: none)."""
    if row["error"]:
        return ["diagnose failed"]
    if row["effect"] is None:
        return [f"null names {', '.join(row['named'])}"] if row["named"] else []
    why = []
    if not row["named"]:
        why.append("silent" + ("" if row["limit"] is None else
                               f" ({'below' if row['below_limit'] else 'at or above'} the limit it states, "
                               f"{row['limit']:.4g})"))
    elif not row["top_strict"]:
        why.append(f"{row['first']} named first" + (" (look-alike)" if row["top_group"] else ""))
    if row["lookalike"]:
        why.append(f"look-alike {', '.join(row['lookalike'])} named"
                   + (", with a doubt in the verdict" if row.get("doubted") else ", undoubted"))
    if row["extra"]:
        why.append(f"extra {', '.join(row['extra'])}")
    if row["injected_named"] and not row["covered"]:
        why.append("interval misses the injected value")
    return why


def matrix_main(args):
    gyro = args[args.index("--gyro") + 1] if "--gyro" in args else "target/release/gyro-cli"
    keep = args[args.index("--keep") + 1] if "--keep" in args else None
    out_path = args[args.index("--out") + 1] if "--out" in args else None
    only = args[args.index("--only") + 1] if "--only" in args else None
    lines = []
    if "--draw" in args:
        count = int(args[args.index("--draw") + 1])
        first = int(args[args.index("--first") + 1]) if "--first" in args else DRAW_DEVELOPMENT_FIRST
        cases = [draw_case(first + i) for i in range(count)]
    else:
        cases = [(effect, param, value, seed, label, noise)
                 for effect, param, magnitudes, noise in MATRIX for value, seed, label in magnitudes]

    def say(text=""):
        print(text, flush=True)
        lines.append(text)

    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        directory = keep or scratch
        os.makedirs(directory, exist_ok=True)
        say("| effect | noise | magnitude | seed | named first | all named (95% interval) | injected: fitted [95%] "
            "covers | extra | look-alike | model fits | held-out max abs err before -> after (median) | s |")
        say("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for effect, param, value, seed, label, noise in cases:
            if only is not None and only != (effect or "none"):
                continue
            name = f"m{seed}"
            row = matrix_case(gyro, directory, name, effect, param, value, seed, label, noise)
            rows.append(row)
            if row["error"]:
                say(f"| {effect or 'none'} | {noise} | {label} | {seed} | diagnose failed: "
                    f"{row['error'][:200]} | | | | | | | {row['seconds']:.0f} |")
                continue
            if row["fit"] is None:
                fit = "-"
            else:
                v, (lo, hi), sig = row["fit"]
                fit = (f"{v:.4g} [{'-inf' if lo is None else f'{lo:.4g}'}, "
                       f"{'inf' if hi is None else f'{hi:.4g}'}] "
                       f"{'yes' if row['covered'] else 'no'}{'' if sig else ' (not named)'}")
            comp = "-" if row["comp"] is None else f"{row['comp'][0]:.2f} -> {row['comp'][1]:.2f}"
            fits = "yes" if row["model_fits"] else f"no ({row['unexplained']} unexplained)"
            say(f"| {effect or 'none'} | {noise} | {label} | {seed} | {row['first'] or 'nothing'} | "
                f"{'; '.join(row['named_text']) or 'nothing'} | {fit} | {', '.join(row['extra']) or '-'} | "
                f"{', '.join(row['lookalike']) or '-'} | {fits} | {comp} | {row['seconds']:.0f} |")

        say()
        say("Notes on what was drawn:")
        for row in rows:
            if row["notes"]:
                say(f"- {row['effect']} {row['label']} ({row['noise']} noise, seed {row['seed']}): "
                    + "; ".join(row["notes"]))

        ok = [r for r in rows if not r["error"]]
        single = [r for r in ok if r["effect"] is not None]
        nulls = [r for r in ok if r["effect"] is None]
        say()
        say("Summary:")
        for title, group in (("all single-effect cases", single),
                             ("default noise (1.8 deg/sqrt(h))", [r for r in single if r["noise"] == "default"]),
                             ("low noise (0.28 deg/sqrt(h))", [r for r in single if r["noise"] == "low"])):
            if not group:
                continue
            named = [r for r in group if r["injected_named"]]
            say(f"- {title}: {len(group)} cases")
            say(f"  - named first (strict id): {sum(r['top_strict'] for r in group)}/{len(group)}")
            say(f"  - named first (latency~bandwidth as one): {sum(r['top_group'] for r in group)}/{len(group)}")
            say(f"  - injected effect named at all: {len(named)}/{len(group)}")
            silent = [r for r in group if not r["named"]]
            say(f"  - silent: {len(silent)}, of which below the detection limit `diagnose` states: "
                f"{sum(r['below_limit'] for r in silent)}")
            above = [r for r in group if not r["below_limit"]]
            say(f"  - named first where not below the stated limit: "
                f"{sum(r['top_strict'] for r in above)}/{len(above)}")
            say(f"  - nothing extra named (look-alike not counted): {sum(not r['extra'] for r in group)}/{len(group)}")
            say(f"  - look-alike named: {sum(bool(r['lookalike']) for r in group)}/{len(group)}"
                f" (the verdict doubts it: {sum(bool(r['lookalike']) and r.get('doubted', False) for r in group)})")
            say(f"  - 95% interval covers the injected value, where named: "
                f"{sum(bool(r['covered']) for r in named)}/{len(named)}")
            say(f"  - model fits: {sum(r['model_fits'] for r in group)}/{len(group)}")
        if nulls:
            say(f"- nulls clean (nothing named): {sum(not r['named'] for r in nulls)}/{len(nulls)}; "
                f"model fits on nulls: {sum(r['model_fits'] for r in nulls)}/{len(nulls)}")
        errors = [r for r in rows if r["error"]]
        if errors:
            say(f"- diagnose failed on {len(errors)} cases")

        say()
        say("Failures, and the null cases, with the first 3 lines of `diagnose`'s text output:")
        listed = [r for r in rows if matrix_failures(r) or r["effect"] is None]
        if not listed:
            say("- none")
        for row in listed:
            why = matrix_failures(row)
            say(f"- {row['effect'] or 'none'} {row['label']} ({row['noise']} noise, seed {row['seed']}): "
                f"{'; '.join(why) or 'clean'}")
            if row["error"]:
                continue
            text = subprocess.run(row["base"], capture_output=True, text=True)
            for line in (text.stdout.splitlines() or text.stderr.splitlines())[:3]:
                say(f"    {line}")
    if out_path:
        with open(out_path, "w") as out:
            out.write("\n".join(lines) + "\n")


def main():
    args = sys.argv[1:]
    if "--matrix" in args:
        return matrix_main(args)
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
