"""Vehicle H2 norms under white road velocity: the Wk filter as states, the wheelbase
delay exact, and the ``seat_wk`` objective of the vehicle optimiser."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inerterlab.iso2631 import WEIGHTINGS
from inerterlab.network_design import road_scale
from inerterlab.vehicles import example_vehicle_path, load_vehicle
from inerterlab.vehicles.design import h2_metrics, optimize_vehicle, vehicle_with
from inerterlab.vehicles.linear import linear_vehicle
from inerterlab.vehicles.spectral import white_velocity_h2

SPEED = 25.0


def _frequency_integral(veh, output, speed, weighting, nodes=48):
    """(1/2 pi) int |H(j w) W(j w)|^2 S_v dw over all w, summed over the tracks, from the
    vehicle's frequency response from wheel heights (divided by j w: from road velocity),
    the rear wheels' inputs delayed by wheelbase / speed; Gauss-Legendre with ``nodes``
    points on each of 400 logarithmic pieces from 1e-4 to 1e4 Hz (every piece spans a
    factor 1.047 of frequency, over which the integrand is smooth)."""
    tau = veh.parameters.wheelbase / speed
    tracks = [(0, 1)] if veh.kind == "half" else [(0, 2), (1, 3)]
    edges = np.geomspace(1e-4, 1e4, 401)
    u, wq = np.polynomial.legendre.leggauss(nodes)
    a, b = edges[:-1, None], edges[1:, None]
    x = (0.5 * (b - a) * u + 0.5 * (a + b)).ravel()
    wts = (0.5 * (b - a) * wq).ravel()
    h = veh.frequency_response(x, [output])[output]
    s = 2j * math.pi * x
    hu = h / s[:, None]
    d = np.exp(-s * tau)
    tot = sum(np.abs(hu[:, i] + hu[:, j] * d) ** 2 for i, j in tracks)
    if weighting:
        tot = tot * WEIGHTINGS[weighting].magnitude(x) ** 2
    return math.sqrt(2.0 * float(np.sum(wts * tot)))  # (1/2 pi) int dw = 2 int_0^inf df


@pytest.mark.parametrize("kind", ["full", "half"])
def test_seat_wk_equals_the_frequency_integral(kind):
    """The Lyapunov norm of the Wk-weighted seat acceleration (filter states, delay by
    e^(A tau)) equals the independent frequency-domain integral to 1e-8."""
    p = load_vehicle(example_vehicle_path())
    if kind == "half":
        p = p.half_car()
    veh = linear_vehicle(p)
    h = white_velocity_h2(
        veh, speed=SPEED, weighted={"seat_wk": ("seat_acc", "Wk"), "body_wk": ("bounce_acc", "Wk")}
    )
    for name, out, w in (("seat_wk", "seat_acc", "Wk"), ("body_wk", "bounce_acc", "Wk"),
                         ("seat_acc", "seat_acc", None)):  # fmt: skip
        ref = _frequency_integral(veh, out, SPEED, w)
        # the quadrature has converged: half the nodes give the same integral
        assert _frequency_integral(veh, out, SPEED, w, nodes=24) == pytest.approx(ref, rel=1e-12)
        assert h[name] == pytest.approx(ref, rel=1e-8), name


def test_the_delay_matters_and_without_speed_the_wheels_are_independent():
    veh = linear_vehicle(load_vehicle(example_vehicle_path()))
    delayed = white_velocity_h2(veh, speed=SPEED, outputs=["pitch_acc"])["pitch_acc"]
    indep = white_velocity_h2(veh, outputs=["pitch_acc"])["pitch_acc"]
    assert abs(delayed / indep - 1.0) > 0.01


def test_infinite_norms_say_why():
    veh = linear_vehicle(load_vehicle(example_vehicle_path()))
    h = white_velocity_h2(veh, speed=SPEED)
    assert h["front_left_tyre_load"] == math.inf
    why = h.reasons["front_left_tyre_load"]
    assert "feed-through" in why and "0.01-10 cycle/m" in why and "\n" not in why
    assert math.isfinite(h["seat_acc"]) and "seat_acc" not in h.reasons


def test_seat_wk_rms_scales_with_the_road():
    p = load_vehicle(example_vehicle_path())
    m = h2_metrics(p, "C", SPEED, ["seat_wk"])["seat_wk"]
    veh = linear_vehicle(p)
    h = white_velocity_h2(veh, speed=SPEED, weighted={"s": ("seat_acc", "Wk")}, outputs=[])
    assert m == pytest.approx(h["s"] * road_scale("C", SPEED), rel=1e-14)


@pytest.fixture(scope="module")
def optimum():
    return optimize_vehicle(objective="seat_wk", road_class="C", speed=SPEED, starts=3, seed=0)


def test_seat_wk_optimum_not_beaten_on_a_grid(optimum):
    """No point of a 5 x 5 grid of +-2 % and +-10 % around the optimum dampers beats it."""
    base = load_vehicle(example_vehicle_path())
    best = optimum.value
    assert optimum.feasible and not optimum.at_bound
    assert best < optimum.baseline["seat_wk"]
    p = optimum.parameters
    for f in (0.9, 0.98, 1.0, 1.02, 1.1):
        for r in (0.9, 0.98, 1.0, 1.02, 1.1):
            car = vehicle_with(base, front_damping=p["front_damping"] * f,
                               rear_damping=p["rear_damping"] * r)  # fmt: skip
            v = h2_metrics(car, "C", SPEED, ["seat_wk"])["seat_wk"]
            assert v >= best * (1 - 1e-9), (f, r, v, best)


def test_seat_wk_optimum_does_not_depend_on_the_start(optimum):
    other = optimize_vehicle(objective="seat_wk", road_class="C", speed=SPEED, starts=3, seed=11)
    assert other.value == pytest.approx(optimum.value, rel=1e-6)
    for k, v in optimum.parameters.items():
        assert other.parameters[k] == pytest.approx(v, rel=1e-2), k


def test_seat_wk_needs_a_seat():
    from inerterlab.errors import ParameterError

    p = load_vehicle(example_vehicle_path())
    import dataclasses

    with pytest.raises(ParameterError, match="seat"):
        h2_metrics(dataclasses.replace(p, seat=None), "C", SPEED, ["seat_wk"])
