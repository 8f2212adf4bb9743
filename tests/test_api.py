"""The Python API: version, top-level names, short summaries, xarray export."""

import importlib.metadata
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import inerterlab

ROOT = Path(__file__).resolve().parents[1]


def test_version_option():
    r = subprocess.run(
        [sys.executable, "-m", "inerterlab", "--version"], capture_output=True, text=True
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"inerterlab {inerterlab.__version__}"
    try:
        assert inerterlab.__version__ == importlib.metadata.version("inerterlab")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - source tree only
        pass


def test_top_level_names_resolve():
    for name in inerterlab.__all__:
        assert getattr(inerterlab, name) is not None, name
    assert "simulate" in dir(inerterlab) and "quarter_car" in dir(inerterlab)
    # inerterlab.simulate is the module and calling it simulates
    import inerterlab.simulate as sim

    assert inerterlab.simulate is sim and callable(sim)
    car = inerterlab.quarter_car("traditional")
    a = inerterlab.simulate(car, inerterlab.bump(0.05), 1.0, output="metrics").metrics()
    b = sim.simulate_metrics(car, inerterlab.bump(0.05), 1.0)
    assert a == b
    with pytest.raises(AttributeError):
        inerterlab.no_such_name  # noqa: B018


def test_quick_start_in_the_package_docstring():
    doc = inerterlab.__doc__
    assert "Quick start" in doc and ">>> inerterlab.simulate(" in doc.replace("res = ", "")


def test_simulation_result_summary_and_xarray():
    car = inerterlab.quarter_car("afw")
    res = inerterlab.simulate(car, inerterlab.sine(0.01, 2.0), 1.0)
    text = repr(res)
    assert len(text) < 300 and "\n" not in text
    assert re.search(r"rms_body_acc=[0-9.]+ m/s\^2", text)
    # across the bump's steps the plain RMS of an inerter car is not finite, and says so
    step = repr(inerterlab.simulate(car, inerterlab.bump(0.05), 1.0))
    assert "rms_body_acc=not finite" in step and "None" not in step
    assert "rms_deflection=" in text and "samples=1001" in text
    html = res._repr_html_()
    assert html.startswith("<table") and "min_tyre_force" in html and "N<" in html


def test_frequency_response_summary_and_xarray():
    fr = inerterlab.frequency_response(
        inerterlab.chapter7_system(0.03), "shb", freq_hz=[0.8, 1.2, 2.0]
    )
    text = repr(fr)
    assert text.startswith("<FrequencyResponse shb: 3 points (3 converged), 0.8 .. 2 Hz, H=1")
    assert "amplitude" in text and " m" in text and len(text) < 300
    assert fr._repr_html_().startswith("<table")
    ds = fr.to_xarray()
    assert ds["amplitude_m"].attrs["units"] == "m" and ds["freq_hz"].attrs["units"] == "Hz"
    np.testing.assert_allclose(ds["amplitude_m"].values, fr.amplitude_m.data)


def test_device_force_summary_and_xarray():
    dev = inerterlab.device_preset("hydraulic")
    res = inerterlab.device_force(
        dev, inerterlab.Motion.sine(frequency=1.0, amplitude=0.005), duration=1.0, sample_rate=50
    )
    text = repr(res)
    assert text.startswith("<DeviceForceResult 51 samples over 0 .. 1 s: force ")
    assert "kg" in text and len(text) < 300
    ds = res.to_xarray()
    assert ds["force"].attrs["units"] == "N" and ds["t"].attrs["units"] == "s"
    np.testing.assert_array_equal(ds["force"].values, res.force)


def test_intervals_printed_with_digits_that_differ():
    from inerterlab.identify.fit import ParameterEstimate

    p = ParameterEstimate(
        name="stiffness", value=1970000.6, ci95=(1969998.1, 1970003.2), unit="N/m"
    )
    text = str(p)
    value, lo, hi = re.match(r"(\S+) N/m \(95 %: (\S+) \.\. (\S+)\)", text).groups()
    assert len({value, lo, hi}) == 3, text
    assert float(lo) < float(value) < float(hi)


def _fake_model(slope):
    def model(x):
        v = 1.0 + slope * x
        return {i: {"rms_body_acc": v, "rms_tyre_grip": v} for i in ("drop", "bump", "sine")}

    return model


def test_ratio_optimum_at_a_bound_is_said():
    from inerterlab.studies.ratio import optimize_ratio

    base = {i: {"rms_body_acc": 1.0, "rms_tyre_grip": 1.0} for i in ("drop", "bump", "sine")}
    res = optimize_ratio(_fake_model(+1.0), base, cost="continuous")
    assert res.at_bound == "lower" and res.to_dict()["at_bound"] == "lower"
    assert "lower bound" in res.bound_note() and "lower bound" in repr(res)
    inside = optimize_ratio(_fake_model(-1.0), base, cost="continuous")
    assert inside.at_bound is None and inside.bound_note() == ""
    ds = res.to_xarray()
    assert ds.attrs["at_bound"] == "lower" and set(ds["input"].values) == {"drop", "bump", "sine"}


def test_cli_tables_and_example_use_the_api():
    src = (ROOT / "examples" / "identify_from_rig.py").read_text()
    assert "inerterlab.cli" not in src and "main(" not in src


def test_h2_and_continuation_summaries():
    import math

    from inerterlab.metrics import h2_norms

    h = h2_norms(inerterlab.quarter_car("cfw"))
    assert "body_acc=inf" in repr(h) and h._repr_html_().startswith("<table")
    ds = h.to_xarray()
    assert math.isnan(float(ds["body_acc"])) and "infinite" in ds["body_acc"].attrs
    assert ds["suspension_deflection"].attrs["units"] == "m"

    from inerterlab.frequency import DuffingOscillator, continue_branch, make_engine

    eng = make_engine(DuffingOscillator.nlvib_example(), 3)
    x0 = np.zeros(eng.basis.size * 1)
    path = continue_branch(eng, x0, 0.8, 0.9, max_points=20)
    text = repr(path)
    assert text.startswith("<ContinuationPath") and len(text) < 300
    if len(path.omega):
        assert path.to_xarray()["omega"].attrs["units"] == "rad/s"
