"""gyro: the rotation angle of a torque wrench from a single-axis gyroscope (CRM100).

The pipeline and the host tools of the gyro workspace on numpy arrays and log files:

- ``run(path, **options)``: ``gyro-cli run PATH --format json`` as Python objects, plus
  the output series as numpy arrays under ``"series"``;
- ``run_arrays(time_s, rate_dps, reference_deg=None, temperature_c=None, **options)``:
  the same on arrays, as if they were a CSV log's columns;
- ``Pipeline(sample_rate_hz, **options)``: the pipeline fed block by block;
- ``noise(paths, **options)``: ``gyro-cli noise LOG... --format json`` as Python objects;
  ``noise_arrays(logs, **options)`` the same on arrays;
- ``calibrate(logs, **options)``: ``gyro-cli calibrate LOG... --format json`` and the model;
  ``calibrate_arrays(train, holdout, **options)`` the same on arrays;
- ``diagnose(train, holdout, **options)``: ``gyro-cli diagnose --format json`` as Python
  objects (the contract of docs/diagnose-json.md); ``diagnose_arrays(train, holdout,
  **options)`` the same on arrays;
- ``decide(angle_deg, angle_std_deg, target_deg, tolerance_deg, ...)``: one verdict.

Options are ``gyro-cli run``'s flags with ``_`` for ``-`` (``target_deg=90``,
``tolerance_deg=0.5``, ``model="x.model.json"``, ``offline=True``). Errors raise
``GyroError`` (a ``ValueError``) with the command line's message.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Optional

import numpy as np

from . import _gyro
from ._gyro import GyroError

__all__ = [
    "GyroError",
    "Pipeline",
    "calibrate",
    "calibrate_arrays",
    "decide",
    "diagnose",
    "diagnose_arrays",
    "noise",
    "noise_arrays",
    "run",
    "run_arrays",
    "__version__",
]
__version__: str = _gyro.__version__

SERIES_KEYS = (
    "time_s",
    "rate_dps",
    "moving",
    "angle_deg",
    "raw_angle_deg",
    "angle_std_deg",
    "bias_dps",
    "reference_deg",
    "error_deg",
)


def _f64(name: str, values: Any) -> Optional[np.ndarray]:
    """A contiguous float64 view of ``values`` (no copy when it is one already)."""
    if values is None:
        return None
    a = np.ascontiguousarray(values, dtype=np.float64)
    if a.ndim != 1:
        raise GyroError(f"{name}: expected a 1-D array, got {a.ndim} dimensions")
    return a


def _report(text: str, series: Optional[Dict[str, np.ndarray]]) -> Dict[str, Any]:
    report = json.loads(text)
    if series is not None:
        report["series"] = series
    return report


def run(path: "os.PathLike[str] | str", **options: Any) -> Dict[str, Any]:
    """Replay a log (CSV, MCAP, ROS 2 bag) as ``gyro-cli run PATH --format json`` does.

    Returns the JSON as Python objects (``docs/run-json.md``), the same numbers, and
    ``"series"``: the output-rate series as numpy arrays (``time_s``, ``rate_dps``,
    ``moving``, ``angle_deg``, ``raw_angle_deg``, ``angle_std_deg``, ``bias_dps``,
    ``reference_deg``, ``error_deg``; NaN where missing).
    """
    file = os.fspath(path)
    text, series = _gyro.run_file(file, file, options)
    return _report(text, series)


def run_arrays(
    time_s: Any,
    rate_dps: Any,
    reference_deg: Any = None,
    temperature_c: Any = None,
    *,
    nominal_rate_hz: Optional[float] = None,
    name: str = "<arrays>",
    first_line: int = 1,
    **options: Any,
) -> Dict[str, Any]:
    """``run`` on arrays, as if they were a CSV log's columns (s, deg/s, deg, °C).

    NaN marks a missing value, as an empty CSV field. ``nominal_rate_hz`` is what a CSV's
    ``# sample_rate_hz:`` line says; ``sample_rate_hz`` (an option) what
    ``--sample-rate-hz`` says. ``name`` stands for the file name in the result and errors,
    where sample ``i`` is line ``first_line + i``. float64 contiguous arrays are read in place.
    """
    text, series = _gyro.run_arrays(
        _f64("time_s", time_s),
        _f64("rate_dps", rate_dps),
        _f64("reference_deg", reference_deg),
        _f64("temperature_c", temperature_c),
        nominal_rate_hz,
        name,
        first_line,
        options,
    )
    return _report(text, series)


class Pipeline:
    """The pipeline fed block by block with samples on a regular grid at ``sample_rate_hz``.

    Each sample is one grid slot, as on the wrench (no gap filling). ``push`` returns the
    outputs the block completed and the movement events; ``finish`` the run's report. On
    samples with regular stamps, the outputs and movements equal
    ``run_arrays(..., sample_rate_hz=sample_rate_hz)``'s. Causal only: ``offline`` and
    ``reference_delay_s`` are refused.
    """

    def __init__(self, sample_rate_hz: float, **options: Any) -> None:
        self._stream = _gyro._Stream(float(sample_rate_hz), options)

    def push(
        self,
        time_s: Any,
        rate_dps: Any,
        reference_deg: Any = None,
        temperature_c: Any = None,
    ) -> Dict[str, Any]:
        """Push a block of samples.

        Returns ``{"series": {...arrays...}, "started_s": [...], "ended": [...]}``: the
        outputs this block completed, the start times (s) of movements that began, and
        the movements that ended (dicts as in ``run``'s ``"movements"``).
        """
        series, started_s, ended = self._stream.push(
            _f64("time_s", time_s),
            _f64("rate_dps", rate_dps),
            _f64("reference_deg", reference_deg),
            _f64("temperature_c", temperature_c),
        )
        return {"series": series, "started_s": list(started_s), "ended": json.loads(ended)}

    def finish(self, name: str = "<stream>") -> Dict[str, Any]:
        """The report of everything pushed, as ``run`` gives it (without ``"series"``)."""
        return _report(self._stream.finish(name), None)


def noise(paths: Any, **options: Any) -> Dict[str, Any]:
    """``gyro-cli noise LOG... --format json`` (Allan deviation, fitted noise terms, PSD).

    ``paths``: one log or several (pooled when they share a sample rate). Options are the
    command's flags that do not write files: ``static_only``, ``margin_s``, ``min_rest_s``,
    ``model``, ``tau_grid``, ``per_decade``, ``confidence``, ``psd_segment``,
    ``sample_rate_hz``, ``max_gap_s`` and the time and rate input options.
    """
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    return json.loads(_gyro.noise_files([os.fspath(p) for p in paths], options))


def calibrate(logs: Any, **options: Any) -> Dict[str, Any]:
    """``gyro-cli calibrate LOG... --format json`` as Python objects, plus ``"model"``: the
    model file it fits (a dict), written to ``out`` when given (as ``-o`` writes it).

    Options: ``holdout`` (paths), ``objective`` (``"mean-max-abs"``, ``"movement-rms"``, ...),
    ``model``, ``tau_s``, ``fit_motion``, ``reference_delay_s``, ``leave_one_out`` (True),
    ``out``, the grid and the input options.
    """
    if isinstance(logs, (str, os.PathLike)):
        logs = [logs]
    if "holdout" in options and options["holdout"] is not None:
        options["holdout"] = [os.fspath(p) for p in options["holdout"]]
    text, model = _gyro.calibrate_files([os.fspath(p) for p in logs], options)
    report = json.loads(text)
    report["model"] = json.loads(model)
    return report


def _array_log(log: Any, name: str) -> tuple:
    """One log given as arrays (a mapping such as a dict or a pandas DataFrame with
    ``time_s``, ``rate_dps`` and optionally ``reference_deg``, ``temperature_c``, ``name``,
    ``nominal_rate_hz``, ``first_line``) as the native module takes it."""

    def get(key: str) -> Any:
        return log[key] if key in log else None

    for key in ("time_s", "rate_dps"):
        if key not in log:
            raise GyroError(f"a log given as arrays needs {key!r}")
    nominal = get("nominal_rate_hz")
    first_line = get("first_line")
    return (
        str(get("name") or name),
        _f64("time_s", log["time_s"]),
        _f64("rate_dps", log["rate_dps"]),
        _f64("reference_deg", get("reference_deg")),
        _f64("temperature_c", get("temperature_c")),
        None if nominal is None else float(nominal),
        1 if first_line is None else int(first_line),
    )


def _is_one_log(logs: Any) -> bool:
    """True if ``logs`` is one log given as arrays, not a sequence of them."""
    if isinstance(logs, (list, tuple)):
        return False
    try:
        return "time_s" in logs
    except TypeError:
        return False


def _array_logs(logs: Any, prefix: str) -> List[tuple]:
    if _is_one_log(logs):
        return [_array_log(logs, f"<{prefix}>")]
    return [_array_log(log, f"<{prefix} {i}>") for i, log in enumerate(logs, start=1)]


def noise_arrays(logs: Any, **options: Any) -> Dict[str, Any]:
    """``noise`` on logs given as arrays: the same JSON as ``noise`` on CSVs holding them.

    ``logs``: one log or a list of them, each a mapping (a dict, a pandas DataFrame) with
    ``time_s`` (s) and ``rate_dps`` (deg/s), and optionally ``name`` (its file name in the
    result; default ``"<arrays>"``, ``"<arrays 1>"``, ...), ``nominal_rate_hz`` (a CSV's
    ``# sample_rate_hz:`` line) and ``first_line`` (the line of the first sample in errors).
    Options as ``noise``'s, without the input options (columns, MCAP).
    """
    return json.loads(_gyro.noise_arrays(_array_logs(logs, "arrays"), options))


def calibrate_arrays(train: Any, holdout: Any = (), **options: Any) -> Dict[str, Any]:
    """``calibrate`` on runs given as arrays: the same JSON and model as ``calibrate`` on
    CSVs holding them.

    ``train``, ``holdout``: runs as ``noise_arrays`` takes logs, each with ``reference_deg``
    (and ``temperature_c`` where logged); default names ``"<train 1>"``, ``"<holdout 1>"``,
    ... Options as ``calibrate``'s, without ``holdout`` and the input options.
    """
    text, model = _gyro.calibrate_arrays(
        _array_logs(train, "train"), _array_logs(holdout, "holdout"), options
    )
    report = json.loads(text)
    report["model"] = json.loads(model)
    return report


def diagnose(train: Any, holdout: Any, **options: Any) -> Dict[str, Any]:
    """``gyro-cli diagnose --train ... --holdout ... --format json`` as Python objects.

    Where a real sensor differs from its simulation, which unmodelled effect causes it, and
    how far adding it closes the gap on the held-out runs: the JSON contract of
    ``docs/diagnose-json.md``, the same numbers as the command line's. ``train``,
    ``holdout``: log paths (each with ``reference_deg``; at least two runs each, or cut
    into windows by ``split_s``). Options: ``split_s``, ``model``, ``seed`` (1),
    ``members`` (50), ``candidate_members`` (20), ``score_every_candidate``, the grid and
    the input options. A log given twice (by any spelling) raises ``GyroError``, as on the
    command line. The files the command line can write (``-o``, ``--report``,
    ``--noise-yaml``) and ``--self-test`` are not offered.
    """
    if isinstance(train, (str, os.PathLike)):
        train = [train]
    if isinstance(holdout, (str, os.PathLike)):
        holdout = [holdout]
    return json.loads(
        _gyro.diagnose_files([os.fspath(p) for p in train], [os.fspath(p) for p in holdout], options)
    )


def diagnose_arrays(train: Any, holdout: Any, **options: Any) -> Dict[str, Any]:
    """``diagnose`` on runs given as arrays: the same JSON as ``diagnose`` on CSVs holding
    them.

    ``train``, ``holdout``: runs as ``calibrate_arrays`` takes them, each with
    ``reference_deg`` (and ``temperature_c`` where logged), cut into windows by ``split_s``
    when given; default names ``"<train 1>"``, ``"<holdout 1>"``, ... Options as
    ``diagnose``'s, without the input options (columns, MCAP).
    """
    return json.loads(
        _gyro.diagnose_arrays(_array_logs(train, "train"), _array_logs(holdout, "holdout"), options)
    )


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
    """The tightening verdict on one angle, as ``run`` gives each movement's.

    ``"ok"`` (inside the window by more than k·σ), ``"nok"`` (outside by more than k·σ),
    ``"recheck"``, ``"invalid"`` (``untrusted``: saturated, cut off, filled samples), or
    ``None`` for a turn the other way. σ includes ``scale_sigma`` times the angle.
    """
    return _gyro.decide(angle_deg, angle_std_deg, target_deg, tolerance_deg, k_sigma,
                        tightening_direction, scale_sigma, untrusted)


def concat_series(blocks: List[Dict[str, np.ndarray]]) -> Dict[str, np.ndarray]:
    """Join the ``"series"`` of successive ``Pipeline.push`` results."""
    return {k: np.concatenate([b[k] for b in blocks]) for k in SERIES_KEYS}
