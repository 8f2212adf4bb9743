"""The flywheel command and the shared error handling of the command line."""

import json
import subprocess
import sys

import pytest

from inerterlab import flywheel
from inerterlab.cli import main


def run(args, capsys):
    rc = main(args)
    out, err = capsys.readouterr()
    return rc, out, err


def test_flywheel_json(capsys):
    rc, out, err = run(["flywheel", "--preset", "nylon", "--json"], capsys)
    assert rc == 0, err
    d = json.loads(out)
    assert d["inertia_min"] == pytest.approx(flywheel("nylon").inertia_min)
    assert d["changing_ratio"] == pytest.approx(0.285, abs=5e-4)
    assert d["saturation_speed"] == pytest.approx(45.45, abs=0.01)
    assert set(d["equivalent_mass"]) == {"hydraulic", "rectifier", "screw"}
    lo, hi = d["equivalent_mass"]["hydraulic"]
    assert lo == pytest.approx(206.2, abs=0.05) and hi == pytest.approx(288.4, abs=0.05)


def test_flywheel_variant_and_law(capsys):
    rc, out, _ = run(["flywheel", "--preset", "metal", "--law", "geometry", "--json"], capsys)
    assert rc == 0
    assert json.loads(out)["rest_inertia"] == pytest.approx(8.028e-4, rel=1e-3)
    rc, out, _ = run(["flywheel", "--changing-ratio", "0.4", "--json"], capsys)
    assert json.loads(out)["changing_ratio"] == pytest.approx(0.4)


def test_flywheel_plot(tmp_path, capsys):
    p = tmp_path / "fw.png"
    rc, _, err = run(["flywheel", "--preset", "metal", "--plot", str(p)], capsys)
    assert rc == 0, err
    assert p.stat().st_size > 1000


def test_table_output(capsys):
    rc, out, _ = run(["flywheel", "--preset", "metal"], capsys)
    assert rc == 0 and "changing_ratio" in out and "11.668" in out


@pytest.mark.parametrize(
    "args, needle",
    [
        (["flywheel", "--preset", "steel"], "preset"),
        (["flywheel", "--changing-ratio", "1.5"], "changing_ratio"),
        (["flywheel", "--changing-ratio", "abc"], "--changing-ratio"),
        (["flywheel", "--law", "magic"], "law"),
        (["flywheel", "--prest", "x"], "--prest"),
    ],
)
def test_bad_input_is_one_line_exit_2(args, needle, capsys):
    rc, out, err = run(args, capsys)
    assert rc == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0]
    assert "Traceback" not in err


def test_unknown_option_suggests(capsys):
    rc, _, err = run(["flywheel", "--prest", "metal"], capsys)
    assert rc == 2 and "--preset" in err


def test_console_script_exit_status():
    r = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from inerterlab.cli import _run; sys.argv=['inerterlab','flywheel','--preset','x']; _run()",
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2
    assert r.stderr.strip().startswith("inerterlab: error:")
