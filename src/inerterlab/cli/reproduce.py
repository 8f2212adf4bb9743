"""``inerterlab reproduce``: the thesis reproduction report."""

from __future__ import annotations

import signal
from pathlib import Path
from typing import Annotated

import typer


def reproduce_command(
    out: Annotated[
        Path,
        typer.Option(
            help="Report directory: new, empty or an earlier report of inerterlab "
            "(replaced atomically at the end; any other folder is refused)."
        ),
    ] = Path("reproduction"),
    tables: Annotated[
        str | None,
        typer.Option(
            help="Only these thesis tables, e.g. 4.1-4.9,6.1-6.9 (CSV + HTML, no figures)."
        ),
    ] = None,
    quick: Annotated[
        bool, typer.Option("--quick", help="Reduced grids and horizons (seconds, for smoke tests).")
    ] = False,
    workers: Annotated[
        int | None,
        typer.Option(
            min=1,
            help="Worker processes (default: the CPUs this process may use); 1 computes "
            "everything in this process.",
        ),
    ] = None,
    json_out: Annotated[bool, typer.Option("--json", help="Print the manifest as JSON.")] = False,
    progress_interval: Annotated[
        float,
        typer.Option(
            min=0.1,
            help="Seconds between progress lines on standard error when it is not a "
            "terminal (on a terminal a live bar shows the running item and the time left).",
        ),
    ] = 10.0,
) -> None:
    """Regenerate every thesis table and figure beside the thesis's numbers.

    Writes OUT/index.html (self-contained), OUT/tables/*.csv, OUT/figures/*.png,
    OUT/data/*.csv and OUT/manifest.json. An interrupted run resumes from OUT.work/.
    Values are in SI units unless a column name says otherwise.

    Example: inerterlab reproduce --out reproduction
    """
    from ..report.build import (
        _load_chapters,
        count_items,
        parse_table_selection,
        reproduce,
        resolve_report_target,
    )
    from ..report.registry import ReproduceSettings
    from ..studies.backends import check_workers
    from ._common import emit_json
    from ._progress import RunProgress

    if workers is None:
        from ..report.parallel import default_workers

        workers = default_workers()
    settings = ReproduceSettings(quick=quick, workers=check_workers("--workers", workers))
    resolve_report_target(out)  # refuse a bad --out before any progress line
    ids = parse_table_selection(tables, list(_load_chapters()[0])) if tables is not None else None
    from ..report.timeleft import TimeLeft

    total = count_items(ids, ids is None)
    tracker = TimeLeft()
    with RunProgress(total, label="reproduce", interval=progress_interval,
                     estimator=tracker) as bar:  # fmt: skip
        # first Ctrl-C: finish the current item, keep everything, stop; second: stop now.
        # Raising inside the handler could land in a native callback (numba compiling)
        # that swallows it, so the first one only sets a flag polled between items.
        stop = {"requested": False}

        def on_sigint(signum, frame):
            if stop["requested"]:
                raise KeyboardInterrupt
            stop["requested"] = True
            bar.note("Ctrl-C: stopping after the current item (press again to stop now)")

        previous = signal.signal(signal.SIGINT, on_sigint)
        try:
            manifest = reproduce(
                out,
                settings=settings,
                tables=tables,
                progress=bar.done,
                on_start=bar.start,
                should_stop=lambda: stop["requested"],
                tracker=tracker,
            )
        finally:
            signal.signal(signal.SIGINT, previous)
    failed = [i for i in manifest["items"] if not i["ok"]]
    if json_out:
        emit_json(manifest)
    else:
        n = len(manifest["items"])
        typer.echo(
            f"report written to {out / 'index.html'}: {n - len(failed)} of {n} items done "
            f"in {manifest['run_seconds']:.1f} s"
        )
        for i in failed:
            typer.echo(f"  failed: {i['kind']} {i['id']}: {i['error']}", err=True)
    if failed:
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    app.command("reproduce")(reproduce_command)
