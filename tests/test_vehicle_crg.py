"""OpenCRG tracks through pycrg: round trip, and the CLI reading them."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("pycrg")

from inerterlab.cli import main  # noqa: E402
from inerterlab.errors import DataFileError  # noqa: E402
from inerterlab.vehicles.crg import (  # noqa: E402
    read_crg_profile,
    read_crg_tracks,
    write_crg_tracks,
)
from inerterlab.vehicles.roads import generate_tracks, road_spectrum  # noqa: E402


# double formats round-trip to ~3e-10 m through the library's evaluation, single to ~1e-8 m
@pytest.mark.parametrize("fmt,tol", [("KDBI", 1e-9), ("LDFI", 1e-9), ("KRBI", 1e-8)])
def test_round_trip(tmp_path, fmt, tol):
    x, zl, zr = generate_tracks(road_spectrum("C"), length=100.0, step=0.05, seed=4)
    path = write_crg_tracks(tmp_path / "r.crg", x, zl, zr, track=1.5, fmt=fmt)
    u, a, b = read_crg_tracks(path, track=1.5)
    np.testing.assert_allclose(u, x, atol=1e-9)
    np.testing.assert_allclose(a, zl, atol=tol)
    np.testing.assert_allclose(b, zr, atol=tol)
    # the reference line lies half way between the tracks, linear across
    _, mid = read_crg_profile(path)
    np.testing.assert_allclose(mid, 0.5 * (zl + zr), atol=tol)
    _, left = read_crg_profile(path, lateral=0.75)
    np.testing.assert_allclose(left, zl, atol=tol)


def test_not_a_crg_file(tmp_path):
    bad = tmp_path / "bad.crg"
    bad.write_text("hello\n")
    with pytest.raises(DataFileError, match="bad.crg"):
        read_crg_tracks(bad)


def test_cli_simulate_on_crg_equals_csv(tmp_path, capsys):
    crg, csv = tmp_path / "r.crg", tmp_path / "r.csv"
    for out in (crg, csv):
        args = ["vehicle", "generate", "--output", str(out), "--length", "300"]
        assert main(args + ["--track", "1.51"]) == 0
    capsys.readouterr()
    res = []
    for road in (crg, csv):
        assert main(["vehicle", "simulate", "--road-file", str(road), "--json"]) == 0
        res.append(json.loads(capsys.readouterr().out))
    for k, v in res[0]["rms"].items():
        assert v == pytest.approx(res[1]["rms"][k], rel=1e-6), k
