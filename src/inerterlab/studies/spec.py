"""Sweep descriptions: which parameters vary, over which values, and what stays fixed.

A :class:`SweepSpec` is built in Python with :func:`sweep_spec` or read from a TOML file
with :func:`load_sweep_config`. Everything is validated when the description is built,
before any point is computed: unknown parameters, empty ranges, values outside their
valid range and inconsistent weights are reported with the key (and, for files, the
line) and the valid values.

TOML layout::

    point = "quarter-car"       # point function (default "quarter-car")
    chunk_size = 64             # optional: points per task and per store chunk

    [parameters]                # swept: one dimension each, in this order
    changing_ratio = {start = 0.05, stop = 0.55, step = 0.05}   # stop included
    input = ["drop", "bump", "sine"]
    sprung_mass = {start = 340.0, stop = 400.0, num = 7}

    [settings]                  # fixed for every point
    suspension = "afw"
    horizon = 10.0

    [weights]                   # optional: weights of the performance function (4.30)-(4.33)
    comfort = 0.35
    grip = 0.65
    inputs = {drop = 0.1, bump = 0.5, sine = 0.4}
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DataFileError, ParameterError
from ..resources import check_memory
from .points import PointFunction, point_function

__all__ = ["SweepSpec", "sweep_spec", "load_sweep_config", "PerformanceWeights", "expand_range"]

_WEIGHT_TOL = 1e-9


@dataclass(frozen=True, kw_only=True)
class PerformanceWeights:
    """Weights of the performance function (4.30)-(4.33).

    Parameters
    ----------
    comfort : float
        x1, weight of ride comfort (body acceleration), in [0, 1].
    grip : float
        x2, weight of tyre grip, in [0, 1]; comfort + grip = 1.
    inputs : tuple of (str, float)
        Input name -> weight (x3, x4, x5 for drop, bump, sine), each in [0, 1],
        summing to 1.

    Examples
    --------
    >>> w = PerformanceWeights()
    >>> w.comfort, w.grip, dict(w.inputs)
    (0.35, 0.65, {'drop': 0.1, 'bump': 0.5, 'sine': 0.4})
    """

    comfort: float = 0.35
    grip: float = 0.65
    inputs: tuple[tuple[str, float], ...] = (("drop", 0.1), ("bump", 0.5), ("sine", 0.4))

    def __post_init__(self) -> None:
        check_weight("weights.comfort", self.comfort)
        check_weight("weights.grip", self.grip)
        if abs(self.comfort + self.grip - 1.0) > _WEIGHT_TOL:
            raise ParameterError(
                "weights.comfort+weights.grip",
                self.comfort + self.grip,
                "weights in [0, 1] summing to 1 (x1 + x2 = 1, (4.30))",
            )
        inputs = dict(self.inputs) if not isinstance(self.inputs, dict) else self.inputs
        if not inputs:
            raise ParameterError("weights.inputs", self.inputs, "at least one input weight")
        for name, w in inputs.items():
            if name not in ("drop", "bump", "sine"):
                raise ParameterError(
                    f"weights.inputs.{name}", w, "weights for 'drop', 'bump', 'sine'"
                )
            check_weight(f"weights.inputs.{name}", w)
        total = sum(float(w) for w in inputs.values())
        if abs(total - 1.0) > _WEIGHT_TOL:
            raise ParameterError(
                "weights.inputs",
                dict(inputs),
                "input weights in [0, 1] summing to 1 (x3 + x4 + x5 = 1, (4.33)); "
                f"they sum to {total:g}",
            )
        object.__setattr__(self, "inputs", tuple((str(k), float(v)) for k, v in inputs.items()))
        object.__setattr__(self, "comfort", float(self.comfort))
        object.__setattr__(self, "grip", float(self.grip))

    def to_dict(self) -> dict:
        """Plain-dict form (JSON-ready)."""
        return {"comfort": self.comfort, "grip": self.grip, "inputs": dict(self.inputs)}


def check_weight(key: str, value: Any) -> float:
    """A weight in [0, 1] or a ParameterError naming ``key``."""
    valid = "a weight in [0, 1]"
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(key, value, valid)
    x = float(value)
    if not math.isfinite(x) or x < 0.0 or x > 1.0:
        raise ParameterError(key, value, valid)
    return x


def expand_range(key: str, value: Any) -> tuple:
    """Values of one swept parameter from a list, a scalar or a range table.

    A range is ``{start, stop, step}`` (stop included when it falls on the grid, within
    1e-9 of a step) or ``{start, stop, num}`` (``num`` evenly spaced values, ends
    included). Raises ParameterError naming ``key`` for an empty or malformed range.
    """
    if isinstance(value, dict):
        keys = set(value)
        forms = "{start, stop, step} or {start, stop, num}"
        if keys not in ({"start", "stop", "step"}, {"start", "stop", "num"}):
            raise ParameterError(key, value, f"a list or a range table {forms}")
        for k in keys:
            v = value[k]
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ParameterError(f"{key}.{k}", v, "a finite number")
        start, stop = float(value["start"]), float(value["stop"])
        if "num" in value:
            num = value["num"]
            if not isinstance(num, int) or num < 1:
                raise ParameterError(f"{key}.num", num, "an integer >= 1 (empty range)")
            if num > 1 and stop < start:
                raise ParameterError(key, value, "a range with stop >= start (empty range)")
            # swept values are kept as Python floats in tuples (about 64 bytes each)
            check_memory(
                num, what="list of swept values", parameter=f"{key}.num", bytes_per_value=64
            )
            out = np.linspace(start, stop, num)
        else:
            step = float(value["step"])
            if step <= 0:
                raise ParameterError(f"{key}.step", value["step"], "a step > 0")
            if stop < start:
                raise ParameterError(key, value, "a range with stop >= start (empty range)")
            count = math.floor((stop - start) / step + 1e-9) + 1
            check_memory(
                count, what="list of swept values", parameter=f"{key}.step", bytes_per_value=64
            )
            n = int(count)
            out = start + step * np.arange(n)
        return tuple(round(float(v), 12) for v in out)
    if isinstance(value, list | tuple):
        if len(value) == 0:
            raise ParameterError(key, value, "a non-empty list of values (empty range)")
        if len(set(map(repr, value))) != len(value):
            raise ParameterError(key, value, "a list without repeated values")
        return tuple(value)
    return (value,)


@dataclass(frozen=True, kw_only=True)
class SweepSpec:
    """A validated sweep: the point function, the swept values and the fixed settings.

    Build it with :func:`sweep_spec` or :func:`load_sweep_config`.

    Attributes
    ----------
    point : str
        Registered point function name.
    parameters : tuple of (str, tuple)
        Swept parameters in dimension order, each with its values.
    settings : tuple of (str, value)
        Fixed parameters.
    weights : PerformanceWeights or None
        Optional performance-function weights stored with the result.
    chunk_size : int or None
        Points per task and per store chunk (None: chosen from the size of the sweep).
    """

    point: str
    parameters: tuple[tuple[str, tuple], ...]
    settings: tuple[tuple[str, Any], ...] = ()
    weights: PerformanceWeights | None = None
    chunk_size: int | None = None
    source: str = field(default="", compare=False)
    #: content digests of every input the points read: ``(key, "sha256:...")``
    inputs: tuple[tuple[str, str], ...] = ()

    @property
    def point_function(self) -> PointFunction:
        return point_function(self.point)

    @property
    def dims(self) -> tuple[str, ...]:
        return tuple(name for name, _ in self.parameters)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for _, v in self.parameters)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64)) if self.parameters else 1

    def fixed(self) -> dict:
        """Defaults of the point function overridden by the fixed settings."""
        out = dict(self.point_function.defaults)
        out.update(dict(self.settings))
        return out

    def params_at(self, index: int) -> dict:
        """Parameters of flat point ``index`` (C order over :attr:`dims`)."""
        out = self.fixed()
        for (name, values), i in zip(
            self.parameters, np.unravel_index(index, self.shape), strict=True
        ):
            out[name] = values[int(i)]
        return out

    def to_dict(self) -> dict:
        """JSON-ready description; the basis of :meth:`config_hash`."""
        out = {
            "point": self.point,
            "parameters": {k: list(v) for k, v in self.parameters},
            "settings": dict(self.settings),
            "weights": None if self.weights is None else self.weights.to_dict(),
        }
        if self.inputs:
            out["inputs"] = dict(self.inputs)
        return out

    def input_files(self) -> tuple[tuple[str, str, str], ...]:
        """``(key, path, digest)`` of every input file (``file`` parameters)."""
        pf = self.point_function
        digests = dict(self.inputs)
        out = []
        for key, name, value in _file_values(pf, self.parameters, self.settings):
            path = str(pf.parameters[name].path_of(value))
            out.append((key, path, digests.get(key, "")))
        return tuple(out)

    def config_hash(self) -> str:
        """SHA-256 of the canonical JSON description (chunk size and source excluded).

        A ``file`` parameter enters by the content of its file (:attr:`inputs`), not by
        its path: the same file moved or copied elsewhere is the same input, an edited
        file another one."""
        d = self.to_dict()
        pf = self.point_function
        for name in list(d["settings"]):
            spec = pf.parameters.get(name)
            if spec is not None and spec.kind == "file":
                d["settings"][name] = "(file: see inputs)"
        for name in list(d["parameters"]):
            if pf.parameters[name].kind == "file":
                d["parameters"][name] = [
                    f"(file {i}: see inputs)" for i in range(len(d["parameters"][name]))
                ]
        text = json.dumps(d, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()


def _file_values(pf, swept, fixed):
    """``(key, name, value)`` of every value of a ``file`` parameter, swept or fixed."""
    out = []
    for name, values in swept:
        if pf.parameters[name].kind == "file":
            out += [(f"{name}[{i}]", name, v) for i, v in enumerate(values)]
    names = {n for n, _ in swept}
    merged = dict(pf.defaults)
    merged.update(dict(fixed))
    for name, value in merged.items():
        spec = pf.parameters.get(name)
        if spec is not None and spec.kind == "file" and name not in names:
            out.append((name, name, value))
    return out


def file_digest(path, what: str = "input file") -> str:
    """``"sha256:<hex>"`` of a file's bytes (read size- and time-capped)."""
    from ..io import read_bytes_limited

    return "sha256:" + hashlib.sha256(read_bytes_limited(path, what)).hexdigest()


def _input_digests(pf, swept, fixed) -> tuple[tuple[str, str], ...]:
    out = []
    for key, name, value in _file_values(pf, swept, fixed):
        spec = pf.parameters[name]
        out.append((key, file_digest(spec.path_of(value), f"{name} file")))
    if pf.inputs is not None:
        text = json.dumps(pf.inputs(), sort_keys=True, separators=(",", ":"))
        out.append(("point", "sha256:" + hashlib.sha256(text.encode()).hexdigest()))
    return tuple(out)


def sweep_spec(
    point: str = "quarter-car",
    *,
    parameters: dict[str, Any],
    settings: dict[str, Any] | None = None,
    weights: PerformanceWeights | dict | None = None,
    chunk_size: int | None = None,
    inputs: dict[str, str] | None = None,
    _lines: dict[str, int] | None = None,
    _path: str | None = None,
) -> SweepSpec:
    """Build and validate a :class:`SweepSpec`.

    Parameters
    ----------
    point : str
        Point function name (``"quarter-car"`` or ``"synthetic"``).
    parameters : dict
        Swept parameter -> list of values, scalar, or range table (see
        :func:`expand_range`). Dimension order follows the dict order.
    settings : dict, optional
        Fixed parameters.
    weights : PerformanceWeights or dict, optional
        ``{"comfort": .., "grip": .., "inputs": {"drop": .., ...}}``.
    chunk_size : int, optional
        Points per task (>= 1).
    inputs : dict, optional
        Content digests of the inputs (as a store records them); by default read now
        from every ``file`` parameter's file and the point function's other inputs.

    Examples
    --------
    >>> s = sweep_spec("synthetic", parameters={"changing_ratio": {"start": 0.1, "stop": 0.3, "step": 0.1}})
    >>> s.dims, s.shape
    (('changing_ratio',), (3,))
    """
    settings = dict(settings or {})

    def fail(key: str, exc: ParameterError):
        if _path is not None:
            parts = key.split(".")
            line = None
            while parts and line is None:
                line = (_lines or {}).get(".".join(parts))
                parts.pop()
            raise DataFileError(_path, f"{exc}", line) from None
        raise exc

    try:
        if not isinstance(point, str):
            raise ParameterError("point", point, "the name of a point function (a string)")
        pf = point_function(point)
    except ParameterError as exc:
        fail("point", exc)
    if not parameters:
        fail("parameters", ParameterError("parameters", {}, "at least one swept parameter"))
    swept = []
    for name, raw in parameters.items():
        key = f"parameters.{name}"
        try:
            if name not in pf.parameters:
                pf.check_parameter(key, name, None)
            values = expand_range(key, raw)
            values = tuple(
                pf.check_parameter(f"{key}[{i}]" if len(values) > 1 else key, name, v)
                for i, v in enumerate(values)
            )
        except ParameterError as exc:
            fail(key, exc)
        swept.append((name, values))
    fixed = []
    for name, value in settings.items():
        key = f"settings.{name}"
        try:
            if name in parameters:
                raise ParameterError(key, value, "a parameter that is not also swept")
            fixed.append((name, pf.check_parameter(key, name, value)))
        except ParameterError as exc:
            fail(key, exc)
    if isinstance(weights, dict):
        try:
            unknown = set(weights) - {"comfort", "grip", "inputs"}
            if unknown:
                k = sorted(unknown)[0]
                raise ParameterError(f"weights.{k}", weights[k], "keys comfort, grip, inputs")
            inputs = weights.get("inputs", dict(PerformanceWeights().inputs))
            if not isinstance(inputs, dict):
                raise ParameterError("weights.inputs", inputs, "a table {drop, bump, sine}")
            weights = PerformanceWeights(
                comfort=weights.get("comfort", 0.35),
                grip=weights.get("grip", 0.65),
                inputs=tuple(inputs.items()),
            )
        except ParameterError as exc:
            fail(exc.name.split("+")[0] if "+" in exc.name else exc.name, exc)
    if chunk_size is not None and (
        isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1
    ):
        fail("chunk_size", ParameterError("chunk_size", chunk_size, "an integer >= 1"))
    if chunk_size is not None:
        try:  # one chunk of every variable is held in memory at once
            check_memory(
                float(chunk_size) * (len(pf.metrics) + 2),
                what="store chunk",
                parameter="chunk_size",
            )
        except ParameterError as exc:
            fail("chunk_size", exc)
    n_points = 1
    for _, values in swept:
        n_points *= len(values)
    try:
        # every point keeps one float per metric plus a status; refuse grids that cannot fit
        check_memory(
            float(n_points) * (len(pf.metrics) + 2),
            what="sweep result grid",
            parameter="parameters",
        )
    except ParameterError as exc:
        fail("parameters", exc)
    if inputs is None:
        digests = _input_digests(pf, swept, fixed)
    else:
        digests = tuple((str(k), str(v)) for k, v in dict(inputs).items())
    return SweepSpec(
        point=point,
        parameters=tuple(swept),
        settings=tuple(fixed),
        weights=weights,
        chunk_size=chunk_size,
        source=_path or "",
        inputs=digests,
    )


def _key_lines(text: str) -> dict[str, int]:
    """Map dotted keys (``parameters.changing_ratio``) to their 1-based line numbers."""
    out: dict[str, int] = {}
    section = ""
    for n, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        m = re.match(r"^\[\s*([A-Za-z0-9_.\-]+)\s*\]", s)
        if m:
            section = m.group(1)
            out.setdefault(section, n)
            continue
        m = re.match(r'^"?([A-Za-z0-9_\-]+)"?\s*=', s)
        if m:
            key = f"{section}.{m.group(1)}" if section else m.group(1)
            out.setdefault(key, n)
    return out


def load_sweep_config(path: str | Path) -> SweepSpec:
    """Read and validate a sweep TOML file (layout in the module docstring).

    Raises
    ------
    DataFileError
        With the file, the line and the valid values for any problem.
    """
    from ..io import read_toml

    p = Path(path)
    text, data = read_toml(p, "sweep file")
    lines = _key_lines(text)
    allowed = {"point", "chunk_size", "parameters", "settings", "weights"}
    for key in data:
        if key not in allowed:
            raise DataFileError(
                p,
                f"unknown key {key!r}: expected one of " + ", ".join(sorted(allowed)),
                lines.get(key),
            )
    for key in ("parameters", "settings", "weights"):
        if key in data and not isinstance(data[key], dict):
            raise DataFileError(p, f"{key!r} must be a table [{key}]", lines.get(key))
    if "parameters" not in data:
        raise DataFileError(p, "missing table [parameters] (the swept parameters)")
    point = data.get("point", "quarter-car")
    try:
        return sweep_spec(
            point,
            parameters=data["parameters"],
            settings=data.get("settings"),
            weights=data.get("weights"),
            chunk_size=data.get("chunk_size"),
            _lines=lines,
            _path=str(p),
        )
    except (TypeError, ValueError, RecursionError) as exc:
        if isinstance(exc, DataFileError):
            raise
        # a value of a type no check expected (a list or table where a number or a
        # name belongs, a structure nested too deeply): name the file, never crash
        raise DataFileError(
            p, f"a value has the wrong type or shape ({type(exc).__name__}: {exc})"
        ) from None
