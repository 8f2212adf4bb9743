"""Half and full cars as systems of the model core (systems/vehicle.py).

Oracles: the linear vehicle model (tests/_vehicle_oracle.py: M, C, K assembled by hand, its
own frequency response and state space), the core quarter car (a separate template),
and the symmetry of a full car on identical tracks (the half car that lumps each axle).
The time simulation's oracles are in tests/test_vehicle_time.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from _vehicle_oracle import build
from inerterlab.elements import AdaptiveFlywheelInerter, HydraulicElement, Inerter
from inerterlab.errors import ParameterError
from inerterlab.networks import NetworkError
from inerterlab.systems import quarter_car
from inerterlab.systems.vehicle import full_car, half_car, simulate, vehicle
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
from inerterlab.vehicles.roads import generate_tracks, road_spectrum
from inerterlab.vehicles.spectral import road_inputs

FREQ = np.array([0.3, 1.1, 1.7, 4.0, 9.5, 14.0, 25.0])


def _core_response(sys, f):
    """name -> (n_f, n_roads) transfer from each road height to the vehicle outputs of
    the core's state space (inputs: height, rate, acceleration per road)."""
    A, B, C, D = sys.linear_state_space()
    names = list(sys.output_names)

    def row(n):
        j = names.index(n)
        return C[j], D[j]

    rows = {"bounce_acc": row("bounce.a"), "pitch_acc": row("pitch.a")}
    if "roll.a" in names:
        rows["roll_acc"] = row("roll.a")
    if "seat.a" in names:
        rows["seat_acc"] = row("seat.a")
    for st in sys.info["stations"]:
        cb, db = row(f"body_{st}.x")
        cw, dw = row(f"wheel_{st}.x")
        rows[f"{st}_deflection"] = (cb - cw, db - dw)
        ct, dt = row(f"{st}_tyre.force")
        rows[f"{st}_tyre_load"] = (-ct, -dt)
    m = sys.info["roads"]
    out = {k: np.zeros((f.size, m), complex) for k in rows}
    n = A.shape[0]
    for i, fi in enumerate(f):
        s = 2j * math.pi * fi
        u = np.array([1.0, s, s * s])
        X = np.linalg.solve(s * np.eye(n) - A, np.stack([B[:, 3 * k : 3 * k + 3] @ u for k in range(m)], 1))
        for k, (c, d) in rows.items():
            out[k][i] = c @ X + np.array([d[3 * j : 3 * j + 3] @ u for j in range(m)])
    return out


def _assert_responses_equal(core, ref, rtol=1e-9):
    for name, h in ref.items():
        scale = np.abs(h).max()
        err = np.abs(core[name] - h).max() / scale
        assert err < rtol, (name, err)


def _half(front_strut, rear_strut=None, seat=None, inertia=None):
    tyre = Tyre(stiffness=2.4e5, damping=200.0)
    rear = front_strut if rear_strut is None else rear_strut
    m, a, b = 1200.0, 1.2, 1.4
    return HalfCar(
        sprung_mass=m, pitch_inertia=m * a * b if inertia is None else inertia,
        cg_to_front=a, cg_to_rear=b, seat=seat,
        front=Corner(unsprung_mass=45.0, strut=front_strut, tyre=tyre),
        rear=Corner(unsprung_mass=40.0, strut=rear, tyre=tyre),
    )  # fmt: skip


def test_linear_full_car_equals_the_vehicle_model():
    """The packaged example (seat off the centre line, anti-roll bars): every transfer
    function, the eigenvalues and the static tyre loads of the core full car equal those
    of the hand-built M, C, K model to 1e-9."""
    p = load_vehicle(example_vehicle_path())
    car = build(p)
    sys = full_car(p, lift_off=False)
    assert sys.linear
    _assert_responses_equal(_core_response(sys, FREQ), car.frequency_response(FREQ))
    lam = np.sort_complex(np.linalg.eigvals(sys.linear_state_space()[0]))
    ref = np.sort_complex(np.linalg.eigvals(car.state_space()[0]))
    assert np.abs(lam - ref).max() < 1e-9 * np.abs(ref).max()
    loads = sys.info["static_tyre_loads"]
    for k, v in car.static_tyre_loads().items():
        assert loads[k] == pytest.approx(v, rel=1e-12)


@pytest.mark.parametrize(
    "strut",
    [
        Strut(stiffness=30e3, damping=1500.0, inertance=120.0),
        NetworkStrut("k | (c - b)", {"k": 30e3, "c": 2500.0, "b": 150.0}),
        NetworkStrut("k | (b - c)", {"k": 30e3, "c": 2500.0, "b": 150.0}),
        NetworkStrut("(k1 - c) | k2", {"k1": 20e3, "c": 3e3, "k2": 25e3}),
    ],
    ids=["k|c|b", "k|(c-b)", "k|(b-c)", "(k1-c)|k2"],
)
def test_linear_half_car_with_any_network_equals_the_vehicle_model(strut):
    """Inerters at the body point (the mass matrix coupled in bounce and pitch),
    internal nodes on either side, a seat: equal to the model's realisation to 1e-9.
    ``k | (b - c)`` has the inerter between the body-side terminal and an internal
    node, which the core places like any other."""
    seat = Seat(x=0.3, mass=75.0, stiffness=47e3, damping=1100.0)
    p = _half(strut, Strut(stiffness=25e3, damping=1800.0), seat=seat, inertia=1500.0)
    sys = half_car(p, lift_off=False)
    _assert_responses_equal(_core_response(sys, FREQ), build(p).frequency_response(FREQ))


def test_full_car_on_identical_tracks_equals_the_half_car():
    """Identical corners left and right, seat on the centre line: the full car's
    response to both tracks together (in phase) equals the half car that lumps each
    axle's two corners, to 1e-9 (roll and the anti-roll bars stay out of it)."""
    p = load_vehicle(example_vehicle_path())
    p = FullCar(**{**{k: getattr(p, k) for k in p.__dataclass_fields__},
                   "seat": Seat(x=0.25, y=0.0, mass=75.0, stiffness=47e3, damping=1100.0)})  # fmt: skip
    hf = _core_response(full_car(p, lift_off=False), FREQ)
    hh = _core_response(half_car(p.half_car(), lift_off=False), FREQ)
    for a, b in (("bounce_acc", "bounce_acc"), ("pitch_acc", "pitch_acc"),
                 ("seat_acc", "seat_acc"), ("front_left_deflection", "front_deflection"),
                 ("rear_right_deflection", "rear_deflection")):  # fmt: skip
        full = np.stack([hf[a][:, 0] + hf[a][:, 1], hf[a][:, 2] + hf[a][:, 3]], 1)
        assert np.abs(full - hh[b]).max() < 1e-9 * np.abs(hh[b]).max(), a
    tl = hf["front_left_tyre_load"]
    full = np.stack([tl[:, 0] + tl[:, 1], tl[:, 2] + tl[:, 3]], 1)
    assert np.abs(2 * full - hh["front_tyre_load"]).max() < 1e-9 * np.abs(hh["front_tyre_load"]).max()


def test_decoupled_half_car_equals_two_core_quarter_cars():
    """I_y = m a b splits the body into m b / L over the front axle and m a / L over the
    rear: each axle is then the core's quarter car with that sprung mass (a separate
    template), to 1e-9, here with ``k | (c - b)`` at the front."""
    front = NetworkStrut("k | (c - b)", {"k": 30e3, "c": 2500.0, "b": 150.0})
    rear = Strut(stiffness=25e3, damping=1800.0)
    p = _half(front, rear)
    h = _core_response(half_car(p, lift_off=False), FREQ)
    L = p.cg_to_front + p.cg_to_rear
    for st, net, prm, ms, corner in (
        ("front", "k | (c - b)", front.parameters, p.sprung_mass * p.cg_to_rear / L, p.front),
        ("rear", "k | c", {"k": 25e3, "c": 1800.0}, p.sprung_mass * p.cg_to_front / L, p.rear),
    ):
        q = quarter_car(
            net, prm, sprung_mass=ms, unsprung_mass=corner.unsprung_mass,
            tyre_stiffness=corner.tyre.stiffness, tyre_damping=corner.tyre.damping,
        )  # fmt: skip
        w = 2 * math.pi * FREQ
        # quarter car: transfer from road velocity; the road height's is times j w
        defl = q.transfer(w, "suspension_deflection") * 1j * w
        j = 0 if st == "front" else 1
        assert np.abs(h[f"{st}_deflection"][:, j] - defl).max() < 1e-9 * np.abs(defl).max()
        other = h[f"{st}_deflection"][:, 1 - j]
        assert np.abs(other).max() < 1e-9 * np.abs(defl).max()


def _afw_car():
    text = example_vehicle_path().read_text()
    adaptive = ('adaptive = { flywheel = "nylon", changing_ratio = 0.285, law = "thesis", '
                'rest_inertance = "150 kg" }\n')  # fmt: skip
    from inerterlab.vehicles import loads_vehicle

    return loads_vehicle(text.replace('inertance = "0 kg"\n', 'inertance = "0 kg"\n' + adaptive))


def _class_c(car, dt, seconds, seed=11):
    length = seconds * 20.0 + 3.0 + 40 * dt
    x, zl, zr = generate_tracks(road_spectrum("C"), length=length, step=20.0 * dt, seed=seed)
    return road_inputs(car, x, zl, zr, 20.0, dt)[: int(round(seconds / dt)) + 1]


def test_lift_off_is_an_event_and_contact_never_pulls():
    """A light car dropped onto its tyres from a step-free but violent road: the
    contact force is never negative and the lift-offs are located as events."""
    p = _half(Strut(stiffness=30e3, damping=1500.0))
    dt = 1e-3
    t = dt * np.arange(801)
    bump = np.where((t > 0.1) & (t < 0.16), 0.08 * np.sin(np.pi * (t - 0.1) / 0.06) ** 2, 0.0)
    r = np.stack([bump, np.roll(bump, 120)], 1)
    res = simulate(vehicle(p), r, dt, rtol=1e-9)
    assert res.stats["events"] > 0
    assert res.lift_off_fraction["front"] > 0
    for c in res.contact_force.values():
        assert c.min() >= -1e-6 * c.max()
    lin = simulate(vehicle(p, lift_off=False), r, dt, rtol=1e-9)
    assert np.abs(lin.outputs["front_tyre_load"]).max() > np.abs(res.outputs["front_tyre_load"]).max()


def test_the_same_element_gives_the_same_force_in_a_vehicle():
    """An inerter at a corner: its force is b times the relative acceleration of its
    ends (the body point a combination of bounce and pitch), read from the outputs."""
    p = _half(Strut(stiffness=30e3, damping=1500.0),
              Strut(stiffness=25e3, damping=1800.0), inertia=1500.0)  # fmt: skip
    sys = vehicle(p, networks={"front": ("k | c | b", {"k": 30e3, "c": 1500.0, "b": Inerter(inertance=90.0)})})
    dt = 1e-3
    t = dt * np.arange(401)
    r = np.stack([0.01 * np.sin(8 * t), 0.01 * np.sin(8 * t - 1.0)], 1)
    res = simulate(sys, r, dt, rtol=1e-10)
    o = res.signals
    rel = o["body_front.a"] - o["wheel_front.a"]
    ab = o["bounce.a"] - p.cg_to_front * o["pitch.a"]
    assert np.abs(o["body_front.a"] - ab).max() <= 1e-12 * np.abs(ab).max()
    np.testing.assert_allclose(o["front.b.force"], 90.0 * rel, rtol=1e-12, atol=1e-12)


def test_errors_name_what_is_wrong():
    p = _half(Strut(stiffness=30e3, damping=1500.0))
    with pytest.raises(ParameterError, match="networks"):
        vehicle(p, networks={"middle": ("k", {"k": 1e4})})
    with pytest.raises(ParameterError, match="front network"):
        vehicle(p, networks={"front": ("k | zz", {"k": 1e4})})
    with pytest.raises(ParameterError, match="static"):
        vehicle(p, networks={"front": ("k - c", {"k": 1e4, "c": 1e3})})
    with pytest.raises(ParameterError, match="FullCar"):
        full_car(p)
    with pytest.raises(ParameterError, match="r"):
        simulate(vehicle(p), np.zeros((10, 3)), 1e-3)
    with pytest.raises(ParameterError, match="rtol"):
        simulate(vehicle(p), np.zeros((10, 2)), 1e-3, rtol=0.5)
    with pytest.raises(ParameterError, match="x0"):
        simulate(vehicle(p), np.zeros((10, 2)), 1e-3, x0=np.zeros(3))
    with pytest.raises(NetworkError, match="not linear"):
        vehicle(p).linear_state_space()
    with pytest.raises(ParameterError):
        vehicle(p, networks={"front": AdaptiveFlywheelInerter(flywheel="nylon", law="thesis")})


def _file_with_front(lines: str) -> str:
    text = example_vehicle_path().read_text()
    head, rest = text.split("[front]", 1)
    _, tail = rest.split("[rear]", 1)
    front = ('[front]\nunsprung_mass = "40 kg"\ntyre_stiffness = "200 kN/m"\n'
             'tyre_damping = "50 N s/m"\nanti_roll = "12 kN/m"\n' + lines + "\n\n")  # fmt: skip
    return head + front + "[rear]" + tail


@pytest.mark.parametrize(
    "lines,net,values",
    [
        ('network = "k | c | hyd"\nk = "28 kN/m"\nc = "2.2 kN s/m"\nhyd = { flywheel = "none" }',
         "k | c | hyd", {"k": 28e3, "c": 2200.0, "hyd": HydraulicElement(flywheel="none")}),
        ('network = "k | (c - gap)"\nk = "28 kN/m"\nc = "2200 N s/m"\n'
         'gap = { stiffness = "90 kN/m", free_play = "1.5 mm" }',
         "k | (c - gap)", {"k": 28e3, "c": 2200.0, "gap": {"stiffness": 9e4, "free_play": 1.5e-3}}),
        ('network = "k | c | afw"\nk = "28 kN/m"\nc = "2200 N s/m"\n'
         'afw = { flywheel = "nylon", ratio = "40 rad/m", law = "thesis" }',
         "k | c | afw", {"k": 28e3, "c": 2200.0,
                         "afw": AdaptiveFlywheelInerter(flywheel="nylon", ratio=40.0, law="thesis")}),
    ],
    ids=["k|c|hyd", "k|(c-gap)", "k|c|afw"],
)
def test_vehicle_file_network_in_the_elements_units_equals_python(lines, net, values):
    """A corner's network from the vehicle file, each element's parameters in the units
    the element declares, builds the same core vehicle as the network given in Python:
    the same motion on a road."""
    from inerterlab.vehicles import loads_vehicle

    p = loads_vehicle(_file_with_front(lines))
    dt = 2e-3
    t = dt * np.arange(301)
    wave = 0.02 * np.sin(2 * np.pi * 1.5 * t) * np.minimum(t / 0.2, 1.0)
    r = np.stack([wave, 0.5 * wave, np.roll(wave, 50), np.roll(wave, 60)], 1)
    a = simulate(vehicle(p), r, dt, rtol=1e-9)
    b = simulate(vehicle(p, networks={"front": (net, values)}), r, dt, rtol=1e-9)
    for k in ("bounce_acc", "roll_acc", "front_left_deflection", "rear_right_tyre_load"):
        np.testing.assert_allclose(a.outputs[k], b.outputs[k], rtol=0, atol=1e-7 * np.abs(b.outputs[k]).max())


@pytest.mark.parametrize(
    "name,value",
    [
        ("k2", 2e4),
        ("c2", {"damping": 800.0, "quadratic": 300.0}),
        ("b", 60.0),
        ("fric", {"force": 150.0, "velocity": 2e-3}),
        ("gap", {"stiffness": 5e4, "free_play": 2e-3}),
        ("afw", AdaptiveFlywheelInerter(flywheel="nylon", ratio=40.0, law="thesis")),
    ],
)
def test_the_same_element_gives_the_same_force_in_the_rig_and_the_vehicle(name, value):
    """Each primitive element of the registry at a corner of a full car (in parallel with
    the strut): its force sampled in the vehicle equals the force of a core rig driven
    with the same relative displacement, velocity and acceleration of its ends, to 1e-9
    of its peak."""
    from inerterlab.systems import rig

    p = load_vehicle(example_vehicle_path())
    net = {"front_left": (f"k | c | {name}", {"k": 28e3, "c": 2200.0, name: value})}
    if name == "gap":
        # beside the strut the contact spring takes part of the weight, past its play: a
        # law with free play cannot be taken about that rest, so the car is refused
        with pytest.raises(NetworkError, match=r"front_left\.gap .*moved .* at rest"):
            vehicle(p, networks=net)
        net = {"front_left": ("k | c | (k2 - gap)", {"k": 28e3, "c": 2200.0, "k2": 1e4, name: value})}
        with pytest.raises(NetworkError, match=r"front_left\.gap"):
            vehicle(p, networks=net)
        return
    sys = vehicle(p, networks=net)
    dt = 2e-3
    t = dt * np.arange(401)
    wave = 0.03 * np.sin(2 * np.pi * 2.0 * t) * np.minimum(t / 0.3, 1.0)
    r = np.stack([wave, 0.3 * wave, np.roll(wave, 40), np.roll(wave, 45)], 1)
    o = simulate(sys, r, dt, rtol=1e-9).signals
    el = f"front_left.{name}"
    i = sys.element_names.index(el)
    top, bot = (sys.node_names[j] for j in sys.info["layout"].edges[i][2:4])
    rel = [o[f"{top}.{q}"] - o[f"{bot}.{q}"] for q in ("x", "v", "a")]
    one = rig(name, {name: value})
    assert one.n_states == len(sys.elements[i].internal_states)
    out = np.empty(len(one.output_names))
    f = np.empty(t.size)
    j = one.output_names.index(f"{name}.force")
    for s in range(t.size):
        road = np.array([rel[0][s], rel[1][s], rel[2][s]])
        one.outputs(0.0, np.zeros(one.n_states), road, one.itab, one.ftab, out)
        f[s] = out[j]
    scale = np.abs(o[f"{el}.force"]).max()
    assert scale > 0
    np.testing.assert_allclose(o[f"{el}.force"], f, rtol=0, atol=1e-9 * scale)


def test_contact_envelope_attenuates_short_waves_by_the_sinc_of_the_patch():
    """The moving average over a contact patch L multiplies a road wave of wavelength
    lambda by sin(pi L / lambda) / (pi L / lambda) (closed form); long waves pass, a
    wave as long as the patch vanishes; the road's level parts are unchanged."""
    from inerterlab.systems.vehicle import enveloped

    dt, v, L = 1e-4, 10.0, 0.25
    t = dt * np.arange(40001)
    for lam in (5.0, 1.0, 0.6, 0.25, 0.1):
        r = np.sin(2 * np.pi * v / lam * t)[:, None]
        y = enveloped(r, dt, v, L)[5000:35000, 0]
        gain = np.sqrt(2.0 * np.mean(y**2))
        x = math.pi * L / lam
        assert abs(gain - abs(math.sin(x) / x)) < 2e-4, lam
    level = np.full((50, 2), 0.03)
    np.testing.assert_allclose(enveloped(level, 1e-3, 20.0, 0.2), level, rtol=1e-13)
    with pytest.raises(ParameterError, match="contact_length"):
        enveloped(level, 1e-3, 20.0, 0.0)
