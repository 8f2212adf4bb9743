"""Rig data: one CSV file per test plus a manifest, as in thesis Appendix A.

Test file
---------
Optional ``#`` comment lines, then a header naming the columns with their units in
brackets, then one row per sample::

    time [s],displacement [m],velocity [m/s],force [N]
    0.000,0.0,0.0314,254.3

``time`` and ``force`` are required, ``displacement`` and/or ``velocity`` at least one.
Accepted units: time s, ms; displacement m, cm, mm; velocity m/s, cm/s, mm/s; force N,
kN (written ``name [unit]``, ``name (unit)`` or ``name_unit``). A header without units is accepted only when the units are passed to the loader
(``units={"force": "kN", ...}``); units that disagree with the header are an error.

Manifest
--------
``manifest.csv`` (columns ``file,signal,frequency_hz,amplitude_m,purpose``) or
``manifest.toml`` (an array ``[[test]]`` with keys ``file``, ``signal``,
``frequency_hz``, ``amplitude_m``, ``purpose``). ``signal`` is ``sine``, ``square``,
``triangle`` or ``other``; ``purpose`` is ``identification`` or ``validation``.

Every problem raises :class:`~inerterlab.errors.DataFileError` naming the file and the
line; a data set with one bad file is refused as a whole.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..datafiles import read_columns
from ..errors import DataFileError, ParameterError

__all__ = ["RigTest", "RigDataSet", "load_rig_data", "read_rig_test", "write_rig_data"]

_SI = {"time": "s", "displacement": "m", "velocity": "m/s", "force": "N"}
SIGNAL_TYPES = ("sine", "square", "triangle", "other")
PURPOSES = ("identification", "validation")


@dataclass(frozen=True, kw_only=True, eq=False)
class RigTest:
    """One rig test in SI units.

    Attributes
    ----------
    name : str
        File name of the test.
    signal : str
        sine, square, triangle or other.
    frequency : float
        Nominal frequency [Hz] (NaN if not given).
    amplitude : float
        Nominal displacement amplitude [m] (NaN if not given).
    purpose : str
        identification or validation.
    t, force : ndarray
        Time [s] and measured force [N].
    displacement, velocity : ndarray or None
        Measured x [m] and v [m/s]; either may be missing.
    """

    name: str
    signal: str
    frequency: float
    amplitude: float
    purpose: str
    t: np.ndarray
    force: np.ndarray
    displacement: np.ndarray | None = None
    velocity: np.ndarray | None = None


@dataclass(frozen=True, kw_only=True, eq=False)
class RigDataSet:
    """The tests of one rig campaign."""

    tests: tuple[RigTest, ...]
    source: str = ""
    meta: dict = field(default_factory=dict)

    def select(self, purpose: str | None = None, signals: tuple[str, ...] | None = None):
        """Tests with this purpose and signal type."""
        return [
            t
            for t in self.tests
            if (purpose is None or t.purpose == purpose)
            and (signals is None or t.signal in signals)
        ]


_NAMES = {n: n for n in _SI}


def read_rig_test(path, *, units: dict | None = None, meta: dict | None = None) -> RigTest:
    """Read one test file (see the module docstring; the reader is
    :func:`inerterlab.datafiles.read_columns`, shared with road files)."""
    p = Path(path)
    meta = meta or {}
    tab = read_columns(p, _NAMES, units=units, increasing="time", min_rows=3, what="rig test")
    names = list(tab.columns)
    hl = (tab.header_line or 0) + 1
    for req in ("time", "force"):
        if req not in names:
            raise DataFileError(p, f"missing column {req!r}", hl)
    if "displacement" not in names and "velocity" not in names:
        raise DataFileError(p, "missing column: need displacement and/or velocity", hl)
    return _make_test(p, meta, tab.columns)


def _make_test(p, meta, col):
    return RigTest(
        name=p.name,
        signal=meta.get("signal", "other"),
        frequency=float(meta.get("frequency_hz", math.nan)),
        amplitude=float(meta.get("amplitude_m", math.nan)),
        purpose=meta.get("purpose", "identification"),
        t=col["time"],
        force=col["force"],
        displacement=col.get("displacement"),
        velocity=col.get("velocity"),
    )


def _manifest(directory: Path) -> tuple[Path, list[tuple[int, dict]]]:
    csvp, tomlp = directory / "manifest.csv", directory / "manifest.toml"
    from ..io import read_text_limited

    if csvp.exists():
        lines = read_text_limited(csvp, "manifest").splitlines()
        body = [(i + 1, ln) for i, ln in enumerate(lines) if ln.strip() and not ln.startswith("#")]
        if not body:
            raise DataFileError(csvp, "empty manifest", 1)
        header = [h.strip() for h in next(csv.reader([body[0][1]]))]
        twice = sorted({h for h in header if header.count(h) > 1})
        if twice:
            raise DataFileError(csvp, f"column {twice[0]!r} appears twice", body[0][0])
        for req in ("file", "purpose"):
            if req not in header:
                raise DataFileError(csvp, f"missing column {req!r}", body[0][0])
        out = []
        for ln, text in body[1:]:
            cells = [c.strip() for c in next(csv.reader([text]))]
            if len(cells) != len(header):
                raise DataFileError(csvp, f"expected {len(header)} values, found {len(cells)}", ln)
            out.append((ln, dict(zip(header, cells, strict=True))))
        return csvp, out
    if tomlp.exists():
        from ..io import read_toml

        _, doc = read_toml(tomlp, "manifest")
        tests = doc.get("test")
        if not isinstance(tests, list) or not tests or not all(isinstance(t, dict) for t in tests):
            raise DataFileError(tomlp, "needs an array of [[test]] tables")
        return tomlp, [(None, {k: str(v) for k, v in t.items()}) for t in tests]
    raise DataFileError(directory, "no manifest.csv or manifest.toml in this directory")


def load_rig_data(directory, *, units: dict | None = None) -> RigDataSet:
    """Load every test listed in the manifest of ``directory``.

    Parameters
    ----------
    directory : path
        Folder with ``manifest.csv`` or ``manifest.toml`` and the test files.
    units : dict, optional
        Units of columns whose header does not state them, e.g. ``{"force": "kN"}``.

    Raises
    ------
    DataFileError
        Naming the file and line of the first problem; nothing is returned from a
        partly bad data set.
    """
    d = Path(directory)
    if not d.is_dir():
        raise DataFileError(d, "is not a directory")
    mpath, entries = _manifest(d)
    tests = []
    seen: dict = {}
    for ln, e in entries:
        if "file" not in e or not e["file"]:
            raise DataFileError(mpath, "test without a file name", ln)
        if not isinstance(e["file"], str):
            raise DataFileError(mpath, f"file {e['file']!r} is not a file name", ln)
        inside = (d / e["file"]).resolve()
        if not inside.is_relative_to(d.resolve()):
            # a manifest names tests of its own data set, never other files of the system
            raise DataFileError(mpath, f"file {e['file']!r} is outside the data directory {d}", ln)
        if inside in seen:
            # one record counted twice would weigh twice in the fit and its intervals
            first = seen[inside]
            where = f" (first on line {first})" if first is not None else ""
            raise DataFileError(mpath, f"file {e['file']!r} is listed twice{where}", ln)
        seen[inside] = ln
        sig = e.get("signal", "other") or "other"
        if sig not in SIGNAL_TYPES:
            raise DataFileError(
                mpath, f"signal {sig!r} is not one of {', '.join(SIGNAL_TYPES)}", ln
            )
        purpose = e.get("purpose", "")
        if purpose not in PURPOSES:
            raise DataFileError(
                mpath, f"purpose {purpose!r} is not identification or validation", ln
            )
        meta = {"signal": sig, "purpose": purpose}
        for key in ("frequency_hz", "amplitude_m"):
            if e.get(key, "") not in ("", None):
                try:
                    meta[key] = float(e[key])
                except (ValueError, TypeError):
                    raise DataFileError(mpath, f"{key} {e[key]!r} is not a number", ln) from None
        tests.append(read_rig_test(d / e["file"], units=units, meta=meta))
    return RigDataSet(tests=tuple(tests), source=str(d))


_RIG_FILE = re.compile(r"manifest\.csv|[A-Za-z0-9_.\-]+\.csv")


def _replaceable_rig_dir(text: str, d: Path) -> None:
    """Refuse ``d`` unless it is new, empty, or a data set written by :func:`write_rig_data`."""
    if not d.exists():
        return
    if not d.is_dir():
        raise ParameterError("out", text, "a directory; it is an existing file, not replaced")
    entries = list(d.iterdir())
    if not entries:
        return
    from ..io import CONFIG_SIZE_LIMIT, read_text_limited

    mpath = d / "manifest.csv"
    lines = []
    if mpath.is_file() and not mpath.is_symlink():  # a FIFO or device is not ours
        try:
            lines = read_text_limited(mpath, "manifest", CONFIG_SIZE_LIMIT).splitlines()
        except DataFileError:
            lines = []
    first = lines[:1]
    listed = {"manifest.csv"}
    if first == [_MANIFEST_HEADER]:
        for row in lines[1:]:
            listed.add(row.split(",", 1)[0])
    ours = first == [_MANIFEST_HEADER] and all(
        e.name in listed and e.is_file() and not e.is_symlink() for e in entries
    )
    if not ours:
        raise ParameterError(
            "out",
            text,
            "a new or empty directory, or a rig data set written by inerterlab (it holds "
            "other files, and the data set replaces the directory as a whole; nothing was written)",
        )


_MANIFEST_HEADER = "file,signal,frequency_hz,amplitude_m,purpose"


def write_rig_data(dataset: RigDataSet, directory, *, header: str = "") -> Path:
    """Write ``dataset`` as test CSV files plus ``manifest.csv``.

    The whole directory is replaced at once (new files are written beside it and
    swapped in), so an interrupted or failed write leaves the previous data set
    complete and never a mix of old and new files. A directory that holds anything
    other than a data set of ours is refused and left as it was.
    """
    from ..io import replace_directory

    d = check_rig_output(directory)
    files: dict[str, str] = {}
    rows = [_MANIFEST_HEADER]
    for test in dataset.tests:
        cols = [("time [s]", test.t)]
        if test.displacement is not None:
            cols.append(("displacement [m]", test.displacement))
        if test.velocity is not None:
            cols.append(("velocity [m/s]", test.velocity))
        cols.append(("force [N]", test.force))
        arr = np.column_stack([c[1] for c in cols])
        buf = io.StringIO()
        if header:
            for hl in header.splitlines():
                buf.write(f"# {hl}\n")
        buf.write(",".join(c[0] for c in cols) + "\n")
        np.savetxt(buf, arr, delimiter=",", fmt="%.10g")
        files[test.name] = buf.getvalue()
        rows.append(
            f"{test.name},{test.signal},{test.frequency:g},{test.amplitude:g},{test.purpose}"
        )
    files["manifest.csv"] = "\n".join(rows) + "\n"
    return replace_directory(d, files)


def check_rig_output(directory) -> Path:
    """The resolved directory a data set will replace; raises if it is not ours to replace."""
    text = os.fspath(directory)
    if not str(text).strip():
        raise ParameterError("out", text, "a directory path (it is empty)")
    d = Path(os.path.realpath(text))
    cwd = Path.cwd().resolve()
    if d == d.parent or d == cwd or d in cwd.parents:
        raise ParameterError(
            "out", text, "a directory path other than the current one, above it or a root"
        )
    _replaceable_rig_dir(text, d)
    return d
