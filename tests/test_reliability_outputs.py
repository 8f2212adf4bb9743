"""Outputs: the resume cache runs no code, nothing of the user's is removed or replaced,
special files are streamed into, modes follow the umask."""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import stat
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from inerterlab import ParameterError
from inerterlab.cli import main
from inerterlab.errors import LockedError
from inerterlab.io import atomic_write_text
from inerterlab.report import build, cache
from inerterlab.report.registry import FigureResult, ReproduceSettings, TableResult


def _fake_chapters(calls):
    def table(settings):
        calls.append("t")
        frame = pd.DataFrame(
            {
                "quantity": ["a", "b", None],
                "ours": [1.0, np.nan, 1e-300],
                "n": np.array([1, 2, 3], dtype=np.int64),
                "flag": [True, False, True],
                "mixed": ["x", 1.5, None],
                "masked": pd.array([0.25, pd.NA, 2.0], dtype="Float64"),
                "count": pd.array([1, pd.NA, 3], dtype="Int64"),
            }
        )
        return TableResult(
            table_id="9.1",
            title="t",
            frame=frame,
            claim="c",
            claim_holds=None,
            reason="r",
            settings={"h": (1, 2), "x": np.float64(0.1), "law": "thesis"},
        )

    def figure(settings):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        calls.append("f")
        fig, ax = plt.subplots()
        ax.plot([0, 1], [0, 1])
        return FigureResult(
            figure_id="F", title="f", figure=fig, data=pd.DataFrame({"x": [0.1, 0.2]})
        )

    return {"9.1": table}, {"Figure 9": figure}


# ---- the resume cache ----------------------------------------------------------------


class _Boom:
    def __reduce__(self):
        return (os.system, ("touch PWNED",))


def test_planted_pickle_in_the_cache_is_never_loaded(tmp_path, monkeypatch):
    """The cache no longer reads pickles: a malicious one under every name the old and
    new formats use is ignored, nothing runs, and the item is computed afresh."""
    calls: list[str] = []
    monkeypatch.setattr(build, "_load_chapters", lambda: _fake_chapters(calls))
    monkeypatch.chdir(tmp_path)
    work = tmp_path / "w"
    work.mkdir()
    key = cache.cache_key({"quick": True, "workers": 1})
    old_key = hashlib.sha256(json.dumps({"quick": True, "workers": 1}, sort_keys=True).encode())
    payload = pickle.dumps(_Boom())
    for name in (f"table-9.1-{key}.json", f"table-9.1-{old_key.hexdigest()[:12]}.pkl"):
        (work / name).write_bytes(payload)
    recs = build.run_items(ReproduceSettings(quick=True), None, False, work, None)
    assert not (tmp_path / "PWNED").exists()
    assert calls == ["t"] and recs[0]["ok"] and not recs[0].get("reused")


def test_cache_round_trip_is_exact_and_rejects_forgeries(tmp_path, monkeypatch):
    calls: list[str] = []
    monkeypatch.setattr(build, "_load_chapters", lambda: _fake_chapters(calls))
    work = tmp_path / "w"
    s = ReproduceSettings(quick=True)
    first = build.run_items(s, None, True, work, None)
    again = build.run_items(s, None, True, work, None)
    assert calls == ["t", "f"]  # second run reused both
    assert all(r["reused"] for r in again)
    files_a = build.render(first, s, 1.0, "")
    files_b = build.render(again, s, 1.0, "")
    for k in files_a:
        if k not in ("index.html", "manifest.json"):
            assert files_a[k] == files_b[k], k
    a, b = first[0]["frame"], again[0]["frame"]
    assert list(a.dtypes) == list(b.dtypes) and a.equals(b)
    assert again[0]["settings"] == first[0]["settings"]
    assert type(again[0]["settings"]["h"]) is tuple
    # a cache file with a wrong key, a bad shape or garbage is ignored and recomputed
    (p,) = work.glob("table-*.json")
    good = json.loads(p.read_text())
    for bad in (
        {**good, "key": "0" * 16},
        {**good, "record": {**good["record"], "frame": "not a frame"}},
        {"format": cache.FORMAT, "key": good["key"], "record": {"__np__": "<M8[ns]", "v": 1}},
    ):
        p.write_text(json.dumps(bad))
        build.run_items(s, None, False, work, None)
    p.write_bytes(b"\x80\x04garbage")
    build.run_items(s, None, False, work, None)
    assert calls.count("t") == 5


def test_cache_key_covers_the_package_source(monkeypatch):
    from inerterlab import _provenance

    k = cache.cache_key({"quick": True})
    monkeypatch.setattr(_provenance, "source_hash", lambda: "something else")
    assert cache.cache_key({"quick": True}) != k


def test_symlinked_work_dir_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(build, "_load_chapters", lambda: _fake_chapters([]))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (tmp_path / "rep.work").symlink_to(elsewhere)
    with pytest.raises(ParameterError, match="symbolic link"):
        build.reproduce(tmp_path / "rep", settings=ReproduceSettings(quick=True))
    assert list(elsewhere.iterdir()) == []


# ---- --out: never remove what is not ours ---------------------------------------------


def test_out_into_a_foreign_folder_is_refused_and_nothing_removed(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(build, "_load_chapters", lambda: _fake_chapters([]))
    folder = tmp_path / "thesis"
    (folder / "data").mkdir(parents=True)
    (folder / "main.tex").write_text("\\documentclass{article}")
    (folder / "data" / "x.csv").write_text("1,2\n")
    rc = main(["reproduce", "--quick", "--tables", "9.1", "--out", str(folder)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "--out" in err and "nothing was written" in err
    assert (folder / "main.tex").read_text() == "\\documentclass{article}"
    assert (folder / "data" / "x.csv").read_text() == "1,2\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["thesis"]


def test_out_report_of_ours_is_replaced_but_not_with_extra_files(tmp_path, monkeypatch):
    monkeypatch.setattr(build, "_load_chapters", lambda: _fake_chapters([]))
    out = tmp_path / "rep"
    build.reproduce(out, settings=ReproduceSettings(quick=True), tables="9.1")
    assert (out / "tables" / "9.1.csv").is_file()
    build.reproduce(out, settings=ReproduceSettings(quick=True), tables="9.1")  # ours: ok
    (out / "notes.txt").write_text("mine")
    with pytest.raises(ParameterError, match="--out"):
        build.reproduce(out, settings=ReproduceSettings(quick=True), tables="9.1")
    assert (out / "notes.txt").read_text() == "mine"
    for bad, match in (("", "empty"), (str(out / "notes.txt"), "existing file")):
        with pytest.raises(ParameterError, match=match):
            build.reproduce(bad, settings=ReproduceSettings(quick=True), tables="9.1")


def test_empty_tables_selection_is_refused_not_the_whole_report(tmp_path, capsys):
    rc = main(["reproduce", "--quick", "--tables", "", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert rc == 2 and "--tables" in err and not (tmp_path / "r").exists()


def test_huge_table_range_is_refused_quickly():
    avail = [f"4.{i}" for i in range(1, 16)]
    with pytest.raises(ParameterError, match="4.16"):
        build.parse_table_selection("4.1-4.99999999", avail)


def test_stale_temporaries_are_cleaned_and_report_mode_follows_umask(tmp_path, monkeypatch):
    monkeypatch.setattr(build, "_load_chapters", lambda: _fake_chapters([]))
    out = tmp_path / "rep"
    (tmp_path / ".rep.new-abc123").mkdir()
    (tmp_path / ".rep.old-4242").mkdir()
    (tmp_path / ".other.new-abc").mkdir()  # not this report's: left alone
    old = os.umask(0o022)
    try:
        build.reproduce(out, settings=ReproduceSettings(quick=True), tables="9.1")
    finally:
        os.umask(old)
    assert sorted(p.name for p in tmp_path.iterdir()) == [".other.new-abc", "rep"]
    assert stat.S_IMODE(out.stat().st_mode) == 0o755


def test_a_second_writer_is_locked_out(tmp_path, monkeypatch):
    monkeypatch.setattr(build, "_load_chapters", lambda: _fake_chapters([]))
    out = tmp_path / "rep"
    work = cache.prepare_work_dir(tmp_path / "rep.work")
    with cache.report_lock(work, out):
        with pytest.raises(LockedError, match="another inerterlab reproduce"):
            build.reproduce(out, settings=ReproduceSettings(quick=True), tables="9.1")
    build.reproduce(out, settings=ReproduceSettings(quick=True), tables="9.1")
    assert not work.exists()


# ---- single-file outputs ---------------------------------------------------------------


def test_devices_fifos_links_and_stdout_are_written_into(tmp_path, capfd):
    atomic_write_text("/dev/null", "x")
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    reader = subprocess.Popen([sys.executable, "-c", f"print(open({str(fifo)!r}).read())"],
                              stdout=subprocess.PIPE, text=True)  # fmt: skip
    atomic_write_text(fifo, "through the pipe")
    assert reader.communicate(timeout=20)[0].strip() == "through the pipe"
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)

    target = tmp_path / "target.csv"
    target.write_text("old")
    os.chmod(target, 0o640)
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    atomic_write_text(link, "new")
    assert link.is_symlink() and target.read_text() == "new"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640  # mode of the replaced file kept

    atomic_write_text("-", "to stdout\n")
    assert capfd.readouterr().out == "to stdout\n"


def test_new_files_follow_the_umask(tmp_path):
    old = os.umask(0o027)
    try:
        atomic_write_text(tmp_path / "a.csv", "x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "a.csv").stat().st_mode) == 0o640


def test_cli_output_paths_that_cannot_be_written_are_user_errors(tmp_path, capsys):
    base = ["frequency-response", "--method", "shb", "--fmin", "1", "--fmax", "1.2", "--df", "0.1"]
    cases = [
        (["--csv", str(tmp_path)], "--csv"),
        (["--plot", str(tmp_path)], "--plot"),
        (["--plot", str(tmp_path / "f.xyz")], "--plot"),
        (["--csv", ""], "--csv"),
    ]
    for extra, name in cases:
        rc = main(base + ["--no-stability"] + extra)
        err = capsys.readouterr().err
        assert rc == 2, (extra, err)
        assert err.count("\n") == 1 and name in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_dev_stdout_redirected_to_a_file_keeps_everything(tmp_path):
    """``--csv /dev/stdout > file`` writes through the descriptor: the CSV and the table
    both end up in the file (reopening the path would truncate it)."""
    code = "import sys; from inerterlab.cli import main; sys.exit(main())"
    args = ["device-force", "--amplitude", "0.01", "--duration", "0.002", "--csv", "/dev/stdout"]
    out = tmp_path / "out.txt"
    with open(out, "w") as fh:
        r = subprocess.run([sys.executable, "-c", code, *args], stdout=fh, stderr=subprocess.PIPE,
                           text=True, timeout=120)  # fmt: skip
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert text.startswith("t,force,equivalent_mass\n") and "samples" in text


def test_a_reader_that_stops_early_is_not_an_error():
    code = "import sys; from inerterlab.cli import main; sys.exit(main())"
    args = [
        "device-force",
        "--amplitude",
        "0.01",
        "--duration",
        "5",
        "--csv",
        "-",
    ]  # > a pipe buffer
    p = subprocess.Popen([sys.executable, "-c", code, *args], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)  # fmt: skip
    p.stdout.read(10)
    p.stdout.close()
    err = p.stderr.read().decode()
    assert p.wait(120) == 0 and "Traceback" not in err, err


@pytest.mark.slow
def test_killed_table_run_resumes_from_the_json_cache_byte_for_byte(tmp_path):
    """``reproduce --quick --tables 4.1,6.1``: SIGKILL after the first finished item, rerun;
    the first item is reused and both tables equal an uninterrupted run's."""
    import signal
    import time

    code = "import sys; from inerterlab.cli import main; sys.exit(main())"
    sel = ["reproduce", "--quick", "--tables", "4.1,6.1"]
    ref = tmp_path / "ref"
    r = subprocess.run([sys.executable, "-c", code, *sel, "--out", str(ref)],
                       capture_output=True, text=True, timeout=900)  # fmt: skip
    assert r.returncode == 0, r.stderr
    out, work = tmp_path / "out", tmp_path / "out.work"
    cmd = [sys.executable, "-c", code, *sel, "--out", str(out)]
    # the interrupted run lingers in its second item, so the kill always lands there
    slow = (
        "import time\nfrom inerterlab.report import build\norig = build._load_chapters\n"
        "def patched():\n    t, f = orig()\n    g = t['6.1']\n"
        "    t['6.1'] = lambda s: (time.sleep(120), g(s))[1]\n    return t, f\n"
        "build._load_chapters = patched\n"
    )
    slow_cmd = [sys.executable, "-c", slow + code, *sel, "--out", str(out)]
    proc = subprocess.Popen(slow_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 600
    while time.monotonic() < deadline and not list(work.glob("table-*.json")):
        assert proc.poll() is None, "the run ended before it could be interrupted"
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert not out.exists()
    r = subprocess.run(cmd + ["--json"], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr
    manifest = json.loads(r.stdout)
    assert [i["reused"] for i in manifest["items"]] == [True, False]
    for name in ("4.1.csv", "6.1.csv"):
        assert (out / "tables" / name).read_bytes() == (ref / "tables" / name).read_bytes()
    assert not work.exists()


def test_a_new_file_in_a_missing_folder_is_refused_and_no_folder_made(tmp_path):
    for target, why in (
        (tmp_path / "no" / "such" / "x.csv", "does not exist"),
        (tmp_path / "plain.txt" / "x.csv", "usable file path"),  # a file as the folder
    ):
        (tmp_path / "plain.txt").write_text("keep")
        with pytest.raises(ParameterError, match=r"--csv.*" + why) as err:
            atomic_write_text(target, "x", option="--csv")
        assert str(target.parent.parent) in str(err.value) or why == "usable file path"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain.txt"]
    assert (tmp_path / "plain.txt").read_text() == "keep"
    # the package's own working files (not followed through links) get their folder
    from inerterlab.io import atomic_write_bytes

    atomic_write_bytes(tmp_path / "work" / "a.json", b"{}", follow_links=False)
    assert (tmp_path / "work" / "a.json").read_bytes() == b"{}"


def _leaf_commands():
    import typer

    from inerterlab.cli import app

    def walk(cmd, name):
        subs = getattr(cmd, "commands", None)
        if subs:
            for n, sub in subs.items():
                yield from walk(sub, f"{name} {n}".strip())
        else:
            yield name, cmd

    return list(walk(typer.main.get_command(app), ""))


def test_every_file_output_option_is_checked_as_the_command_line_is_read():
    checked = []
    for name, cmd in _leaf_commands():
        for p in cmd.params:
            if p.name in ("csv", "plot", "save", "output"):  # the options that name a file
                cb = p.callback  # (compared by name: another test may reload the CLI)
                assert (getattr(cb, "__module__", None), getattr(cb, "__qualname__", None)) == (
                    "inerterlab.cli._common",
                    "output_file",
                ), f"{name} --{p.name} is not checked as the command line is read"
                checked.append(f"{name} --{p.name}")
    assert len(checked) >= 17, checked  # every such option of today's commands


def test_a_mistyped_output_folder_is_refused_before_any_work(tmp_path, capsys, monkeypatch):
    import inerterlab.simulate as sim

    def no_work(*a, **k):
        raise AssertionError("the simulation ran before the output path was checked")

    monkeypatch.setattr(sim, "simulate", no_work)
    missing = tmp_path / "resluts" / "run.csv"
    for opt in ("--save", "--plot"):
        rc = main(["simulate", "--suspension", "afw", "--input", "bump", opt, str(missing)])
        err = capsys.readouterr().err
        assert rc == 2, err
        assert err.count("\n") == 1 and opt in err and "does not exist" in err, err
    rc = main(["vehicle", "generate", "--output", str(missing), "--length", "10"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "--output" in err, err
    assert sorted(tmp_path.iterdir()) == []
