"""``inerterlab vehicle ...`` commands."""

from __future__ import annotations

import json

import pytest

from inerterlab.cli import main


def _json(capsys, args):
    rc = main(args)
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    return json.loads(cap.out)


def test_spectral_json_full_and_half(capsys, tmp_path):
    full = _json(capsys, ["vehicle", "spectral", "--road-class", "C", "--speed", "20", "--json"])
    assert full["model"] == "full"
    assert set(full["rms"]) >= {"bounce_acc", "roll_acc", "seat_acc_wk", "rear_right_tyre_load"}
    assert full["units"]["pitch_acc"] == "rad/s^2"
    assert 0 < full["lift_off_probability"]["rear_left"] < 1
    half = _json(capsys, ["vehicle", "spectral", "--model", "half", "--json"])
    assert half["model"] == "half"
    assert "roll_acc" not in half["rms"]
    same = _json(
        capsys,
        ["vehicle", "spectral", "--model", "half", "--coherence", "identical", "--json"],
    )
    assert same["rms"]["bounce_acc"] == pytest.approx(half["rms"]["bounce_acc"], rel=1e-12)
    # a road four times rougher doubles every RMS value (linear model)
    rough = _json(capsys, ["vehicle", "spectral", "--road-class", "D", "--json"])
    assert rough["rms"]["bounce_acc"] == pytest.approx(2 * full["rms"]["bounce_acc"], rel=1e-9)


def test_example_round_trip(capsys, tmp_path):
    assert main(["vehicle", "example"]) == 0
    text = capsys.readouterr().out
    path = tmp_path / "car.toml"
    path.write_text(text.replace('sprung_mass = "1200 kg"', 'sprung_mass = "1300 kg"'))
    out = _json(capsys, ["vehicle", "modes", "--vehicle", str(path), "--json"])
    assert len(out["rigid_tyres_hz"]) == 4  # bounce, pitch, roll, seat
    assert len(out["whole_car_hz"]) == 8


def test_bad_vehicle_file_exits_2(capsys, tmp_path):
    path = tmp_path / "car.toml"
    path.write_text('model = "half"\nsprung_mass = "1200 N"\n')
    assert main(["vehicle", "spectral", "--vehicle", str(path)]) == 2
    err = capsys.readouterr().err
    assert "car.toml, line 2: sprung_mass" in err and "mass" in err


def test_generate_then_classify(capsys, tmp_path):
    path = tmp_path / "road.csv"
    args = ["vehicle", "generate", "--output", str(path), "--road-class", "D"]
    assert main(args + ["--length", "1500", "--seed", "2"]) == 0
    capsys.readouterr()
    out = _json(capsys, ["vehicle", "road", "--profile", str(path), "--track", "left", "--json"])
    assert out["road_class"] == "D"
    assert out["iri_m_per_km"] > 0


def test_simulate_agrees_roughly_with_spectral(capsys):
    out = _json(
        capsys,
        ["vehicle", "simulate", "--model", "half", "--length", "3000", "--dt", "0.002", "--json"],
    )
    assert out["rms"]["bounce_acc"] == pytest.approx(out["spectral_rms"]["bounce_acc"], rel=0.15)
    assert out["crest_factor"] > 2


def test_simulate_nonlinear(capsys):
    args = ["vehicle", "simulate", "--road-class", "E", "--speed", "25", "--length", "400"]
    out = _json(capsys, args + ["--lift-off", "--rebound", "1.6", "--compression", "0.6", "--json"])
    assert out["model"] == "nonlinear"
    assert 0 < out["lift_off_fraction"]["rear_left"] < 1
    lin = _json(capsys, args + ["--json"])
    assert lin["model"] == "linear" and "lift_off_fraction" not in lin
