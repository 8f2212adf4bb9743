"""Observers integrated as states (systems/observers.py) against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inerterlab.excitation import bump, road_series, sine
from inerterlab.metrics import wk_state_space, wk_weighting
from inerterlab.systems import base_excited, quarter_car, rig
from inerterlab.systems.observers import Observer, energy, weighted, with_observers

A, F = 0.01, 2.0  # drive amplitude [m], frequency [Hz]
W = 2 * math.pi * F
K, C = 1e4, 100.0


def _rig(observers):
    return with_observers(rig("k | c", {"k": K, "c": C}), observers)


def test_rms_and_fourth_power_of_a_sine_drive():
    """int F^2 of the rig force F = k A sin + c A w cos over whole periods, and int x^4 =
    3/8 A^4 T, to 1e-9."""
    sys = _rig([
        Observer("f2", "square", {"k.force": 1.0, "c.force": 1.0}, scale=1.0),
        Observer("x4", "fourth", {"drive.x": 1.0}, scale=1e-8),
        Observer("xint", "integral", {"drive.x": 1.0}, scale=1e-3),
    ])  # fmt: skip
    T = 5.0
    res = sys.simulate(sine(A, F), T, rtol=1e-10)
    o = res.observed
    exact_f2 = 0.5 * T * ((K * A) ** 2 + (C * A * W) ** 2)
    assert o["f2"] == pytest.approx(exact_f2, rel=1e-9)
    assert o["x4"] == pytest.approx(3.0 / 8.0 * A**4 * T, rel=1e-9)
    assert abs(o["xint"]) < 1e-9 * A * T  # whole periods of a sine
    assert res.observed.keys() == {"f2", "x4", "xint"}


def test_peaks_located_between_steps():
    """The running peaks of +-x and of the force of a sine drive: their exact maxima
    (A, and A sqrt(k^2 + (c w)^2)) to 1e-9, wherever the steps fall (steps the size
    the force's integral asks for at a loose tolerance: a peak is located within the
    steps the states set)."""
    sys = _rig([
        Observer("f", "integral", {"k.force": 1.0}, scale=1.0),
        Observer("px", "peak", {"drive.x": 1.0}),
        Observer("nx", "peak", {"drive.x": -1.0}),
        Observer("pf", "peak", {"k.force": 1.0, "c.force": 1.0}),
    ])  # fmt: skip
    o = sys.simulate(sine(A, F), 1.3, rtol=1e-6).observed
    assert o["px"] == pytest.approx(A, rel=1e-9)
    assert o["nx"] == pytest.approx(A, rel=1e-9)
    assert o["pf"] == pytest.approx(A * math.hypot(K, C * W), rel=1e-9)


def test_wk_weighted_integral_against_the_frequency_domain():
    """The ISO 2631-1 Wk filter of the drive acceleration as observer states, started
    on its steady state: int a_w^2 over whole periods = T/2 |Wk(f)|^2 (A w^2)^2."""
    Af, Bf, Cf, Df = wk_state_space()
    obs, aw = weighted("wk", {"drive.a": 1.0}, Af, Bf, Cf, Df, scale=1e-1)
    sys = _rig([*obs, Observer("i_wk", "square", aw, scale=1e-2)])
    # steady state of z' = A z + B a with a = -A w^2 sin(w t) = Im(-A w^2 e^{jwt}): at t = 0
    zc = np.linalg.solve(1j * W * np.eye(Af.shape[0]) - Af, Bf) * (-A * W * W)
    x0 = np.concatenate([zc.imag, [0.0]])
    T = 10.0
    res = sys.simulate(sine(A, F), T, rtol=1e-10, x0=x0)
    exact = 0.5 * T * abs(wk_weighting(F)) ** 2 * (A * W * W) ** 2
    assert res.observed["i_wk"] == pytest.approx(exact, rel=1e-8)


@pytest.mark.parametrize("suspension", ["traditional", "afw", "device-afw"])
def test_energy_balance(suspension):
    """The energy ledger: the work of the road equals the work done on every element
    and mass (stored plus dissipated), to 1e-8 of the input, on a nonlinear car too."""
    car = quarter_car(suspension)
    sys = with_observers(car, energy(car, scale=1e-4))
    res = sys.simulate(bump(height=0.05, edge="ramp", edge_width=0.01), 2.0, rtol=1e-11,
                       x0=sys.initial_state())  # fmt: skip
    o = res.observed
    parts = sum(v for k, v in o.items() if k != "energy.input")
    assert o["energy.input"] != 0.0
    assert parts == pytest.approx(o["energy.input"], rel=1e-8)
    # each element's share has its sign: dampers dissipate
    assert o["energy.c"] > 0 and o["energy.tyre_c"] > 0
    # the springs and masses hold at the end what the states say they hold
    xw, vw, xb, vb = (res.states[-1, car.state_names.index(n)]
                      for n in ("wheel.x", "wheel.v", "body.x", "body.v"))  # fmt: skip
    m = car.info["car"]
    assert o["energy.body"] == pytest.approx(0.5 * m["sprung_mass"] * vb**2, rel=1e-7, abs=1e-9)
    assert o["energy.wheel"] == pytest.approx(0.5 * m["unsprung_mass"] * vw**2, rel=1e-7, abs=1e-9)
    if suspension == "traditional":
        assert o["energy.k"] == pytest.approx(0.5 * 9e4 * (xb - xw) ** 2, rel=1e-7, abs=1e-9)


def test_observer_errors():
    with pytest.raises(Exception, match="signal"):
        _rig([Observer("q", "square", {"nowhere.x": 1.0})])
    with pytest.raises(Exception, match="kind"):
        Observer("q", "cube", {"drive.x": 1.0})


# ---------------------------------------------------------------------------------------
# observers on the exact (matrix-exponential) steps

X0, PHI = 0.01, 0.3  # amplitude [m] and phase [rad] of a free undamped oscillation
M_OSC, F_OSC = 10.0, 2.0  # mass [kg], natural frequency [Hz]


def _flat(T):
    return road_series([0.0, T + 1.0], [0.0, 0.0])


def _oscillator(observers):
    """A mass on a spring over a base at rest, oscillating freely: x = X0 cos(w t + phi)
    (a linear system on a piecewise-linear road: exact steps)."""
    w = 2 * math.pi * F_OSC
    sys = with_observers(base_excited(M_OSC, "k", {"k": M_OSC * w * w}), observers)
    x0 = np.zeros(sys.n_states)
    x0[:2] = X0 * math.cos(PHI), -X0 * w * math.sin(PHI)
    return sys, x0, w


#: samples every 1 ms (exact steps of one quadrature panel) or only at the horizon
#: (steps of several panels, core.EXACT_OBSERVER_LONGEST apart)
SAMPLED = pytest.mark.parametrize("sparse", [False, True], ids=["1 kHz", "horizon only"])


def _times(T, sparse):
    return np.array([T]) if sparse else None


def _panels_used(res, sparse, T):
    """With samples at the horizon only, the steps hold several panels: fewer steps
    than panels of core.EXACT_OBSERVER_PANEL x its share."""
    from inerterlab.systems.core import EXACT_OBSERVER_PANEL

    if sparse:
        assert res.stats["exact_steps"] < 0.5 * T / EXACT_OBSERVER_PANEL


@SAMPLED
def test_exact_steps_fourth_power_square_and_peaks_of_a_sine(sparse):
    """On the exact path: int x^4 = 3/8 X0^4 T and int v^2 = (X0 w)^2 T / 2 over whole
    periods, the peak of x (between samples) = X0, to 1e-10; with samples every 1 ms
    and with one sample at the horizon (exact steps of several quadrature panels)."""
    sys, x0, w = _oscillator([
        Observer("x4", "fourth", {"body.x": 1.0}, scale=1e-8),
        Observer("v2", "square", {"body.v": 1.0}, scale=1e-2),
        Observer("px", "peak", {"body.x": 1.0}),
        Observer("pv", "peak", {"body.v": -1.0}),
    ])  # fmt: skip
    T = 5.0  # ten periods
    res = sys.simulate(_flat(T), T, x0=x0, times=_times(T, sparse))
    assert res.method == "exact"
    _panels_used(res, sparse, T)
    o = res.observed
    assert o["x4"] == pytest.approx(3.0 / 8.0 * X0**4 * T, rel=1e-10)
    assert o["v2"] == pytest.approx(0.5 * (X0 * w) ** 2 * T, rel=1e-10)
    assert o["px"] == pytest.approx(X0, rel=1e-10)
    assert o["pv"] == pytest.approx(X0 * w, rel=1e-10)


@SAMPLED
def test_exact_steps_wk_integral_against_the_frequency_domain(sparse):
    """On the exact path: the Wk filter of a pure sine acceleration (the oscillator's),
    started on its steady state, int a_w^2 over whole periods = T/2 |Wk(f)|^2 (X0 w^2)^2
    to 1e-10 (samples every 1 ms, or at the horizon only)."""
    Af, Bf, Cf, Df = wk_state_space()
    obs, aw = weighted("wk", {"body.a": 1.0}, Af, Bf, Cf, Df, scale=1e-1)
    sys, x0, w = _oscillator([*obs, Observer("i_wk", "square", aw, scale=1e-2)])
    # a = Re(-X0 w^2 e^{j(w t + phi)}): the filter's steady state at t = 0
    zc = np.linalg.solve(1j * w * np.eye(Af.shape[0]) - Af, Bf) * (-X0 * w * w * np.exp(1j * PHI))
    x0[2 : 2 + Af.shape[0]] = zc.real
    T = 5.0
    res = sys.simulate(_flat(T), T, x0=x0, times=_times(T, sparse))
    assert res.method == "exact"
    _panels_used(res, sparse, T)
    exact = 0.5 * T * abs(wk_weighting(F_OSC)) ** 2 * (X0 * w * w) ** 2
    assert res.observed["i_wk"] == pytest.approx(exact, rel=1e-10)


@SAMPLED
def test_exact_steps_square_against_the_lyapunov_value(sparse):
    """On the exact path: a linear car's free decay from a displaced body, int (C x)^2
    over [0, T] = x0' (P - e^{A'T} P e^{AT}) x0 with A'P + PA + C'C = 0, for the body
    acceleration and the suspension deflection, to 1e-10 (samples every 1 ms, or at the
    horizon only)."""
    from scipy.linalg import expm, solve_continuous_lyapunov

    car = quarter_car("k | c", {"k": 3e4, "c": 1.5e3})
    sys = with_observers(car, [
        Observer("i_acc", "square", {"body.a": 1.0}, scale=1e-2),
        Observer("i_defl", "square", {"body.x": 1.0, "wheel.x": -1.0}, scale=1e-6),
    ])  # fmt: skip
    A, _, Cm, _ = car.linear_state_space()
    x = car.initial_state(body=0.03)
    T = 1.5
    res = sys.simulate(_flat(T), T, x0=np.r_[x, 0.0, 0.0], times=_times(T, sparse))
    assert res.method == "exact"
    _panels_used(res, sparse, T)
    E = expm(A * T)
    out = car.output_names
    rows = {"i_acc": Cm[out.index("body.a")], "i_defl": Cm[out.index("body.x")] - Cm[out.index("wheel.x")]}
    for name, c in rows.items():
        P = solve_continuous_lyapunov(A.T, -np.outer(c, c))
        exact = x @ (P - E.T @ P @ E) @ x
        assert res.observed[name] == pytest.approx(exact, rel=1e-10)


@pytest.mark.parametrize("metrics_only", [False, True], ids=["1 kHz", "metrics only"])
def test_observers_ride_the_exact_steps_of_the_linear_regimes(metrics_only):
    """The afw car (flywheel saturated through most of a 5 Hz sine) with its ride
    observers takes exact steps in its linear regimes, and its metrics agree with
    Dormand-Prince steps throughout at rtol 1e-11 to 1e-7; metrics only, its exact
    steps hold several quadrature panels each."""
    from inerterlab.systems.core import EXACT_FOURTH_POWER_SHARE, EXACT_OBSERVER_PANEL

    car = quarter_car("afw")
    ex = sine(0.05, 5.0)
    T = 2.0
    res = car.simulate(ex, T, metrics_only=metrics_only)
    if metrics_only:  # several panels to a step: fewer, longer exact steps
        assert 100 < res.stats["exact_steps"] < 0.5 * T / (
            EXACT_FOURTH_POWER_SHARE * EXACT_OBSERVER_PANEL
        )
    else:
        assert res.stats["exact_steps"] > 0.8 * res.stats["steps"]
    ref = car.simulate(ex, T, method="adaptive", rtol=1e-11)
    assert ref.stats["exact_steps"] == 0
    for k, v in ref.metrics.items():
        if isinstance(v, float):
            assert res.metrics[k] == pytest.approx(v, rel=1e-7), k


@pytest.mark.parametrize("network", ["afw", "k | c"])
def test_several_panels_keep_the_vdv_after_a_road_step(network):
    """A car over a 1 cm bump of 10 ms (the Wk filter rings at 100 Hz after each edge,
    the case that set the fourth power's panel): metrics only (exact steps of several
    panels: the linear car's throughout, the afw car's where its flywheel saturates)
    against 1 kHz samples (steps of one panel) to 1e-9, every metric."""
    from inerterlab.systems.core import EXACT_OBSERVER_PANEL

    car = quarter_car(network) if network == "afw" else quarter_car(network, {"k": 3e4, "c": 1.5e3})
    ex = bump(0.01, duration=0.01)
    T = 1.0
    few = car.simulate(ex, T, rtol=1e-10, metrics_only=True)
    full = car.simulate(ex, T, rtol=1e-10)
    if network != "afw":
        assert few.method == full.method == "exact"
        assert few.stats["exact_steps"] < 0.5 * T / EXACT_OBSERVER_PANEL < full.stats["exact_steps"]
    for k, v in full.metrics.items():
        if isinstance(v, float) and v:
            assert few.metrics[k] == pytest.approx(v, rel=1e-9), k


def test_one_rule_over_a_long_step_is_as_accurate_as_fine_samples():
    """The linear cfw car over the thesis bump (Wk's 100 Hz ringing after each edge):
    metrics only (exact steps up to 10 ms, each summed by one Gauss-Legendre rule of 15
    nodes) against samples every 0.1 ms (steps of 0.1 ms, five nodes each: their
    quadrature error is below round-off), every metric to 1e-12. Five nodes on each of
    the eight 1.25 ms panels were 7.2e-11 off in the VDV here (docs/decisions.md)."""
    from inerterlab import quarter_car as named_car
    from inerterlab.excitation import bump as thesis_bump
    from inerterlab.metrics import METRIC_KEYS
    from inerterlab.simulate import SimulationOptions, simulate, simulate_metrics

    car = named_car("cfw", sprung_mass=370.0)
    few = simulate_metrics(car, thesis_bump(), 5.0)
    fine = simulate(car, thesis_bump(), 5.0, options=SimulationOptions(sample_rate=10000.0)).metrics()
    for k in METRIC_KEYS:
        if isinstance(fine[k], float) and fine[k]:
            assert few[k] == pytest.approx(fine[k], rel=1e-12, abs=0.0), k


def test_observed_system_keeps_its_own_observers_after_its_base_ran():
    """A quarter car with a user observer, simulated after the plain car ran (which
    cached its ride system): the run carries both the user's observer and the ride
    metrics, and the observer equals the ride's own integral of a^2."""
    car = quarter_car("k | c", {"k": 3e4, "c": 1.5e3})
    ex = bump(height=0.05, edge="ramp", edge_width=0.01)
    plain = car.simulate(ex, 1.0)
    sys = with_observers(car, [Observer("mine", "square", {"body.a": 1.0}, scale=1e-2)])
    res = sys.simulate(ex, 1.0)
    assert "mine" in res.observed and "ride.i_acc" in res.observed
    assert res.observed["mine"] == pytest.approx(res.observed["ride.i_acc"], rel=1e-12)
    assert res.metrics["rms_body_acc"] == pytest.approx(plain.metrics["rms_body_acc"], rel=1e-12)
