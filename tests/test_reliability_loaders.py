"""Fuzz the file loaders: any bytes give either a valid object or a DataFileError.

Bounded in time (hypothesis deadline and example counts), deterministic (derandomize).
A loader may never raise anything but an :class:`inerterlab.InerterlabError`, never
return NaN, and a corruption at a known line must be reported at that line.
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inerterlab import DataFileError, InerterlabError
from inerterlab.excitation import read_road_csv
from inerterlab.studies.spec import load_sweep_config

FUZZ = settings(
    max_examples=150,
    deadline=2000,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)

CSV_TOKENS = st.sampled_from(list("0123456789.,-+eE \n#abc\t;") + ["nan", "inf", "1e308", "\n0.5,"])
CSV_TEXT = st.lists(CSV_TOKENS, max_size=120).map("".join)


@FUZZ
@given(content=st.one_of(st.binary(max_size=300), CSV_TEXT))
def test_road_csv_fuzz(tmp_path, content):
    p = tmp_path / "road.csv"
    if isinstance(content, bytes):
        p.write_bytes(content)
    else:
        p.write_text(content)
    try:
        road = read_road_csv(p)
    except InerterlabError as e:
        assert "road.csv" in str(e)
        return
    assert np.all(np.isfinite(road.time)) and np.all(np.isfinite(road.displacement))
    assert np.all(np.diff(road.time) > 0)


@FUZZ
@given(
    n=st.integers(3, 30),
    bad_row=st.integers(0, 29),
    corruption=st.sampled_from(["nan", "", "abc", "inf", "1,2,3", "backwards"]),
)
def test_road_csv_corruption_reported_at_its_line(tmp_path, n, bad_row, corruption):
    bad_row = bad_row % n
    rows = [f"{0.01 * i:.3f},{0.001 * math.sin(i):.6f}" for i in range(n)]
    if corruption == "backwards":
        if bad_row == 0:
            bad_row = 1
        rows[bad_row] = f"{0.01 * (bad_row - 1) - 0.001:.4f},0.0"
    elif corruption == "1,2,3":
        rows[bad_row] = corruption
    else:
        rows[bad_row] = f"{0.01 * bad_row:.3f},{corruption}"
    p = tmp_path / "road.csv"
    p.write_text("time_s,displacement_m\n" + "\n".join(rows) + "\n")
    with pytest.raises(DataFileError) as e:
        read_road_csv(p)
    assert e.value.line == bad_row + 2  # one header line, lines count from 1


TOML_PIECES = st.sampled_from(
    [
        'point = "synthetic"\n',
        'point = "quarter-car"\n',
        'point = "nope"\n',
        "[parameters]\n",
        "[settings]\n",
        "[weights]\n",
        "changing_ratio = [0.1, 0.2]\n",
        "changing_ratio = [1.5]\n",
        "changing_ratio = []\n",
        "changing_ratio = {start = 0.1, stop = 0.05, step = 0.01}\n",
        "sprung_mass = -3\n",
        "comfort = 0.35\ngrip = 0.65\n",
        "comfort = 2\n",
        'input = ["drop", "bump"]\n',
        "horizon = 0.5\n",
        "bogus = 1\n",
        "x = \n",
        "[[a]]\n",
        "chunk_size = 0\n",
        "\x00\xff",
    ]
)


@FUZZ
@given(pieces=st.lists(TOML_PIECES, max_size=8), raw=st.binary(max_size=40))
def test_sweep_toml_fuzz(tmp_path, pieces, raw):
    p = tmp_path / "sweep.toml"
    p.write_bytes("".join(pieces).encode("utf-8", "surrogateescape") + raw)
    try:
        spec = load_sweep_config(p)
    except InerterlabError as e:
        assert "sweep.toml" in str(e)
        return
    assert spec is not None


def test_sweep_toml_binary_file_is_a_clear_error(tmp_path):
    p = tmp_path / "sweep.toml"
    p.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(DataFileError, match="sweep.toml"):
        load_sweep_config(p)
