"""The fleet example on a small plant-day with two workers: its Parquet table holds every
movement of every log, each equal to gyro-cli run --format json's."""

import json
import os
import pathlib
import shutil
import subprocess
import sys

import pyarrow.parquet as pq
import pytest

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))

import fleet  # noqa: E402
import make_plant_day  # noqa: E402


def find_cli():
    given = os.environ.get("GYRO_CLI")
    if given:
        return given
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    for build in ("release", "debug"):
        if (target / build / "gyro-cli").exists():
            return str(target / build / "gyro-cli")
    return shutil.which("gyro-cli")


def test_two_workers_give_gyro_cli_s_movements(tmp_path):
    cli = find_cli()
    if cli is None:
        pytest.skip("gyro-cli not found: set GYRO_CLI, or cargo build -p gyro-cli")
    logs = [str(p) for p in make_plant_day.make(tmp_path / "day", wrenches=3, logs=3, duration_s=20.0, cli=cli)]
    bad = tmp_path / "day" / "wrench_004" / "broken.csv"
    bad.parent.mkdir()
    bad.write_text("time_s,rate_dps\n0.0,1.0\n0.001,abc\n")
    logs.append(str(bad))
    options = dict(target_deg=90.0, tolerance_deg=1.0)
    client = fleet.client_for(None, workers=2)
    try:
        assert len(client.scheduler_info()["workers"]) == 2
        table, failed = fleet.run_fleet(client, logs, options)
    finally:
        client.close()
    out = tmp_path / "movements.parquet"
    table.to_parquet(out, engine="pyarrow", index=False)
    rows = pq.read_table(out).to_pylist()

    expected = []
    for log in logs[:-1]:
        report = json.loads(subprocess.run(
            [cli, "run", log, "--format", "json", "--target-deg", "90", "--tolerance-deg", "1"],
            check=True, capture_output=True, text=True).stdout)
        for m in report["movements"]:
            row = {"wrench": pathlib.Path(log).parent.name, "log": log, "movement": m["index"]}
            row.update({k: m[k] for k in fleet.MOVEMENT_KEYS})
            row["verdict"] = m.get("verdict")
            expected.append(row)
    assert len(expected) >= 9
    assert rows == expected
    assert list(failed) == [str(bad)]
    error = subprocess.run([cli, "run", str(bad)], capture_output=True, text=True).stderr
    assert error.strip() == "error: " + failed[str(bad)]
    summary = fleet.per_wrench(table)
    assert summary["movements"].sum() == len(expected)
    assert set(summary.index) == {"wrench_001", "wrench_002", "wrench_003"}
