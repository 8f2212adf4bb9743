"""The chapter-7 report module runs in quick mode and states its claims."""

import math

from inerterlab.report.ch7 import FIGURES, TABLES, thesis_values
from inerterlab.report.registry import ReproduceSettings

QUICK = ReproduceSettings(quick=True)


def test_thesis_values_transcribed():
    df = thesis_values()
    assert len(df) == 12 + 6 + 7 + 7
    assert set(df.table.astype(str)) == {"7.1", "7.2", "7.3", "7.4"}


def test_tables_quick():
    for key, fn in TABLES.items():
        t = fn(QUICK)
        assert t.table_id == key
        assert t.claim and t.reason and t.settings["quick"]
        assert t.claim_holds in (True, False)
        numbers = t.frame.select_dtypes("number").to_numpy().ravel()
        assert all(math.isfinite(x) for x in numbers if x is not None)
    t1 = TABLES["7.1"](QUICK).frame
    # the resonance falls with the input amplitude in our physics too
    assert (t1.resonance_hz_ours.diff().dropna() < 0).all()


def test_figures_quick():
    for key, fn in FIGURES.items():
        f = fn(QUICK)
        assert f.figure_id == key and len(f.data) > 0
