"""The vehicle's right-hand side with its mass matrix factored beforehand
(systems/_kernel.py: dense_tables, _dense_solve; used by systems.vehicle.simulate).

Oracles: the kernel's own evaluation, which assembles and solves the whole mass matrix
at every call (the same forces, another route to the accelerations), at random states
and held sides; and a tight integration of the car on those tables.
"""

from __future__ import annotations

import numpy as np
import pytest

from inerterlab.elements import BumpStop, HydraulicElement, Inerter
from inerterlab.systems import _kernel
from inerterlab.systems.vehicle import simulate, vehicle
from inerterlab.vehicles import (
    Strut,
    example_vehicle_path,
    generate_tracks,
    loads_vehicle,
    road_inputs,
    road_spectrum,
)
from inerterlab.vehicles.linear import linear_vehicle

ADAPTIVE = (
    'adaptive = { flywheel = "nylon", changing_ratio = 0.285, law = "thesis", '
    'rest_inertance = "150 kg" }\n'
)


def _afw_params(inertance="0 kg"):
    text = example_vehicle_path().read_text()
    text = text.replace('inertance = "0 kg"\n', f'inertance = "{inertance}"\n' + ADAPTIVE)
    return loads_vehicle(text)


def _evaluate(itab, ftab, x, road):
    W = np.empty(_kernel.work_size(itab))
    dx = np.empty(x.size)
    assert _kernel.evaluate(0.0, x, road, itab, ftab, W, dx, np.empty(0))
    nn, ne = int(itab[_kernel.I_NN]), int(itab[_kernel.I_NE])
    return dx, W[: 3 * nn + ne]


def _hydraulic_front(p):
    from dataclasses import replace

    front = Strut(stiffness=p.front.strut.stiffness, damping=p.front.strut.damping,
                  device=HydraulicElement())  # fmt: skip
    return replace(p, front=replace(p.front, strut=front))


CARS = {
    # adaptive inerters at four corners
    "afw": lambda: vehicle(_afw_params()),
    # a constant inerter beside each adaptive one: into the factor
    "afw + b": lambda: vehicle(_afw_params("80 kg")),
    # the hydraulic device: its internal node's only inertance is its flywheel's
    "hydraulic": lambda: vehicle(_hydraulic_front(_afw_params())),
    # an inerter in series with a damper: an internal node of inertance only
    "c - b": lambda: vehicle(_afw_params(), networks={"rear": (
        "k | (c - b)", {"k": 30e3, "c": 2500.0, "b": Inerter(inertance=150.0)})}),
    # a bump stop at the rear: a spring law with a switching function of its own
    "bump stop": lambda: vehicle(_afw_params(), networks={"rear": (
        "k | c | bump", {"k": 30e3, "c": 2500.0,
                         "bump": BumpStop(stiffness=2e4, clearance=0.02)})}),
}  # fmt: skip


@pytest.mark.parametrize("name", CARS)
def test_factored_evaluation_equals_the_whole_solve(name):
    # random states and roads; held sides take each law on one side of its kink
    sys = CARS[name]()
    got = _kernel.dense_tables(sys.itab, sys.ftab)
    assert got is not None
    itab, ftab = got
    rng = np.random.default_rng(3)
    nlen = int(_kernel.road_layout_of(sys.itab)[0])
    hs = nlen - int(sys.itab[_kernel.I_NE])
    for trial in range(60):
        x = rng.normal(size=sys.n_states) * 0.05
        road = np.zeros(nlen)
        road[: hs - 1] = rng.normal(size=hs - 1) * 0.05
        if trial % 2:
            road[hs:] = rng.choice([-1.0, 1.0], size=nlen - hs)
        d0, w0 = _evaluate(sys.itab, sys.ftab, x, road)
        d1, w1 = _evaluate(itab, ftab, x, road)
        assert np.abs(d1 - d0).max() <= 1e-11 * np.abs(d0).max()
        ok = np.isfinite(w0)
        assert np.array_equal(ok, np.isfinite(w1))
        # the inertial forces m_e (a_top - a_bottom) carry the solve's rounding
        assert np.abs(w1[ok] - w0[ok]).max() <= 1e-10 * np.abs(w0[ok]).max()


def test_a_massless_node_keeps_the_whole_solve():
    # a spring in series with a damper: a node whose velocity the force balance sets
    sys = vehicle(_afw_params(), networks={"front": (
        "(k1 - c) | k2", {"k1": 20e3, "c": 3e3, "k2": 25e3})})  # fmt: skip
    assert _kernel.dense_tables(sys.itab, sys.ftab) is None


def test_factored_run_agrees_with_the_whole_solve_at_tight_tolerance():
    # the adaptive-flywheel full car over 2 s of class C at 20 m/s (tyres lift off,
    # flywheels saturate): the metrics of both routes at rtol 1e-11 agree to 1e-7
    p = _afw_params()
    car = linear_vehicle(loads_vehicle(example_vehicle_path().read_text()))
    dt, speed = 2e-3, 20.0
    x, zl, zr = generate_tracks(road_spectrum("C"), length=60.0, step=speed * dt, seed=11)
    r = road_inputs(car, x, zl, zr, speed, dt)[:1001]
    sys = vehicle(p)
    fast = simulate(sys, r, dt, rtol=1e-11)
    sys.info["factored"] = (sys.ftab, (sys.itab, sys.ftab))  # the whole solve per call
    whole = simulate(sys, r, dt, rtol=1e-11)
    assert fast.stats["events"] > 0
    for name, ref in whole.outputs.items():
        err = np.abs(fast.outputs[name] - ref).max() / np.abs(ref).max()
        assert err <= 1e-7, (name, err)


def _rhs_of(itab):
    """The per-structure right-hand side of ``itab`` (code written out statement by
    statement for factored tables, :func:`_kernel.dense_source`) as a callable."""
    import numba as nb

    from inerterlab.systems import _compiled

    spec = _compiled.specialised(itab)
    assert spec.specialised

    @nb.njit
    def call(ev, x, road, itab, ftab, W, dx, imp):
        return ev(0.0, x, road, itab, ftab, W, dx, imp)

    def of(ev):  # a whole evaluation; the switching functions alone with only=True; with
        # of_work=True those of the evaluation the work array holds (into dx)
        def f(*a, only=False, of_work=False, stage=False):
            imp = np.full(1, np.inf) if only else (_kernel.STAGE.copy() if stage else np.empty(0))
            return call(ev, *a, np.full(1, -np.inf) if of_work else imp)

        return f

    return of(spec), of(_compiled.generic())


@pytest.mark.parametrize("name", CARS)
def test_written_out_code_and_switches_equal_the_generic_evaluation(name):
    # the per-structure code of factored tables is evaluate's statements written out:
    # the same derivative, outputs and switching functions to the last bit; and the
    # switching functions from the nodes' motion alone (switches_at, and either code
    # called with SWITCHES_ONLY, which writes them into dx, the written-out code without
    # touching the work array) equal those after a whole
    # evaluation, bit for bit, at random states, roads and held sides; and either code
    # called with SWITCHES_OF_WORK gives switches() of the work array it is handed,
    # writing nothing else; called with STAGE, the same derivative to the last bit (the
    # written-out code without the work array's outputs, the generic one with them)
    sys = CARS[name]()
    itab, ftab = _kernel.dense_tables(sys.itab, sys.ftab)
    assert _kernel.dense_source(itab) is not None
    spec, generic = _rhs_of(itab)
    rng = np.random.default_rng(5)
    nlen = int(_kernel.road_layout_of(itab)[0])
    ne = int(itab[_kernel.I_NE])
    hs = nlen - ne
    nout = 3 * int(itab[_kernel.I_NN]) + ne
    assert not _kernel.switches_read_forces(itab, ftab)
    for trial in range(40):
        x = rng.normal(size=sys.n_states) * 0.05
        road = np.zeros(nlen)
        road[: hs - 1] = rng.normal(size=hs - 1) * 0.05
        if trial % 2:
            road[hs:] = rng.choice([-1.0, 0.0, 1.0], size=ne)
        if trial % 3 == 0:
            road = road[:hs]  # no held sides
        got = []
        for f in (generic, spec):
            W = np.full(_kernel.work_size(itab), 7.0)
            dx = np.full(x.size, 3.0)
            assert f(x, road, itab, ftab, W, dx)
            sw = np.empty(2 * ne)
            n = _kernel.switches(itab, ftab, W, sw)
            got.append((dx, W[:nout], sw, n))
        (d0, w0, s0, n0), (d1, w1, s1, n1) = got
        assert np.array_equal(d0, d1)
        assert np.array_equal(w0, w1, equal_nan=True)
        assert np.array_equal(s0, s1) and n0 == n1
        for f, whole in ((generic, True), (spec, False)):
            W = np.full(_kernel.work_size(itab), 7.0)
            dx = np.full(x.size, 3.0)
            assert f(x, road, itab, ftab, W, dx, stage=True)
            assert np.array_equal(dx, d0)
            # the outputs: the generic code's all there; the written-out code's none
            assert np.array_equal(W[:nout], w0, equal_nan=True) if whole else (W[:nout] == 7.0).all()
        for f in (generic, spec):
            W = np.full(_kernel.work_size(itab), 7.0)
            assert f(x, road, itab, ftab, W, np.full(x.size, 3.0))
            W0 = W.copy()
            sw = np.full(2 * ne, 5.0)
            assert f(x, road, itab, ftab, W, sw, of_work=True)
            assert np.array_equal(sw, s0) and np.array_equal(W, W0, equal_nan=True)
        sw = np.empty(2 * ne)
        n2 = _kernel.switches_at(x, road, itab, ftab, np.empty(_kernel.work_size(itab)), sw)
        assert np.array_equal(s0, sw) and n0 == n2 > 0
        for f, whole in ((generic, True), (spec, False)):
            W = np.full(_kernel.work_size(itab), 7.0)
            got = np.full(2 * ne, 3.0)
            assert f(x, road, itab, ftab, W, got, only=True)
            assert np.array_equal(got, s0)  # one call: the switching functions, into dx
            if whole:  # the generic code leaves the nodes' motion in the work array
                assert _kernel.switches(itab, ftab, W, sw) == n0 and np.array_equal(s0, sw)
            else:  # the written-out code computes them from its local variables alone
                assert (W == 7.0).all()


def test_a_clutch_switch_reads_the_force():
    # the one-way clutch's switching function is its torque: only the whole
    # right-hand side gives it
    from inerterlab.elements import OneWayClutch

    sys = vehicle(_afw_params(), networks={"rear": (
        "k | c | owc", {"k": 30e3, "c": 2500.0, "owc": OneWayClutch()})})  # fmt: skip
    assert _kernel.switches_read_forces(sys.itab, sys.ftab)
    afw = CARS["afw"]()
    assert not _kernel.switches_read_forces(afw.itab, afw.ftab)


def _written_solve(m):
    """:func:`_kernel.solve_source` (m) compiled as a function of (C, r, out): the
    matrix and the right-hand side in, the solution into ``out``; returns ``sol``."""
    import math

    import numba as nb

    head = [f"c{i}_{j} = C[{i}, {j}]" for i in range(m) for j in range(m)]
    head += [f"w{i} = r[{i}]" for i in range(m)]
    tail = [f"out[{i}] = w{i}" for i in range(m)] + ["return sol"]
    body = "\n".join("    " + line for line in head + _kernel.solve_source(m) + tail)
    scope = {"math": math}
    exec(f"def solve(C, r, out):\n{body}\n", scope)
    return nb.njit(scope["solve"])



@pytest.mark.parametrize("m", [1, 2, 3, 4, 6])
def test_written_out_solve_equals_the_kernels_solve_bit_for_bit(m):
    # the capacitance solve of the written-out right-hand side (solve_source) against
    # _kernel._solve on the same matrices: diagonally dominant ones (no row swap), ones
    # whose pivots need swaps, ties of magnitude (the first largest is the pivot),
    # zeros in the column (a factor skipped), singular and non-finite ones (False); and
    # the solution numpy's where the matrix is well conditioned
    import numba as nb

    written = _written_solve(m)

    @nb.njit
    def kernel(C, r):
        M = C.ravel().copy()
        x = r.copy()
        return _kernel._solve(M, 0, x, 0, C.shape[0]), x

    rng = np.random.default_rng(11)
    cases = []
    for trial in range(200):
        C = rng.normal(size=(m, m))
        if trial % 4 == 0:
            C += 5.0 * np.eye(m)  # dominant diagonal: no swap
        if trial % 5 == 1:
            C[:, 0] = np.round(C[:, 0])  # ties of magnitude in the first column
            C[rng.integers(m), 0] = 0.0
        if trial % 7 == 2 and m > 1:
            C[-1] = C[0]  # singular
        cases.append(C)
    cases += [np.zeros((m, m)), np.full((m, m), np.nan), np.eye(m)]
    swapped = 0
    for C in cases:
        r = rng.normal(size=m)
        ok0, x0 = kernel(C, r)
        out = np.full(m, 7.0)
        ok1 = written(C, r, out)
        assert ok0 == ok1
        if ok0:
            assert np.array_equal(x0, out)
            swapped += int(np.argmax(np.abs(C[:, 0])) != 0)
            if np.linalg.cond(C) < 1e6:  # and it solves the system (numpy's as oracle)
                assert np.allclose(out, np.linalg.solve(C, r), rtol=1e-9, atol=1e-12)
    assert m == 1 or swapped > 20  # the pivoting was exercised


def _stops_patterns(m):
    """Held sides of m flywheels: all on their stops, each alone away, the first two
    away, all away (1: on the stops, -1: below saturation)."""
    pats = [np.ones(m)]
    for k in range(m):
        p = np.ones(m)
        p[k] = -1.0
        pats.append(p)
    if m > 1:
        pats.append(np.r_[-1.0, -1.0, np.ones(m - 2)])
    pats.append(-np.ones(m))
    return pats


@pytest.mark.parametrize("m", [1, 2, 3, 4])
def test_flywheels_on_their_stops_skip_the_solve(m):
    # the factor takes each adaptive flywheel on its stops (factor_inertance): where a
    # flywheel is held there its departure from the factor is exactly 0; with all of
    # them there the accelerations are M0^-1 Q (no solve), with one away its unknown
    # alone, with two or more the whole pivoted elimination. Cars with m adaptive
    # corners (the others a spring and a damper); every pattern: the factored
    # evaluation equals the whole mass matrix's solve, and the written-out code equals
    # the generic one bit for bit
    from inerterlab.elements.adaptive_flywheel import factor_inertance, flywheel_inertance

    plain = ("k | c", {"k": 28e3, "c": 2200.0})
    corners = ["front_left", "front_right", "rear_left", "rear_right"]
    sys = vehicle(_afw_params(), networks={c: plain for c in corners[m:]})
    itab, ftab = _kernel.dense_tables(sys.itab, sys.ftab)
    db = int(itab[_kernel.I_DNS])
    assert int(itab[db + 1]) == m
    var = itab[db + 2 : db + 2 + m]
    eo = int(itab[_kernel.I_ELEM])
    for k, e in enumerate(var):  # on the stops: the law's own value at speed, to the bit
        o = int(itab[eo + _kernel.ELEM_W * e + 3])
        me = ftab[-m + k]
        assert me == factor_inertance(ftab, o) == flywheel_inertance(ftab, o, 5.0, 0.0, 0.0)[0]
        assert me > flywheel_inertance(ftab, o, 0.0, 0.0, 0.0)[0] > 0.0  # above rest
    spec, generic = _rhs_of(itab)
    rng = np.random.default_rng(8)
    nlen = int(_kernel.road_layout_of(itab)[0])
    ne = int(itab[_kernel.I_NE])
    hs = nlen - ne
    for stops in [p for p in _stops_patterns(m) for _ in range(6)]:
        x = rng.normal(size=sys.n_states) * 0.05
        road = np.zeros(nlen)
        road[: hs - 1] = rng.normal(size=hs - 1) * 0.05
        road[hs:] = rng.choice([-1.0, 1.0], size=ne)
        road[hs + var] = stops
        d0, w0 = _evaluate(sys.itab, sys.ftab, x, road)
        d1, w1 = _evaluate(itab, ftab, x, road)
        assert np.abs(d1 - d0).max() <= 1e-11 * np.abs(d0).max()
        ok = np.isfinite(w0)
        assert np.abs(w1[ok] - w0[ok]).max() <= 1e-10 * np.abs(w0[ok]).max()
        got = []
        for f in (generic, spec):
            W = np.full(_kernel.work_size(itab), 7.0)
            dx = np.full(x.size, 3.0)
            assert f(x, road, itab, ftab, W, dx)
            got.append(dx)
        assert np.array_equal(got[0], got[1])
