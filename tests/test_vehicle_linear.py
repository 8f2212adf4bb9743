"""The linear vehicle is the core car about its Newton equilibrium (vehicles/linear.py).

Oracles: the hand-assembled M, C, K model (tests/_vehicle_oracle.py: its state space, transfer
functions, static loads and undamped frequencies), scipy's own evaluation of the core's
state space (scipy.signal.freqresp), the statics of a car on gas springs (every wheel's
contact force and the moment about the centre of gravity balance the weights), and the
full car on identical tracks against the half car that lumps its axles.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from _vehicle_oracle import build
from inerterlab.elements import GasSpring
from inerterlab.vehicles import (
    Corner,
    FullCar,
    HalfCar,
    NetworkStrut,
    Seat,
    Strut,
    Tyre,
    example_vehicle_path,
    load_vehicle,
)
from inerterlab.vehicles.frequency import frequency_response
from inerterlab.vehicles.linear import linear_vehicle

FREQ = np.geomspace(0.3, 30.0, 23)


def _half(strut, seat=None):
    tyre = Tyre(stiffness=2.4e5, damping=200.0)
    return HalfCar(
        sprung_mass=1200.0, pitch_inertia=1500.0, cg_to_front=1.2, cg_to_rear=1.4, seat=seat,
        front=Corner(unsprung_mass=45.0, strut=strut, tyre=tyre),
        rear=Corner(unsprung_mass=40.0, strut=Strut(stiffness=25e3, damping=1800.0), tyre=tyre),
    )  # fmt: skip


SEAT = Seat(x=0.3, mass=75.0, stiffness=47e3, damping=1100.0)
CARS = {
    "full example": lambda: load_vehicle(example_vehicle_path()),
    "half example": lambda: load_vehicle(example_vehicle_path()).half_car(),
    "k|c|b": lambda: _half(Strut(stiffness=30e3, damping=1500.0, inertance=120.0), SEAT),
    "k|(b-c)": lambda: _half(NetworkStrut("k | (b - c)", {"k": 30e3, "c": 2500.0, "b": 150.0}), SEAT),
}


@pytest.mark.parametrize("name", list(CARS))
def test_core_linear_vehicle_equals_the_assembled_model(name):
    """Every transfer function, the static tyre loads and (without internal nodes) the
    eigenvalues and undamped frequencies equal the hand-assembled model's to 1e-9."""
    p = CARS[name]()
    core, ref = linear_vehicle(p), build(p)
    assert not core.linearised and list(core.outputs) == list(ref.outputs)
    h, h0 = core.frequency_response(FREQ), ref.frequency_response(FREQ)
    for k in h0:
        assert np.abs(h[k] - h0[k]).max() <= 1e-9 * np.abs(h0[k]).max(), k
    for c, f in ref.static_tyre_loads().items():
        assert core.static_tyre_loads()[c] == pytest.approx(f, rel=1e-12)
    if core.plain:  # (a network's internal nodes are realised differently: fewer states)
        lam = np.sort_complex(np.linalg.eigvals(core.state_space()[0]))
        lam0 = np.sort_complex(np.linalg.eigvals(ref.state_space()[0]))
        assert np.abs(lam - lam0).max() <= 1e-9 * np.abs(lam0).max()
        for rigid in (True, False):
            np.testing.assert_allclose(core.natural_frequencies(rigid),
                                       ref.natural_frequencies(rigid), rtol=1e-9)  # fmt: skip


@pytest.mark.parametrize(("tracks", "axles", "speed"),
                         [("in-phase", None, 20.0), ("anti-phase", "anti-phase", None)])  # fmt: skip
def test_full_car_response_equals_the_state_space(tracks, axles, speed):
    """|H(j 2 pi f)| x amplitude from the modal form of the core full car's state space,
    H = C V diag(1 / (s - lambda)) V^-1 B + D (inputs: each road's height, rate and
    acceleration; no linear solve), equals the frequency response's amplitudes to 1e-9."""
    p = load_vehicle(example_vehicle_path())
    veh = linear_vehicle(p)
    fr = frequency_response(veh, FREQ, amplitude=0.015, tracks=tracks, axles=axles, speed=speed)
    sys = veh.system
    A, B, C, D = sys.linear_state_space()
    w = 2 * math.pi * FREQ
    s = 1j * w
    side = 1.0 if tracks == "in-phase" else -1.0
    rear = np.exp(-s * p.wheelbase / speed) if speed else -np.ones(w.size)
    pattern = np.column_stack([np.ones(w.size), side * np.ones(w.size), rear, side * rear])
    names = list(sys.output_names)
    lam, V = np.linalg.eig(A)
    VB = np.linalg.solve(V, B)
    want = {"heave": "bounce.x", "pitch": "pitch.x", "roll": "roll.x", "seat_acc": "seat.a"}
    for key, out in want.items():
        j = names.index(out)
        H = np.zeros(w.size, complex)
        for col in range(3 * 4):
            road, kind = divmod(col, 3)
            h = ((C[j] @ V) * VB[:, col] / (s[:, None] - lam)).sum(1) + D[j, col]
            H += h * s**kind * pattern[:, road]
        amp = 0.015 * np.abs(H)
        np.testing.assert_allclose(fr.amplitudes()[key], amp, rtol=1e-9, atol=1e-12 * amp.max())


def test_full_car_on_identical_tracks_equals_the_half_car():
    """Identical corners left and right, seat on the centre line, in-phase tracks: heave,
    pitch and seat acceleration equal the half car's to 1e-9, and no roll."""
    p = load_vehicle(example_vehicle_path())
    p = FullCar(**{**{k: getattr(p, k) for k in p.__dataclass_fields__},
                   "seat": Seat(x=0.25, y=0.0, mass=75.0, stiffness=47e3, damping=1100.0)})  # fmt: skip
    full = frequency_response(linear_vehicle(p), FREQ, speed=15.0)
    half = frequency_response(linear_vehicle(p.half_car()), FREQ, speed=15.0)
    for k in ("heave", "pitch", "seat_acc"):
        assert np.abs(full.transfer[k] - half.transfer[k]).max() <= 1e-9 * np.abs(half.transfer[k]).max()
    assert np.abs(full.transfer["roll"]).max() <= 1e-9 * np.abs(full.transfer["pitch"]).max()


def test_full_car_on_gas_springs_rests_on_the_nonlinear_balance():
    """Gas springs at every corner with anti-roll bars: the Newton equilibrium balances the
    weights to 1e-9 of the total weight, checked apart from the solver's own residual:
    the contact forces add up to the weight, and the front and rear axles' shares
    satisfy the moment balance about the centre of gravity."""
    p = load_vehicle(example_vehicle_path())
    gas = GasSpring(pressure=2.5e6, area=4e-3, volume=8e-4, exponent=1.3)
    corner = {ax: Corner(unsprung_mass=getattr(p, ax).unsprung_mass, tyre=getattr(p, ax).tyre,
                         strut=Strut(stiffness=5e3, damping=2000.0, device=gas))
              for ax in ("front", "rear")}  # fmt: skip
    p = FullCar(**{**{k: getattr(p, k) for k in p.__dataclass_fields__}, **corner, "seat": None})
    veh = linear_vehicle(p)
    eq = veh.equilibrium
    assert veh.linearised
    g = p.gravity
    weight = (p.sprung_mass + 2 * (p.front.unsprung_mass + p.rear.unsprung_mass)) * g
    assert eq.weight == pytest.approx(weight, rel=1e-12)
    loads = veh.static_tyre_loads()
    assert abs(sum(loads.values()) - weight) <= 1e-9 * weight
    front = loads["front_left"] + loads["front_right"] - 2 * p.front.unsprung_mass * g
    rear = loads["rear_left"] + loads["rear_right"] - 2 * p.rear.unsprung_mass * g
    assert abs(front * p.cg_to_front - rear * p.cg_to_rear) <= 1e-9 * weight * p.wheelbase
    # every gas spring is compressed by its share: at rest it carries no force about it
    for name, el in zip(veh.system.element_names, veh.system.elements, strict=True):
        if isinstance(el, GasSpring):
            assert el.operating_point < 0.0 and name in eq.forces
