"""Energy balance of the slider-dynamics law under a prescribed flywheel speed."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from inerterlab import ParameterError, flywheel
from inerterlab.slider_dynamics import (
    SliderDynamics,
    slider_state_derivative,
    stored_energy,
)


def rotor_torque(l, ldot, omega, omega_dot, rest_inertia, n, m_s):
    """Torque [N m] that drives the rotor: d/dt[(I_rest + n m_s l^2) omega]."""
    return (rest_inertia + n * m_s * l * l) * omega_dot + 2.0 * n * m_s * l * ldot * omega


def _run(fw, opts, omega_amp, freq, t_end):
    ri, n, m, k, lmin, lmax, cs, kc, cc = opts.coefficients(fw)
    w = 2 * math.pi * freq

    def om(t):
        return omega_amp * math.sin(w * t), omega_amp * w * math.cos(w * t)

    def rhs(t, y):
        l, ld = y[0], y[1]
        o, od = om(t)
        lacc, diss = slider_state_derivative(l, ld, o, n, m, k, lmin, lmax, cs, kc, cc)
        torque = rotor_torque(l, ld, o, od, ri, n, m)
        return [ld, lacc, torque * o, diss]

    sol = solve_ivp(rhs, (0, t_end), [lmin, 0.0, 0.0, 0.0], method="LSODA", rtol=1e-10, atol=1e-13)
    assert sol.success
    l, ld, work, diss = sol.y[:, -1]
    o, _ = om(sol.t[-1])
    e1 = stored_energy(l, ld, o, ri, n, m, k, lmin, lmax, kc)
    e0 = stored_energy(lmin, 0.0, 0.0, ri, n, m, k, lmin, lmax, kc)
    return work, e1 - e0, diss, sol


@pytest.mark.parametrize("omega_amp", [30.0, 200.0])  # below and far above saturation
def test_work_equals_stored_plus_dissipated(omega_amp):
    fw = flywheel("nylon")
    work, de, diss, sol = _run(fw, SliderDynamics(), omega_amp, 2.0, 1.3)
    scale = max(abs(work), 1e-9)
    assert abs(work - de - diss) / scale < 1e-6
    assert diss >= 0
    if omega_amp > fw.saturation_speed:
        assert sol.y[0].max() > fw.slider_max - 1e-3  # reached the stop


def test_lossless_without_damping_slow_motion_tracks_quasi_static():
    fw = flywheel("nylon")
    opts = SliderDynamics(damping_ratio=0.0, restitution=1.0)
    work, de, diss, sol = _run(fw, opts, 30.0, 0.05, 5.0)
    assert abs(work - de) <= 1e-7 * max(abs(work), 1.0)
    # slow speed change: the slider follows the quasi-static law (3.9) closely
    t = sol.t[-1]
    quasi = fw.slider_position(30.0 * math.sin(2 * math.pi * 0.05 * t))
    assert sol.y[0, -1] == pytest.approx(quasi, abs=2e-4)


def test_thesis_literal_rejected():
    with pytest.raises(ParameterError, match="law"):
        SliderDynamics().coefficients(flywheel("metal", law="thesis-literal"))


def test_options_validated():
    with pytest.raises(ParameterError, match="restitution"):
        SliderDynamics(restitution=0.0)
    assert np.isfinite(SliderDynamics().coefficients(flywheel("metal"))).all()
