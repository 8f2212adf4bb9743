"""One reader for the package's column files: rig records and road profiles.

A file holds optional ``#`` comment lines, a header naming the columns with their units,
then one row of numbers per sample. A unit is written in brackets or parentheses after
the name, or as a suffix after an underscore::

    time [s],displacement [mm]
    time (ms),force (kN)
    distance_m,height_cm

Every value is returned in SI units. A unit the quantity does not know is an error
listing the units it does know; so is a column the caller does not expect, a cell that
is not a finite number, a row with the wrong number of values, or a key column that does
not increase. Every error is a :class:`~inerterlab.errors.DataFileError` naming the file
and the line.

Examples
--------
>>> import tempfile, pathlib
>>> p = pathlib.Path(tempfile.mkdtemp()) / "road.csv"
>>> _ = p.write_text("time [s],displacement [mm]\\n0,0\\n0.5,12\\n1,0\\n")
>>> tab = read_columns(p, {"time": "time", "displacement": "displacement"},
...                    increasing="time")
>>> tab.units, tab["displacement"].tolist()
({'time': 's', 'displacement': 'mm'}, [0.0, 0.012, 0.0])
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import DataFileError

__all__ = ["UNITS", "SI_UNITS", "ColumnTable", "read_columns", "parse_header_cell"]

#: accepted units of each physical quantity and their factor to SI (keys lower case)
UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3},
    "distance": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "km": 1e3},
    "displacement": {"m": 1.0, "cm": 1e-2, "mm": 1e-3},
    "velocity": {"m/s": 1.0, "cm/s": 1e-2, "mm/s": 1e-3},
    "force": {"n": 1.0, "kn": 1e3},
}
#: SI unit of each quantity, as written in headers
SI_UNITS = {"time": "s", "distance": "m", "displacement": "m", "velocity": "m/s", "force": "N"}
_SPELLING = {"n": "N", "kn": "kN"}

_HEAD = re.compile(r"^\s*([A-Za-z][A-Za-z0-9_ ]*?)\s*(?:[\[(]\s*([^\])]*?)\s*[\])])?\s*$")


def _unit_names(quantity: str) -> str:
    return ", ".join(_SPELLING.get(u, u) for u in UNITS[quantity])


def parse_header_cell(cell: str, names: dict[str, str]) -> tuple[str, str | None] | None:
    """``(column, unit)`` of a header cell, or None if it is not a header cell.

    ``names`` maps every accepted spelling (lower case) to a column name. A suffix
    after the last underscore counts as a unit only if the rest is an accepted name.

    >>> parse_header_cell("time_ms", {"time": "time"})
    ('time', 'ms')
    >>> parse_header_cell("Height [mm]", {"height": "displacement"})
    ('displacement', 'mm')
    """
    m = _HEAD.match(cell)
    if not m:
        return None
    name, unit = m.group(1).strip().lower(), m.group(2)
    if unit is None and name not in names and "_" in name:
        base, _, suffix = name.rpartition("_")
        if base in names:
            return names[base], suffix
    if name not in names:
        return (name, unit)
    return names[name], unit


@dataclass(frozen=True)
class ColumnTable:
    """Columns read from a file, in SI units.

    Attributes
    ----------
    path : Path
    columns : dict
        Column name -> values [SI].
    units : dict
        Column name -> the unit the file used (or the default it was read in).
    header_line : int or None
        Line of the header (None for a file without one).
    first_data_line : int or None
        Line (1-based) of the first data row.
    """

    path: Path
    columns: dict
    units: dict
    header_line: int | None
    first_data_line: int | None = None

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def __contains__(self, name: str) -> bool:
        return name in self.columns


def read_columns(
    path,
    names: dict[str, str],
    *,
    quantities: dict[str, str] | None = None,
    units: dict | None = None,
    default_units: dict | None = None,
    headerless: tuple[str, ...] | None = None,
    increasing: str | tuple[str, ...] | None = None,
    required: tuple[str, ...] = (),
    min_rows: int = 2,
    what: str = "",
) -> ColumnTable:
    """Read a column file (see the module docstring).

    Parameters
    ----------
    path : path-like
    names : dict
        Accepted header spellings (lower case) -> column name.
    quantities : dict, optional
        Column name -> physical quantity (a key of :data:`UNITS`); by default the
        column name itself.
    units : dict, optional
        Units of columns the header leaves without one; a unit that disagrees with the
        header is an error.
    default_units : dict, optional
        Units assumed for columns without a unit when ``units`` does not give one; a
        column without either is an error.
    headerless : tuple, optional
        Columns of a file whose first row is already numbers (read in ``default_units``
        or SI); without it such a file is an error. A row with fewer values is read as
        the first columns of this tuple if they hold every ``required`` column.
    increasing : str or tuple, optional
        Column(s) that must increase strictly; the first of them present is checked.
    required : tuple, optional
        Columns the file must have.
    min_rows : int
        Fewest data rows accepted.
    what : str
        What the file holds, for messages ("rig test", "road").
    """
    p = Path(path)
    quantities = quantities or {}
    units = {k.lower(): v for k, v in (units or {}).items()}
    default_units = default_units or {}
    from .io import read_text_limited

    # size-capped, UTF-8 only, devices and FIFOs read up to the cap
    text = read_text_limited(p, f"{what} file" if what else "data file")
    lines = text.splitlines()
    first = None
    for i, ln in enumerate(lines):
        if ln.strip() and not ln.lstrip().startswith("#"):
            first = i
            break
    if first is None:
        raise DataFileError(p, "empty file: no header and no data", 1)
    _check_line(p, lines[first], first)
    cells = _cells(p, lines[first], first)
    expected = ", ".join(dict.fromkeys(names.values()))
    if headerless is not None and _all_numbers(cells):
        hline = None
        cols = list(headerless)
        if len(required) <= len(cells) < len(cols) and set(required) <= set(cols[: len(cells)]):
            cols = cols[: len(cells)]
        col_units = [
            units.get(c) or default_units.get(c) or SI_UNITS[quantities.get(c, c)] for c in cols
        ]
        if len(cells) != len(cols):
            raise DataFileError(
                p,
                f"expected {len(cols)} values ({', '.join(cols)}), found {len(cells)}",
                first + 1,
            )
    else:
        hline = first
        cols, col_units = [], []
        for cell in cells:
            parsed = parse_header_cell(cell, names)
            if parsed is None:
                raise DataFileError(p, f"cannot read column header {cell!r}", hline + 1)
            name, unit = parsed
            if name not in names.values():
                raise DataFileError(p, f"unknown column {name!r} (expected {expected})", hline + 1)
            if name in cols:
                raise DataFileError(p, f"column {name!r} appears twice", hline + 1)
            flag = units.get(name)
            if unit is None:
                unit = flag or default_units.get(name)
            elif flag is not None and flag.lower() != unit.lower():
                raise DataFileError(
                    p, f"column {name!r} is in [{unit}] but units={flag!r} was given", hline + 1
                )
            q = quantities.get(name, name)
            if unit is None:
                raise DataFileError(
                    p,
                    f"column {name!r} has no unit; write '{name} [{SI_UNITS[q]}]' or pass units",
                    hline + 1,
                )
            cols.append(name)
            col_units.append(unit)
    missing = [c for c in required if c not in cols]
    if missing:
        raise DataFileError(
            p,
            f"missing column {missing[0]!r} (expected {expected})",
            (hline if hline is not None else first) + 1,
        )
    scale = {}
    for name, unit in zip(cols, col_units, strict=True):
        q = quantities.get(name, name)
        if unit.lower() not in UNITS[q]:
            raise DataFileError(
                p,
                f"unknown unit [{unit}] for {name}; expected one of {_unit_names(q)}",
                (hline if hline is not None else first) + 1,
            )
        scale[name] = UNITS[q][unit.lower()]
    start = first if hline is None else hline + 1
    if isinstance(increasing, str):
        increasing = (increasing,)
    key = next((c for c in (increasing or ()) if c in cols), None)
    arr = _fast_parse(lines, start, len(cols))
    if arr is not None and arr.shape[0] >= min_rows:
        if key is None or np.all(np.diff(arr[:, cols.index(key)]) > 0):
            return _table(p, cols, col_units, arr, scale, hline, _first_row(lines, start))
    rows = []
    for i in range(start, len(lines)):
        ln = lines[i]
        if not ln.strip() or ln.lstrip().startswith("#"):
            continue
        _check_line(p, ln, i)
        row = _cells(p, ln, i)
        if len(row) != len(cols):
            raise DataFileError(p, f"expected {len(cols)} values, found {len(row)}", i + 1)
        vals = []
        for name, c in zip(cols, row, strict=True):
            try:
                x = float(c)
            except ValueError:
                raise DataFileError(
                    p, f"{name} value {c.strip()!r} is not a number", i + 1
                ) from None
            if not math.isfinite(x):
                raise DataFileError(p, f"{name} value {c.strip()!r} is not finite", i + 1)
            vals.append(x)
        if key is not None and rows:
            j = cols.index(key)
            if not vals[j] > rows[-1][1][j]:
                raise DataFileError(
                    p,
                    f"{key} is not strictly increasing ({vals[j]!r} after {rows[-1][1][j]!r})",
                    i + 1,
                )
        rows.append((i + 1, vals))
    if len(rows) < min_rows:
        raise DataFileError(
            p,
            f"empty file: {len(rows)} data rows (need at least {min_rows})",
            (hline if hline is not None else first) + 1,
        )
    arr = np.array([r[1] for r in rows], dtype=float)
    return _table(p, cols, col_units, arr, scale, hline, rows[0][0])


#: longest line of a column file [characters]: a row holds a few numbers
MAX_LINE = 65536


def _check_line(p, line: str, i: int) -> None:
    if len(line) > MAX_LINE:
        raise DataFileError(
            p, f"line of {len(line)} characters; a row of numbers has at most {MAX_LINE}", i + 1
        )


def _cells(p, line: str, i: int) -> list[str]:
    try:
        return next(csv.reader([line]), [])
    except csv.Error as e:
        raise DataFileError(p, f"cannot read the row ({e})", i + 1) from None


def _all_numbers(cells) -> bool:
    try:
        [float(c) for c in cells]
    except ValueError:
        return False
    return True


def _first_row(lines, start: int) -> int | None:
    for i in range(start, len(lines)):
        if lines[i].strip() and not lines[i].lstrip().startswith("#"):
            return i + 1
    return None


def _table(p, cols, col_units, arr, scale, hline, first_row) -> ColumnTable:
    columns = {n: arr[:, j] * scale[n] for j, n in enumerate(cols)}
    return ColumnTable(
        path=p,
        columns=columns,
        units=dict(zip(cols, col_units, strict=True)),
        header_line=hline,
        first_data_line=first_row,
    )


def _fast_parse(lines, start, ncol):
    """All data rows as floats, or None if anything needs the careful line-by-line pass."""
    import pandas as pd

    body = "\n".join(lines[start:])
    if not body.strip():
        return None
    try:
        df = pd.read_csv(
            io.StringIO(body),
            header=None,
            comment="#",
            skip_blank_lines=True,
            dtype=float,
            engine="c",
        )
    except (ValueError, pd.errors.ParserError, pd.errors.EmptyDataError):
        return None
    arr = df.to_numpy()
    if arr.ndim != 2 or arr.shape[1] != ncol or not np.all(np.isfinite(arr)):
        return None
    return arr
