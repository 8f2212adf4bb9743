"""Error types shared by the whole package.

Every error a user can cause is an :class:`InerterlabError`. Its message names the
parameter (or file and line), the value that was given and the valid range, so the
command line can print it on one line and exit with status 2.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = [
    "InerterlabError",
    "ParameterError",
    "DataFileError",
    "ConvergenceError",
    "NetworkError",
    "Interrupted",
    "LockedError",
    "check_positive",
    "check_nonnegative",
    "check_finite",
    "check_in_range",
    "check_choice",
]


class InerterlabError(Exception):
    """Base class of every error the package raises on purpose."""


class ParameterError(InerterlabError, ValueError):
    """A parameter is outside its valid range or of the wrong type.

    Attributes
    ----------
    name : str
        Name of the parameter as the user wrote it.
    value : object
        The rejected value.
    valid : str
        Human-readable description of the valid range.
    """

    def __init__(self, name: str, value: Any, valid: str):
        self.name = name
        self.value = value
        self.valid = valid
        super().__init__(f"invalid {name}={value!r}: expected {valid}")


class DataFileError(InerterlabError, ValueError):
    """A data or configuration file cannot be used; names the file and line."""

    def __init__(self, path: Any, message: str, line: int | None = None):
        self.path = str(path)
        self.line = line
        where = f"{self.path}, line {line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")


class NetworkError(InerterlabError, ValueError):
    """A network text, or the parameters given for it, cannot be used."""


class ConvergenceError(InerterlabError, RuntimeError):
    """A numerical method did not converge; the message says which and why."""


class Interrupted(InerterlabError):
    """The user interrupted a long run; the message says what was kept."""


class LockedError(InerterlabError):
    """Another run is writing the same output; the message names it and what to do."""


def _as_float(name: str, value: Any, valid: str) -> float:
    # text is not a number here, even "1": a value read from a file or typed on the
    # command line is converted where it is read, naming the file, line or option
    if isinstance(value, bool | str | bytes):
        raise ParameterError(name, value, valid)
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, valid) from None
    if not math.isfinite(x):
        raise ParameterError(name, value, valid)
    return x


def check_finite(name: str, value: Any) -> float:
    """Return ``value`` as a finite float or raise :class:`ParameterError`."""
    return _as_float(name, value, "a finite number")


def check_positive(name: str, value: Any, unit: str = "") -> float:
    """Return ``value`` as a float > 0 or raise :class:`ParameterError`."""
    valid = f"a finite number > 0{(' ' + unit) if unit else ''}"
    x = _as_float(name, value, valid)
    if x <= 0:
        raise ParameterError(name, value, valid)
    return x


def check_nonnegative(name: str, value: Any, unit: str = "") -> float:
    """Return ``value`` as a float >= 0 or raise :class:`ParameterError`."""
    valid = f"a finite number >= 0{(' ' + unit) if unit else ''}"
    x = _as_float(name, value, valid)
    if x < 0:
        raise ParameterError(name, value, valid)
    return x


def check_in_range(
    name: str,
    value: Any,
    low: float,
    high: float,
    *,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
) -> float:
    """Return ``value`` as a float inside the given interval or raise."""
    lb = "(" if low_open else "["
    hb = ")" if high_open else "]"
    valid = f"a number in {lb}{low:g}, {high:g}{hb}{(' ' + unit) if unit else ''}"
    x = _as_float(name, value, valid)
    if (x < low or (low_open and x == low)) or (x > high or (high_open and x == high)):
        raise ParameterError(name, value, valid)
    return x


def check_choice(name: str, value: Any, choices: tuple[str, ...] | list[str]) -> str:
    """Return ``value`` if it is one of ``choices`` or raise :class:`ParameterError`."""
    if value not in choices:
        raise ParameterError(name, value, "one of " + ", ".join(repr(c) for c in choices))
    return value
