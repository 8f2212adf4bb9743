"""Quarter-car models: factory, kernels' inertia laws, device branch, impulse."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from inerterlab import flywheel, quarter_car
from inerterlab.errors import ParameterError
from inerterlab.suspension import QuarterCarParameters
from inerterlab.suspension import _kernels as K
from inerterlab.suspension.model import describe_quarter_car
from inerterlab.suspension.reference import ReferenceRHS


def test_factory_and_validation():
    car = quarter_car("afw", sprung_mass=370, changing_ratio=0.3).info["model"]
    assert car.flywheel.changing_ratio == pytest.approx(0.3)
    assert quarter_car("cfw").info["model"].inertance == pytest.approx(961.66**2 * 2.231e-4, rel=1e-4)
    assert quarter_car("cfw", inertance=150.0).info["model"].inertance == pytest.approx(150.0)
    assert quarter_car("device-afw", law="slider-dynamics").state_names[-2:] == (
        "hyd.afw.slider_radius",
        "hyd.afw.slider_rate",
    )
    with pytest.raises(ParameterError, match="suspension"):
        quarter_car("magic")
    with pytest.raises(ParameterError, match="inertance"):
        quarter_car("afw", inertance=100.0)
    with pytest.raises(ParameterError, match="changing_ratio"):
        quarter_car("traditional", changing_ratio=0.2)
    with pytest.raises(ParameterError, match="sprung_mass"):
        QuarterCarParameters(sprung_mass=-1)
    with pytest.raises(ParameterError, match="law"):
        quarter_car("afw", law="magic")


@pytest.mark.parametrize("ratio", [None, 0.1, 0.5])
def test_kernel_inertia_laws_match_flywheel_module(ratio):
    fw = flywheel("nylon", changing_ratio=ratio)
    car = describe_quarter_car("afw", flywheel=fw)
    p = car.kernel_parameters
    for w in (0.0, 10.0, -30.0, 45.0, 45.4, 46.0, 300.0):
        assert K.inertia(p, w) == pytest.approx(fw.inertia(w), rel=1e-13)
        assert K.momentum_inertia(p, w) == pytest.approx(fw.momentum_inertia(w), rel=1e-12)
    for w in (5.0, -40.0, 45.0, 120.0):
        ref, _ = quad(
            lambda s: fw.inertia(s),
            0.0,
            abs(w),
            points=[fw.saturation_speed],
            epsabs=0,
            epsrel=1e-13,
        )
        assert K.inertia_integral(p, w) == pytest.approx(math.copysign(ref, w), rel=1e-11)


def test_branch_velocity_solves_the_force_balance():
    b, ff, eps = 8100.0, 190.0, 1e-3
    for f in (0.0, 1.0, 150.0, -189.0, 200.0, -5000.0):
        u = K.branch_velocity(f, b, ff, eps)
        assert b * u + ff * math.tanh(u / eps) == pytest.approx(f, abs=1e-9)


@pytest.mark.parametrize("law", ["thesis", "momentum"])
def test_jump_impulse_compiled_equals_reference(law):
    car = describe_quarter_car("afw", law=law)
    y = np.r_[car.initial_state(), np.zeros(13)]
    y[1], y[3] = 0.01, -0.02
    y_ref = y.copy()
    K.apply_jump(car.kernel_parameters, y, 0.05)
    ReferenceRHS(car).apply_jump(y_ref, 0.05)
    np.testing.assert_allclose(y[:4], y_ref[:4], rtol=1e-10)


def test_compiled_rhs_equals_reference_rhs():
    seg = np.array([0.0, 1.0, 1.0, 0.0, 0.0, 0.05, 31.4, 0.3])
    from inerterlab.metrics import wk_sections

    rng = np.random.default_rng(0)
    for susp, law in [("traditional", "thesis"), ("cfw", "thesis"), ("afw", "thesis"), ("afw", "momentum"),
                      ("afw", "slider-dynamics"), ("device", "thesis"), ("device-afw", "thesis"),
                      ("device-afw", "slider-dynamics")]:  # fmt: skip
        car = describe_quarter_car(susp, law=law, tyre_lift_off=True)
        ref = ReferenceRHS(car)
        ref.seg = seg
        for _ in range(5):
            y = np.r_[car.initial_state(), np.zeros(13)] + rng.normal(size=car.n_states + 13) * 0.01
            if "slider_radius" in car.state_names:
                y[car.state_names.index("slider_radius")] = 0.03
            dy = np.empty_like(y)
            K.rhs(0.37, y, dy, car.kernel_parameters, seg, wk_sections())
            np.testing.assert_allclose(dy, ref(0.37, y), rtol=1e-10, atol=1e-10)
