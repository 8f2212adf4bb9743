"""The report's verdicts, counts, labels and figures say what they are (issue: numbers a
user can trust, part three): each verdict names what it judges, a magnitude
disagreement is flagged beside it, the claim count is one number, the ride figures put
one quantity on one axis."""

from __future__ import annotations

import pandas as pd
import pytest

from inerterlab.report import build
from inerterlab.report.registry import FigureResult, ReproduceSettings, TableResult


def test_a_verdict_without_what_it_judges_is_refused():
    with pytest.raises(ValueError, match="judges"):
        TableResult(table_id="9.1", title="t", frame=pd.DataFrame(), claim_holds=True)
    with pytest.raises(ValueError, match="judges"):
        FigureResult(figure_id="F", title="t", figure=None, data=None, holds=False)
    TableResult(table_id="9.1", title="t", frame=pd.DataFrame(), claim_holds=None)


def test_magnitude_check_flags_values_five_times_the_thesis():
    """Table 4.3 held on the ordering while ours were about 5x the thesis's."""
    frame = pd.DataFrame(
        {"body_mass_kg": [340, 400], "afw_ours": [10.43, 9.0], "afw_thesis": [1.98, 1.8],
         "afw_diff": [8.45, 7.2], "cfw_ours": [None, 2.0], "cfw_thesis": [1.0, 0.0]}
    )  # fmt: skip
    ok, text = build.magnitude_check(frame, 0.10)
    assert ok is False
    assert "5-5.27 times the thesis's" in text and "2 values" in text and "±10 %" in text
    ok, text = build.magnitude_check(frame.assign(afw_ours=[2.0, 1.85], cfw_ours=[1.05, 2]), 0.1)
    assert ok is True and "within 5 %" in text
    assert build.magnitude_check(pd.DataFrame({"a_ours": [1.0]}), 0.1)[0] is None
    # explicit pairs: like with like where the name-matched column is another quantity
    frame = pd.DataFrame({"x_ours": [5.0], "x_plain": [1.0], "x_thesis": [1.02]})
    assert build.magnitude_check(frame, 0.1, {"x_plain": "x_thesis"})[0] is True
    # the pairs found by name
    cols = ["q_ours", "q_thesis", "ours", "thesis", "m ours [kg]", "m thesis [kg]", "r_ours"]
    assert build._magnitude_pairs(cols) == {
        "q_ours": "q_thesis", "ours": "thesis", "m ours [kg]": "m thesis [kg]"
    }  # fmt: skip


def _table_record(**kw):
    frame = pd.DataFrame({"body_mass_kg": [340], "afw_ours": [10.43], "afw_thesis": [1.98]})
    rec = build.compute_item(
        "table",
        "4.3",
        lambda s: TableResult(
            table_id="4.3", title="t", frame=frame, claim="AFW worst", claim_holds=True,
            judges="the ordering of the suspensions at every mass, not the values", **kw,
        ),
        ReproduceSettings(quick=True),
    )  # fmt: skip
    assert rec["ok"], rec.get("error")
    return rec


def test_the_page_says_what_a_verdict_judges_and_flags_the_magnitude():
    rec = _table_record()
    assert rec["magnitude_agrees"] is False
    page = build.render([rec], ReproduceSettings(), 1.0, "")["index.html"].decode()
    summary = page.split("id='summary'")[1].split("</table>")[0]
    assert "holds" in summary and "judged: the ordering of the suspensions" in summary
    assert "magnitude differs" in summary and "5.27 times the thesis" in summary
    table = page.split("id='t-4.3'")[1]
    assert "Magnitude against the thesis:" in table and "magnitude differs" in table
    manifest = build.render([rec], ReproduceSettings(), 1.0, "")["manifest.json"].decode()
    assert '"magnitude_agrees": false' in manifest


def test_one_claim_count_at_the_top_and_in_the_conclusion():
    recs = [
        _table_record(),
        {"kind": "figure", "id": "F", "ok": True, "holds": False, "verdict": "v",
         "judges": "j", "title": "t", "caption": "c", "png": b"", "data": pd.DataFrame()},
    ]  # fmt: skip
    page = build.render(recs, ReproduceSettings(), 1.0, "")["index.html"].decode()
    sentence = build.claim_count(recs)
    assert sentence.startswith("1 of 2 thesis claims hold")
    assert page.count(sentence) == 2  # the headline and the conclusion, the same words
    assert "table claims and" not in page


def test_an_errata_paragraph_wrapped_over_lines_stays_one_paragraph():
    text = "# Errata\n\nEquation numbers are the thesis. Each entry says\nwhat we do.\n\n- a\n"
    out = build._markdown_to_html(text)
    assert "<p>Equation numbers are the thesis. Each entry says what we do.</p>" in out
    assert out.count("<p>") == 1 and "<li>a</li>" in out


def test_the_settings_list_the_version_and_the_commit(tmp_path):
    import re

    v = build._versions()
    assert v["inerterlab"] and "inerterlab git commit (HEAD)" in v
    # a checkout: HEAD on a branch, the branch in packed-refs
    pkg = tmp_path / "repo" / "src" / "inerterlab"
    pkg.mkdir(parents=True)
    git = tmp_path / "repo" / ".git"
    git.mkdir()
    (git / "HEAD").write_text("ref: refs/heads/main\n")
    sha = "0123456789abcdef0123456789abcdef01234567"
    (git / "packed-refs").write_text(f"# pack-refs\n{sha} refs/heads/main\n")
    assert build.source_revision(pkg) == sha
    # a loose ref wins; a detached HEAD is the commit itself
    (git / "refs" / "heads").mkdir(parents=True)
    (git / "refs" / "heads" / "main").write_text("f" * 40 + "\n")
    assert build.source_revision(pkg) == "f" * 40
    (git / "HEAD").write_text("a" * 40)
    assert build.source_revision(pkg) == "a" * 40
    # not a checkout (an installed copy), or a broken one: said so, never an error
    assert build.source_revision(tmp_path / "site" / "inerterlab") == "not a git checkout"
    (git / "HEAD").write_text("ref: refs/heads/gone\n")
    assert build.source_revision(pkg).startswith("unknown")
    assert re.fullmatch(r"[0-9a-f]{40}|not a git checkout|unknown.*", v["inerterlab git commit (HEAD)"])


def test_table_headers_carry_units_not_placeholders():
    """Where the unit changes from row to row it is a column, not "[of quantity]"."""
    from inerterlab.report import ch3

    t = ch3.table_check_values(ReproduceSettings(quick=True))
    assert "unit" in t.frame.columns and set(t.frame.unit) >= {"kg m^2", "%", "rad/s"}
    head = build._html_table(t.frame, t.units)
    assert "[of " not in head and "<th>thesis</th>" in head
    assert t.judges and t.magnitude_pairs == {"ours_published_law": "thesis"}


@pytest.mark.parametrize(
    ("margin", "words"),
    [(-0.42, "never beats"), (0.2, "adds at most 0.20 points"), (0.8, "adds up to 0.80")],
)
def test_adaptivity_verdict_is_worded_for_the_sign(margin, words):
    from inerterlab.report.layouts import adaptivity_verdict

    text = adaptivity_verdict(margin)
    assert words in text and "-0." not in text and "+" not in text
    if margin < 0:
        assert "0.42 points of comfort behind" in text


def test_ride_figure_keeps_one_quantity_per_axis_and_the_common_size():
    """Fig. 4.5 (bump): the thesis's plain RMS beside ours of the same quantity, the
    Wk-weighted values on their own panel; short labels with units; same size as 4.4;
    the caption names every marker."""
    from PIL import Image

    from inerterlab.report import ch4_6

    st = ReproduceSettings(quick=True)
    sizes = {}
    for fid in ("Fig. 4.4", "Fig. 4.5"):
        r = ch4_6.FIGURES[fid](st)
        axes = r.figure.axes
        for ax in axes:
            label = ax.get_ylabel()
            assert len(label) <= 40 and label.endswith("]"), label
        sizes[fid] = Image.open(__import__("io").BytesIO(build._fig_png(r.figure))).size
        if fid == "Fig. 4.5":
            left, right = axes
            texts = lambda ax: " ".join(ln.get_label() for ln in ax.get_lines())  # noqa: E731
            assert "thesis" in texts(left) and "Wk" not in texts(left)
            assert "Wk" in texts(right) and "thesis" not in texts(right)
            for marker in ("crosses", "triangles", "circles"):
                assert marker in r.caption
    (w4, h4), (w5, h5) = sizes["Fig. 4.4"], sizes["Fig. 4.5"]
    assert abs(w4 - w5) <= 10 and abs(h4 - h5) <= 10, sizes


@pytest.mark.slow
def test_ratio_figure_bump_panel_compares_plain_with_plain():
    from inerterlab.report import studies

    r = studies.FIGURES["Fig. 4.13-4.21"](ReproduceSettings(quick=True))
    ax = r.figure.axes[3]  # bump, body acceleration
    twin = [a for a in r.figure.axes if a is not ax and a.bbox.bounds == ax.bbox.bounds]
    assert len(twin) == 1
    left = [ln.get_label() for ln in ax.get_lines()]
    assert "thesis" in left and any("edges" in x for x in left)
    assert not any("Wk" in x for x in left)
    assert any("Wk" in ln.get_label() for ln in twin[0].get_lines())
    assert "rms_body_acc_smoothed_edges" in set(r.data.metric)
    assert "triangles" in r.caption and "right axis" in r.caption
