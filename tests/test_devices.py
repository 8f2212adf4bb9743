"""Real devices (docs/model.md §3): linear limits, independent references, energy, step independence."""

import dataclasses
import math
import subprocess
import sys

import numpy as np
import pytest
from scipy import signal
from scipy.integrate import cumulative_trapezoid, solve_ivp

from inerterlab import ParameterError, constant_flywheel, flywheel
from inerterlab.devices import (
    HydraulicDevice,
    Motion,
    RectifierDevice,
    ScrewDevice,
    device_force,
    device_preset,
    motion_from_samples,
)

I_CONST = 2.5e-4  # kg m^2


def _series_ss(k, b, m):
    # states (x_k, v_a), input v, output F = k x_k  -- (3.15) without friction
    A = [[0.0, -1.0], [k / m, -b / m]]
    B = [[1.0], [0.0]]
    C = [[k, 0.0]]
    return signal.StateSpace(A, B, C, [[0.0]])


@pytest.mark.parametrize("cls", [HydraulicDevice, RectifierDevice])
def test_series_device_with_constant_flywheel_is_linear_system(cls):
    """(3.15) with constant m_e and no friction is LTI: compare with scipy.signal.lsim."""
    dev = cls(flywheel=constant_flywheel(I_CONST), friction=0.0)
    r = dev.transmission.ratio
    m = r * r * I_CONST
    mot = Motion.sine(frequency=3.0, amplitude=0.01)
    res = device_force(dev, mot, duration=2.0, sample_rate=2000, rtol=1e-10)
    sys_ = _series_ss(dev.stiffness, dev.damping, m)
    x0 = [res.spring_deflection[0], res.branch_velocity[0]]
    _, y, _ = signal.lsim(sys_, res.velocity, res.t, X0=x0, interp=True)
    scale = np.abs(y).max()
    assert np.abs(res.force - y).max() < 2e-5 * scale
    # and the steady state follows the transfer function (3.18)
    w = 2 * math.pi * 3.0
    G = (
        dev.stiffness
        * (m * 1j * w + dev.damping)
        / (dev.stiffness + m * (1j * w) ** 2 + dev.damping * 1j * w)
    )
    tail = res.t > 1.0
    v_amp = mot.velocity_amplitude
    # v = V cos(wt) -> F = |G| V cos(wt + arg G)
    f_ss = abs(G) * v_amp * np.cos(w * res.t + np.angle(G))
    # the transient decays as exp(-zeta wn t); after 1 s it is far below 1e-3 of the amplitude
    assert np.abs(res.force[tail] - f_ss[tail]).max() < 1e-3 * abs(G) * v_amp


def test_screw_with_constant_flywheel_is_closed_form():
    dev = ScrewDevice(flywheel=constant_flywheel(I_CONST), friction=0.0)
    m = dev.transmission.ratio**2 * I_CONST
    res = device_force(
        dev, Motion.sine(frequency=2.0, amplitude=0.01), duration=1.0, sample_rate=500
    )
    t = res.t
    w = 4 * math.pi
    x, v, a = 0.01 * np.sin(w * t), 0.01 * w * np.cos(w * t), -0.01 * w * w * np.sin(w * t)
    ref = dev.stiffness * x + dev.damping * v + m * a
    np.testing.assert_allclose(res.force, ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def test_screw_adaptive_thesis_law_against_numpy():
    """(3.38) with the nylon law and friction tanh(v/eps), computed independently."""
    dev = device_preset("screw")
    fw, r = flywheel("nylon"), dev.transmission.ratio
    mot = Motion.sine(frequency=2.0, amplitude=0.005)
    res = device_force(dev, mot, duration=1.0, sample_rate=400)
    t = res.t
    w = 4 * math.pi
    x, v, a = 0.005 * np.sin(w * t), 0.005 * w * np.cos(w * t), -0.005 * w * w * np.sin(w * t)
    ref = 1.97e6 * x + 7600 * v + 80 * np.tanh(v / 1e-3) + r**2 * fw.inertia(r * v) * a
    np.testing.assert_allclose(res.force, ref, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(res.equivalent_mass, r**2 * fw.inertia(r * v), rtol=1e-12)


def test_screw_backlash_removes_inertance_out_of_contact():
    dev = device_preset("screw", backlash=0.004)
    mot = Motion.sine(frequency=2.0, amplitude=0.005)
    full = device_force(device_preset("screw"), mot, duration=0.5, sample_rate=400)
    res = device_force(dev, mot, duration=0.5, sample_rate=400)
    elastic = dev.stiffness * res.displacement + dev.damping * res.velocity
    inside = np.abs(elastic) < dev.stiffness * dev.backlash  # (3.36)
    assert inside.any() and (~inside).any()
    no_inertia = elastic + dev.friction * np.tanh(res.velocity / 1e-3)
    np.testing.assert_allclose(res.force[inside], no_inertia[inside], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(res.force[~inside], full.force[~inside], rtol=1e-12, atol=1e-9)


def _hydraulic_reference(dev, mot, t_eval, y0):
    """(3.15), thesis law, integrated by scipy Radau at rtol 1e-10 with the flywheel's own law."""
    fw, r = dev.flywheel, dev.transmission.ratio
    k, b, f, eps = dev.stiffness, dev.damping, dev.friction, dev.friction_velocity

    def rhs(t, y):
        v = float(mot.velocity(t))
        xk, va = y
        fin = k * xk - b * va - f * math.tanh(va / eps)
        return [v - va, fin / (r * r * fw.inertia(r * va))]

    sol = solve_ivp(
        rhs,
        (t_eval[0], t_eval[-1]),
        y0,
        method="Radau",
        t_eval=t_eval,
        rtol=1e-10,
        atol=1e-13,
        max_step=2e-3,
    )
    assert sol.success
    return k * sol.y[0]


@pytest.mark.parametrize("sig", ["sine", "square"])
def test_hydraulic_adaptive_against_scipy_radau(sig):
    dev = device_preset("hydraulic")
    mot = (
        Motion.sine(frequency=1.0, amplitude=0.005)
        if sig == "sine"
        else Motion.square(frequency=0.5, velocity_amplitude=0.01)
    )
    res = device_force(dev, mot, duration=2.0, sample_rate=200, rtol=1e-10)
    ref = _hydraulic_reference(dev, mot, res.t, [res.spring_deflection[0], res.branch_velocity[0]])
    assert np.abs(res.force - ref).max() < 1e-6 * np.abs(ref).max()


def test_square_velocity_plateau_is_damping_plus_friction():
    """(5.1): on a velocity plateau F = b_ah q + F_fh once the series transient has decayed."""
    dev = device_preset("hydraulic")
    q = 0.01
    res = device_force(
        dev, Motion.square(frequency=0.05, velocity_amplitude=q), duration=15.0, sample_rate=20
    )
    plateau = (res.t > 11.0) & (res.t < 14.5)  # velocity -q from 5 s to 15 s
    np.testing.assert_allclose(res.force[plateau], -(dev.damping * q + dev.friction), rtol=1e-6)


def test_result_does_not_depend_on_step():
    """Smoothed friction with v_eps = 1e-3 m/s: the tolerance does not matter (a 1000x
    tighter one takes about 10^(3/5) = 4x the steps of the order-5 pair)."""
    dev = device_preset("hydraulic", flywheel_preset="nylon")
    mot = Motion.sine(frequency=1.0, amplitude=0.005)
    a = device_force(dev, mot, duration=2.0, sample_rate=200, rtol=1e-7)
    b = device_force(dev, mot, duration=2.0, sample_rate=200, rtol=1e-10)
    scale = np.abs(b.force).max()
    assert np.abs(a.force - b.force).max() < 1e-5 * scale
    assert b.steps > 3 * a.steps


@pytest.mark.parametrize("name", ["hydraulic", "screw", "rectifier"])
@pytest.mark.parametrize("law", ["momentum", "slider-dynamics"])
def test_energy_balance_energy_consistent_laws(name, law):
    """Work in = change of stored (spring + flywheel) + dissipated, to solver tolerance."""
    dev = device_preset(name, law=law, flywheel_preset="nylon")
    mot = Motion.sine(frequency=1.0, amplitude=0.02)  # crosses the saturation speed
    errs = []
    for rtol in (1e-7, 1e-10):
        res = device_force(dev, mot, duration=2.0, sample_rate=200, rtol=rtol)
        errs.append(np.abs(res.energy_residual).max() / np.abs(res.work).max())
    assert errs[1] < 1e-7
    assert errs[1] < errs[0] or errs[0] < 1e-8  # shrinks with the tolerance


def test_thesis_law_energy_imbalance_is_the_inertia_rate_term():
    """F = m_e(v) dv/dt does not conserve energy: work - stored - dissipated equals
    -int 1/2 (dI/dt) omega^2 dt - (slider spring energy ignored); here the flywheel stored
    energy is taken as 1/2 I omega^2."""
    dev = device_preset("screw", law="thesis")
    mot = Motion.sine(frequency=1.0, amplitude=0.01)
    res = device_force(dev, mot, duration=2.0, sample_rate=4000, rtol=1e-10)
    r = dev.transmission.ratio
    inertia = res.equivalent_mass / r**2
    omega = r * res.velocity
    didt = np.gradient(inertia, res.t)
    expected = cumulative_trapezoid(-0.5 * didt * omega**2, res.t, initial=0.0)
    imbalance = res.energy_residual
    kinetic = 0.5 * inertia * omega**2
    assert np.abs(imbalance).max() > 0.02 * kinetic.max()  # clearly not zero
    assert np.abs(imbalance - expected).max() < 2e-3 * np.abs(imbalance).max()


def test_rectifier_freewheel():
    dev = device_preset("rectifier", freewheel=True, flywheel_drag=0.002)
    mot = Motion.sine(frequency=1.0, amplitude=0.02)
    res = device_force(dev, mot, duration=3.0, sample_rate=500, rtol=1e-9)
    free = res.freewheeling
    assert 0.1 < free.mean() < 0.9
    # free-wheeling: the branch has no inertance, F = b v_a + f tanh(v_a/eps); the core
    # integrates v_a (the derivative of that balance), so the balance holds to the
    # integration's tolerance: k times the error of the spring deflection, measured
    # 4e-7 of the peak force at rtol 1e-9
    fb = dev.damping * res.branch_velocity + dev.friction * np.tanh(res.branch_velocity / 1e-3)
    np.testing.assert_allclose(res.force[free], fb[free], rtol=0, atol=2e-6 * np.abs(res.force).max())
    # the flywheel never turns slower than it is driven, and free time = overrunning
    assert np.all(
        res.flywheel_speed[free]
        >= dev.transmission.ratio * np.abs(res.branch_velocity[free]) - 1e-6
    )
    assert np.abs(res.energy_residual).max() < 1e-5 * np.abs(res.work).max()
    coupled = device_force(
        dataclasses.replace(dev, freewheel=False), mot, duration=3.0, sample_rate=500
    )
    assert np.abs(coupled.force).max() > np.abs(res.force).max()


def test_sampled_motion_matches_analytic():
    mot = Motion.sine(frequency=1.0, amplitude=0.01)
    t = np.linspace(0, 2, 2001)
    x, v, _ = mot.evaluate(t)
    dev = device_preset("hydraulic")
    a = device_force(dev, mot, t=t)
    b = device_force(dev, motion_from_samples(t, x, v), t=t)
    assert np.abs(a.force - b.force).max() < 1e-4 * np.abs(a.force).max()


def test_sampled_acceleration_is_fourth_order_from_the_velocity_alone():
    """The node accelerations of a sampled motion: fourth-order accurate on a smooth
    motion (uniform and jittered spacing), blind to the displacement samples, and with
    a velocity-noise gain of the five-point stencil (sqrt(130) / 12 per sample step)."""
    w = 2 * np.pi * 10.0

    def err(n, jitter=0.0):
        t = np.linspace(0.0, 1.0, n)
        t = t + jitter * (t[1] - t[0]) * np.sin(37.0 * t)
        mot = motion_from_samples(t, 0.005 * np.sin(w * t), 0.005 * w * np.cos(w * t))
        _, _, a = mot.evaluate(t)
        return np.abs(a + 0.005 * w * w * np.sin(w * t)).max() / (0.005 * w * w)

    e1, e2 = err(501), err(1001)
    assert e1 < 2e-5 and 12.0 < e1 / e2 < 20.0  # halving the step: about 16x
    # spacing that wanders by 10 %: the stencil reads the mean spacing, still convergent
    e1, e2 = err(501, 0.1), err(1001, 0.1)
    assert e1 < 1e-4 and e1 / e2 > 3.5
    t = np.arange(2001) / 500.0
    rng = np.random.default_rng(3)
    x = 0.005 * np.sin(w * t)
    v = 0.005 * w * np.cos(w * t)
    clean = motion_from_samples(t, x, v).evaluate(t)[2]
    noisy_x = motion_from_samples(t, x + 1e-6 * rng.standard_normal(t.size), v).evaluate(t)[2]
    np.testing.assert_array_equal(clean, noisy_x)
    dv = 1e-5 * rng.standard_normal(t.size)
    gain = np.std(motion_from_samples(t, x, v + dv).evaluate(t)[2][2:-2] - clean[2:-2])
    assert gain == pytest.approx(1e-5 * 500.0 * np.sqrt(130.0) / 12.0, rel=0.1)


def test_triangle_is_square_velocity():
    a = Motion.triangle(frequency=0.5, amplitude=0.01)
    b = Motion.square(frequency=0.5, velocity_amplitude=0.02)
    t = np.linspace(0, 4, 801)
    for p, q in zip(a.evaluate(t), b.evaluate(t), strict=True):
        np.testing.assert_allclose(p, q)
    x, v, _ = a.evaluate(t)
    assert v.max() == pytest.approx(0.02) and x.max() <= 0.01


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"stiffness": -1.0}, "stiffness"),
        ({"damping": float("nan")}, "damping"),
        ({"law": "magic"}, "law"),
        ({"friction_velocity": 0.0}, "friction_velocity"),
    ],
)
def test_bad_parameters(kwargs, name):
    with pytest.raises(ParameterError, match=name):
        HydraulicDevice(**kwargs)


def test_bad_motion():
    with pytest.raises(ParameterError, match="amplitude"):
        Motion.sine(frequency=1.0)
    with pytest.raises(ParameterError, match="frequency"):
        Motion.sine(frequency=-1.0, amplitude=0.01)


def _cli(*args):
    return subprocess.run(
        [
            sys.executable,
            "-c",
            "from inerterlab.cli import main; import sys; sys.exit(main())",
            *args,
        ],
        capture_output=True,
        text=True,
    )


def test_cli_device_force_json_and_errors(tmp_path):
    import json

    out = _cli(
        "device-force",
        "--device",
        "screw",
        "--signal",
        "sine",
        "--freq",
        "2",
        "--amplitude",
        "0.005",
        "--duration",
        "0.5",
        "--sample-rate",
        "200",
        "--json",
        "--csv",
        str(tmp_path / "f.csv"),
    )
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert set(data) == {"t", "force", "equivalent_mass"} and len(data["t"]) == 101
    dev = device_preset("screw")
    res = device_force(
        dev, Motion.sine(frequency=2, amplitude=0.005), duration=0.5, sample_rate=200
    )
    np.testing.assert_allclose(data["force"], res.force)
    lines = (tmp_path / "f.csv").read_text().splitlines()
    assert lines[0] == "t,force,equivalent_mass" and len(lines) == 102
    bad = _cli("device-force", "--amplitude", "abc")
    assert (
        bad.returncode == 2
        and "amplitude" in bad.stderr
        and len(bad.stderr.strip().splitlines()) == 1
    )
    bad = _cli("device-force", "--amplitude", "0.01", "--freq", "-2")
    assert bad.returncode == 2 and "freq" in bad.stderr


def test_rectifier_default_start_includes_bearing_drag():
    # "as if it had been moving steadily": at t = 0 the spring carries the whole steady
    # branch force, bearing drag c_d r^2 v0 included, so the branch starts with the
    # terminals and no start-up transient pulls it away from them
    dev = device_preset("rectifier", freewheel=True, flywheel_drag=0.002)
    mot = Motion.sine(frequency=1.0, amplitude=0.02)
    v0 = 0.02 * 2 * math.pi  # terminal velocity at t = 0, where the acceleration is zero
    r = dev.transmission.ratio
    expected = (
        dev.damping * v0
        + dev.friction * math.tanh(v0 / dev.friction_velocity)
        + dev.flywheel_drag * r * r * v0
    )
    assert dev.flywheel_drag * r * r * v0 > 100.0  # the term is not negligible here
    res = device_force(dev, mot, duration=0.02, sample_rate=1000, rtol=1e-10)
    assert res.force[0] == pytest.approx(expected, rel=1e-12)
    # the branch follows the terminals closely over the first 5 ms
    v = res.velocity
    # (6e-5 with the drag term, 4.5e-4 without it)
    assert np.abs(res.branch_velocity[:6] - v[:6]).max() < 1e-3 * v0


def test_slider_dynamics_losses_are_the_laws_own():
    """The ledger's dissipation under slider-dynamics against an independent quadrature
    at 20 kHz of what the models dissipate: c v_a^2 + f tanh(v_a/eps) v_a in the branch
    and the sliders' own loss rate (damping and stop impacts) from their states."""
    from scipy.integrate import trapezoid

    from inerterlab.slider_dynamics import slider_state_derivative

    dev = device_preset("hydraulic", law="slider-dynamics", flywheel_preset="nylon")
    mot = Motion.sine(frequency=1.0, amplitude=0.02)  # the sliders reach their stops
    t = np.linspace(0.0, 1.0, 20001)
    res = device_force(dev, mot, t=t, rtol=1e-10)
    va = res.branch_velocity
    co = dev.slider_dynamics.coefficients(dev.flywheel)
    r = dev.transmission.ratio
    slider = np.array([
        slider_state_derivative(l, ld, r * v, co[1], co[2], co[3], co[4], co[5], co[6], co[7],
                                co[8])[1]
        for l, ld, v in zip(res.slider_position, res.slider_rate, va, strict=True)
    ])  # fmt: skip
    branch = dev.damping * va**2 + dev.friction * np.tanh(va / dev.friction_velocity) * va
    expected = trapezoid(branch + slider, t)
    assert slider.max() > 0.0
    assert res.dissipated[-1] == pytest.approx(expected, rel=1e-5)
