"""Progress of a run of named items on standard error.

On a terminal: a live bar naming the item being computed, with elapsed time and an
estimate of the time left (:class:`inerterlab.report.timeleft.TimeLeft`: measured task
costs and the speed of this run; it says when it cannot estimate). Otherwise (a log file, CI, a pipe): plain lines, one when the
run starts and then one every ``interval`` seconds, each naming the running item, so a
long item still shows signs of life; and a last line when the run ends.
"""

from __future__ import annotations

import sys
import threading
import time


def _duration(seconds: float) -> str:
    seconds = max(0.0, seconds)
    if seconds < 60:
        return f"{seconds:.0f} s"
    m, s = divmod(int(round(seconds)), 60)
    if m < 60:
        return f"{m} min {s:02d} s"
    h, m = divmod(m, 60)
    return f"{h} h {m:02d} min"


class RunProgress:
    """Progress of ``total`` items; call :meth:`start` and :meth:`done` per item.

    Parameters
    ----------
    total : int
        Number of items.
    label : str
        What runs ("reproduce").
    stream : file, optional
        Where lines go (standard error by default).
    interval : float
        Seconds between plain lines.
    live : bool, optional
        Force the live bar (True) or plain lines (False); by default the bar only if
        ``stream`` is a terminal.
    estimator : TimeLeft, optional
        Follows the run's tasks and gives the time left (a fresh one by default; pass
        the same object to the run).
    """

    def __init__(self, total: int, *, label: str, stream=None, interval: float = 10.0,
                 live: bool | None = None, estimator=None):  # fmt: skip
        from ..report.timeleft import TimeLeft

        self.total = int(total)
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.interval = float(interval)
        if live is None:
            isatty = getattr(self.stream, "isatty", None)
            live = bool(isatty and isatty())
        self.live = live
        self.estimator = estimator if estimator is not None else TimeLeft()
        self.completed = 0
        self.current: str | None = None
        self.current_since = 0.0
        self.t0 = time.perf_counter()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None
        self._bar = None
        self._task = None

    # -- estimate ----------------------------------------------------------------
    def eta(self) -> tuple[float | None, str]:
        """(seconds left, how obtained) or (None, why not): see :class:`TimeLeft`."""
        return self.estimator.estimate()

    def left_text(self) -> str:
        """The time left in words, saying how it was obtained or why it cannot be."""
        eta, how = self.eta()
        if eta is None:
            return f"time left unknown ({how})"
        return f"about {_duration(eta)} left ({how})"

    def line(self) -> str:
        """One plain progress line."""
        now = time.perf_counter()
        parts = [f"{self.label}: {self.completed}/{self.total} done"]
        if self.current:
            parts.append(f"running {self.current} ({_duration(now - self.current_since)})")
        parts.append(f"elapsed {_duration(now - self.t0)}")
        parts.append(self.left_text())
        return ", ".join(parts)

    # -- events ------------------------------------------------------------------
    def start(self, name: str) -> None:
        with self._lock:
            if name != self.current:  # the same work described again keeps its start
                self.current_since = time.perf_counter()
            self.current = name
        if self._bar is not None:
            self._bar.update(self._task, description=f"running {name}")

    def done(self, name: str) -> None:
        with self._lock:
            self.completed += 1
            self.current = None
        if self._bar is not None:
            self._bar.update(self._task, advance=1, description=f"done {name}",
                             left=self.left_text())  # fmt: skip

    def note(self, text: str) -> None:
        """A message that must be seen now (e.g. how Ctrl-C is handled)."""
        if self._bar is not None:
            self._bar.console.print(text, markup=False, highlight=False)
        else:
            self._write(f"{self.label}: {text}")

    # -- context -----------------------------------------------------------------
    def __enter__(self) -> RunProgress:
        self.t0 = time.perf_counter()
        if self.live:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
            )

            self._bar = Progress(
                TextColumn(f"[bold]{self.label}"),
                BarColumn(),
                TextColumn("{task.completed}/{task.total}"),
                TimeElapsedColumn(),
                TextColumn("{task.fields[left]}"),
                TextColumn("{task.description}"),
                transient=True,
                console=Console(file=self.stream, force_terminal=True),
            )
            self._bar.__enter__()
            self._task = self._bar.add_task("starting", total=self.total, left=self.left_text())
        else:
            self._write(f"{self.label}: {self.total} item{'' if self.total == 1 else 's'}")
        self._thread = threading.Thread(target=self._beat, daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2 * self.interval + 1)
        if self._bar is not None:
            self._bar.__exit__(*exc)
        elif exc[0] is None:
            self._write(
                f"{self.label}: {self.completed}/{self.total} done in "
                f"{_duration(time.perf_counter() - self.t0)}"
            )

    def _beat(self) -> None:
        while not self._stop.wait(1.0 if self._bar is not None else self.interval):
            if self._bar is not None:  # the live bar's time left, kept current
                self._bar.update(self._task, left=self.left_text())
                continue
            with self._lock:
                text = self.line()
            self._write(text)

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text + "\n")
            self.stream.flush()
        except (OSError, ValueError):  # closed stream: progress is not worth an error
            pass
