"""Progress of a run of named items on standard error.

On a terminal: a live bar naming the item being computed, with elapsed time and an
estimate of the time left. Otherwise (a log file, CI, a pipe): plain lines, one when the
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
    """

    def __init__(self, total: int, *, label: str, stream=None, interval: float = 10.0,
                 live: bool | None = None):  # fmt: skip
        self.total = int(total)
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.interval = float(interval)
        if live is None:
            isatty = getattr(self.stream, "isatty", None)
            live = bool(isatty and isatty())
        self.live = live
        self.completed = 0
        self.computed = 0  # items computed (not reused), for the estimate
        self.reused_seconds = 0.0  # time spent on reused items (near zero)
        self.current: str | None = None
        self.current_since = 0.0
        self.t0 = time.perf_counter()
        self._last_event = self.t0
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None
        self._bar = None
        self._task = None

    # -- estimate ----------------------------------------------------------------
    def eta(self) -> float | None:
        """Seconds left: the time per item computed so far (reused items not counted)
        times the items left (None before the first computed item)."""
        if self.computed == 0:
            return None
        left = self.total - self.completed
        elapsed = time.perf_counter() - self.t0 - self.reused_seconds
        return max(0.0, left * elapsed / self.computed)

    def line(self) -> str:
        """One plain progress line."""
        now = time.perf_counter()
        parts = [f"{self.label}: {self.completed}/{self.total} done"]
        if self.current:
            parts.append(f"running {self.current} ({_duration(now - self.current_since)})")
        parts.append(f"elapsed {_duration(now - self.t0)}")
        eta = self.eta()
        parts.append(f"about {_duration(eta)} left" if eta is not None else "estimating time left")
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
        reused = name.endswith("(reused)")
        with self._lock:
            if reused:
                if self.current is None:  # time since the last event went on reading it
                    self.reused_seconds += time.perf_counter() - self._last_event
            else:
                self.computed += 1
            self.completed += 1
            self.current = None
            self._last_event = time.perf_counter()
        if self._bar is not None:
            self._bar.update(self._task, advance=1, description=f"done {name}")

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
                TimeRemainingColumn,
            )

            self._bar = Progress(
                TextColumn(f"[bold]{self.label}"),
                BarColumn(),
                TextColumn("{task.completed}/{task.total}"),
                TimeElapsedColumn(),
                TextColumn("left"),
                TimeRemainingColumn(),
                TextColumn("{task.description}"),
                transient=True,
                console=Console(file=self.stream, force_terminal=True),
            )
            self._bar.__enter__()
            self._task = self._bar.add_task("starting", total=self.total)
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
        while not self._stop.wait(self.interval):
            with self._lock:
                text = self.line()
            self._write(text)

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text + "\n")
            self.stream.flush()
        except (OSError, ValueError):  # closed stream: progress is not worth an error
            pass
