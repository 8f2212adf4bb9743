"""Every store, against every class of change and damage: recompute nothing wrong.

Generated cases over every command that keeps a store under ``--out`` (``vehicle
monte-carlo``, ``network truth``, ``sweep`` with a point that reads no file and with
one that reads a vehicle file), each run in a forked child capped in memory and time:

* keyed on content: an input file edited (or the point's own inputs changed) between
  two runs with the same ``--out`` is refused with one line saying the inputs changed
  and what to do; the same inputs resume to the same numbers; a file edited *while*
  a sweep runs stops it;
* damaged: a truncated chunk, a flipped byte, a deleted array, a deleted chunk of a
  metric, a deleted or garbled array description -> "store damaged" naming the array;
* not ours: a dangling link, someone else's Zarr group, a plain file, a folder with
  other files -> refused, nothing written into it; a link to a store of ours is used;
* the report cache, the coverage study and every sweep store are keyed on every file
  of the package (code and data) and the libraries' versions: a store made by other code
  is not resumed, and a worker running other code refuses its chunk.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from _capped import assert_user_error, run_capped

pytestmark = pytest.mark.timeout(600)

SWEEP_TOML = """point = "synthetic"
chunk_size = 2
[parameters]
changing_ratio = [0.1, 0.2, 0.3, 0.4]
"""


def _vehicle_sweep(car: Path) -> str:
    return f"""point = "vehicle-spectral"
chunk_size = 1
[parameters]
front_damping = [1500.0, 2500.0]
[settings]
vehicle = "{car}"
"""


def _example_car(d: Path) -> Path:
    from inerterlab.vehicles.config import example_vehicle_path

    car = d / "car.toml"
    car.write_text(example_vehicle_path().read_text())
    return car


def _edit_car(car: Path) -> None:
    text = car.read_text()
    assert 'damping = "2200 N s/m"' in text
    car.write_text(text.replace('damping = "2200 N s/m"', 'damping = "6000 N s/m"'))


# each store command: (argv for a folder d and an --out, the store inside --out)
def _argv(kind: str, d: Path, out: Path) -> list:
    car = d / "car.toml"
    if kind == "vehicle monte-carlo":
        return ["vehicle", "monte-carlo", "--vehicle", car, "--roads", "2", "--length", "50",
                "--backend", "serial", "--quiet", "--json", "--out", out]  # fmt: skip
    if kind == "network truth":
        return ["network", "truth", "--layout", "series", "--input", "bump", "--horizon", "1",
                "--variant", "ideal", "--backend", "serial", "--json", "--out", out]  # fmt: skip
    if kind == "sweep":
        return ["sweep", d / "sweep.toml", "--out", out, "--backend", "serial", "--quiet", "--json"]
    if kind == "sweep vehicle-spectral":
        return ["sweep", d / "vsweep.toml", "--out", out, "--backend", "serial", "--quiet",
                "--json"]  # fmt: skip
    raise KeyError(kind)


INNER = {"network truth": "layouts-*.zarr"}  # keyed on its sweep and the code
KINDS = ["vehicle monte-carlo", "network truth", "sweep", "sweep vehicle-spectral"]


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """One finished store of every kind, with its inputs and first output."""
    base = tmp_path_factory.mktemp("stores")
    out = {}
    for kind in KINDS:
        d = base / kind.replace(" ", "_")
        d.mkdir()
        car = _example_car(d)
        (d / "sweep.toml").write_text(SWEEP_TOML)
        (d / "vsweep.toml").write_text(_vehicle_sweep(car))
        res = run_capped(_argv(kind, d, d / "s.zarr"), memory_mb=2500, seconds=240)
        assert res.rc == 0, (kind, res.err)
        out[kind] = (d, res.out)
    return out


def _copy(made, kind, tmp_path) -> tuple[Path, Path, str]:
    """A private copy of the finished store of ``kind``: (folder, --out, first output)."""
    src, first = made[kind]
    d = tmp_path / "w"
    shutil.copytree(src, d, symlinks=True)
    # the configuration names the copy's car: another path, the same content
    (d / "vsweep.toml").write_text(_vehicle_sweep(d / "car.toml"))
    return d, d / "s.zarr", first


def _numbers(text: str):
    obj = json.loads(text)
    for k in ("store", "backend", "points_computed", "computed_now", "seconds",
              "points_per_second", "resumed_from", "unread_stores"):  # fmt: skip
        obj.pop(k, None)
    return obj


# --- keyed on content ------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
def test_same_inputs_resume_to_the_same_numbers(made, tmp_path, kind):
    # a copy elsewhere: the input files have other paths and the same content
    d, out, first = _copy(made, kind, tmp_path)
    res = run_capped(_argv(kind, d, out), memory_mb=2500, seconds=240)
    assert res.rc == 0, res.err
    assert _numbers(res.out) == _numbers(first)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["vehicle monte-carlo", "sweep vehicle-spectral"])
def test_an_edited_input_file_is_refused(made, tmp_path, kind):
    """The issue's example: the car edited, the same --out -> refused, not the old car."""
    src, _ = made[kind]
    d = src  # the original folder: its configuration names this car
    car = d / "car.toml"
    saved = car.read_text()
    try:
        _edit_car(car)
        res = run_capped(_argv(kind, d, d / "s.zarr"), memory_mb=2500, seconds=240)
        line = assert_user_error(res, "s.zarr", "inputs changed", "new --out", "vehicle")
        assert "sha256:" in line
    finally:
        car.write_text(saved)
    again = run_capped(_argv(kind, d, d / "s.zarr"), memory_mb=2500, seconds=240)
    assert again.rc == 0, again.err  # the file as it was: resumed


@pytest.mark.slow
def test_changed_network_texts_are_computed_anew(made, tmp_path):
    """network truth is keyed on what its points read, the layouts' network texts among
    them: each of its stores is named by a digest of its sweep, inputs included, so a
    study with an edited layout computes into new stores and leaves the old ones as they
    were (as a design study's stages)."""
    d, out, first = _copy(made, "network truth", tmp_path)
    argv = _argv("network truth", d, out)
    before = {p.name: _listing(p) for p in out.iterdir()}

    def edited():
        import inerterlab.network_truth as nt
        from inerterlab.cli import main

        nt.LAYOUTS["series"] = "k | (b - c)"
        return main([str(a) for a in argv])

    res = run_capped(edited, memory_mb=2500, seconds=240)
    assert res.rc == 0, res.err
    after = {p.name: p for p in out.iterdir()}
    assert set(before) < set(after)
    assert {n.split("-")[0] for n in set(after) - set(before)} == {"baseline", "layouts"}
    assert all(_listing(after[n]) == before[n] for n in before)
    assert _numbers(res.out) != _numbers(first)
    again = run_capped(_argv("network truth", d, out), memory_mb=2500, seconds=240)
    assert again.rc == 0, again.err
    assert _numbers(again.out) == _numbers(first)
    # the edited study's stores are named as not read by this one
    assert json.loads(again.out)["unread_stores"] == sorted(set(after) - set(before))


def test_a_file_edited_while_the_sweep_runs_stops_it(tmp_path):
    from inerterlab.studies import sweep
    from inerterlab.studies.sweep import InputChanged

    car = _example_car(tmp_path)
    spec = {
        "point": "vehicle-spectral",
        "parameters": {"front_damping": [1500.0, 2000.0, 2500.0]},
        "settings": {"vehicle": str(car)},
        "chunk_size": 1,
    }

    def edit(done, total):
        if done == 1:
            _edit_car(car)

    with pytest.raises(InputChanged, match="changed while the sweep ran"):
        sweep(spec, store=tmp_path / "s.zarr", backend="serial", progress=edit)


def test_the_store_records_the_digest_of_the_vehicle_file(tmp_path):
    import hashlib

    import zarr

    from inerterlab.vehicles.stochastic import monte_carlo

    car = _example_car(tmp_path)
    monte_carlo(vehicle=str(car), model="half", roads=2, length=30.0, store=tmp_path / "m.zarr")
    cfg = dict(zarr.open_group(str(tmp_path / "m.zarr"), mode="r").attrs)["config"]
    digest = "sha256:" + hashlib.sha256(car.read_bytes()).hexdigest()
    assert cfg["inputs"] == {"vehicle": digest}


def _zarr_groups(out: Path) -> list[Path]:
    """Every sweep store at or under ``out`` (a folder whose zarr.json holds our format)."""
    found = []
    for meta in sorted([out / "zarr.json", *out.rglob("*/zarr.json")]):
        if meta.exists() and "inerterlab-sweep" in meta.read_text():
            found.append(meta.parent)
    return found


def _made_by_other_code(store: Path) -> None:
    """Rewrite a store's record of its code: another inerterlab's files and numpy."""
    import zarr

    g = zarr.open_group(str(store), mode="r+")
    code = dict(g.attrs)["code"]
    g.attrs["code"] = {**code, "source": "0" * 64,
                       "libraries": {**code["libraries"], "numpy": "1.0.0"}}  # fmt: skip


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
def test_a_store_made_by_other_code_is_not_resumed(made, tmp_path, kind):
    """An upgrade (or an edit of the package) between two runs with the same --out: the
    finished points are another code's; refused in one line, the store left as it was."""
    d, out, _ = _copy(made, kind, tmp_path)
    stores = _zarr_groups(out)
    assert stores, kind
    for store in stores:
        _made_by_other_code(store)
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    res = run_capped(_argv(kind, d, out), memory_mb=2500, seconds=240)
    assert_user_error(res, ".zarr", "other code", "numpy 1.0.0 -> ", "inerterlab's files",
                      "new --out")  # fmt: skip
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_the_store_records_its_code_and_refuses_other_code(tmp_path, monkeypatch):
    import zarr

    from inerterlab import DataFileError, _provenance
    from inerterlab.studies import load_sweep, sweep

    spec = {"point": "synthetic", "parameters": {"changing_ratio": [0.1, 0.2]}}
    store = tmp_path / "s.zarr"
    ds = sweep(spec, store=store, backend="serial")
    code = _provenance.code_identity()
    assert dict(zarr.open_group(str(store), mode="r").attrs)["code"] == code
    assert json.loads(ds.attrs["code"]) == code
    sweep(spec, store=store, backend="serial")  # the same code: resumed
    # a store of a version that did not record its code
    old = tmp_path / "old.zarr"
    shutil.copytree(store, old)
    g = zarr.open_group(str(old), mode="r+")
    del g.attrs["code"]
    with pytest.raises(DataFileError, match="code that made it is not recorded"):
        sweep(spec, store=old, backend="serial")
    # this process's files changed: the store is another code's; reading it still works
    _provenance._tree_hash.cache_clear()
    monkeypatch.setattr(_provenance, "source_hash", lambda: "f" * 64)
    with pytest.raises(DataFileError, match=r"other code \(inerterlab's files [0-9a-f]{12} -> "
                       r"ffffffffffff\)"):  # fmt: skip
        sweep(spec, store=store, backend="serial")
    back = load_sweep(store)
    assert json.loads(back.attrs["code"]) == code
    np.testing.assert_array_equal(back.rms_body_acc.values, ds.rms_body_acc.values)


def test_a_worker_running_other_code_refuses_its_chunk():
    from inerterlab import _provenance
    from inerterlab.studies import sweep_spec
    from inerterlab.studies.sweep import ChunkTask, CodeChanged, evaluate_chunk

    sp = sweep_spec("synthetic", parameters={"changing_ratio": [0.1, 0.2]})
    other = _provenance.code_identity()
    other = {**other, "libraries": {**other["libraries"], "scipy": "0.1"}}
    task = ChunkTask(sp.point_function, ("changing_ratio",), ((0.1, 0.2),),
                     tuple(sorted(sp.fixed().items())), (0, 1), 0, (),
                     json.dumps(other, sort_keys=True))  # fmt: skip
    with pytest.raises(CodeChanged, match=r"scipy 0\.1 -> "):
        evaluate_chunk(task)
    same = json.dumps(_provenance.code_identity(), sort_keys=True)
    res = evaluate_chunk(ChunkTask(*[getattr(task, f) for f in
                                     ("point", "names", "values", "fixed", "indices", "chunk",
                                      "inputs")], same))  # fmt: skip
    assert list(res.status) == [1, 1], res.reasons


# --- damaged ---------------------------------------------------------------------------


def _damage(store: Path, how: str) -> str:
    """Damage ``store``; return the array the message must name."""
    name = "status" if how in ("truncated chunk", "flipped byte") else None
    metrics = sorted(p.name for p in store.iterdir() if p.is_dir() and p.name not in
                     ("status", "reason"))  # fmt: skip
    name = name or metrics[0]
    arr = store / name
    chunk = sorted((arr / "c").rglob("*"))[0] if (arr / "c").exists() else None
    if how == "truncated chunk":
        data = chunk.read_bytes()
        chunk.write_bytes(data[: len(data) // 2])
    elif how == "flipped byte":
        data = bytearray(chunk.read_bytes())
        data[len(data) // 2] ^= 0x10
        chunk.write_bytes(bytes(data))
    elif how == "metric chunk flipped":
        data = bytearray(chunk.read_bytes())
        data[len(data) // 3] ^= 0x01
        chunk.write_bytes(bytes(data))
    elif how == "deleted array":
        shutil.rmtree(arr)
    elif how == "deleted metric chunk":
        chunk.unlink()
    elif how == "deleted array description":
        (arr / "zarr.json").unlink()
    elif how == "garbled array description":
        (arr / "zarr.json").write_text("{not json")
    else:
        raise KeyError(how)
    return name


DAMAGE = [
    "truncated chunk",
    "flipped byte",
    "metric chunk flipped",
    "deleted array",
    "deleted metric chunk",
    "deleted array description",
    "garbled array description",
]


@pytest.mark.slow
@pytest.mark.parametrize("how", DAMAGE)
@pytest.mark.parametrize("kind", KINDS)
def test_a_damaged_store_is_reported_naming_the_array(made, tmp_path, kind, how):
    d, out, _ = _copy(made, kind, tmp_path)
    store = next(out.glob(INNER[kind])) if kind in INNER else out
    name = _damage(store, how)
    res = run_capped(_argv(kind, d, out), memory_mb=2500, seconds=240)
    assert_user_error(res, "store damaged", f"'{name}'")


@pytest.mark.parametrize("how", ["truncated chunk", "deleted array", "deleted metric chunk"])
def test_load_sweep_of_a_damaged_store(tmp_path, how):
    from inerterlab import DataFileError
    from inerterlab.studies import load_sweep, sweep

    spec = {"point": "synthetic", "parameters": {"changing_ratio": [0.1, 0.2]}}
    sweep(spec, store=tmp_path / "s.zarr", backend="serial")
    name = _damage(tmp_path / "s.zarr", how)
    with pytest.raises(DataFileError, match=f"store damaged: array '{name}'"):
        load_sweep(tmp_path / "s.zarr")


# --- not ours --------------------------------------------------------------------------


def _foreign(kind_out: str, tmp_path: Path) -> Path:
    p = tmp_path / "elsewhere"
    if kind_out == "dangling link":
        p.symlink_to(tmp_path / "gone")
    elif kind_out == "someone else's zarr group":
        import zarr

        g = zarr.open_group(str(p), mode="w")
        g.attrs["owner"] = "another program"
        g.create_array("data", shape=(3,), dtype="float64")
    elif kind_out == "plain file":
        p.write_text("precious\n")
    elif kind_out == "folder with other files":
        p.mkdir()
        (p / "notes.txt").write_text("precious\n")
    else:
        raise KeyError(kind_out)
    return p


NOT_OURS = ["dangling link", "someone else's zarr group", "plain file", "folder with other files"]


def _listing(p: Path):
    if p.is_symlink() and not p.exists():
        return "dangling"
    if p.is_file():
        return p.read_bytes()
    return sorted((str(q.relative_to(p)), q.stat().st_size) for q in p.rglob("*"))


@pytest.mark.slow
@pytest.mark.parametrize("what", NOT_OURS)
@pytest.mark.parametrize("kind", KINDS)
def test_an_out_that_is_not_ours_is_refused_and_left_alone(made, tmp_path, kind, what):
    d, _, _ = _copy(made, kind, tmp_path)
    out = _foreign(what, tmp_path)
    before = _listing(out)
    res = run_capped(_argv(kind, d, out), memory_mb=2500, seconds=240)
    assert_user_error(res, "elsewhere", "another --out")
    assert _listing(out) == before


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["vehicle monte-carlo", "sweep"])
def test_a_link_to_our_store_is_followed(made, tmp_path, kind):
    d, out, first = _copy(made, kind, tmp_path)
    link = tmp_path / "link.zarr"
    link.symlink_to(out)
    res = run_capped(_argv(kind, d, link), memory_mb=2500, seconds=240)
    assert res.rc == 0, res.err
    assert _numbers(res.out) == _numbers(first)


# --- the report cache and the coverage study ---------------------------------------------


def test_report_cache_key_follows_every_package_file(tmp_path, monkeypatch):
    from inerterlab import _provenance
    from inerterlab.report import cache

    root = tmp_path / "pkg"
    (root / "data").mkdir(parents=True)
    (root / "a.py").write_text("x = 1\n")
    (root / "data" / "thesis.csv").write_text("table,value\n4.3,1.98\n")
    monkeypatch.setattr(_provenance, "_ROOT", root)
    keys = [cache.cache_key({"quick": True})]
    for path, text in ((root / "data" / "thesis.csv", "table,value\n4.3,2.05\n"),
                       (root / "a.py", "x = 2\n")):  # fmt: skip
        path.write_text(text)
        _provenance._tree_hash.cache_clear()
        keys.append(cache.cache_key({"quick": True}))
    assert len(set(keys)) == 3
    monkeypatch.setattr(_provenance, "library_versions", lambda: {"numpy": "0.0"})
    assert cache.cache_key({"quick": True}) != keys[-1]


def test_coverage_study_refuses_results_of_other_inputs(tmp_path):
    import importlib.util

    bench = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_identify_coverage.py"
    out = tmp_path / "cov"
    out.mkdir()
    settings = {"max_duration": 0.5, "sample_rate": 100.0, "reversal_window": None}
    stale = {**settings, "inputs": {"package_files": "0" * 64, "libraries": {}}}
    (out / "settings.json").write_text(json.dumps(stale))

    def run():
        spec = importlib.util.spec_from_file_location("bench_cov", bench)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod.main(["--campaigns", "2", "--devices", "screw", "--out", str(out),
                         "--max-duration", "0.5", "--sample-rate", "100"])  # fmt: skip

    res = run_capped(run, memory_mb=2500, seconds=120)
    assert res.rc == 2, res.err
    assert "other inputs" in res.err and "package_files" in res.err
    assert not (out / "screw").exists()  # nothing computed


def test_damaged_status_never_reads_as_numbers(tmp_path):
    """Every chunk carries a checksum: a flipped bit anywhere is found, not decoded."""
    from inerterlab import DataFileError
    from inerterlab.studies import load_sweep, sweep

    spec = {"point": "synthetic", "parameters": {"changing_ratio": [0.1, 0.2, 0.3]}}
    sweep(spec, store=tmp_path / "s.zarr", backend="serial")
    chunk = next((tmp_path / "s.zarr" / "rms_body_acc" / "c").rglob("*"))
    data = bytearray(chunk.read_bytes())
    for i in range(len(data)):
        flipped = bytearray(data)
        flipped[i] ^= 0x04
        chunk.write_bytes(bytes(flipped))
        with pytest.raises(DataFileError, match="store damaged: array 'rms_body_acc'"):
            load_sweep(tmp_path / "s.zarr")
    chunk.write_bytes(bytes(data))
    assert np.isfinite(load_sweep(tmp_path / "s.zarr").rms_body_acc.values).all()
