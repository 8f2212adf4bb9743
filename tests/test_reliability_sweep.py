"""Sweep crash safety: a store is valid from its first byte, a second writer is locked
out, workers die with the main process, a sweep file cannot write files of the user's."""

from __future__ import annotations

import importlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from inerterlab.cli import main
from inerterlab.errors import LockedError
from inerterlab.studies import load_sweep, sweep
from inerterlab.studies.points import LOG_FILE_ENV

sweep_mod = importlib.import_module("inerterlab.studies.sweep")

SWEEP = {"point": "synthetic", "parameters": {"changing_ratio": [0.1, 0.2, 0.3]}}
CFG = 'point = "synthetic"\n[parameters]\nchanging_ratio = {start = 0.05, stop = 0.55, num = 40}\n'


def test_store_creation_interrupted_leaves_no_store_and_next_run_cleans(tmp_path, monkeypatch):
    store = tmp_path / "s.zarr"
    real_rename = os.rename

    def killed(src, dst):
        raise KeyboardInterrupt  # as if the run died just before the store appeared

    monkeypatch.setattr(sweep_mod.os, "rename", killed)
    with pytest.raises(KeyboardInterrupt):
        sweep(SWEEP, store=store, backend="serial")
    monkeypatch.setattr(sweep_mod.os, "rename", real_rename)
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing half made
    # a leftover of a run killed by SIGKILL mid-creation is removed by the next run
    (tmp_path / ".s.zarr.new-k1ll3d").mkdir()
    ds = sweep(SWEEP, store=store, backend="serial")
    assert int((ds.status == 1).sum()) == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr"]


def test_second_writer_is_locked_out(tmp_path):
    store = tmp_path / "s.zarr"
    sweep(SWEEP, store=store, backend="serial")
    fd = sweep_mod._lock_store(store)
    try:
        with pytest.raises(LockedError, match="another inerterlab sweep"):
            sweep(SWEEP, store=store, backend="serial")
    finally:
        os.close(fd)
    sweep(SWEEP, store=store, backend="serial")  # free again


def test_log_file_from_a_sweep_file_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.delenv(LOG_FILE_ENV, raising=False)
    target = tmp_path / "victim.txt"
    cfg = tmp_path / "s.toml"
    cfg.write_text(CFG + f'[settings]\nlog_file = "{target}"\n')
    rc = main(["sweep", str(cfg), "--backend", "serial", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "log_file" in err and "line 5" in err
    assert not target.exists()


def _children(pid: int) -> set[int]:
    out = set()
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                out.add(int(d.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_killing_the_main_process_takes_the_workers_with_it(tmp_path):
    cfg = tmp_path / "s.toml"
    cfg.write_text("chunk_size = 1\n" + CFG + "[settings]\ndelay = 0.5\n")
    code = "import sys; from inerterlab.cli import main; sys.exit(main())"
    cmd = [sys.executable, "-c", code, "sweep", str(cfg), "--out", str(tmp_path / "s.zarr")]
    proc = subprocess.Popen(cmd + ["--workers", "2", "--quiet"], stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 60
        kids: set[int] = set()
        while time.time() < deadline and len(kids) < 2:
            kids = _children(proc.pid)
            time.sleep(0.1)
        assert len(kids) >= 2, "workers did not start"
        time.sleep(1.0)  # workers busy with points
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
        deadline = time.time() + 10
        while time.time() < deadline and any(_alive(k) for k in kids):
            time.sleep(0.1)
        assert not any(_alive(k) for k in kids), "workers outlived the main process"
    finally:
        if proc.poll() is None:
            proc.kill()
    # and the store it left resumes
    rc = subprocess.run(cmd + ["--backend", "serial", "--quiet"], capture_output=True, timeout=120)
    assert rc.returncode == 0, rc.stderr
    assert int((load_sweep(tmp_path / "s.zarr").status == 1).sum()) == 40


@pytest.mark.slow
def test_sigkill_right_after_the_store_appears_always_resumes(tmp_path):
    """Kill -9 at once when the store directory shows up, ten times: every store resumes."""
    code = "import sys; from inerterlab.cli import main; sys.exit(main())"
    cfg = tmp_path / "s.toml"
    cfg.write_text(CFG)
    for k in range(10):
        store = tmp_path / f"s{k}.zarr"
        cmd = [sys.executable, "-c", code, "sweep", str(cfg), "--out", str(store)]
        cmd += ["--backend", "serial", "--quiet"]
        proc = subprocess.Popen(cmd, stderr=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
        deadline = time.time() + 60
        while time.time() < deadline and not store.exists() and proc.poll() is None:
            time.sleep(0.001)
        time.sleep(0.002 * k)
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, (k, r.stderr)
        assert int((load_sweep(store).status == 1).sum()) == 40


def test_dask_run_without_any_worker_stops_with_a_message(tmp_path):
    from distributed import LocalCluster

    from inerterlab.studies import DaskBackend
    from inerterlab.studies.backends import WorkersLost

    with LocalCluster(
        n_workers=0, processes=False, dashboard_address=":0", host="127.0.0.1", protocol="tcp"
    ) as cluster:
        be = DaskBackend(scheduler=cluster.scheduler_address)
        be.no_worker_timeout = 3.0
        t0 = time.monotonic()
        with pytest.raises(WorkersLost, match="every Dask worker has been gone"):
            sweep(SWEEP, store=tmp_path / "s.zarr", backend=be)
        assert time.monotonic() - t0 < 60
    # nothing was computed, the store is valid and resumes with a working backend
    ds = sweep(SWEEP, store=tmp_path / "s.zarr", backend="serial")
    assert int((ds.status == 1).sum()) == 3
