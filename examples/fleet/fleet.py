"""Every movement of every log of a plant-day in one Parquet table, on Dask's distributed
scheduler, through the Python package `gyro`.

    # here: a LocalCluster of N worker processes
    python examples/fleet/fleet.py /tmp/plant-day --workers 2 --out movements.parquet \
        --target-deg 90 --tolerance-deg 1
    # a real cluster: the scheduler's address (the logs on a file system every worker sees,
    # the gyro wheel installed on every worker)
    python examples/fleet/fleet.py /shared/plant-day --scheduler tcp://10.0.0.5:8786 ...

A log is a task (`gyro.run` on a worker, the GIL released while it replays); the rows come
back to the client, which writes one table (pyarrow) and prints a summary per wrench. A log
gyro refuses does not stop the day: it is listed with gyro's message.
"""

from __future__ import annotations

import argparse
import pathlib
import time
from typing import Any, Dict, List, Optional, Tuple

import pandas as pd

# One row per movement: the log's and the movement's identity, then gyro run's numbers.
MOVEMENT_KEYS = (
    "start_time_s", "end_time_s", "duration_s", "complete", "angle_deg", "raw_angle_deg",
    "reference_deg", "error_deg", "saturated", "filled_samples", "angle_std_deg",
)
COLUMNS = ("wrench", "log", "movement", *MOVEMENT_KEYS, "verdict")


def wrench_of(path: str) -> str:
    """The wrench a log belongs to: its folder's name."""
    return pathlib.PurePath(path).parent.name


def movements_of(path: str, options: Dict[str, Any]) -> Tuple[List[Dict[str, Any]], Optional[str]]:
    """One log (on a worker): its movements as rows, or gyro's error message."""
    import gyro  # imported on the worker

    try:
        report = gyro.run(path, **options)
    except gyro.GyroError as e:
        return [], str(e)
    rows = []
    for m in report["movements"]:
        row = {"wrench": wrench_of(path), "log": path, "movement": m["index"]}
        row.update({k: m[k] for k in MOVEMENT_KEYS})
        row["verdict"] = m.get("verdict")  # absent: a turn the other way, or no window
        rows.append(row)
    return rows, None


def run_fleet(client, logs: List[str], options: Dict[str, Any]) -> Tuple[pd.DataFrame, Dict[str, str]]:
    """All movements of `logs` (one task each on `client`), in log order; the failed logs."""
    futures = client.map(movements_of, logs, options=options, pure=False)
    rows, failed = [], {}
    for log, (log_rows, error) in zip(logs, client.gather(futures)):
        rows.extend(log_rows)
        if error is not None:
            failed[log] = error
    table = pd.DataFrame(rows, columns=list(COLUMNS))
    table["verdict"] = table["verdict"].astype("string")
    return table, failed


def per_wrench(table: pd.DataFrame) -> pd.DataFrame:
    """Per wrench: logs, movements, each verdict's count, mean and max |error|, max σ."""
    g = table.groupby("wrench")
    summary = pd.DataFrame({
        "logs": g["log"].nunique(),
        "movements": g.size(),
        **{v: g["verdict"].apply(lambda s, v=v: int((s == v).sum())) for v in ("ok", "nok", "recheck", "invalid")},
        "mean_error_deg": g["error_deg"].mean(),
        "max_abs_error_deg": g["error_deg"].apply(lambda s: s.abs().max()),
        "max_angle_std_deg": g["angle_std_deg"].max(),
    })
    return summary


def client_for(scheduler: Optional[str], workers: int):
    """A client of the cluster at `scheduler`, else of a LocalCluster of `workers` processes."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        client = Client(scheduler)
    else:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    # The workers import this module by name: send it to them.
    client.upload_file(__file__)
    return client


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("logs", type=pathlib.Path, help="a folder of logs (searched for *.csv and *.mcap)")
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("movements.parquet"))
    p.add_argument("--scheduler", help="the address of a running Dask scheduler (tcp://host:8786)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    p.add_argument("--target-deg", type=float)
    p.add_argument("--tolerance-deg", type=float)
    p.add_argument("--scale-sigma", type=float)
    p.add_argument("--model", help="a model file (on every worker's file system)")
    a = p.parse_args()
    logs = sorted(str(x) for x in a.logs.rglob("*") if x.suffix in (".csv", ".mcap"))
    options = {k: v for k, v in dict(target_deg=a.target_deg, tolerance_deg=a.tolerance_deg,
                                     scale_sigma=a.scale_sigma, model=a.model).items() if v is not None}
    client = client_for(a.scheduler, a.workers)
    # Warm the workers (import gyro) so that the time below is the logs'.
    client.run(lambda: __import__("gyro"))
    start = time.perf_counter()
    table, failed = run_fleet(client, logs, options)
    elapsed_s = time.perf_counter() - start
    table.to_parquet(a.out, engine="pyarrow", index=False)
    print(f"{len(logs)} logs, {len(table)} movements -> {a.out} in {elapsed_s:.2f} s "
          f"({len(client.scheduler_info()['workers'])} workers)")
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(per_wrench(table).round(4).to_string())
    for log, error in failed.items():
        print(f"failed: {log}: {error}")
    client.close()


if __name__ == "__main__":
    main()
