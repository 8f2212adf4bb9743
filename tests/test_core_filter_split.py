"""The Wk filter advanced outside the Dormand-Prince stages (observers.filter_split,
_integrate._fz_step): exact over a step against the matrix exponential, the ride
metrics against the scipy reference at tight tolerance and against the filter carried
in the stages, and the step count it saves."""

from __future__ import annotations

import numpy as np
import pytest

import _quarter_car_oracle as oracle
from inerterlab import quarter_car
from inerterlab.excitation import bump, drop, sine
from inerterlab.metrics import METRIC_KEYS, wk_state_space
from inerterlab.simulate import SimulationOptions, simulate_metrics
from inerterlab.systems import _integrate
from inerterlab.systems.observers import NO_SPLIT, filter_split, ride, with_observers

NUMERIC = [k for k in METRIC_KEYS if k != "tyre_lift_off"]


def _ride_system():
    car = quarter_car("afw", changing_ratio=0.3)
    return with_observers(car, ride(car))


def _close(fast, ref, rtol, load):
    """Largest difference of the numeric metrics relative to each (the least tyre force:
    to the static load)."""
    worst = 0.0
    for k in NUMERIC:
        if ref[k] is None:  # not finite across a road step: both say so
            assert fast[k] is None, k
            continue
        scale = load if k == "min_tyre_force" else abs(ref[k])
        worst = max(worst, abs(fast[k] - ref[k]) / scale)
    assert fast["tyre_lift_off"] == ref["tyre_lift_off"]
    return worst


def test_split_of_the_ride_observers():
    """The eight Wk states and int a_w^2, int a_w^4 leave the stages; the filter reads
    the body's velocity state (w = z - B v), the stages keep int a^2, grip and
    deflection."""
    sys = _ride_system()
    oit, fzi, _, _ = filter_split(sys.itab, sys.ftab, sys.n_states)
    names = sys.state_names
    nf, m = fzi[0], fzi[1]
    assert [names[s] for s in fzi[5 : 5 + nf]] == [f"ride.wk.z{i}" for i in range(8)]
    assert [names[s] for s in fzi[5 + nf : 5 + nf + m]] == ["body.v"]
    assert oit[_integrate.I_NOB] == 3  # i_acc, i_grip, i_defl
    # a rig's drive acceleration is no state's derivative: nothing is split
    from inerterlab.systems import rig
    from inerterlab.systems.observers import weighted

    obs, aw = weighted("wk", {"drive.a": 1.0}, *wk_state_space())
    r = rig("k | (c - b)", {"k": 1e4, "c": 100.0, "b": 20.0})
    r = with_observers(r, obs)
    assert filter_split(r.itab, r.ftab, r.n_states)[1][0] == 0


def expm(M):
    """The matrix exponential to 30 digits (mpmath), as floats: the reference. scipy's
    double-precision expm of the filter's augmented matrix errs by up to 1.5e-11 of the
    result at |lam h| ~ 19, more than the filter step it checks (6e-13; stop 69)."""
    import mpmath

    with mpmath.workdps(30):
        E = mpmath.expm(mpmath.matrix(np.asarray(M, float).tolist()))
        return np.array([[float(E[i, j]) for j in range(E.cols)] for i in range(E.rows)])


@pytest.mark.parametrize("h", [1e-4, 2e-3, 3e-2, 0.4])
@pytest.mark.parametrize("thx", [1.0, 0.37])
def test_filter_step_is_exact_for_the_quartic_input(h, thx):
    """Over a step (cut at thx or not) the filter equals the matrix exponential of the
    Wk filter driven by the derivative of the body velocity's continuous extension, to
    1e-11 of its size, for |lam h| from 2e-4 to 250 (both ways of summing a mode)."""
    sys = _ride_system()
    n = sys.n_states
    _, fzi, fzf, fzc = filter_split(sys.itab, sys.ftab, n)
    nf, m, nq, nd = fzi[:4]
    slots = fzi[5 : 5 + nf]
    rng = np.random.default_rng(3)
    y = rng.standard_normal(n)
    ya = y + 0.1 * rng.standard_normal(n)
    K = rng.standard_normal((7, n))
    K[:, fzi[5 + nf + m + nq : 5 + nf + m + nq + nd]] = 0.0
    stc, stf = _integrate.fz_scratch(fzi)
    out = np.empty(n)
    _integrate._dense(y, ya, K, h, thx, out)
    itab = _integrate._readonly(sys.itab)
    ftab = _integrate._readonly(sys.ftab)
    _integrate._fz_step(fzi, fzf, fzc, stc, stf, itab, y, ya, K, h, thx, out)
    # reference: z' = A z + B a(tau), a the derivative of the body velocity's quartic
    A, B, _, _ = wk_state_space()
    B = np.ravel(B)
    hs = thx * h
    cf = stf[1 + fzi[4] + nf : 1 + fzi[4] + nf + 5 * m].reshape(5, m)[:, 0]
    M = np.zeros((12, 12))
    M[:8, :8] = A
    for k in range(4):  # a(tau) = sum (k + 1) cf_(k+1) tau^k / hs^(k+1), tau^k as states
        M[:8, 8 + k] = B * (k + 1) * cf[k + 1] / hs ** (k + 1)
        if k:
            M[8 + k, 7 + k] = k
    z0 = np.concatenate([y[slots], [1.0, 0.0, 0.0, 0.0]])
    ref = expm(M * hs) @ z0
    assert np.abs(out[slots] - ref[:8]).max() < 1e-11 * np.abs(ref[:8]).max()
    # the modes' values kept at the middle node (the peaks' midpoint reads them)
    mid = np.empty(n)
    _integrate._dense(y, ya, K, h, 0.5 * thx, mid)
    _integrate._fz_at(fzi, fzf, fzc, stc, stf, 0.5, mid, np.int64(2))
    ref_mid = (expm(M * 0.5 * hs) @ z0)[:8]
    assert np.abs(mid[slots] - ref_mid).max() < 1e-11 * np.abs(ref_mid).max()
    # the quadratures (int a_w^2, int a_w^4): five-node Gauss-Legendre sums of their
    # signals read by the generic observer code on the states at each node (the
    # continuous extension, the filter from the matrix exponential)
    from inerterlab.systems import _kernel as K_
    from inerterlab.systems.observers import _GL_W, _GL_X

    ob = itab[K_.I_OBS]
    for q in fzi[5 + nf + m : 5 + nf + m + nq]:
        kind, a, b, slot = (int(itab[ob + K_.OBS_W * q + c]) for c in range(4))
        total = 0.0
        for x, w in zip(_GL_X, _GL_W, strict=True):
            xn = np.empty(n)
            _integrate._dense(y, ya, K, h, x * thx, xn)
            xn[slots] = (expm(M * x * hs) @ z0)[:8]
            v = K_.signal(itab, ftab, np.zeros(64), xn, a)
            v = {K_.OBS_SQUARE: v * v, K_.OBS_FOURTH: v**4}.get(kind, None)
            if v is None:
                v = K_.signal(itab, ftab, np.zeros(64), xn, a) * K_.signal(itab, ftab, np.zeros(64), xn, b)
            total += w * v
        expect = y[slot] + hs * total
        assert abs(out[slot] - expect) <= 1e-11 * max(abs(expect), hs * abs(total)), (kind, slot)
    assert nq == 2


@pytest.mark.slow
@pytest.mark.parametrize("name", ["drop", "bump"])
def test_ride_metrics_against_tight_scipy_reference(name):
    """The afw car, 6 s (the flywheel settles and the steps grow long): every metric at
    rtol 1e-8 within 1e-7 of scipy's DOP853 at rtol 1e-12 on the independent equations
    (measured: at most 2e-8)."""
    car = quarter_car("afw", changing_ratio=0.3)
    ex = {"drop": drop(), "bump": bump()}[name]
    ref = oracle.simulate_metrics(car, ex, 6.0, rtol=1e-12)
    fast = simulate_metrics(car, ex, 6.0, options=SimulationOptions(rtol=1e-8))
    assert _close(fast, ref, 1e-7, (370.0 + 25.0) * 9.81) < 1e-7


@pytest.mark.parametrize("name", ["drop", "sine"])
def test_split_against_the_filter_in_the_stages(name, monkeypatch):
    """At rtol 1e-11 the metrics with the filter outside the stages equal those with it
    carried in the stages (two ways of integrating it) to 1e-8; at rtol 1e-8, once the
    flywheel settles after the drop, the adaptive steps are far fewer (the 100 Hz
    section no longer bounds them)."""
    car = quarter_car("afw", changing_ratio=0.3)
    ex = {"drop": drop(), "sine": sine()}[name]
    tight = SimulationOptions(rtol=1e-11)
    stats = []
    orig = _integrate.integrate

    def counted(*args, **kw):
        out = orig(*args, **kw)
        stats.append(args[13][0] - args[13][4])  # the Dormand-Prince steps
        return out

    monkeypatch.setattr(_integrate, "integrate", counted)
    split = simulate_metrics(car, ex, 3.0, options=tight)
    simulate_metrics(car, ex, 3.0)
    few = stats[-1]
    monkeypatch.setattr(
        _integrate, "_split_of", lambda itab, ftab, n: (_integrate._readonly(itab), *NO_SPLIT)
    )
    staged = simulate_metrics(car, ex, 3.0, options=tight)
    simulate_metrics(car, ex, 3.0)
    many = stats[-1]
    assert _close(split, staged, 1e-8, (370.0 + 25.0) * 9.81) < 1e-8
    if name == "drop":
        assert few < 0.5 * many, (few, many)


def test_split_kept_across_cars_of_a_sweep():
    """Two cars that differ in their masses (so in the tyre-grip quadrature's coefficient,
    their static tyre load) read the same tables: the key of the kept splits ignores
    what the split does not read, and the split computed for each is the same to the
    last bit. A coefficient it does read (the Wk quadrature's) changes the key."""
    from inerterlab.systems import observers as O

    systems = []
    for m, r in ((370.0, 0.3), (391.0, 0.45)):
        car = quarter_car("afw", sprung_mass=m, changing_ratio=r)
        systems.append(with_observers(car, ride(car)))
    a, b = systems
    assert not np.array_equal(a.ftab, b.ftab)
    assert O._filter_coefficients(a.itab, a.ftab) == O._filter_coefficients(b.itab, b.ftab)
    for x, y in zip(O._split(a.itab, a.ftab, a.n_states), O._split(b.itab, b.ftab, b.n_states),
                    strict=True):  # fmt: skip
        assert np.array_equal(x, y)
    O._SPLITS.clear()
    O._SPLITS_BY_TABLES.clear()
    got = filter_split(a.itab, a.ftab, a.n_states)
    assert filter_split(b.itab, b.ftab, b.n_states) is got and len(O._SPLITS) == 1
    # each car's tables are kept too: a run again finds its split without the key
    assert len(O._SPLITS_BY_TABLES) == 2
    assert filter_split(a.itab, a.ftab.copy(), a.n_states) is got
    assert len(O._SPLITS_BY_TABLES) == 2
    # the Wk quadrature's coefficient: read by the split, so in the key
    K = O._kernel
    it, ft = a.itab, a.ftab.copy()
    ob, sg, cf = int(it[K.I_OBS]), int(it[K.I_SG]), int(it[K.I_SGF])
    fz = filter_split(a.itab, a.ftab, a.n_states)[1]
    q = int(fz[5 + fz[0] + fz[1]])  # the first quadrature over the filter
    ft[cf + int(it[sg + it[ob + K.OBS_W * q + 1]])] *= 2.0
    assert O._filter_coefficients(it, ft) != O._filter_coefficients(a.itab, a.ftab)
    assert not np.array_equal(O._split(it, ft, a.n_states)[3], got[3])
