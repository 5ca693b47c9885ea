"""Type hints of the native module ``gyro._gyro`` (the ``gyro`` package wraps it)."""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class GyroError(ValueError):
    """A log, a model or an option gyro refuses; the message is gyro-cli's."""

Series = Dict[str, npt.NDArray[Any]]

def run_file(
    path: str, file: str, options: Optional[Dict[str, Any]] = None
) -> Tuple[str, Series]:
    """``gyro-cli run PATH --format json``: (JSON text, series arrays)."""

def run_arrays(
    time_s: npt.NDArray[np.float64],
    rate_dps: npt.NDArray[np.float64],
    reference_deg: Optional[npt.NDArray[np.float64]],
    temperature_c: Optional[npt.NDArray[np.float64]],
    nominal_rate_hz: Optional[float],
    name: str,
    first_line: int,
    options: Optional[Dict[str, Any]] = None,
) -> Tuple[str, Series]:
    """``gyro-cli run`` on arrays: (JSON text, series arrays)."""

def noise_files(paths: List[str], options: Optional[Dict[str, Any]] = None) -> str:
    """``gyro-cli noise LOG... --format json``: the JSON text."""

def calibrate_files(
    logs: List[str], options: Optional[Dict[str, Any]] = None
) -> Tuple[str, str]:
    """``gyro-cli calibrate LOG... --format json``: (JSON text, model file text)."""

ArrayLog = Tuple[
    str,
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    Optional[npt.NDArray[np.float64]],
    Optional[npt.NDArray[np.float64]],
    Optional[float],
    int,
]
"""A log as arrays: (name, time_s, rate_dps, reference_deg, temperature_c,
nominal_rate_hz, first_line)."""

def noise_arrays(logs: List[ArrayLog], options: Optional[Dict[str, Any]] = None) -> str:
    """``gyro-cli noise`` on logs as arrays: the JSON text."""

def calibrate_arrays(
    train: List[ArrayLog],
    holdout: List[ArrayLog],
    options: Optional[Dict[str, Any]] = None,
) -> Tuple[str, str]:
    """``gyro-cli calibrate`` on runs as arrays: (JSON text, model file text)."""

def diagnose_files(
    train: List[str], holdout: List[str], options: Optional[Dict[str, Any]] = None
) -> str:
    """``gyro-cli diagnose --train ... --holdout ... --format json``: the JSON text."""

def diagnose_arrays(
    train: List[ArrayLog],
    holdout: List[ArrayLog],
    options: Optional[Dict[str, Any]] = None,
) -> str:
    """``gyro-cli diagnose`` on runs as arrays: the JSON text."""

def decide(
    angle_deg: float,
    angle_std_deg: float,
    target_deg: float,
    tolerance_deg: float,
    k_sigma: float = 2.0,
    tightening_direction: str = "positive",
    scale_sigma: float = 0.0,
    untrusted: bool = False,
) -> Optional[str]:
    """The tightening decision on one angle: "ok", "nok", "recheck", "invalid", or None."""

class _Stream:
    """The streaming pipeline; ``gyro.Pipeline`` wraps it."""

    def __init__(
        self, sample_rate_hz: float, options: Optional[Dict[str, Any]] = None
    ) -> None: ...
    def push(
        self,
        time_s: npt.NDArray[np.float64],
        rate_dps: npt.NDArray[np.float64],
        reference_deg: Optional[npt.NDArray[np.float64]] = None,
        temperature_c: Optional[npt.NDArray[np.float64]] = None,
    ) -> Tuple[Series, List[float], str]:
        """Push a block: (series arrays, movement start times, JSON of the ended movements)."""
    def finish(self, name: str) -> str:
        """The report of everything pushed (JSON text)."""
