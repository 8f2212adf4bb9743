"""Error types shared by the whole package.

Every error a user can cause is an :class:`InerterlabError`. Its message names the
parameter (or file and line), the value that was given and the valid range, so the
command line can print it on one line and exit with status 2.
"""

from __future__ import annotations

import math
import numbers
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
    "check_seed",
    "check_unique",
    "check_physical",
    "PHYSICAL_RANGES",
    "SEED_MAX",
    "one_line",
    "shorten",
]

#: longest message the package prints for one error [characters]
MESSAGE_LIMIT = 400

#: longest rendering of one user value inside a message [characters]
VALUE_LIMIT = 80


def shorten(text: str, limit: int = VALUE_LIMIT) -> str:
    """``text`` cut to at most ``limit`` characters by an ellipsis in the middle.

    The start says what the text is and the end usually says what is expected, so
    both are kept.

    >>> shorten("a" * 10 + "b" * 10, 9)
    'aaaa…bbbb'
    """
    text = str(text)
    if len(text) <= limit:
        return text
    head = (limit - 1) // 2
    tail = limit - 1 - head
    return text[:head] + "…" + (text[-tail:] if tail else "")


def one_line(text: str, limit: int = MESSAGE_LIMIT) -> str:
    """A message on one line of at most ``limit`` characters.

    Line breaks and runs of white space (a foreign library's multi-line message) are
    folded into single spaces, then the text is shortened in the middle.

    >>> one_line("first line" + chr(10) + "   second line")
    'first line second line'
    """
    return shorten(" ".join(str(text).split()), limit)


class InerterlabError(Exception):
    """Base class of every error the package raises on purpose.

    Its text is always one line of at most :data:`MESSAGE_LIMIT` characters.
    """

    def __str__(self) -> str:
        return one_line(super().__str__())


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
        super().__init__(f"invalid {name}={shorten(repr(value))}: expected {valid}")


class DataFileError(InerterlabError, ValueError):
    """A data or configuration file cannot be used; names the file and line."""

    def __init__(self, path: Any, message: str, line: int | None = None):
        self.path = str(path)
        self.line = line
        shown = shorten(self.path, 160)
        where = f"{shown}, line {line}" if line is not None else shown
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


#: largest seed accepted: every random generator of the package takes 0 ... 2**32 - 1
SEED_MAX = 2**32 - 1


def check_seed(name: str, value: Any, count: int = 1) -> int:
    """Return ``value`` as a seed (an integer 0 ... 2**32 - 1) or raise.

    ``count`` seeds starting at ``value`` are used (``value + count - 1`` must fit too).
    """
    top = SEED_MAX - (int(count) - 1)
    valid = f"an integer in [0, {top}]"
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ParameterError(name, value, valid)
    if not 0 <= int(value) <= top:
        raise ParameterError(name, value, valid)
    return int(value)


def check_unique(name: str, names: Any) -> None:
    """Raise if a name occurs twice in ``names`` (the same key given twice)."""
    seen: set = set()
    for n in names:
        if n in seen:
            raise ParameterError(name, n, "each name at most once (it was given twice)")
        seen.add(n)


#: the physical range of a value of each kind of quantity [SI units]: a value outside
#: (but not zero, where zero is allowed) is refused, so that tiny and huge numbers such
#: as 1e-320 kg or 1e300 N/m never reach the linear algebra
PHYSICAL_RANGES: dict[str, tuple[float, float, str]] = {
    "mass": (1e-6, 1e7, "kg"),
    "inertance": (1e-6, 1e7, "kg"),
    "inertia": (1e-9, 1e8, "kg m^2"),
    "length": (1e-6, 1e5, "m"),
    "stiffness": (1e-3, 1e12, "N/m"),
    "damping": (1e-3, 1e10, "N s/m"),
    "acceleration": (1e-3, 1e3, "m/s^2"),
    "force": (1e-6, 1e9, "N"),
    "velocity": (1e-9, 1e3, "m/s"),
    "area": (1e-12, 1e3, "m^2"),
    "density": (1e-3, 1e5, "kg/m^3"),
    "transmission ratio": (1e-3, 1e7, "rad/m"),
    "rotary damping": (1e-12, 1e6, "N m s/rad"),
    "quadratic damping": (1e-3, 1e10, "N s^2/m^2"),
    "pressure": (1e-3, 1e10, "Pa"),
    "volume": (1e-15, 1e3, "m^3"),
    "viscosity": (1e-6, 1e4, "N s/m^2"),
}


def check_physical(name: str, value: Any, quantity: str, *, zero: bool = False) -> float:
    """Return ``value`` if its magnitude is in the physical range of ``quantity``.

    ``zero=True`` also accepts exactly 0 (a damping or an anti-roll bar left out).
    The sign is checked by the caller (coordinates may be negative).
    """
    lo, hi, unit = PHYSICAL_RANGES[quantity]
    article = "an" if quantity[0] in "aeiou" else "a"
    valid = f"{article} {quantity} of magnitude {lo:g} to {hi:g} {unit}" + (" or 0" if zero else "")
    x = _as_float(name, value, valid)
    if x == 0.0 and zero:
        return x
    if not lo <= abs(x) <= hi:
        raise ParameterError(name, value, valid)
    return x
