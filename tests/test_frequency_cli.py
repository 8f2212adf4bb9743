"""``inerterlab frequency-response``: JSON, CSV, plot and bad input."""

import json

import pytest

from inerterlab.cli import main


def test_json_output(capsys):
    rc = main(
        ["frequency-response", "--method", "mhb", "--amplitude", "0.03", "--fmin", "0.5",
         "--fmax", "1.5", "--df", "0.25", "--harmonics", "7", "--json"]
    )  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    assert rc == 0
    assert out["freq_hz"] == [0.5, 0.75, 1.0, 1.25, 1.5]
    assert len(out["amplitude_m"]) == len(out["stable"]) == len(out["residual"]) == 5
    assert all(out["converged"]) and out["failed_points"] == 0
    assert max(out["residual"]) < 1e-10


def test_csv_and_plot(tmp_path, capsys):
    csv, png = tmp_path / "fr.csv", tmp_path / "fr.png"
    rc = main(
        ["frequency-response", "--amplitude", "0.05", "--df", "0.2", "--harmonics", "5",
         "--csv", str(csv), "--plot", str(png)]
    )  # fmt: skip
    assert rc == 0
    assert csv.read_text().splitlines()[0].startswith("freq_hz,amplitude_m,stable")
    assert png.stat().st_size > 1000
    assert "resonance" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["--fmin", "2", "--fmax", "1"], "--fmin"),
        (["--df", "0"], "--df"),
        (["--harmonics", "0"], "--harmonics"),
        (["--method", "fourier"], "method"),
        (["--law", "newton"], "law"),
    ],
)
def test_bad_input_exit_2(args, option, capsys):
    rc = main(["frequency-response", *args])
    err = capsys.readouterr().err
    assert rc == 2
    assert option in err and len(err.strip().splitlines()) == 1
