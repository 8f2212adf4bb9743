"""The resume cache of ``reproduce``: finished items stored as plain data.

Each finished table or figure is kept in ``<out>.work/`` as one JSON file. JSON holds
only data (numbers, strings, lists, objects), so reading a cache file can never run
code, whoever put it there; that is why it replaces the pickles used before. Tables
and figure data (pandas DataFrames) are stored column by column with their dtypes and
floats written with their shortest round-trip representation, so a reused item renders
byte for byte as when it was computed. PNG bytes are stored as base64.

The file name carries a key made of the run settings, the package version, a hash of
every file of the package (its source and the data it reads: the thesis tables, the
example vehicle, the errata) and the versions of the libraries that compute and draw
the numbers, so an edit to the code or the data (or an upgrade) never reuses a result
computed from other inputs. A file that is not valid JSON of this format,
or whose recorded key differs from its name's, is ignored and the item recomputed.
"""

from __future__ import annotations

import base64
import fcntl
import hashlib
import json
import math
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from .._provenance import code_identity

__all__ = [
    "FORMAT",
    "clean_work_dir",
    "prepare_work_dir",
    "cache_key",
    "dumps_record",
    "loads_record",
]

#: format tag written into every cache file
FORMAT = "inerterlab-report-item/1"

_PLAIN_DTYPES = ("float64", "float32", "int64", "int32", "int16", "int8", "uint64", "uint32",
                 "uint16", "uint8", "bool", "object")  # fmt: skip


#: pandas dtypes with their own missing value (NA) and "str"; rebuilt with pd.array
_PANDAS_DTYPES = ("str", "Float64", "Float32", "Int64", "Int32", "Int16", "Int8",
                  "UInt64", "UInt32", "UInt16", "UInt8", "boolean")  # fmt: skip


class Uncacheable(TypeError):
    """A record holds a value this format cannot store exactly (the item is not cached)."""


def cache_key(settings: dict) -> str:
    """Key of a cache file: settings and the code that computes the items (the package
    version, the hash of the package's files and the libraries' versions:
    :func:`inerterlab._provenance.code_identity`), 16 hex digits."""
    blob = json.dumps({"settings": settings, **code_identity()}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


# ---- encoding ------------------------------------------------------------------------


def _enc(x: Any) -> Any:
    import pandas as pd

    if x is None or isinstance(x, bool | str):
        return x
    if x is pd.NA:
        return {"__na__": 1}
    if isinstance(x, int):
        return x
    if isinstance(x, float):
        return x if math.isfinite(x) else {"__float__": repr(x)}
    if isinstance(x, np.generic):
        if isinstance(x, np.floating | np.integer | np.bool_):
            return {"__np__": x.dtype.str, "v": _enc(x.item())}
        raise Uncacheable(type(x).__name__)
    if isinstance(x, bytes):
        return {"__bytes__": base64.b64encode(x).decode("ascii")}
    if isinstance(x, tuple):
        return {"__tuple__": [_enc(v) for v in x]}
    if isinstance(x, list):
        return [_enc(v) for v in x]
    if isinstance(x, dict):
        if all(isinstance(k, str) for k in x) and not any(k.startswith("__") for k in x):
            return {k: _enc(v) for k, v in x.items()}
        return {"__dict__": [[_enc(k), _enc(v)] for k, v in x.items()]}
    if isinstance(x, np.ndarray):
        if x.dtype.name not in _PLAIN_DTYPES or x.dtype.kind == "O":
            raise Uncacheable(f"array of {x.dtype}")
        return {"__array__": x.dtype.str, "shape": list(x.shape), "v": _enc(x.ravel().tolist())}
    if isinstance(x, pd.DataFrame):
        return {"__frame__": _enc_frame(x)}
    raise Uncacheable(type(x).__name__)


def _enc_frame(df) -> dict:
    import pandas as pd

    if isinstance(df.columns, pd.MultiIndex) or df.columns.name is not None:
        raise Uncacheable("DataFrame with a named or multi-level column index")
    idx = df.index
    if not (isinstance(idx, pd.RangeIndex) and idx.start == 0 and idx.step == 1
            and idx.name is None):  # fmt: skip
        raise Uncacheable("DataFrame with a non-default index")
    cols = []
    for i in range(df.shape[1]):
        s = df.iloc[:, i]
        if s.dtype.name not in _PLAIN_DTYPES + _PANDAS_DTYPES:
            raise Uncacheable(f"column of dtype {s.dtype}")
        cols.append({"dtype": s.dtype.name, "v": _enc(s.tolist())})
    return {"columns": _enc(list(df.columns)), "data": cols, "n": len(df)}


def _dec(x: Any) -> Any:
    if isinstance(x, list):
        return [_dec(v) for v in x]
    if not isinstance(x, dict):
        return x
    if len(x) >= 1:
        tag = next(iter(x))
        if tag == "__na__":
            import pandas as pd

            return pd.NA
        if tag == "__float__":
            v = x[tag]
            if v not in ("nan", "inf", "-inf"):
                raise ValueError("bad float")
            return float(v)
        if tag == "__np__":
            return np.dtype(_plain_dtype(x[tag])).type(_dec(x["v"]))
        if tag == "__bytes__":
            return base64.b64decode(x[tag].encode("ascii"), validate=True)
        if tag == "__tuple__":
            return tuple(_dec(v) for v in x[tag])
        if tag == "__dict__":
            return {_dec(k): _dec(v) for k, v in x[tag]}
        if tag == "__array__":
            dt = _plain_dtype(x[tag])
            return np.array(_dec(x["v"]), dtype=dt).reshape(x["shape"])
        if tag == "__frame__":
            return _dec_frame(x[tag])
    return {k: _dec(v) for k, v in x.items()}


def _plain_dtype(s: str) -> np.dtype:
    dt = np.dtype(s)
    if dt.name not in _PLAIN_DTYPES or dt.kind == "O":
        raise ValueError(f"dtype {s!r} not allowed")
    return dt


def _dec_frame(f: dict):
    import pandas as pd

    columns = _dec(f["columns"])
    n = int(f["n"])
    data = {}
    for i, c in enumerate(f["data"]):
        if c["dtype"] not in _PLAIN_DTYPES + _PANDAS_DTYPES:
            raise ValueError(f"dtype {c['dtype']!r} not allowed")
        vals = _dec(c["v"])
        if c["dtype"] in _PANDAS_DTYPES:
            arr = pd.array(vals, dtype=c["dtype"])
        elif c["dtype"] == "object":
            arr = np.empty(len(vals), dtype=object)
            arr[:] = vals
        else:
            arr = np.array(vals, dtype=c["dtype"])
        if len(arr) != n:
            raise ValueError("column length")
        data[i] = arr
    df = pd.DataFrame(data, index=pd.RangeIndex(n))
    df.columns = pd.Index(columns, tupleize_cols=False)
    return df


def _well_formed(rec: Any) -> bool:
    """The fields ``render`` uses are there and of the right types."""
    import pandas as pd

    if not isinstance(rec, dict) or rec.get("ok") is not True:
        return False
    if not isinstance(rec.get("id"), str) or not isinstance(rec.get("seconds"), float | int):
        return False
    if rec.get("kind") == "table":
        return (
            all(isinstance(rec.get(k), str) for k in ("title", "claim", "reason"))
            and rec.get("claim_holds") in (True, False, None)
            and isinstance(rec.get("settings"), dict)
            and isinstance(rec.get("frame"), pd.DataFrame)
        )
    if rec.get("kind") == "figure":
        return (
            all(isinstance(rec.get(k), str) for k in ("title", "caption"))
            and isinstance(rec.get("png"), bytes)
            and isinstance(rec.get("data"), pd.DataFrame)
        )
    return False


# ---- files ---------------------------------------------------------------------------


def dumps_record(record: dict, key: str) -> bytes:
    """Serialise one finished item; raises :class:`Uncacheable` if it cannot be exact."""
    return json.dumps({"format": FORMAT, "key": key, "record": _enc(record)}).encode()


def loads_record(data: bytes, key: str) -> dict | None:
    """The item stored in ``data``, or None if it is not a valid cache file for ``key``."""
    try:
        obj = json.loads(data.decode("utf-8"))
        if not isinstance(obj, dict) or obj.get("format") != FORMAT or obj.get("key") != key:
            return None
        rec = _dec(obj["record"])
        return rec if _well_formed(rec) else None
    except (ValueError, TypeError, KeyError, AttributeError, IndexError, RecursionError,
            OverflowError, UnicodeDecodeError):  # fmt: skip
        return None


def read_cached(path: Path, key: str) -> dict | None:
    """Load the cache file ``path`` if it is a regular file of this format, else None."""
    try:
        st = os.lstat(path)
    except OSError:
        return None
    import stat

    if not stat.S_ISREG(st.st_mode):
        return None
    try:
        with open(path, "rb") as fh:
            return loads_record(fh.read(), key)
    except OSError:
        return None


# ---- the work directory --------------------------------------------------------------

_OURS = re.compile(r"(table|figure)-.+-[0-9a-f]{12,16}\.(json|pkl)|\..+\.tmp|\.lock")


def prepare_work_dir(work: Path) -> Path:
    """Create the work directory; refuse one that is a symbolic link or not a directory.

    A link would send the cache (and its later removal) outside the output folder.
    """
    from ..errors import ParameterError

    work = Path(work)
    if work.is_symlink():
        raise ParameterError(
            "--out", str(work), "a work directory that is not a symbolic link (remove the link)"
        )
    if work.exists() and not work.is_dir():
        raise ParameterError(
            "--out", str(work), "a path whose work directory is free (it is an existing file)"
        )
    work.mkdir(parents=True, exist_ok=True)
    return work


def clean_work_dir(work: Path) -> None:
    """Remove the files this package wrote into ``work``, then ``work`` if it is empty.

    Anything else found there is left in place.
    """
    work = Path(work)
    if work.is_symlink() or not work.is_dir():
        return
    for p in work.iterdir():
        if _OURS.fullmatch(p.name) and p.is_file() and not p.is_symlink():
            p.unlink(missing_ok=True)
    try:
        work.rmdir()
    except OSError:
        pass


@contextmanager
def report_lock(work: Path, out: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``work/.lock`` for the whole run; refuse if taken.

    The lock file is removed with the work directory at the end; a run that opened it
    just before then notices (the path no longer names the file it locked) and retries.
    """
    from ..errors import LockedError

    lock = Path(work) / ".lock"
    for _ in range(20):
        prepare_work_dir(work)
        fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise LockedError(
                f"{out}: another inerterlab reproduce is writing this report (lock {lock}); "
                "wait for it to finish or choose another --out"
            ) from None
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock, follow_symlinks=False))
        except OSError:
            same = False
        if same:
            break
        os.close(fd)
    else:  # pragma: no cover - only under a storm of competing runs
        raise LockedError(f"{out}: could not lock {lock}; try again")
    try:
        yield
    finally:
        os.close(fd)
