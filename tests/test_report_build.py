"""Report assembly: table selection, atomic replacement, resume from finished items."""

import json

import pandas as pd
import pytest

from inerterlab import ParameterError
from inerterlab.report import build
from inerterlab.report.registry import ReproduceSettings, TableResult


def test_parse_selection():
    avail = [f"4.{i}" for i in range(1, 16)] + ["6.1", "7.1", "7.2"]
    assert build.parse_table_selection("4.1-4.3,7.2", avail) == ["4.1", "4.2", "4.3", "7.2"]
    assert build.parse_table_selection("4.10-4.12", avail) == ["4.10", "4.11", "4.12"]
    for bad in ["4.3-4.1", "4.1-6.1", "9.9", ",", "4.1-4.99"]:
        with pytest.raises(ParameterError, match="--tables"):
            build.parse_table_selection(bad, avail)


def _fake_chapters(calls):
    def table(settings):
        calls.append("t")
        return TableResult(
            table_id="9.1", title="t", frame=pd.DataFrame({"a": [1.0]}), claim="c", claim_holds=True
        )

    def broken(settings):
        calls.append("b")
        raise ValueError("boom")

    return {"9.1": table, "9.2": broken}, {}


def test_resume_reuses_finished_items_and_records_failures(tmp_path, monkeypatch):
    calls = []
    monkeypatch.setattr(build, "_load_chapters", lambda: _fake_chapters(calls))
    work = tmp_path / "w"
    recs = build.run_items(ReproduceSettings(quick=True), None, False, work, None)
    assert [r["ok"] for r in recs] == [True, False]
    assert "boom" in recs[1]["error"]
    assert calls == ["t", "b"]
    # rerun: the finished table is reused, only the failed one is retried
    recs2 = build.run_items(ReproduceSettings(quick=True), None, False, work, None)
    assert calls == ["t", "b", "b"]
    assert recs2[0]["frame"].equals(recs[0]["frame"])
    # a different setting does not reuse the cache
    build.run_items(ReproduceSettings(quick=False), None, False, work, None)
    assert calls.count("t") == 2
    files = list(work.glob("*.json"))
    assert files and all(json.loads(p.read_text())["record"]["ok"] for p in files)


def test_atomic_replace_keeps_old_report_on_failure(tmp_path, monkeypatch):
    out = tmp_path / "rep"
    build.write_report_atomically(out, {"index.html": b"old"})
    assert (out / "index.html").read_bytes() == b"old"

    class Boom(Exception):
        pass

    def bad_sync(fd):  # the disk fails while the new report is being written
        raise Boom()

    monkeypatch.setattr("os.fsync", bad_sync)
    with pytest.raises(Boom):
        build.write_report_atomically(out, {"index.html": b"new"})
    monkeypatch.undo()
    assert (out / "index.html").read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["rep"]


def test_render_marks_failures_without_numbers():
    recs = [
        {
            "kind": "table",
            "id": "9.1",
            "ok": True,
            "title": "x",
            "frame": pd.DataFrame({"v": [1.5]}),
            "claim": "c",
            "claim_holds": False,
            "reason": "because",
            "settings": {"h": 1},
            "seconds": 0.1,
        },
        {"kind": "table", "id": "9.2", "ok": False, "error": "ValueError: boom", "seconds": 0.0},
    ]
    files = build.render(recs, ReproduceSettings(), 1.0, "# Errata\n- item")
    page = files["index.html"].decode()
    assert "does not hold" in page and "failed: ValueError: boom" in page
    assert "tables/9.1.csv" in files and "tables/9.2.csv" not in files
    assert files["tables/9.1.csv"].decode().startswith("# table: 9.1")


def test_headline_counts_the_claims_and_marks_a_quick_run():
    from inerterlab.report.build import _headline
    from inerterlab.report.registry import ReproduceSettings

    recs = [
        {"ok": True, "id": "4.7", "claim_holds": True, "reason": ""},
        {"ok": True, "id": "4.2", "claim_holds": False, "reason": "the body velocity jumps"},
        {"ok": False, "id": "4.3"},
    ]
    quick = _headline(recs, ReproduceSettings(quick=True))
    assert "Quick run" in quick and "1 of 2 thesis claims hold" in quick
    assert "(tables 4.7)" in quick and "Wk-weighted" in quick
    full = _headline(recs[:1], ReproduceSettings(quick=False))
    assert "Quick run" not in full and "1 of 1" in full and "Wk-weighted" not in full
