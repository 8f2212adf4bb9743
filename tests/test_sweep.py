"""Sweep machinery: backends agree point for point, stores resume, interrupts lose nothing."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import xarray as xr

from inerterlab import DataFileError
from inerterlab.studies import load_sweep, save_netcdf, sweep, sweep_spec
from inerterlab.studies.sweep import STATUS_FAILED, STATUS_MISSING, STATUS_OK

METRICS = ("rms_body_acc", "rms_tyre_grip", "rms_deflection")


def spec(log=None, chunk=7, fail_above=1.0, num=23, delay=0.0):
    settings = {"suspension": "afw", "fail_above_ratio": fail_above, "delay": delay}
    if log is not None:
        settings["log_file"] = str(log)
    return sweep_spec(
        "synthetic",
        parameters={
            "changing_ratio": {"start": 0.05, "stop": 0.55, "num": num},
            "input": ["drop", "bump", "sine"],
            "sprung_mass": [340.0, 400.0],
        },
        settings=settings,
        chunk_size=chunk,
    )


def logged(path):
    if not os.path.exists(path):
        return []
    with open(path) as fh:
        return [json.loads(line) for line in fh]


def key(rec):
    return (round(rec["changing_ratio"], 12), rec["input"], rec["sprung_mass"])


def assert_same(a, b):
    for m in METRICS:
        np.testing.assert_array_equal(a[m].values, b[m].values)
    np.testing.assert_array_equal(a.status.values, b.status.values)
    np.testing.assert_array_equal(a.reason.values, b.reason.values)


def test_dataset_layout_and_failed_points_are_not_numbers():
    ds = sweep(spec(fail_above=0.4), backend="serial")
    assert ds.rms_body_acc.dims == ("changing_ratio", "input", "sprung_mass")
    assert ds.sizes == {"changing_ratio": 23, "input": 3, "sprung_mass": 2}
    failed = ds.status == STATUS_FAILED
    assert int(failed.sum()) > 0
    assert np.isnan(ds.rms_body_acc.values[failed.values]).all()
    assert np.isfinite(ds.rms_body_acc.values[~failed.values]).all()
    assert all("synthetic failure" in r for r in ds.reason.where(failed, drop=True).values.ravel())
    assert int((ds.status == STATUS_OK).sum()) + int(failed.sum()) == ds.attrs["points"]
    assert ds.attrs["setting_suspension"] == "afw"
    # a point computed directly equals the swept one
    from inerterlab.studies.points import synthetic_point

    direct = synthetic_point(
        {
            "changing_ratio": float(ds.changing_ratio[3]),
            "input": "bump",
            "sprung_mass": 400.0,
            "suspension": "afw",
        }
    )
    assert (
        ds.rms_body_acc.isel(changing_ratio=3).sel(input="bump", sprung_mass=400.0)
        == direct["rms_body_acc"]
    )


def test_process_backend_matches_serial(tmp_path):
    s = spec(fail_above=0.5)
    assert_same(sweep(s, backend="serial"), sweep(s, backend="processes", workers=2))


def test_store_round_trip_resume_and_netcdf(tmp_path):
    log = tmp_path / "log.jsonl"
    s = spec(log=log)
    store = tmp_path / "s.zarr"
    ds1 = sweep(s, store=store, backend="serial")
    n = ds1.attrs["points"]
    assert len(logged(log)) == n
    ds2 = sweep(s, store=store, backend="processes", workers=2)  # nothing left to do
    assert len(logged(log)) == n
    assert ds2.attrs["points_computed"] == 0
    assert_same(ds1, load_sweep(store))
    nc = save_netcdf(ds1, tmp_path / "s.nc")
    back = xr.open_dataset(nc)
    np.testing.assert_array_equal(back.rms_body_acc.values, ds1.rms_body_acc.values)
    back.close()


def test_store_from_other_config_is_refused(tmp_path):
    store = tmp_path / "s.zarr"
    sweep(spec(num=5), store=store, backend="serial")
    with pytest.raises(DataFileError, match="different sweep configuration.*changing_ratio"):
        sweep(spec(num=6), store=store, backend="serial")
    (tmp_path / "other").mkdir()
    with pytest.raises(DataFileError, match="not a sweep store"):
        sweep(spec(num=5), store=tmp_path / "other", backend="serial")


def test_partial_store_resumes_only_missing_points(tmp_path):
    log = tmp_path / "log.jsonl"
    store = tmp_path / "s.zarr"
    s = spec(log=log, chunk=5)
    calls = []

    def stop_after_three_chunks(done, total):
        calls.append(done)
        if len(calls) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt, match="15 of 138 points are stored"):
        sweep(s, store=store, backend="serial", progress=stop_after_three_chunks)
    partial = load_sweep(store)
    assert int((partial.status != STATUS_MISSING).sum()) == 15
    first = {key(r) for r in logged(log)}
    ds = sweep(s, store=store, backend="serial")
    again = [key(r) for r in logged(log)][15:]
    assert len(again) == len(set(again)) == 138 - 15
    assert not (set(again) & first)
    assert_same(ds, sweep(spec(chunk=5), backend="serial"))


def test_dask_local_cluster_matches_serial():
    pytest.importorskip("distributed")
    from inerterlab.studies import DaskBackend

    s = spec(fail_above=0.5, chunk=11)
    with DaskBackend(workers=2, processes=False) as be:
        ds = sweep(s, backend=be)
    assert "dask" in ds.attrs["backend"]
    assert_same(sweep(s, backend="serial"), ds)


def test_killed_sweep_resumes_without_recomputing_or_losing_points(tmp_path):
    log = tmp_path / "log.jsonl"
    store = tmp_path / "s.zarr"
    cfg = tmp_path / "sweep.toml"
    cfg.write_text(
        'point = "synthetic"\nchunk_size = 4\n[parameters]\n'
        "changing_ratio = {start = 0.05, stop = 0.55, num = 30}\n"
        'input = ["drop", "bump", "sine"]\n'
        f'[settings]\nsuspension = "afw"\ndelay = 0.01\nlog_file = "{log}"\n'
    )
    main = "import sys; from inerterlab.cli import main; sys.exit(main())"
    cmd = [sys.executable, "-c", main, "sweep", str(cfg), "--out", str(store)]
    cmd += ["--backend", "serial", "--quiet"]
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 60
        while time.time() < deadline:
            if len(logged(log)) >= 30 or proc.poll() is not None:  # past the first chunks
                break
            time.sleep(0.02)
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == -signal.SIGKILL
    partial = load_sweep(store)
    stored = partial.status.values.ravel() != STATUS_MISSING
    assert 0 < stored.sum() < 90
    n_before = len(logged(log))
    res = subprocess.run(cmd + ["--json"], env=env, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    summary = json.loads(res.stdout)
    assert summary["ok"] == 90 and summary["computed_now"] == 90 - stored.sum()
    rerun = [key(r) for r in logged(log)[n_before:]]
    # exactly the points missing after the kill were computed, each once
    flat = partial.status.stack(p=("changing_ratio", "input"))
    missing = {
        (round(float(x), 12), str(i), 370.0)
        for x, i, st in zip(flat.changing_ratio.values, flat.input.values, flat.values, strict=True)
        if st == STATUS_MISSING
    }
    assert len(rerun) == len(set(rerun))
    assert set(rerun) == missing
    final = load_sweep(store)
    assert bool((final.status == STATUS_OK).all())
    ref = sweep(
        sweep_spec(
            "synthetic",
            parameters={
                "changing_ratio": {"start": 0.05, "stop": 0.55, "num": 30},
                "input": ["drop", "bump", "sine"],
            },
            settings={"suspension": "afw"},
        ),
        backend="serial",
    )
    np.testing.assert_array_equal(final.rms_body_acc.values, ref.rms_body_acc.values)


def test_processes_first_compile_in_the_calling_process(monkeypatch):
    """With worker processes, the calling process evaluates one point before it starts
    them (a first sweep after an install compiles the kernels there once, and the
    workers inherit them), its result not kept; serially nothing extra is evaluated,
    and nothing either when no point is left to compute."""
    import importlib
    import importlib.util

    sweep_module = importlib.import_module("inerterlab.studies.sweep")
    calls = []
    inner = sweep_module._evaluate_points

    def recorded(task):
        calls.append((os.getpid(), len(task.indices)))
        return inner(task)

    monkeypatch.setattr(sweep_module, "_evaluate_points", recorded)
    s = spec()
    ds = sweep(s, backend="processes", workers=2)
    assert calls == [(os.getpid(), 1)]  # the chunks ran in the workers
    assert ds.attrs["points_computed"] == ds.attrs["points"] == int((ds.status == STATUS_OK).sum())
    calls.clear()
    sweep(s, backend="serial")
    assert calls and all(n > 1 for _, n in calls)
    if importlib.util.find_spec("distributed") is not None:  # a local cluster's workers
        calls.clear()  # are processes started after the point (they load its cache)
        ds = sweep(s, backend="dask", workers=2)
        assert calls == [(os.getpid(), 1)]
        assert ds.attrs["points_computed"] == ds.attrs["points"]
