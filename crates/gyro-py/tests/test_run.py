"""gyro.run and gyro.run_arrays give gyro-cli run --format json's numbers, bit for bit."""

import json
import math
import subprocess

import numpy as np
import pytest

import gyro
from conftest import BENCH, REAL, real_recordings


def cli_json(cli, path, *flags):
    out = subprocess.run(
        [cli, "run", str(path), "--format", "json", *flags],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout)


def without_series(report):
    return {k: v for k, v in report.items() if k != "series"}


def read_csv(path):
    """A log's columns as float64 arrays (NaN for an empty field) and its metadata."""
    metadata, header, rows, first_line = {}, None, [], None
    with open(path) as f:
        for number, line in enumerate(f, start=1):
            line = line.rstrip("\n")
            if line.startswith("#"):
                key, _, value = line[1:].partition(":")
                metadata[key.strip()] = value.strip()
            elif header is None:
                header = line.split(",")
                first_line = number + 1
            elif line:
                rows.append([float(v) if v else math.nan for v in line.split(",")])
    data = np.array(rows, dtype=np.float64).reshape(-1, len(header))
    columns = {name: np.ascontiguousarray(data[:, i]) for i, name in enumerate(header)}
    return columns, metadata, first_line


def arrays_of(path):
    columns, metadata, first_line = read_csv(path)
    nominal = metadata.get("sample_rate_hz")
    return dict(
        time_s=columns["time_s"],
        rate_dps=columns["rate_dps"],
        reference_deg=columns.get("reference_deg"),
        temperature_c=columns.get("temperature_c"),
        nominal_rate_hz=float(nominal) if nominal else None,
        first_line=first_line,
    )


# (gyro.run keyword arguments, the same as gyro-cli flags)
OPTIONS = [
    ({}, []),
    (
        dict(target_deg=90, tolerance_deg=1.0, scale_sigma=0.01),
        ["--target-deg", "90", "--tolerance-deg", "1.0", "--scale-sigma", "0.01"],
    ),
    (dict(offline=True), ["--offline"]),
    (dict(reference_delay_s=0.05), ["--reference-delay-s", "0.05"]),
    (dict(compensation="paper"), ["--compensation", "paper"]),
]


@pytest.mark.parametrize("options,flags", OPTIONS)
def test_run_equals_cli_on_the_bench_log(cli, options, flags):
    expected = cli_json(cli, BENCH, *flags)
    got = gyro.run(str(BENCH), **options)
    assert without_series(got) == expected
    assert len(got["series"]["time_s"]) == expected["summary"]["outputs"]


@pytest.mark.parametrize("options,flags", OPTIONS)
def test_run_arrays_equals_cli_on_the_bench_log(cli, options, flags):
    expected = cli_json(cli, BENCH, *flags)
    got = gyro.run_arrays(name=str(BENCH), **arrays_of(BENCH), **options)
    assert without_series(got) == expected


def test_series_equals_the_cli_out_csv(cli, tmp_path):
    out = tmp_path / "series.csv"
    subprocess.run([cli, "run", str(BENCH), "--out", str(out)], check=True, capture_output=True)
    lines = [l for l in out.read_text().splitlines() if not l.startswith("#")][1:]
    s = gyro.run(str(BENCH))["series"]
    assert len(lines) == len(s["time_s"])

    def f(v, digits=6):
        return "" if math.isnan(v) else f"{v:.{digits}f}"

    for i, line in enumerate(lines):
        row = ",".join(
            [
                f(s["time_s"][i]),
                f(s["rate_dps"][i], 5),
                "dynamic" if s["moving"][i] else "static",
                f(s["angle_deg"][i]),
                f(s["raw_angle_deg"][i]),
                f(s["angle_std_deg"][i]),
                f(s["bias_dps"][i]),
                f(s["reference_deg"][i]),
                f(s["error_deg"][i]),
            ]
        )
        assert row == line, i


RECORDINGS = real_recordings()


@pytest.mark.skipif(
    not RECORDINGS, reason=f"the shared real recordings are not at {REAL} (set GYRO_REAL_DATA)"
)
@pytest.mark.parametrize("path", RECORDINGS, ids=lambda p: p.name)
def test_run_and_run_arrays_equal_cli_on_real_recordings(cli, path):
    expected = cli_json(cli, path)
    assert without_series(gyro.run(str(path))) == expected
    got = gyro.run_arrays(name=str(path), **arrays_of(path))
    assert without_series(got) == expected
