"""Run the command line in a forked child with its memory and time capped.

The child inherits the imported package (no start-up cost), gets an address-space
limit of ``memory_mb`` above what it already maps and a CPU-time limit, and is killed
when it runs past ``seconds`` of wall time. The result says whether it had to be
killed, so a test can tell "refused in time" from "blocked" or "grew without bound".
"""

from __future__ import annotations

import io
import os
import resource
import signal
import sys
import tempfile
import time
from dataclasses import dataclass


@dataclass
class Capped:
    rc: int | None  # exit status; None if killed
    out: str
    err: str
    killed: str  # "" or why it was killed (timeout, signal)
    seconds: float


def _mapped_bytes() -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


def run_capped(args, *, memory_mb: int = 1500, seconds: float = 60.0, env=None, cwd=None):
    """``inerterlab.cli.main(args)`` (or ``args()``, a callable returning the exit
    status) in a child capped at ``memory_mb`` and ``seconds``."""
    out = tempfile.TemporaryFile()
    err = tempfile.TemporaryFile()
    sys.stdout.flush()
    sys.stderr.flush()
    t0 = time.monotonic()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        code = 99
        try:
            os.dup2(out.fileno(), 1)
            os.dup2(err.fileno(), 2)
            sys.stdout = io.TextIOWrapper(os.fdopen(1, "wb", closefd=False), write_through=True)
            sys.stderr = io.TextIOWrapper(os.fdopen(2, "wb", closefd=False), write_through=True)
            os.environ.update(env or {})
            if cwd is not None:
                os.chdir(cwd)
            cap = _mapped_bytes() + memory_mb * 1024**2
            resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
            cpu = int(seconds) + 1
            resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu))
            if callable(args):
                code = args()
            else:
                from inerterlab.cli import main

                code = main([str(a) for a in args])
        except BaseException as exc:  # noqa: BLE001 - reported through the exit status
            try:
                sys.stderr.write(f"CHILD-CRASH {type(exc).__name__}: {exc}\n")
            except BaseException:  # noqa: BLE001
                pass
        finally:
            try:
                sys.stdout.flush()
                sys.stderr.flush()
            finally:
                os._exit(code if isinstance(code, int) else 98)
    killed = ""
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() - t0 > seconds:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            killed = f"timeout after {seconds:g} s"
            status = None
            break
        time.sleep(0.02)
    rc = None
    if status is not None:
        if os.WIFEXITED(status):
            rc = os.WEXITSTATUS(status)
        else:
            killed = f"signal {os.WTERMSIG(status)}"
    texts = []
    for fh in (out, err):
        fh.seek(0)
        texts.append(fh.read().decode("utf-8", "replace"))
        fh.close()
    return Capped(rc, texts[0], texts[1], killed, time.monotonic() - t0)


def assert_user_error(res: Capped, *words: str) -> str:
    """Exit 2 with one line on standard error holding ``words``; return the line."""
    assert not res.killed, f"{res.killed}; stderr: {res.err[-500:]}"
    assert res.rc == 2, f"exit {res.rc}: {res.err[-800:]}"
    lines = [ln for ln in res.err.splitlines() if ln.strip()]
    assert len(lines) == 1, res.err
    line = lines[0]
    assert line.startswith("inerterlab: error: "), line
    assert len(line) < 600, line
    for w in words:
        assert w.lower() in line.lower(), (w, line)
    return line
