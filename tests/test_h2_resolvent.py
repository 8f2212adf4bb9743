"""`h2.resolvent_solve`, the one frequency-domain solve of a state space, against a solve
per frequency, across the blocks it splits the frequencies into."""

import numpy as np
import pytest

from inerterlab import h2


@pytest.mark.parametrize("columns", [None, 3])
def test_equals_a_solve_per_frequency_across_blocks(monkeypatch, columns):
    rng = np.random.default_rng(3)
    n, nf = 7, 50
    A = rng.normal(size=(n, n)) - 3.0 * np.eye(n)
    s = 1j * np.geomspace(0.01, 100.0, nf)
    shape = (nf, n) if columns is None else (nf, n, columns)
    R = rng.normal(size=shape) + 1j * rng.normal(size=shape)
    want = np.array([np.linalg.solve(si * np.eye(n) - A, R[i]) for i, si in enumerate(s)])
    whole = h2.resolvent_solve(A, s, R)
    assert whole.shape == want.shape
    assert np.max(np.abs(whole - want)) <= 1e-12 * np.max(np.abs(want))
    # blocks of 2 frequencies (the last one short): the same numbers
    m = 1 if columns is None else columns
    monkeypatch.setattr(h2, "SOLVE_BLOCK_BYTES", 2 * 16 * n * (n + m))
    np.testing.assert_array_equal(h2.resolvent_solve(A, s, R), whole)


def test_a_system_without_states_gives_an_empty_solution():
    x = h2.resolvent_solve(np.zeros((0, 0)), np.array([1j, 2j]), np.zeros((2, 0)))
    assert x.shape == (2, 0)
