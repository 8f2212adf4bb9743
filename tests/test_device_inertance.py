"""Devices given by their inertance [kg], and the fluid inerter's losses from geometry.

Independent routes: the inertance in kg against the equivalent transmission ratio or
channel length worked out by hand (b = r^2 I_min, b = rho l A1^2 / A2) in the same
simulation; the default loss coefficients against a hand calculation from the
geometry, and the Hagen-Poiseuille law against a finite-difference solution of the
laminar flow in the channel's cross-section.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.sparse import diags
from scipy.sparse.linalg import spsolve

from inerterlab.cli import main
from inerterlab.elements import FluidInerter, HydraulicElement, make_element
from inerterlab.errors import ParameterError
from inerterlab.excitation import sine
from inerterlab.flywheels import flywheel
from inerterlab.networks import linearise
from inerterlab.suspension.network_linear import network_quarter_car
from inerterlab.systems import quarter_car, rig

#: the flywheels' I_min [kg m^2] as published (docs/model.md §1): metal 9.53875e-4,
#: nylon 2.229925e-4, nylon-large 2.229925e-4 scaled in the rectifier's preset
DEVICES = {"hyd": "metal", "rect": "nylon-large", "screw": "nylon"}


@pytest.mark.parametrize("prefix", sorted(DEVICES))
def test_inertance_in_kg_gives_the_forces_of_the_equivalent_ratio(prefix):
    b = 300.0
    r = math.sqrt(b / flywheel(DEVICES[prefix]).inertia_min)  # by hand: b = r^2 I_min
    drive = sine(0.01, 2.0)
    by_kg = rig(prefix, {f"{prefix}.inertance": b}).simulate(drive, 1.0, rtol=1e-10)
    by_ratio = rig(prefix, {f"{prefix}.ratio": r}).simulate(drive, 1.0, rtol=1e-10)
    f1, f2 = by_kg.outputs["force"], by_ratio.outputs["force"]
    assert np.abs(f1 - f2).max() <= 1e-12 * np.abs(f2).max()
    el = make_element(prefix, {"inertance": b})
    assert el.ratio == pytest.approx(r, rel=1e-14) and el.inertance == pytest.approx(b, rel=1e-14)
    # the quarter car too, by the network parameter text
    car = {"k": 90e3, "c": 3e3}
    a = quarter_car(f"k | c | {prefix}", {**car, f"{prefix}.inertance": b})
    c = quarter_car(f"k | c | {prefix}", {**car, f"{prefix}.ratio": r})
    ra, rc = (q.simulate(sine(0.02, 1.5), 1.0, rtol=1e-10) for q in (a, c))
    x1, x2 = ra.outputs["body.x"], rc.outputs["body.x"]
    assert np.abs(x1 - x2).max() <= 1e-12 * np.abs(x2).max()


def test_both_given_must_agree():
    el = HydraulicElement()
    same = make_element("hyd", {"inertance": el.inertance, "ratio": el.ratio})
    assert same.ratio == el.ratio
    with pytest.raises(ParameterError, match=r"hyd\.inertance=300.*ratio=900 rad/m") as e:
        make_element("hyd", {"inertance": 300.0, "ratio": 900.0})
    assert "\n" not in str(e.value)
    with pytest.raises(ParameterError, match=r"hyd\.inertance.*no flywheel"):
        make_element("hyd", {"inertance": 300.0, "flywheel": "none"})
    with pytest.raises(ParameterError, match=r"screw\.inertance"):
        make_element("screw", {"inertance": -5.0})
    with pytest.raises(ParameterError, match=r"fluid\.inertance=300.*length=3 m"):
        make_element("fluid", {**GEOMETRY, "length": 3.0, "inertance": 300.0})


def test_cli_takes_the_inertance(capsys):
    """`-p hyd.inertance=300` in the CLI; both given and inconsistent: exit 2, one line."""
    assert main(["network", "h2", "--network", "k | c | hyd", "-p",
                 "k=90000,c=3000,hyd.inertance=300", "--json"]) == 0  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert out["linear_parameters"]["b_afw_hyd"] == pytest.approx(300.0, rel=1e-12)
    r = math.sqrt(300.0 / flywheel("metal").inertia_min)
    assert main(["network", "h2", "--network", "k | c | hyd", "-p",
                 f"k=90000,c=3000,hyd.ratio={r!r}", "--json"]) == 0  # fmt: skip
    out2 = json.loads(capsys.readouterr().out)
    assert out2["body_acc"] == pytest.approx(out["body_acc"], rel=1e-12)
    code = main(["network", "h2", "--network", "k | c | hyd", "-p",
                 "k=90000,c=3000,hyd.inertance=300,hyd.ratio=900"])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.count("\n") == 0 and "hyd.inertance" in err


def test_vehicle_file_takes_the_inertance():
    """A vehicle file's [front.device] goes through the same element: kg or rad/m, and
    the fluid inerter's viscosity with its unit (l = 344 kg * 3e-5 / (860 * 4e-6) = 3 m)."""
    from inerterlab.vehicles.config import example_vehicle_path, loads_vehicle

    car = example_vehicle_path().read_text()

    r = math.sqrt(300.0 / flywheel("nylon").inertia_min)
    by_kg = loads_vehicle(car + '[front.device]\nkind = "screw"\ninertance = "300 kg"\n')
    by_r = loads_vehicle(car + f'[front.device]\nkind = "screw"\nratio = "{r!r} rad/m"\n')
    a, b = by_kg.front.strut.device.adaptive, by_r.front.strut.device.adaptive
    assert a.ratio == pytest.approx(b.ratio, rel=1e-14)
    assert a.inertance_min == pytest.approx(300.0, rel=1e-12)
    fluid = loads_vehicle(
        car + '[front.device]\nkind = "fluid"\ndensity = "860 kg/m^3"\n'
        'inertance = "344 kg"\npiston_area = "2e-3 m^2"\nchannel_area = "3e-5 m^2"\n'
        'viscosity = "0.03 N s/m^2"\nquadratic = "0 N s^2/m^2"\n'
    ).front.strut.device  # b | c, linear, straight across: they join the strut
    assert fluid.inertance == pytest.approx(344.0, rel=1e-12)
    assert fluid.damping == pytest.approx(3200.0 * math.pi, rel=1e-12)


# ------------------------------------------------------------- fluid inerter

#: oil of 860 kg/m^3 and 0.03 Pa s; piston 2e-3 m^2, channel 3e-5 m^2
GEOMETRY = {"density": 860.0, "piston_area": 2e-3, "channel_area": 3e-5}


def test_fluid_default_losses_by_hand():
    """l = 3 m: b = 860 * 3 * 4e-6 / 3e-5 = 344 kg;
    c = 8 pi mu l A1^2 / A2^2 = 8 pi * 0.03 * 3 * 4e-6 / 9e-10 = 3200 pi N s/m;
    c_2 = K rho A1^3 / (2 A2^2) = 1.5 * 860 * 8e-9 / 1.8e-9 = 17200/3 N s^2/m^2."""
    f = make_element("fluid", {**GEOMETRY, "length": 3.0, "viscosity": 0.03})
    assert f.inertance == pytest.approx(344.0, rel=1e-14)
    assert f.damping == pytest.approx(3200.0 * math.pi, rel=1e-14)
    assert f.quadratic == pytest.approx(17200.0 / 3.0, rel=1e-14)
    text, parts = f.expansion()
    assert text == "b | c" and parts["c"].damping == f.damping
    # given by its inertance instead of its length: the same element
    g = make_element("fluid", {**GEOMETRY, "inertance": 344.0, "viscosity": 0.03})
    assert g.length == pytest.approx(3.0, rel=1e-14)
    assert g.damping == pytest.approx(f.damping, rel=1e-14)
    # no viscosity and no damping: refused, naming what to give
    with pytest.raises(ParameterError, match=r"fluid\.viscosity.*damping"):
        make_element("fluid", {**GEOMETRY, "length": 3.0})


def test_fluid_losses_set_to_zero_vanish():
    f = make_element("fluid", {**GEOMETRY, "inertance": 344.0, "damping": 0.0, "quadratic": 0.0})
    assert f.expansion()[0] == "b"
    k = make_element("fluid", {**GEOMETRY, "length": 3.0, "viscosity": 0.03, "loss_coefficient": 0.0})
    assert k.quadratic == 0.0 and k.damping > 0
    text, lin = linearise("k | c | fluid", {"k": 9e4, "c": 2e3, "fluid": f}, exact=True)
    h_f = network_quarter_car(text).h2(lin)
    h_b = network_quarter_car("k | c | b").h2({"k": 9e4, "c": 2e3, "b": 344.0})
    for name in h_b:
        assert h_f[name] == pytest.approx(h_b[name], rel=1e-12)


def test_fluid_rig_force_is_inertance_plus_the_losses():
    """The simulated rig force on a sine equals b a + c v + c_2 v |v| of the motion."""
    f = make_element("fluid", {**GEOMETRY, "length": 3.0, "viscosity": 0.03})
    amp, freq = 0.01, 2.0
    w = 2 * math.pi * freq
    res = rig("fluid", {"fluid": f}).simulate(sine(amp, freq), 1.0, rtol=1e-11, sample_rate=400.0)
    t = res.time
    v, a = amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t)
    ref = 344.0 * a + 3200.0 * math.pi * v + 17200.0 / 3.0 * v * np.abs(v)
    assert np.abs(res.outputs["force"] - ref).max() <= 1e-6 * np.abs(ref).max()


def test_hagen_poiseuille_against_the_flow_in_the_cross_section():
    """Laminar flow in a circular channel of radius R: mu (u'' + u'/r) = -G, u(R) = 0,
    solved by finite differences; the resistance G / Q agrees with 8 pi mu / A^2."""
    mu, radius, grad = 0.03, 3e-3, 1.0
    n = 4000
    h = radius / n
    r = (np.arange(n) + 0.5) * h  # cell centres; u(R) = 0 at the wall
    rp, rm = r + h / 2, r - h / 2
    main_ = -(rp + rm) / (r * h * h)
    main_[-1] = -(rp[-1] * 2 + rm[-1]) / (r[-1] * h * h)  # wall half a cell away
    upper = rp[:-1] / (r[:-1] * h * h)
    lower = rm[1:] / (r[1:] * h * h)
    A = diags([main_, upper, lower], [0, 1, -1], format="csc")
    u = spsolve(A, np.full(n, -grad / mu))
    q = float(np.sum(u * 2 * math.pi * r * h))
    area = math.pi * radius**2
    assert grad / q == pytest.approx(8 * math.pi * mu / area**2, rel=1e-5)
    # and the element's damping is that resistance times A1^2 over the channel length
    f = FluidInerter(density=860.0, length=2.0, piston_area=2e-3, channel_area=area, viscosity=mu)
    assert f.damping == pytest.approx(2.0 * (grad / q) * 2e-3**2, rel=1e-5)
