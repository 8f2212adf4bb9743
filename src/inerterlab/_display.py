"""Short text and HTML summaries of results (``__repr__`` and ``_repr_html_``)."""

from __future__ import annotations

import html
import math


def fmt(value, unit: str = "", digits: int = 4) -> str:
    """``value`` with ``digits`` significant digits and its unit."""
    if isinstance(value, bool) or value is None:
        text = str(value)
    elif isinstance(value, int):
        text = str(value)
    else:
        try:
            v = float(value)
        except (TypeError, ValueError):
            text = str(value)
        else:
            text = f"{v:.{digits}g}" if math.isfinite(v) else str(v)
    return f"{text} {unit}".rstrip() if unit and unit != "1" else text


def span(lo, hi, unit: str = "", digits: int = 4) -> str:
    """``lo .. hi unit``."""
    return f"{fmt(lo, '', digits)} .. {fmt(hi, unit, digits)}"


def html_table(title: str, rows: list[tuple[str, str]]) -> str:
    """A two-column HTML table with a caption (for notebooks)."""
    body = "".join(
        f"<tr><th style='text-align:left'>{html.escape(str(k))}</th>"
        f"<td style='text-align:right'>{html.escape(str(v))}</td></tr>"
        for k, v in rows
    )
    return (
        f"<table><caption style='text-align:left'><b>{html.escape(title)}</b></caption>"
        f"{body}</table>"
    )


def distinct(values, min_digits: int = 4, max_digits: int = 12) -> list[str]:
    """The values with the fewest significant digits (at least ``min_digits``) that keep
    different values different in print, e.g. an estimate and its interval.

    >>> distinct([1.97e6, 1.9699e6, 1.9701e6])
    ['1.97e+06', '1.9699e+06', '1.9701e+06']
    >>> distinct([190.0, 189.86, 190.13])
    ['190.0', '189.9', '190.1']
    >>> distinct([80.0022, 79.979, 80.0254], min_digits=6)
    ['80.0022', '79.9790', '80.0254']

    Between 1e-3 and 1e6 the values share one number of decimals (no trailing zero is
    dropped, so their digits line up); outside it they keep the ``g`` format.
    """
    vals = [float(v) for v in values]
    want = len(set(vals))
    texts = [f"{v:.{max_digits}g}" for v in vals]
    finite = [abs(v) for v in vals if math.isfinite(v)]
    top = max(finite, default=0.0)
    for d in range(min_digits, max_digits + 1):
        if 1e-3 <= top < 1e6:
            places = max(d - 1 - math.floor(math.log10(top)), 0)
            t = [f"{v:.{places}f}" if math.isfinite(v) else str(v) for v in vals]
        else:
            t = [f"{v:.{d}g}" for v in vals]
        if len(set(t)) == want:
            return t
    return texts
