"""Progress of the reproduction: the running item is named, the time left estimated;
without a terminal, plain periodic lines on standard error."""

import io
import re
import subprocess
import sys
import time
import warnings

from inerterlab.cli._progress import RunProgress


def test_plain_lines_name_the_running_item_and_the_time_left():
    buf = io.StringIO()
    with RunProgress(3, label="reproduce", stream=buf, interval=0.05) as p:
        p.start("table 4.1")
        time.sleep(0.02)
        p.done("table 4.1")
        p.start("table 5.A")
        time.sleep(0.3)
        p.done("table 5.A")
        p.done("figure 7.9 (reused)")
    lines = buf.getvalue().splitlines()
    assert lines[0] == "reproduce: 3 items"
    running = [ln for ln in lines if "running table 5.A" in ln]
    assert running, lines
    assert all("1/3 done" in ln and "time left" in ln for ln in running)
    assert not any("running table 4.1" in ln and "1/3" in ln for ln in lines)
    assert re.fullmatch(r"reproduce: 3/3 done in \d+ s", lines[-1])
    assert "\x1b" not in buf.getvalue()  # no terminal control codes in a log


def test_live_bar_describes_the_running_item():
    buf = io.StringIO()
    with RunProgress(2, label="reproduce", stream=buf, live=True) as p:
        p.start("table 7.1")
        assert p._bar.tasks[0].description == "running table 7.1"
        p.done("table 7.1")
        assert p._bar.tasks[0].completed == 1


class FakeClock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def test_time_left_from_measured_costs_and_the_observed_speed():
    from inerterlab.report.timeleft import TimeLeft

    clock = FakeClock()
    est = TimeLeft({"a": 10.0, "b": 10.0, "c": 20.0}, clock=clock)
    assert est.estimate() == (None, "no tasks planned yet")
    est.plan([], workers=1)
    assert est.estimate() == (0.0, "nothing to compute, every item reused")
    est.plan(["a", "b", "c"], workers=1)
    # nothing finished: the reference costs, said so, less what the running task did
    est.begin("a")
    clock.t = 4.0
    left, how = est.estimate()
    assert left == 36.0 and "reference costs, none finished" in how
    clock.t = 15.0  # a overran its 10 s: this machine is at least 1.5 times slower
    assert est.estimate()[0] == 0.0 + 15.0 + 30.0
    # a finished at twice its cost: this machine is twice as slow, the rest scales
    clock.t = 20.0
    est.end("a")
    left, how = est.estimate()
    assert left == 60.0 and "this run's speed" in how
    est.begin("b")
    clock.t = 30.0
    assert est.estimate()[0] == 50.0  # b: 20 expected, 10 done; c: 40
    clock.t = 45.0  # b overran its estimate: counted as done soon, never negative
    assert est.estimate()[0] == 40.0


def test_time_left_shares_the_work_among_workers_and_waits_for_the_longest():
    from inerterlab.report.timeleft import TimeLeft

    clock = FakeClock()
    est = TimeLeft({"p": 100.0, "q": 10.0, "r": 10.0}, clock=clock)
    est.plan(["p", "q", "r"], workers=2)
    est.begin("p")
    est.begin("q")
    clock.t = 10.0
    est.end("q")  # speed 1
    left, _ = est.estimate()
    assert left == 90.0  # (90 + 10) / 2 = 50, but p alone still needs 90


def test_time_left_says_when_it_cannot_estimate():
    from inerterlab.report.timeleft import TimeLeft

    est = TimeLeft({}, clock=FakeClock())
    est.plan(["x"], 1)
    assert est.estimate() == (None, "no measured cost for these tasks yet")
    p = RunProgress(1, label="r", stream=io.StringIO(), estimator=est)
    assert p.left_text() == "time left unknown (no measured cost for these tasks yet)"
    # a task not in the table gets the median of the known ones
    est = TimeLeft({"a": 1.0, "b": 3.0, "c": 5.0}, clock=FakeClock())
    est.plan(["a", "new"], 1)
    assert est.estimate()[0] == 1.0 + 3.0


def test_costs_come_from_the_previous_run_at_the_same_out(tmp_path):
    import json

    from inerterlab.report.timeleft import known_costs

    out = tmp_path / "rep"
    out.mkdir()
    (out / "manifest.json").write_text(json.dumps(
        {"settings": {"quick": True}, "task_mode": "parallel", "task_seconds": {"k": 2.5}}
    ))  # fmt: skip
    assert known_costs(out, True, True) == ({"k": 2.5}, "the previous run at this --out")
    costs, source = known_costs(out, True, False)  # another mode: the shipped table
    assert source in ("the shipped cost table", "no measured costs")
    assert known_costs(tmp_path / "none", False, True)[1] in (
        "the shipped cost table", "no measured costs")


def test_cli_progress_on_stderr_when_not_a_terminal(tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "inerterlab", "reproduce", "--quick", "--tables", "4.1",
         "--progress-interval", "0.2", "--out", str(tmp_path / "rep")],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    err = r.stderr.splitlines()
    assert err[0] == "reproduce: 1 item" and err[-1].startswith("reproduce: 1/1 done in ")
    assert "\x1b" not in r.stderr
    assert "report written to" in r.stdout


def test_report_settings_do_not_alias():
    from inerterlab.report.ch7 import figure_convergence
    from inerterlab.report.registry import ReproduceSettings

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        res = figure_convergence(ReproduceSettings(quick=True))
    n = res.data[res.data.study == "samples"].n_samples
    assert n.min() >= 4 * 15 + 1
