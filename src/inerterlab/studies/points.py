"""Point functions: what a sweep evaluates at each point of its grid.

A point function maps a dict of parameters (the swept ones and the fixed settings) to a
dict of float metrics. It is described by a :class:`PointFunction`, which names the
parameters it accepts (with their valid values, so a sweep description can be checked
before any work starts) and the metrics it returns. The callable must be a module-level
function so that it pickles by reference and runs in worker processes and on Dask
workers.

Two point functions are registered:

``quarter-car``
    The quarter-car simulator (docs/model.md §5): builds the suspension from the parameters,
    simulates the input and returns its metrics.
``synthetic``
    A cheap closed-form stand-in with the same metric names and trends similar to the
    thesis tables (ride metrics falling with the changing ratio for ``drop`` and
    ``bump``, body acceleration rising for ``sine``). It is **not** a physical model; it
    exists so the sweep machinery (backends, storage, resume, goal programming) can be
    tested and demonstrated in milliseconds. It can append one line per evaluation to
    a log file, sleep, or fail on purpose.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..errors import ParameterError

__all__ = [
    "ParameterSpec",
    "PointFunction",
    "POINT_FUNCTIONS",
    "point_function",
    "register_point_function",
    "synthetic_point",
    "QUARTER_CAR_METRICS",
]

#: metric names returned by the quarter-car simulator (``SimulationResult.metrics()``)
QUARTER_CAR_METRICS = (
    "rms_body_acc",
    "rms_tyre_grip",
    "rms_deflection",
    "rms_body_acc_wk",
    "vdv",
    "peak_body_acc",
    "tyre_lift_off",
)


@dataclass(frozen=True, kw_only=True)
class ParameterSpec:
    """Valid values of one point-function parameter.

    Parameters
    ----------
    kind : {"float", "int", "choice", "text", "file"}
        Number, integer, one of ``choices``, free text, or the path of an input file
        the point reads (a sweep store is keyed on the file's content, not its name).
    low, high : float, optional
        Bounds of a number; ``low_open``/``high_open`` exclude them.
    choices : tuple of str
        Valid values of a ``choice`` parameter.
    unit : str
        SI unit, shown in error messages and help texts.
    doc : str
        One-line description.
    """

    kind: str = "float"
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple[str, ...] = ()
    unit: str = ""
    doc: str = ""
    #: a ``file`` parameter's file when its value is "" (a module-level function)
    empty: Callable[[], Any] | None = None

    def path_of(self, value: str):
        """The file a ``file`` parameter's value names ("" -> :attr:`empty`)."""
        return self.empty() if value == "" and self.empty is not None else value

    def describe(self) -> str:
        """Human-readable description of the valid values."""
        if self.kind == "choice":
            return "one of " + ", ".join(repr(c) for c in self.choices)
        if self.kind == "text":
            return "a text value"
        if self.kind == "file":
            return "a file path (text)"
        what = "an integer" if self.kind == "int" else "a number"
        lo = "-inf" if self.low is None else f"{self.low:g}"
        hi = "inf" if self.high is None else f"{self.high:g}"
        lb = "(" if (self.low_open or self.low is None) else "["
        hb = ")" if (self.high_open or self.high is None) else "]"
        unit = f" {self.unit}" if self.unit else ""
        return f"{what} in {lb}{lo}, {hi}{hb}{unit}"

    def check(self, key: str, value: Any) -> Any:
        """Return ``value`` normalised (float/int/str) or raise ParameterError naming ``key``."""
        valid = self.describe()
        if self.kind == "choice":
            if not isinstance(value, str) or value not in self.choices:
                raise ParameterError(key, value, valid)
            return value
        if self.kind in ("text", "file"):
            if not isinstance(value, str):
                raise ParameterError(key, value, valid)
            return value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ParameterError(key, value, valid)
        if self.kind == "int":
            if float(value) != int(value):
                raise ParameterError(key, value, valid)
            value = int(value)
        else:
            value = float(value)
        if not math.isfinite(value):
            raise ParameterError(key, value, valid)
        if self.low is not None and (value < self.low or (self.low_open and value == self.low)):
            raise ParameterError(key, value, valid)
        if self.high is not None and (value > self.high or (self.high_open and value == self.high)):
            raise ParameterError(key, value, valid)
        return value


@dataclass(frozen=True, kw_only=True)
class PointFunction:
    """A picklable point function with its parameter schema.

    Parameters
    ----------
    name : str
        Registry name, written into the sweep store.
    function : callable
        Module-level ``function(params: dict) -> dict[str, float]``. It raises to mark
        a point as failed; the exception text becomes the point's failure reason.
    parameters : mapping
        Parameter name -> :class:`ParameterSpec`. Any other name is rejected.
    defaults : mapping
        Values used for parameters neither swept nor fixed.
    metrics : tuple of str
        Names of the metrics the function returns (one dataset variable each).
    """

    name: str
    function: Callable[[dict], Mapping[str, float]]
    parameters: Mapping[str, ParameterSpec]
    defaults: Mapping[str, Any] = field(default_factory=dict)
    metrics: tuple[str, ...] = QUARTER_CAR_METRICS
    #: what the function reads besides its parameters (network texts, device data, ...),
    #: as JSON-ready data: part of a sweep store's key, so a change is never resumed
    inputs: Callable[[], Any] | None = None

    def __hash__(self) -> int:  # mappings are not hashable; the name identifies it
        return hash(self.name)

    def check_parameter(self, key: str, name: str, value: Any) -> Any:
        """Validate one value of parameter ``name``; ``key`` is the path shown in errors."""
        spec = self.parameters.get(name)
        if spec is None:
            raise ParameterError(
                key,
                name,
                f"a parameter of point function {self.name!r}: " + ", ".join(self.parameters),
            )
        value = spec.check(key, value)
        if name == "log_file" and value and os.environ.get(LOG_FILE_ENV) != "1":
            # a sweep file must not be able to create or append to files of the user's
            raise ParameterError(
                key,
                value,
                f"no value: the evaluation log of the synthetic point is a testing aid, "
                f"enabled only when the environment sets {LOG_FILE_ENV}=1",
            )
        return value


#: environment variable that enables the synthetic point's ``log_file`` (tests only)
LOG_FILE_ENV = "INERTERLAB_ALLOW_POINT_LOG"


# --- the synthetic point function ---------------------------------------------------

_SYNTHETIC_BASE = {  # (acceleration [m/s^2], grip index [-], deflection [m]) at x = 0
    "drop": (0.43, 0.28, 0.0035),
    "bump": (0.44, 0.32, 0.0031),
    "sine": (1.63, 0.73, 0.0091),
}


def synthetic_point(params: Mapping[str, Any]) -> dict[str, float]:
    """Closed-form stand-in for the quarter car (not physics; see the module docstring).

    With r the changing ratio (0 for the ``traditional`` suspension) and
    s = sprung_mass / 370 kg:
    acceleration = a0 (1 - 1.2 r + 0.6 r^2) / sqrt(s) for drop and bump,
    a0 (1 + 1.5 r - 0.4 r^2) / sqrt(s) for sine; grip = g0 exp(-2.5 r) / s;
    deflection = d0 (1 + 0.05 r) / s. Every value is smooth in r and in s.
    """
    if params.get("log_file"):
        record = {k: params[k] for k in sorted(params) if k != "log_file"}
        line = json.dumps(record, sort_keys=True) + "\n"
        fd = os.open(params["log_file"], os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, line.encode())
        finally:
            os.close(fd)
    delay = float(params.get("delay", 0.0))
    if delay > 0:
        time.sleep(delay)
    r = 0.0 if params.get("suspension") == "traditional" else float(params["changing_ratio"])
    if r > float(params.get("fail_above_ratio", 1.0)):
        raise RuntimeError(f"synthetic failure requested above changing_ratio {r:g}")
    s = float(params["sprung_mass"]) / 370.0
    a0, g0, d0 = _SYNTHETIC_BASE[params["input"]]
    if params["input"] == "sine":
        acc = a0 * (1.0 + 1.5 * r - 0.4 * r * r) / math.sqrt(s)
    else:
        acc = a0 * (1.0 - 1.2 * r + 0.6 * r * r) / math.sqrt(s)
    grip = g0 * math.exp(-2.5 * r) / s
    defl = d0 * (1.0 + 0.05 * r) / s
    return {
        "rms_body_acc": acc,
        "rms_tyre_grip": grip,
        "rms_deflection": defl,
        "rms_body_acc_wk": 0.8 * acc,
        "vdv": 1.2 * acc,
        "peak_body_acc": 3.0 * acc,
        "tyre_lift_off": 0.0,
    }


_COMMON = {
    "sprung_mass": ParameterSpec(low=0.0, low_open=True, unit="kg", doc="body mass M_v"),
    "changing_ratio": ParameterSpec(
        low=0.0, high=1.0, low_open=True, high_open=True, doc="changing ratio x of the flywheel"
    ),
    "input": ParameterSpec(kind="choice", choices=("drop", "bump", "sine"), doc="road input"),
    "suspension": ParameterSpec(
        kind="choice",
        choices=("traditional", "cfw", "afw", "device", "device-afw"),
        doc="suspension layout",
    ),
}

SYNTHETIC = PointFunction(
    name="synthetic",
    function=synthetic_point,
    parameters={
        **_COMMON,
        "log_file": ParameterSpec(kind="text", doc="append one JSON line per evaluation"),
        "delay": ParameterSpec(low=0.0, high=60.0, unit="s", doc="sleep per point"),
        "fail_above_ratio": ParameterSpec(
            low=0.0, high=1.0, doc="fail on purpose above this changing ratio"
        ),
    },
    defaults={
        "sprung_mass": 370.0,
        "changing_ratio": 0.285,
        "input": "drop",
        "suspension": "afw",
        "log_file": "",
        "delay": 0.0,
        "fail_above_ratio": 1.0,
    },
)

POINT_FUNCTIONS: dict[str, PointFunction] = {"synthetic": SYNTHETIC}


def register_point_function(pf: PointFunction) -> PointFunction:
    """Add ``pf`` to the registry under ``pf.name`` (replacing any previous entry)."""
    POINT_FUNCTIONS[pf.name] = pf
    return pf


#: point functions defined in modules that register them when imported (loaded on
#: first use, so the sweep machinery never imports the models it runs)
LAZY_POINT_MODULES = {
    "quarter-car": "inerterlab.studies.quarter_car",
    "half-car-road": "inerterlab.vehicles.stochastic",
    "full-car-road": "inerterlab.vehicles.stochastic",
    "vehicle-spectral": "inerterlab.vehicles.design",
    "network-truth": "inerterlab.network_truth",
}


def point_function(name: str) -> PointFunction:
    """The registered point function ``name``, or a ParameterError listing the valid ones."""
    if name in LAZY_POINT_MODULES and name not in POINT_FUNCTIONS:
        import importlib

        importlib.import_module(LAZY_POINT_MODULES[name])  # registers itself on import
    if name not in POINT_FUNCTIONS:
        raise ParameterError("point", name, "one of " + ", ".join(repr(n) for n in _known()))
    return POINT_FUNCTIONS[name]


def _known() -> list[str]:
    names = list(POINT_FUNCTIONS)
    names += [n for n in LAZY_POINT_MODULES if n not in names]
    return names
