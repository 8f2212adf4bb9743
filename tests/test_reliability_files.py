"""Every reader of a user's file, against every class of bad file: one line, exit 2.

Generated cases: each class below is tried on every command (or reader) that takes a
file of that kind, not only on the example that found it. Every case runs in a forked
child capped in memory (address space) and time (CPU and wall clock): a reader that
grows without bound or blocks is killed and the case fails.

Classes (the counts are in docs/reliability.md):

* not a regular file or unbounded: ``/dev/zero``, a FIFO nobody writes to, a
  directory, a missing path, a dangling link;
* not text: a binary file (NUL bytes), a Latin-1 header, UTF-16;
* too long: a line of 1 MB (and one of 160 MB for ``--road-file``), a configuration
  file over its 16 MiB cap;
* TOML: nested too deeply, not TOML;
* column files: an unknown unit in any column, a column twice, a missing column,
  ``nan``/``inf``/``-inf``/text/an empty cell in any column, a row with one or with one
  more value, distance (time) decreasing or repeated, no data rows;
* units read from the header: the same road in mm and in m gives the same numbers.
"""

from __future__ import annotations

import json
import os
import threading
from pathlib import Path

import numpy as np
import pytest

from _capped import assert_user_error, run_capped
from inerterlab.errors import InerterlabError

# a hang guard, not a speed limit: under pytest-xdist a worker may compile the core's
# kernels inside one of these tests (the first of its worker to simulate), 150-250 s of
# CPU on a slow machine
pytestmark = pytest.mark.timeout(900)

FAST = {"INERTERLAB_READ_TIMEOUT": "1"}

# --- the commands and readers ----------------------------------------------------------

VEHICLE_COMMANDS = {
    "vehicle spectral": ["vehicle", "spectral", "--vehicle"],
    "vehicle modes": ["vehicle", "modes", "--vehicle"],
    "vehicle simulate": ["vehicle", "simulate", "--length", "100", "--vehicle"],
    "vehicle monte-carlo": [
        "vehicle", "monte-carlo", "--roads", "2", "--length", "50", "--backend", "serial",
        "--quiet", "--vehicle",
    ],  # fmt: skip
    "vehicle optimize": ["vehicle", "optimize", "--vehicle"],
}
TOML_COMMANDS = {**VEHICLE_COMMANDS, "sweep": ["sweep"]}
COLUMN_COMMANDS = {
    "vehicle simulate --road-file": ["vehicle", "simulate", "--road-file"],
    "vehicle road --profile": ["vehicle", "road", "--profile"],
    "simulate --input": ["simulate", "--input"],
}


def _api(name):
    """A reader of the Python API as a callable of the path."""
    if name == "read_rig_test":
        from inerterlab.identify.data import read_rig_test

        return read_rig_test
    if name == "load_car_file":
        from inerterlab.identify.carfile import load_car_file

        return load_car_file
    if name == "load_rig_data (manifest)":
        from inerterlab.identify.data import load_rig_data

        def load(path):
            d = Path(path).parent / "data"
            d.mkdir(exist_ok=True)
            target = d / "manifest.csv"
            if not target.exists() and not target.is_symlink():
                target.symlink_to(Path(path).resolve())
            return load_rig_data(d)

        return load
    raise KeyError(name)


API_TOML = ("load_car_file",)
API_COLUMNS = ("read_rig_test",)
API_ANY = ("load_rig_data (manifest)",)


def _run(reader: str, path, **kw):
    """Run one reader (a command or an API function) on ``path`` in a capped child."""
    commands = {**TOML_COMMANDS, **COLUMN_COMMANDS}
    if reader in commands:
        return run_capped([*commands[reader], str(path)], **kw)
    fn = _api(reader)

    def call():
        try:
            fn(path)
        except InerterlabError as exc:
            print(f"inerterlab: error: {exc}", file=__import__("sys").stderr)
            return 2
        return 0

    return run_capped(call, **kw)


ALL_READERS = [*TOML_COMMANDS, *COLUMN_COMMANDS, *API_TOML, *API_COLUMNS, *API_ANY]

# --- not a regular file, unbounded, not text -------------------------------------------


def _special(kind: str, tmp_path: Path, suffix: str = ".csv") -> Path:
    if kind == "/dev/zero":
        return Path("/dev/zero")
    if kind == "fifo without writer":
        p = tmp_path / f"pipe{suffix}"
        os.mkfifo(p)
        return p
    if kind == "directory":
        p = tmp_path / f"folder{suffix}"
        p.mkdir()
        return p
    if kind == "missing":
        return tmp_path / f"nothing{suffix}"
    if kind == "dangling link":
        p = tmp_path / f"link{suffix}"
        p.symlink_to(tmp_path / f"gone{suffix}")
        return p
    p = tmp_path / f"file{suffix}"
    if kind == "binary":
        p.write_bytes(np.random.default_rng(0).integers(0, 256, 4096, dtype=np.uint8).tobytes())
    elif kind == "NUL in text":
        p.write_bytes(b"distance [m],left [m]\n0,0\x00\n1,0\n")
    elif kind == "latin-1 header":
        p.write_bytes("distance [m],h\xf6he [m]\n0,0\n1,0\n".encode("latin-1"))
    elif kind == "utf-16":
        p.write_bytes("distance [m],left [m]\n0,0\n1,0\n".encode("utf-16"))
    elif kind == "1 MB line":
        p.write_text("distance [m],left [m]\n" + "1," * 500_000 + "1\n")
    else:
        raise KeyError(kind)
    return p


SPECIAL = [
    "/dev/zero",
    "fifo without writer",
    "directory",
    "missing",
    "dangling link",
    "binary",
    "NUL in text",
    "latin-1 header",
    "utf-16",
    "1 MB line",
]


@pytest.mark.slow
@pytest.mark.parametrize("kind", SPECIAL)
@pytest.mark.parametrize("reader", ALL_READERS)
def test_special_files_are_refused_in_bounded_time_and_memory(tmp_path, reader, kind):
    path = _special(kind, tmp_path)
    res = _run(reader, path, memory_mb=1200, seconds=60, env=FAST)
    line = assert_user_error(res)
    assert path.name in line or "data" in line  # names the file (or the data folder)
    if kind == "fifo without writer":
        assert res.seconds < 30


def test_a_fifo_with_a_writer_is_read(tmp_path):
    """Bounded is not refused: a FIFO that delivers a vehicle file is read."""
    from inerterlab.vehicles.config import example_vehicle_path

    p = tmp_path / "car.toml"
    os.mkfifo(p)
    text = example_vehicle_path().read_bytes()

    def write():
        with open(p, "wb") as fh:  # blocks until the reader opens it
            fh.write(text)

    t = threading.Thread(target=write, daemon=True)
    t.start()
    res = run_capped(["vehicle", "modes", "--vehicle", p, "--json"], seconds=60, env=FAST)
    t.join(5)
    assert res.rc == 0, res.err
    assert json.loads(res.out)["whole_car_hz"]


CRG_COMMANDS = {
    "vehicle simulate --road-file (.crg)": ["vehicle", "simulate", "--road-file"],
    "vehicle road --profile (.crg)": ["vehicle", "road", "--profile"],
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", [k for k in SPECIAL if k != "/dev/zero"])
@pytest.mark.parametrize("reader", CRG_COMMANDS)
def test_special_openCRG_files_are_refused(tmp_path, reader, kind):
    pytest.importorskip("pycrg")
    path = _special(kind, tmp_path, ".crg")
    res = run_capped([*CRG_COMMANDS[reader], path], memory_mb=1200, seconds=60, env=FAST)
    line = assert_user_error(res, path.name)
    if kind == "fifo without writer":
        assert res.seconds < 30 and "regular file" in line


@pytest.mark.slow
def test_a_160_mb_line_in_a_road_file(tmp_path):
    p = tmp_path / "road.csv"
    with open(p, "w") as fh:
        fh.write("distance [m],left [m],right [m]\n")
        fh.write("0," * (80 * 1024**2) + "0\n")
    res = run_capped(["vehicle", "simulate", "--road-file", p], memory_mb=1500, seconds=90)
    assert_user_error(res, "road.csv", "line 2")


# --- TOML ------------------------------------------------------------------------------


def _toml(kind: str, tmp_path: Path) -> Path:
    p = tmp_path / "config.toml"
    if kind == "nested arrays":
        p.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    elif kind == "nested inline tables":
        p.write_text("a = " + "{b = " * 50_000 + "1" + "}" * 50_000 + "\n")
    elif kind == "not TOML":
        p.write_text("sprung_mass = = 3\n")
    elif kind == "over the size cap":
        with open(p, "w") as fh:
            fh.write("# padding\n" * (17 * 1024**2 // 10 + 1))
    else:
        raise KeyError(kind)
    return p


TOML_CASES = ["nested arrays", "nested inline tables", "not TOML", "over the size cap"]


@pytest.mark.slow
@pytest.mark.parametrize("kind", TOML_CASES)
@pytest.mark.parametrize("reader", [*TOML_COMMANDS, *API_TOML])
def test_bad_toml_files(tmp_path, reader, kind):
    path = _toml(kind, tmp_path)
    res = _run(reader, path, memory_mb=1200, seconds=60)
    line = assert_user_error(res, "config.toml")
    if kind.startswith("nested"):
        assert "nested too deeply" in line
    if kind == "over the size cap":
        assert "at most" in line


def test_loads_vehicle_nested_too_deeply():
    from inerterlab import DataFileError
    from inerterlab.vehicles.config import loads_vehicle

    with pytest.raises(DataFileError, match="nested too deeply"):
        loads_vehicle("a = " + "[" * 100_000 + "]" * 100_000, "car.toml")


# --- column files ----------------------------------------------------------------------

#: the columns (header cells in SI) and a row builder of each column reader
LAYOUT = {
    "vehicle simulate --road-file": ["distance [m]", "left [m]", "right [m]"],
    "vehicle road --profile": ["distance [m]", "elevation [m]"],
    "simulate --input": ["time [s]", "displacement [m]"],
    "read_rig_test": ["time [s]", "force [N]", "displacement [m]"],
}
ROWS = 40


def _rows(n: int, ncol: int) -> list[list[str]]:
    out = []
    for i in range(n):
        key = 0.05 * i
        out.append([f"{key:.3f}"] + [f"{1e-3 * np.sin(i + j):.6f}" for j in range(ncol - 1)])
    return out


def _column_case(reader: str, case: tuple, tmp_path: Path) -> tuple[Path, int | None]:
    """The file of ``case`` and the line the error must name (None: any)."""
    head = list(LAYOUT[reader])
    rows = _rows(ROWS, len(head))
    kind, col = case[0], (case[1] if len(case) > 1 else None)
    line = None
    bad = 20  # index of the damaged data row (file line bad + 2)
    if kind == "unknown unit":
        name = head[col].split(" [")[0]
        head[col] = f"{name} [furlong]"
        line = 1
    elif kind == "column twice":
        head.append(head[col])
        for r in rows:
            r.append(r[col])
        line = 1
    elif kind == "missing column":
        del head[col]
        for r in rows:
            del r[col]
    elif kind == "bad cell":
        rows[bad][col] = case[2]
        line = bad + 2
    elif kind == "one value":
        rows[bad] = rows[bad][:1]
        line = bad + 2
    elif kind == "one more value":
        rows[bad].append("0")
        line = bad + 2
    elif kind == "decreasing key":
        rows[bad][0] = f"{0.05 * (bad - 1) - 0.01:.3f}"
        line = bad + 2
    elif kind == "repeated key":
        rows[bad][0] = rows[bad - 1][0]
        line = bad + 2
    elif kind == "no data":
        rows = []
    else:
        raise KeyError(kind)
    p = tmp_path / "data.csv"
    p.write_text(",".join(head) + "\n" + "".join(",".join(r) + "\n" for r in rows))
    return p, line


def _column_cases(reader: str) -> list[tuple]:
    n = len(LAYOUT[reader])
    out = [("unknown unit", c) for c in range(n)]
    out += [("column twice", c) for c in range(n)]
    # the key and the first value column are required by every reader
    out += [("missing column", c) for c in range(min(n, 2))]
    for c in range(n):
        out += [("bad cell", c, v) for v in ("nan", "inf", "-inf", "abc", "")]
    out += [("one value",), ("one more value",), ("decreasing key",), ("repeated key",)]
    out += [("no data",)]
    return out


COLUMN_CASES = [
    pytest.param(reader, case, id=f"{reader}-{'-'.join(map(str, case))}")
    for reader in LAYOUT
    for case in _column_cases(reader)
]


@pytest.mark.slow
@pytest.mark.parametrize("reader, case", COLUMN_CASES)
def test_bad_column_files(tmp_path, reader, case):
    path, line = _column_case(reader, case, tmp_path)
    res = _run(reader, path, memory_mb=1200, seconds=60)
    text = assert_user_error(res, "data.csv")
    if line is not None:
        assert f"line {line}" in text
    if case[0] == "unknown unit":
        assert "[furlong]" in text and "expected one of" in text


def _mm_road(tmp_path, unit_scale: dict, name: str, header: list[str]) -> Path:
    x = np.arange(0.0, 200.0, 0.05)
    rng = np.random.default_rng(3)
    cols = [x] + [np.cumsum(rng.normal(0, 1e-4, x.size)) for _ in header[1:]]
    p = tmp_path / name
    cells = [h.replace("[m]", f"[{unit_scale.get(i, 'm')}]") for i, h in enumerate(header)]
    factor = {"m": 1.0, "mm": 1e3, "cm": 1e2, "km": 1e-3}
    with open(p, "w") as fh:
        fh.write(",".join(cells) + "\n")
        for row in zip(*cols, strict=True):
            fh.write(
                ",".join(
                    repr(float(v) * factor[unit_scale.get(i, "m")]) for i, v in enumerate(row)
                )
                + "\n"
            )
    return p


@pytest.mark.parametrize(
    "command, header, units",
    [
        (["vehicle", "simulate", "--json", "--road-file"],
         ["distance [m]", "left [m]", "right [m]"], {0: "mm", 1: "mm", 2: "mm"}),
        (["vehicle", "simulate", "--json", "--road-file"],
         ["distance [m]", "left [m]", "right [m]"], {0: "km", 1: "cm", 2: "mm"}),
        (["vehicle", "road", "--json", "--profile"],
         ["distance [m]", "elevation [m]"], {1: "mm"}),
        (["vehicle", "road", "--json", "--profile"],
         ["distance [m]", "elevation [m]"], {0: "cm", 1: "cm"}),
    ],
)  # fmt: skip
def test_units_in_the_header_are_applied(tmp_path, command, header, units):
    """The same road written in other units gives the same numbers (to rounding)."""
    si = _mm_road(tmp_path, {}, "si.csv", header)
    other = _mm_road(tmp_path, units, "other.csv", header)
    a = run_capped([*command, si], seconds=120)
    b = run_capped([*command, other], seconds=120)
    assert a.rc == 0 and b.rc == 0, a.err + b.err
    ja, jb = json.loads(a.out), json.loads(b.out)
    flat = ja.get("rms", ja)
    for k, v in flat.items():
        if isinstance(v, float):
            assert jb.get("rms", jb)[k] == pytest.approx(v, rel=1e-6), k


def test_road_file_and_profile_agree_with_the_api(tmp_path):
    """``--profile`` in mm gives the IRI of the profile in metres (12.5, not 12525)."""
    from inerterlab.vehicles.roads import iri, read_profile_csv

    p = _mm_road(tmp_path, {1: "mm"}, "p.csv", ["distance [m]", "elevation [m]"])
    x, z = read_profile_csv(p)
    assert np.max(np.abs(z)) < 0.1  # metres, not millimetres
    res = run_capped(["vehicle", "road", "--json", "--profile", p], seconds=120)
    assert res.rc == 0, res.err
    assert json.loads(res.out)["iri_m_per_km"] == pytest.approx(iri(x, z), rel=1e-9)


def test_generate_refuses_an_unknown_extension(tmp_path):
    res = run_capped(["vehicle", "generate", "--output", tmp_path / "road.xyz"], seconds=60)
    assert_user_error(res, "output", ".csv", ".crg")
    assert not (tmp_path / "road.xyz").exists()
    ok = run_capped(["vehicle", "generate", "--output", tmp_path / "road.csv", "--length", "50"])
    assert ok.rc == 0, ok.err
    assert (tmp_path / "road.csv").read_text().startswith("distance [m],left [m],right [m]\n")


def test_manifest_listing_a_file_twice(tmp_path):
    from inerterlab import DataFileError
    from inerterlab.identify.data import load_rig_data

    d = tmp_path / "rig"
    d.mkdir()
    (d / "a.csv").write_text("time [s],force [N],displacement [m]\n0,0,0\n0.1,1,0.001\n0.2,0,0\n")
    for listed in (["a.csv", "a.csv"], ["a.csv", "./a.csv"]):
        rows = "".join(f"{f},identification\n" for f in listed)
        (d / "manifest.csv").write_text("file,purpose\n" + rows)
        with pytest.raises(DataFileError, match=r"manifest.csv, line 3: .*listed twice"):
            load_rig_data(d)


@pytest.mark.parametrize("lateral", ["-1e9", "0.76", "-0.7501", "1e300"])
def test_crg_lateral_outside_the_file(tmp_path, lateral):
    pytest.importorskip("pycrg")
    road = tmp_path / "road.crg"
    assert run_capped(["vehicle", "generate", "--output", road, "--length", "100"]).rc == 0
    res = run_capped(["vehicle", "road", "--profile", road, "--lateral", lateral], seconds=60)
    assert_user_error(res, "lateral", "[-0.75, 0.75]")


def test_crg_tracks_wider_than_the_file(tmp_path):
    """The example car's wheels (track 1.51 m) do not fit a 1.5 m wide file."""
    pytest.importorskip("pycrg")
    road = tmp_path / "road.crg"
    assert run_capped(["vehicle", "generate", "--output", road, "--length", "100"]).rc == 0
    res = run_capped(["vehicle", "simulate", "--road-file", road], seconds=60)
    assert_user_error(res, "track", "[-0.75, 0.75]")


def test_rig_output_folder_with_a_fifo_manifest_does_not_block(tmp_path):
    """Deciding whether ``rig-simulate --out`` may replace a folder reads its manifest
    only if it is a regular file: a planted FIFO is refused at once, never waited for."""
    d = tmp_path / "rig"
    d.mkdir()
    os.mkfifo(d / "manifest.csv")
    res = run_capped(["rig-simulate", "--out", d, "--max-duration", "0.2"], seconds=30)
    assert_user_error(res, "out")
    assert res.seconds < 20
    assert sorted(p.name for p in d.iterdir()) == ["manifest.csv"]
