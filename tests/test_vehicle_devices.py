"""Real devices at a vehicle corner (hydraulic, rectifier, screw, any core network).

The decisive check is cross-model: a half car whose pitch inertia decouples the axles
(I_y = m a b) must move at each axle like the model core's quarter car with the same
device in parallel with the strut (``k | c | hyd``), a separate program: node
formulation, adaptive Dormand-Prince at rtol 1e-10 against the core vehicle's
combination nodes and several roads at rtol 1e-10.
"""

from __future__ import annotations

import numpy as np
import pytest

from _vehicle_oracle import nonlinear_device
from inerterlab.elements import (
    FluidInerter,
    HydraulicElement,
    RectifierElement,
    ScrewElement,
)
from inerterlab.errors import DataFileError, ParameterError
from inerterlab.vehicles import (
    Corner,
    FullCar,
    HalfCar,
    Strut,
    Tyre,
    example_vehicle_path,
    linear_vehicle,
    loads_vehicle,
)
from inerterlab.vehicles.parameters import corner_device
from inerterlab.vehicles.roads import generate_tracks, road_spectrum
from inerterlab.vehicles.simulation import simulate_vehicle
from inerterlab.vehicles.spectral import road_inputs

M, A, B = 1200.0, 1.2, 1.4
TYRE = Tyre(stiffness=2.4e5, damping=200.0)


def _half(strut, rear=None):
    front = Corner(unsprung_mass=45.0, strut=strut, tyre=TYRE)
    rear = front if rear is None else Corner(unsprung_mass=45.0, strut=rear, tyre=TYRE)
    return HalfCar(sprung_mass=M, pitch_inertia=M * A * B, cg_to_front=A, cg_to_rear=B,
                   front=front, rear=rear)  # fmt: skip


def _axles(car):
    """What road_inputs reads of a car: its parameters and kind."""
    from types import SimpleNamespace

    return SimpleNamespace(parameters=car, kind="full" if isinstance(car, FullCar) else "half")


def _road(car, dt=1e-3, n=3001, seed=5):
    x, zl, zr = generate_tracks(road_spectrum("C"), length=80.0, step=20.0 * dt, seed=seed)
    r = road_inputs(_axles(car), x, zl, zr, 20.0, dt)[:n]
    return r - r[0]


@pytest.mark.slow
@pytest.mark.parametrize(
    "device",
    [HydraulicElement(), HydraulicElement(flywheel="none"), RectifierElement(), ScrewElement()],
    ids=["hydraulic", "hydraulic-no-flywheel", "rectifier", "screw"],
)
def test_decoupled_half_car_with_a_device_equals_the_core_quarter_car(device):
    from inerterlab.excitation import road_series
    from inerterlab.systems import quarter_car

    strut = Strut(stiffness=30e3, damping=1500.0, device=device)
    half = _half(strut)
    dt = 1e-3
    r = _road(half, dt)
    t = dt * np.arange(r.shape[0])
    run = simulate_vehicle(half, r, dt, lift_off=False, rtol=1e-10)
    veh = run.outputs
    qc = quarter_car(f"k | c | {device.prefix}", {"k": 30e3, "c": 1500.0, device.prefix: device},
                     sprung_mass=M * B / (A + B), unsprung_mass=45.0, tyre_stiffness=2.4e5,
                     tyre_damping=200.0)  # fmt: skip
    core = qc.simulate(road_series(t, r[:, 0]), horizon=t[-1], rtol=1e-10, sample_rate=1 / dt)
    defl = core.outputs["body.x"] - core.outputs["wheel.x"]
    err = np.abs(veh["front_deflection"] - defl).max() / np.abs(defl).max()
    assert err < 1e-8, err
    # accelerations: the road's slope changes at each sample and the tyre damper and the
    # inerters pass that to the body, so the acceleration jumps there; the vehicle
    # reports the value just after the sample, so evaluate the core there too
    itab, ftab = qc.tables
    names = qc.output_names
    slope = np.append(np.diff(r[:, 0]) / dt, 0.0)
    out = np.empty(len(names))
    right = np.empty(t.size - 1)
    for i in range(t.size - 1):
        qc.outputs(t[i], core.states[i], np.array([r[i, 0], slope[i], 0.0]), itab, ftab, out)
        right[i] = out[names.index("body.a")]
    acc = (veh["bounce_acc"] - A * veh["pitch_acc"])[:-1]
    err = np.abs(acc - right).max() / np.abs(right).max()
    assert err < 1e-6, err


def test_device_parts_straight_across_join_the_strut():
    """A device's direct linear parts and adaptive inerter are read off into the strut's
    (b, c, k); anything else is beyond the hand-assembled matrices of the tests' oracle
    (the core vehicle takes it all)."""
    screw = corner_device(ScrewElement())  # k | c | fric | afw: all across the terminals
    assert screw.stiffness == ScrewElement().stiffness
    assert screw.damping == ScrewElement().damping
    assert screw.adaptive is not None
    hyd = corner_device(HydraulicElement())  # k - (c | fric | afw): internal node
    assert (hyd.stiffness, hyd.damping, hyd.adaptive) == (0.0, 0.0, None)
    for dev in (screw, hyd):  # the friction, the internal node
        law = Strut(stiffness=1.0, damping=0.0, device=dev)
        assert nonlinear_device(law) is law.device
    law = Strut(stiffness=1.0, damping=0.0, device="k2 | c2", device_parameters={"k2": 5.0, "c2": 2.0})
    assert nonlinear_device(law) is None and law.mck() == (0.0, 2.0, 6.0)


def test_linear_device_equals_the_same_strut_in_every_linear_analysis():
    """A fluid inerter without quadratic loss is b | c straight across: linear."""
    fluid = FluidInerter(density=870.0, length=3.0, piston_area=2e-3, channel_area=3e-5,
                         damping=400.0, quadratic=0.0)  # fmt: skip
    b, c = fluid.inertance, fluid.damping
    with_device = linear_vehicle(_half(Strut(stiffness=30e3, damping=1500.0, device=fluid)))
    plain = linear_vehicle(_half(Strut(stiffness=30e3, damping=1500.0 + c, inertance=b)))
    f = np.geomspace(0.3, 30.0, 25)
    h1, h2 = with_device.frequency_response(f), plain.frequency_response(f)
    for name in h1:
        np.testing.assert_allclose(h1[name], h2[name], rtol=1e-12, atol=1e-300)


def test_full_car_with_devices_equals_the_half_car():
    """Identical tracks, no seat: the half car lumps each axle's two devices into one
    (every force and inertia doubled), which must move alike (rtol 1e-12, two-sided
    tyres)."""
    tyre = Tyre(stiffness=200e3, damping=80.0)
    full = FullCar(
        sprung_mass=1200.0, pitch_inertia=1800.0, roll_inertia=450.0, cg_to_front=1.15,
        cg_to_rear=1.45, front_track=1.52, rear_track=1.50, front_anti_roll=12e3,
        front=Corner(unsprung_mass=40.0, tyre=tyre,
                     strut=Strut(stiffness=28e3, damping=1800.0, device=HydraulicElement())),
        rear=Corner(unsprung_mass=38.0, tyre=tyre,
                    strut=Strut(stiffness=25e3, damping=1600.0, device=RectifierElement())),
    )  # fmt: skip
    cf, ch = _axles(full), _axles(full.half_car())
    dt = 2e-3
    x, zl, _ = generate_tracks(road_spectrum("C"), length=60.0, step=20.0 * dt, seed=2)
    rf = road_inputs(cf, x, zl, zl, 20.0, dt)[:1001]
    rh = road_inputs(ch, x, zl, zl, 20.0, dt)[:1001]
    rf, rh = rf - rf[0], rh - rh[0]
    yf = simulate_vehicle(full, rf, dt, lift_off=False, rtol=1e-12).outputs
    yh = simulate_vehicle(full.half_car(), rh, dt, lift_off=False, rtol=1e-12).outputs
    for a, b in (("bounce_acc", "bounce_acc"), ("front_left_deflection", "front_deflection"),
                 ("rear_right_deflection", "rear_deflection")):  # fmt: skip
        # the devices' kinks (the rectifier's clutches, flywheel saturation) fall at the
        # same instant on both sides of the full car: one event, both switch (3e-11;
        # 1e-5 when the second side switched a step late, docs/decisions.md)
        err = np.abs(yf[a] - yh[b]).max() / np.abs(yh[b]).max()
        assert err < 1e-9, (a, err)


def test_linear_analyses_refuse_a_nonlinear_device_by_corner():
    # the linear vehicle (every linear analysis starts from it) names the element at
    # its corner whose response depends on the amplitude
    with pytest.raises(ParameterError, match=r"front\.dev\.hyd\.fric.*linear model about rest"):
        linear_vehicle(_half(Strut(stiffness=30e3, damping=1500.0, device=HydraulicElement())))


def test_devices_the_split_refused_sit_at_a_corner_of_the_core():
    """An inerter at the body-side terminal (``b - c``) and series springs that carry
    load were refused when a device was split into matrix parts and a rig; the core
    vehicle places them as networks, and its statics carry the load."""
    from inerterlab.systems.vehicle import vehicle

    for text, params in (("b - c", {"b": 100.0, "c": 2000.0}), ("k2 - k3", {"k2": 1e5, "k3": 2e5})):
        car = _half(Strut(stiffness=30e3, damping=1500.0, device=text, device_parameters=params))
        loads = vehicle(car).info["static_tyre_loads"]
        assert sum(loads.values()) == pytest.approx((M + 90.0) * 9.81, rel=1e-12), text


def test_energy_of_a_device_corner_decays_without_road():
    """Released from a deflected state on a flat road, a car with lossy devices comes
    to rest: the device's friction and damping dissipate (no energy made)."""
    car = _half(Strut(stiffness=30e3, damping=1500.0, device=RectifierElement()))
    dt = 1e-3
    r = np.zeros((4001, 2))
    r[0] = 0.02  # start on a 2 cm step that drops at the first sample
    y = simulate_vehicle(car, r, dt, lift_off=False).outputs
    d = np.abs(y["front_deflection"])
    assert d[-500:].max() < 0.05 * d.max()


VEHICLE_DEVICE = """
[front.device]
kind = "hyd"
stiffness = "700 kN/m"
damping = "8 kN s/m"
friction = "150 N"
flywheel = "metal"
changing_ratio = 0.2
ratio = "900 rad/m"
"""


def test_vehicle_file_takes_a_device_per_axle():
    text = example_vehicle_path().read_text() + VEHICLE_DEVICE
    p = loads_vehicle(text)
    dev = p.front.strut.device
    assert dev.source == "hydraulic device" and p.rear.strut.device is None
    spring = [el for n, el, _, _ in dev.edges if n.endswith(".k")][0]
    assert spring.stiffness == pytest.approx(700e3)
    afw = [el for n, el, _, _ in dev.edges if n.endswith(".afw")][0]
    assert afw.ratio == pytest.approx(900.0)


@pytest.mark.parametrize(
    "extra,match",
    [
        ('[front.device]\nkind = "hydraulic_pump"\n', r"\[front.device\] kind"),
        ('[front.device]\nkind = "hyd"\nstiffness = "700 kg"\n', r"\[front.device\] stiffness"),
        ('[front.device]\nkind = "hyd"\nsize = 3\n', r"\[front.device\] size"),
        ('[front.device]\nstiffness = "700 kN/m"\n', r"\[front.device\] kind"),
    ],
)
def test_vehicle_file_device_errors_name_key_and_line(extra, match):
    with pytest.raises(DataFileError, match=match):
        loads_vehicle(example_vehicle_path().read_text() + extra)


def test_statistical_linearisation_takes_a_device_element_by_element(tmp_path):
    from inerterlab.vehicles.stochastic import statistical_linearisation

    path = tmp_path / "car.toml"
    path.write_text(example_vehicle_path().read_text() + VEHICLE_DEVICE)
    lin = statistical_linearisation(vehicle=str(path), points=800)
    assert lin.converged and lin.equivalents
    assert all(name.startswith("front") for name in lin.equivalents)


def test_cli_simulate_runs_a_device_car_nonlinearly(tmp_path):
    import json

    from typer.testing import CliRunner

    from inerterlab.cli import app

    path = tmp_path / "car.toml"
    path.write_text(example_vehicle_path().read_text() + VEHICLE_DEVICE)
    res = CliRunner().invoke(
        app, ["vehicle", "simulate", "--vehicle", str(path), "--length", "200", "--json"]
    )
    assert res.exit_code == 0, res.output
    out = json.loads(res.output)
    assert out["model"] == "nonlinear"
    assert "spectral_rms" not in out
    assert out["rms"]["front_left_deflection"] > 0


def test_half_and_full_car_types_keep_devices():
    p = loads_vehicle(example_vehicle_path().read_text() + VEHICLE_DEVICE)
    assert isinstance(p, FullCar)
    half = p.half_car()
    assert isinstance(half, HalfCar)
    assert half.front.strut.device.source.startswith("2 x")


def test_cli_monte_carlo_of_a_device_car_skips_the_linearisation(tmp_path):
    import json

    from typer.testing import CliRunner

    from inerterlab.cli import app

    path = tmp_path / "car.toml"
    path.write_text(example_vehicle_path().read_text() + VEHICLE_DEVICE)
    res = CliRunner().invoke(
        app,
        ["vehicle", "monte-carlo", "--vehicle", str(path), "--roads", "2", "--length", "120",
         "--warmup", "1", "--backend", "serial", "--out", str(tmp_path / "mc.zarr"), "--json"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    out = json.loads(res.output)
    assert out["linearised"] is None
    assert out["realisations"] == 2
    assert out["rms"]["front_left_deflection"]["value"] > 0


def test_vehicle_file_device_error_names_the_line():
    text = example_vehicle_path().read_text() + '\n[rear.device]\nkind = "rect"\nstiffness = "5 kg"\n'
    with pytest.raises(DataFileError) as e:
        loads_vehicle(text)
    assert e.value.line == len(text.splitlines())
