"""gyro.noise equals gyro-cli noise --format json; gyro.decide equals run's verdicts."""

import json
import subprocess

import pytest

import gyro
from conftest import BENCH


def cli_noise(cli, *args):
    out = subprocess.run([cli, "noise", *map(str, args), "--format", "json"],
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


@pytest.fixture(scope="module")
def static_log(cli, tmp_path_factory):
    path = tmp_path_factory.mktemp("noise") / "static.csv"
    subprocess.run([cli, "simulate", "-o", str(path), "--static", "--duration-s", "120", "--seed", "4"],
                   check=True, capture_output=True)
    return path


def test_noise_equals_cli_on_a_static_log(cli, static_log):
    assert gyro.noise(str(static_log)) == cli_noise(cli, static_log)
    assert gyro.noise(str(static_log), tau_grid="octave") == cli_noise(cli, static_log, "--tau-grid", "octave")


def test_noise_equals_cli_on_rests_and_pooled(cli, static_log):
    assert gyro.noise(str(BENCH), static_only=True) == cli_noise(cli, BENCH, "--static-only")
    assert gyro.noise([str(static_log), str(BENCH)]) == cli_noise(cli, static_log, BENCH)


def test_noise_refuses_what_the_cli_refuses(cli, tmp_path):
    with pytest.raises(gyro.GyroError, match="power of two"):
        gyro.noise(str(BENCH), psd_segment=100)
    with pytest.raises(gyro.GyroError):
        gyro.noise(str(tmp_path / "missing.csv"))
    with pytest.raises(TypeError):
        gyro.noise(str(BENCH), reference_column="x")


def test_decide_gives_run_s_verdicts():
    r = gyro.run(str(BENCH), target_deg=90, tolerance_deg=0.02, scale_sigma=0.0001)
    verdicts = []
    for m in r["movements"]:
        v = gyro.decide(m["angle_deg"], m["angle_std_deg"], 90, 0.02, scale_sigma=0.0001)
        assert v == m.get("verdict"), m
        verdicts.append(v)
    assert None in verdicts and len(set(verdicts)) >= 2, verdicts
    assert gyro.decide(90.0, 0.01, 90, 1, untrusted=True) == "invalid"
    assert gyro.decide(-90.0, 0.01, 90, 1) is None
    assert gyro.decide(-90.0, 0.01, 90, 1, tightening_direction="negative") == "ok"
    with pytest.raises(gyro.GyroError):
        gyro.decide(90.0, 0.01, 90, -1)
