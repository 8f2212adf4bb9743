import numpy as np
import pytest

from inerterlab import flywheel, inertance, transmission
from inerterlab.errors import ParameterError
from inerterlab.transmissions import inverse_screw


def test_ratios_from_tables():
    assert transmission("hydraulic").ratio == pytest.approx(0.001256 / 1.30607e-6)
    assert transmission("hydraulic").ratio == pytest.approx(961.66, abs=0.01)
    assert transmission("rectifier").ratio == pytest.approx(1318.6, abs=0.05)
    assert transmission("screw").ratio == pytest.approx(501.35, abs=0.01)


def test_equivalent_masses_of_spec():
    r2 = transmission("hydraulic").ratio ** 2
    ny, me = flywheel("nylon"), flywheel("metal")
    assert r2 * ny.inertia_min == pytest.approx(206.2, abs=0.05)
    assert r2 * ny.inertia_max == pytest.approx(288.4, abs=0.05)
    assert r2 * me.inertia_min == pytest.approx(882.1, abs=0.05)
    assert r2 * me.inertia_max == pytest.approx(998.7, abs=0.05)


def test_momentum_inertance_is_derivative_of_momentum():
    fw, tr = flywheel("nylon"), transmission("hydraulic")
    v = np.linspace(-0.06, 0.06, 41)
    h = 1e-8
    p = lambda vv: tr.ratio * fw.inertia(tr.ratio * vv) * tr.ratio * vv  # noqa: E731  r * I * omega
    fd = (p(v + h) - p(v - h)) / (2 * h)
    np.testing.assert_allclose(inertance(fw, tr, v, law="momentum"), fd, rtol=1e-5)


def test_bad_screw_angle():
    with pytest.raises(ParameterError, match="helix_angle_deg"):
        inverse_screw(helix_angle_deg=95)
