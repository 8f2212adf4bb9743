"""End to end: ``inerterlab reproduce --quick`` and the report in a real browser."""

import json
import os
import shutil
from pathlib import Path

import pytest

from inerterlab.cli import main


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("rep") / "reproduction"
    rc = main(["reproduce", "--quick", "--out", str(out)])
    manifest = json.loads((out / "manifest.json").read_text())
    return rc, out, manifest


def test_quick_reproduction_completes(quick_report):
    rc, out, manifest = quick_report
    failed = [i for i in manifest["items"] if not i["ok"]]
    assert failed == [], failed
    assert rc == 0
    tables = [i for i in manifest["items"] if i["kind"] == "table"]
    # every table id of docs/model.md §8 is present
    ids = {i["id"] for i in tables}
    expected = (
        {f"4.{i}" for i in range(1, 16)}
        | {f"6.{i}" for i in range(1, 16)}
        | {f"7.{i}" for i in range(1, 5)}
    )
    assert expected <= ids, sorted(expected - ids)
    for i in tables:
        assert (out / "tables" / f"{i['id']}.csv").is_file()
    assert not (out.parent / "reproduction.work").exists()


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


_CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def test_report_renders_in_headless_chromium(quick_report, tmp_path):
    _, out, manifest = quick_report
    exe = _chromium()
    if exe is None:
        msg = "chromium is not installed (Debian package 'chromium'; .ci/run installs it)"
        if os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    sync_api = pytest.importorskip("playwright.sync_api")
    errors = []
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=_CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": 1280, "height": 900})
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto((out / "index.html").as_uri())
        page.wait_for_load_state("load")
        n_images = page.evaluate("document.images.length")
        broken = page.evaluate(
            "Array.from(document.images).filter(i => !(i.complete && i.naturalWidth > 0)).length"
        )
        headings = page.evaluate(
            "Array.from(document.querySelectorAll('h3')).map(h => h.textContent)"
        )
        shot = Path(os.environ.get("INERTERLAB_SCREENSHOT", tmp_path / "report.png"))
        page.screenshot(path=str(shot), full_page=False)
        browser.close()
    assert errors == []
    n_fig = sum(1 for i in manifest["items"] if i["kind"] == "figure" and i["ok"])
    assert n_images == n_fig > 0
    assert broken == 0
    for i in manifest["items"]:
        if i["kind"] == "table":
            assert f"Table {i['id']}" in headings
    assert shot.stat().st_size > 10_000


#: narrowest an <img> of the report may be drawn in a 1280 px wide window [CSS px]: a
#: panel of a three-column figure is then about 100 px, the least that keeps axis labels
#: legible, and a single-panel figure is shown at least at this width
MIN_IMAGE_PX = 300

# elements wider than the window are allowed only inside a box that scrolls sideways
_LAYOUT_JS = """() => {
  const vw = document.documentElement.clientWidth;
  const out = {vw: vw, page: document.documentElement.scrollWidth, escaping: [],
               images: [], tables: 0, wrapped: 0, scrolling: 0};
  const scroller = (el) => {
    for (let p = el.parentElement; p; p = p.parentElement) {
      const o = getComputedStyle(p).overflowX;
      if (o === 'auto' || o === 'scroll') return p;
    }
    return null;
  };
  for (const el of document.body.querySelectorAll('*')) {
    const r = el.getBoundingClientRect();
    if (r.width === 0 && r.height === 0) continue;
    if (r.right > vw + 0.5 || r.left < -0.5) {
      const box = scroller(el);
      if (!box || box.getBoundingClientRect().right > vw + 0.5)
        out.escaping.push(el.tagName + ' ' + Math.round(r.left) + '..' + Math.round(r.right));
    }
  }
  for (const img of document.images)
    out.images.push([img.alt, img.getBoundingClientRect().width]);
  for (const t of document.querySelectorAll('table')) {
    out.tables += 1;
    const w = t.parentElement;
    if (w.classList.contains('tablewrap')) {
      out.wrapped += 1;
      if (w.scrollWidth > w.clientWidth + 1) out.scrolling += 1;
    }
  }
  return out;
}"""


def test_report_layout_in_headless_chromium(quick_report):
    """No page-wide horizontal overflow (wide tables scroll in their own box) and every
    figure drawn at a readable width, in a desktop window and a narrow one; every figure
    has its verdict and the report its conclusion."""
    _, out, manifest = quick_report
    exe = _chromium()
    if exe is None:
        msg = "chromium is not installed (Debian package 'chromium'; .ci/run installs it)"
        if os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    sync_api = pytest.importorskip("playwright.sync_api")
    seen = {}
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=_CHROMIUM_ARGS)
        for width in (1280, 800):
            page = browser.new_page(viewport={"width": width, "height": 900})
            page.goto((out / "index.html").as_uri())
            page.wait_for_load_state("load")
            seen[width] = page.evaluate(_LAYOUT_JS)
            if width == 1280:
                verdicts = page.evaluate(
                    "Array.from(document.querySelectorAll('figure')).filter("
                    "f => f.previousElementSibling && "
                    "f.previousElementSibling.classList.contains('claim')).length"
                )
                conclusion = page.evaluate(
                    "document.getElementById('conclusion') ? "
                    "document.getElementById('conclusion').nextElementSibling.textContent : ''"
                )
            page.close()
        browser.close()
    n_fig = sum(1 for i in manifest["items"] if i["kind"] == "figure" and i["ok"])
    for width, s in seen.items():
        assert s["page"] <= s["vw"], (width, s["page"], s["escaping"][:5])
        assert s["escaping"] == [], (width, s["escaping"][:5])
        assert s["tables"] > 0 and s["wrapped"] == s["tables"], (width, s)
        assert len(s["images"]) == n_fig
        small = [(alt, w) for alt, w in s["images"] if w < MIN_IMAGE_PX]
        assert small == [], (width, small)
    # at 800 px the widest tables do not fit: they scroll inside their box instead
    assert seen[800]["scrolling"] > 0
    assert verdicts == n_fig
    assert "thesis claims hold" in conclusion and "figures" in conclusion


def _children(pid: int) -> list[int]:
    """Process ids whose parent is ``pid`` (Linux /proc)."""
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(d.name))
    return out


def _alive(pid: int) -> bool:
    """True while ``pid`` exists and is not a zombie."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


@pytest.mark.slow
def test_killed_reproduce_resumes_to_identical_results(quick_report, tmp_path):
    """SIGKILL part way, rerun: finished items are reused and the report equals an
    uninterrupted run's (tables and figure data byte for byte)."""
    import signal
    import subprocess
    import sys
    import time

    _, ref, _ = quick_report
    out = tmp_path / "reproduction"
    work = tmp_path / "reproduction.work"
    cmd = [sys.executable, "-m", "inerterlab", "reproduce", "--quick", "--out", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and len(list(work.glob("*.json"))) < 4:
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before it could be interrupted"
    workers = _children(proc.pid)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    # the worker processes of the parallel run end with it (nothing left computing)
    t_end = time.monotonic() + 20
    while time.monotonic() < t_end and any(_alive(w) for w in workers):
        time.sleep(0.1)
    assert not [w for w in workers if _alive(w)], "worker processes outlived the killed run"
    done_before = {p.name for p in work.glob("*.json")}
    assert len(done_before) >= 4
    assert not out.exists()  # no half-written report
    mtimes = {p.name: p.stat().st_mtime_ns for p in work.glob("*.json")}

    r = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-2000:]
    # the items finished before the kill were not recomputed
    assert not work.exists()
    manifest = json.loads((out / "manifest.json").read_text())
    assert all(i["ok"] for i in manifest["items"])
    reused = [i for i in manifest["items"] if i["reused"]]
    assert len(reused) == len(done_before) == len(mtimes)
    for sub in ("tables", "data"):
        names = sorted(p.name for p in (ref / sub).iterdir())
        assert names == sorted(p.name for p in (out / sub).iterdir())
        for n in names:
            assert (out / sub / n).read_bytes() == (ref / sub / n).read_bytes(), (
                f"{sub}/{n} differs"
            )


@pytest.mark.slow
def test_ctrl_c_keeps_finished_items_and_says_so(tmp_path):
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "reproduction"
    work = tmp_path / "reproduction.work"
    cmd = [sys.executable, "-m", "inerterlab", "reproduce", "--quick", "--out", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and len(list(work.glob("*.json"))) < 2:
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before it could be interrupted"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err[-2000:]
    assert "interrupted" in err and "Traceback" not in err
    assert len(list(work.glob("*.json"))) >= 2  # finished items kept for the rerun
    assert not out.exists()
