"""Every element of the registry in every analysis.

Parametrised over :data:`inerterlab.elements.ELEMENTS` (plus two elements a user adds
with :func:`inerterlab.elements.register`, an eddy-current damper and a gas spring taken
linear about rest), so
an element that misses an analysis fails here. Each analysis is checked against an
independent route: the nonlinear model at small motion about rest against its declared
linearisation (rig force from the admittance, quarter car against the linear core
system, harmonic balance against the linear transfer), identification by recovering a
parameter from noise-free records, H2 against a quadrature of |H(j w)|^2, and the
optimiser against the same network written with an ideal element.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from inerterlab.elements import (
    ELEMENTS,
    KERNEL_LAWS,
    ElementBase,
    Param,
    element_class,
    register,
)  # fmt: skip
from inerterlab.elements._base import DAMPER, SPRING
from inerterlab.excitation import drive_series, sine
from inerterlab.networks import admittance_at, linearise, parse_network
from inerterlab.suspension.network_linear import network_quarter_car
from inerterlab.systems import quarter_car, rig

CAR = dict(sprung_mass=370.0, unsprung_mass=25.0, tyre_stiffness=120e3, tyre_damping=1300.0)


# ------------------------------------------------------- two elements a user adds


@dataclass(frozen=True, kw_only=True)
class EddyCurrentDamper(ElementBase):
    """A conducting plate of ``conductivity`` sigma [S/m] and ``thickness`` d [m] moving
    through a field of ``flux_density`` B [T] over ``area`` S [m^2]: F = sigma d S B^2 v
    (the low-speed law; the damping falls off above the plate's critical speed, which is
    not modelled)."""

    conductivity: float = 3.5e7
    thickness: float = 5e-3
    flux_density: float
    area: float = 0.05

    prefix = "eddy"
    description = "eddy-current damper"
    ROLE = "dissipative"
    EXAMPLE = {"flux_density": 0.5}
    PARAMETERS = (
        Param("conductivity", "S/m"),
        Param("thickness", "m"),
        Param("flux_density", "T", design=(0.05, 2.0)),
        Param("area", "m^2"),
    )
    code = DAMPER
    is_linear = True

    @property
    def damping(self) -> float:
        return self.conductivity * self.thickness * self.area * self.flux_density**2

    def row(self):
        return self._row(self.damping, 0.0)

    def rest_network(self):
        return "c", {"c": self.damping}


@dataclass(frozen=True, kw_only=True)
class SmallMotionGasSpring(ElementBase):
    """A gas column of ``pressure`` p0 [Pa] and ``volume`` V0 [m^3] behind a piston of
    ``area`` A [m^2], polytropic index ``index``: small-motion stiffness n p0 A^2 / V0."""

    pressure: float
    volume: float = 1e-3
    area: float = 3e-3
    index: float = 1.4

    prefix = "lgas"
    description = "gas spring (small motion)"
    ROLE = "elastic"
    EXAMPLE = {"pressure": 2e6}
    PARAMETERS = (
        Param("pressure", "Pa", design=(1e5, 2e7)),
        Param("volume", "m^3"),
        Param("area", "m^2"),
        Param("index", ""),
    )
    code = SPRING
    is_linear = True

    @property
    def stiffness(self) -> float:
        return self.index * self.pressure * self.area**2 / self.volume

    def row(self):
        return self._row(self.stiffness)

    def rest_network(self):
        return "k", {"k": self.stiffness}


USER = (EddyCurrentDamper, SmallMotionGasSpring)
PREFIXES = [*ELEMENTS, *(c.prefix for c in USER)]


@pytest.fixture(autouse=True)
def user_elements():
    """The user's elements are registered for each test and removed afterwards."""
    for cls in USER:
        register(cls)
    yield
    for cls in USER:
        del ELEMENTS[cls.prefix]
    element_class.cache_clear()


#: elements whose response to small motions about rest has no linearisation, with the
#: reason: the three small-motion checks (rig, quarter car, harmonic balance) do not
#: apply to them; their own closed-form tests are in tests/test_device_elements.py
NO_LINEARISATION = {
    "owc": "a one-way clutch drives its flywheel only while the shaft speeds up past it, "
    "so a small oscillation spins the flywheel up and then lets it run free (re-engaging "
    "briefly where the bearing drag has slowed it): a force that is not linear in the "
    "motion, and a flywheel speed whose mean no periodic balance determines",
    "asym": "an asymmetric damper has a kink at rest and a force positively homogeneous "
    "in the motion, so the mean and even harmonics of its force keep their share of the "
    "force however small the motion; its linearisation is the first-harmonic damping "
    "(tests/test_vehicle_time.py)",
}


def _example(prefix: str) -> dict:
    cls = ELEMENTS[prefix]
    assert cls.EXAMPLE is not None, f"{cls.__name__} declares no EXAMPLE"
    return dict(cls.EXAMPLE)


# ------------------------------------------------------------- declarations


@pytest.mark.parametrize("prefix", PREFIXES)
def test_element_declares_itself(prefix):
    cls = ELEMENTS[prefix]
    assert cls.prefix == prefix and cls.description
    assert cls.ROLE in ("elastic", "dissipative", "inertial", "composite")
    assert cls.PARAMETERS, "parameters with units"
    for p in cls.PARAMETERS:
        assert isinstance(p.unit, str)
        if p.design is not None:
            assert 0 < p.design[0] < p.design[1] < math.inf
    el = cls.from_value(prefix, _example(prefix))
    assert (el.expansion() is None) == (cls.ROLE != "composite")
    rest = el.rest_network()
    if rest is not None:
        text, values = rest
        net = parse_network(text)
        assert net.is_linear and set(net.names) == set(values)
        assert all(v > 0 for v in values.values())


@pytest.mark.parametrize("prefix", PREFIXES)
def test_primitive_declares_its_kernel_law(prefix):
    """Every primitive's kernel law (KERNEL_LAWS, by code: what the builder, the static
    balance and the statistical linearisation read, nothing about an element outside
    elements/) agrees with the element's role: what its force depends on, how it ties
    the nodes it joins; and a law's equivalent row of a gain has that gain as its slope
    at rest (the round trip the linearised car relies on)."""
    cls = ELEMENTS[prefix]
    if cls.ROLE == "composite":
        assert cls.code is None
        return
    law = KERNEL_LAWS[cls.code]
    assert law.code == cls.code
    role = {"elastic": "displacement", "dissipative": "velocity", "inertial": "acceleration"}
    assert law.argument == role[cls.ROLE]
    ties = {
        "elastic": law.elastic or law.contact,
        "dissipative": law.holds_velocity or law.bounded,
        "inertial": law.inertial,
    }  # fmt: skip
    assert ties[cls.ROLE] and sum(ties.values()) == 1
    el = cls.from_value(prefix, _example(prefix))
    if law.inertial:
        assert 0.0 < law.nominal_inertance(el) < math.inf
    row = el.row()
    if law.gaussian_keeps(row) or law.gaussian_refusal(row, cls.description) is not None:
        return
    for gain in (0.37, 1234.5):
        eq = law.gaussian_row(row, gain)
        assert law.gaussian_gain(eq, 0.0, None) == pytest.approx(gain, rel=1e-12)


def test_an_element_of_no_kernel_law_is_refused_by_name():
    from inerterlab.elements import kernel_law
    from inerterlab.errors import ParameterError

    @dataclass(frozen=True, kw_only=True)
    class Odd(ElementBase):
        prefix = "odd"
        description = "an element of no kernel law"
        code = 99

    with pytest.raises(ParameterError, match="an element of no kernel law"):
        kernel_law(Odd())


# --------------------------------------------------- rig: force about rest


@pytest.mark.parametrize("prefix", PREFIXES)
def test_rig_small_motion_is_the_linearisation(prefix):
    """Driven at 2 um, 1 Hz from rest, the rig force settles on Im(Y(jw) jw A e^{jwt})
    with Y the admittance of the element's linearisation about rest."""
    if prefix in NO_LINEARISATION:
        pytest.skip(NO_LINEARISATION[prefix])
    params = {prefix: _example(prefix)}
    amp, f = 2e-6, 1.0
    w = 2 * math.pi * f
    res = rig(prefix, params).simulate(sine(amp, f), 6.0, rtol=1e-11, sample_rate=200.0)
    t, force = res.time, res.outputs["force"]
    assert np.all(np.isfinite(force))
    try:
        lin, values = linearise(prefix, params)
        y = complex(admittance_at(lin, values, 1j * w))
    except Exception as e:  # noqa: BLE001 - the open circuit is a NetworkError
        assert "no force for small motions" in str(e)
        y = 0.0
    ref = np.imag(y * 1j * w * amp * np.exp(1j * w * t))
    late = t >= 4.0
    scale = max(np.abs(ref[late]).max(), 1e-12)
    assert np.abs(force[late] - ref[late]).max() <= 1e-3 * scale, prefix


# -------------------------------------------- quarter car and frequency response


def _car_and_linear(prefix):
    name = f"{prefix}2" if prefix in ("k", "c") else prefix
    text = f"k | c | {name}"
    params = {"k": 5e4, "c": 3e3, name: _example(prefix)}
    lin, values = linearise(text, params)
    return text, params, lin, values


@pytest.mark.parametrize("prefix", PREFIXES)
def test_quarter_car_small_motion_is_the_linear_car(prefix):
    if prefix in NO_LINEARISATION:
        pytest.skip(NO_LINEARISATION[prefix])
    text, params, lin, values = _car_and_linear(prefix)
    road = sine(2e-6, 1.5)
    a = quarter_car(text, params, **CAR).simulate(road, 3.0, rtol=1e-11, sample_rate=200.0)
    b = quarter_car(lin.text, values, **CAR).simulate(road, 3.0, rtol=1e-11, sample_rate=200.0)
    x, y = a.outputs["body.x"], b.outputs["body.x"]
    assert np.abs(x - y).max() <= 2e-3 * np.abs(y).max(), prefix


@pytest.mark.parametrize("prefix", PREFIXES)
def test_frequency_response_small_motion_is_the_linear_transfer(prefix):
    if prefix in NO_LINEARISATION:
        pytest.skip(NO_LINEARISATION[prefix])
    from inerterlab.frequency import frequency_response

    text, params, lin, values = _car_and_linear(prefix)
    freqs = np.array([1.0, 3.0, 9.0])
    amp = 2e-6
    fr = frequency_response(
        quarter_car(text, params, **CAR), "sihb", freq_hz=freqs, amplitude=amp, direction="up"
    )
    assert np.asarray(fr.converged).all()
    w = 2 * math.pi * freqs
    h = network_quarter_car(lin, **CAR).transfer(values, w)["body_acc"]  # per road velocity
    ref = np.abs(h) * amp / w  # body displacement amplitude
    np.testing.assert_allclose(np.asarray(fr.amplitude_m), ref, rtol=2e-3, err_msg=prefix)


# ------------------------------------------------------------ identification


#: the series devices k - (c | fric | afw): the fit projects out the internal node's
#: free response, which is exact for a linear network only; with the friction in the
#: branch the stiffness comes back to 2e-4 (hyd) and 6e-4 (rect), measured
SERIES_FRICTION = {"hyd": 1e-3, "rect": 1e-3}


def _first_numeric(cls) -> str:
    return next(
        p.name for p in cls.PARAMETERS if p.choices is None and not p.optional
    )


@pytest.mark.parametrize("prefix", PREFIXES)
def test_identification_recovers_a_parameter(prefix):
    """Noise-free rig records of the element alone; its first numeric parameter is
    fitted from a start 20 % off and comes back."""
    from inerterlab.identify import RigDataSet, RigTest, identify_network

    cls = ELEMENTS[prefix]
    example = _example(prefix)
    name = _first_numeric(cls)
    el = cls.from_value(prefix, example)
    truth = el.parameters()[name]
    r = rig(prefix, {prefix: el})
    fs, tests = 400.0, []
    for i, (f, amp) in enumerate([(1.0, 0.01), (3.0, 0.004)]):
        # two seconds from rest; the second is the record (the start's transient gone)
        t = np.arange(int(2.0 * fs) + 1) / fs
        w = 2 * math.pi * f
        x, v, a = amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t)
        res = r.simulate(drive_series(t, x, v, a), t[-1], rtol=1e-11, times=t)
        k = t >= 1.0
        tests.append(
            RigTest(name=f"t{i}", signal="sine", frequency=f, amplitude=amp,
                    purpose="identification", t=t[k] - 1.0, force=res.outputs["force"][k],
                    displacement=x[k], velocity=v[k])  # fmt: skip
        )
    data = RigDataSet(tests=tuple(tests), source="core rig")
    if len(cls.PARAMETERS) == 1:
        key, start = prefix, {prefix: 0.8 * truth}
    else:
        key = f"{prefix}.{name}"
        start = {f"{prefix}.{k}": v for k, v in example.items()}
        start[key] = 0.8 * truth
    fit = identify_network(
        data, prefix, start, free=(key,), loss="linear", reversal_window=0.0, rtol=1e-11,
    )
    rel = SERIES_FRICTION.get(prefix, 1e-4)
    assert fit.parameters[key].value == pytest.approx(truth, rel=rel), prefix


# ------------------------------------------------------------------------- H2


@pytest.mark.parametrize("prefix", PREFIXES)
def test_h2_of_the_linearisation_equals_the_integral(prefix):
    """The compiled Lyapunov route against (1/pi) int_0^inf |H(j w)|^2 dw by quadrature."""
    from scipy.integrate import quad

    _, _, lin, values = _car_and_linear(prefix)
    q = network_quarter_car(lin, **CAR)
    norms = q.h2(values)
    for out in ("tyre_deflection", "suspension_deflection"):

        def g(u, out=out):
            w = math.exp(u)
            return abs(q.transfer(values, [w])[out][0]) ** 2 * w

        val = quad(g, -25.0, 30.0, limit=1000, epsabs=0.0, epsrel=1e-10)[0] / math.pi
        assert norms[out] ** 2 == pytest.approx(val, rel=1e-6), (prefix, out)


# ------------------------------------------------------------------ optimiser


@pytest.mark.parametrize("prefix", PREFIXES)
def test_every_element_can_be_optimised(prefix):
    """`network optimize` takes the element: with one of its parameters searched over
    0.2-5 times the example's value (the others held) the optimum of the tyre
    deflection norm is finite and no worse than at the example itself."""
    from inerterlab.network_design import design_parameters, optimize_network

    text, params, lin, values = _car_and_linear(prefix)
    name = text.rsplit("| ", 1)[1]
    cls = element_class(name)
    dp = design_parameters(text)
    own = [n for n in dp if n == name or n.startswith(name + ".")]
    assert own, f"{prefix}: no parameter of the element can be optimised"
    el = cls.from_value(name, params[name])
    example = el.parameters()

    def value(n):
        return example[n.split(".", 1)[1]] if "." in n else example[cls.PARAMETERS[0].name]

    # the parameter searched: one with a default range, else the first with a value
    free = next((n for n in own if dp[n].design is not None), None)
    free = free or next(n for n in own if value(n) is not None)
    fixed = {"k": 5e4, "c": 3e3}
    fixed.update({n: value(n) for n in own if n != free and value(n) is not None})
    x0 = value(free)
    res = optimize_network(
        text, "tyre_deflection", fixed=fixed, bounds={free: (0.2 * x0, 5.0 * x0)},
        compare=False, starts=2, samples=32, **CAR,
    )  # fmt: skip
    assert math.isfinite(res.objective)
    assert res.units[free] == dp[free].unit
    at_example = network_quarter_car(lin, **CAR).h2(values)["tyre_deflection"]
    assert res.objective <= at_example * (1 + 1e-9)


def test_fluid_inerter_optimum_is_the_ideal_inerters():
    """k | (c - fluid) over the channel length is k | (c - b) over b = rho l A1^2 / A2."""
    from inerterlab.network_design import optimize_network

    # the losses set to zero explicitly (by default they follow the geometry)
    fluid = {"density": 860.0, "piston_area": 2e-3, "channel_area": 3e-5, "damping": 0.0,
             "quadratic": 0.0}  # fmt: skip
    fixed = {"k": 5e4, **{f"fluid.{n}": v for n, v in fluid.items()}}
    a = optimize_network("k | (c - fluid)", fixed=fixed, compare=False, **CAR)
    scale = 860.0 * 2e-3**2 / 3e-5
    b = optimize_network(
        "k | (c - b)", fixed={"k": 5e4}, bounds={"b": (0.01 * scale, 100.0 * scale)},
        compare=False, **CAR,
    )  # fmt: skip
    assert a.objective == pytest.approx(b.objective, rel=1e-9)
    assert a.parameters["fluid.length"] * scale == pytest.approx(b.parameters["b"], rel=1e-5)
    assert a.parameters["c"] == pytest.approx(b.parameters["c"], rel=1e-5)
    assert a.units["fluid.length"] == "m"


@pytest.mark.slow
def test_user_elements_in_the_cli_optimiser():
    import json
    import subprocess
    import sys

    code = (
        "import sys; from tests.test_element_registry import USER; "
        "from inerterlab.elements import register; [register(c) for c in USER]; "
        "from inerterlab.cli import main; sys.exit(main())"
    )
    args = ["network", "optimize", "--network", "k | (eddy - b) | lgas", "--fix", "k=20000",
            "--json"]  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    res = json.loads(out.stdout)
    assert set(res["parameters"]) == {"k", "eddy.flux_density", "b", "lgas.pressure"}
    assert res["units"]["eddy.flux_density"] == "T"
    assert res["objective"] > 0
