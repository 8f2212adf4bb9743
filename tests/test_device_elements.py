"""The device elements against closed forms: the one-way clutch's disengagement and
re-engagement instants and the bearing drag's decay of the free flywheel, the ball
screw's contact rule with backlash (tests/test_devices.py), the drag as a damper."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from inerterlab.elements import BearingDrag, OneWayClutch, ScrewContact
from inerterlab.excitation import sine
from inerterlab.systems import rig

A, F = 0.02, 1.0  # drive x = A sin(w t) [m], [Hz]
W = 2 * math.pi * F
R, CD = 1000.0, 1e-3  # ratio [rad/m], bearing drag [N m s/rad]


def _clutch():
    return OneWayClutch(flywheel="metal", ratio=R, drag=CD)


def test_clutch_events_and_free_decay_closed_form():
    """The drive starts at A w from rest: the clutch spins the flywheel to r A w (above
    the metal flywheel's saturation, so I = I_max) and passes m_e a + c_d r^2 v, which
    turns negative at tan(w t_d) = c_d / (I_max w); from there the flywheel runs free,
    omega = r A w cos(w t_d) exp(-c_d (t - t_d) / I_max), with no force, until the shaft
    catches up, r A w |cos w t_e| = omega(t_e). Sampled 1 us either side of both
    instants (the engagement 100 us after t_d: a sample reads the mode from the state,
    and the flywheel and the shaft part only quadratically in time after t_d, by less
    than the 1e-10 the clutch allows within about 3 us) and along the free interval."""
    el = _clutch()
    i_max = el.wheel.inertia_max
    t_d = math.atan(CD / (i_max * W)) / W
    w0 = R * A * W * math.cos(W * t_d)
    assert w0 * math.exp(-0.5 * CD / i_max) > el.wheel.saturation_speed  # I = I_max throughout

    def omega_free(t):
        return w0 * np.exp(-CD * (t - t_d) / i_max)

    t_e = brentq(lambda t: R * A * W * abs(math.cos(W * t)) - omega_free(t), 0.26, 0.5, xtol=1e-14)
    d = 1e-6
    free_t = np.linspace(t_d + 0.01, t_e - 0.01, 50)
    times = np.sort(np.concatenate([[t_d - d, t_d + 100 * d, t_e - d, t_e + d], free_t]))
    sys = rig("owc", {"owc": el})
    res = sys.simulate(sine(A, F), 0.5, rtol=1e-11, times=times)
    force = res.outputs["force"]
    omega = res.states[:, sys.state_names.index("owc.flywheel_speed")]
    at = {t: j for j, t in enumerate(times)}
    # engaged just before t_d: m_e a + c_d r^2 v, which passes through zero at t_d
    tb = t_d - d
    before = -R * R * i_max * A * W * W * math.sin(W * tb) + CD * R * R * A * W * math.cos(W * tb)
    assert before > 0.0 and force[at[tb]] == pytest.approx(before, rel=1e-4)
    assert force[at[t_d + 100 * d]] == 0.0 and force[at[t_e - d]] == 0.0  # free between
    assert abs(force[at[t_e + d]]) > 1.0  # engaged again
    j = np.searchsorted(times, free_t)
    np.testing.assert_array_equal(force[j], 0.0)
    np.testing.assert_allclose(omega[j], omega_free(free_t), rtol=1e-8)
    assert res.stats["events"] >= 2


def test_clutch_engaged_is_the_flywheel_inerter_with_drag():
    """While it drives (the first instants), the force is r^2 I(r|v|) a + c_d r^2 v."""
    el = _clutch()
    times = np.linspace(0.0, 0.02, 21)[1:]
    sys = rig("owc", {"owc": el})
    res = sys.simulate(sine(A, F), 0.02, rtol=1e-11, times=times)
    v = A * W * np.cos(W * times)
    a = -A * W * W * np.sin(W * times)
    engaged = times < math.atan(CD / (el.wheel.inertia_max * W)) / W
    expected = R * R * el.wheel.inertia(R * np.abs(v)) * a + CD * R * R * v
    assert engaged.sum() >= 1
    np.testing.assert_allclose(res.outputs["force"][engaged], expected[engaged], rtol=1e-9)


def test_bearing_drag_is_the_rotary_damper():
    el = BearingDrag(drag=CD, ratio=R)
    assert el.rest_network() == ("c", {"c": pytest.approx(CD * R * R)})
    res = rig("drag", {"drag": el}).simulate(sine(A, F), 0.5, rtol=1e-10, sample_rate=100)
    v = A * W * np.cos(W * res.time)
    np.testing.assert_allclose(res.outputs["force"][1:], CD * R * R * v[1:], rtol=1e-12)


def test_screw_contact_without_backlash_is_the_flywheel_inerter():
    from inerterlab.elements import AdaptiveFlywheelInerter

    gated = rig("sgap", {"sgap": ScrewContact(flywheel="nylon", ratio=500.0)})
    plain = rig("afw", {"afw": AdaptiveFlywheelInerter(flywheel="nylon", ratio=500.0)})
    a = gated.simulate(sine(0.005, 2.0), 0.5, rtol=1e-10, sample_rate=200).outputs["force"]
    b = plain.simulate(sine(0.005, 2.0), 0.5, rtol=1e-10, sample_rate=200).outputs["force"]
    np.testing.assert_array_equal(a, b)
