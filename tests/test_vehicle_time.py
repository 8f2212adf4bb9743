"""The vehicle's time simulation on the model core (vehicles/simulation.py,
systems/vehicle.py): against an independent scipy integration of hand-written
equations, against the exact discretisation of the linear car, the full car on
identical tracks against the half car, a decoupled half car against two quarter cars,
the asymmetric damper's law, the rest on uneven ground, the comfort observers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from inerterlab.elements import AsymmetricDamper
from inerterlab.errors import ParameterError
from inerterlab.systems import vehicle as core
from inerterlab.vehicles import (
    Corner,
    HalfCar,
    Strut,
    Tyre,
    example_vehicle_path,
    generate_tracks,
    load_vehicle,
    road_spectrum,
)
from inerterlab.vehicles.simulation import simulate_vehicle
from inerterlab.vehicles.spectral import generated_road

MS, IY, A, B = 600.0, 900.0, 1.2, 1.5
MU = (40.0, 35.0)
KS, CS = (25e3, 22e3), (1.8e3, 1.5e3)
KT, CT = 2.0e5, 100.0
HALF = HalfCar(
    sprung_mass=MS, pitch_inertia=IY, cg_to_front=A, cg_to_rear=B,
    front=Corner(unsprung_mass=MU[0], strut=Strut(stiffness=KS[0], damping=CS[0]),
                 tyre=Tyre(stiffness=KT, damping=CT)),
    rear=Corner(unsprung_mass=MU[1], strut=Strut(stiffness=KS[1], damping=CS[1]),
                tyre=Tyre(stiffness=KT, damping=CT)),
)  # fmt: skip


def _road(road_class: str, speed: float, dt: float, length: float, seed: int = 1):
    x, z, _ = generate_tracks(road_spectrum(road_class), length=length, step=speed * dt, seed=seed)
    wb = A + B
    s = speed * dt * np.arange(int((x[-1] - wb) / (speed * dt)))
    return np.column_stack([np.interp(s + wb, x, z), np.interp(s, x, z)])


def _oracle(r, dt, rebound=1.0, compression=1.0, friction=0.0, v_f=1e-3, lift_off=True):
    """scipy DOP853 on the half car written out by hand: bounce z, pitch theta (nose
    down), wheels w_f, w_r; strut extension e = z - x theta - w (x = +a, -b); tyres
    about their static loads, one-sided with ``lift_off``; the road linear between
    samples."""
    g = 9.81
    load_f = (MS * g * B / (A + B)) + MU[0] * g
    load_r = (MS * g * A / (A + B)) + MU[1] * g
    loads = (load_f, load_r)
    xs = (A, -B)

    def rhs(t, y, r0, slope):
        z, th, wf, wr, zd, thd, wfd, wrd = y
        w, wd = (wf, wr), (wfd, wrd)
        fz = 0.0
        mth = 0.0
        acc_w = [0.0, 0.0]
        for i in range(2):
            e = z - xs[i] * th - w[i]
            ed = zd - xs[i] * thd - wd[i]
            c = CS[i] * (rebound if ed > 0 else compression)
            f = KS[i] * e + c * ed + friction * math.tanh(ed / v_f)  # tension
            fz -= f
            mth += xs[i] * f  # the moment of -f at x on theta (nose down +)
            d = w[i] - (r0[i] + slope[i] * t)
            dd = wd[i] - slope[i]
            contact = loads[i] - KT * d - CT * dd  # static load + compression force
            tyre = (max(contact, 0.0) if lift_off else contact) - loads[i]  # change from rest
            acc_w[i] = (f + tyre) / MU[i]
        return [zd, thd, wfd, wrd, fz / MS, mth / IY, acc_w[0], acc_w[1]]

    y = np.zeros(8)
    # at rest on the first heights: wheels on the road, the body on its springs
    K = np.array([[KS[0] + KS[1], -A * KS[0] + B * KS[1], -KS[0], -KS[1]],
                  [-A * KS[0] + B * KS[1], A * A * KS[0] + B * B * KS[1], A * KS[0], -B * KS[1]],
                  [-KS[0], A * KS[0], KS[0] + KT, 0.0],
                  [-KS[1], -B * KS[1], 0.0, KS[1] + KT]])  # fmt: skip
    y[:4] = np.linalg.solve(K, [0.0, 0.0, KT * r[0, 0], KT * r[0, 1]])
    out = [y.copy()]
    for i in range(r.shape[0] - 1):
        slope = (r[i + 1] - r[i]) / dt
        sol = solve_ivp(rhs, (0.0, dt), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        args=(r[i], slope))  # fmt: skip
        y = sol.y[:, -1]
        out.append(y.copy())
    out = np.array(out)
    return {
        "front_deflection": out[:, 0] - A * out[:, 1] - out[:, 2],
        "rear_deflection": out[:, 0] + B * out[:, 1] - out[:, 3],
    }


def _err(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def test_asymmetric_damper_and_friction_against_scipy():
    """Rebound 1.6 c, compression 0.6 c and 80 N of strut friction on class D: the core
    (rtol 1e-10) and DOP853 on the hand-written equations agree to 1e-7 of the peak."""
    dt = 1e-3
    r = _road("D", 20.0, dt, 12.0, seed=2)
    res = simulate_vehicle(HALF, r, dt, lift_off=False, rebound=1.6, compression=0.6,
                           friction=80.0, friction_velocity=1e-2, rtol=1e-10)  # fmt: skip
    ref = _oracle(r, dt, 1.6, 0.6, 80.0, 1e-2, lift_off=False)
    for k in ("front_deflection", "rear_deflection"):
        assert _err(res.outputs[k], ref[k]) < 1e-7, k


def test_lift_off_against_scipy():
    """Class F at 30 m/s: the tyres leave the road; the core locates lift-off and
    landing as events and agrees with DOP853 (which steps over them at rtol 1e-12)."""
    dt = 1e-3
    r = _road("F", 30.0, dt, 15.0, seed=3)
    res = simulate_vehicle(HALF, r, dt, lift_off=True, rtol=1e-10)
    assert max(res.lift_off_fraction.values()) > 0.05
    ref = _oracle(r, dt)
    for k in ("front_deflection", "rear_deflection"):
        assert _err(res.outputs[k], ref[k]) < 1e-6, k
    for corner, f in res.contact_force.items():
        assert f.min() >= -1e-9 * f.max(), corner


def test_linear_car_equals_the_exact_linear_simulation():
    """A linear car (two-sided tyres, symmetric dampers): the core's time simulation
    equals the exact first-order-hold discretisation of its state space to 1e-9 of each
    output's peak (measured 9e-13 against the assembled M, C, K model, docs/decisions.md)."""
    from inerterlab.vehicles.linear import linear_vehicle
    from inerterlab.vehicles.spectral import simulate

    p = load_vehicle(example_vehicle_path())
    dt = 2e-3
    r = generated_road(p, road_spectrum("C"), length=80.0, speed=20.0, dt=dt, track=1.5, seed=5)
    run = simulate_vehicle(p, r, dt, lift_off=False, rtol=1e-12)
    exact = simulate(linear_vehicle(p), r, dt)
    for k, y in exact.items():
        assert _err(run.outputs[k], y) < 1e-9, k


def _identical_tracks(**opts):
    from inerterlab.vehicles import FullCar, Seat

    p = load_vehicle(example_vehicle_path())
    p = FullCar(**{**{k: getattr(p, k) for k in p.__dataclass_fields__},
                   "seat": Seat(x=0.25, y=0.0, mass=75.0, stiffness=47e3, damping=1100.0)})  # fmt: skip
    dt = 2e-3
    r = generated_road(p, road_spectrum("E"), length=60.0, speed=20.0, dt=dt, track=1.5, seed=7)
    r = r - r[0]
    rf = np.column_stack([r[:, 0], r[:, 0], r[:, 2], r[:, 2]])
    full = simulate_vehicle(p, rf, dt, rtol=1e-12, **opts)
    half = simulate_vehicle(p.half_car(), r[:, [0, 2]], dt, rtol=1e-12, **opts)
    return full.outputs, half.outputs


def test_full_car_on_identical_tracks_equals_the_half_car_in_time():
    """Left and right tracks the same, seat on the centre line: the full car's bounce,
    pitch, seat and each side's deflections equal the half car that lumps its axles,
    asymmetric dampers included (1e-9, at rtol 1e-12; measured 7e-11); its tyre loads
    are half the half car's."""
    f, h = _identical_tracks(lift_off=False, rebound=1.5, compression=0.7)
    for k in ("bounce_acc", "pitch_acc", "seat_acc"):
        assert _err(f[k], h[k]) < 1e-9, k
    for side in ("left", "right"):
        for axle in ("front", "rear"):
            assert _err(f[f"{axle}_{side}_deflection"], h[f"{axle}_deflection"]) < 1e-9
            assert _err(2 * f[f"{axle}_{side}_tyre_load"], h[f"{axle}_tyre_load"]) < 1e-9
    assert np.max(np.abs(f["roll_acc"])) < 1e-9 * np.max(np.abs(f["pitch_acc"]))


@pytest.mark.slow
def test_full_car_on_identical_tracks_with_lift_off_equals_the_half_car():
    """The two tyres of an axle lift off at the same instant: one event switches both,
    and the full car's bounce equals the half car's (9e-11 of its peak; 5.8e-3 when the
    second tyre switched a step late)."""
    f, h = _identical_tracks(lift_off=True)
    for k in ("bounce_acc", "pitch_acc", "seat_acc"):
        assert _err(f[k], h[k]) < 1e-9, k


def test_decoupled_half_car_equals_two_quarter_cars_in_time():
    """I_y = m a b: the half car's axles move as two quarter cars of the core with
    sprung masses m b/(a+b) and m a/(a+b), asymmetric dampers included (1e-9 at rtol
    1e-12; the quarter car's tyre lifts off only under its named suspensions)."""
    from inerterlab.excitation import road_series
    from inerterlab.systems import quarter_car

    car = HalfCar(sprung_mass=MS, pitch_inertia=MS * A * B, cg_to_front=A, cg_to_rear=B,
                  front=HALF.front, rear=HALF.rear)  # fmt: skip
    dt = 1e-3
    r = _road("E", 25.0, dt, 10.0, seed=4)
    r = r - r[0]  # both start at rest on level ground
    veh = simulate_vehicle(car, r, dt, lift_off=False, rebound=1.5, compression=0.7, rtol=1e-12)
    for i, (name, ms) in enumerate((("front", MS * B / (A + B)), ("rear", MS * A / (A + B)))):
        asym = AsymmetricDamper(rebound=1.5 * CS[i], compression=0.7 * CS[i])
        qc = quarter_car("k | asym", {"k": KS[i], "asym": asym}, sprung_mass=ms,
                         unsprung_mass=MU[i], tyre_stiffness=KT, tyre_damping=CT)  # fmt: skip
        road = road_series(dt * np.arange(r.shape[0]), r[:, i])
        out = qc.simulate(road, dt * (r.shape[0] - 1), rtol=1e-12, sample_rate=1.0 / dt).outputs
        defl = out["body.x"] - out["wheel.x"]
        assert _err(veh.outputs[f"{name}_deflection"][: defl.size], defl) < 1e-9, name


def test_asymmetric_damper_law_and_its_linearisation():
    from inerterlab.excitation import sine
    from inerterlab.systems import rig

    el = AsymmetricDamper(rebound=4e3, compression=1.5e3)
    assert el.rest_network() == ("c", {"c": 2750.0})
    assert not el.is_linear and AsymmetricDamper(rebound=2.0, compression=2.0).is_linear
    amp, f = 0.01, 2.0
    res = rig("asym", {"asym": el}).simulate(sine(amp, f), 2.0, rtol=1e-10, sample_rate=400.0)
    v = amp * 2 * math.pi * f * np.cos(2 * math.pi * f * res.time)
    law = np.where(v > 0, 4e3 * v, 1.5e3 * v)
    assert _err(res.outputs["force"], law) < 1e-8
    # the first harmonic of the force is that of the mean damping (any amplitude)
    w = 2 * math.pi * f
    t, F = res.time[:-1], res.outputs["force"][:-1]
    b1 = 2 * np.mean(F * np.cos(w * t))
    assert b1 == pytest.approx(2750.0 * amp * w, rel=1e-3)


def test_rest_on_uneven_ground_is_the_static_balance():
    """The start on first heights that differ: Newton's rest of the core (with lift-off
    tyres about their static loads) equals the linear spring balance of the oracle."""
    sys = core.vehicle(HALF, lift_off=True)
    h = np.array([0.02, -0.01])
    x = core.rest_state(sys, h)
    names = sys.state_names
    ref = _oracle(np.array([h, h]), 1e-3)
    defl = x[names.index("bounce.x")] - A * x[names.index("pitch.x")] - x[names.index("wheel_front.x")]
    assert defl == pytest.approx(ref["front_deflection"][0], abs=1e-12)


def test_comfort_observers_equal_the_sampled_weighting():
    """The Wk RMS and VDV integrated as observer states agree with ISO 2631 weighting
    of the sampled seat acceleration (the samples' sum, 1 kHz) to 1 %."""
    from inerterlab import iso2631

    p = load_vehicle(example_vehicle_path())
    dt = 1e-3
    r = generated_road(p, road_spectrum("C"), length=200.0, speed=20.0, dt=dt, track=1.5, seed=1)
    run = simulate_vehicle(p, r, dt, lift_off=True, warmup=2.0)
    aw = iso2631.weight(run.outputs["seat_acc"], 1.0 / dt, "Wk")[2000:]
    assert run.comfort["signal"] == "seat_acc"
    assert run.comfort["wk_rms"] == pytest.approx(math.sqrt(np.mean(aw**2)), rel=1e-2)
    assert run.comfort["vdv"] == pytest.approx(iso2631.vibration_dose_value(aw, 1.0 / dt), rel=1e-2)


def test_options_refused_in_one_line():
    r = np.zeros((10, 2))
    with pytest.raises(ParameterError, match="rebound"):
        simulate_vehicle(HALF, r, 1e-3, rebound=0.0)
    with pytest.raises(ParameterError, match="friction"):
        simulate_vehicle(HALF, r, 1e-3, friction=-1.0)
    with pytest.raises(ParameterError, match="r="):
        simulate_vehicle(HALF, np.zeros((10, 4)), 1e-3)
    with pytest.raises(ParameterError, match="rebound/compression"):
        simulate_vehicle(HALF, r, 1e-3, rebound=2.0, networks={"front": ("k | c", {"k": 2e4, "c": 1e3})})
