"""Where the tests find gyro-cli, the fixtures and the shared real recordings."""

import os
import pathlib
import shutil

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]
BENCH = REPO / "fixtures" / "logs" / "bench_run.csv"
# The real recordings live beside the repository (README.md), or where GYRO_REAL_DATA says.
REAL = pathlib.Path(os.environ.get("GYRO_REAL_DATA", REPO.parent / "shared" / "data" / "real"))


def find_cli():
    """gyro-cli: $GYRO_CLI, else the workspace's debug or release build, else PATH."""
    given = os.environ.get("GYRO_CLI")
    if given:
        return given
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    for build in ("release", "debug"):
        path = target / build / "gyro-cli"
        if path.exists():
            return str(path)
    return shutil.which("gyro-cli")


@pytest.fixture(scope="session")
def cli():
    path = find_cli()
    if path is None:
        pytest.skip("gyro-cli not found: set GYRO_CLI, or cargo build -p gyro-cli")
    return path


def real_recordings():
    """The shared real recordings (single-axis CSVs), or an empty list."""
    if not REAL.is_dir():
        return []
    return sorted(REAL.glob("ssong_*.csv")) + sorted((REAL / "rasteiro").glob("rasteiro_*.csv"))
