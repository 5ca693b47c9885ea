"""Make a plant-day of tightening logs with `gyro-cli simulate`: W wrenches, L logs each.

Each wrench has its own scale error (a gyro whose scale is off by up to ±1.5 %), each log
its own seed: `OUT/wrench_007/tightening_0003.csv`.

    python examples/fleet/make_plant_day.py --out /tmp/plant-day --wrenches 20 --logs 15
"""

from __future__ import annotations

import argparse
import concurrent.futures
import os
import pathlib
import shutil
import subprocess


def scale_error(wrench: int) -> float:
    """The wrench's scale error (fraction), from -0.015 to 0.015."""
    return ((wrench * 7) % 11 - 5) * 0.003


def make(out: pathlib.Path, wrenches: int, logs: int, duration_s: float, cli: str) -> list[pathlib.Path]:
    """Write the logs (those already there are kept) and return their paths."""
    jobs = []
    for w in range(1, wrenches + 1):
        folder = out / f"wrench_{w:03d}"
        folder.mkdir(parents=True, exist_ok=True)
        for i in range(1, logs + 1):
            path = folder / f"tightening_{i:04d}.csv"
            seed = w * 10_000 + i
            jobs.append((path, [cli, "simulate", "-o", str(path), "--seed", str(seed),
                                "--duration-s", str(duration_s),
                                "--effect", f"scale_factor:k={scale_error(w)}"]))

    def one(job):
        path, command = job
        if not path.exists():
            subprocess.run(command, check=True, capture_output=True)
        return path

    with concurrent.futures.ThreadPoolExecutor(os.cpu_count() or 2) as pool:
        return list(pool.map(one, jobs))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, type=pathlib.Path)
    p.add_argument("--wrenches", type=int, default=20)
    p.add_argument("--logs", type=int, default=15, help="logs per wrench")
    p.add_argument("--duration-s", type=float, default=30.0)
    p.add_argument("--cli", default=os.environ.get("GYRO_CLI") or shutil.which("gyro-cli") or "target/release/gyro-cli")
    a = p.parse_args()
    paths = make(a.out, a.wrenches, a.logs, a.duration_s, a.cli)
    print(f"{len(paths)} logs in {a.out}")


if __name__ == "__main__":
    main()
