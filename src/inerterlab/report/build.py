"""Run the reproduction and write the report directory atomically, with resume.

Layout of a finished report directory::

    index.html            self-contained page (figures embedded as PNG data URIs)
    tables/<id>.csv       every table, with a commented settings header
    figures/<id>.png      every figure
    data/<id>.csv         the data behind every figure
    manifest.json         versions, settings, run time, what failed and why

While it runs, finished items are kept in ``<out>.work/`` (one JSON file per item,
keyed by the settings, the package version and source; see :mod:`.cache`); a rerun of
the same command after a crash or Ctrl-C reuses them. The final directory is built
beside ``<out>`` and swapped in with renames, so a crashed run leaves the previous
report intact. ``<out>`` must be new, empty or an earlier report of ours: nothing else
is ever replaced (:func:`resolve_report_target`).
"""

from __future__ import annotations

import base64
import html
import importlib
import io
import json
import os
import platform
import re
import time
import traceback
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

from ..errors import ParameterError
from ..io import atomic_write_bytes
from .cache import (
    Uncacheable,
    cache_key,
    clean_work_dir,
    dumps_record,
    prepare_work_dir,
    read_cached,
    report_lock,
)
from .registry import FigureResult, ReproduceSettings, TableResult

CHAPTERS = ("ch3", "ch4_6", "studies", "ch5", "ch7", "layouts")


def _missing_chapter(name: str, error: str) -> Callable:
    def fail(settings: ReproduceSettings):
        raise RuntimeError(f"chapter module {name!r} could not be loaded: {error}")

    return fail


def _load_chapters() -> tuple[dict[str, Callable], dict[str, Callable]]:
    """All chapter tables and figures; a chapter that fails to import becomes a failed item."""
    tables: dict[str, Callable] = {}
    figures: dict[str, Callable] = {}
    for name in CHAPTERS:
        try:
            mod = importlib.import_module(f"{__package__}.{name}")
        except Exception as e:  # noqa: BLE001 - reported in the report, never hidden
            figures[f"chapter {name}"] = _missing_chapter(name, f"{type(e).__name__}: {e}")
            continue
        tables.update(getattr(mod, "TABLES", {}))
        figures.update(getattr(mod, "FIGURES", {}))
    return tables, figures


def _table_key(tid: str) -> tuple:
    parts = re.split(r"[.\s]", tid)
    return tuple((0, int(p)) if p.isdigit() else (1, p) for p in parts)


def parse_table_selection(spec: str, available: list[str]) -> list[str]:
    """Expand "4.1-4.9,6.1-6.9,7.2" into table ids; every id must exist.

    Raises
    ------
    ParameterError
        Naming ``--tables`` and the available ids if a token is malformed or unknown.
    """
    out: list[str] = []
    valid = "a comma list of table ids or ranges like 4.1-4.9; available: " + ", ".join(
        sorted(available, key=_table_key)
    )
    for token in [t.strip() for t in spec.split(",") if t.strip()]:
        m = re.fullmatch(r"(\d+)\.(\d+)\s*-\s*(\d+)\.(\d+)", token)
        if m:
            c1, a, c2, b = (int(g) for g in m.groups())
            if c1 != c2 or a > b:
                raise ParameterError("--tables", token, valid)
            ids = (f"{c1}.{i}" for i in range(a, b + 1))  # lazy: stops at the first unknown
        else:
            ids = [token]
        for i in ids:
            if i not in available:
                raise ParameterError("--tables", i, valid)
            if i not in out:
                out.append(i)
    if not out:
        raise ParameterError("--tables", spec, valid)
    return out


def _fig_png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close(fig)
    return buf.getvalue()


def _slug(s: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", s).strip("_")


def _csv_with_header(frame, header: dict) -> str:
    lines = [f"# {k}: {v}" for k, v in header.items()]
    return "\n".join(lines) + "\n" + frame.to_csv(index=False)


def count_items(table_ids: list[str] | None, include_figures: bool) -> int:
    """Number of items :func:`run_items` will process (for progress bars)."""
    tables, figures = _load_chapters()
    n = len(table_ids) if table_ids is not None else len(tables)
    return n + (len(figures) if include_figures else 0)


#: fewest items to compute for which a run with workers starts worker processes
MIN_PARALLEL_ITEMS = 4


def _magnitude_pairs(columns) -> dict[str, str]:
    """Our columns and the thesis's counterparts, found by name: ``<q>_ours`` and
    ``<q>_thesis``, ``ours`` and ``thesis``, ``<q> ours [u]`` and ``<q> thesis [u]``."""
    cols = [str(c) for c in columns]
    pairs = {}
    for c in cols:
        if c.endswith("_ours"):
            other = c[: -len("_ours")] + "_thesis"
        elif c == "ours":
            other = "thesis"
        elif " ours" in c:
            other = c.replace(" ours", " thesis", 1)
        else:
            continue
        if other in cols:
            pairs[c] = other
    return pairs


def magnitude_check(frame, tolerance: float, pairs: dict | None = None) -> tuple[bool | None, str]:
    """Do our values agree in magnitude with the thesis's, within ``tolerance`` (relative)?

    Every finite value of ours is set against its printed counterpart (``pairs``: {our
    column: the thesis's column}, found by name when None; cells without a thesis value
    or with a thesis value of 0 are skipped). Returns (True/False, a sentence with the
    range of ours/thesis and the tolerance), or (None, why nothing was compared).
    """
    import numpy as np

    pairs = _magnitude_pairs(frame.columns) if pairs is None else pairs
    ratios = []
    for ours, thesis in pairs.items():
        if ours not in frame.columns or thesis not in frame.columns:
            continue
        o = np.asarray(frame[ours].to_numpy(dtype=float, na_value=np.nan), dtype=float)
        t = np.asarray(frame[thesis].to_numpy(dtype=float, na_value=np.nan), dtype=float)
        ok = np.isfinite(o) & np.isfinite(t) & (t != 0)
        ratios.extend((o[ok] / t[ok]).tolist())
    tol = f"tolerance ±{100 * tolerance:g} %"
    if not ratios:
        return None, "no value of ours has a printed counterpart to compare"
    r = np.array(ratios)
    lo, hi = float(r.min()), float(r.max())
    worst = float(np.max(np.abs(r - 1.0)))
    span = _span(lo, hi) if lo > 0 else f"{lo:.3g} to {hi:.3g}"
    n = f"{r.size} value{'s' if r.size != 1 else ''}"
    if worst <= tolerance:
        return True, f"our {n} agree with the thesis's within {100 * worst:.2g} % ({tol})"
    return False, (
        f"ours are {span} times the thesis's over {n}, beyond the {tol}"
    )


def compute_item(kind: str, ident: str, fn: Callable, settings: ReproduceSettings) -> dict:
    """Compute one item and return its record (a failure is recorded, not raised)."""
    t0 = time.perf_counter()
    try:
        res = fn(settings)
        rec = {"kind": kind, "id": ident, "ok": True, "seconds": time.perf_counter() - t0}
        if isinstance(res, TableResult):
            rec.update(
                title=res.title,
                frame=res.frame,
                claim=res.claim,
                claim_holds=res.claim_holds,
                judges=res.judges,
                reason=res.reason,
                settings=res.settings,
                units=dict(res.units),
            )
            rec["magnitude_agrees"], rec["magnitude"] = magnitude_check(
                res.frame, res.magnitude_tolerance, res.magnitude_pairs
            )
        elif isinstance(res, FigureResult):
            rec.update(
                title=res.title,
                png=_fig_png(res.figure),
                data=res.data,
                caption=res.caption,
                statement=res.statement,
                verdict=res.verdict,
                holds=res.holds,
                judges=res.judges,
            )
        else:  # a chapter function returned something unexpected: record, do not guess
            rec.update(ok=False, error=f"returned {type(res).__name__}")
    except KeyboardInterrupt:
        raise
    except Exception as e:  # noqa: BLE001 - recorded as a failed item, run goes on
        rec = {
            "kind": kind,
            "id": ident,
            "ok": False,
            "error": f"{type(e).__name__}: {e}",
            "traceback": traceback.format_exc(),
            "seconds": time.perf_counter() - t0,
        }
    return rec


def run_items(
    settings: ReproduceSettings,
    table_ids: list[str] | None,
    include_figures: bool,
    work_dir: Path,
    progress: Callable[[str], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_start: Callable[[str], None] | None = None,
    timeline: list | None = None,
    tracker=None,
) -> list[dict]:
    """Compute (or reuse from ``work_dir``) every selected item; returns item records.

    ``should_stop`` is polled before each item; when it returns True the run stops
    with ``KeyboardInterrupt``, every finished item being already in ``work_dir``.
    ``on_start`` is called with the name of each item about to be computed,
    ``progress`` with the name of each item done. ``timeline`` (a list) receives the
    tasks of a parallel run with their times (:func:`.parallel.run_parallel`).
    ``tracker`` (a :class:`.timeleft.TimeLeft`) follows the tasks for the time left.
    """
    tables, figures = _load_chapters()
    chosen_tables = table_ids if table_ids is not None else sorted(tables, key=_table_key)
    items = [("table", t, tables[t]) for t in chosen_tables]
    if include_figures:
        items += [("figure", f, figures[f]) for f in figures]
    prepare_work_dir(work_dir)
    tag = cache_key(asdict(settings))
    records = []
    pre: dict = {}

    def cache_of(kind: str, ident: str) -> Path:
        return work_dir / f"{kind}-{_slug(ident)}-{tag}.json"

    def save(rec: dict) -> None:
        if not rec["ok"]:
            return
        try:
            atomic_write_bytes(
                cache_of(rec["kind"], rec["id"]), dumps_record(rec, tag), follow_links=False
            )
        except Uncacheable:  # stored inexactly would break resume: recompute instead
            pass

    def reusable(kind: str, ident: str):
        cached = read_cached(cache_of(kind, ident), tag)
        if cached is not None and (cached["kind"], cached["id"]) == (kind, ident):
            return cached
        return None

    todo = [it for it in items if reusable(it[0], it[1]) is None]
    # shared pieces and independent chapters in parallel first; a few items are not worth
    # starting worker processes for (each imports the package and loads the kernels)
    if settings.workers > 1 and len(todo) >= MIN_PARALLEL_ITEMS:
        from .parallel import run_parallel

        def arrived(rec: dict) -> None:  # saved at once: a killed run keeps it
            save(rec)
            if progress:
                progress(f"{rec['kind']} {rec['id']}")

        pre = run_parallel(
            settings,
            todo,
            settings.workers,
            note=on_start,
            done=arrived,
            should_stop=should_stop,
            timeline=timeline,
            tracker=tracker,
        )
    elif tracker is not None:
        tracker.plan([f"{k} {i}" for k, i, _ in todo], 1)
    for kind, ident, fn in items:
        if should_stop is not None and should_stop():
            raise KeyboardInterrupt
        from_worker = (kind, ident) in pre  # computed, saved and reported by run_parallel
        cached = None if from_worker else reusable(kind, ident)
        if cached is not None:
            records.append({**cached, "reused": True})
            if progress:
                progress(f"{kind} {ident} (reused)")
            continue
        if on_start and not from_worker:
            on_start(f"{kind} {ident}")
        if tracker is not None and not from_worker:
            tracker.begin(f"{kind} {ident}")
        rec = pre.pop((kind, ident)) if from_worker else compute_item(kind, ident, fn, settings)
        if tracker is not None and not from_worker:
            tracker.end(f"{kind} {ident}")
        if not from_worker:
            save(rec)
        records.append(rec)
        if progress and not from_worker:
            progress(f"{kind} {ident}")
    return records


_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;max-width:1200px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.45;overflow-wrap:break-word}
h1{border-bottom:2px solid #345}h2{margin-top:2em;border-bottom:1px solid #ccc}
.tablewrap{overflow-x:auto;max-width:100%;margin:0.5em 0 1em}
table{border-collapse:collapse;font-size:0.85em}
th,td{border:1px solid #ccc;padding:3px 6px;text-align:right}th{background:#eef}
td:first-child,th:first-child{text-align:left}
.ok{color:#1a7f37;font-weight:bold}.no{color:#b42318;font-weight:bold}.na{color:#777}
.claim{background:#f6f8fa;border-left:4px solid #345;padding:0.4em 0.8em;margin:0.5em 0}
figure{margin:0.5em 0 1.5em}figcaption{margin-top:0.3em}
img{display:block;max-width:100%;height:auto;border:1px solid #ddd}nav a{margin-right:0.8em}
table.summary td,table.summary th{text-align:left}
.failed{background:#fff0f0;border-left:4px solid #b42318;padding:0.4em 0.8em}
code,pre{background:#f6f8fa}pre{overflow-x:auto}
"""


def claim_count(records: list[dict]) -> str:
    """How many of the thesis's claims hold, counted once for the whole report.

    A claim is a table's claim or a figure's statement that the report judges (a
    verdict of holds or does not hold); failed items and items with nothing to judge
    are not counted. The same sentence opens the report and its conclusion.
    """
    tables = [r for r in records if r["kind"] == "table" and r["ok"]]
    figures = [r for r in records if r["kind"] == "figure" and r["ok"]]
    jt = [r for r in tables if r.get("claim_holds") is not None]
    jf = [r for r in figures if r.get("holds") is not None]
    ht = sum(bool(r["claim_holds"]) for r in jt)
    hf = sum(bool(r["holds"]) for r in jf)
    return (
        f"{ht + hf} of {len(jt) + len(jf)} thesis claims hold in our physics (a claim: each "
        f"judged table claim and figure statement; tables {ht} of {len(jt)}, figures {hf} "
        f"of {len(jf)})"
    )


def _headline(records: list[dict], settings: ReproduceSettings) -> str:
    """The report's first lines: a quick run marked as such, how many claims hold and
    how many tables differ in magnitude from the thesis's values."""
    tables = [r for r in records if r["kind"] == "table"]
    parts = []
    if settings.quick:
        parts.append(
            "<p class='failed'><b>Quick run</b> (--quick): fewer masses, shorter horizons and "
            "coarser grids than the full report; numbers are not the report's.</p>"
        )
    judged = [r for r in tables if r["ok"] and r.get("claim_holds") is not None]
    held = [r for r in judged if r["claim_holds"]]
    compared = [r for r in tables if r["ok"] and r.get("magnitude_agrees") is not None]
    apart = [r for r in compared if not r["magnitude_agrees"]]
    if judged:
        ids = ", ".join(html.escape(r["id"]) for r in held) or "none"
        parts.append(
            f"<p class='claim'><b>{html.escape(claim_count(records))}</b>; tables whose claim "
            f"holds: {ids}. Each verdict says what it judges and why it fails."
            + (
                f" {len(apart)} of the {len(compared)} tables with printed values differ from "
                "them in magnitude beyond the stated tolerance, flagged beside their verdicts."
                if compared
                else ""
            )
            + (
                " Across the rectangular bump an inerter straight between wheel and body "
                "passes part of the tyre impulse to the body, so plain RMS accelerations "
                "there are infinite and the report compares ISO 2631 Wk-weighted values "
                "instead."
                if any("body velocity" in r.get("reason", "") for r in judged)
                else ""
            )
            + "</p>"
        )
    return "".join(parts)


def _numeric_none(frame):
    """Columns of numbers and ``None`` (a value that is not finite, or no thesis value)
    as float columns, so they print with the number format and ``None`` as the dash."""
    import numbers

    out = frame.copy()
    for c in out.columns:
        col = out[c]
        if col.dtype == object and all(
            v is None or (isinstance(v, numbers.Real) and not isinstance(v, bool)) for v in col
        ):
            out[c] = col.astype(float)
    return out


def _verdict(v) -> str:
    if v is True:
        return '<span class="ok">holds</span>'
    if v is False:
        return '<span class="no">does not hold</span>'
    return '<span class="na">not judged</span>'


def _judged(r: dict, verdict_key: str) -> str:
    """The verdict, what it judges, and a magnitude disagreement beside it (HTML)."""
    out = _verdict(r.get(verdict_key))
    if r.get("judges"):
        out += f" <small>(judged: {html.escape(r['judges'])})</small>"
    if r.get("magnitude_agrees") is False:
        out += (
            "; <span class='no'>magnitude differs</span>: "
            f"{html.escape(r.get('magnitude', ''))}"
        )
    return out


def _markdown_to_html(text: str) -> str:
    """Tiny Markdown subset (headings, bullets, paragraphs, code spans) for the errata."""
    out, in_list, in_para = [], False, False
    for raw in text.splitlines():
        line = html.escape(raw.rstrip())
        line = re.sub(r"`([^`]+)`", r"<code>\1</code>", line)
        line = re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", line)
        if line.startswith("- "):
            in_para = False
            if not in_list:
                out.append("<ul>")
                in_list = True
            out.append(f"<li>{line[2:]}</li>")
            continue
        if line.startswith("  ") and in_list and out:
            out[-1] = out[-1][:-5] + " " + line.strip() + "</li>"
            continue
        if in_list:
            out.append("</ul>")
            in_list = False
        if line.startswith("#"):
            level = min(len(line) - len(line.lstrip("#")) + 2, 6)
            out.append(f"<h{level}>{line.lstrip('#').strip()}</h{level}>")
            in_para = False
        elif not line.strip():
            in_para = False
        elif in_para:  # a paragraph runs on until a blank line, as in Markdown
            out[-1] = out[-1][:-4] + " " + line.strip() + "</p>"
        else:
            out.append(f"<p>{line.strip()}</p>")
            in_para = True
    if in_list:
        out.append("</ul>")
    return "\n".join(out)


def source_revision(package_dir: str | os.PathLike | None = None) -> str:
    """The git commit the package's source is from, read from the repository's files
    (no program is run): "<40 hex digits>", or a sentence saying why there is none (not
    a git checkout, e.g. an installed wheel; or a state this reader does not follow).

    Only a repository whose ``src/inerterlab`` is this package counts, so a checkout
    that merely contains an installed copy is not mistaken for its source.
    """
    pkg = Path(package_dir) if package_dir is not None else Path(__file__).resolve().parents[1]
    root = pkg.parent.parent  # <root>/src/inerterlab
    dotgit = root / ".git"
    try:
        if pkg.name != "inerterlab" or pkg.parent.name != "src" or not dotgit.exists():
            return "not a git checkout"
        if dotgit.is_file():  # a worktree: "gitdir: <path>"
            text = dotgit.read_text().strip()
            if not text.startswith("gitdir:"):
                return "not a git checkout"
            gitdir = (root / text.split(":", 1)[1].strip()).resolve()
        else:
            gitdir = dotgit
        common = gitdir
        if (gitdir / "commondir").is_file():
            common = (gitdir / (gitdir / "commondir").read_text().strip()).resolve()
        head = (gitdir / "HEAD").read_text().strip()
        if re.fullmatch(r"[0-9a-f]{40}", head):
            return head
        if not head.startswith("ref:"):
            return "unknown (unreadable HEAD)"
        ref = head.split(":", 1)[1].strip()
        for base in (gitdir, common):
            loose = base / ref
            if loose.is_file():
                sha = loose.read_text().strip()
                if re.fullmatch(r"[0-9a-f]{40}", sha):
                    return sha
        packed = common / "packed-refs"
        if packed.is_file():
            for line in packed.read_text().splitlines():
                parts = line.split()
                if len(parts) == 2 and parts[1] == ref and re.fullmatch(r"[0-9a-f]{40}", parts[0]):
                    return parts[0]
        return f"unknown (branch {ref} not found)"
    except (OSError, UnicodeDecodeError) as e:
        return f"unknown ({type(e).__name__})"


def _versions() -> dict:
    import importlib.metadata as md

    from .. import __version__

    out = {
        "inerterlab": __version__,
        "inerterlab git commit (HEAD)": source_revision(),
        "python": platform.python_version(),
        "platform": platform.platform(),
    }
    for pkg in ("numpy", "scipy", "numba", "pandas", "xarray", "matplotlib"):
        try:
            out[pkg] = md.version(pkg)
        except md.PackageNotFoundError:
            out[pkg] = "not installed"
    return out


#: unit of a quantity named at the start of a column (ratios and weights are fractions)
_PREFIX_UNITS = (
    ("rms_body_acc", "m/s^2"),
    ("rms_tyre_grip", "-"),
    ("rms_deflection", "m"),
    ("optimal_ratio", "-"),
    ("comfort_weight", "-"),
    ("grip_weight", "-"),
    ("bump_weight", "-"),
    ("sine_weight", "-"),
)
#: unit implied by one "_"-separated word of a column name
_WORD_UNITS = {"kg": "kg", "cm": "cm", "hz": "Hz", "%": "%"}


def column_unit(name: str, units: dict | None = None) -> str | None:
    """The unit of table column ``name``: None if the name already carries one
    ("peak force [N]") or none is known; ``units`` (the table's own) comes first."""
    if "[" in name:
        return None
    if units and name in units:
        return units[name]
    for prefix, unit in _PREFIX_UNITS:
        if name.startswith(prefix):
            return unit
    for word in name.split("_"):
        if word.lower() in _WORD_UNITS:
            return _WORD_UNITS[word.lower()]
    return None


def _header(name: str, units: dict | None) -> str:
    unit = column_unit(name, units)
    return name if unit is None else f"{name} [{unit}]"


def _html_table(frame, units: dict | None = None) -> str:
    """A table with units in its column headers, inside a box that scrolls sideways
    when the table is wider than the page."""
    shown = frame.rename(columns=lambda c: _header(str(c), units))
    body = shown.to_html(index=False, float_format=lambda x: f"{x:.5g}", na_rep="—")
    return f"<div class='tablewrap'>{body}</div>"


def _first_sentence(text: str, limit: int = 120) -> str:
    """The first clause of ``text`` (up to the first full stop or semicolon), cut to
    ``limit`` characters."""
    head = re.split(r"(?<=[.;])\s", text.strip(), maxsplit=1)[0].rstrip(".;")
    return head if len(head) <= limit else head[: limit - 3].rstrip() + "..."


def _span(lo: float, hi: float, fmt: str = ".3g") -> str:
    return f"{lo:{fmt}}" if f"{lo:{fmt}}" == f"{hi:{fmt}}" else f"{lo:{fmt}}-{hi:{fmt}}"


def _findings(records: list[dict]) -> list[str]:
    """Main findings in plain words, each computed from the tables it names."""
    import numpy as np

    tab = {r["id"]: r for r in records if r["kind"] == "table" and r["ok"]}
    out = []

    def col(tid: str, name: str):
        f = tab[tid]["frame"] if tid in tab else None
        if f is None or name not in f.columns:
            return None
        v = np.asarray(f[name].to_numpy(), dtype=float)
        v = v[np.isfinite(v)]
        return v if v.size else None

    c = col("3.C", "imbalance [% of work]")
    if c is not None and "law" in tab["3.C"]["frame"]:
        law = dict(zip(tab["3.C"]["frame"]["law"], c, strict=False))
        if "thesis" in law:
            rest = [abs(v) for k, v in law.items() if k != "thesis"]
            out.append(
                f"Energy (table 3.C): the thesis's force law leaves {abs(law['thesis']):.3g} % "
                "of the work done on the inerter unaccounted for"
                + (f"; the energy-consistent laws at most {max(rest):.2g} %." if rest else ".")
            )
    for ch, what in (("4", "ideal devices (ch. 4)"), ("6", "real hydraulic device (ch. 6)")):
        ids = [i for i in tab if i.split(".")[0] == ch and tab[i]["claim_holds"] is not None]
        if ids:
            held = [i for i in ids if tab[i]["claim_holds"]]
            why: dict[str, list[str]] = {}  # first clause of the reason -> tables
            for i in sorted(set(ids) - set(held), key=_table_key):
                why.setdefault(_first_sentence(tab[i]["reason"]), []).append(i)
            out.append(
                f"Ride metrics with the {what}: {len(held)} of {len(ids)} claims hold"
                + (
                    "; not: " + "; ".join(f"{', '.join(t)} ({w})" for w, t in why.items())
                    if why
                    else ""
                )
                + "."
            )
    for ch in ("4", "6"):
        ours, th = col(f"{ch}.13", "optimal_ratio_ours"), col(f"{ch}.13", "optimal_ratio_thesis")
        tt = col(f"{ch}.13", "optimal_ratio_from_thesis_tables")
        if ours is not None and th is not None:
            out.append(
                f"Optimal changing ratio (table {ch}.13): ours {ours[0]:.3f}, the thesis "
                f"{th[0]:.3f}"
                + (f"; the thesis's own tables give {tt[0]:.3f}" if tt is not None else "")
                + "."
            )
    d = col("5.A", "diff_rel_%")
    if d is not None:
        nr = col("5.A", "validation_nrmse_%")
        out.append(
            "Identification (table 5.A, simulated rig data): every parameter recovered "
            f"within {np.max(np.abs(d)):.2g} % of the value that made the data"
            + (f"; validation NRMSE {_span(nr.min(), nr.max(), '.2g')} %" if nr is not None else "")
            + "."
        )
    f_ours, f_th = col("7.1", "resonance_hz_ours"), col("7.1", "resonance_hz_thesis")
    if f_ours is not None and f_th is not None:
        out.append(
            f"Frequency response (table 7.1): our resonances lie at {_span(f_ours.min(), f_ours.max())} "
            f"Hz, the thesis's at {_span(f_th.min(), f_th.max())} Hz; "
            + ("both fall" if tab["7.1"]["claim_holds"] else "the thesis's trends do not both hold")
            + " as the amplitude grows."
        )
    errs = [
        (t, col(t, f"nrmse_{m}_%_ours"), col(t, f"nrmse_{m}_%_thesis"))
        for t, m in (("7.2", "shb"), ("7.3", "mhb"), ("7.4", "sihb"))
    ]
    errs = [e for e in errs if e[1] is not None and e[2] is not None]
    if errs:
        out.append(
            "Harmonic balance against brute force (tables "
            + ", ".join(e[0] for e in errs)
            + f"): our NRMSE at most {max(e[1].max() for e in errs):.2g} %, the thesis's up to "
            f"{max(e[2].max() for e in errs):.3g} %."
        )
    return out


def _conclusion(records: list[dict]) -> str:
    tables = [r for r in records if r["kind"] == "table" and r["ok"]]
    figures = [r for r in records if r["kind"] == "figure" and r["ok"]]
    parts = ["<h2 id='conclusion'>Conclusion</h2>"]
    parts.append(
        f"<p>{html.escape(claim_count(records))}"
        + (
            f"; {len(records) - len(tables) - len(figures)} item(s) failed"
            if len(tables) + len(figures) < len(records)
            else ""
        )
        + ". Main findings:</p><ul>"
    )
    parts += [f"<li>{html.escape(f)}</li>" for f in _findings(records)]
    bad = [r for r in figures if r.get("holds") is False]
    if bad:
        parts.append(
            "<li>Figures whose data contradict the thesis's statement (each says how, above "
            "it): "
            + ", ".join(f"<a href='#f-{_slug(r['id'])}'>{html.escape(r['id'])}</a>" for r in bad)
            + ".</li>"
        )
    parts.append("</ul>")
    return "".join(parts)


def _figure_verdict(r: dict) -> str:
    verdict = html.escape(r.get("verdict", ""))
    if r.get("statement"):
        return (
            f"<div class='claim'><b>Thesis:</b> {html.escape(r['statement'])}<br>"
            f"<b>The data:</b> {_judged(r, 'holds')}. {verdict}</div>"
        )
    return f"<div class='claim'><b>Not in the thesis</b> (ours). {verdict}</div>"


def render(
    records: list[dict],
    settings: ReproduceSettings,
    elapsed: float,
    errata: str,
    timeline: list | None = None,
    task_costs: tuple[str, dict] | None = None,
) -> dict:
    """Build the files of the report in memory: {relative path: bytes}.

    ``timeline``: the tasks of a parallel run with their times, kept in the manifest
    (``parallel_tasks``) to show where the wall time went. ``task_costs``: ("serial" or
    "parallel", {task key: seconds}), kept (``task_mode``, ``task_seconds``) for the next
    run's estimate of the time left (:mod:`.timeleft`)."""
    files: dict[str, bytes] = {}
    versions = _versions()
    tables = [r for r in records if r["kind"] == "table"]
    figures = [r for r in records if r["kind"] == "figure"]
    failed = [r for r in records if not r["ok"]]
    parts = [
        "<!doctype html><html lang='en'><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width, initial-scale=1'>",
        "<title>inerterlab: thesis reproduction report</title>",
        f"<style>{_CSS}</style></head><body>",
        "<h1>Thesis reproduction report</h1>",
        _headline(records, settings),
        "<p>Every thesis table and figure that carries information, regenerated by inerterlab "
        "beside the thesis's own numbers. Differences are expected: the thesis's MATLAB code "
        "never adapts the flywheel and leaves several settings unstated (see the errata). "
        "No model was tuned to match a thesis value; for each table and figure the report says "
        "whether the thesis's statement holds in our physics.</p>",
        "<nav><a href='#summary'>Summary</a><a href='#conclusion'>Conclusion</a>"
        "<a href='#tables'>Tables</a><a href='#figures'>Figures</a><a href='#errata'>Errata</a>"
        "<a href='#settings'>Settings</a></nav>",
        "<h2 id='summary'>Summary</h2><div class='tablewrap'><table class='summary'><tr><th>item</th>"
        "<th>title</th><th>thesis claim</th><th>verdict</th></tr>",
    ]
    for r in tables:
        if r["ok"]:
            parts.append(
                f"<tr><td><a href='#t-{_slug(r['id'])}'>Table {html.escape(r['id'])}</a></td>"
                f"<td>{html.escape(r['title'])}</td><td>{html.escape(r['claim'])}</td>"
                f"<td>{_judged(r, 'claim_holds')}</td></tr>"
            )
        else:
            parts.append(
                f"<tr><td>Table {html.escape(r['id'])}</td><td colspan='2'>failed: "
                f"{html.escape(r['error'])}</td><td class='no'>failed</td></tr>"
            )
    for r in figures:
        link = f"<a href='#f-{_slug(r['id'])}'>{html.escape(r['id'])}</a>"
        if r["ok"]:
            parts.append(
                f"<tr><td>{link}</td><td>{html.escape(r['title'])}</td>"
                f"<td>{html.escape(r.get('statement') or '(not in the thesis)')}</td>"
                f"<td>{_judged(r, 'holds')}: {html.escape(r.get('verdict', ''))}</td></tr>"
            )
        else:
            parts.append(
                f"<tr><td>{link}</td><td colspan='2'>failed: {html.escape(r['error'])}</td>"
                "<td class='no'>failed</td></tr>"
            )
    parts.append("</table></div>")
    if failed:
        parts.append(
            f"<p class='failed'>{len(failed)} item(s) failed; they are listed with their reason "
            "and no number is shown for them.</p>"
        )
    parts.append(_conclusion(records))
    parts.append("<h2 id='tables'>Tables</h2>")
    for r in tables:
        sid = _slug(r["id"])
        parts.append(f"<h3 id='t-{sid}'>Table {html.escape(r['id'])}</h3>")
        if not r["ok"]:
            parts.append(f"<div class='failed'>failed: {html.escape(r['error'])}</div>")
            continue
        parts.append(f"<p>{html.escape(r['title'])}</p>")
        parts.append(
            f"<div class='claim'><b>Thesis claim:</b> {html.escape(r['claim'])}<br>"
            f"<b>In our physics:</b> {_judged(r, 'claim_holds')}. {html.escape(r['reason'])}"
            + (
                f"<br><b>Magnitude against the thesis:</b> {html.escape(r['magnitude'])}."
                if r.get("magnitude")
                else ""
            )
            + "</div>"
        )
        frame = _numeric_none(r["frame"])
        units = r.get("units") or {}
        parts.append(_html_table(frame, units))
        if r.get("settings"):
            s = "; ".join(f"{k} = {v}" for k, v in r["settings"].items())
            parts.append(
                f"<p><small>Settings: {html.escape(s)}. CSV: "
                f"<a href='tables/{sid}.csv'>tables/{sid}.csv</a></small></p>"
            )
        header = {"table": r["id"], "title": r["title"], **{k: v for k, v in r["settings"].items()}}
        known = {str(c): column_unit(str(c), units) for c in frame.columns}
        if any(known.values()):
            header["units"] = "; ".join(f"{c} [{u}]" for c, u in known.items() if u)
        files[f"tables/{sid}.csv"] = _csv_with_header(frame, header).encode()
    parts.append("<h2 id='figures'>Figures</h2>")
    for r in figures:
        sid = _slug(r["id"])
        parts.append(
            f"<h3 id='f-{sid}'>{html.escape(r['id'])}: {html.escape(r.get('title', ''))}</h3>"
        )
        if not r["ok"]:
            parts.append(f"<div class='failed'>failed: {html.escape(r['error'])}</div>")
            continue
        parts.append(_figure_verdict(r))
        b64 = base64.b64encode(r["png"]).decode()
        parts.append(
            f"<figure><img alt='{html.escape(r['id'])}' src='data:image/png;base64,{b64}'>"
            f"<figcaption>{html.escape(r['caption'])} Data: "
            f"<a href='data/{sid}.csv'>data/{sid}.csv</a></figcaption></figure>"
        )
        files[f"figures/{sid}.png"] = r["png"]
        files[f"data/{sid}.csv"] = r["data"].to_csv(index=False).encode()
    parts.append("<h2 id='errata'>Errata</h2>")
    parts.append(_markdown_to_html(errata))
    parts.append(
        "<h2 id='settings'>Settings and versions</h2><div class='tablewrap'><table>"
        "<tr><th>setting or package</th><th>value (run time in s)</th></tr>"
    )
    for k, v in {**asdict(settings), **versions, "run time [s]": f"{elapsed:.1f}"}.items():
        parts.append(f"<tr><td>{html.escape(str(k))}</td><td>{html.escape(str(v))}</td></tr>")
    parts.append("</table></div></body></html>")
    files["index.html"] = "\n".join(parts).encode()
    manifest = {
        "settings": asdict(settings),
        "versions": versions,
        "run_seconds": elapsed,
        "items": [
            {k: r[k] for k in ("kind", "id", "ok", "seconds") if k in r}
            | {"reused": bool(r.get("reused", False))}
            | ({"error": r["error"]} if not r["ok"] else {})
            | ({"claim_holds": r["claim_holds"]} if r["ok"] and r["kind"] == "table" else {})
            | (
                {"magnitude_agrees": r.get("magnitude_agrees")}
                if r["ok"] and r["kind"] == "table"
                else {}
            )
            | ({"holds": r.get("holds")} if r["ok"] and r["kind"] == "figure" else {})
            for r in records
        ],
    }
    if timeline:
        manifest["parallel_tasks"] = timeline
    if task_costs is not None:
        manifest["task_mode"], manifest["task_seconds"] = task_costs
    files["manifest.json"] = json.dumps(manifest, indent=2).encode()
    return files


#: what a report directory of ours holds at its top level
REPORT_ENTRIES = frozenset({"index.html", "manifest.json", "tables", "figures", "data"})


def _is_our_report(d: Path) -> bool:
    """True if ``d`` is empty or holds exactly a report this package wrote.

    A report of ours has a ``manifest.json`` with our keys, nothing at its top level but
    the entries of :data:`REPORT_ENTRIES`, and only ``.csv``/``.png`` files (no links,
    no subfolders) in ``tables/``, ``figures/`` and ``data/``.
    """
    entries = list(d.iterdir())
    if not entries:
        return True
    names = {e.name for e in entries}
    if not names <= REPORT_ENTRIES or "manifest.json" not in names:
        return False
    for e in entries:
        if e.is_symlink():
            return False
        if e.name in ("index.html", "manifest.json"):
            if not e.is_file():
                return False
        elif not e.is_dir() or any(
            f.is_symlink() or not f.is_file() or f.suffix not in (".csv", ".png")
            for f in e.iterdir()
        ):
            return False
    try:
        m = json.loads((d / "manifest.json").read_text())
    except (OSError, ValueError):
        return False
    return isinstance(m, dict) and {"settings", "versions", "items"} <= set(m)


def resolve_report_target(out: str | os.PathLike) -> Path:
    """The directory a report for ``--out`` goes to; refuses what is not ours to replace.

    A symbolic link is followed (the report replaces what it points to, the link stays).
    An existing path must be an empty directory or a report this package wrote:
    anything else is refused, so no file of the user's is ever removed.
    """
    text = os.fspath(out)
    if not str(text).strip():
        raise ParameterError("--out", text, "a directory path (it is empty)")
    p = Path(os.path.realpath(text))
    if p.name in ("", ".", "..") or p == p.parent:
        raise ParameterError("--out", text, "a directory path with a name (not a root)")
    cwd = Path.cwd().resolve()
    if p == cwd or p in cwd.parents:
        raise ParameterError("--out", text, "a directory other than the current one or above it")
    if p.exists():
        if not p.is_dir():
            raise ParameterError(
                "--out", text, "a new or report directory; it is an existing file, not replaced"
            )
        try:
            ours = _is_our_report(p)
        except OSError as e:
            raise ParameterError("--out", text, f"a readable directory ({e.strerror})") from None
        if not ours:
            raise ParameterError(
                "--out",
                text,
                "a new directory, an empty one or an earlier report of inerterlab; this folder "
                "holds other files, and --out is replaced as a whole, so nothing was written",
            )
    return p


def _umask() -> int:
    from ..io import current_umask

    return current_umask()


def clean_stale_temporaries(out: Path) -> list[Path]:
    """Remove ``.<name>.new-*`` / ``.<name>.old-*`` folders left by an interrupted write.

    Call only while holding the report lock (:func:`report_lock`): then no other run can
    be writing them.
    """
    from ..io import clean_stale_siblings

    return clean_stale_siblings(out)


def write_report_atomically(out: Path, files: dict[str, bytes]) -> Path:
    """Write ``files`` into a fresh directory and swap it in place of ``out``.

    ``out`` must have passed :func:`resolve_report_target` (empty or ours). The swap is
    :func:`inerterlab.io.replace_directory` (filled beside, two renames, synced files).
    """
    from ..io import replace_directory

    return replace_directory(out, files)


def read_errata(path: str | os.PathLike | None = None) -> str:
    """The errata text: ``path`` if given, else the copy shipped in the package."""
    if path is not None:
        return Path(path).read_text()
    from importlib import resources

    return resources.files("inerterlab.data").joinpath("errata.md").read_text()


def reproduce(
    out: str | os.PathLike,
    *,
    settings: ReproduceSettings | None = None,
    tables: str | None = None,
    figures: bool = True,
    progress: Callable[[str], None] | None = None,
    errata_path: str | os.PathLike | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_start: Callable[[str], None] | None = None,
    tracker=None,
) -> dict:
    """Run the reproduction and write the report to ``out``; returns the manifest.

    Parameters
    ----------
    out : path
        Report directory (replaced atomically when the run completes).
    settings : ReproduceSettings
        ``quick=True`` for the reduced run.
    tables : str, optional
        Selection such as "4.1-4.9,6.1-6.9"; with a selection, figures are skipped
        unless ``figures`` is True and no selection is given.
    tracker : TimeLeft, optional
        Given the measured costs of an earlier run (:func:`.timeleft.known_costs`) and
        the tasks as they run, for the progress line's time left.
    """
    from .timeleft import TimeLeft, known_costs

    settings = settings or ReproduceSettings()
    out = resolve_report_target(out)
    t0 = time.perf_counter()
    all_tables, _ = _load_chapters()
    ids = parse_table_selection(tables, list(all_tables)) if tables is not None else None
    work = prepare_work_dir(out.parent / f"{out.name}.work")
    with report_lock(work, out):
        clean_stale_temporaries(out)
        out = resolve_report_target(out)  # checked again now that no one else writes it
        timeline: list = []
        tracker = tracker if tracker is not None else TimeLeft()
        costs, source = known_costs(out, settings.quick, settings.workers > 1)
        tracker.set_costs(costs, source)
        records = run_items(
            settings, ids, figures and ids is None, work, progress, should_stop, on_start,
            timeline, tracker,
        )  # fmt: skip
        mode = "parallel" if tracker.workers > 1 else "serial"
        measured = {**costs, **tracker.finished} if ids is None else None
        manifest = _finish(out, records, settings, t0, errata_path, timeline,
                           (mode, measured) if measured else None)  # fmt: skip
        clean_work_dir(work)
    return manifest


def _finish(out, records, settings, t0, errata_path, timeline=None, task_costs=None) -> dict:
    errata = read_errata(errata_path)
    files = render(records, settings, time.perf_counter() - t0, errata, timeline, task_costs)
    write_report_atomically(out, files)
    return json.loads(files["manifest.json"])
