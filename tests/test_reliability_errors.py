"""Bad input that used to end in an internal error (exit 1) or a silent wrong action:
each is now exit 2 with one line on stderr naming the option, file or line."""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

import pytest

from inerterlab.cli import main


def _run(capsys, args):
    rc = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


def _one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("inerterlab: error: "), err
    assert "Traceback" not in err and "internal error" not in err
    return lines[0]


@pytest.fixture()
def files(tmp_path):
    (tmp_path / "dir").mkdir()
    (tmp_path / "dir" / "keep.txt").write_text("mine")
    (tmp_path / "file.txt").write_text("x")
    (tmp_path / "nested.toml").write_text("x = " + "[" * 3000 + "]" * 3000 + "\n")
    (tmp_path / "list_point.toml").write_text(
        'point = ["synthetic"]\n[parameters]\nchanging_ratio = [0.1, 0.2]\n'
    )
    (tmp_path / "huge_num.toml").write_text(
        'point = "synthetic"\n[parameters]\nchanging_ratio = {start = 0.1, stop = 0.5, num = 100000000000}\n'
    )
    (tmp_path / "tiny_step.toml").write_text(
        'point = "synthetic"\n[parameters]\nchanging_ratio = {start = 0.1, stop = 0.5, step = 1e-15}\n'
    )
    (tmp_path / "huge_chunk.toml").write_text(
        'point = "synthetic"\nchunk_size = 1000000000000\n[parameters]\nchanging_ratio = [0.1, 0.2]\n'
    )
    (tmp_path / "ok.toml").write_text(
        'point = "synthetic"\n[parameters]\nchanging_ratio = [0.1, 0.2]\n'
    )
    rig = tmp_path / "rig"
    rig.mkdir()
    (rig / "manifest.csv").write_text(
        "file,signal,frequency_hz,amplitude_m,purpose\n/etc/passwd,sine,1,0.01,identification\n"
    )
    binrig = tmp_path / "binrig"
    binrig.mkdir()
    (binrig / "manifest.csv").write_text(
        "file,signal,frequency_hz,amplitude_m,purpose\nt.csv,sine,1,0.01,identification\n"
    )
    (binrig / "t.csv").write_bytes(b"\x00\x81\xfe\xff" * 100)
    return tmp_path


CASES = [
    # (arguments, text the error line must contain)
    (["simulate", "--input", "iso8608", "--seed", "-1", "--horizon", "1"], "seed"),
    (["rig-simulate", "--seed", "-1", "--out", "{tmp}/never"], "seed"),
    (["h2", "--suspension", "cfw", "--inertance", "1e300"], "inertance"),
    (["frequency-response", "--harmonics", "99999999999999999999"], "harmonics"),
    (["frequency-response", "--method", "mhb", "--harmonics", "2000"], "harmonics"),
    (["frequency-response", "--df", "1e-9"], "df"),
    (["frequency-response", "--samples", "100000000"], "n_samples"),
    (["rig-simulate", "--sample-rate", "1e6", "--out", "{tmp}/never"], "sample_rate"),
    (["rig-simulate", "--out", "{tmp}/file.txt"], "out"),
    (["rig-simulate", "--out", "{tmp}/dir", "--max-duration", "0.2"], "out"),
    (["simulate", "--horizon", "0.5", "--plot", "{tmp}/f.xyz"], "--plot"),
    (["simulate", "--horizon", "0.5", "--plot", "{tmp}/dir"], "--plot"),
    (["sweep", "{tmp}/nested.toml"], "nested.toml"),
    (["sweep", "{tmp}/list_point.toml"], "list_point.toml, line 1"),
    (["sweep", "{tmp}/huge_num.toml"], "num"),
    (["sweep", "{tmp}/tiny_step.toml"], "step"),
    (["sweep", "{tmp}/huge_chunk.toml"], "chunk_size"),
    (["sweep", "{tmp}/list_point.toml", "--scheduler", "notanaddress"], "list_point"),
    (["identify", "--data", "{tmp}/rig"], "outside the data directory"),
    (["identify", "--data", "{tmp}/binrig"], "not a UTF-8 text file"),
    (["simulate", "--input", "iso8608", "--speed", "1e6"], "speed"),
    (["simulate", "--input", "/dev/zero", "--horizon", "1"], "/dev/zero"),
    (["simulate", "--input", "{tmp}/dir", "--horizon", "1"], "is a directory"),
    (["optimize-ratio", "--method", "interpolate", "--grid-step", "1e-9"], "--grid-step"),
    (["simulate", "--method", "exact", "--suspension", "afw", "--horizon", "1"], "exact"),
    (["sweep", "{tmp}/ok.toml", "--workers", "99999999999999999999"], "--workers"),
    (["sweep", "{tmp}/list_point.toml", "--workers", "100000"], "list_point"),
    (["reproduce", "--quick", "--workers", "1000000", "--out", "{tmp}/r"], "--workers"),
    (["reproduce", "--tables", "", "--out", "{tmp}/r"], "--tables"),
    (["reproduce", "--tables", "4.1-4.99999999", "--out", "{tmp}/r"], "--tables"),
]


@pytest.mark.parametrize("args,needle", CASES, ids=[" ".join(c[0][:3]) for c in CASES])
def test_bad_input_is_one_line_and_exit_2(files, capsys, args, needle):
    args = [a.replace("{tmp}", str(files)) for a in args]
    rc, _, err = _run(capsys, args)
    line = _one_error_line(err)
    assert rc == 2, err
    assert needle in line, line
    assert not (files / "never").exists() and not (files / "r").exists()


def test_bad_scheduler_address_is_a_user_error(files, capsys):
    (files / "ok.toml").write_text(
        'point = "synthetic"\n[parameters]\nchanging_ratio = [0.1, 0.2]\n'
    )
    rc, _, err = _run(capsys, ["sweep", files / "ok.toml", "--scheduler", "notanaddress"])
    assert rc == 2 and "scheduler" in _one_error_line(err)


def test_manifest_outside_file_is_never_read_or_echoed(files, capsys):
    rc, _, err = _run(capsys, ["identify", "--data", files / "rig"])
    assert rc == 2 and "root:" not in err


def test_library_warnings_come_after_the_error_line_once(capsys):
    rc, _, err = _run(capsys, ["h2", "--sprung-mass", "1e-300"])
    lines = err.splitlines()
    assert rc == 2
    assert lines[0].startswith("inerterlab: error: "), err
    assert all(ln.startswith("inerterlab: warning: ") for ln in lines[1:]), err
    assert len(lines[1:]) == len(set(lines[1:]))


def test_non_finite_json_names_the_result(monkeypatch):
    from inerterlab.cli import _common
    from inerterlab.errors import InerterlabError

    with pytest.raises(InerterlabError, match=r"result metrics\.rms\[1\] is nan"):
        _common.emit_json({"metrics": {"rms": [1.0, float("nan")]}})


@pytest.mark.parametrize(
    "code,needle", [(errno.ENOSPC, "free some space"), (errno.EROFS, "read-only")]
)
def test_full_disk_and_read_only_are_user_errors(tmp_path, capsys, monkeypatch, code, needle):
    import inerterlab.io as io_mod

    def full(*a, **k):
        raise OSError(code, os.strerror(code), str(tmp_path / "x.csv"))

    monkeypatch.setattr(io_mod.os, "replace", full)
    rc, _, err = _run(
        capsys,
        ["device-force", "--amplitude", "0.01", "--duration", "0.1", "--csv", tmp_path / "x.csv"],
    )
    line = _one_error_line(err)
    assert rc == 2 and needle in line and "x.csv" in line
    assert [p.name for p in tmp_path.iterdir()] == []  # no temporary left behind


def test_rig_data_set_is_replaced_whole(tmp_path, capsys, monkeypatch):
    """A failed write over an older data set leaves the older set intact, never a mix."""
    out = tmp_path / "rig"
    base = ["rig-simulate", "--max-duration", "0.2", "--out", out]
    assert _run(capsys, base + ["--seed", "1"])[0] == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    assert stat.S_IMODE(out.stat().st_mode) == 0o777 & ~_umask()

    import inerterlab.io as io_mod

    real_open = open
    calls = {"n": 0}

    def failing_open(path, mode="r", *a, **k):
        if "w" in mode and ".new-" in str(path):
            calls["n"] += 1
            if calls["n"] == 5:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        return real_open(path, mode, *a, **k)

    monkeypatch.setattr("builtins.open", failing_open)
    rc, _, err = _run(capsys, base + ["--seed", "2"])
    monkeypatch.undo()
    assert rc == 2 and "No space left" in err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rig"]
    # a stale temporary from a killed run is cleaned by the next write
    (tmp_path / ".rig.new-deadbeef").mkdir()
    assert _run(capsys, base + ["--seed", "2"])[0] == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rig"]
    assert io_mod  # module used above through monkeypatch


def _umask() -> int:
    from inerterlab.io import current_umask

    return current_umask()


def test_reproduce_out_is_not_the_current_directory(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, _, err = _run(capsys, ["reproduce", "--quick", "--tables", "4.1", "--out", ""])
    assert rc == 2 and "--out" in _one_error_line(err)
    assert list(Path(tmp_path).iterdir()) == []


def test_identify_size_guard_refuses_hours_and_announces_minutes(capsys):
    from types import SimpleNamespace

    import numpy as np

    from inerterlab import ParameterError
    from inerterlab.cli.identify import _check_fit_size

    def data(n):
        return SimpleNamespace(tests=[SimpleNamespace(t=np.empty(n))])

    _check_fit_size(data(100_000), 0)  # seconds: silent
    assert capsys.readouterr().err == ""
    _check_fit_size(data(3_000_000), 0)  # minutes: a note first
    assert "note: fitting 3000000 samples" in capsys.readouterr().err
    with pytest.raises(ParameterError, match="--bootstrap"):
        _check_fit_size(data(1_000_000), 100)  # hours: refused
    with pytest.raises(ParameterError, match="--data"):
        _check_fit_size(data(100_000_000), 0)


def test_absurd_worker_counts_are_refused_before_any_process_starts():
    from inerterlab import ParameterError
    from inerterlab.studies import sweep
    from inerterlab.studies.backends import max_workers

    spec = {"point": "synthetic", "parameters": {"changing_ratio": [0.1, 0.2]}}
    for n in (max_workers() + 1, 10**20):
        with pytest.raises(ParameterError, match="workers"):
            sweep(spec, backend="processes", workers=n)
        with pytest.raises(ParameterError, match="workers"):
            sweep(spec, backend="dask", workers=n)


def test_frequency_response_announces_long_runs_and_only_those(capsys, monkeypatch):
    from inerterlab.cli import frequency

    frequency._note_if_long(59, "sihb", None, None, True)  # the default: seconds
    assert capsys.readouterr().err == ""
    frequency._note_if_long(2901, "mhb", 60, None, False)  # minutes
    assert "note: 2901 frequencies" in capsys.readouterr().err
    frequency._note_if_long(10**9, "mhb", 60, None, False)  # refused later: no note
    assert capsys.readouterr().err == ""
