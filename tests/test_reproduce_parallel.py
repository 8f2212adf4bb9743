"""A parallel reproduction gives exactly the numbers of a serial one."""

import importlib

import pandas as pd

from inerterlab.report._memo import Memo
from inerterlab.report.build import run_items
from inerterlab.report.registry import ReproduceSettings

CHAPTERS = ("ch3", "ch4_6", "ch5", "ch7", "studies")


def _clear_memos():
    for name in CHAPTERS:
        mod = importlib.import_module(f"inerterlab.report.{name}")
        for value in vars(mod).values():
            if isinstance(value, Memo):
                value.cache_clear()


def test_memo_keys_fill_defaults():
    calls = []

    def f(a, b=2):
        calls.append((a, b))
        return a + b

    m = Memo(f)
    assert m(1) == m(1, 2) == m(a=1, b=2) == 3 and calls == [(1, 2)]
    m.put((5, 2), 99)
    assert m(5) == 99 and len(calls) == 1


def test_parallel_equals_serial(tmp_path):
    ids = ["3.A", "3.B", "4.1", "7.3"]  # chapter-3 items whole, pieces of ch4_6 and ch7
    started, finished = [], []
    _clear_memos()
    par = run_items(
        ReproduceSettings(quick=True, workers=2), ids, False, tmp_path / "p",
        progress=finished.append, on_start=started.append,
    )  # fmt: skip
    _clear_memos()
    ser = run_items(ReproduceSettings(quick=True, workers=1), ids, False, tmp_path / "s")
    assert [r["id"] for r in par] == [r["id"] for r in ser] == ids
    for p, s in zip(par, ser, strict=True):
        assert p["ok"] and s["ok"], (p.get("error"), s.get("error"))
        pd.testing.assert_frame_equal(p["frame"], s["frame"], check_exact=True)
        assert p["claim_holds"] == s["claim_holds"] and p["reason"] == s["reason"]
    assert sorted(finished) == sorted(f"table {i}" for i in ids)
    assert any("processes" in s for s in started)


def test_few_items_run_in_this_process(tmp_path):
    started = []
    recs = run_items(
        ReproduceSettings(quick=True, workers=2), ["3.A"], False, tmp_path, on_start=started.append
    )
    assert recs[0]["ok"] and started == ["table 3.A"]  # no worker processes for one item


def test_a_cold_cache_keeps_two_workers_off_one_compile_family():
    """While a task of a family compiles (a cold numba cache), the next worker takes
    the best task of another family; with none ready, the best task of any."""
    from inerterlab.report.parallel import COMPILE_FAMILY, family, pick

    assert family("inerterlab.report.ch5") == family("inerterlab.report.ch4_6") == "core"
    assert family("inerterlab.report.ch7") == "inerterlab.report.ch7"

    def task(order, module, cost):
        return [cost, order, f"t{order}", None, (), ("items", module), set()]

    ch5 = task(0, "inerterlab.report.ch5", 9.0)
    ch4 = task(1, "inerterlab.report.ch4_6", 8.0)
    ch7 = task(2, "inerterlab.report.ch7", 2.0)
    rank = lambda t: t[0]  # noqa: E731
    assert pick([ch5, ch4, ch7], rank, set()) is ch5  # warm: the costliest
    assert pick([ch4, ch7], rank, {"core"}) is ch7  # cold, core compiling: another family
    assert pick([ch4], rank, {"core"}) is ch4  # nothing else ready: it runs anyway
    assert pick([ch4, ch7], rank, {"inerterlab.report.ch7"}) is ch4
    assert set(COMPILE_FAMILY.values()) == {"core"}
