"""One BLAS thread for the set-up of a simulation (inerterlab._blas)."""

import pytest
import threadpoolctl

from inerterlab._blas import one_blas_thread


def _blas_threads():
    return [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]


def test_one_thread_inside_and_the_limits_back_after():
    import scipy.linalg  # noqa: F401  (both BLAS copies loaded)

    before = _blas_threads()
    assert before  # numpy's BLAS at least

    @one_blas_thread
    def inside(x):
        return x + 1, _blas_threads()

    out, seen = inside(1)
    assert out == 2
    assert seen and all(n == 1 for n in seen)
    assert _blas_threads() == before


def test_the_limits_come_back_after_an_error():
    before = _blas_threads()

    @one_blas_thread
    def fails():
        raise ValueError("x")

    with pytest.raises(ValueError):
        fails()
    assert _blas_threads() == before
