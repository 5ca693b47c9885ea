"""gyro.diagnose equals gyro-cli diagnose --format json; its errors are the CLI's."""

import json
import subprocess

import pytest

import gyro
from conftest import BENCH, REPO

# Runs from a generator that is not the project's (fixtures/diagnose/make_foreign_runs.py),
# cut into 60 s windows: four training and four held-out runs, small ensembles (quick).
FIXTURES = REPO / "fixtures" / "diagnose"
TRAIN = str(FIXTURES / "even_train.csv")
HOLDOUT = str(FIXTURES / "even_holdout.csv")
QUICK = ["--split-s", "60", "--members", "12", "--candidate-members", "6"]
QUICK_KW = dict(split_s=60, members=12, candidate_members=6)


def cli_diagnose(cli, train, holdout, *flags):
    out = subprocess.run(
        [cli, "diagnose", "--train", *train, "--holdout", *holdout, *flags, "--format", "json"],
        check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def cli_error(cli, *args):
    out = subprocess.run([cli, *args], capture_output=True, text=True)
    assert out.returncode == 1, out.stderr
    return out.stderr.strip().removeprefix("error: ")


def test_diagnose_equals_cli(cli):
    got = gyro.diagnose(TRAIN, HOLDOUT, **QUICK_KW)
    assert got == cli_diagnose(cli, [TRAIN], [HOLDOUT], *QUICK)
    assert got["inputs"][0]["file"] == TRAIN
    assert got["model"]["effects"] or got["effects"]


def test_diagnose_with_a_seed_and_every_candidate_equals_cli(cli):
    got = gyro.diagnose([TRAIN], [HOLDOUT], seed=3, score_every_candidate=True, **QUICK_KW)
    assert got == cli_diagnose(cli, [TRAIN], [HOLDOUT], *QUICK, "--seed", "3",
                               "--score-every-candidate")


def test_a_log_given_twice_is_refused_as_by_the_cli(cli):
    again = str(FIXTURES / ".." / "diagnose" / "even_train.csv")
    with pytest.raises(gyro.GyroError) as e:
        gyro.diagnose(TRAIN, again, **QUICK_KW)
    assert str(e.value) == cli_error(cli, "diagnose", "--train", TRAIN, "--holdout", again, *QUICK)
    assert "give each run once" in str(e.value)
    with pytest.raises(gyro.GyroError) as e:
        gyro.diagnose([TRAIN, again], [HOLDOUT])
    assert str(e.value) == cli_error(cli, "diagnose", "--train", TRAIN, again, "--holdout", HOLDOUT)


def test_diagnose_errors_carry_the_cli_message(cli, tmp_path):
    cases = [
        # too few runs: the message with the command line's advice
        ((TRAIN, HOLDOUT), {}, ["--train", TRAIN, "--holdout", HOLDOUT]),
        # no reference
        (([TRAIN, str(REPO / "fixtures" / "noise" / "allan_input.csv")], HOLDOUT), {},
         ["--train", TRAIN, str(REPO / "fixtures" / "noise" / "allan_input.csv"), "--holdout", HOLDOUT]),
        # a window longer than the log
        ((TRAIN, HOLDOUT), dict(split_s=1000), ["--train", TRAIN, "--holdout", HOLDOUT, "--split-s", "1000"]),
        # rates differ: the advice names --sample-rate-hz
        (([TRAIN, str(BENCH)], HOLDOUT), dict(split_s=60),
         ["--train", TRAIN, str(BENCH), "--holdout", HOLDOUT, "--split-s", "60"]),
        # a missing log, a missing model
        (([TRAIN, str(tmp_path / "missing.csv")], HOLDOUT), {},
         ["--train", TRAIN, str(tmp_path / "missing.csv"), "--holdout", HOLDOUT]),
        ((TRAIN, HOLDOUT), dict(model=str(tmp_path / "missing.json")),
         ["--train", TRAIN, "--holdout", HOLDOUT, "--model", str(tmp_path / "missing.json")]),
    ]
    for (train, holdout), kw, flags in cases:
        with pytest.raises(gyro.GyroError) as e:
            gyro.diagnose(train, holdout, **kw)
        assert str(e.value) == cli_error(cli, "diagnose", *flags), flags


def test_diagnose_refuses_bad_options():
    with pytest.raises(gyro.GyroError, match="at least 2"):
        gyro.diagnose(TRAIN, HOLDOUT, members=1)
    with pytest.raises(gyro.GyroError, match="split-s"):
        gyro.diagnose(TRAIN, HOLDOUT, split_s=-1.0)
    with pytest.raises(TypeError):
        gyro.diagnose(TRAIN, HOLDOUT, report="x")


def test_diagnose_on_arrays_equals_diagnose_on_the_files():
    from test_run import arrays_of

    def named(path):
        return dict(arrays_of(path), name=path)

    got = gyro.diagnose_arrays([named(TRAIN)], [named(HOLDOUT)], **QUICK_KW)
    assert got == gyro.diagnose(TRAIN, HOLDOUT, **QUICK_KW)
    with pytest.raises(TypeError):
        gyro.diagnose_arrays([named(TRAIN)], [named(HOLDOUT)], rate_column="x")
