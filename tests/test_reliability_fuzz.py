"""Fuzz of the command line: random hostile values for every option of every command.

Each generated command runs in its own process with caps on address space, CPU time
and file size, in a scratch directory (every path it is offered lies there, apart from
/dev/null and -). Whatever the input, it must end with exit status 0 or
2 (never an internal error or a crash), print at most one error line (library
warnings may follow it, never precede it) and stay within the caps.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inerterlab.cli import app

#: caps for each fuzzed command
MEMORY_CAP = 4 * 1024**3  # bytes of address space
TIME_CAP = 120  # seconds
FILE_CAP = 512 * 1024**2  # bytes per file written
MAX_OPTIONS = int(os.environ.get("INERTERLAB_FUZZ_OPTIONS", "3"))  # options per command line

HOSTILE_NUMBERS = ["0", "-1", "1", "1e-300", "1e300", "-1e300", "nan", "inf", "-inf",
                   "99999999999999999999", "1e9", "0.5", "abc", "", " ", "1,2", "0x10"]  # fmt: skip


def _commands() -> dict[str, list]:
    import typer.main

    out: dict[str, list] = {}

    def walk(group, prefix: str) -> None:
        for name, cmd in group.commands.items():
            if hasattr(cmd, "commands"):  # a command group: fuzz each of its commands
                walk(cmd, f"{prefix}{name} ")
            else:
                out[f"{prefix}{name}"] = list(cmd.params)

    walk(typer.main.get_command(app), "")
    return out


COMMANDS = _commands()


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    d = tmp_path_factory.mktemp("fuzz")
    (d / "dir").mkdir()
    (d / "dir" / "keep.txt").write_text("user data")
    (d / "file.txt").write_text("user data")
    (d / "bin.bin").write_bytes(bytes(range(256)) * 8)
    (d / "nested.toml").write_text("x = " + "[" * 2000 + "]" * 2000 + "\n")
    (d / "ok.toml").write_text('point = "synthetic"\n[parameters]\nchanging_ratio = [0.1, 0.2]\n')
    (d / "road.csv").write_text("t,x\n0,0\n0.5,0.01\n1,0\n")
    os.mkfifo(d / "fifo")
    (d / "link_to_dir").symlink_to(d / "dir")
    (d / "dangling").symlink_to(d / "nowhere" / "x")
    return d


def _path_values(d: Path) -> list[str]:
    return [str(d / n) for n in ("dir", "file.txt", "bin.bin", "nested.toml", "ok.toml",
                                 "road.csv", "missing", "new_out", "x.xyz", "x.png", "x.csv")] + [
        "/dev/null", "-", "", str(d / "link_to_dir"), str(d / "dangling")]  # fmt: skip


def _value_strategy(param, d: Path):
    pool = HOSTILE_NUMBERS + _path_values(d) + ["sine", "drop", "afw", "cfw", "dask", "4.1"]
    return st.sampled_from(pool)


@st.composite
def command_lines(draw, d: Path):
    name = draw(st.sampled_from(sorted(COMMANDS)))
    params = [p for p in COMMANDS[name] if p.name not in ("help",)]
    args: list[str] = name.split()
    positional = [p for p in params if p.param_type_name == "argument"]
    options = [p for p in params if p.param_type_name == "option"]
    for _p in positional:
        args.append(draw(st.sampled_from(_path_values(d))))
    chosen = (
        draw(st.lists(st.sampled_from(options), max_size=MAX_OPTIONS, unique_by=lambda p: p.name))
        if options
        else []
    )
    for p in chosen:
        flag = p.opts[0]
        if p.is_flag:
            args.append(flag)
        else:
            args += [flag, draw(_value_strategy(p, d))]
    if name == "reproduce":  # keep every run small: a quick run of at most one table
        args += ["--quick"] + (
            [] if any(p.name == "tables" for p in chosen) else ["--tables", "4.1"]
        )
    # studies whose defaults run for minutes: a small one unless the draw set the size
    small = {
        "network truth": {"layout": "series", "variant": "ideal", "input_": "drop",
                          "horizon": "1"},
        "vehicle monte-carlo": {"roads": "2", "length": "100"},
    }.get(name, {})  # fmt: skip
    names = {p.name for p in chosen}
    for pname, value in small.items():
        if pname not in names:
            opt = next(p for p in options if p.name == pname)
            args += [opt.opts[0], value]
    return args


def _limits():  # pragma: no cover - runs in the child
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))
    resource.setrlimit(resource.RLIMIT_CPU, (TIME_CAP, TIME_CAP + 5))
    resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_CAP, FILE_CAP))


def run_capped(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    code = "import sys; from inerterlab.cli import main; sys.exit(main())"
    env = {**os.environ, "NUMBA_NUM_THREADS": "1", "MPLBACKEND": "Agg", "COLUMNS": "100"}
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        cwd=cwd,
        env=env,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        errors="replace",
        timeout=TIME_CAP,
        preexec_fn=_limits,
    )


def check_outcome(args: list[str], r: subprocess.CompletedProcess) -> None:
    where = f"inerterlab {' '.join(repr(a) for a in args)}"
    assert r.returncode in (0, 2), f"{where}: exit {r.returncode}\n{r.stderr[-3000:]}"
    assert "Traceback" not in r.stderr, f"{where}\n{r.stderr[-3000:]}"
    lines = [ln for ln in r.stderr.splitlines() if ln.startswith("inerterlab: error:")]
    if r.returncode == 2:
        assert len(lines) == 1, f"{where}\n{r.stderr[-3000:]}"
        first = next(ln for ln in r.stderr.splitlines() if ln.strip())
        assert first.startswith("inerterlab: error:"), f"{where}: text before the error\n{r.stderr}"
    else:
        assert lines == [], f"{where}\n{r.stderr[-3000:]}"


def _assert_user_files_intact(d: Path) -> None:
    assert (d / "dir" / "keep.txt").read_text() == "user data"
    assert (d / "file.txt").read_text() == "user data"
    assert (d / "fifo").is_fifo()


@pytest.mark.slow
@settings(max_examples=40, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])  # fmt: skip
@given(data=st.data())
def test_fuzz_every_command(scratch, data):
    args = data.draw(command_lines(scratch))
    if any(a == str(scratch / "fifo") for a in args):  # nothing would ever write to it
        return
    r = run_capped(args, scratch)
    check_outcome(args, r)
    _assert_user_files_intact(scratch)


# a fixed handful from the same generator that runs in the ordinary (not slow) suite
SMOKE = [
    ["simulate", "--horizon", "nan"],
    ["h2", "--sprung-mass", "1e-300"],
    ["frequency-response", "--harmonics", "99999999999999999999"],
    ["sweep", "{d}/nested.toml"],
    ["simulate", "--plot", "{d}/dir", "--horizon", "0.1"],
]


@pytest.mark.parametrize("args", SMOKE, ids=[a[0] + " " + a[1] for a in SMOKE])
def test_fuzz_smoke(scratch, args):
    args = [a.replace("{d}", str(scratch)) for a in args]
    r = run_capped(args, scratch)
    check_outcome(args, r)
    assert r.returncode == 2
    _assert_user_files_intact(scratch)
