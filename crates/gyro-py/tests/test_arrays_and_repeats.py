"""gyro.noise_arrays and gyro.calibrate_arrays give what gyro.noise and gyro.calibrate give
on the CSVs holding the same arrays; a log given twice is refused as gyro-cli refuses it."""

import subprocess

import pytest

import gyro
from conftest import BENCH
from test_run import arrays_of


@pytest.fixture(scope="module")
def runs(cli, tmp_path_factory):
    folder = tmp_path_factory.mktemp("arrays")
    paths = []
    for seed in (7, 8, 9):
        path = folder / f"run{seed}.csv"
        subprocess.run([cli, "simulate", "-o", str(path), "--seed", str(seed), "--duration-s", "30"],
                       check=True, capture_output=True)
        paths.append(str(path))
    return paths


def named(path):
    return dict(arrays_of(path), name=str(path))


def cli_error(cli, *args):
    out = subprocess.run([cli, *args], capture_output=True, text=True)
    assert out.returncode == 1, out.stderr
    return out.stderr.strip().removeprefix("error: ")


def test_noise_on_arrays_equals_noise_on_the_file(runs):
    assert gyro.noise_arrays(named(BENCH), static_only=True) == gyro.noise(str(BENCH), static_only=True)
    assert gyro.noise_arrays([named(p) for p in runs]) == gyro.noise(runs)
    one = gyro.noise_arrays({"time_s": arrays_of(BENCH)["time_s"], "rate_dps": arrays_of(BENCH)["rate_dps"]},
                            sample_rate_hz=1000, tau_grid="octave")
    assert one["logs"][0]["file"] == "<arrays>"
    assert one["logs"][0]["input"]["sample_rate_source"] == "option"


def test_calibrate_on_arrays_equals_calibrate_on_the_files(runs):
    got = gyro.calibrate_arrays([named(p) for p in runs[:2]], [named(runs[2])], objective="movement-rms")
    want = gyro.calibrate(runs[:2], holdout=[runs[2]], objective="movement-rms")
    assert got == want


def test_arrays_refuse_bad_input():
    a = arrays_of(BENCH)
    with pytest.raises(gyro.GyroError, match="rate_dps has 2 values"):
        gyro.noise_arrays({"time_s": a["time_s"], "rate_dps": a["rate_dps"][:2]})
    with pytest.raises(gyro.GyroError, match="needs 'rate_dps'"):
        gyro.noise_arrays({"time_s": a["time_s"]})
    with pytest.raises(gyro.GyroError):
        gyro.noise_arrays([])
    with pytest.raises(TypeError):
        gyro.noise_arrays(named(BENCH), rate_column="x")
    with pytest.raises(TypeError):
        gyro.calibrate_arrays([named(BENCH)], holdout_paths=[str(BENCH)])


def test_a_log_given_twice_is_refused_as_by_the_cli(cli, runs, tmp_path):
    again = runs[0].replace("/run7.csv", "/../" + runs[0].split("/")[-2] + "/run7.csv")
    with pytest.raises(gyro.GyroError) as e:
        gyro.noise([runs[0], again])
    assert str(e.value) == cli_error(cli, "noise", runs[0], again)
    with pytest.raises(gyro.GyroError) as e:
        gyro.calibrate([runs[0], runs[1]], holdout=[again])
    assert str(e.value) == cli_error(cli, "calibrate", runs[0], runs[1], "--holdout", again,
                                     "-o", str(tmp_path / "m.json"))
    assert "give each run once" in str(e.value)
    assert not (tmp_path / "m.json").exists()
