"""Model core: a measured drive (displacement, velocity and acceleration samples) as the
road of a core system, against the device models' sampled motion and closed forms."""

import math

import numpy as np
import pytest

from inerterlab.devices import device_force, device_preset, motion_from_samples
from inerterlab.errors import ParameterError
from inerterlab.excitation import drive_series, road_displacement, sine
from inerterlab.systems import quarter_car, rig

FS = 500.0


def _noisy_sine(duration=2.0, t0=0.0, seed=1):
    t = t0 + np.arange(int(round(duration * FS)) + 1) / FS
    w, amp = 2.0 * math.pi * 2.0, 0.004
    rng = np.random.default_rng(seed)
    x = amp * np.sin(w * t) + 1e-6 * rng.standard_normal(t.size)
    v = amp * w * np.cos(w * t) + 1e-4 * rng.standard_normal(t.size)
    return t, x, v


def test_drive_passes_through_the_samples_like_the_sampled_motion():
    """Between the samples the drive is the device models' cubic Hermite, and its
    acceleration the velocity-only channel (not the cubic's second derivative)."""
    t, x, v = _noisy_sine()
    drive = drive_series(t, x, v)
    motion = motion_from_samples(t, x, v)
    segs = drive.segments(t[-1])
    tq = np.linspace(0.0, t[-1], 7919)
    xd, vd = road_displacement(segs, tq)
    xm, vm, am = motion.evaluate(tq)
    assert np.abs(xd - xm).max() <= 1e-12 * np.abs(xm).max()
    assert np.abs(vd - vm).max() <= 1e-11 * np.abs(vm).max()
    # the acceleration channel: the same array the device models read
    assert np.array_equal(drive.acceleration, motion.kernel_args()[4][t.size :])
    # a parallel network reads the road's acceleration: k | c | b gives k x + c v + b a
    k, c, b = 5e4, 800.0, 120.0
    res = rig("k | c | b", {"k": k, "c": c, "b": b}).simulate(drive, t[-1], sample_rate=FS)
    f = res.outputs["force"]
    ref = k * x + c * v + b * drive.acceleration
    assert np.allclose(res.time, t - t[0])
    assert np.abs(f - ref).max() <= 1e-10 * np.abs(ref).max()


@pytest.mark.parametrize("name", ["screw", "hydraulic", "rectifier"])
def test_device_in_rig_on_measured_drive_equals_device_model(name):
    """The same noisy record at 500 Hz drives the core rig and devices.device_force.
    Measured, both at rtol 1e-10: 3.6e-15 (screw), 2.3e-8 (hydraulic), 6.3e-9
    (rectifier) of the peak force."""
    t, x, v = _noisy_sine()
    dev = device_preset(name)
    ref = device_force(dev, motion_from_samples(t, x, v), t=t, rtol=1e-10, initial_force=0.0)
    r = rig(dev)
    x0 = None
    if dev.series:  # the spring unloaded, the branch moving with the drive
        x0 = np.zeros(r.n_states)
        node = r.state_names[0].rpartition(".")[0]
        x0[r.state_names.index(f"{node}.x")] = x[0]
        x0[r.state_names.index(f"{node}.v")] = v[0]
    res = r.simulate(drive_series(t, x, v), t[-1], rtol=1e-10, sample_rate=FS, x0=x0)
    f = res.outputs["force"]
    assert np.abs(f - ref.force).max() <= 1e-7 * np.abs(ref.force).max()


def test_network_with_internal_node_on_drive_converges_to_the_analytic_sine():
    """k | (c - b) with the massless node between damper and inerter: the drive sampled
    from an exact sine gives the sine's response to the Hermite interpolation error,
    which falls by about 16 when the sampling rate doubles (fourth order). Measured:
    6.5e-7 at 100 Hz, 4.0e-8 at 200 Hz of the peak force."""
    params = {"k": 5e4, "c": 2e3, "b": 150.0}
    r = rig("k | (c - b)", params)
    w, amp = 2.0 * math.pi * 3.0, 0.01
    x0 = np.zeros(r.n_states)  # given, so neither road starts with an impulse
    ref = r.simulate(sine(amp, 3.0), 1.0, rtol=1e-12, sample_rate=100.0, x0=x0)
    errs = []
    for fs in (100.0, 200.0):
        t = np.arange(int(fs) + 1) / fs
        a = -amp * w * w * np.sin(w * t)
        drive = drive_series(t, amp * np.sin(w * t), amp * w * np.cos(w * t), a)
        res = r.simulate(drive, 1.0, rtol=1e-12, sample_rate=100.0, x0=x0)
        f, fr = res.outputs["force"], ref.outputs["force"]
        errs.append(np.abs(f - fr).max() / np.abs(fr).max())
    assert errs[1] < 1e-7
    assert 8.0 < errs[0] / errs[1] < 32.0, errs


def test_drive_starting_late_is_led_in_at_its_first_velocity():
    t, x, v = _noisy_sine(duration=0.5, t0=0.25)
    drive = drive_series(t, x, v)
    segs = drive.segments(t[-1])
    assert segs[0, 0] == 0.0 and segs[0, 1] == t[0]
    x_in, v_in = road_displacement(segs, np.array([0.0, t[0] - 1e-12, t[0]]))
    assert x_in[0] == pytest.approx(x[0] - v[0] * t[0], abs=1e-15)
    assert abs(x_in[1] - x[0]) < 1e-12 and v_in[1] == v[0] == v_in[2]
    # no velocity jump at t = 0 or at the first sample: no impulse through the inerter
    res = rig("k | b", {"k": 1e4, "b": 50.0}).simulate(drive, t[-1], sample_rate=FS)
    assert "road_velocity_jumps" not in res.stats
    assert drive.initial_road_velocity(1.0) == v[0]


def test_drive_bad_input_and_refusal_outside_the_core():
    t, x, v = _noisy_sine(duration=0.1)
    with pytest.raises(ParameterError, match="velocity"):
        drive_series(t, x, v[:-1])
    with pytest.raises(ParameterError, match="time"):
        drive_series(t[::-1], x, v)
    with pytest.raises(ParameterError, match="acceleration"):
        drive_series(t, x, v, np.full(t.size, np.nan))
    from inerterlab.simulate import simulate

    with pytest.raises(ParameterError, match="core systems"):
        simulate(quarter_car("traditional"), drive_series(t, x, v), horizon=0.1)


@pytest.mark.parametrize("method", ["exact", "adaptive"])
def test_explicit_sample_times_equal_the_uniform_samples(method):
    from inerterlab.excitation import bump
    from inerterlab.systems import quarter_car

    car = quarter_car("k | (c - b)", {"k": 9e4, "c": 3e3, "b": 200.0})
    every = car.simulate(bump(), 1.0, method=method)
    some = car.simulate(bump(), 1.0, method=method, times=[0.1, 0.2, 0.55, 1.0])
    ref = every.outputs["body.x"][[100, 200, 550, 1000]]
    # the uniform run carries the ride observers (their states share the step control:
    # another step sequence for adaptive steps, another grid of exact ones)
    tol = 1e-15 if method == "exact" else 1e-7 * np.abs(every.outputs["body.x"]).max()
    assert np.abs(some.outputs["body.x"] - ref).max() <= tol
    assert some.metrics is None and every.metrics["rms_body_acc"] > 0
    for bad in ([0.5, 0.2], [0.1, 2.0], [-0.1, 0.2], [np.nan]):
        with pytest.raises(ParameterError, match="times"):
            car.simulate(bump(), 1.0, times=bad)


@pytest.mark.parametrize("network", ["hyd", "k | (c - b)", "screw"])
def test_drive_runs_equal_the_simulation_from_the_first_sample(network):
    """DriveRuns (the identification's repeated runs: force only, segments built once)
    gives the force System.simulate gives on the same record and start, over the whole
    record and over its first m samples; for a record starting at 0 the two integrate
    the same segments, so they agree to round-off."""
    from inerterlab.systems import DriveRuns

    params = {"k": 5e4, "c": 2e3, "b": 150.0} if network.startswith("k") else None
    t, x, v = _noisy_sine()
    drive = drive_series(t, x, v)
    r = rig(network, params)
    x0 = np.zeros(r.n_states)
    for i, name in enumerate(r.state_names):
        x0[i] = {"x": x[0], "v": v[0]}.get(name.rpartition(".")[2], 0.0)
    runs = DriveRuns(drive)
    for m in (t.size, 301):
        ref = r.simulate(drive, t[m - 1], rtol=1e-9, x0=x0, times=t[:m]).outputs["force"]
        f = runs.force(r, x0, m, rtol=1e-9)
        assert f.shape == (m,)
        assert np.abs(f - ref).max() <= 1e-12 * np.abs(ref).max()


def test_drive_runs_start_at_the_first_sample_of_a_late_record():
    """A record starting at 0.25 s: the runs start at its first sample. For the
    parallel pair k | c the force is algebraic, k x + c v at every sample; for the
    series pair k - c it starts at the spring force the given state holds."""
    from inerterlab.systems import DriveRuns

    t, x, v = _noisy_sine(duration=0.5, t0=0.25)
    runs = DriveRuns(drive_series(t, x, v))
    f = runs.force(rig("k | c", {"k": 1e4, "c": 100.0}), np.empty(0))
    assert np.abs(f - (1e4 * x + 100.0 * v)).max() <= 1e-12 * np.abs(f).max()
    r = rig("k - c", {"k": 1e4, "c": 100.0})
    f0 = 3.0
    x0 = np.array([x[0] - f0 / 1e4])
    f = runs.force(r, x0, rtol=1e-10)
    assert f[0] == pytest.approx(f0, rel=1e-12)


def test_drive_runs_refuse_bad_input():
    from inerterlab.systems import DriveRuns, quarter_car

    t, x, v = _noisy_sine(duration=0.1)
    with pytest.raises(ParameterError, match="drive"):
        DriveRuns(sine(0.01, 1.0))
    runs = DriveRuns(drive_series(t, x, v))
    with pytest.raises(ParameterError, match="rig"):
        runs.force(quarter_car("traditional"), np.zeros(4))
    r = rig("k - c", {"k": 1e4, "c": 100.0})
    with pytest.raises(ParameterError, match="m"):
        runs.force(r, np.zeros(1), 0)
    with pytest.raises(ParameterError, match="x0"):
        runs.force(r, np.zeros(3))
    with pytest.raises(ParameterError, match="rtol"):
        runs.force(r, np.zeros(1), rtol=-1.0)
