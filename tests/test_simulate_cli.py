"""Command line: inerterlab simulate / h2."""

import json

import pytest

from inerterlab.cli import main


def _json(capsys, args):
    assert main(args) == 0
    return json.loads(capsys.readouterr().out)


def test_simulate_json_and_files(capsys, tmp_path):
    out = _json(
        capsys,
        ["simulate", "--suspension", "cfw", "--input", "bump", "--horizon", "0.5", "--json",
         "--save", str(tmp_path / "s.csv"), "--plot", str(tmp_path / "s.png")],
    )  # fmt: skip
    for k in (
        "rms_body_acc",
        "rms_tyre_grip",
        "rms_deflection",
        "rms_body_acc_wk",
        "vdv",
        "peak_body_acc",
        "tyre_lift_off",
    ):
        assert k in out
    assert (tmp_path / "s.csv").read_text().startswith("# model.suspension: cfw")
    assert (tmp_path / "s.png").stat().st_size > 1000
    assert (
        main(
            [
                "simulate",
                "--input",
                "drop",
                "--horizon",
                "0.2",
                "--save",
                str(tmp_path / "s.nc"),
                "--json",
            ]
        )
        == 0
    )
    import xarray as xr

    ds = xr.open_dataset(tmp_path / "s.nc", engine="scipy")
    assert ds["body_acc"].attrs["units"] == "m/s^2"
    ds.close()


def test_h2_closed_form_through_cli(capsys):
    out = _json(
        capsys,
        ["h2", "--suspension", "traditional", "--sprung-mass", "250", "--unsprung-mass", "35",
         "--tyre-stiffness", "150000", "--tyre-damping", "0", "--json"],
    )  # fmt: skip
    assert out["suspension_deflection"] ** 2 == pytest.approx(285 / 10000)
    out = _json(capsys, ["h2", "--suspension", "cfw", "--json"])
    assert out["body_acc"] is None and "body_acc" in out["infinite"]


@pytest.mark.parametrize(
    "args",
    [
        ["simulate", "--suspension", "magic"],
        ["simulate", "--horizon", "-1"],
        ["simulate", "--input", "/nonexistent/road.csv"],
        ["h2", "--suspension", "afw"],
    ],
)
def test_bad_input_exit_2(args, capsys):
    assert main(args) == 2
    assert "error" in capsys.readouterr().err


def test_nan_in_road_file(tmp_path, capsys):
    p = tmp_path / "r.csv"
    p.write_text("time,displacement\n0,0\n0.1,NaN\n")
    assert main(["simulate", "--input", str(p)]) == 2
    assert "line 3" in capsys.readouterr().err
