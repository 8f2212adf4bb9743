"""Model core results and the quarter car's options: one-line representations,
figures, ``simulate --network --plot`` and a tyre without damping."""

import json

import numpy as np
import pytest

import _quarter_car_oracle as oracle
from inerterlab.cli import main
from inerterlab.errors import ParameterError
from inerterlab.excitation import bump
from inerterlab.systems import quarter_car, rig

ROAD = bump(0.05, edge="ramp", edge_width=0.005)


def test_system_and_result_print_one_short_line():
    car = quarter_car("k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200.0})
    res = car.simulate(ROAD, 0.5)
    for text in (repr(car), repr(res)):
        assert "\n" not in text and len(text) < 240
    assert "6 states" in repr(car) and "linear" in repr(car)
    assert "501 samples" in repr(res) and "rms_body_acc=" in repr(res)
    r = rig("k | c", {"k": 1e4, "c": 100.0}).simulate(ROAD, 0.2)
    assert "rms" not in repr(r) and "\n" not in repr(r)


def test_result_plot_panels():
    pytest.importorskip("matplotlib")
    res = quarter_car("traditional").simulate(ROAD, 0.3)
    assert len(res.plot().axes) == 3
    assert len(res.plot(["body.x", "wheel.v"]).axes) == 2
    with pytest.raises(ParameterError, match="outputs"):
        res.plot(["nothing"])


def test_simulate_network_plot(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    png = tmp_path / "n.png"
    args = ["simulate", "--network", "k | c", "-p", "k=90000,c=5000", "--input", "drop",
            "--horizon", "0.3", "--json", "--plot", str(png)]  # fmt: skip
    assert main(args) == 0
    assert json.loads(capsys.readouterr().out)["plot"] == str(png)
    assert png.read_bytes().startswith(b"\x89PNG")


def test_tyre_without_damping_equals_the_scipy_oracle():
    """Tyre damping 0 is well posed (the wheel has a mass): the core's linear car (exact
    steps) and its adaptive steps against the scipy oracle's traditional car at rtol
    1e-11."""
    core = quarter_car("traditional", tyre_damping=0.0)
    assert "tyre_c" not in core.element_names
    ref = oracle.simulate(quarter_car("traditional", tyre_damping=0.0), ROAD, 1.0, rtol=1e-11)
    idx = [core.state_names.index(n) for n in ("wheel.x", "wheel.v", "body.x", "body.v")]
    for method in ("exact", "adaptive"):
        res = core.simulate(ROAD, 1.0, method=method, rtol=1e-10)
        a, b = res.states[:, idx], ref.states[:, :4]
        assert (np.abs(a - b).max(axis=0) / np.abs(b).max(axis=0)).max() < 1e-7
        assert np.allclose(res.outputs["tyre_force"], res.outputs["tyre_k.force"])
