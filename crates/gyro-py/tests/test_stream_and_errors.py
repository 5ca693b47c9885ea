"""The streaming Pipeline equals the one call; bad input raises with gyro-cli's message."""

import subprocess

import numpy as np
import pytest

import gyro
from conftest import BENCH
from test_run import arrays_of, without_series


@pytest.mark.parametrize("block", [1, 777, 10_000, 10**7])
def test_blocks_equal_the_one_call(block):
    a = arrays_of(BENCH)
    one = gyro.run_arrays(a["time_s"], a["rate_dps"], a["reference_deg"], a["temperature_c"],
                          sample_rate_hz=1000.0, target_deg=90, tolerance_deg=1.0)
    p = gyro.Pipeline(1000.0, target_deg=90, tolerance_deg=1.0)
    pushed = []
    for start in range(0, len(a["time_s"]), block):
        end = start + block
        pushed.append(p.push(a["time_s"][start:end], a["rate_dps"][start:end],
                             a["reference_deg"][start:end], a["temperature_c"][start:end]))
    report = p.finish()
    series = gyro.concat_series([b["series"] for b in pushed])
    for key in gyro.SERIES_KEYS:
        np.testing.assert_array_equal(series[key], one["series"][key], err_msg=key)
    assert report["movements"] == one["movements"]
    assert report["summary"] == one["summary"]
    ended = [m for b in pushed for m in b["ended"]]
    assert ended == [m for m in one["movements"] if m["complete"]]
    started = [t for b in pushed for t in b["started_s"]]
    assert started == [m["start_time_s"] for m in one["movements"]]
    verdicts = [m["verdict"] for m in ended if "verdict" in m]
    assert verdicts == ["ok", "ok"]


def test_a_finished_pipeline_refuses_more():
    p = gyro.Pipeline(1000.0)
    p.push([0.0, 0.001], [0.0, 0.0])
    p.finish()
    with pytest.raises(gyro.GyroError, match="finished"):
        p.push([0.002], [0.0])


def cli_error(cli, *args):
    out = subprocess.run([cli, *args], capture_output=True, text=True)
    assert out.returncode == 1
    return out.stderr.strip().removeprefix("error: ")


def test_errors_carry_the_cli_message(cli, tmp_path):
    missing = str(tmp_path / "missing.csv")
    with pytest.raises(gyro.GyroError) as e:
        gyro.run(missing)
    assert str(e.value) == cli_error(cli, "run", missing)
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,rate_dps\n0.0,1.0\n0.001,abc\n")
    with pytest.raises(gyro.GyroError) as e:
        gyro.run(str(bad))
    assert str(e.value) == cli_error(cli, "run", str(bad))
    model = tmp_path / "model.json"
    model.write_text('{"format": "gyro-model", "version": 1, "nonsense": 1}')
    with pytest.raises(gyro.GyroError) as e:
        gyro.run(str(BENCH), model=str(model))
    assert str(e.value) == cli_error(cli, "run", str(BENCH), "--model", str(model))
    with pytest.raises(gyro.GyroError) as e:
        gyro.run(str(BENCH), compensation="paper", offline=True)
    assert str(e.value) == cli_error(cli, "run", str(BENCH), "--compensation", "paper", "--offline")


@pytest.mark.parametrize(
    "call,error",
    [
        (lambda: gyro.run(str(BENCH), target_deg=90), gyro.GyroError),
        (lambda: gyro.run(str(BENCH), tolerance_deg=-1, target_deg=90), gyro.GyroError),
        (lambda: gyro.run(str(BENCH), range_dps=float("nan")), gyro.GyroError),
        (lambda: gyro.run(str(BENCH), compensation="magic"), gyro.GyroError),
        (lambda: gyro.run(str(BENCH), time_unit="fortnight"), gyro.GyroError),
        (lambda: gyro.run(str(BENCH), no_such_option=1), TypeError),
        (lambda: gyro.run_arrays([0.0, 0.001], [0.0]), gyro.GyroError),
        (lambda: gyro.run_arrays([0.0, float("nan")], [0.0, 0.0]), gyro.GyroError),
        (lambda: gyro.run_arrays([], []), gyro.GyroError),
        (lambda: gyro.run_arrays([[0.0]], [[0.0]]), gyro.GyroError),
        (lambda: gyro.run_arrays(["a"], [0.0]), ValueError),
        (lambda: gyro.run_arrays([0.0, 0.001], [0.0, 0.0], time_column="t"), TypeError),
        (lambda: gyro.Pipeline(0.0), gyro.GyroError),
        (lambda: gyro.Pipeline(1000.0, offline=True), gyro.GyroError),
        (lambda: gyro.Pipeline(1000.0).push([0.0, 0.0], [1.0, 1.0]), gyro.GyroError),
    ],
)
def test_bad_input_raises(call, error):
    with pytest.raises(error):
        call()
