"""Run a sweep on any backend, with incremental, resumable storage in a Zarr store.

The grid of a :class:`~inerterlab.studies.spec.SweepSpec` is numbered in C order over
its dimensions and cut into chunks of consecutive points. A chunk is one task for the
backend and one chunk of every array in the store, so a finished task is written with
one atomic file write per array, and the ``status`` array is written last: a point
whose status is set has all its metrics on disk. Rerunning the same sweep into the same
store computes only the points whose status is still *missing*.

Store layout (Zarr v3 group): one float64 array of length N per metric, ``status``
(int8: 0 missing, 1 ok, 2 failed), ``reason`` (N x 160 UTF-8 bytes, the failure
message), and the attributes ``config`` (the sweep description), ``config_hash``,
``code`` (the code that computes the points: :func:`inerterlab._provenance.code_identity`),
``chunk_size`` and ``metrics``. A store is resumed only by the same description, the same
input files and the same code: after an edit to the package or an upgrade of a library
that computes the numbers, its finished points would be another code's, so it is
refused. :func:`load_sweep` turns it into an :class:`xarray.Dataset` with one dimension
per swept parameter.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from .._provenance import code_identity, describe_change
from ..errors import DataFileError, InerterlabError
from .backends import Backend, make_backend
from .points import PointFunction
from .spec import SweepSpec, sweep_spec

__all__ = [
    "sweep",
    "load_sweep",
    "save_netcdf",
    "SweepInterrupted",
    "STATUS_MISSING",
    "STATUS_OK",
    "STATUS_FAILED",
    "evaluate_chunk",
    "InputChanged",
    "CodeChanged",
    "claim_store_folder",
    "keyed_store",
    "unread_stores",
]

STATUS_MISSING, STATUS_OK, STATUS_FAILED = 0, 1, 2
_STATUS_MEANINGS = "missing ok failed"
REASON_BYTES = 160
_FORMAT = "inerterlab-sweep-1"


class SweepInterrupted(KeyboardInterrupt):
    """The sweep was interrupted; every finished chunk is already in the store."""

    def __init__(self, done: int, total: int, store: str | None):
        self.done, self.total, self.store = done, total, store
        where = (
            f"{done} of {total} points are stored in {store}; rerun the same command to resume"
            if store
            else f"{done} of {total} points were computed (no store given, nothing kept)"
        )
        super().__init__(f"sweep interrupted: {where}")


# --- tasks ----------------------------------------------------------------------------


@dataclass(frozen=True)
class ChunkTask:
    """One task: the points ``indices`` (flat, sorted) of chunk ``chunk``."""

    point: PointFunction
    names: tuple[str, ...]
    values: tuple[tuple, ...]
    fixed: tuple[tuple[str, Any], ...]
    indices: tuple[int, ...]
    chunk: int
    #: ``(key, path, digest)`` of every input file; checked before and after the chunk
    inputs: tuple[tuple[str, str, str], ...] = ()
    #: the code the sweep runs (:func:`inerterlab._provenance.code_identity` as JSON); a
    #: worker running other code (a cluster's, or one started after an edit) refuses it
    software: str = ""

    def params(self, index: int) -> dict:
        out = dict(self.fixed)
        shape = tuple(len(v) for v in self.values)
        for name, vals, i in zip(
            self.names, self.values, np.unravel_index(index, shape), strict=True
        ):
            out[name] = vals[int(i)]
        return out


@dataclass(frozen=True)
class ChunkResult:
    values: np.ndarray  # (n_points, n_metrics) float64, NaN where not ok
    status: np.ndarray  # (n_points,) int8
    reasons: tuple[str, ...]


class InputChanged(InerterlabError):
    """An input file of a sweep changed while it ran; nothing of the chunk is stored."""


class CodeChanged(InputChanged):
    """A worker runs other code than the sweep (another inerterlab, its files edited,
    other library versions); nothing of the chunk is computed."""


def _code_text() -> str:
    return json.dumps(code_identity(), sort_keys=True)


def _check_code(task: ChunkTask) -> None:
    if task.software and task.software != _code_text():
        raise CodeChanged(
            "a worker runs other code than the sweep ("
            f"{describe_change(json.loads(task.software))}); its points would not be the "
            "sweep's. Run every worker on the same inerterlab and the same libraries"
        )


def _check_inputs(task: ChunkTask) -> None:
    from .spec import file_digest

    for key, path, digest in task.inputs:
        try:
            now = file_digest(path, f"{key} file")
        except DataFileError as exc:
            now = str(exc)
        if now != digest:
            raise InputChanged(
                f"{path}: the {key} file changed while the sweep ran; what was finished "
                "before is stored, but a rerun refuses the store (it was made from the old "
                "file): keep the file as it was to resume, or use a new --out"
            )


def evaluate_chunk(task: ChunkTask) -> ChunkResult:
    """Evaluate every point of ``task``; a point that raises or returns a non-finite
    or missing metric is marked failed with the reason, never given a number.

    Every input file is checked against its recorded digest before and after: a file
    changed meanwhile raises :class:`InputChanged` (no result of the chunk is kept). A
    worker whose code differs from the sweep's raises :class:`CodeChanged` first."""
    _check_code(task)
    _check_inputs(task)
    res = _evaluate_points(task)
    _check_inputs(task)
    return res


def _evaluate_points(task: ChunkTask) -> ChunkResult:
    metrics = task.point.metrics
    n = len(task.indices)
    values = np.full((n, len(metrics)), np.nan)
    status = np.full(n, STATUS_OK, dtype=np.int8)
    reasons = [""] * n
    fn = task.point.function
    for k, index in enumerate(task.indices):
        try:
            out = fn(task.params(index))
            # None: a metric the point function reports as not finite by its physics
            # (unweighted body acceleration across a road step); kept as NaN with the
            # point still valid and the metric named in its reason
            absent = [m for m in metrics if out[m] is None]
            row = [math.nan if out[m] is None else float(out[m]) for m in metrics]
            bad = [
                m
                for m, v in zip(metrics, row, strict=True)
                if m not in absent and not math.isfinite(v)
            ]
            if bad:
                raise ArithmeticError(f"non-finite {', '.join(bad)}")
            values[k] = row
            if absent:
                reasons[k] = "not finite across a road step: " + ", ".join(absent)
        except KeyError as exc:
            status[k] = STATUS_FAILED
            reasons[k] = f"point function returned no metric {exc}"
        except Exception as exc:  # noqa: BLE001 - recorded as the point's failure reason
            status[k] = STATUS_FAILED
            reasons[k] = f"{type(exc).__name__}: {exc}"
    return ChunkResult(values, status, tuple(reasons))


# --- storage --------------------------------------------------------------------------


def _encode_reasons(reasons) -> np.ndarray:
    out = np.zeros((len(reasons), REASON_BYTES), dtype=np.uint8)
    for k, r in enumerate(reasons):
        b = r.encode("utf-8")[:REASON_BYTES]
        out[k, : len(b)] = np.frombuffer(b, dtype=np.uint8)
    return out


def _decode_reasons(arr: np.ndarray) -> np.ndarray:
    return np.array(
        [bytes(row).rstrip(b"\0").decode("utf-8", errors="replace") for row in arr], dtype=object
    )


class _MemoryStore:
    def __init__(self, spec: SweepSpec):
        n, m = spec.size, len(spec.point_function.metrics)
        self.values = np.full((n, m), np.nan)
        self.status_arr = np.zeros(n, dtype=np.int8)
        self.reasons = np.zeros((n, REASON_BYTES), dtype=np.uint8)
        self.path = None

    def status(self) -> np.ndarray:
        return self.status_arr

    def write(self, idx: np.ndarray, res: ChunkResult) -> None:
        self.values[idx] = res.values
        self.reasons[idx] = _encode_reasons(res.reasons)
        self.status_arr[idx] = res.status

    def read(self):
        return self.values, self.status_arr, _decode_reasons(self.reasons)


def _check_consistent(path, metrics, values, status, reasons) -> None:
    """A point marked ok has every metric, unless its reason names the missing ones (a
    chunk file of a metric that went missing reads as NaN)."""
    ok = np.asarray(status) == STATUS_OK
    for j, name in enumerate(metrics):
        lost = ok & np.isnan(values[:, j])
        if lost.any():
            unexplained = [i for i in np.flatnonzero(lost) if name not in str(reasons[i])]
            if unexplained:
                raise _damaged(
                    path,
                    name,
                    ValueError(f"point {unexplained[0]} is marked done but has no value"),
                )


def _damaged(path, name: str, exc: BaseException) -> DataFileError:
    why = " ".join(str(exc).split())[:160] or type(exc).__name__
    return DataFileError(
        path,
        f"store damaged: array {name!r} cannot be read ({type(exc).__name__}: {why}); "
        "move the store aside (or choose a new --out) to compute it again",
    )


class _ZarrStore:
    def __init__(self, path: Path, spec: SweepSpec, chunk_size: int):
        import zarr

        self.path = str(path)
        self.metrics = spec.point_function.metrics
        self._lock_fd: int | None = None
        config_hash = spec.config_hash()
        claim_store_folder(path)
        if not path.exists():
            _create_store(path, spec, chunk_size, config_hash, self.metrics)
        if path.is_symlink() and not path.exists():
            raise DataFileError(path, "is a symbolic link to nothing; choose another --out")
        try:
            group = zarr.open_group(str(path), mode="r+")
            attrs = dict(group.attrs)
        except Exception:  # noqa: BLE001 - anything unreadable is not our store
            raise DataFileError(
                path, "exists and is not a sweep store; choose another --out"
            ) from None
        if attrs.get("format") != _FORMAT:
            raise DataFileError(path, "exists and is not a sweep store; choose another --out")
        if attrs.get("config_hash") != config_hash:
            old = attrs.get("config", {})
            diff = _describe_difference(old if isinstance(old, dict) else {}, spec.to_dict())
            what = (
                "its inputs changed since it was made"
                if diff.startswith("inputs")
                else "it was made from a different sweep configuration"
            )
            raise DataFileError(
                path,
                f"{what} ({diff}); refusing to resume into it, its results would not be "
                "those of these inputs. Use a new --out, or move the store aside to start over",
            )
        if attrs.get("code") != code_identity():
            raise DataFileError(
                path,
                f"it was made by other code ({describe_change(attrs.get('code'))}); refusing "
                "to resume into it, its finished points and this code's would mix in one "
                "result. Use a new --out, or move the store aside to start over",
            )
        self.group = group
        try:
            self.chunk_size = int(attrs["chunk_size"])
        except (KeyError, TypeError, ValueError) as exc:
            raise _damaged(path, "chunk_size (attribute)", exc) from None
        self._lock_fd = _lock_store(path)
        # opened once: looking an array up by name reads its metadata from disk,
        # which cost as much as writing a chunk of it (about 1.5 ms each)
        self._arrays = {}
        try:
            for name in (*self.metrics, "reason", "status"):
                try:
                    self._arrays[name] = group[name]
                except Exception as exc:  # noqa: BLE001 - a missing or unreadable array
                    raise _damaged(path, name, exc) from None
                # read whole once: a truncated or altered chunk is found before any work
                self._read(name)
            _check_consistent(path, self.metrics, *self.read())
        except BaseException:
            self.close()
            raise

    def _read(self, name: str) -> np.ndarray:
        try:
            data = np.asarray(self._arrays[name][:])
        except Exception as exc:  # noqa: BLE001 - decompression, shape, missing chunk file
            raise _damaged(self.path, name, exc) from None
        n = self._arrays["status"].shape[0] if "status" in self._arrays else None
        if n is not None and data.shape[0] != n:
            raise _damaged(self.path, name, ValueError(f"{data.shape[0]} points, not {n}"))
        return data

    def close(self) -> None:
        if self._lock_fd is not None:
            os.close(self._lock_fd)
            self._lock_fd = None

    def status(self) -> np.ndarray:
        return self._read("status")

    def write(self, idx: np.ndarray, res: ChunkResult) -> None:
        contiguous = idx[-1] - idx[0] + 1 == len(idx)
        sel = slice(int(idx[0]), int(idx[-1]) + 1) if contiguous else idx

        def put(name, data):
            arr = self._arrays[name]
            if contiguous:
                arr[sel] = data
            else:
                arr.oindex[sel] = data

        for j, name in enumerate(self.metrics):
            put(name, res.values[:, j])
        put("reason", _encode_reasons(res.reasons))
        put("status", res.status)  # last: marks the points as done

    def read(self):
        values = np.stack([self._read(m) for m in self.metrics], axis=1)
        return values, self.status(), _decode_reasons(self._read("reason"))


def _is_sweep_store(path: Path) -> bool:
    import json as _json

    try:
        meta = _json.loads((path / "zarr.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(meta, dict) and (meta.get("attributes") or {}).get("format") == _FORMAT


def claim_store_folder(
    path: Path, members: tuple[str, ...] | None = None, keyed: bool = False
) -> None:
    """The one rule for an ``--out`` a command keeps its stores in; refuses what is not ours.

    ``members`` None: ``path`` is itself a sweep store. It may be new, or an existing
    sweep store (checked further by the caller); an existing empty folder is refused as
    well as anything else, since the tool never writes into a folder it did not make.
    ``members`` given: ``path`` is a folder holding exactly these sweep stores (and the
    temporary folders of their creation); it may be new or empty, and any other entry,
    such as another program's Zarr group, is refused. With ``keyed`` a member ``X.zarr``
    stands also for ``X-<12 hex digits>.zarr`` (stores named by a digest of their
    content, as the design study's stages).
    """
    path = Path(path)
    if path.is_symlink() and not path.exists():
        raise DataFileError(path, "is a symbolic link to nothing; choose another --out")
    if not path.exists():
        return
    if not path.is_dir():
        raise DataFileError(path, "exists and is not a folder; choose another --out")
    if members is None:
        if not _is_sweep_store(path):
            raise DataFileError(path, "exists and is not a sweep store; choose another --out")
        return
    import re

    # each member's name (with ``keyed``, its stem may carry a digest), and the temporary
    # folder of its creation
    stem = "(?:-[0-9a-f]{12})?" if keyed else ""
    name = "|".join(re.escape(m.removesuffix(".zarr")) + stem + re.escape(".zarr") for m in members)
    store = re.compile(f"(?:{name})" if members else "(?!)")
    temp = re.compile(rf"\.(?:{name})\.new-[A-Za-z0-9_]+" if members else "(?!)")
    for entry in sorted(path.iterdir()):
        if store.fullmatch(entry.name) and entry.is_dir() and _is_sweep_store(entry):
            continue
        if temp.fullmatch(entry.name):
            continue
        raise DataFileError(
            path,
            f"holds {entry.name!r}, which this command did not write (it keeps only "
            f"{', '.join(m[:-5] + '-<key>.zarr' if keyed else m for m in members)} there); "
            "choose another --out",
        )


def keyed_store(store: str | os.PathLike, spec: SweepSpec) -> Path:
    """``<folder>/<stem>-<key>.zarr`` for ``store`` = ``<folder>/<stem>.zarr``: the key is
    12 hex digits of SHA-256 over the sweep (its description and input files,
    :meth:`SweepSpec.config_hash`) and the code that computes it (:func:`inerterlab.
    _provenance.code_identity`). A study that keeps one store per sweep under these
    names resumes each sweep on a rerun, and computes the sweeps a changed setting,
    input or code changes into new stores beside the others (which it leaves in place);
    :func:`claim_store_folder` with ``keyed`` accepts them."""
    import hashlib

    key = json.dumps([spec.config_hash(), code_identity()], sort_keys=True)
    path = Path(store)
    return path.with_name(f"{path.stem}-{hashlib.sha256(key.encode()).hexdigest()[:12]}.zarr")


def unread_stores(folder: str | os.PathLike, read) -> list[str]:
    """The names of the sweep stores in ``folder`` other than those in ``read`` (names),
    sorted: under :func:`keyed_store` names, the stores of earlier settings or code that
    a study's rerun does not read. They are left in place (the tool deletes nothing it
    was not asked to); a study reports them so that a user can delete them."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    names = set(read)
    return sorted(
        e.name for e in folder.iterdir()
        if e.name not in names and e.is_dir() and _is_sweep_store(e)
    )  # fmt: skip


def _lock_store(path: Path) -> int:
    """Exclusive lock on the store directory for this run; refuses a second writer."""
    import fcntl

    from ..errors import LockedError

    fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise LockedError(
            f"{path}: another inerterlab sweep is writing this store; wait for it to finish "
            "(then rerun to pick up what it did not compute) or choose another --out"
        ) from None
    return fd


def _codecs():
    """Compression with a checksum of every chunk: a damaged chunk is found, never read."""
    from zarr.codecs import Crc32cCodec, ZstdCodec

    return [ZstdCodec(level=0), Crc32cCodec()]


def _create_store(path: Path, spec: SweepSpec, chunk_size: int, config_hash: str, metrics):
    """Create a complete empty store beside ``path`` and rename it into place.

    The store is valid from the moment ``path`` exists: a run killed while creating it
    leaves only a ``.<name>.new-*`` folder, removed by the next run. Creation is
    serialised by a short lock on the parent directory, so two runs starting at once
    do not both create one (the second finds the first's store and is locked out).
    """
    import fcntl
    import re
    import shutil
    import tempfile

    import zarr

    from ..io import current_umask

    parent = path.parent
    parent.mkdir(parents=True, exist_ok=True)
    dfd = os.open(parent, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(dfd, fcntl.LOCK_EX)
        if path.exists() or path.is_symlink():
            return
        pat = re.compile(re.escape(f".{path.name}.new-") + r"[A-Za-z0-9_]+")
        for p in parent.iterdir():
            if pat.fullmatch(p.name) and p.is_dir() and not p.is_symlink():
                shutil.rmtree(p, ignore_errors=True)
        tmp = Path(tempfile.mkdtemp(dir=parent, prefix=f".{path.name}.new-"))
        try:
            os.chmod(tmp, 0o777 & ~current_umask())
            group = zarr.open_group(str(tmp), mode="w")
            n = spec.size
            for name in metrics:
                group.create_array(
                    name,
                    shape=(n,),
                    chunks=(chunk_size,),
                    dtype="float64",
                    fill_value=np.nan,
                    dimension_names=["point"],
                    compressors=_codecs(),
                )
            group.create_array(
                "reason",
                shape=(n, REASON_BYTES),
                chunks=(chunk_size, REASON_BYTES),
                dtype="uint8",
                fill_value=0,
                dimension_names=["point", "reason_byte"],
                compressors=_codecs(),
            )
            group.create_array(
                "status",
                shape=(n,),
                chunks=(chunk_size,),
                dtype="int8",
                fill_value=STATUS_MISSING,
                dimension_names=["point"],
                compressors=_codecs(),
                attributes={"flag_values": [0, 1, 2], "flag_meanings": _STATUS_MEANINGS},
            )
            group.attrs.update(
                {
                    "format": _FORMAT,
                    "config": spec.to_dict(),
                    "config_hash": config_hash,
                    "code": code_identity(),
                    "chunk_size": int(chunk_size),
                    "metrics": list(metrics),
                    "dims": list(spec.dims),
                    "shape": list(spec.shape),
                    "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                }
            )
            os.rename(tmp, path)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
    finally:
        os.close(dfd)


def _short(v: Any) -> str:
    if isinstance(v, list) and len(v) > 6:
        return f"{len(v)} values {v[0]!r}..{v[-1]!r}"
    return repr(v)


def _describe_difference(old: dict, new: dict) -> str:
    diffs = []
    oi, ni = old.get("inputs") or {}, new.get("inputs") or {}
    for key in sorted(set(oi) | set(ni)):
        if oi.get(key) != ni.get(key):
            was = str(oi.get(key, "not recorded"))[:19]
            diffs.append(
                f"inputs: the {key} content differs (stored {was}, now {str(ni.get(key))[:19]})"
            )
    for key in ("point", "settings", "weights"):
        if old.get(key) != new.get(key):
            diffs.append(f"{key}: stored {old.get(key)!r}, now {new.get(key)!r}")
    op, np_ = old.get("parameters", {}), new.get("parameters", {})
    for name in sorted(set(op) | set(np_)):
        if op.get(name) != np_.get(name):
            diffs.append(
                f"parameters.{name}: stored {_short(op.get(name))}, now {_short(np_.get(name))}"
            )
    if list(op) != list(np_) and not diffs:
        diffs.append(f"parameter order: stored {list(op)}, now {list(np_)}")
    return "; ".join(diffs) or "hash differs"


# --- the driver -------------------------------------------------------------------------


def _auto_chunk_size(n: int, workers: int) -> int:
    # at least 8 chunks per worker for balance and a fine-grained resume, at most 1024
    # points per chunk: each chunk costs about 1.5 ms per stored array to write
    return int(max(1, min(1024, math.ceil(n / (8 * max(1, workers))))))


def _progress_bar(total: int, done: int, label: str):
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TaskProgressColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    class _Rate(TextColumn):
        def __init__(self):
            super().__init__("")

        def render(self, task):
            from rich.text import Text

            speed = task.finished_speed or task.speed
            return Text("" if not speed else f"{speed:,.0f} points/s")

    prog = Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TaskProgressColumn(),
        _Rate(),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        transient=False,
    )
    task = prog.add_task(label, total=total, completed=done)
    return prog, task


def sweep(
    spec: SweepSpec | dict,
    *,
    store: str | os.PathLike | None = None,
    backend: str | Backend | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool | Callable[[int, int], None] = False,
):
    """Evaluate the point function over the grid of ``spec``.

    Parameters
    ----------
    spec : SweepSpec or dict
        The sweep (a dict is passed to :func:`~inerterlab.studies.spec.sweep_spec`).
    store : path, optional
        Zarr store written chunk by chunk. If it exists and was made from the same
        description, the same input files and the same code (the package's files and
        the libraries' versions), only the missing points are computed (resume); else
        :class:`~inerterlab.errors.DataFileError` is raised before any work.
    backend : {"serial", "processes", "dask"} or Backend, optional
        Default ``processes`` (``dask`` if ``scheduler`` is given).
    workers : int, optional
        Number of local workers (processes, or a local Dask cluster).
    scheduler : str, optional
        Address of a running Dask scheduler.
    progress : bool or callable
        Show a progress bar on standard error, or call ``progress(done, total)``.

    Returns
    -------
    xarray.Dataset
        One dimension per swept parameter, one variable per metric (NaN where the
        point failed), ``status`` and ``reason``, the settings in the attributes.

    Raises
    ------
    SweepInterrupted
        On Ctrl-C; the store keeps every finished chunk.

    Examples
    --------
    >>> ds = sweep({"point": "synthetic", "parameters": {"changing_ratio": [0.1, 0.2]}},
    ...            backend="serial")
    >>> ds.rms_body_acc.dims, int((ds.status == 1).sum())
    (('changing_ratio',), 2)
    """
    if isinstance(spec, dict):
        spec = sweep_spec(**spec)
    n = spec.size
    be = make_backend(backend, workers=workers, scheduler=scheduler)
    chunk_size = spec.chunk_size or _auto_chunk_size(
        n, be.workers if be.name != "dask" else max(1, workers or 2)
    )
    target = _ZarrStore(Path(store), spec, chunk_size) if store is not None else _MemoryStore(spec)
    try:
        return _run_sweep(spec, target, be, chunk_size, store, progress)
    finally:
        if store is not None:
            target.close()


def _run_sweep(spec, target, be, chunk_size, store, progress):
    n = spec.size
    point = spec.point_function
    if store is not None:
        chunk_size = target.chunk_size
    status = target.status()
    missing = np.flatnonzero(status == STATUS_MISSING)
    done = n - len(missing)
    already = done
    fixed = tuple(sorted(spec.fixed().items()))
    names, values = spec.dims, tuple(v for _, v in spec.parameters)
    chunk_of = missing // chunk_size
    inputs = spec.input_files()
    tasks = [
        ChunkTask(
            point,
            names,
            values,
            fixed,
            tuple(int(i) for i in missing[chunk_of == c]),
            int(c),
            inputs,
            _code_text(),
        )
        for c in np.unique(chunk_of)
    ]
    if tasks:
        bar = None
        try:
            local = be.name == "processes" and be.workers > 1
            local |= be.name == "dask" and getattr(be, "scheduler", None) is None
            if local:
                # one point here first, its result not kept: the first sweep after an
                # install compiles the kernels once, in this process (the command line
                # says so on a terminal), and the local workers, forked from it or
                # started after it (loading its cache), inherit them; each had compiled
                # them itself (two workers: 122 s of CPU for the minute a compilation
                # takes). A cluster's workers elsewhere compile their own.
                _evaluate_points(replace(tasks[0], indices=tasks[0].indices[:1]))
            with be:
                if progress is True:
                    bar, bar_task = _progress_bar(n, done, f"sweep ({be.describe()})")
                    bar.start()
                for task, res in be.run(evaluate_chunk, tasks):
                    target.write(np.asarray(task.indices, dtype=np.int64), res)
                    done += len(task.indices)
                    if bar is not None:
                        bar.update(bar_task, completed=done)
                    elif callable(progress):
                        progress(done, n)
        except KeyboardInterrupt:
            raise SweepInterrupted(done, n, target.path) from None
        finally:
            if bar is not None:
                bar.stop()
    vals, stat, reasons = target.read()
    ds = _to_dataset(spec, vals, stat, reasons, store=target.path, backend=be.describe(),
                     code=code_identity() if store is not None else None)  # fmt: skip
    ds.attrs["points_computed"] = done - already
    return ds


def _to_dataset(spec: SweepSpec, vals, stat, reasons, *, store=None, backend="", code=None):
    import xarray as xr

    from ..metrics import METRIC_UNITS

    shape = spec.shape
    pspecs = spec.point_function.parameters
    coords = {}
    for name, v in spec.parameters:
        unit = getattr(pspecs.get(name), "unit", "")
        coords[name] = (name, np.asarray(v), {"units": unit} if unit else {})
    data = {}
    metrics = spec.point_function.metrics
    for j, name in enumerate(metrics):
        unit = METRIC_UNITS.get(name)
        attrs = {"units": unit} if unit else {}
        data[name] = (spec.dims, vals[:, j].reshape(shape), attrs)
    data["status"] = (
        spec.dims,
        np.asarray(stat, dtype=np.int8).reshape(shape),
        {"flag_values": np.array([0, 1, 2], dtype=np.int8), "flag_meanings": _STATUS_MEANINGS},
    )
    data["reason"] = (spec.dims, np.asarray(reasons, dtype=str).reshape(shape))
    attrs = {
        "point_function": spec.point,
        "config": json.dumps(spec.to_dict(), sort_keys=True),
        "config_hash": spec.config_hash(),
        "points": spec.size,
        "points_ok": int(np.sum(stat == STATUS_OK)),
        "points_failed": int(np.sum(stat == STATUS_FAILED)),
        "points_missing": int(np.sum(stat == STATUS_MISSING)),
    }
    for key, value in spec.fixed().items():
        if key in spec.dims:
            continue
        attrs[f"setting_{key}"] = value
    if spec.weights is not None:
        attrs["weights"] = json.dumps(spec.weights.to_dict())
    if store:
        attrs["store"] = str(store)
    if code is not None:  # the code that computed a store's points
        attrs["code"] = json.dumps(code, sort_keys=True)
    if backend:
        attrs["backend"] = backend
    return xr.Dataset(data, coords=coords, attrs=attrs)


def load_sweep(store: str | os.PathLike):
    """Read a sweep store (complete or partial) as an :class:`xarray.Dataset`.

    Its inputs are described by the digests it recorded; they are not read again. The
    attribute ``code`` (JSON) names the code that computed its points, whatever code
    reads it now (only a resume refuses other code's store)."""
    import zarr

    path = Path(store)
    try:
        group = zarr.open_group(str(path), mode="r")
        attrs = dict(group.attrs)
    except Exception:  # noqa: BLE001
        raise DataFileError(path, "is not a readable sweep store") from None
    if attrs.get("format") != _FORMAT:
        raise DataFileError(path, "is not a sweep store (no inerterlab sweep attributes)")
    try:
        cfg = attrs["config"]
        spec = sweep_spec(
            cfg["point"],
            parameters=cfg["parameters"],
            settings=cfg["settings"],
            weights=cfg["weights"],
            inputs=cfg.get("inputs") or {},
        )
        metrics = list(attrs["metrics"])
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        if isinstance(exc, DataFileError):
            raise
        raise _damaged(path, "config (attribute)", exc) from None

    def read(name):
        try:
            return np.asarray(group[name][:])
        except Exception as exc:  # noqa: BLE001
            raise _damaged(path, name, exc) from None

    arrays = {name: read(name) for name in (*metrics, "status", "reason")}
    for name, arr in arrays.items():
        if arr.shape[0] != spec.size:
            raise _damaged(path, name, ValueError(f"{arr.shape[0]} points, not {spec.size}"))
    vals = np.stack([arrays[m] for m in metrics], axis=1)
    reasons = _decode_reasons(arrays["reason"])
    _check_consistent(path, metrics, vals, arrays["status"], reasons)
    return _to_dataset(spec, vals, arrays["status"], reasons, store=str(path),
                       code=attrs.get("code"))  # fmt: skip


def save_netcdf(ds, path: str | os.PathLike) -> Path:
    """Write ``ds`` to a netCDF file atomically (temporary file and rename).

    netCDF-4 through h5netcdf when h5py is installed, else classic netCDF through scipy.
    """
    from ..io import atomic_path

    with atomic_path(path, suffix=".nc", option="--netcdf") as tmp:
        try:
            ds.to_netcdf(tmp, engine="h5netcdf")
        except ImportError:  # h5netcdf without h5py: classic netCDF through scipy
            ds.to_netcdf(tmp, engine="scipy")
    return Path(path)
