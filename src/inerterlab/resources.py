"""Up-front resource checks: refuse a run that would not fit, with the estimate.

A run that would build arrays larger than the memory this machine has (for instance a
saved time series at a very high sample rate over a very long horizon, or a sweep
whose result grid is enormous) is refused before any work starts, with the estimate
and the limit in the message, instead of failing half way with a MemoryError.
"""

from __future__ import annotations

import os

from .errors import ParameterError

__all__ = ["available_memory", "check_memory", "check_work"]

#: fraction of the physical memory one run may claim for a single result
MEMORY_FRACTION = 0.5

#: floating point operations one command may plan before it is refused (about ten
#: minutes on one core of an ordinary machine)
WORK_LIMIT = 1e12


def available_memory() -> int:
    """Physical memory of this machine [bytes] (falls back to 4 GiB if unknown)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 4 * 1024**3


def _fmt(nbytes: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if nbytes < 1024 or unit == "TiB":
            return f"{nbytes:.3g} {unit}"
        nbytes /= 1024
    return f"{nbytes:.3g} TiB"  # pragma: no cover


def check_memory(
    n_values: float,
    *,
    what: str,
    parameter: str,
    bytes_per_value: int = 8,
    limit: int | None = None,
    value: object = None,
) -> int:
    """Raise if ``n_values`` floats would exceed the memory budget; return the estimate.

    Parameters
    ----------
    n_values : float
        Number of values the result will hold.
    what : str
        What is being built, for the message (e.g. "saved time series").
    parameter : str
        The option the user can change to make it fit (named in the message).
    limit : int, optional
        Budget [bytes]; default half the physical memory.
    value : optional
        The value the user gave for ``parameter`` (shown in the message; default the
        number of values).

    Examples
    --------
    >>> check_memory(1e6, what="time series", parameter="--horizon")
    8000000
    """
    budget = int(limit if limit is not None else MEMORY_FRACTION * available_memory())
    need = float(n_values) * bytes_per_value
    if not need < budget:
        raise ParameterError(
            parameter,
            f"{n_values:.3g} values" if value is None else value,
            f"a setting whose {what} fits in memory: it needs about {_fmt(need)}, "
            f"the limit is {_fmt(budget)}",
        )
    return int(need)


def check_work(
    ops: float, *, what: str, parameter: str, limit: float | None = None, value: object = None
) -> float:
    """Raise if a run is estimated to need more than ``limit`` floating point operations.

    The estimate is deliberately rough (an order of magnitude); it only stops runs
    that would take hours or days from starting silently.

    Examples
    --------
    >>> check_work(1e9, what="frequency sweep", parameter="--df")
    1000000000.0
    """
    budget = float(limit if limit is not None else WORK_LIMIT)
    ops = float(ops)
    if not ops < budget:
        raise ParameterError(
            parameter,
            f"{ops:.3g} operations" if value is None else value,
            f"a setting whose {what} finishes in reasonable time: it needs about {ops:.3g} "
            f"floating point operations (~{ops / 1e9 / 3600:.3g} h at 1 Gflop/s), "
            f"the limit is {budget:.3g}",
        )
    return ops
