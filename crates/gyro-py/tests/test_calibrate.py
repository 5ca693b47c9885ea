"""gyro.calibrate equals gyro-cli calibrate --format json, and writes the same model file."""

import json
import subprocess

import pytest

import gyro
from conftest import BENCH


@pytest.fixture(scope="module")
def runs(cli, tmp_path_factory):
    folder = tmp_path_factory.mktemp("calibrate")
    paths = []
    for seed in (5, 6):
        path = folder / f"run{seed}.csv"
        subprocess.run([cli, "simulate", "-o", str(path), "--seed", str(seed), "--duration-s", "40",
                        "--effect", "scale_factor:k=0.01"], check=True, capture_output=True)
        paths.append(str(path))
    return paths


def test_calibrate_equals_cli(cli, runs, tmp_path):
    cli_model = tmp_path / "cli.model.json"
    out = subprocess.run([cli, "calibrate", *runs, "--holdout", str(BENCH), "-o", str(cli_model),
                          "--objective", "movement-rms", "--format", "json"],
                         check=True, capture_output=True, text=True)
    py_model = tmp_path / "py.model.json"
    got = gyro.calibrate(runs, holdout=[str(BENCH)], objective="movement-rms", out=str(py_model))
    model = got.pop("model")
    assert got == json.loads(out.stdout)
    assert py_model.read_bytes() == cli_model.read_bytes()
    assert model == json.loads(cli_model.read_text())


def test_calibrate_refuses_bad_input(tmp_path):
    with pytest.raises(gyro.GyroError):
        gyro.calibrate([str(tmp_path / "missing.csv")])
    with pytest.raises(gyro.GyroError):
        gyro.calibrate([str(BENCH)], objective="best")
    with pytest.raises(gyro.GyroError):
        gyro.calibrate([str(BENCH)], tau_s=-1.0)
