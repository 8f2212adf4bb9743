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
    assert all("1/3 done" in ln and re.search(r"about \d+ s left", ln) for ln in running)
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


def test_estimate_from_computed_items():
    p = RunProgress(10, label="x", stream=io.StringIO())
    assert p.eta() is None
    p.start("a")
    p.done("a")
    p.t0 -= 2.0  # the item took 2 s
    assert 17.9 < p.eta() <= 18.1  # 9 items left at 2 s each
    p.done("b (reused)")  # reused items do not count as work done
    assert 15.9 < p.eta() <= 16.2


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
