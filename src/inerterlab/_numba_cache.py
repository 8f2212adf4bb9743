"""On-disk cache of the compiled kernels, keyed on every source file of the package.

numba keys a cached function on the content of the file that defines it. A kernel also
compiles in what it uses from other modules: constants (the ``P_*`` slots of the packed
parameters), helper functions, the layout of arrays. After an edit to one of those
modules alone, numba would load the old machine code and run it silently against the new
Python side (a swap of two parameter slots in ``suspension/model.py`` once gave a
right-hand side 50 m/s^2 off).

This module registers, ahead of numba's own, a cache locator for the functions of this
package whose source stamp is a hash of *every* ``.py`` file of the package. Any edit
anywhere in the package invalidates every cached kernel; the next call compiles afresh
(about a minute for all kernels) and caches again. Functions of other packages keep
numba's default behaviour. It must be imported before any module that defines a cached
kernel, which ``inerterlab/__init__.py`` does first.
"""

from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

from numba.core import caching

__all__ = ["package_source_stamp", "PACKAGE_ROOT"]

#: numba's warning that first-class function types are experimental (the integrator's
#: right-hand side is one), as a pattern for ``warnings.filterwarnings`` (numba wraps the
#: text in terminal highlighting: the pattern allows a prefix)
FIRST_CLASS_WARNING = r".*First-class function type feature is experimental"

PACKAGE_ROOT = Path(__file__).resolve().parent


@functools.cache
def package_source_stamp() -> str:
    """sha256 over the names and contents of every ``.py`` file of the package, as they
    were when this process first asked: at the package's import (below), so the stamp
    names the source the process runs. Read again later, an edit made while a process
    runs would file the old machine code it compiles under the new source's stamp, and
    every later process would load that stale code."""
    h = hashlib.sha256()
    for f in sorted(PACKAGE_ROOT.rglob("*.py")):
        h.update(str(f.relative_to(PACKAGE_ROOT)).encode())
        h.update(b"\0")
        h.update(f.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def _in_package(py_file: str) -> bool:
    try:
        Path(py_file).resolve().relative_to(PACKAGE_ROOT)
    except (ValueError, OSError):
        return False
    return True


class PackageSourceLocator(caching._CacheLocator):
    """Cache next to the source (``__pycache__``) or in the user cache, stamped by the
    whole package's sources."""

    def __init__(self, py_func, py_file: str, cache_path: str):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = cache_path

    def get_cache_path(self) -> str:
        return self._cache_path

    def get_source_stamp(self):
        return package_source_stamp()

    def get_disambiguator(self) -> str:
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func, py_file):
        if not _in_package(py_file):
            return None
        user = os.environ.get("NUMBA_CACHE_DIR")
        candidates = []
        if user:
            candidates.append(os.path.join(user, cls.get_suitable_cache_subpath(py_file)))
        candidates.append(os.path.join(os.path.dirname(py_file), "__pycache__"))
        candidates.append(
            os.path.join(
                os.path.expanduser("~"),
                ".cache",
                "inerterlab-numba",
                cls.get_suitable_cache_subpath(py_file),
            )
        )
        for path in candidates:
            self = cls(py_func, py_file, path)
            try:
                self.ensure_cache_path()
            except OSError:
                continue
            return self
        return None


def _install() -> None:
    impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # renamed in numba 0.6x
    classes = impl._locator_classes
    if PackageSourceLocator not in classes:
        classes.insert(0, PackageSourceLocator)


_install()


package_source_stamp()  # the source this process imports
