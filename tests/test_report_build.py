"""Report assembly: table selection, atomic replacement, resume from finished items."""

import json

import numpy as np
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
            table_id="9.1", title="t", frame=pd.DataFrame({"a": [1.0]}), claim="c",
            claim_holds=True, judges="j",
        )  # fmt: skip

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
        {"kind": "table", "ok": True, "id": "4.7", "claim_holds": True, "reason": ""},
        {"kind": "table", "ok": True, "id": "4.2", "claim_holds": False,
         "reason": "the body velocity jumps"},
        {"kind": "table", "ok": False, "id": "4.3"},
    ]  # fmt: skip
    quick = _headline(recs, ReproduceSettings(quick=True))
    assert "Quick run" in quick and "1 of 2 thesis claims hold" in quick
    assert "claim holds: 4.7." in quick and "Wk-weighted" in quick
    full = _headline(recs[:1], ReproduceSettings(quick=False))
    assert "Quick run" not in full and "1 of 1" in full and "Wk-weighted" not in full


def test_every_numeric_column_of_every_table_has_a_unit():
    """Column units come from the name or the table's own map; a new table whose
    numeric column has neither fails here."""
    from inerterlab.report.build import column_unit

    # the column names each chapter writes, as in the full report's CSV files
    frames = {
        "4.2": ["body_mass_kg", "afw_ours", "afw_thesis", "afw_diff", "afw_plain_rms",
                "afw_smoothed_plain_rms"],
        "4.13": ["optimal_ratio_ours", "optimal_ratio_from_thesis_tables",
                 "rms_body_acc_wk_traditional", "rms_tyre_grip_diff", "rms_deflection_thesis"],
        "4.14": ["comfort_weight", "grip_weight", "optimal_ratio_diff"],
        "4.15": ["bump_weight", "sine_weight"],
        "7.1": ["amplitude_cm", "resonance_hz_ours", "max_amplitude_cm_diff",
                "resonance_hz_thesis_literal_law", "max_amplitude_cm_thesis_literal_law"],
        "7.3": ["nrmse_mhb_%_ours", "nrmse_other_hb_method_%_ours"],
        "3.A": ["diff_published_rel_%"],
        "5.A": ["diff_rel_%", "validation_nrmse_%"],
    }  # fmt: skip
    expect = {
        "body_mass_kg": "kg", "rms_body_acc_wk_traditional": "m/s^2", "rms_tyre_grip_diff": "-",
        "rms_deflection_thesis": "m", "amplitude_cm": "cm", "resonance_hz_ours": "Hz",
        "max_amplitude_cm_diff": "cm", "nrmse_mhb_%_ours": "%", "comfort_weight": "-",
    }  # fmt: skip
    units = {"4.2": dict.fromkeys(frames["4.2"][1:], "m/s^2")}
    for tid, cols in frames.items():
        for c in cols:
            u = column_unit(c, units.get(tid))
            assert u, (tid, c)
            if c in expect:
                assert u == expect[c], (c, u)
    assert column_unit("peak force [N]") is None  # the name carries it
    assert column_unit("flywheel") is None and column_unit("input") is None  # text


def test_html_tables_scroll_in_a_box_and_show_units():
    from inerterlab.report.build import _html_table

    frame = pd.DataFrame({"body_mass_kg": [340], "afw_ours": [0.5], "law": ["thesis"]})
    html = _html_table(frame, {"afw_ours": "m/s^2"})
    assert html.startswith("<div class='tablewrap'>") and html.endswith("</div>")
    assert "body_mass_kg [kg]" in html and "afw_ours [m/s^2]" in html
    assert "<th>law</th>" in html


def _recs_for_conclusion():
    t31 = pd.DataFrame({"law": ["thesis", "momentum"], "imbalance [% of work]": [-38.07, -0.0031]})
    t71 = pd.DataFrame({"resonance_hz_ours": [1.19, 1.15], "resonance_hz_thesis": [0.68, 0.35]})
    base = {"kind": "table", "ok": True, "title": "t", "claim": "c", "settings": {}}
    return [
        {**base, "id": "3.C", "frame": t31, "claim_holds": True, "reason": "r"},
        {**base, "id": "4.1", "frame": pd.DataFrame(), "claim_holds": True, "reason": "r"},
        {**base, "id": "4.2", "frame": pd.DataFrame(), "claim_holds": False,
         "reason": "AFW is not below CFW at 340 kg; more. And more."},
        {**base, "id": "7.1", "frame": t71, "claim_holds": True, "reason": "r"},
        {"kind": "figure", "id": "Fig. 7.9", "ok": True, "holds": False,
         "verdict": "it raises the resonance"},
        {"kind": "figure", "id": "Laws", "ok": True, "holds": None, "verdict": "v"},
    ]  # fmt: skip


def test_conclusion_is_computed_from_the_tables():
    from inerterlab.report.build import _conclusion, _findings

    recs = _recs_for_conclusion()
    found = _findings(recs)
    assert any("38.1 %" in f and "0.0031 %" in f for f in found), found
    assert any("1 of 2 claims hold" in f and "4.2 (AFW is not below CFW at 340 kg)" in f
               for f in found), found  # fmt: skip
    assert any("1.15-1.19 Hz" in f and "0.35-0.68 Hz" in f and "both fall" in f for f in found)
    page = _conclusion(recs)
    assert "3 of 5 thesis claims hold" in page and "tables 3 of 4, figures 0 of 1" in page
    assert "#f-Fig._7.9" in page and "Laws" not in page  # only the contradicted figure
    # change a number: the finding follows it
    recs[3]["frame"].loc[0, "resonance_hz_ours"] = 1.4
    assert any("1.15-1.4 Hz" in f for f in _findings(recs))


def test_figure_7_9_words_follow_its_data():
    """The caption of Fig. 7.9 says lowers or raises from the numbers it describes."""
    from inerterlab.report.ch7 import flywheel_effect

    f = np.linspace(0.1, 4.0, 391)

    def curve(f0, peak, sus, a):
        amp = (a / 100) * (1 + (peak - 1) * np.exp(-(((f - f0) / 0.2) ** 2)))
        return pd.DataFrame({"amplitude_cm": a, "suspension": sus, "freq_hz": f,
                             "amplitude_m": amp})  # fmt: skip

    rows = [curve(1.2, 1.24, "adaptive flywheel", a) for a in (1, 20)]
    rows += [curve(2.76, 1.50, "traditional", a) for a in (1, 20)]
    text, lowers = flywheel_effect(pd.concat(rows, ignore_index=True))
    assert lowers and "lowers the resonance from 2.76 Hz to 1.2 Hz" in text
    assert "lowers the peak X1/B from 1.5 to 1.24" in text and "raises" not in text
    rows = [curve(1.2, 1.8, "adaptive flywheel", a) for a in (1, 20)]
    rows += [curve(2.76, 1.50, "traditional", a) for a in (1, 20)]
    text, lowers = flywheel_effect(pd.concat(rows, ignore_index=True))
    assert lowers and "raises the peak X1/B from 1.5 to 1.8" in text


def test_harmonic_balance_gap_read_from_figure_data():
    from inerterlab.report.ch7 import _peak_gaps

    f = np.linspace(0.5, 2.0, 16)
    br = 0.01 + 0.01 * np.exp(-((f - 1.2) ** 2))
    rows = []
    for a, err in ((1, 0.0), (5, 0.002)):
        rows.append(pd.DataFrame({"amplitude_cm": a, "method": "brute", "freq_hz": f,
                                  "amplitude_m": br, "converged": True}))  # fmt: skip
        hb = br.copy()
        hb[5] += err
        rows.append(pd.DataFrame({"amplitude_cm": a, "method": "shb", "freq_hz": f[::-1],
                                  "amplitude_m": hb[::-1], "converged": True}))  # fmt: skip
    gaps = _peak_gaps(pd.concat(rows, ignore_index=True), "shb")
    assert gaps[1] == 0.0
    assert gaps[5] == pytest.approx(100 * 0.002 / br.max(), rel=1e-12)


def test_printed_digits_rule():
    from inerterlab.report.ch3 import _agrees_to_print

    assert _agrees_to_print(11.668, 11.67) and not _agrees_to_print(11.664, 11.67)
    assert _agrees_to_print(28.503, 28.5) and not _agrees_to_print(28.56, 28.5)
    assert _agrees_to_print(882.14, 882.1) and not _agrees_to_print(882.16, 882.1)
    assert _agrees_to_print(0.000954 + 4e-7, 0.000954)
