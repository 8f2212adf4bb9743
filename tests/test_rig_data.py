"""Rig data files: loader errors name file and line; a partly bad set is refused."""

import numpy as np
import pytest

from inerterlab import DataFileError
from inerterlab.devices import device_preset
from inerterlab.identify import TestSpec, load_rig_data, read_rig_test, simulate_rig, write_rig_data

GOOD = "time [s],displacement [m],velocity [m/s],force [N]\n0,0,0.1,10\n0.01,0.001,0.1,11\n0.02,0.002,0.1,12\n"


def _write(tmp_path, body, name="t.csv"):
    p = tmp_path / name
    p.write_text(body)
    return p


@pytest.mark.parametrize(
    "body, line, words",
    [
        ("time [s],velocity [m/s]\n0,1\n1,2\n2,3\n", 1, "missing column 'force'"),
        ("time [s],force [N]\n0,1\n1,2\n2,3\n", 1, "displacement and/or velocity"),
        (GOOD.replace("0.02,0.002", "0.005,0.002"), 4, "not strictly increasing"),
        (GOOD.replace("0.01,0.001,0.1,11", "0.01,0.001,nan,11"), 3, "not finite"),
        (GOOD.replace("0.01,0.001,0.1,11", "0.01,0.001,abc,11"), 3, "not a number"),
        (GOOD.replace("force [N]", "force [lbf]"), 1, "unknown unit [lbf] for force; expected one of N, kN"),
        (GOOD.replace("0.01,0.001,0.1,11", "0.01,0.001,11"), 3, "expected 4 values"),
        ("# only a comment\n", 1, "empty file"),
        ("time [s],velocity [m/s],force [N]\n", 1, "empty file"),
        (GOOD.replace("force [N]", "force"), 1, "has no unit"),
    ],
)
def test_malformed_file_names_file_and_line(tmp_path, body, line, words):
    p = _write(tmp_path, body)
    with pytest.raises(DataFileError) as e:
        read_rig_test(p)
    msg = str(e.value)
    assert msg.startswith(f"{p}, line {line}:"), msg
    assert words in msg


def test_units_converted_and_flags(tmp_path):
    p = _write(tmp_path, "time [ms],displacement [mm],force [kN]\n0,0,1\n10,1,2\n20,2,3\n")
    t = read_rig_test(p)
    np.testing.assert_allclose(t.t, [0, 0.01, 0.02])
    np.testing.assert_allclose(t.displacement, [0, 0.001, 0.002])
    np.testing.assert_allclose(t.force, [1000, 2000, 3000])
    q = _write(tmp_path, "time,velocity,force\n0,0,1\n1,1,2\n2,2,3\n", "q.csv")
    assert (
        read_rig_test(q, units={"time": "s", "velocity": "mm/s", "force": "N"}).velocity[1] == 1e-3
    )
    with pytest.raises(DataFileError, match="units="):
        read_rig_test(p, units={"force": "N"})


def test_partly_bad_dataset_is_refused(tmp_path):
    dev = device_preset("screw")
    tests = [
        TestSpec(number=i, signal="sine", frequency=1.0, amplitude=0.005, duration=1.0, purpose=p)
        for i, p in enumerate(["identification", "identification", "validation"])
    ]
    write_rig_data(simulate_rig(dev, matrix=tests, sample_rate=100, seed=0), tmp_path)
    assert len(load_rig_data(tmp_path).tests) == 3
    bad = sorted(tmp_path.glob("test_001*.csv"))[0]
    lines = bad.read_text().splitlines()
    cells = lines[40].split(",")
    cells[-1] = "nan"
    lines[40] = ",".join(cells)
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataFileError) as e:
        load_rig_data(tmp_path)
    assert bad.name in str(e.value) and "line 41" in str(e.value)


def test_manifest_toml_and_errors(tmp_path):
    _write(tmp_path, GOOD, "a.csv")
    (tmp_path / "manifest.toml").write_text(
        '[[test]]\nfile = "a.csv"\nsignal = "sine"\nfrequency_hz = 1.0\namplitude_m = 0.01\npurpose = "identification"\n'
    )
    ds = load_rig_data(tmp_path)
    assert ds.tests[0].frequency == 1.0 and ds.tests[0].purpose == "identification"
    (tmp_path / "manifest.csv").write_text("file,signal,purpose\na.csv,sine,training\n")
    with pytest.raises(DataFileError, match=r"manifest.csv, line 2: purpose 'training'"):
        load_rig_data(tmp_path)
    (tmp_path / "empty").mkdir()
    with pytest.raises(DataFileError, match="no manifest"):
        load_rig_data(tmp_path / "empty")
