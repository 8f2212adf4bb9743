"""Command line: simulate --network and network h2."""

import json
import math

from inerterlab.cli import main
from inerterlab.suspension.network_linear import network_h2


def _json(capsys, args):
    assert main(args) == 0
    return json.loads(capsys.readouterr().out)


def test_simulate_network(capsys, tmp_path):
    out = _json(
        capsys,
        ["simulate", "--network", "k | (c - b)", "--param", "k=90000", "--param", "c=5000",
         "--param", "b=200", "--input", "drop", "--horizon", "0.5", "--json",
         "--save", str(tmp_path / "n.csv")],
    )  # fmt: skip
    assert out["method"] == "exact" and out["rms_body_acc"] > 0
    assert (tmp_path / "n.csv").read_text().startswith("time,")
    out = _json(
        capsys,
        ["simulate", "--network", "k | c | afw", "-p", "k=90000,c=5000,afw.law=momentum",
         "--input", "sine", "--horizon", "0.3", "--json"],
    )  # fmt: skip
    assert out["method"] == "adaptive" and math.isfinite(out["rms_body_acc_wk"])


def test_simulate_network_bad_params_exit_2(capsys):
    assert main(["simulate", "--network", "k | c", "--param", "k=1e5", "--horizon", "0.1"]) == 2
    assert "c.damping" in capsys.readouterr().err
    args = ["simulate", "--network", "k | c", "-p", "k=1e5,c=1e3,q=3", "--horizon", "0.1"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "q" in err and "Traceback" not in err
    assert main(["simulate", "--param", "k=1", "--horizon", "0.1"]) == 2


def test_h2_of_a_network_is_network_h2_only(capsys):
    """One command gives a network's H2 norms (`network h2`); the thesis car's `h2`
    takes no network (two ways of one thing removed)."""
    out = _json(
        capsys,
        ["network", "h2", "--network", "k | (c - b)", "-p", "k=90000,c=5000,b=200",
         "--tyre-damping", "1300", "--json"],
    )  # fmt: skip
    ref = network_h2("k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200.0})
    for k in ("body_acc", "tyre_deflection", "suspension_deflection"):
        assert math.isclose(out[k], ref[k], rel_tol=1e-12)
    assert main(["h2", "--network", "k | c", "-p", "k=9e4,c=5e3", "--json"]) == 2
    assert "Traceback" not in capsys.readouterr().err
