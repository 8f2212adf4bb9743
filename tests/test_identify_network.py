"""identify_network: any network's parameters from rig data, on the model core's rig."""

import math

import numpy as np
import pytest

from inerterlab.devices import device_preset
from inerterlab.errors import ParameterError
from inerterlab.excitation import drive_series
from inerterlab.identify import RigDataSet, RigTest, identify, identify_network, simulate_rig
from inerterlab.identify.fit import _prepare
from inerterlab.systems import device_network, rig

FS = 500.0


def _subset(data, n_ident=10, n_val=3):
    ident = data.select("identification")[:n_ident]
    val = data.select("validation")[:n_val]
    return RigDataSet(tests=tuple(ident + val), source=data.source)


@pytest.fixture(scope="module")
def screw_data():
    return _subset(simulate_rig(device_preset("screw"), max_duration=2.0, seed=3))


def test_screw_as_a_network_equals_the_device_fit(screw_data):
    """The same objective on two engines: identify (device kernel, exact affine
    Jacobian) and identify_network on the core rig (finite differences). Estimates and
    intervals agree to a small fraction of a standard error (measured: 7e-8 se on the
    whole 2 s campaign)."""
    dev = device_preset("screw")
    a = identify(screw_data, dev)
    text, params = device_network(dev)
    assert text == "screw"
    names = ("stiffness", "damping", "friction")
    b = identify_network(
        screw_data, "screw", params, free=[f"screw.{n}" for n in names],
        reversal_window=a.reversal_window,
    )  # fmt: skip
    for n in names:
        pa, pb = a.parameters[n], b.parameters[f"screw.{n}"]
        assert abs(pb.value - pa.value) <= 1e-4 * pa.std_error, (n, pa.value, pb.value)
        assert pb.std_error == pytest.approx(pa.std_error, rel=1e-4)
    assert b.parameters["screw.damping"].unit == "N s/m"
    assert {t.name for t in b.tests} == {t.name for t in screw_data.tests}


def test_parallel_linear_network_is_the_linear_regression(screw_data):
    """k | c | b in the rig is F = k x + c v + b a: with plain least squares and every
    sample used, the fit is the linear regression of the force on the prepared x, v
    and the drive's acceleration channel, whatever made the data."""
    res = identify_network(
        screw_data, "k | c | b", {"k": 1e6, "c": 5e3, "b": 100.0}, free=("k", "c", "b"),
        loss="linear", reversal_window=0.0,
    )  # fmt: skip
    rows, rhs = [], []
    for t in screw_data.select("identification"):
        p = _prepare(t, window=0.02, detrend="constant", reversal_window=0.0)
        a = drive_series(p.t, p.x, p.v).acceleration
        rows.append(np.column_stack([p.x, p.v, a]))
        rhs.append(p.force)
    theta, *_ = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)
    for name, ref in zip(("k", "c", "b"), theta, strict=True):
        assert res.parameters[name].value == pytest.approx(ref, rel=1e-6), name


def _records(net, params, x_start):
    """Noise-free forces of ``net`` in the core rig on three sine drives, each started
    from a state off the network's own start (an unknown initial state)."""
    r = rig(net, params)
    tests = []
    for i, (f, amp) in enumerate([(1.0, 0.01), (3.0, 0.004), (6.0, 0.002)]):
        t = np.arange(int(1.5 * FS) + 1) / FS
        w = 2 * math.pi * f
        x, v = amp * np.sin(w * t + 0.3), amp * w * np.cos(w * t + 0.3)
        drive = drive_series(t, x, v, -amp * w * w * np.sin(w * t + 0.3))
        res = r.simulate(drive, t[-1], rtol=1e-12, x0=np.asarray(x_start[i]), times=t)
        tests.append(
            RigTest(name=f"t{i}", signal="sine", frequency=f, amplitude=amp,
                    purpose="identification", t=t, force=res.outputs["force"],
                    displacement=x, velocity=v)  # fmt: skip
        )
    return RigDataSet(tests=tuple(tests), source="core rig")


def test_series_network_recovered_despite_an_unknown_initial_state():
    """k - (c | b): an internal node whose initial displacement and velocity are not
    known; the projection of the free response is exact for a linear network, so the
    truth comes back from noise-free records started anywhere."""
    truth = {"k": 8e4, "c": 1500.0, "b": 90.0}
    starts = [(0.002, -0.05), (-0.001, 0.2), (0.0005, 0.0)]
    data = _records("k - (c | b)", truth, starts)
    start = {"k": 6e4, "c": 2000.0, "b": 60.0}
    res = identify_network(
        data, "k - (c | b)", start, free=("k", "c", "b"), loss="linear",
        reversal_window=0.0, rtol=1e-12,
    )  # fmt: skip
    for n, v in truth.items():
        assert res.parameters[n].value == pytest.approx(v, rel=1e-5), n
    assert res.cost <= 1e-6 * max(np.abs(t.force).max() for t in data.tests)


def test_bad_input_is_named(screw_data):
    with pytest.raises(ParameterError, match="free"):
        identify_network(screw_data, "k | c", {"k": 1e5, "c": 1e3}, free=("b",))
    with pytest.raises(ParameterError, match="k"):
        identify_network(screw_data, "k | c", {"k": "soft", "c": 1e3}, free=("k",))
    with pytest.raises(ParameterError, match="free"):
        identify_network(screw_data, "k | c", {"k": 1e5, "c": 1e3}, free=())
    with pytest.raises(ParameterError, match="interval"):
        identify_network(screw_data, "k | c", {"k": 1e5, "c": 1e3}, free=("k",),
                         interval="profile")  # fmt: skip


def test_cli_identify_network(tmp_path):
    import json
    import subprocess
    import sys

    def run(*a):
        code = "import sys; from inerterlab.cli import main; sys.exit(main())"
        return subprocess.run([sys.executable, "-c", code, *a], capture_output=True, text=True)

    out = run("rig-simulate", "--device", "screw", "--matrix", "appendix-a2", "--max-duration",
              "0.5", "--sample-rate", "100", "--seed", "1", "--out", str(tmp_path / "d"))  # fmt: skip
    assert out.returncode == 0, out.stderr
    args = ["identify", "--data", str(tmp_path / "d"), "--network", "k | c | b",
            "--param", "k=2e6,c=7000", "--param", "b=100", "--free", "k,c", "--free", "b"]  # fmt: skip
    out = run(*args, "--json")
    assert out.returncode == 0, out.stderr
    res = json.loads(out.stdout)
    assert res["free"] == ["k", "c", "b"] and res["network"] == "k | c | b"
    for p in res["parameters"].values():
        lo, hi = p["ci95"]
        assert lo < p["value"] < hi
    assert res["parameters"]["b"]["unit"] == "kg"
    out = run(*args, "--bootstrap", "2")
    assert out.returncode == 2 and "bootstrap" in out.stderr and "Traceback" not in out.stderr
    out = run("identify", "--data", str(tmp_path / "d"), "--free", "k")
    assert out.returncode == 2 and "--network" in out.stderr


def test_hydraulic_device_as_a_network_equals_the_device_fit():
    """A series device with friction and the adaptive flywheel: projecting the internal
    displacement only (the branch starts with the drive, as identify assumes), the core
    rig's fit equals identify's (measured on the whole 2 s campaign: 2e-4 se, standard
    errors equal to 2e-6)."""
    dev = device_preset("hydraulic")
    data = _subset(simulate_rig(dev, max_duration=2.0, seed=3), n_ident=8, n_val=2)
    a = identify(data, dev)
    text, params = device_network(dev)
    names = ("stiffness", "damping", "friction")
    b = identify_network(
        data, text, params, free=[f"{text}.{n}" for n in names],
        reversal_window=a.reversal_window, initial_state="displacements",
    )  # fmt: skip
    for n in names:
        pa, pb = a.parameters[n], b.parameters[f"{text}.{n}"]
        assert abs(pb.value - pa.value) <= 0.01 * pa.std_error, (n, pa.value, pb.value)
        assert pb.std_error == pytest.approx(pa.std_error, rel=1e-3)


def test_floating_network_recovered():
    """A network with a floating inertance component (the middle inerter between
    massless nodes in every order): its parameters come back from noise-free records.
    Its start has states the records barely see; the projection leaves those alone
    instead of fitting them to round-off (which once sent the start to 1e8 m and the
    integration past its step limit)."""
    from inerterlab.systems.core import _initial

    net = "k | ((c1 | (k2 - b1)) - (c3 | (k4 - b2)) - (c5 | (k6 - b3)))"
    truth = dict(k=9e4, c1=3e3, k2=2e4, b1=50.0, c3=4e3, k4=4e4, b2=80.0, c5=5e3, k6=6e4,
                 b3=120.0)  # fmt: skip
    r = rig(net, truth)
    assert any(n.endswith("_rel") for n in r.state_names)
    x0 = _initial(r, {}, 0.0)
    data = _records(net, truth, [x0, x0, x0])
    res = identify_network(
        data, net, dict(truth, k=7e4, b2=60.0), free=("k", "b2"), loss="linear",
        reversal_window=0.0, rtol=1e-12,
    )  # fmt: skip
    for n in ("k", "b2"):
        assert res.parameters[n].value == pytest.approx(truth[n], rel=1e-5), n
