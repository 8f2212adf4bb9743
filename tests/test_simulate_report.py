"""Report module of chapters 4 and 6: tables beside the thesis, in quick mode."""

import pytest

from inerterlab.report.ch4_6 import FIGURES, TABLES, thesis_values
from inerterlab.report.registry import ReproduceSettings


def test_thesis_transcription_is_complete():
    df = thesis_values()
    assert len(df) == 18 * 7 * 3
    assert (
        df[(df.table == "4.1") & (df.body_mass_kg == 340) & (df.suspension == "afw")].value.item()
        == 0.3098
    )


@pytest.mark.parametrize("tid", ["4.1", "4.9", "6.3", "6.8"])
def test_tables_quick(tid):
    t = TABLES[tid](ReproduceSettings(quick=True))
    assert t.table_id == tid and len(t.frame) == 3
    assert {"traditional_ours", "traditional_thesis", "traditional_diff"} <= set(t.frame.columns)
    assert isinstance(t.claim_holds, bool) and t.reason
    assert t.settings["horizon_s"] == 2.0 and "inertia_law" in t.settings
    assert set(TABLES) == {f"{c}.{i}" for c in "46" for i in range(1, 10)}


def test_figures_quick():
    f = FIGURES["Fig. 4.4"](ReproduceSettings(quick=True))
    assert f.figure is not None and len(f.data) == 3
