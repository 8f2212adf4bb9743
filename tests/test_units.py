"""Units on every human-readable output: simulate and flywheel tables, saved CSV
headers, sweep dataset variables."""

import re

import pandas as pd

from inerterlab.cli import main
from inerterlab.metrics import METRIC_KEYS, METRIC_UNITS


def _table(capsys, args):
    assert main(args) == 0
    return capsys.readouterr().out


def test_simulate_table_has_units(capsys):
    out = _table(capsys, ["simulate", "--suspension", "traditional", "--input", "bump",
                          "--horizon", "0.5"])  # fmt: skip
    for k in METRIC_KEYS:
        unit = METRIC_UNITS[k]
        if unit:
            shown = "-" if unit == "1" else unit
            assert f"{k} [{shown}]" in out, (k, out)
    assert "rms_body_acc [m/s^2]" in out and "min_tyre_force [N]" in out


def test_flywheel_table_units_are_not_eaten_as_markup(capsys):
    out = _table(capsys, ["flywheel", "--preset", "nylon"])
    assert "inertia_min [kg m^2]" in out
    assert "saturation_speed [rad/s]" in out
    assert "equivalent mass, hydraulic [kg]" in out  # "[kg]" was taken for a style tag
    rows = [ln for ln in out.splitlines() if "│" in ln]
    assert rows and all(re.search(r"\[[^\]]+\]", ln) for ln in rows), rows


def test_saved_csv_header_has_units(tmp_path, capsys):
    path = tmp_path / "run.csv"
    _table(capsys, ["simulate", "--suspension", "traditional", "--input", "bump",
                    "--horizon", "0.2", "--save", str(path)])  # fmt: skip
    df = pd.read_csv(path, comment="#")
    assert df.columns[0] == "time [s]"
    for col in ("body_acc [m/s^2]", "deflection [m]", "tyre_force [N]", "tyre_grip [-]",
                "road [m]", "body.v [m/s]"):  # fmt: skip
        assert col in df.columns, df.columns
    assert all(re.fullmatch(r"[\w.]+ \[[^\]]+\]", c) for c in df.columns), list(df.columns)


def test_sweep_dataset_has_units():
    from inerterlab.studies import sweep, sweep_spec

    spec = sweep_spec(
        "synthetic",
        parameters={"changing_ratio": [0.1, 0.2], "sprung_mass": [340.0, 370.0]},
        settings={"input": "bump"},
    )
    ds = sweep(spec, backend="serial")
    assert ds["rms_body_acc"].attrs["units"] == "m/s^2"
    assert ds["rms_deflection"].attrs["units"] == "m"
    assert ds["rms_tyre_grip"].attrs["units"] == "1"
    assert ds["sprung_mass"].attrs["units"] == "kg"
