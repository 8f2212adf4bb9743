"""Which code computed a stored result: the package's files and the libraries' versions.

Every store of results (the reproduction's resume cache, a sweep's zarr store and so the
design study's stages) records :func:`code_identity` and reuses nothing computed by other
code: an edit to any file of the package (its source or the data it reads: the thesis
tables, the example vehicle, the errata) or an upgrade of a library that computes the
numbers makes a stored result another input's.

(The compiled kernels' numba cache has its own stamp,
:func:`inerterlab._numba_cache.package_source_stamp`: the ``.py`` files alone, taken at
import, because it names the machine code of the source the process runs.)
"""

from __future__ import annotations

import hashlib
import importlib.metadata as md
from functools import lru_cache
from pathlib import Path

__all__ = ["LIBRARIES", "code_identity", "describe_change", "source_hash"]

#: the package folder whose files key the stores (a test may point it elsewhere)
_ROOT = Path(__file__).resolve().parent
#: libraries whose version is part of the identity: they compute or draw the numbers
LIBRARIES = ("numpy", "scipy", "numba", "pandas", "matplotlib", "sympy", "xarray")


def _package_files(root: Path) -> list[Path]:
    return sorted(
        p
        for p in root.rglob("*")
        if p.is_file()
        and "__pycache__" not in p.parts
        and not p.name.startswith(".")
        and p.suffix not in (".pyc", ".nbi", ".nbc")
    )


@lru_cache(maxsize=4)
def _tree_hash(root: Path) -> str:
    h = hashlib.sha256()
    for p in _package_files(root):
        h.update(p.relative_to(root).as_posix().encode() + b"\0")
        h.update(p.read_bytes() + b"\0")
    return h.hexdigest()


def source_hash() -> str:
    """SHA-256 of every file of the installed package (path and content): the code and
    the data files it reads (compiled caches left out)."""
    return _tree_hash(_ROOT)


@lru_cache(maxsize=1)
def package_version() -> str:
    try:
        return md.version("inerterlab")
    except md.PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "unknown"


@lru_cache(maxsize=1)
def _versions() -> tuple:
    out = []
    for name in LIBRARIES:
        try:
            out.append((name, md.version(name)))
        except md.PackageNotFoundError:
            out.append((name, None))
    return tuple(out)


def library_versions() -> dict:
    """The versions of :data:`LIBRARIES` this process loaded (read once: a library
    upgraded while it runs is not the one it computes with)."""
    return dict(_versions())


def code_identity() -> dict:
    """``{"inerterlab": version, "source": source_hash(), "libraries": {name: version}}``:
    what a stored result was computed by (plain JSON data)."""
    return {
        "inerterlab": package_version(),
        "source": source_hash(),
        "libraries": library_versions(),
    }


def describe_change(old, new: dict | None = None) -> str:
    """What differs from a recorded identity ``old`` to ``new`` (default this process's),
    in a few words: ``"inerterlab's files ac1fd0a7aff0 -> 5e0c41b2d9a7"``,
    ``"numpy 2.3.0 -> 2.4.6"``; for a store made before stores recorded it, that it is not
    recorded."""
    new = code_identity() if new is None else new
    if not isinstance(old, dict):
        return "the code that made it is not recorded"
    diffs = []
    if old.get("inerterlab") != new["inerterlab"]:
        diffs.append(f"inerterlab {old.get('inerterlab')} -> {new['inerterlab']}")
    if old.get("source") != new["source"]:
        diffs.append(f"inerterlab's files {str(old.get('source'))[:12]} -> {new['source'][:12]}")
    libs = old.get("libraries") if isinstance(old.get("libraries"), dict) else {}
    for name in sorted(set(libs) | set(new["libraries"])):
        if libs.get(name) != new["libraries"].get(name):
            diffs.append(f"{name} {libs.get(name)} -> {new['libraries'].get(name)}")
    return "; ".join(diffs) or "the same code"
