"""Model core: the tables of exact steps a new car computes (regime exponentials, the
observers' Taylor rows, the plan of exact steps) equal, to the last bit, what their
definitions give, and the plan kept across cars is the plan."""

import numpy as np
from scipy.linalg import expm

from inerterlab.excitation import bump, drop
from inerterlab.systems import quarter_car
from inerterlab.systems.core import (
    TAYLOR_TERMS,
    _exact_plan,
    _exact_plan_of,
    _expm_lengths,
    _step_tables,
)


def _taylor_one(M, S, h):
    """The Taylor rows of one length, term by term (the definition: S (M h)^k / k!,
    each term the last times M h / (k + 1), until two fall below 1e-18 of the largest)."""
    rows = []
    P = S.copy()
    big = np.abs(P).max()
    small = 0
    for k in range(TAYLOR_TERMS):
        rows.append(P)
        P = P @ (M * (h / (k + 1)))
        top = np.abs(P).max()
        big = max(big, top)
        small = small + 1 if top <= 1e-18 * big else 0
        if small == 2:
            break
    return np.array(rows).transpose(1, 0, 2)


def _system(seed=5, n=8):
    rng = np.random.default_rng(seed)
    M = rng.normal(size=(n, n)) * 300.0 - 400.0 * np.eye(n)
    S = rng.normal(size=(3, n))
    return M, S


def test_taylor_rows_of_power_of_two_lengths_equal_their_own_chains():
    """Lengths H, H/2, ..., H/64 (one chain of products, scaled) and two lengths of
    their own: every length's rows equal its own chain's to the last bit, zero past
    its own last term."""
    M, S = _system()
    q = 1e-11
    hs = np.r_[np.rint(0.01 / 2.0 ** np.arange(7)[::-1] / q) * q, 0.0031, 0.0047]
    hs = np.sort(hs)
    TR = _step_tables(M, S, hs)[0]
    assert TR.shape[2] == max(_taylor_one(M, S, h).shape[1] for h in hs)
    for j, h in enumerate(hs):
        own = _taylor_one(M, S, h)
        k = own.shape[1]
        assert np.array_equal(TR[j, :, :k], own)
        assert not TR[j, :, k:].any()


def test_taylor_rows_fall_back_where_scaling_would_leave_the_normal_range():
    """A family whose scaled products would underflow (a tiny entry of M): each length
    then runs its own chain, and the rows are still its own."""
    M, S = _system(seed=7)
    M[0, 1] = 1e-300
    hs = np.array([0.001, 0.002, 0.004])
    TR = _step_tables(M, S, hs)[0]
    for j, h in enumerate(hs):
        own = _taylor_one(M, S, h)
        assert np.array_equal(TR[j, :, : own.shape[1]], own)


def test_exponentials_square_up_each_family_of_lengths():
    """Lengths a power of two apart (a family) take scipy's expm of the shortest, squared
    up: each member equals that product to the last bit and scipy's expm of its own
    length to 1e-13 of its size; a length alone in its family is scipy's expm of it, 0
    the identity; a member's matrix does not depend on which other members are asked
    for, only on the family's shortest length."""
    M, S = _system(seed=11)
    h0 = 0.01 / 64
    fam = h0 * 2.0 ** np.arange(7)
    hs = np.r_[0.0, fam, 0.0031]
    E = _expm_lengths(M, hs)
    assert np.array_equal(E[0], np.eye(8))
    assert np.array_equal(E[-1], expm(M * 0.0031))
    P = expm(M * h0)
    for j, h in enumerate(fam):
        assert np.array_equal(E[1 + j], P)
        ref = expm(M * h)
        assert np.abs(E[1 + j] - ref).max() <= 1e-13 * np.abs(ref).max()
        P = P @ P
    some = _expm_lengths(M, fam[[0, 3, 6]])
    assert np.array_equal(some, E[[1, 4, 7]])


def test_plan_of_exact_steps_is_kept_by_content_across_cars():
    """Two cars of one structure (different masses) get the same plan of a road; a
    different road its own; the kept plan equals a fresh dry walk."""
    a = quarter_car("afw", sprung_mass=340.0, changing_ratio=0.2)
    b = quarter_car("afw", sprung_mass=390.0, changing_ratio=0.4)
    ts = np.array([10.0])
    sa = drop(0.05).prepared(10.0).segments
    sb = bump(0.05, duration=0.01).prepared(10.0).segments
    pa = _exact_plan(a, sa, 10.0, ts)
    assert _exact_plan(b, sa, 10.0, ts) is pa
    for x, y in zip(pa, _exact_plan_of(b, sa, 10.0, ts), strict=True):
        assert np.array_equal(x, y) and x.dtype == y.dtype
    pb = _exact_plan(a, sb, 10.0, ts)
    fresh = _exact_plan_of(a, sb, 10.0, ts)
    assert all(np.array_equal(x, y) for x, y in zip(pb, fresh, strict=True))
    assert pa[0].size and np.all(pa[0] > 0.0)


def test_regime_tables_read_the_system_once_and_equal_a_fresh_build():
    """The rows the observers read and the system's part of the exponentials' key are
    kept on the ride system: a second input on the car reads them again, and the tables
    equal, entry for entry, those of the same car built anew."""
    from inerterlab.systems.core import _exact_plan, _regime_tables, _ride_system

    ts = np.array([10.0])
    segs = drop(0.05).prepared(10.0).segments
    tables = []
    for _ in range(2):
        car = _ride_system(quarter_car("afw", sprung_mass=355.0, changing_ratio=0.25))
        got = _regime_tables(car, segs, 10.0, ts, _exact_plan(car, segs, 10.0, ts))
        kept = car.info["regime_read"]
        sb = bump(0.05, duration=0.01).prepared(10.0).segments
        _regime_tables(car, sb, 10.0, ts, _exact_plan(car, sb, 10.0, ts))
        assert car.info["regime_read"] is kept
        tables.append(got)
    a, b = tables
    assert len(a) == len(b) == 8
    for x, y in zip(a[:7] + a[7], b[:7] + b[7], strict=True):
        assert np.array_equal(x, y) and x.dtype == y.dtype


def test_point_rows_kept_per_length_in_the_integrators_layout():
    """The regime tables' point rows, kept per step length already in the layout the
    integrator sums over ([q, p nu + r]: :func:`core._point_layout`), and their Taylor
    rows padded to one table, equal those of one :func:`_step_tables` call over all the
    lengths, laid out afterwards, to the last bit."""
    from inerterlab.systems import core
    from inerterlab.systems.core import (
        _exact_plan,
        _point_layout,
        _points,
        _regime_read,
        _regime_system,
        _regime_tables,
        _ride_system,
    )

    car = _ride_system(quarter_car("afw", sprung_mass=362.0, changing_ratio=0.35))
    ts = np.array([10.0])
    segs = bump(0.05, duration=0.01).prepared(10.0).segments
    XE, _, keys, _, _, _, _, xo = _regime_tables(car, segs, 10.0, ts,
                                                 _exact_plan(car, segs, 10.0, ts))  # fmt: skip
    SR, TR = xo[1], xo[6]
    n, a, b, gx, gu, sx, su = _regime_read(car, _regime_system(car))[3]
    A = np.frombuffer(a).reshape(n, n)
    B = np.frombuffer(b).reshape(n, 3)
    Sx = np.frombuffer(sx).reshape(-1, n)
    Su = np.frombuffer(su).reshape(-1, 3)
    hs = keys * core.EXACT_STEP_QUANTUM * 10.0
    npts = SR.shape[3] // Sx.shape[0]  # the panels the tables were built for
    m = next(k for k in range(1, 64) if _points(k).size == npts)
    M = np.zeros((n + 3, n + 3))  # the class of the road's linear segments (w = 0)
    M[:n, :n] = A
    M[:n, n:] = B @ np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    M[n, n + 1] = 1.0
    S = np.hstack([Sx, Su @ np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])])
    full = _expm_lengths(M, hs)
    tr, kj, R = _step_tables(M, S, hs, m, full)
    assert np.array_equal(XE[0], full[:, :n])
    assert np.array_equal(SR[0], _point_layout(R))
    assert TR.shape[3] == kj.max()
    assert np.array_equal(TR[0], tr[:, :, : kj.max()])
