"""One BLAS thread for the small dense linear algebra of a simulation's set-up.

A simulation's set-up multiplies and exponentiates matrices of a few dozen rows (the
matrix exponentials of exact steps, eigenvalues, state-space columns). OpenBLAS spreads
even such products over all its threads; on a machine whose cores are busy with other
work (a sweep's other worker, another job) the threads wait for each other, and one
``scipy.linalg.expm`` of four 15 x 15 matrices was measured at 170 ms instead of
0.2 ms. :func:`one_blas_thread` runs a function with every BLAS library loaded in the
process limited to one thread (threadpoolctl), and restores the limits after it.
"""

from __future__ import annotations

import functools
import threading

__all__ = ["one_blas_thread"]

_lock = threading.Lock()
_controller: list = []


def _get_controller():
    """The process's thread-pool controller, made once, after scipy's BLAS is loaded
    (numpy and scipy each load their own copy)."""
    if not _controller:
        with _lock:
            if not _controller:
                import scipy.linalg  # noqa: F401  (loads scipy's BLAS before the scan)
                from threadpoolctl import ThreadpoolController

                _controller.append(ThreadpoolController())
    return _controller[0]


def one_blas_thread(fn):
    """Decorator: ``fn`` runs with one BLAS thread (see the module docstring)."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with _get_controller().limit(limits=1, user_api="blas"):
            return fn(*args, **kwargs)

    return wrapper
