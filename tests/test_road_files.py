"""Road profile files: units from the header, distance with a speed, short roads warned."""

import json
import subprocess
import sys
import warnings

import numpy as np
import pytest

from inerterlab import DataFileError, ParameterError, quarter_car
from inerterlab.excitation import RoadTooShortWarning, read_road_csv, road_series
from inerterlab.identify.data import read_rig_test
from inerterlab.simulate import SimulationOptions, simulate_metrics


def _w(tmp_path, text, name="road.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize(
    "header, scale",
    [
        ("time [s],displacement [m]", 1.0),
        ("time [s],displacement [mm]", 1e-3),
        ("time (s),height (cm)", 1e-2),
        ("time_s,elevation_mm", 1e-3),
        ("time [ms],displacement [m]", 1.0),
    ],
)
def test_units_read_from_the_header(tmp_path, header, scale):
    p = _w(tmp_path, f"# measured\n{header}\n0,0\n500,12\n1000,0\n")
    r = read_road_csv(p)
    np.testing.assert_allclose(r.displacement, np.array([0, 12, 0]) * scale)
    tscale = 1e-3 if "[ms]" in header else 1.0
    np.testing.assert_allclose(r.time, np.array([0, 500, 1000]) * tscale)


def test_distance_profile_needs_a_speed(tmp_path):
    p = _w(tmp_path, "distance [m],displacement [mm]\n10,0\n20,5\n30,0\n")
    with pytest.raises(DataFileError, match=r"road.csv, line 1: .*vehicle speed"):
        read_road_csv(p)
    r = read_road_csv(p, speed=20.0)
    np.testing.assert_allclose(r.time, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(r.displacement, [0.0, 0.005, 0.0])
    q = _w(tmp_path, "position [km],height [cm]\n0,0\n0.01,1\n", "q.csv")
    np.testing.assert_allclose(read_road_csv(q, speed=10.0).time, [0.0, 1.0])
    with pytest.raises(ParameterError, match="speed"):
        read_road_csv(_w(tmp_path, "time [s],displacement [m]\n0,0\n1,0\n", "t.csv"), speed=3.0)


@pytest.mark.parametrize(
    "text, words",
    [
        (
            "time [s],displacement [in]\n0,0\n1,0\n",
            "unknown unit [in] for displacement; expected one of m, cm, mm",
        ),
        (
            "time [h],displacement [m]\n0,0\n1,0\n",
            "unknown unit [h] for time; expected one of s, ms",
        ),
        ("time [s],speed [m/s]\n0,0\n1,0\n", "unknown column 'speed'"),
        ("time [s],distance [m],displacement [m]\n0,0,0\n1,1,0\n", "exactly one of"),
    ],
)
def test_unknown_units_and_columns_are_clear_errors(tmp_path, text, words):
    with pytest.raises(DataFileError) as e:
        read_road_csv(_w(tmp_path, text))
    assert str(e.value).startswith(f"{tmp_path / 'road.csv'}, line 1: ")
    assert words in str(e.value)


def test_rig_and_road_share_one_reader(tmp_path):
    # the rig reader accepts the same spellings and units (cm here)
    p = _w(tmp_path, "time (ms),displacement_cm,force [kN]\n0,0,1\n10,1,2\n20,2,3\n", "rig.csv")
    t = read_rig_test(p)
    np.testing.assert_allclose(t.displacement, [0, 0.01, 0.02])
    np.testing.assert_allclose(t.t, [0, 0.01, 0.02])
    import inerterlab.excitation as ex
    import inerterlab.identify.data as rig

    assert ex.read_columns is rig.read_columns


def test_short_road_warns_long_road_does_not():
    car = quarter_car("traditional")
    opts = SimulationOptions()
    short = road_series([0.0, 1.0, 5.0], [0.0, 0.01, 0.0], label="short.csv")
    with pytest.warns(RoadTooShortWarning, match=r"short.csv ends at 5 s, before the horizon 20 s"):
        simulate_metrics(car, short, 20.0, options=opts)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate_metrics(car, short, 5.0, options=opts)


def test_cli_reads_millimetres_and_warns_on_a_short_road(tmp_path):
    mm = _w(tmp_path, "time [s],displacement [mm]\n0,0\n0.01,50\n0.02,0\n5,0\n", "mm.csv")
    m = _w(tmp_path, "time [s],displacement [m]\n0,0\n0.01,0.05\n0.02,0\n5,0\n", "m.csv")
    out = {}
    for p in (mm, m):
        r = subprocess.run(
            [
                sys.executable,
                "-m",
                "inerterlab",
                "simulate",
                "--suspension",
                "traditional",
                "--input",
                str(p),
                "--horizon",
                "20",
                "--json",
            ],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert r.returncode == 0, r.stderr
        assert "ends at 5 s, before the horizon 20 s" in r.stderr
        out[p.name] = json.loads(r.stdout)
    assert out["mm.csv"]["rms_deflection"] == pytest.approx(
        out["m.csv"]["rms_deflection"], rel=1e-9
    )
    bad = _w(tmp_path, "time [s],displacement [furlong]\n0,0\n1,0\n", "bad.csv")
    r = subprocess.run(
        [sys.executable, "-m", "inerterlab", "simulate", "--input", str(bad)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 2 and "unknown unit [furlong]" in r.stderr
